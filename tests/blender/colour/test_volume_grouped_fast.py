"""A Principled Volume blackbody inside a shared node group, fast mode (F12): seen at ``D T``.

Two slabs of 3000 K gas (density 0) on two objects with two materials, both using one node group
that holds the Principled Volume, beside a 3000 K emitter mesh; the scene at rest, the observer at
0.5c toward it. As for the ungrouped gas (``test_volume_blackbody.py``), each must be the blackbody
at ``D T`` with luminance ``Y(D T) / Y(T)`` times its rest luminance times the slab's path-length
change under aberration (Weiskopf et al. 1999 eq. 14, docs/physics.md; ``D`` from each pixel's
viewing direction; colour-science's Planck spectra). Before the fix the fast mode kept the RGB
matrix's shift there (Delta E 27, 0.27 of the luminance). Remove gives the file back exactly.
"""

import math

import numpy as np
import pytest
import scene_dump

import colour_helpers as dh
from colour_helpers import ch

TEMPERATURE = 3000.0
RESOLUTION = (64, 48)
UPPER = (slice(14, 20), slice(12, 18))  # gas A (y > 0)
LOWER = (slice(28, 34), slice(12, 18))  # gas B (y < 0)
MESH = (slice(20, 28), slice(46, 52))
BETA = (0.0, 0.0, -0.5)


def _share_group(bpy, first, second):
    """Move ``first``'s Principled Volume into a new node group and use that group in both
    materials (``second``'s own volume node replaced by it)."""
    node = first.node_tree.nodes["Principled Volume"]
    group = bpy.data.node_groups.new("Gas Group", "ShaderNodeTree")
    group.interface.new_socket(name="Volume", in_out="OUTPUT", socket_type="NodeSocketShader")
    inner = group.nodes.new(node.bl_idname)
    for socket in node.inputs:
        if hasattr(socket, "default_value") and socket.enabled:
            inner.inputs[socket.identifier].default_value = socket.default_value
    group.links.new(inner.outputs[0], group.nodes.new("NodeGroupOutput").inputs[0])
    for material in (first, second):
        tree = material.node_tree
        user = tree.nodes.new("ShaderNodeGroup")
        user.node_tree = group
        tree.links.new(user.outputs[0], tree.nodes["Material Output"].inputs["Volume"])
        tree.nodes.remove(tree.nodes["Principled Volume"])
    return group


def _xyz(image, window):
    return dh.linear_rec709_to_xyz(image[window].reshape(-1, 3)).mean(axis=0)


def _expected(doppler, y_rest):
    """Mean XYZ of blackbodies at ``D T``, each scaled to its ``y_rest`` times ``Y(D T) / Y(T)``."""
    y_t = dh.blackbody_xyz_colour_science(TEMPERATURE)[1]
    y_rest = np.broadcast_to(y_rest, np.shape(doppler))
    return np.mean(dh.blackbody_xyz_colour_science(np.asarray(doppler) * TEMPERATURE) / y_t * y_rest[:, None], axis=0)


def test_grouped_volume_blackbody_is_seen_at_d_t_in_the_fast_mode(relativity_addon, tmp_path):
    bpy = __import__("bpy")
    effect = dh.addon_module(relativity_addon, "pipeline.effect")  # the add-on's own (bl_ext) module

    scene, camera = dh.emitter_scene(bpy, samples=16, resolution=RESOLUTION)
    dh.add_emitter_plane(
        bpy, scene, "Mesh", (0.3, 2.5), (-1.0, 1.0), colour=(1.0, 1.0, 1.0), beta=None, temperature=TEMPERATURE
    )
    gas = [
        dh.volume_material(bpy, name, Density=0.0, Blackbody_Intensity=1.0, Temperature=TEMPERATURE)
        for name in ("Gas A", "Gas B")
    ]
    _share_group(bpy, *gas)
    dh.add_box(bpy, scene, "Gas A", (-4.0, -0.2), (0.1, 2.0), (-6.0, -4.0), gas[0])
    dh.add_box(bpy, scene, "Gas B", (-4.0, -0.2), (-2.0, -0.1), (-6.0, -4.0), gas[1])
    windows = {"gas A": UPPER, "gas B": LOWER, "mesh": MESH}
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {name: dh.linear_rec709_to_xyz(rest[window].reshape(-1, 3))[:, 1] for name, window in windows.items()}
    assert min(y.min() for y in y_rest.values()) > 0.5
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0
    rest_path = scene.render.filepath
    before = scene_dump.dump(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    moving = dh.render(bpy, scene, tmp_path / "moving.exr")
    assert np.all(np.isfinite(moving)) and moving.min() >= 0.0
    warnings = [line for line in effect.scene_warnings(scene) if "'Gas Group'" in line]

    doppler = dh.pixel_doppler(bpy, scene, camera, BETA)
    rest_k = dh.pixel_photon_directions(bpy, scene, camera)
    scene_k = np.array([ch.aberrate(k, -np.asarray(BETA)) for k in rest_k.reshape(-1, 3)]).reshape(rest_k.shape)
    path = np.abs(rest_k[..., 2]) / np.abs(scene_k[..., 2])
    measured = {}
    failures = []
    for name, window in windows.items():
        gas_path = path[window].ravel() if name != "mesh" else 1.0
        expected = _expected(doppler[window].ravel(), y_rest[name] * gas_path)
        measured[name] = _xyz(moving, window)
        delta_e = dh.delta_e_2000_normalised(measured[name], expected)
        ratio = measured[name][1] / expected[1]
        print(f"{name}: D {doppler[window].mean():.3f}, Delta E {delta_e:.3f}, Y / expected {ratio:.4f}")
        if delta_e >= 1.0 or not ratio == pytest.approx(1.0, abs=0.03):
            failures.append(name)
    between = dh.delta_e_2000_normalised(measured["gas A"], measured["mesh"])
    print(f"gas A against the emitter mesh: Delta E {between:.3f}; warnings {warnings}")
    assert not failures, failures
    assert between < 1.0
    assert not warnings  # handled: the panel no longer names the grouped blackbody

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    scene.render.filepath = rest_path  # the test's own output file, set by the second render
    lines = scene_dump.differences(before, scene_dump.dump(bpy))
    assert not lines, f"{len(lines)} differences after Remove:\n" + "\n".join(lines[:40])
    assert math.isclose(y_rest["gas A"].mean(), y_rest["gas B"].mean(), rel_tol=0.05)  # the two slabs alike


def test_a_user_with_a_surface_shader_keeps_the_shared_group_on_the_rgb_shift(relativity_addon):
    """The boundary belongs to each material using the group: where one of them has a surface
    shader of its own, none can be marked done without leaving that one's gas shifted twice, so the
    group's fast part stays off, no material gets the boundary, and the panel names them; Set Up
    again after the surface is gone switches it on."""
    bpy = __import__("bpy")
    grouped_volumes = dh.addon_module(relativity_addon, "colour.grouped_volumes")
    volumes = dh.addon_module(relativity_addon, "colour.volumes")
    effect = dh.addon_module(relativity_addon, "pipeline.effect")  # the add-on's own (bl_ext) module

    scene, _camera = dh.emitter_scene(bpy, samples=1, resolution=RESOLUTION)
    gas = [
        dh.volume_material(bpy, name, Density=0.0, Blackbody_Intensity=1.0, Temperature=TEMPERATURE)
        for name in ("Gas A", "Gas B")
    ]
    group = _share_group(bpy, *gas)
    tree = gas[1].node_tree
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(diffuse.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    dh.add_box(bpy, scene, "Gas A", (-4.0, -0.2), (0.1, 2.0), (-6.0, -4.0), gas[0])
    dh.add_box(bpy, scene, "Gas B", (-4.0, -0.2), (-2.0, -0.1), (-6.0, -4.0), gas[1])
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    corrector = group.nodes[f"{volumes.NODE_PREFIX} Principled Volume"]
    assert corrector.inputs["Fast Part"].default_value == 0.0
    assert not any(grouped_volumes.handled(material) for material in gas)
    effect.sync(scene)  # what the panel shows after any change
    warnings = [line for line in effect.scene_warnings(scene) if "RGB colour shift" in line and "Gas Group" in line]
    assert len(warnings) == 2 and all("'Gas Group'" in line for line in warnings)
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}

    tree.nodes.remove(diffuse)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    corrector = group.nodes[f"{volumes.NODE_PREFIX} Principled Volume"]
    assert corrector.inputs["Fast Part"].default_value == 1.0
    assert all(grouped_volumes.handled(material) for material in gas)
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert not any(node.name.startswith(volumes.NODE_PREFIX) for m in gas for node in m.node_tree.nodes)


def test_grouped_temperature_grid_is_seen_at_d_t_with_d4_luminance(relativity_addon, tmp_path):
    """The two-temperature VDB of ``test_volume_temperature_grid.py`` (2500 K and 4000 K halves) with
    its Principled Volume inside a node group that a second material, on a mesh (out of view), uses
    too: each half must be colour-science's blackbody at ``D T`` (Delta E 2000 <= 1) with its rest
    luminance times ``D^4`` (eq. 15) and the slab's path-length change, within 2 % as ungrouped
    (the Principled Volume's own emission shifted: it reads the grid as at rest).
    Before: the RGB shift (the group could not read the grid)."""
    bpy = __import__("bpy")
    import test_volume_temperature_grid as tg

    scene, camera, fire = tg.grid_scene(bpy, tmp_path)
    other = dh.volume_material(bpy, "Other", Density=0.0, Blackbody_Intensity=1.0, Temperature=TEMPERATURE)
    _share_group(bpy, fire, other)
    dh.add_box(bpy, scene, "Behind the camera", (-1.0, 1.0), (-1.0, 1.0), (2.0, 3.0), other)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {name: tg._xyz(rest, window)[:, 1] for name, (_grid, window) in tg.HALVES.items()}
    tg.observe(scene)
    rest_path = scene.render.filepath
    before = scene_dump.dump(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    moving = dh.render(bpy, scene, tmp_path / "moving.exr")
    assert np.all(np.isfinite(moving))

    assert not tg.halves_off(bpy, scene, camera, moving, y_rest, label="grouped grid ")

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    scene.render.filepath = rest_path
    lines = scene_dump.differences(before, scene_dump.dump(bpy))
    assert not lines, f"{len(lines)} differences after Remove:\n" + "\n".join(lines[:40])


def test_grouped_temperature_grid_in_spectral_mode_is_seen_at_d_t_with_d4_luminance(relativity_addon, tmp_path):
    """The same grouped grid in the spectral mode (3 passes): each half colour-science's blackbody
    at ``D T`` with ``D^4`` times its rest luminance, as ungrouped (``test_volume_temperature_grid.py``).
    Refused before (the shared group did not read the grid)."""
    bpy = __import__("bpy")
    import test_volume_temperature_grid as tg

    scene, camera, fire = tg.grid_scene(bpy, tmp_path)
    other = dh.volume_material(bpy, "Other", Density=0.0, Blackbody_Intensity=1.0, Temperature=TEMPERATURE)
    _share_group(bpy, fire, other)
    dh.add_box(bpy, scene, "Behind the camera", (-1.0, 1.0), (-1.0, 1.0), (2.0, 3.0), other)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {name: tg._xyz(rest, window)[:, 1] for name, (_grid, window) in tg.HALVES.items()}
    tg.observe(scene)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    pixels, _info = dh.addon_module(relativity_addon, "pipeline.spectral_render").render(scene, 3)
    spectral = pixels[::-1, :, :3].astype(float)  # top row first, like the EXR reader
    assert np.all(np.isfinite(spectral)) and spectral.min() >= 0.0

    assert not tg.halves_off(bpy, scene, camera, spectral, y_rest, label="spectral grouped grid ", luminance=0.05)
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
