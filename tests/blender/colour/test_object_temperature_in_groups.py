"""An object's blackbody temperature reaches an emission colour computed inside a shared node group.

Two emitter walls use one node group ("Glow": an Emission whose white colour is set inside the
group). One wall's object is marked as a 3000 K blackbody (``Object.relativity.temperature``), the
other is not. Observer at 0.5c toward them (exact camera, fast mode). The marked wall must be seen
as colour-science's blackbody at ``D T`` with luminance ``Y(D T) / Y(T)`` times its rest luminance
(Weiskopf et al. 1999 eq. 14, docs/physics.md), ``D`` from each pixel's viewing direction; the
other, sharing the group, keeps the RGB path (white seen at ``D``, far from a 3000 K blackbody).
The spectral mode (3 passes) must see the marked wall the same way.
"""

import math

import numpy as np
import pytest

import colour_helpers as dh
from colour_helpers import ch

TEMPERATURE = 3000.0
RESOLUTION = (64, 48)
MARKED = (slice(20, 28), slice(14, 20))
PLAIN = (slice(20, 28), slice(44, 50))
BETA = (0.0, 0.0, -0.5)


def _glow_group(bpy):
    group = bpy.data.node_groups.new("Glow", "ShaderNodeTree")
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    emission = group.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    group.links.new(emission.outputs[0], group.nodes.new("NodeGroupOutput").inputs["Shader"])
    return group


def _use_group(material, group):
    tree = material.node_tree
    for node in [n for n in tree.nodes if n.bl_idname == "ShaderNodeEmission"]:
        tree.nodes.remove(node)
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    output = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
    tree.links.new(node.outputs["Shader"], output.inputs["Surface"])


def _scene(bpy):
    scene, camera = dh.emitter_scene(bpy, samples=4, resolution=RESOLUTION)
    group = _glow_group(bpy)
    walls = {}
    for name, x_range in (("Marked", (-2.5, -0.3)), ("Plain", (0.3, 2.5))):
        walls[name] = dh.add_emitter_plane(bpy, scene, name, x_range, (-1.0, 1.0), beta=None)
        _use_group(bpy.data.materials[name], group)
    walls["Marked"].relativity.temperature = TEMPERATURE
    return scene, camera, group


def _xyz(image, window):
    return dh.linear_rec709_to_xyz(image[window].reshape(-1, 3))


def test_object_temperature_reaches_an_emission_inside_a_shared_group(relativity_addon, tmp_path):
    bpy = __import__("bpy")
    from relativity_addon.blender.common import names

    scene, camera, group = _scene(bpy)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = _xyz(rest, MARKED)[:, 1]
    assert y_rest.min() > 0.5
    group_links = sorted((link.from_node.name, link.to_node.name) for link in group.links)
    group_nodes = len(group.nodes)

    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    moving = dh.render(bpy, scene, tmp_path / "moving.exr")
    assert np.all(np.isfinite(moving))

    view = -dh.pixel_photon_directions(bpy, scene, camera)
    gamma = 1.0 / math.sqrt(1.0 - np.dot(BETA, BETA))
    doppler = 1.0 / (gamma * (1.0 - view @ np.asarray(BETA)))
    y_t = dh.blackbody_xyz_colour_science(TEMPERATURE)[1]
    d = doppler[MARKED].ravel()
    expected = np.mean(dh.blackbody_xyz_colour_science(d * TEMPERATURE) / y_t * np.asarray(y_rest)[:, None], axis=0)
    xyz = _xyz(moving, MARKED).mean(axis=0)
    delta_e = dh.delta_e_2000_normalised(xyz, expected)
    ratio = xyz[1] / expected[1]
    plain = dh.delta_e_2000_normalised(
        _xyz(moving, PLAIN).mean(axis=0), dh.blackbody_xyz_colour_science(doppler[PLAIN].mean() * TEMPERATURE)
    )
    print(f"marked: D {d.mean():.3f}, Delta E {delta_e:.3f}, Y / expected {ratio:.4f}; plain wall Delta E {plain:.1f}")
    assert delta_e < 1.0
    assert ratio == pytest.approx(1.0, abs=0.02)
    assert plain > 5.0  # the object without a temperature keeps the RGB path through the same group
    # the file renders the same where the add-on is not installed (a render farm worker)
    elsewhere = dh.render_without_addon(bpy, ch.save_blend(bpy, tmp_path / "grouped.blend"), tmp_path / "plain.exr")
    away = dh.delta_e_2000_normalised(_xyz(elsewhere, MARKED).mean(axis=0), xyz)
    print(f"without the add-on: Delta E {away:.4f} from the render with it")
    assert away < 0.01

    # the spectral passes: the same colour group gives the marked wall its Planck spectrum
    pixels, _info = dh.addon_module(relativity_addon, "pipeline.spectral_render").render(scene, 3)
    spectral = pixels[::-1, :, :3].astype(float)
    xyz = _xyz(spectral, MARKED).mean(axis=0)
    delta_e, ratio = dh.delta_e_2000_normalised(xyz, expected), xyz[1] / expected[1]
    print(f"spectral mode: Delta E {delta_e:.3f}, Y / expected {ratio:.4f}")
    assert delta_e < 1.0
    assert ratio == pytest.approx(1.0, abs=0.02)

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert not any(names.OBJECT_TEMPERATURE_PROPERTY in obj for obj in scene.objects)
    assert sorted((link.from_node.name, link.to_node.name) for link in group.links) == group_links
    assert len(group.nodes) == group_nodes
