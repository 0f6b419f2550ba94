"""Blackbody sources that do not link straight into the emission (relativity_addon.blender.scene.sources),
in real Cycles renders: a Blackbody reaching the Emission through a reroute, a Mix multiplying
by a grey, or a node group must be seen as a blackbody at ``D T`` like a direct link; the world's
Background fed by a Blackbody too, on the exact camera's path.

Expected colours come from colour-science (Planck spectra through the CIE 1931 observer) at the
Doppler factor computed per pixel in numpy (docs/physics.md), as in test_doppler_mesh_path.py.
"""

import math

import numpy as np
import pytest

import colour_helpers as dh
from colour_helpers import ch

TEMPERATURE = 5762.0
VARIANTS = ("direct", "reroute", "multiply", "group")
# The Emission inside a node group: with the Blackbody inside too, or fed from outside through the
# group's Color input (grouped_colours.py: the colour group goes into the group, or in front of it).
GROUPED_VARIANTS = ("direct", "inner group", "passed group")
GREY_FACTOR = 0.5  # the Mix multiply variant's grey


def _feed_blackbody(bpy, material, kind, temperature=TEMPERATURE, tint=(GREY_FACTOR,) * 3):
    """Link a Blackbody node into the material's Emission colour, through ``kind``."""
    tree = material.node_tree
    colour = tree.nodes["Emission"].inputs["Color"]
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = temperature
    if kind == "direct":
        tree.links.new(blackbody.outputs[0], colour)
    elif kind == "reroute":
        reroute = tree.nodes.new("NodeReroute")
        tree.links.new(blackbody.outputs[0], reroute.inputs[0])
        tree.links.new(reroute.outputs[0], colour)
    elif kind == "multiply":
        mix = tree.nodes.new("ShaderNodeMix")
        mix.data_type, mix.blend_type = "RGBA", "MULTIPLY"
        inputs = {socket.identifier: socket for socket in mix.inputs}
        inputs["Factor_Float"].default_value = 1.0
        inputs["B_Color"].default_value = (*tint, 1.0)
        tree.links.new(blackbody.outputs[0], inputs["A_Color"])
        tree.links.new(next(s for s in mix.outputs if s.identifier == "Result_Color"), colour)
    elif kind in ("inner group", "passed group"):
        tree.nodes.remove(blackbody)
        dh.emission_in_group(bpy, material, kind, temperature)
    elif kind == "group":
        # the Blackbody inside the group, its temperature from the group node's input
        tree.nodes.remove(blackbody)
        group = bpy.data.node_groups.get("Glow") or _glow_group(bpy)
        node = tree.nodes.new("ShaderNodeGroup")
        node.node_tree = group
        node.inputs["Temperature"].default_value = temperature
        tree.links.new(node.outputs["Colour"], colour)


def _glow_group(bpy):
    group = bpy.data.node_groups.new("Glow", "ShaderNodeTree")
    group.interface.new_socket("Temperature", in_out="INPUT", socket_type="NodeSocketFloat")
    group.interface.new_socket("Colour", in_out="OUTPUT", socket_type="NodeSocketColor")
    group_in, group_out = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    blackbody = group.nodes.new("ShaderNodeBlackbody")
    group.links.new(group_in.outputs["Temperature"], blackbody.inputs["Temperature"])
    group.links.new(blackbody.outputs[0], group_out.inputs["Colour"])
    return group


def _colour_group(material):
    """The colour group in front of the material's emission: in its own tree, else in its group's."""
    trees = [material.node_tree] + [n.node_tree for n in material.node_tree.nodes if n.bl_idname == "ShaderNodeGroup"]
    return next(
        node
        for tree in trees
        for node in tree.nodes
        if node.bl_idname == "ShaderNodeGroup"
        and node.node_tree is not None
        and node.node_tree.name == "Relativity Doppler Colour"
    )


@pytest.mark.parametrize("variants", [VARIANTS, GROUPED_VARIANTS], ids=["traced", "grouped"])
def test_traced_blackbodies_seen_at_dt_on_the_mesh_path(relativity_addon, factory_blender, tmp_path, variants):
    """Top row approaching at D ~ 1.7, bottom row the same emitters at rest; one column per way
    of feeding the Emission. Each column: colour of the blackbody at D T (Delta E 2000 < 1) and
    luminance ratio Y(D T) / Y(T) within 2 %, as test_doppler_mesh_path's direct link."""
    bpy = factory_blender
    scene, camera = dh.emitter_scene(bpy)
    beta = dh.beta_for_doppler(math.sqrt(3.0))
    columns = {}
    for i, kind in enumerate(variants):
        x0 = -1.9 + 1.0 * i
        for row, (y_range, velocity) in enumerate((((0.15, 1.25), beta), ((-1.25, -0.15), (0.0, 0.0, 0.0)))):
            obj = dh.add_emitter_plane(bpy, scene, f"{kind}{row}", (x0, x0 + 0.8), y_range, beta=velocity)
            _feed_blackbody(bpy, obj.active_material, kind)
        columns[kind] = x0 + 0.4
    tinted = dh.add_emitter_plane(bpy, scene, "Tinted", (40.0, 41.0), (0.0, 1.0))  # out of view
    _feed_blackbody(bpy, tinted.active_material, "multiply", tint=(0.2, 0.5, 0.2))

    scene.relativity.method = "GEOMETRY"
    materials = dh.addon_module(relativity_addon, "colour.materials")
    materials.attach_scene(scene, camera_path=False)
    materials.write_settings(dh.addon_module(relativity_addon, "scene.snapshot").read(scene))
    for kind in variants:
        assert _colour_group(bpy.data.materials[f"{kind}0"]).inputs["Is Blackbody"].default_value == 1.0
    # a Mix with a non-grey colour is not a blackbody: the RGB path
    assert _colour_group(tinted.active_material).inputs["Is Blackbody"].default_value == 0.0

    image = dh.render(bpy, scene, tmp_path / "sources.exr")
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    d = dh.source_doppler_factor(dh.pixel_photon_directions(bpy, scene, camera), beta)
    model = ch.pinhole_model(bpy, scene, camera)

    def window(x, y):  # 4 x 4 pixels around the plane's centre
        col, row = np.round(model.project_direction((x, y, -dh.PLANE_DEPTH))).astype(int)
        return slice(row - 2, row + 2), slice(col - 2, col + 2)

    rest_luminance = {}
    for kind, x_centre in columns.items():
        moving, rest = window(x_centre, 0.7), window(x_centre, -0.7)
        rendered = image[moving].reshape(-1, 3).mean(0)
        d_mean = d[moving].mean()
        expected_xyz = dh.blackbody_xyz_colour_science(d_mean * TEMPERATURE)
        xyz = dh.linear_rec709_to_xyz(rendered)
        delta_e = dh.delta_e_2000_normalised(xyz, expected_xyz)
        rest_luminance[kind] = dh.linear_rec709_to_xyz(image[rest].reshape(-1, 3).mean(0))[1]
        ratio = xyz[1] / rest_luminance[kind]
        expected_ratio = expected_xyz[1] / dh.blackbody_xyz_colour_science(TEMPERATURE)[1]
        print(f"{kind}: D = {d_mean:.4f}, Delta E 2000 = {delta_e:.3f}, Y ratio {ratio:.4f} vs {expected_ratio:.4f}")
        assert delta_e < 1.0
        assert ratio == pytest.approx(expected_ratio, rel=0.02)
    # the multiply variant keeps its grey factor, the others the direct link's luminance
    for kind in variants:
        factor = GREY_FACTOR if kind == "multiply" else 1.0
        assert rest_luminance[kind] == pytest.approx(factor * rest_luminance["direct"], rel=1e-3)


def test_blackbody_world_seen_at_dt_by_moving_observer(factory_blender, tmp_path):
    """Nothing but a world whose Background colour is a Blackbody (through a reroute), exact
    camera at 0.5c: background pixels are the blackbody at D T with luminance Y(D T) / Y(T)."""
    bpy = factory_blender
    temperature = 4000.0
    scene, camera = dh.emitter_scene(bpy)
    tree = scene.world.node_tree
    background = tree.nodes["Background"]
    background.inputs["Strength"].default_value = 1.0
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = temperature
    reroute = tree.nodes.new("NodeReroute")
    tree.links.new(blackbody.outputs[0], reroute.inputs[0])
    tree.links.new(reroute.outputs[0], background.inputs["Color"])
    blend = ch.save_blend(bpy, tmp_path / "world.blend")
    rest = ch.render_image(bpy, blend, tmp_path / "rest.exr", "--beta=0,0,0", "--samples=4")
    beta = (0.3, 0.0, -0.5)
    image = ch.render_image(bpy, blend, tmp_path / "moving.exr", f"--beta={','.join(map(str, beta))}", "--samples=4")
    assert np.all(np.isfinite(image)) and image.min() >= 0.0

    view = -dh.pixel_photon_directions(bpy, scene, camera)  # D = 1 / (gamma (1 - beta . d'))
    beta_array = np.asarray(beta)
    d = 1.0 / ((1.0 - view @ beta_array) / math.sqrt(1.0 - beta_array @ beta_array))
    rest_y = dh.linear_rec709_to_xyz(rest[20:28, 28:36].reshape(-1, 3).mean(0))[1]
    worst = 0.0
    for rows, cols in ((slice(4, 8), slice(4, 8)), (slice(22, 26), slice(30, 34)), (slice(40, 44), slice(56, 60))):
        xyz = dh.linear_rec709_to_xyz(image[rows, cols].reshape(-1, 3).mean(0))
        d_mean = d[rows, cols].mean()
        expected_xyz = dh.blackbody_xyz_colour_science(d_mean * temperature)
        delta_e = dh.delta_e_2000_normalised(xyz, expected_xyz)
        ratio = xyz[1] / rest_y
        expected_ratio = expected_xyz[1] / dh.blackbody_xyz_colour_science(temperature)[1]
        print(f"world at D = {d_mean:.4f}: Delta E 2000 = {delta_e:.3f}, Y ratio {ratio:.4f} vs {expected_ratio:.4f}")
        worst = max(worst, delta_e)
        assert delta_e < 2.0
        assert ratio == pytest.approx(expected_ratio, rel=0.03)
    assert d.max() / d.min() > 1.3


def test_blackbody_world_attach_and_detach_restore_the_links(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, _ = dh.emitter_scene(bpy)
    tree = scene.world.node_tree
    background = tree.nodes["Background"]
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    tree.links.new(blackbody.outputs[0], background.inputs["Color"])
    before = sorted(node.name for node in tree.nodes)
    materials = dh.addon_module(relativity_addon, "colour.materials")
    materials.ensure_node_groups()
    assert materials.attach_world(scene.world)
    group = background.inputs["Color"].links[0].from_node
    assert group.node_tree.name == "Relativity Doppler Colour"
    assert group.inputs["Is Blackbody"].default_value == 1.0
    assert group.inputs["Temperature"].default_value == pytest.approx(blackbody.inputs["Temperature"].default_value)
    assert materials.detach_world(scene.world)
    assert sorted(node.name for node in tree.nodes) == before
    assert background.inputs["Color"].links[0].from_node == blackbody
