"""A Principled Volume whose Temperature is driven by nodes is seen, point by point, at ``D T(x)``.

A slab of emitting gas (a mesh cube, Principled Volume, density 0, Blackbody Intensity 1) whose
Temperature input comes from its shading position: 2500 K where x < 0, 4000 K where x > 0 (a
Geometry node through Math nodes, the way a hand-made temperature field is built). Observer moving
toward it at 0.5c: each half must be seen as a blackbody at ``D T`` of its own ``T``, luminance
``Y(D T) / Y(T)`` times its rest luminance (Weiskopf et al. 1999 eq. 14, docs/physics.md), ``D``
from each pixel's viewing direction. References: colour-science's Planck spectra; rest luminances
measured on a render without the effect. Temperature grids (the Temperature Attribute) follow
another rule: ``test_volume_temperature_grid.py``.
"""

import math

import numpy as np
import pytest
from test_volume_blackbody import _slab_path_ratio

import colour_helpers as dh

RESOLUTION = (64, 48)
BETA = (0.0, 0.0, -0.5)
HALVES = {"cool": (2500.0, (slice(20, 28), slice(18, 26))), "hot": (4000.0, (slice(20, 28), slice(38, 46)))}


def _scene(bpy):
    scene, camera = dh.emitter_scene(bpy, samples=16, resolution=RESOLUTION)
    material = dh.volume_material(bpy, "Field", Density=0.0, Blackbody_Intensity=1.0)
    tree = material.node_tree
    volume = tree.nodes["Principled Volume"]
    # T = 2500 K + 1500 K (x > 0)
    position = tree.nodes.new("ShaderNodeNewGeometry")
    split = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(position.outputs["Position"], split.inputs[0])
    side = tree.nodes.new("ShaderNodeMath")
    side.operation = "GREATER_THAN"
    side.inputs[1].default_value = 0.0
    tree.links.new(split.outputs["X"], side.inputs[0])
    temperature = tree.nodes.new("ShaderNodeMath")
    temperature.operation = "MULTIPLY_ADD"
    temperature.inputs[1].default_value = HALVES["hot"][0] - HALVES["cool"][0]
    temperature.inputs[2].default_value = HALVES["cool"][0]
    tree.links.new(side.outputs[0], temperature.inputs[0])
    tree.links.new(temperature.outputs[0], volume.inputs["Temperature"])
    dh.add_box(bpy, scene, "Field", (-3.0, 3.0), (-2.0, 2.0), (-6.0, -4.0), material)
    return scene, camera, material


def _xyz(image, window):
    return dh.linear_rec709_to_xyz(image[window].reshape(-1, 3))


def _expected(bpy, scene, camera, y_rest):
    """Per half: mean XYZ of the blackbodies at ``D T`` with luminance ``Y(D T) / Y(T)`` times the
    rest luminance and the slab's path-length change, and the mean ``D``."""
    view = -dh.pixel_photon_directions(bpy, scene, camera)
    gamma = 1.0 / math.sqrt(1.0 - np.dot(BETA, BETA))
    doppler = 1.0 / (gamma * (1.0 - view @ np.asarray(BETA)))
    path = _slab_path_ratio(bpy, scene, camera)
    expected = {}
    for name, (temperature, window) in HALVES.items():
        y_t = dh.blackbody_xyz_colour_science(temperature)[1]
        rest = y_rest[name] * path[window].ravel()
        colours = dh.blackbody_xyz_colour_science(doppler[window].ravel() * temperature) / y_t * rest[:, None]
        expected[name] = (np.mean(colours, axis=0), doppler[window].mean())
    return expected


def test_node_driven_temperature_in_spectral_mode(relativity_addon, tmp_path):
    """The same field in the spectral mode (3 passes): Delta E 0.2 and 2 %. On Blender 5.2 the
    passes ray-march (with its default null scattering: Delta E 0.42 / 0.60, the 4000 K half 3.4 %
    dim, 25 times slower; docs/spectral-model.md)."""
    bpy = __import__("bpy")
    scene, camera, _material = _scene(bpy)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {name: _xyz(rest, window)[:, 1] for name, (_temperature, window) in HALVES.items()}
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    pixels, _info = dh.addon_module(relativity_addon, "pipeline.spectral_render").render(scene, 3)
    spectral = pixels[::-1, :, :3].astype(float)  # top row first, like the EXR reader
    assert np.all(np.isfinite(spectral)) and spectral.min() >= 0.0
    for name, (expected, doppler) in _expected(bpy, scene, camera, y_rest).items():
        xyz = _xyz(spectral, HALVES[name][1]).mean(axis=0)
        delta_e, ratio = dh.delta_e_2000_normalised(xyz, expected), xyz[1] / expected[1]
        print(f"spectral {name}: D {doppler:.3f}, Delta E {delta_e:.3f}, Y / expected {ratio:.4f}")
        assert delta_e < 0.2, name
        assert ratio == pytest.approx(1.0, abs=0.02), name
    if hasattr(scene.cycles, "volume_biased"):
        assert not scene.cycles.volume_biased  # the user's setting is back


def test_node_driven_temperature_is_seen_at_d_t_per_point(relativity_addon, tmp_path):
    bpy = __import__("bpy")
    scene, camera, material = _scene(bpy)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {}
    for name, (temperature, window) in HALVES.items():
        xyz = _xyz(rest, window)
        y_rest[name] = xyz[:, 1]
        assert y_rest[name].min() > 0.05, name
        # the setup: Cycles' rest colour is the blackbody at the field's temperature there
        delta_e = dh.delta_e_2000_normalised(xyz.mean(axis=0), dh.blackbody_xyz_colour_science(temperature))
        print(f"{name} at rest: Y {y_rest[name].mean():.3f}, Delta E to {temperature:.0f} K {delta_e:.3f}")
        assert delta_e < 2.0, name
    links_before = sorted((link.from_node.name, link.to_node.name) for link in material.node_tree.links)
    nodes_before = len(material.node_tree.nodes)

    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    moving = dh.render(bpy, scene, tmp_path / "moving.exr")
    assert np.all(np.isfinite(moving)) and moving.min() > -1e-6  # X - E may round below 0 where it is 0

    for name, (expected, doppler) in _expected(bpy, scene, camera, y_rest).items():
        xyz = _xyz(moving, HALVES[name][1]).mean(axis=0)
        delta_e = dh.delta_e_2000_normalised(xyz, expected)
        ratio = xyz[1] / expected[1]
        print(f"{name}: D {doppler:.3f}, Delta E {delta_e:.3f}, Y / expected {ratio:.4f}")
        assert delta_e < 2.0, name
        assert ratio == pytest.approx(1.0, abs=0.05), name

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert sorted((link.from_node.name, link.to_node.name) for link in material.node_tree.links) == links_before
    assert len(material.node_tree.nodes) == nodes_before
