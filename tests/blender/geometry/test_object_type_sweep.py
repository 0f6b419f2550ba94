"""Every object type Blender puts in a scene, given its own velocity (``relativity.enabled``, motion
Constant, 0.3 c sideways), on both methods: each is moved (meshes, measured against the
retarded-position relation of docs/physics.md), accepted (lights: the moving-light stage), or named
in Set Up's refusal, which leaves nothing in the file. Set Up never succeeds with an unhandled one.
"""

import numpy as np
import pytest

import geometry_helpers as gh

BETA = (0.3, 0.0, 0.0)
C = 4.0  # scene units per second (slow light: the light delay is large)


def _link(bpy, scene, name, data):
    obj = bpy.data.objects.new(name, data)
    scene.collection.objects.link(obj)
    obj.location = (0.0, 1.0, -6.0)
    return obj


def _cube_mesh(bpy, name, size=0.5):
    mesh = bpy.data.meshes.new(name)
    s = size
    vertices = [(x, y, z) for x in (-s, s) for y in (-s, s) for z in (-s, s)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    return mesh


def _instance_group(bpy):
    """A geometry-nodes group: its mesh, plus a cube instanced on each of its points."""
    group = bpy.data.node_groups.new("Instancer", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = group.nodes, group.links
    given, out = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    cube = nodes.new("GeometryNodeMeshCube")
    cube.inputs["Size"].default_value = (0.1, 0.1, 0.1)
    instance = nodes.new("GeometryNodeInstanceOnPoints")
    join = nodes.new("GeometryNodeJoinGeometry")
    links.new(given.outputs[0], instance.inputs["Points"])
    links.new(cube.outputs["Mesh"], instance.inputs["Instance"])
    links.new(given.outputs[0], join.inputs[0])
    links.new(instance.outputs["Instances"], join.inputs[0])
    links.new(join.outputs[0], out.inputs[0])
    return group


def _make(bpy, scene, kind):
    """One object of ``kind`` in ``scene``; None where this Blender cannot make it from bpy.data."""
    data = bpy.data
    if kind in ("CURVE", "SURFACE", "FONT"):
        curve = data.curves.new(kind.lower(), "CURVE" if kind == "CURVE" else kind)
        if kind == "CURVE":
            spline = curve.splines.new("POLY")
            spline.points.add(1)
            curve.bevel_depth = 0.1
        elif kind == "SURFACE":
            spline = curve.splines.new("NURBS")
            spline.points.add(15)
            for i, point in enumerate(spline.points):
                point.co = (i % 4 * 0.3, i // 4 * 0.3, 0.0, 1.0)
            spline.use_endpoint_u = spline.use_endpoint_v = True
            spline.order_u = spline.order_v = 2
        else:
            curve.body = "Hi"
        return _link(bpy, scene, kind.title(), curve)
    if kind == "META":
        meta = data.metaballs.new("Meta")
        meta.elements.new()
        return _link(bpy, scene, "Meta", meta)
    if kind == "POINTCLOUD":
        collection = getattr(data, "pointclouds", None)
        return None if collection is None else _link(bpy, scene, "Points", collection.new("Points"))
    if kind == "VOLUME":
        return _link(bpy, scene, "Volume", data.volumes.new("Volume"))
    if kind == "GREASEPENCIL":
        for attribute in ("grease_pencils_v3", "grease_pencils"):
            collection = getattr(data, attribute, None)
            if collection is not None:
                return _link(bpy, scene, "Pencil", collection.new("Pencil"))
        return None
    if kind == "CURVES":
        collection = getattr(data, "hair_curves", None)
        return None if collection is None else _link(bpy, scene, "Hair", collection.new("Hair"))
    if kind == "EMPTY":
        return _link(bpy, scene, "Empty", None)
    if kind == "COLLECTION_INSTANCE":
        collection = data.collections.new("Kept")
        collection.objects.link(data.objects.new("Kept cube", _cube_mesh(bpy, "Kept cube")))
        obj = _link(bpy, scene, "Instancer", None)
        obj.instance_type, obj.instance_collection = "COLLECTION", collection
        return obj
    if kind == "CAMERA":
        return _link(bpy, scene, "Other camera", data.cameras.new("Other camera"))
    if kind == "SPEAKER":
        return _link(bpy, scene, "Speaker", data.speakers.new("Speaker"))
    if kind == "LIGHT_PROBE":
        for probe_type in ("SPHERE", "CUBE"):
            try:
                return _link(bpy, scene, "Probe", data.lightprobes.new("Probe", probe_type))
            except TypeError:
                continue
        return None
    if kind == "ARMATURE":
        return _link(bpy, scene, "Armature", data.armatures.new("Armature"))
    if kind == "LATTICE":
        return _link(bpy, scene, "Lattice", data.lattices.new("Lattice"))
    if kind == "LIGHT":
        return _link(bpy, scene, "Lamp", data.lights.new("Lamp", "POINT"))
    if kind == "PARTICLES":
        obj = _link(bpy, scene, "Emitter", _cube_mesh(bpy, "Emitter"))
        obj.modifiers.new("Particles", "PARTICLE_SYSTEM")
        settings = obj.particle_systems[0].settings
        settings.count, settings.frame_start, settings.render_type = 4, -10, "OBJECT"
        settings.instance_object = data.objects.new("Grain", _cube_mesh(bpy, "Grain", 0.05))
        return obj
    if kind == "VERTEX_INSTANCES":
        obj = _link(bpy, scene, "Dupli", _cube_mesh(bpy, "Dupli"))
        child = _link(bpy, scene, "Dupli child", _cube_mesh(bpy, "Dupli child", 0.05))
        child.parent, child.relativity.enabled = obj, False
        obj.instance_type = "VERTS"
        return obj
    if kind == "NODE_INSTANCES":
        obj = _link(bpy, scene, "Scatter", _cube_mesh(bpy, "Scatter"))
        obj.modifiers.new("Instancer", "NODES").node_group = _instance_group(bpy)
        return obj
    raise AssertionError(kind)


NOT_MESHES = (
    "CURVE",
    "SURFACE",
    "FONT",
    "META",
    "POINTCLOUD",
    "VOLUME",
    "GREASEPENCIL",
    "CURVES",
    "EMPTY",
    "COLLECTION_INSTANCE",
    "CAMERA",
    "SPEAKER",
    "LIGHT_PROBE",
    "ARMATURE",
    "LATTICE",
)
MESH_INSTANCERS = ("PARTICLES", "VERTEX_INSTANCES", "NODE_INSTANCES")


def _scene(bpy):
    scene, camera = gh.slow_light_scene(bpy, C, 24)
    return scene, camera


def _give_velocity(obj):
    obj.relativity.enabled = True
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = BETA


def _refused(bpy, scene, method, name, read_refuses=True):
    """Set Up (the operator) on ``method`` fails naming ``name``, and the file is as before; so does
    the snapshot read by the batch script and every sync (F12), unless ``read_refuses`` is False
    (geometry-nodes instances are found on the evaluated scene by Set Up only)."""
    scene.relativity.method = method
    bpy.context.view_layer.update()  # matrix_world of the new objects, evaluated as Set Up evaluates
    before = gh.file_fingerprint(bpy)
    with pytest.raises(RuntimeError) as raised:
        bpy.ops.relativity.setup_scene()
    message = str(raised.value)
    assert repr(name) in message, message
    assert "\n" not in message.strip().removeprefix("Error: ").strip(), message
    assert gh.file_fingerprint(bpy) == before
    assert not gh.addon_module("pipeline.effect").is_applied(scene)
    if not read_refuses:
        return message
    snapshot = gh.addon_module("scene.snapshot")
    with pytest.raises(gh.addon_module("pipeline.effect").RelativityError, match=repr(name).replace("(", r"\(")):
        snapshot.read(scene)  # what the batch script and F12's sync read
    return message


@pytest.mark.parametrize("kind", NOT_MESHES + MESH_INSTANCERS)
def test_unmovable_object_with_velocity_is_refused_on_both_methods(relativity_addon, factory_blender, kind):
    bpy = factory_blender
    scene, _ = _scene(bpy)
    obj = _make(bpy, scene, kind)
    if obj is None:
        pytest.skip(f"this Blender makes no {kind} from bpy.data")
    _give_velocity(obj)
    mover = _link(bpy, scene, "Mover", _cube_mesh(bpy, "Mover"))  # a movable mesh beside it
    _give_velocity(mover)
    geometry = _refused(bpy, scene, "GEOMETRY", obj.name, read_refuses=kind != "NODE_INSTANCES")
    print(f"{kind}: GEOMETRY: {geometry}")
    camera = _refused(bpy, scene, "CAMERA", obj.name)
    print(f"{kind}: CAMERA: {camera}")
    assert "'Mover'" in camera  # the exact camera names every moving object


@pytest.mark.parametrize("kind", NOT_MESHES + MESH_INSTANCERS)
def test_object_without_velocity_is_accepted(relativity_addon, factory_blender, kind):
    """The same objects at rest (motion Static) do not stop Set Up: only their velocity is refused."""
    bpy = factory_blender
    scene, _ = _scene(bpy)
    obj = _make(bpy, scene, kind)
    if obj is None:
        pytest.skip(f"this Blender makes no {kind} from bpy.data")
    for method in ("GEOMETRY", "CAMERA"):
        scene.relativity.method = method
        assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
        gh.remove_effect(scene)  # (Apparent Geometry with no mesh applies nothing to remove)


def test_moving_light_is_accepted_on_both_methods(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, _ = _scene(bpy)
    lamp = _make(bpy, scene, "LIGHT")
    _give_velocity(lamp)
    for method in ("GEOMETRY", "CAMERA"):
        scene.relativity.method = method
        assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
        snap = gh.addon_module("pipeline.effect").last_snapshot(scene)
        assert [light.name for light in snap.moving_lights] == ["Lamp"]
        gh.remove_effect(scene)


def test_moving_mesh_is_at_its_retarded_position(relativity_addon, factory_blender):
    """Apparent Geometry moves a mesh with its own velocity: each evaluated vertex x_a is where the
    mesh was at the retarded time t_e = t_o - |x_a - x_o| / c (docs/physics.md; observer at rest at
    the origin), the mesh Lorentz-contracted along beta about its origin and moving with beta c."""
    bpy = factory_blender
    scene, camera = _scene(bpy)
    scene.frame_set(12)
    obj = _link(bpy, scene, "Mover", _cube_mesh(bpy, "Mover"))
    obj.relativity.tessellation = 0
    rest = np.array([v.co for v in obj.data.vertices])
    _give_velocity(obj)
    scene.relativity.method = "GEOMETRY"
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    x_a, _ = gh.evaluated_points(bpy, obj)
    matrix = np.array(obj.matrix_world)
    x_o = np.array(camera.matrix_world.translation)
    t_delay = np.linalg.norm(x_a - x_o, axis=1) / C  # t_o - t_e
    beta = np.array(BETA)
    x_e = matrix[:3, 3] + gh.contract(rest @ matrix[:3, :3].T, beta) - beta[None] * C * t_delay[:, None]
    residual, mismatch = gh.retarded_residuals(x_a, x_e, x_o)
    shift = np.mean(x_a[:, 0] - (rest @ matrix[:3, :3].T + matrix[:3, 3])[:, 0])
    print(
        f"mesh: mean x shift {shift:.4f} units, max light-cone residual {residual.max():.2e}, "
        f"max mismatch {mismatch.max():.2e}"
    )
    assert shift < -0.3 * 6.0 * 0.9  # seen where it was about |x|/c earlier: beta c |x| / c = 0.3 |x|
    assert residual.max() < 1e-5 and mismatch.max() < 1e-5


def test_exact_camera_refuses_a_moving_mesh_naming_it(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, _ = _scene(bpy)
    obj = _link(bpy, scene, "Sphere", _cube_mesh(bpy, "Sphere"))
    _give_velocity(obj)
    message = _refused(bpy, scene, "CAMERA", "Sphere")
    assert "Apparent Geometry" in message
    # at rest, a disabled object or an animated one is judged by its settings the same way
    obj.relativity.beta = (0.0, 0.0, 0.0)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    obj.relativity.motion = "ANIMATION"
    _refused(bpy, scene, "CAMERA", "Sphere")


def test_mesh_without_vertices_is_skipped_with_a_warning(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, _ = _scene(bpy)
    empty = _link(bpy, scene, "Nothing", bpy.data.meshes.new("Nothing"))
    _give_velocity(empty)
    mover = _link(bpy, scene, "Mover", _cube_mesh(bpy, "Mover"))
    _give_velocity(mover)
    scene.relativity.method = "GEOMETRY"
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    effect = gh.addon_module("pipeline.effect")
    modifier = gh.addon_module("geometry.modifier")
    assert modifier.find_modifier(mover) is not None and modifier.find_modifier(empty) is None
    warnings = effect.scene_warnings(scene)
    assert any("'Nothing'" in warning and "no vertices" in warning for warning in warnings), warnings
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert not any("'Nothing'" in warning for warning in effect.scene_warnings(scene))


def test_render_script_refuses_a_moving_mesh_on_the_exact_camera(relativity_addon, factory_blender, tmp_path):
    """``examples/render.py`` on an Exact Camera file with a mesh given 0.3 c: it exits non-zero
    naming the mesh, and writes no image (it used to render the mesh at rest and exit 0)."""
    bpy = factory_blender
    scene, _ = _scene(bpy)
    obj = _link(bpy, scene, "Sphere", _cube_mesh(bpy, "Sphere"))
    _give_velocity(obj)
    scene.relativity.method = "CAMERA"
    blend = gh.ch.save_blend(bpy, tmp_path / "moving.blend")
    out = tmp_path / "out.png"
    result = gh.ch.run_render_script(blend, out, "--resolution=64x48", check=False)
    print(f"render.py exit {result.returncode}: {result.stderr.strip().splitlines()[-1:]}")
    assert result.returncode != 0
    assert "'Sphere' has its own velocity" in result.stderr + result.stdout
    assert not out.exists()
