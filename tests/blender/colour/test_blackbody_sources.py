"""relativity_addon.blender.scene.sources on real node trees (bpy, no render): each tracing rule, with
the cases that must stay on the RGB path."""

import pytest

from relativity_addon.blender.common import compat
from relativity_addon.blender.scene import sources

T = 4200.0


def _material(bpy, name="Sources"):
    tree = compat.material_node_tree(bpy.data.materials.new(name))
    tree.nodes.clear()
    emission = tree.nodes.new("ShaderNodeEmission")
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    return tree, emission.inputs["Color"]


def _blackbody(tree, temperature=T):
    node = tree.nodes.new("ShaderNodeBlackbody")
    node.inputs["Temperature"].default_value = temperature
    return node.outputs["Color"]


def _mix(tree, blend="MIX", factor=0.5, legacy=False):
    """(node, factor input, A, B, output) of a colour mix."""
    if legacy:
        node = tree.nodes.new("ShaderNodeMixRGB")
        node.blend_type = blend
        node.inputs["Fac"].default_value = factor
        return node, node.inputs["Fac"], node.inputs["Color1"], node.inputs["Color2"], node.outputs[0]
    node = tree.nodes.new("ShaderNodeMix")
    node.data_type = "RGBA"
    node.blend_type = blend
    inputs = {socket.identifier: socket for socket in node.inputs}
    inputs["Factor_Float"].default_value = factor
    result = next(socket for socket in node.outputs if socket.identifier == "Result_Color")
    return node, inputs["Factor_Float"], inputs["A_Color"], inputs["B_Color"], result


def test_direct_and_unlinked(factory_blender):
    tree, colour = _material(factory_blender)
    assert sources.blackbody_source(colour) is None  # a constant colour
    tree.links.new(_blackbody(tree), colour)
    assert sources.blackbody_source(colour) == sources.Blackbody(T, 1.0)


def test_reroutes_and_muted_links(factory_blender):
    tree, colour = _material(factory_blender)
    first, second = tree.nodes.new("NodeReroute"), tree.nodes.new("NodeReroute")
    tree.links.new(_blackbody(tree), first.inputs[0])
    tree.links.new(first.outputs[0], second.inputs[0])
    link = tree.links.new(second.outputs[0], colour)
    assert sources.blackbody_source(colour) == sources.Blackbody(T, 1.0)
    link.is_muted = True
    assert sources.blackbody_source(colour) is None


def test_linked_temperature_is_the_feeding_socket_and_value_nodes_are_constants(factory_blender):
    tree, colour = _material(factory_blender)
    blackbody = _blackbody(tree)
    tree.links.new(blackbody, colour)
    value = tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = 3000.0
    tree.links.new(value.outputs[0], blackbody.node.inputs["Temperature"])
    assert sources.blackbody_source(colour) == sources.Blackbody(3000.0, 1.0)
    attribute = tree.nodes.new("ShaderNodeAttribute")
    tree.links.new(attribute.outputs["Fac"], blackbody.node.inputs["Temperature"])
    found = sources.blackbody_source(colour)
    assert found.temperature == attribute.outputs["Fac"]


@pytest.mark.parametrize("legacy", [False, True], ids=["mix", "mixrgb"])
def test_mix_rules(factory_blender, legacy):
    tree, colour = _material(factory_blender)
    node, factor, a, b, out = _mix(tree, "MULTIPLY", 1.0, legacy)
    tree.links.new(out, colour)
    tree.links.new(_blackbody(tree), a)
    b.default_value = (0.25, 0.25, 0.25, 1.0)
    assert sources.blackbody_source(colour) == sources.Blackbody(T, 0.25)
    factor.default_value = 0.5  # A (1 - f + f B): still a blackbody
    assert sources.blackbody_source(colour) == pytest.approx(sources.Blackbody(T, 0.625))
    b.default_value = (0.25, 0.5, 0.25, 1.0)  # tinted: not a blackbody any more
    assert sources.blackbody_source(colour) is None

    # the blackbody on side B: only a factor of exactly 1 makes it A * B
    tree.links.remove(a.links[0])
    tree.links.new(_blackbody(tree), b)
    a.default_value = (2.0, 2.0, 2.0, 1.0)
    factor.default_value = 1.0
    assert sources.blackbody_source(colour) == sources.Blackbody(T, 2.0)
    factor.default_value = 0.5
    assert sources.blackbody_source(colour) is None

    node.blend_type = "MIX"  # B is the blackbody, A a grey: f = 1 picks B, f = 0 picks A
    factor.default_value = 1.0
    assert sources.blackbody_source(colour) == sources.Blackbody(T, 1.0)
    factor.default_value = 0.0
    assert sources.blackbody_source(colour) is None
    factor.default_value = 0.3
    assert sources.blackbody_source(colour) is None  # a grey plus a blackbody
    tree.links.new(_blackbody(tree), a)  # both sides the same temperature
    assert sources.blackbody_source(colour) == pytest.approx(sources.Blackbody(T, 1.0))
    tree.links.new(_blackbody(tree, 5000.0), a)  # two temperatures
    assert sources.blackbody_source(colour) is None

    node.blend_type = "ADD"
    tree.links.new(_blackbody(tree), a)
    assert sources.blackbody_source(colour) is None  # no rule for other blends


def test_mix_clamping_and_varying_factor(factory_blender):
    tree, colour = _material(factory_blender)
    node, factor, a, b, out = _mix(tree, "MULTIPLY", 1.0)
    tree.links.new(out, colour)
    tree.links.new(_blackbody(tree), a)
    b.default_value = (0.5, 0.5, 0.5, 1.0)
    texture = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(texture.outputs["Fac"], factor)
    node.clamp_factor = True
    assert sources.blackbody_source(colour) == sources.Blackbody(T, None)  # scale varies, stays >= 0
    node.clamp_factor = False
    assert sources.blackbody_source(colour) is None  # f outside [0, 1] can make it negative
    node.clamp_factor = True
    node.clamp_result = True
    assert sources.blackbody_source(colour) is None  # clamping changes a bright blackbody's colour
    node.clamp_result = False
    node.data_type = "VECTOR"
    assert sources.blackbody_source(colour) is None


def test_vector_scale(factory_blender):
    tree, colour = _material(factory_blender)
    scale = tree.nodes.new("ShaderNodeVectorMath")
    scale.operation = "SCALE"
    tree.links.new(_blackbody(tree), scale.inputs[0])
    tree.links.new(scale.outputs["Vector"], colour)
    scale.inputs["Scale"].default_value = 3.0
    assert sources.blackbody_source(colour) == sources.Blackbody(T, 3.0)
    scale.inputs["Scale"].default_value = -1.0
    assert sources.blackbody_source(colour) is None
    scale.operation = "ADD"
    assert sources.blackbody_source(colour) is None


def _group(bpy, blackbody_inside=True):
    """A shader group with a colour output: a Blackbody inside, or one fed from the group input."""
    group = bpy.data.node_groups.new("Glow", "ShaderNodeTree")
    group.interface.new_socket("Temperature", in_out="INPUT", socket_type="NodeSocketFloat")
    group.interface.new_socket("Colour In", in_out="INPUT", socket_type="NodeSocketColor")
    group.interface.new_socket("Colour", in_out="OUTPUT", socket_type="NodeSocketColor")
    group_in, group_out = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    if blackbody_inside:
        blackbody = _blackbody(group)
        group.links.new(group_in.outputs["Temperature"], blackbody.node.inputs["Temperature"])
        group.links.new(blackbody, group_out.inputs["Colour"])
    else:
        group.links.new(group_in.outputs["Colour In"], group_out.inputs["Colour"])
    return group


def test_groups_in_and_out(factory_blender):
    bpy = factory_blender
    tree, colour = _material(bpy)
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = _group(bpy)
    tree.links.new(node.outputs["Colour"], colour)
    node.inputs["Temperature"].default_value = 2500.0
    assert sources.blackbody_source(colour) == sources.Blackbody(2500.0, 1.0)  # T from outside
    attribute = tree.nodes.new("ShaderNodeAttribute")
    tree.links.new(attribute.outputs["Fac"], node.inputs["Temperature"])
    assert sources.blackbody_source(colour).temperature == attribute.outputs["Fac"]

    # a temperature computed inside the group cannot be linked from the material's tree
    inner_blackbody = next(n for n in node.node_tree.nodes if n.bl_idname == "ShaderNodeBlackbody")
    inner_attribute = node.node_tree.nodes.new("ShaderNodeAttribute")
    node.node_tree.links.new(inner_attribute.outputs["Fac"], inner_blackbody.inputs["Temperature"])
    assert sources.blackbody_source(colour) is None

    # a pass-through group: the Blackbody is outside, fed in through the group input
    through = tree.nodes.new("ShaderNodeGroup")
    through.node_tree = _group(bpy, blackbody_inside=False)
    tree.links.new(through.outputs["Colour"], colour)
    assert sources.blackbody_source(colour) is None  # its input is an unlinked colour
    tree.links.new(_blackbody(tree), through.inputs["Colour In"])
    assert sources.blackbody_source(colour) == sources.Blackbody(T, 1.0)


def test_lights(factory_blender):
    bpy = factory_blender
    light = bpy.data.lights.new("Lamp", "POINT")
    light.use_temperature = False
    assert sources.light_blackbody(light) is None
    light.use_temperature = True
    light.temperature = 3200.0
    assert sources.light_blackbody(light) == pytest.approx(3200.0)
    light.color = (1.0, 0.5, 0.5)
    assert sources.light_blackbody(light) is None  # tinted
    light.color = (1.0, 1.0, 1.0)

    if light.node_tree is None:
        light.use_nodes = True  # 4.5 (5.x: lights always have a node tree and use it)
    tree = compat.light_node_tree(light)
    emission = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeEmission")
    assert sources.light_blackbody(light) == pytest.approx(3200.0)  # the default grey emission
    emission.inputs["Color"].default_value = (0.2, 0.4, 1.0, 1.0)
    assert sources.light_blackbody(light) is None
    tree.links.new(_blackbody(tree, 1800.0), emission.inputs["Color"])
    assert sources.light_blackbody(light) is None  # two blackbodies multiplied
    light.use_temperature = False
    assert sources.light_blackbody(light) == pytest.approx(1800.0)

    scene = bpy.context.scene
    obj = bpy.data.objects.new("Lamp", light)
    scene.collection.objects.link(obj)
    scene.collection.objects.link(bpy.data.objects.new("Plain", bpy.data.lights.new("Plain", "SUN")))
    assert sources.scene_blackbody_lights(scene) == {"Lamp": pytest.approx(1800.0)}


def test_principled_volume(factory_blender):
    bpy = factory_blender
    tree, _ = _material(bpy)
    volume = tree.nodes.new("ShaderNodeVolumePrincipled")
    volume.inputs["Blackbody Intensity"].default_value = 0.0
    assert sources.volume_blackbody(volume) is None
    volume.inputs["Blackbody Intensity"].default_value = 1.0
    volume.inputs["Temperature"].default_value = 1500.0
    assert sources.volume_blackbody(volume) == sources.Blackbody(1500.0, None)
    volume.inputs["Blackbody Tint"].default_value = (1.0, 0.5, 1.0, 1.0)
    assert sources.volume_blackbody(volume) is None
    # its Emission Color follows the ordinary rules
    tree.links.new(_blackbody(tree), volume.inputs["Emission Color"])
    assert sources.blackbody_source(volume.inputs["Emission Color"]) == sources.Blackbody(T, 1.0)
