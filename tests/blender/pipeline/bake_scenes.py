"""The scene of the Apparent Geometry bake tests (issue 28, part 2): a 2 m box keyframed to cross
the view at 0.8c, seen by a camera at rest or flying at 0.6-0.9c, optionally with a lamp moving at
0.3c. Used by tests/blender/pipeline/test_bake_apparent_geometry.py and by the real-application
stage, which renders the baked file with Debian's plain Blender through the Flamenco job type."""

from pipeline_helpers import ch

FRAMES = (1, 2, 3)

FPS = 8.0  # one metre per frame at 0.8c: the box crosses a good part of the view in two frames
C = 10.0  # m/s
BOX_BETA = 0.8


def _mesh(bpy, scene, name, vertices, faces, material):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def _cube(bpy, scene, name, half, material):
    vertices = [(x * half, y * half, z * half) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return _mesh(bpy, scene, name, vertices, faces, material)


def _linear_keys(obj, path, keys):
    for frame, value in keys:
        setattr(obj, path, value)
        obj.keyframe_insert(path, frame=frame)
    for fcurve in ch.compat.action_fcurves(obj.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"


def build_moving_box(bpy, fly, moving_light=False, cruise=False):
    """Camera at 1.6 m looking along +Y (at rest, or speeds 0.6c, 0.75c, 0.9c over the frame steps;
    ``cruise``: 0.9c at every frame), floor, wall 14 m ahead, a 2 m box 8 m ahead keyframed along +X
    at 0.8c from frame -30 to 20 (linear), a point lamp at rest (and a lamp moving at 0.3c along -X),
    a grey world."""
    scene, camera = ch.new_scene(bpy, resolution=(64, 48), samples=32, location=(0.0, 0.0, 1.6))
    camera.rotation_euler = (1.5707963, 0.0, 0.0)
    camera.data.lens = 20.0
    scene.render.fps, scene.render.fps_base = int(FPS), 1.0
    scene.cycles.seed = 7
    scene.cycles.use_animated_seed = False
    world_tree = ch.compat.world_node_tree(scene.world)
    background = next(node for node in world_tree.nodes if node.type == "BACKGROUND")
    background.inputs["Color"].default_value = (0.2, 0.25, 0.3, 1.0)
    background.inputs["Strength"].default_value = 1.0
    grey = ch.diffuse_material(bpy, "Floor", (0.5, 0.5, 0.5))
    _mesh(bpy, scene, "Floor", [(-20, -5, 0), (20, -5, 0), (20, 40, 0), (-20, 40, 0)], [(0, 1, 2, 3)], grey)
    _mesh(bpy, scene, "Wall", [(-20, 14, 0), (20, 14, 0), (20, 14, 3), (-20, 14, 3)], [(0, 1, 2, 3)], grey)
    box = _cube(bpy, scene, "Box", 1.0, ch.diffuse_material(bpy, "Red", (0.8, 0.1, 0.1)))
    step = BOX_BETA * C / FPS  # metres per frame
    # x = (frame + 6) step: seen near the middle of the view at frames 1-3, about 6.5 frames later
    _linear_keys(box, "location", [(-30, (-24 * step, 8.0, 1.0)), (20, (26 * step, 8.0, 1.0))])
    box.relativity.enabled = True
    box.relativity.motion = "ANIMATION"
    light = bpy.data.lights.new("Lamp", "POINT")
    light.energy = 800.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = (-1.0, 6.0, 2.5)
    scene.collection.objects.link(lamp)
    settings = scene.relativity
    settings.speed_of_light = C
    settings.method = "GEOMETRY"
    if moving_light:
        moving = bpy.data.objects.new("Moving Lamp", bpy.data.lights.new("Moving Lamp", "POINT"))
        moving.data.energy = 300.0
        moving.location = (1.5, 5.0, 2.5)
        scene.collection.objects.link(moving)
        moving.relativity.enabled = True
        moving.relativity.motion = "CONSTANT"
        moving.relativity.beta = (-0.3, 0.0, 0.0)
    if fly:
        y, path = 0.0, [(1, (0.0, 0.0, 1.6))]
        for frame, speed in ((2, 0.6), (3, 0.75), (4, 0.9)):
            y += speed * C / FPS
            path.append((frame, (0.0, y, 1.6)))
        if cruise:  # linear keys around the frames: 0.9c at each of them
            path = [(frame, (0.0, 0.9 * C / FPS * (frame - 1), 1.6)) for frame in (-10, 10)]
            scene.cycles.samples = 128  # the beamed stand-in lamps' fireflies: the seed noise near the frames' change
        _linear_keys(camera, "location", path)
        settings.velocity_source = "CAMERA_ANIMATION"
        # the wall's edges subdivided in the moving camera's preview (not at rest): the bake keeps that
        scene.objects["Wall"].relativity.tessellation_tolerance = 0.3
    scene.frame_start, scene.frame_end = FRAMES[0], FRAMES[-1]
    scene.frame_set(FRAMES[0])
    return scene
