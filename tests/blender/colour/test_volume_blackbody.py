"""A Principled Volume blackbody seen by the exact camera (fast mode) is a blackbody at ``D T``.

A cube of emitting gas (Principled Volume, density 0, Blackbody Intensity 1, 3000 K) beside a
3000 K emitter mesh, both at rest, observer moving toward them at 0.5c. Both must be seen as
blackbodies at ``D T`` with luminance ``Y(D T) / Y(T)`` times their rest luminance (Weiskopf et
al. 1999 eq. 14, docs/physics.md), ``D`` from each pixel's viewing direction. References:
colour-science's Planck spectra; rest luminances measured on a render without the effect. Before
the volume correction the gas went through the RGB matrix (Delta E 2000 of 26 here).
"""

import math

import numpy as np
import pytest

import colour_helpers as dh
from colour_helpers import ch

TEMPERATURE = 3000.0
RESOLUTION = (64, 48)
VOLUME = (slice(20, 28), slice(12, 18))
MESH = (slice(20, 28), slice(46, 52))
BETA = (0.0, 0.0, -0.5)


def _scene(bpy):
    scene, camera = dh.emitter_scene(bpy, samples=32, resolution=RESOLUTION)
    dh.add_emitter_plane(
        bpy, scene, "Mesh", (0.3, 2.5), (-1.0, 1.0), colour=(1.0, 1.0, 1.0), beta=None, temperature=TEMPERATURE
    )
    material = dh.volume_material(bpy, "Gas", Density=0.0, Blackbody_Intensity=1.0, Temperature=TEMPERATURE)
    dh.add_box(bpy, scene, "Gas", (-4.0, -0.2), (-2.0, 2.0), (-6.0, -4.0), material)
    return scene, camera, material


def _xyz(image, window):
    return dh.linear_rec709_to_xyz(image[window].reshape(-1, 3)).mean(axis=0)


def _expected(doppler, y_rest):
    """Mean XYZ of blackbodies at ``D T``, each scaled to its ``y_rest`` times ``Y(D T) / Y(T)``."""
    y_t = dh.blackbody_xyz_colour_science(TEMPERATURE)[1]
    y_rest = np.broadcast_to(y_rest, np.shape(doppler))
    return np.mean(dh.blackbody_xyz_colour_science(np.asarray(doppler) * TEMPERATURE) / y_t * y_rest[:, None], axis=0)


def _slab_path_ratio(bpy, scene, camera):
    """Per pixel, the gas slab's path length seen moving over the one seen at rest: the pixel's
    ray crosses the slab along its scene-frame direction (aberrated, docs/physics.md), ``1/|k_z|``."""
    rest = dh.pixel_photon_directions(bpy, scene, camera)  # the same pixel's direction at rest
    scene_k = np.array([ch.aberrate(k, -np.asarray(BETA)) for k in rest.reshape(-1, 3)]).reshape(rest.shape)
    return np.abs(rest[..., 2]) / np.abs(scene_k[..., 2])


def test_principled_volume_blackbody_is_seen_at_d_t(relativity_addon, tmp_path):
    bpy = __import__("bpy")
    scene, camera, material = _scene(bpy)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {
        name: dh.linear_rec709_to_xyz(rest[window].reshape(-1, 3))[:, 1]
        for name, window in (("volume", VOLUME), ("mesh", MESH))
    }
    assert y_rest["volume"].min() > 0.5 and y_rest["mesh"].min() > 0.5
    links_before = sorted((link.from_node.name, link.to_node.name) for link in material.node_tree.links)

    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    moving = dh.render(bpy, scene, tmp_path / "moving.exr")
    assert np.all(np.isfinite(moving)) and moving.min() >= 0.0

    view = -dh.pixel_photon_directions(bpy, scene, camera)
    gamma = 1.0 / math.sqrt(1.0 - np.dot(BETA, BETA))
    doppler = 1.0 / (gamma * (1.0 - view @ np.asarray(BETA)))
    path = {"volume": _slab_path_ratio(bpy, scene, camera)[VOLUME].ravel(), "mesh": 1.0}
    measured = {}
    for name, window in (("volume", VOLUME), ("mesh", MESH)):
        xyz = _xyz(moving, window)
        expected = _expected(doppler[window].ravel(), y_rest[name] * path[name])
        measured[name] = xyz
        delta_e = dh.delta_e_2000_normalised(xyz, expected)
        ratio = xyz[1] / expected[1]
        print(
            f"{name}: D {doppler[window].mean():.3f}, path {np.mean(path[name]):.4f}, Delta E {delta_e:.3f}, "
            f"Y / expected {ratio:.4f}"
        )
        assert delta_e < 1.0, name
        assert ratio == pytest.approx(1.0, abs=0.02), name
    between = dh.delta_e_2000_normalised(measured["volume"], measured["mesh"])
    print(f"volume against emitter mesh, Delta E {between:.3f}")
    assert between < 1.0

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert sorted((link.from_node.name, link.to_node.name) for link in material.node_tree.links) == links_before
    assert len(material.node_tree.nodes) == 2


def test_volumes_with_temperature_grids_read_the_grid_and_only_uncorrectable_ones_warn(relativity_addon):
    """A Volume object (OpenVDB grids) multiplies its Temperature by a temperature grid: its
    material gets the correction with an Attribute node reading the grid its Temperature Attribute
    names, shifted by the bolometric rule (test_volume_temperature_grid.py measures it). A copy
    with a surface shader of its own cannot be corrected: it keeps the RGB shift, and the scene's
    warnings name it."""
    bpy = __import__("bpy")
    volumes = dh.addon_module(relativity_addon, "colour.volumes")
    effect = dh.addon_module(
        relativity_addon, "pipeline.effect"
    )  # the add-on's own (bl_ext) module, whose status the operators write

    scene, _camera, material = _scene(bpy)
    grid_material = material.copy()
    grid_material.name = "Fire"
    surfaced = material.copy()
    surfaced.name = "Sooty"
    tree = surfaced.node_tree
    tree.links.new(tree.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    for name, mat in (("Smoke", grid_material), ("Soot", surfaced)):
        volume_object = bpy.data.objects.new(name, bpy.data.volumes.new(name))
        volume_object.data.materials.append(mat)
        scene.collection.objects.link(volume_object)
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}

    def corrected(mat):
        return any(node.name.startswith(volumes.NODE_PREFIX) for node in mat.node_tree.nodes)

    assert corrected(material) and corrected(grid_material) and not corrected(surfaced)
    readers = [node for node in grid_material.node_tree.nodes if node.bl_idname == "ShaderNodeAttribute"]
    assert [(node.attribute_type, node.attribute_name) for node in readers] == [("GEOMETRY", "temperature")]
    group = grid_material.node_tree.nodes[f"{volumes.NODE_PREFIX} Principled Volume"]
    assert group.inputs["Bolometric"].default_value == 1.0 and group.inputs["Grid"].is_linked
    assert not any(node.bl_idname == "ShaderNodeAttribute" for node in material.node_tree.nodes)  # a mesh: no grid
    (warning,) = [line for line in effect.scene_warnings(scene) if "RGB colour shift" in line]
    assert "'Soot'" in warning and "'Sooty'" in warning
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert not corrected(material) and not corrected(grid_material)
    assert len(grid_material.node_tree.nodes) == 2
