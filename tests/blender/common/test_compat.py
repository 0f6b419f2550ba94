"""relativity_addon.blender.common.compat on the running Blender (each supported line runs this file)."""

import pytest

from relativity_addon.blender.common import compat


def _nodes_modifier(bpy):
    group = bpy.data.node_groups.new("Compat Group", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    cache = group.interface.new_socket("Cache", in_out="INPUT", socket_type="NodeSocketObject")
    count = group.interface.new_socket("Count", in_out="INPUT", socket_type="NodeSocketInt")
    group.links.new(group.nodes.new("NodeGroupInput").outputs[0], group.nodes.new("NodeGroupOutput").inputs[0])
    obj = bpy.data.objects.new("Carrier", bpy.data.meshes.new("Carrier"))
    bpy.context.scene.collection.objects.link(obj)
    modifier = obj.modifiers.new("Compat", "NODES")
    modifier.node_group = group
    return modifier, cache.identifier, count.identifier


def test_modifier_inputs_read_and_write(factory_blender):
    bpy = factory_blender
    modifier, cache_id, count_id = _nodes_modifier(bpy)
    target = bpy.data.objects.new("Target", None)
    assert compat.modifier_input(modifier, cache_id) is None
    compat.set_modifier_input(modifier, cache_id, target)
    compat.set_modifier_input(modifier, count_id, 7)
    assert compat.modifier_input(modifier, cache_id) == target
    assert compat.modifier_input(modifier, count_id) == 7
    # Blender sees the value: the object is used by the modifier (one more user than before).
    users = target.users
    compat.set_modifier_input(modifier, cache_id, None)
    assert target.users == users - 1
    assert compat.modifier_input(modifier, cache_id) is None


def test_action_fcurves_of_the_assigned_slot(factory_blender):
    bpy = factory_blender
    obj = bpy.data.objects.new("Moving", None)
    bpy.context.scene.collection.objects.link(obj)
    assert tuple(compat.action_fcurves(obj.animation_data)) == ()
    obj.location = (0.0, 0.0, 0.0)
    obj.keyframe_insert("location", frame=1)
    obj.location = (3.0, 0.0, 0.0)
    obj.keyframe_insert("location", frame=11)
    curves = {(f.data_path, f.array_index): f for f in compat.action_fcurves(obj.animation_data)}
    assert set(curves) == {("location", 0), ("location", 1), ("location", 2)}
    assert curves["location", 0].evaluate(11) == pytest.approx(3.0)
    assert compat.action_channelbag(obj.animation_data).fcurves[0] == curves["location", 0]
    # Another object with its own action sees only its own curves.
    other = bpy.data.objects.new("Other", None)
    bpy.context.scene.collection.objects.link(other)
    other.keyframe_insert("scale", frame=1)
    assert {f.data_path for f in compat.action_fcurves(other.animation_data)} == {"scale"}


def test_world_and_material_node_trees(factory_blender):
    import warnings

    bpy = factory_blender
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no deprecation warning (use_nodes is deprecated in 5.x)
        world = bpy.data.worlds.new("World")
        tree = compat.world_node_tree(world)
        material = bpy.data.materials.new("Material")
        material_tree = compat.material_node_tree(material)
    assert tree is world.node_tree and "Background" in tree.nodes
    assert material_tree is material.node_tree and "Material Output" in material_tree.nodes
    assert compat.world_node_tree(world) is tree  # a second call keeps the tree


def test_eevee_engine_is_accepted(factory_blender):
    scene = factory_blender.context.scene
    scene.render.engine = compat.eevee_engine()
    assert scene.render.engine == compat.eevee_engine()


def test_compositor_tree(factory_blender):
    bpy = factory_blender
    scene = bpy.context.scene
    assert compat.compositor_tree(scene) is None
    if compat.has_compositor_node_groups():
        tree = bpy.data.node_groups.new("Compositing", "CompositorNodeTree")
        scene.compositing_node_group = tree
    else:
        scene.use_nodes = True
        tree = scene.node_tree
    assert compat.compositor_tree(scene) == tree


def test_render_layers_diffuse_colour(factory_blender):
    """The Diffuse Color pass's Render Layers output, named differently in 4.5 and 5.x."""
    bpy = factory_blender
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    tree = compat.new_compositor_tree(scene, "Compositing")
    layers = next((node for node in tree.nodes if node.bl_idname == "CompositorNodeRLayers"), None)
    layers = layers or tree.nodes.new("CompositorNodeRLayers")
    assert compat.render_layers_diffuse_colour(layers) is None
    scene.view_layers[0].use_pass_diffuse_color = True
    layers.update()
    output = compat.render_layers_diffuse_colour(layers)
    assert output is not None and output.name in ("Diffuse Color", "DiffCol")


def test_map_uv_nearest_settings_are_accepted(factory_blender):
    bpy = factory_blender
    tree = bpy.data.node_groups.new("Compat Compositing", "CompositorNodeTree")
    node = tree.nodes.new("CompositorNodeMapUV")
    inputs, props = compat.map_uv_nearest()
    assert inputs or props
    for name, value in inputs.items():
        node.inputs[name].default_value = value
        assert node.inputs[name].default_value == value
    for name, value in props.items():
        setattr(node, name, value)
        assert getattr(node, name) == value


def test_custom_property_keys_are_the_users_only(relativity_addon, factory_blender):
    scene = factory_blender.context.scene
    scene.relativity.beta = (0.0, 0.5, 0.0)  # stored in an ID property on 4.5, apart on 5.x
    scene["user_key"] = 1
    assert compat.custom_property_keys(scene) == ["user_key"]


def test_light_node_tree(factory_blender):
    bpy = factory_blender
    light = bpy.data.lights.new("Lamp", "POINT")
    if light.node_tree is None:  # 4.5: a tree only once use_nodes is switched on, used while it is
        assert compat.light_node_tree(light) is None
        light.use_nodes = True
        assert compat.light_node_tree(light) == light.node_tree
        light.use_nodes = False
        assert compat.light_node_tree(light) is None
    else:  # 5.x: always there and used
        assert compat.light_node_tree(light) == light.node_tree


def test_compositor_output_and_alpha_over_inputs(factory_blender, tmp_path):
    """The output node of a new compositor tree is fed (by its Render Layers node; 4.5 through a
    Reroute); Alpha Over's
    ``(background, foreground)``: an opaque green foreground over red gives green (swapped: red)."""
    bpy = factory_blender
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.render.resolution_x = scene.render.resolution_y = 4
    scene.render.resolution_percentage = 100
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    tree = compat.new_compositor_tree(scene, "Compat Compositing")
    output = compat.compositor_output(tree)
    assert output is not None and output.inputs[0].is_linked
    over = tree.nodes.new("CompositorNodeAlphaOver")
    background, foreground = compat.alpha_over_inputs(over)
    for socket, colour in ((background, (1.0, 0.0, 0.0, 1.0)), (foreground, (0.0, 1.0, 0.0, 1.0))):
        rgb = tree.nodes.new("CompositorNodeRGB")
        rgb.outputs[0].default_value = colour
        tree.links.new(rgb.outputs[0], socket)
    tree.links.new(over.outputs[0], output.inputs[0])
    scene.render.use_compositing = True
    scene.render.filepath = str(tmp_path / "over.exr")
    scene.render.use_file_extension = False
    scene.render.image_settings.file_format = "OPEN_EXR"
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(str(tmp_path / "over.exr"))
    red, green = image.pixels[0], image.pixels[1]
    assert green > 0.9 and red < 0.1


def test_volume_ray_marching(factory_blender):
    """5.x chooses between null scattering (default) and ray marching; 4.5 only ray-marches."""
    bpy = factory_blender
    scene = bpy.context.scene
    before = compat.volume_ray_marching(scene)
    if hasattr(scene.cycles, "volume_biased"):
        assert before is False
        compat.set_volume_ray_marching(scene, True)
        assert scene.cycles.volume_biased and compat.volume_ray_marching(scene) is True
        compat.set_volume_ray_marching(scene, before)
        assert not scene.cycles.volume_biased
    else:
        assert before is None
        compat.set_volume_ray_marching(scene, True)  # nothing to set
        assert compat.volume_ray_marching(scene) is None
