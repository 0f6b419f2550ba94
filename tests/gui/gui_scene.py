"""The scene the real-application stage renders, built the same way in Debian's Blender (by the
driver, ``gui_driver.py``) and in the ``bpy`` wheel (the reference render): bpy only, nothing of
the tests or the add-on, so both sides build exactly this.

A camera at the origin looking down -Z (50 mm lens on a 36 mm sensor), a black world, one
emissive sphere off-axis ("Mover") with its own velocity, and the observer moving forward.
"""

WIDTH, HEIGHT = 160, 120
SAMPLES = 16
STRENGTH = 0.04  # the moving sphere stays below 1 (no clipping) with its Doppler shift and searchlight
FOCAL_MM, SENSOR_MM = 50.0, 36.0
SPHERE_CENTRE = (1.0, 0.5, -5.0)
SPHERE_RADIUS = 0.5
OBSERVER_BETA = (0.0, 0.0, -0.6)
SPHERE_BETA = (0.3, 0.0, 0.0)


def rest_pixel():
    """Where the sphere's centre is at rest (pinhole projection; x right, y down, pixel centres at
    +0.5): computed from the scene's numbers, not by the add-on."""
    x, y, z = SPHERE_CENTRE
    scale = FOCAL_MM / SENSOR_MM * WIDTH  # pixels per unit of x / -z (sensor fit: width)
    return WIDTH / 2 + scale * x / -z, HEIGHT / 2 - scale * y / -z


def _node_tree(datablock):
    if datablock.node_tree is None:  # 4.5's new materials and worlds; 5.2 always has a tree
        datablock.use_nodes = True
    return datablock.node_tree


def build(bpy, method="GEOMETRY", final_render="EXACT", moving_sphere=True):
    """Empty the current scene and build the test scene in it, every Relativity setting at its
    default but those named here; returns (scene, camera, sphere)."""
    import bmesh

    scene = bpy.context.scene
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = SAMPLES
    scene.cycles.preview_samples = SAMPLES
    scene.cycles.use_denoising = False
    scene.cycles.use_preview_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.seed = 1
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    world = bpy.data.worlds.new("Black")
    world.color = (0.0, 0.0, 0.0)
    _node_tree(world).nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    data = bpy.data.cameras.new("Camera")
    data.lens, data.sensor_width, data.sensor_fit = FOCAL_MM, SENSOR_MM, "AUTO"
    data.clip_start, data.clip_end = 0.001, 1000.0
    camera = bpy.data.objects.new("Camera", data)
    scene.collection.objects.link(camera)
    scene.camera = camera

    material = bpy.data.materials.new("Glow")
    tree = _node_tree(material)
    tree.nodes.clear()
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (1.0, 0.6, 0.3, 1.0)
    emission.inputs["Strength"].default_value = STRENGTH
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    mesh = bpy.data.meshes.new("Mover")
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=SPHERE_RADIUS)
    bm.to_mesh(mesh)
    bm.free()
    for polygon in mesh.polygons:
        polygon.use_smooth = True
    mesh.materials.append(material)
    sphere = bpy.data.objects.new("Mover", mesh)
    sphere.location = SPHERE_CENTRE
    scene.collection.objects.link(sphere)

    for name in scene.relativity.bl_rna.properties.keys():
        if name != "rna_type":
            scene.relativity.property_unset(name)
    scene.relativity.method = method
    scene.relativity.geometry_final_render = final_render
    scene.relativity.beta = OBSERVER_BETA
    sphere.relativity.enabled = True
    if moving_sphere:
        sphere.relativity.motion = "CONSTANT"
        sphere.relativity.beta = SPHERE_BETA
    bpy.context.view_layer.update()
    return scene, camera, sphere
