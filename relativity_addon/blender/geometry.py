"""Apparent geometry of moving objects: a geometry-nodes modifier fed by a per-object cache.

Route (DESIGN-NOTES.md, "Feeding Python-computed positions to geometry nodes"):

1. The add-on's modifier (node group ``Relativity Apparent Geometry``) subdivides the mesh, stores
   the tessellated rest positions in the point attribute ``relativity_rest``, then sets the
   positions sampled by index from a cache mesh object, but only when the point counts match.
2. ``update_object`` reads ``relativity_rest`` from the *evaluated* mesh (stored before Set
   Position, so the output never feeds back), computes apparent positions with numpy
   (``physics/apparent.py``) and writes them, with the point velocities relative to the observer
   (attribute ``relativity_beta``, for the Doppler shaders), into the cache mesh.
3. A persistent ``frame_change_post`` handler does that for every frame, and a
   ``depsgraph_update_post`` handler whenever an input (observer velocity, c, camera or object
   transform, object settings) changed: the result depends only on the scene state at the frame.

The cache object is not linked into any scene; the modifier holds the only user, so it is saved
with the .blend and a render farm worker needs nothing else. Removing the effect removes the
modifier, the cache and (when unused) the node group: the original mesh data is never written.

Frames: the scene frame is the observer's frame S only when ``scene.relativity.beta`` is zero.
The mesh path renders in the camera's frame (axes parallel to world): an object at rest in the
scene appears moving with ``-beta``.

Motion sources (``Object.relativity.motion``): STATIC; CONSTANT (the mesh is the rest-frame
shape, Lorentz-contracted along ``beta`` about the object origin; closed-form retarded times);
ANIMATION (rigid: world matrices on a sub-frame grid, per-vertex retarded times), from the keyframes
of the object and its object-parent chain (deltas included; ``animation.world_matrices``, float64,
no ``frame_set``) or, when the object has one, from a motion bake (:func:`bake_motion`: world
matrices sampled through the depsgraph, so constraints, drivers, NLA and any parent count). An
object whose keyframes are not its motion (``animation.keyframe_motion_problem``) and that has no
motion bake is refused with an error naming the fix. ANIMATION with ``use_deformation``: evaluated
vertex positions baked by :func:`bake_deformation`. Bakes step frames and so run outside handlers.

API: :func:`apply_apparent_geometry`, :func:`remove_apparent_geometry`, :func:`update_object`,
:func:`update_scene`, :func:`bake_deformation`, :func:`bake_motion`, :func:`applied_objects`,
:func:`scene_errors`, operators ``relativity.bake_deformation`` and ``relativity.bake_motion``.
Errors are ``RelativityError`` with a one-line message.
"""

import math

import bpy
import numpy as np
from bpy.app.handlers import persistent

from ..physics import apparent
from . import camera as camera_module
from . import animation, compat, compositing, materials
from .camera import RelativityError

NODE_GROUP_NAME = "Relativity Apparent Geometry"
MODIFIER_NAME = "Relativity Apparent Geometry"
REST_ATTRIBUTE = "relativity_rest"
BETA_ATTRIBUTE = "relativity_beta"
CACHE_PREFIX = "RelativityCache"
SIGNATURE_KEY = "relativity_signature"
ERROR_KEY = "relativity_error"  # on the cache mesh: why the last handler update failed
OWNER_KEY = "relativity_owner"  # on the cache mesh: the name of the object it serves
# The node group's interface: (name, socket type, in/out). Builder and modifier use these names.
INTERFACE = (
    ("Geometry", "NodeSocketGeometry", "INPUT"),
    ("Tessellation", "NodeSocketInt", "INPUT"),
    ("Cache", "NodeSocketObject", "INPUT"),
    ("Geometry", "NodeSocketGeometry", "OUTPUT"),
)
# Bump when the tree below changes: an older group in a file is rebuilt.
NODE_GROUP_VERSION = 1


# --- node group ------------------------------------------------------------------------------

# Declarative description of the tree: nodes (key, type, properties, input defaults) and links
# ((from key, output socket), (to key, input socket)). Socket names pick the first available one.
_NODES = (
    ("input", "NodeGroupInput", {}, {}),
    ("output", "NodeGroupOutput", {}, {}),
    ("subdivide", "GeometryNodeSubdivideMesh", {}, {}),
    ("position", "GeometryNodeInputPosition", {}, {}),
    ("store_rest", "GeometryNodeStoreNamedAttribute",
     {"data_type": "FLOAT_VECTOR", "domain": "POINT"}, {"Name": REST_ATTRIBUTE}),
    ("cache_info", "GeometryNodeObjectInfo", {"transform_space": "ORIGINAL"}, {}),
    ("cache_size", "GeometryNodeAttributeDomainSize", {"component": "MESH"}, {}),
    ("mesh_size", "GeometryNodeAttributeDomainSize", {"component": "MESH"}, {}),
    ("counts_match", "FunctionNodeCompare", {"data_type": "INT", "operation": "EQUAL"}, {}),
    ("index", "GeometryNodeInputIndex", {}, {}),
    ("sample_position", "GeometryNodeSampleIndex", {"data_type": "FLOAT_VECTOR", "domain": "POINT"}, {}),
    ("cache_beta", "GeometryNodeInputNamedAttribute", {"data_type": "FLOAT_VECTOR"}, {"Name": BETA_ATTRIBUTE}),
    ("sample_beta", "GeometryNodeSampleIndex", {"data_type": "FLOAT_VECTOR", "domain": "POINT"}, {}),
    ("set_position", "GeometryNodeSetPosition", {}, {}),
    ("store_beta", "GeometryNodeStoreNamedAttribute",
     {"data_type": "FLOAT_VECTOR", "domain": "POINT"}, {"Name": BETA_ATTRIBUTE}),
)
_LINKS = (
    (("input", "Geometry"), ("subdivide", "Mesh")),
    (("input", "Tessellation"), ("subdivide", "Level")),
    (("subdivide", "Mesh"), ("store_rest", "Geometry")),
    (("position", "Position"), ("store_rest", "Value")),
    (("input", "Cache"), ("cache_info", "Object")),
    (("cache_info", "Geometry"), ("cache_size", "Geometry")),
    (("store_rest", "Geometry"), ("mesh_size", "Geometry")),
    (("cache_size", "Point Count"), ("counts_match", "A")),
    (("mesh_size", "Point Count"), ("counts_match", "B")),
    (("cache_info", "Geometry"), ("sample_position", "Geometry")),
    (("position", "Position"), ("sample_position", "Value")),
    (("index", "Index"), ("sample_position", "Index")),
    (("cache_info", "Geometry"), ("sample_beta", "Geometry")),
    (("cache_beta", "Attribute"), ("sample_beta", "Value")),
    (("index", "Index"), ("sample_beta", "Index")),
    (("store_rest", "Geometry"), ("set_position", "Geometry")),
    (("counts_match", "Result"), ("set_position", "Selection")),
    (("sample_position", "Value"), ("set_position", "Position")),
    (("set_position", "Geometry"), ("store_beta", "Geometry")),
    (("counts_match", "Result"), ("store_beta", "Selection")),
    (("sample_beta", "Value"), ("store_beta", "Value")),
    (("store_beta", "Geometry"), ("output", "Geometry")),
)


def _socket(sockets, name):
    for socket in sockets:
        if socket.name == name and getattr(socket, "enabled", True) and not getattr(socket, "is_unavailable", False):
            return socket
    raise KeyError(f"no available socket {name!r}")


def build_node_group():
    """The add-on's node group, built from ``_NODES``/``_LINKS`` (rebuilt if outdated)."""
    group = bpy.data.node_groups.get(NODE_GROUP_NAME)
    if group is not None and group.get("relativity_version") == NODE_GROUP_VERSION:
        return group
    if group is None:
        group = bpy.data.node_groups.new(NODE_GROUP_NAME, "GeometryNodeTree")
    group.nodes.clear()
    group.interface.clear()
    for name, socket_type, in_out in INTERFACE:
        socket = group.interface.new_socket(name, in_out=in_out, socket_type=socket_type)
        if name == "Tessellation":
            socket.min_value, socket.max_value, socket.default_value = 0, 6, 1
    nodes = {}
    for column, (key, node_type, properties, defaults) in enumerate(_NODES):
        node = group.nodes.new(node_type)
        node.name = node.label = key
        node.location = (200.0 * column, 0.0)
        for attribute, value in properties.items():
            setattr(node, attribute, value)
        for socket_name, value in defaults.items():
            _socket(node.inputs, socket_name).default_value = value
        nodes[key] = node
    for (from_key, from_name), (to_key, to_name) in _LINKS:
        group.links.new(_socket(nodes[from_key].outputs, from_name), _socket(nodes[to_key].inputs, to_name))
    group["relativity_version"] = NODE_GROUP_VERSION
    return group


def _input_identifier(group, name):
    for item in group.interface.items_tree:
        if item.item_type == "SOCKET" and item.in_out == "INPUT" and item.name == name:
            return item.identifier
    raise KeyError(name)


# --- modifier and cache ----------------------------------------------------------------------


def find_modifier(obj):
    for modifier in obj.modifiers:
        if modifier.type == "NODES" and modifier.node_group is not None and modifier.node_group.name == NODE_GROUP_NAME:
            return modifier
    return None


def cache_object(obj):
    modifier = find_modifier(obj)
    if modifier is None:
        return None
    return compat.modifier_input(modifier, _input_identifier(modifier.node_group, "Cache"))


def _ensure_modifier(obj):
    group = build_node_group()
    modifier = find_modifier(obj)
    if modifier is None:
        modifier = obj.modifiers.new(MODIFIER_NAME, "NODES")
        modifier.node_group = group
    cache = cache_object(obj)
    if cache is not None and _shared_with_another_object(obj, cache):
        cache = None  # a duplicated object copied the modifier and its cache pointer: own one
    if cache is None:
        mesh = bpy.data.meshes.new(f"{CACHE_PREFIX} {obj.name}")
        cache = bpy.data.objects.new(f"{CACHE_PREFIX} {obj.name}", mesh)
        compat.set_modifier_input(modifier, _input_identifier(group, "Cache"), cache)
    if cache.data.get(OWNER_KEY) != obj.name:
        cache.data[OWNER_KEY] = obj.name  # set on creation, and follows a rename
    identifier = _input_identifier(group, "Tessellation")
    if compat.modifier_input(modifier, identifier) != int(obj.relativity.tessellation):
        compat.set_modifier_input(modifier, identifier, int(obj.relativity.tessellation))
    return modifier, cache


def _shared_with_another_object(obj, cache):
    """True if ``cache`` belongs to another object (its recorded owner) that still uses it."""
    owner = bpy.data.objects.get(cache.data.get(OWNER_KEY, "")) if cache.data is not None else None
    return owner is not None and owner != obj and cache_object(owner) == cache


def applied_objects(scene):
    return [obj for obj in scene.objects if obj.type == "MESH" and find_modifier(obj) is not None]


def _remove_object_effect(obj):
    modifier = find_modifier(obj)
    if modifier is None:
        return False
    cache = cache_object(obj)
    baked = bake_mesh(obj)
    if cache is not None and _shared_with_another_object(obj, cache):
        cache = baked = None  # the owner keeps them
    obj.modifiers.remove(modifier)
    if baked is not None:
        bpy.data.meshes.remove(baked)
    if cache is not None:
        mesh = cache.data
        bpy.data.objects.remove(cache)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
    return True


# --- inputs ----------------------------------------------------------------------------------


def _finite_velocity(beta, what):
    beta = tuple(float(b) for b in beta)
    if not all(math.isfinite(b) for b in beta):
        raise RelativityError(f"{what} is not a finite vector")
    speed = math.sqrt(sum(b * b for b in beta))
    if speed >= 1.0:
        raise RelativityError(f"{what}: speed |beta| = {speed:.6g} must be below 1 (the speed of light)")
    return np.array(beta)


def _evaluated(obj, depsgraph):
    """The object as evaluated for the frame being computed. Blender's animation render does not
    write transforms back to the original objects, so their matrix_world may be stale there."""
    return obj.evaluated_get(depsgraph) if depsgraph is not None else obj


def observer_event(scene, depsgraph=None):
    """(t_o seconds, camera world position, observer beta, c) from the scene; RelativityError if invalid."""
    settings = scene.relativity
    c = float(settings.speed_of_light)
    if not (math.isfinite(c) and c > 0.0):
        raise RelativityError("speed of light must be a positive finite number")
    beta = _finite_velocity(settings.beta, "observer velocity beta")
    camera = scene.camera
    if camera is None:
        raise RelativityError(f"scene {scene.name!r} has no active camera")
    fps = scene.render.fps / scene.render.fps_base
    t_o = (scene.frame_current + scene.frame_subframe) / fps
    return t_o, np.array(_evaluated(camera, depsgraph).matrix_world.translation, dtype=np.float64), beta, c


def _matrix_array(matrix):
    return np.array([list(row) for row in matrix], dtype=np.float64)


def _evaluated_rest_positions(obj, depsgraph):
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        attribute = mesh.attributes.get(REST_ATTRIBUTE)
        if attribute is None:
            return None
        rest = np.empty(len(attribute.data) * 3, dtype=np.float32)
        attribute.data.foreach_get("vector", rest)
    finally:
        obj_eval.to_mesh_clear()
    return rest.reshape(-1, 3).astype(np.float64)


def _to_world(matrix, points):
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def animated_apparent_positions(obj, scene, rest_local, t_o, x_o, beta_o, c, max_tries=4, obj_eval=None):
    """Apparent world positions and beta of an ANIMATION object (rigid motion): from its baked
    world matrices when it has a motion bake, else from its keyframes under its parent chain
    (:func:`animation.world_matrices`). An object whose keyframes are not its motion
    (constraints, transform drivers, NLA, ...) and that has no bake raises RelativityError."""
    fps = scene.render.fps / scene.render.fps_base
    obj_eval = obj if obj_eval is None else obj_eval
    bake = motion_bake(obj)
    if bake is not None:
        return _baked_apparent_positions(obj, bake, obj_eval, rest_local, fps, t_o, x_o, beta_o, c)
    problem = animation.keyframe_motion_problem(obj, scene)
    if problem is not None:
        raise RelativityError(
            f"object {obj.name!r} is moved by more than its keyframes ({problem}): "
            "bake its motion (Bake Motion in the Relativity panel)")
    samples_per_frame = int(obj.relativity.samples_per_frame)
    step = 1.0 / (samples_per_frame * fps)
    world_now = _to_world(_matrix_array(obj_eval.matrix_world), rest_local)
    reach = float(np.max(np.linalg.norm(world_now - world_now.mean(0), axis=1))) if len(world_now) else 0.0
    centre_tau = float(np.linalg.norm(x_o - world_now.mean(0))) / c if len(world_now) else 0.0
    low, high = t_o - centre_tau - 2.0 * reach / c - 2 * step, t_o - centre_tau + 2.0 * reach / c + 2 * step
    for _ in range(max_tries):
        low_index, high_index = math.floor(low / step) - 2, math.ceil(high / step) + 2
        if high_index - low_index > 200000:
            raise RelativityError(f"object {obj.name!r}: light-travel times span too many animation samples")
        times = np.arange(low_index, high_index + 1) * step
        motion = apparent.SampledRigidMotion(times, animation.world_matrices(obj, times * fps), rest_local)
        result = apparent.apparent_positions_sampled(motion, t_o, x_o, c, beta_o)
        t_e = t_o - result[1]
        if t_e.size == 0 or (t_e.min() >= times[1] and t_e.max() <= times[-2]):
            return result
        margin = 4 * step
        low, high = min(low, t_e.min() - margin), max(high, t_e.max() + margin)
    raise RelativityError(f"object {obj.name!r}: retarded times did not settle inside the sampled animation")


def _baked_apparent_positions(obj, bake, obj_eval, rest_local, fps, t_o, x_o, beta_o, c):
    first_frame, per_frame, matrices = bake
    frame_now = t_o * fps
    index = (frame_now - first_frame) * per_frame
    if abs(index - round(index)) < 1e-6 and 0 <= round(index) < len(matrices):
        # The bake holds this very frame: if the object is elsewhere now, the bake is stale.
        now = _matrix_array(obj_eval.matrix_world)
        if np.max(np.abs(matrices[round(index)] - now)) > 1e-5 * (1.0 + np.max(np.abs(now))):
            raise RelativityError(
                f"object {obj.name!r} moves differently from its motion bake at frame {frame_now:g}: "
                "bake its motion again")
    start, step = first_frame / fps, 1.0 / (per_frame * fps)
    times = start + step * np.arange(len(matrices))
    result = apparent.apparent_positions_sampled(apparent.SampledRigidMotion(times, matrices, rest_local),
                                                 t_o, x_o, c, beta_o)
    t_e = t_o - result[1]
    if t_e.size and (t_e.min() < times[0] or t_e.max() > times[-1]):
        raise RelativityError(
            f"object {obj.name!r}: retarded times {t_e.min():.4g}..{t_e.max():.4g} s lie outside the "
            f"baked motion {times[0]:.4g}..{times[-1]:.4g} s; bake a wider frame range")
    return result


BAKE_PREFIX = "RelativityBake"
BAKE_KEY = "relativity_bake"  # on the cache mesh: name of the bake mesh and its time grid
MOTION_BAKE_KEY = "relativity_motion_bake"  # on the cache mesh: baked world matrices and their frames


def bake_mesh(obj):
    cache = cache_object(obj)
    if cache is None or cache.data is None or BAKE_KEY not in cache.data:
        return None
    return bpy.data.meshes.get(cache.data[BAKE_KEY]["mesh"])


def motion_bake(obj):
    """``(first frame, samples per frame, matrices (K, 4, 4) float64)`` of the object's motion
    bake, or None."""
    cache = cache_object(obj)
    if cache is None or cache.data is None or MOTION_BAKE_KEY not in cache.data:
        return None
    info = cache.data[MOTION_BAKE_KEY]
    matrices = np.array(info["matrices"], dtype=np.float64).reshape(-1, 4, 4)
    return float(info["first_frame"]), int(info["samples_per_frame"]), matrices


def _bake_frames(scene, obj, frame_start, frame_end):
    """Sample frames for a bake of ``obj``: ``frame_start`` to ``frame_end`` (default: the scene's
    range, starting earlier by twice the current light-travel time to the farthest vertex) at
    ``relativity.samples_per_frame`` per frame."""
    fps = scene.render.fps / scene.render.fps_base
    first = scene.frame_start if frame_start is None else frame_start
    last = scene.frame_end if frame_end is None else frame_end
    if frame_start is None:
        # Light seen at the first frame left up to ~2 d / c earlier (d: camera to farthest vertex now).
        with _Computing():
            depsgraph = bpy.context.evaluated_depsgraph_get()
            rest = _evaluated_rest_positions(obj, depsgraph)
        _, x_o, _, c = observer_event(scene, depsgraph)
        if rest is not None and len(rest):
            world = _to_world(_matrix_array(obj.evaluated_get(depsgraph).matrix_world), rest)
            first -= math.ceil(2.0 * float(np.max(np.linalg.norm(world - x_o, axis=1))) / c * fps) + 2
    per_frame = int(obj.relativity.samples_per_frame)
    frames = first + np.arange(int(round((last - first) * per_frame)) + 1) / per_frame
    if len(frames) < 2:
        raise RelativityError(f"object {obj.name!r}: bake range needs at least two samples")
    return frames, per_frame


def _sample_frames(scene, frames, sample):
    """Call ``sample(depsgraph)`` at each of ``frames`` (scene.frame_set, sub-frames included),
    with the handlers held off and Blender's progress indicator showing; the scene's frame is
    restored."""
    saved_frame, saved_subframe = scene.frame_current, scene.frame_subframe
    window_manager = bpy.context.window_manager
    window_manager.progress_begin(0, len(frames))
    with _Computing():
        try:
            for done, frame in enumerate(frames):
                whole = int(np.floor(frame))
                scene.frame_set(whole, subframe=float(frame - whole))
                sample(bpy.context.evaluated_depsgraph_get())
                window_manager.progress_update(done + 1)
        finally:
            scene.frame_set(saved_frame, subframe=saved_subframe)
            window_manager.progress_end()


def bake_deformation(scene, obj, frame_start=None, frame_end=None):
    """Sample the evaluated (tessellated, deformed) world positions of ``obj`` from ``frame_start``
    to ``frame_end`` (default: the scene's range, starting earlier by twice the current
    light-travel time to the farthest vertex) at ``relativity.samples_per_frame`` sub-frames, for
    per-vertex retarded times of a deforming mesh. Steps the scene through the frames (frame_set),
    so it runs outside handlers; the scene's frame is restored. The samples live in a mesh
    datablock kept with the .blend (fake user) and are removed with the effect. Returns the number
    of samples.
    """
    modifier, cache = _ensure_modifier(obj)
    fps = scene.render.fps / scene.render.fps_base
    frames, per_frame = _bake_frames(scene, obj, frame_start, frame_end)

    def sample(depsgraph):
        rest = _evaluated_rest_positions(obj, depsgraph)
        if rest is None or (samples and len(rest) != len(samples[0])):
            raise RelativityError(f"object {obj.name!r}: vertex count changes during the bake range")
        samples.append(_to_world(_matrix_array(obj.evaluated_get(depsgraph).matrix_world), rest))

    samples = []
    _sample_frames(scene, frames, sample)
    mesh = bake_mesh(obj)
    if mesh is None:
        mesh = bpy.data.meshes.new(f"{BAKE_PREFIX} {obj.name}")
        mesh.use_fake_user = True
    mesh.clear_geometry()
    count = len(samples[0])
    mesh.vertices.add(count)
    for i, positions in enumerate(samples):
        attribute = mesh.attributes.new(f"sample_{i:05d}", "FLOAT_VECTOR", "POINT")
        attribute.data.foreach_set("vector", positions.astype(np.float32).ravel())
    cache.data[BAKE_KEY] = {"mesh": mesh.name, "start": float(frames[0] / fps), "step": 1.0 / (per_frame * fps),
                            "samples": len(samples), "points": count}
    with _Computing():
        update_object(scene, obj)
    return len(samples)


def bake_motion(scene, obj, frame_start=None, frame_end=None):
    """Sample the world matrix of ``obj`` as Blender evaluates it (depsgraph: constraints, drivers,
    NLA, parents of any type, simulations) from ``frame_start`` to ``frame_end`` (default as
    :func:`bake_deformation`) at ``relativity.samples_per_frame`` sub-frames, for the rigid
    ANIMATION path. Steps the scene through the frames, so it runs outside handlers; the scene's
    frame is restored. The matrices (float64) are stored on the cache mesh, so they are saved with
    the .blend and removed with the effect. Returns the number of samples.
    """
    modifier, cache = _ensure_modifier(obj)
    frames, per_frame = _bake_frames(scene, obj, frame_start, frame_end)
    # Only the transform is sampled: the modifier (tessellation, cache lookup) need not run.
    shown = modifier.show_viewport
    modifier.show_viewport = False
    matrices = []
    try:
        _sample_frames(scene, frames, lambda depsgraph: matrices.append(
            _matrix_array(obj.evaluated_get(depsgraph).matrix_world)))
    finally:
        modifier.show_viewport = shown
    cache.data[MOTION_BAKE_KEY] = {"first_frame": float(frames[0]), "samples_per_frame": per_frame,
                                   "matrices": np.ravel(matrices).tolist()}
    with _Computing():
        update_object(scene, obj)
    return len(matrices)


def deformed_apparent_positions(obj, count, t_o, x_o, beta_o, c):
    """Apparent positions of a deforming object from its baked samples (per-vertex retarded times)."""
    cache = cache_object(obj)
    mesh = bake_mesh(obj)
    if mesh is None:
        raise RelativityError(f"object {obj.name!r} is deforming but not baked: run bake_deformation first")
    info = cache.data[BAKE_KEY]
    if info["points"] != count:
        raise RelativityError(f"object {obj.name!r}: the mesh changed since the deformation bake; bake again")
    positions = np.empty((info["samples"], count * 3), dtype=np.float32)
    for i in range(info["samples"]):
        mesh.attributes[f"sample_{i:05d}"].data.foreach_get("vector", positions[i])
    times = info["start"] + info["step"] * np.arange(info["samples"])
    motion = apparent.SampledPointMotion(times, positions.reshape(info["samples"], count, 3).astype(np.float64))
    result = apparent.apparent_positions(motion.positions, t_o, x_o, c, count, beta_o, velocity=motion.velocities)
    t_e = t_o - result[1]
    if t_e.min() < times[0] or t_e.max() > times[-1]:
        raise RelativityError(
            f"object {obj.name!r}: retarded times {t_e.min():.4g}..{t_e.max():.4g} s lie outside the "
            f"baked range {times[0]:.4g}..{times[-1]:.4g} s; bake a wider frame range")
    return result


def object_signature(scene, obj, depsgraph=None):
    settings, relativity = scene.relativity, obj.relativity
    camera = _evaluated(scene.camera, depsgraph) if scene.camera is not None else None
    parts = [
        scene.frame_current, scene.frame_subframe, settings.speed_of_light, tuple(settings.beta),
        camera.name if camera else "", tuple(map(tuple, camera.matrix_world)) if camera else (),
        tuple(map(tuple, _evaluated(obj, depsgraph).matrix_world)), relativity.enabled, relativity.motion, tuple(relativity.beta),
        relativity.tessellation, relativity.samples_per_frame, scene.render.fps, scene.render.fps_base,
        relativity.use_deformation,
        len(obj.data.vertices),
    ]
    return repr(parts)


def update_object(scene, obj, depsgraph=None):
    """Recompute the cache of one object for the scene's current frame. Raises RelativityError."""
    modifier, cache = _ensure_modifier(obj)
    enabled = bool(obj.relativity.enabled)
    if modifier.show_viewport != enabled or modifier.show_render != enabled:
        modifier.show_viewport = modifier.show_render = enabled
    if depsgraph is None:
        depsgraph = bpy.context.evaluated_depsgraph_get()
    rest = _evaluated_rest_positions(obj, depsgraph)
    if rest is None:
        raise RelativityError(f"object {obj.name!r}: evaluated mesh has no {REST_ATTRIBUTE!r} attribute")
    t_o, x_o, beta_o, c = observer_event(scene, depsgraph)
    obj_eval = obj.evaluated_get(depsgraph)
    try:
        world, beta_seen = _apparent_world_positions(scene, obj, obj_eval, rest, t_o, x_o, beta_o, c)
    except ValueError as error:  # the physics core's checks (superluminal motion, NaN)
        raise RelativityError(f"object {obj.name!r}: {error}") from None
    inverse = np.linalg.inv(_matrix_array(obj_eval.matrix_world))
    # On coordinate rows (3, N): numpy multiplies the transposed views without copying them.
    local = (inverse[:3, :3] @ world.T + inverse[:3, 3:]).T
    _write_cache(cache.data, local, beta_seen)
    cache.data[SIGNATURE_KEY] = object_signature(scene, obj, depsgraph)
    if ERROR_KEY in cache.data:
        del cache.data[ERROR_KEY]
    obj.update_tag()
    return len(local)


def _apparent_world_positions(scene, obj, obj_eval, rest, t_o, x_o, beta_o, c):
    matrix_now = _matrix_array(obj_eval.matrix_world)
    motion = obj.relativity.motion
    if motion == "ANIMATION" and obj.relativity.use_deformation:
        world, _, beta_seen = deformed_apparent_positions(obj, len(rest), t_o, x_o, beta_o, c)
    elif motion == "ANIMATION":
        world, _, beta_seen = animated_apparent_positions(obj, scene, rest, t_o, x_o, beta_o, c, obj_eval=obj_eval)
    else:
        beta_u = _finite_velocity(obj.relativity.beta, f"object {obj.name!r} velocity") if motion == "CONSTANT" else np.zeros(3)
        # The mesh is the object's rest-frame shape: in the scene it is contracted along its motion
        # about the object's origin (folded into the object matrix: one affine map per vertex).
        contracted = apparent.lorentz_contraction_matrix(beta_u) @ matrix_now[:3, :3]
        # Built as coordinate rows (3, N), the layout the closed form works on: no copy there.
        world_now = (contracted @ rest.T + matrix_now[:3, 3:]).T
        world, _, beta_seen = apparent.apparent_positions_uniform(t_o, x_o, world_now, beta_u, c, beta_o)
        beta_seen = beta_seen[:1]  # one velocity for every vertex
    return world, beta_seen


def _write_cache(mesh, positions, beta):
    """Object-space positions ``(N, 3)`` and observer-frame velocities ``beta`` (``(N, 3)``, or
    ``(1, 3)`` shared by every point) into the cache mesh."""
    count = len(positions)
    if len(mesh.vertices) != count:
        mesh.clear_geometry()
        mesh.vertices.add(count)
    # The attribute API copies the float32 buffer in one go; vertices.foreach_set("co") was
    # measured 150x slower (70 ms for a million vertices).
    mesh.attributes["position"].data.foreach_set("vector", np.ascontiguousarray(positions, dtype=np.float32).ravel())
    attribute = mesh.attributes.get(BETA_ATTRIBUTE)
    if attribute is None:
        attribute = mesh.attributes.new(BETA_ATTRIBUTE, "FLOAT_VECTOR", "POINT")
    values = np.empty((count, 3), dtype=np.float32)
    if len(beta) == 1:
        # A shared velocity (constant motion) is usually the one stored at the previous update:
        # reading and comparing costs a fraction of writing. The outcome depends on the data only.
        attribute.data.foreach_get("vector", values.ravel())
        shared = np.asarray(beta[0], dtype=np.float32)
        unchanged = all((values[:, k] == shared[k]).all() for k in range(3))
    else:
        unchanged = False
    if not unchanged:
        values[:] = beta
        attribute.data.foreach_set("vector", values.ravel())
    mesh.update()


def update_object_if_applied(scene, obj):
    """Property-update entry point: never raises (the viewport keeps the last valid state)."""
    if obj.type != "MESH" or find_modifier(obj) is None or _Computing.depth:
        return
    try:
        with _Computing():
            update_object(scene, obj)
    except RelativityError as error:
        print(f"Relativity: {error}")


class _Computing:
    """Re-entrancy guard: evaluating the depsgraph inside our own update fires the depsgraph
    handlers again, and a nested evaluation from a handler crashes Blender."""

    depth = 0

    def __enter__(self):
        _Computing.depth += 1

    def __exit__(self, *exc):
        _Computing.depth -= 1


def update_scene(scene, depsgraph=None, only_changed=False):
    """Recompute every object carrying the modifier. Returns the number of objects updated."""
    with _Computing():
        return _update_scene(scene, depsgraph, only_changed)


def _update_scene(scene, depsgraph, only_changed):
    updated = 0
    if applied_objects(scene):
        materials.sync_settings(scene, camera_path=False)
    for obj in applied_objects(scene):
        cache = cache_object(obj)
        if only_changed and cache is not None and cache.data is not None and \
                cache.data.get(SIGNATURE_KEY) == object_signature(scene, obj, depsgraph):
            continue
        update_object(scene, obj, depsgraph)
        updated += 1
    return updated


# --- public API ------------------------------------------------------------------------------


def apply_apparent_geometry(scene, objects=None):
    """Add the apparent-geometry modifier to ``objects`` (default: every mesh of the scene whose
    ``relativity.enabled`` is on) and compute the current frame. Returns the objects.

    Raises RelativityError (one line) if the scene or an object's settings are invalid; nothing
    is changed in that case.
    """
    observer_event(scene)
    if objects is None:
        objects = [obj for obj in scene.objects if obj.type == "MESH" and obj.relativity.enabled]
    for obj in objects:
        if obj.relativity.motion == "CONSTANT":
            _finite_velocity(obj.relativity.beta, f"object {obj.name!r} velocity")
    try:
        with _Computing():
            for obj in objects:
                _ensure_modifier(obj)
            depsgraph = bpy.context.evaluated_depsgraph_get()
            for obj in objects:
                update_object(scene, obj, depsgraph)
        _apply_doppler_colour(scene)
    except RelativityError:
        for obj in objects:
            _remove_object_effect(obj)
        _remove_unused_group()
        raise
    return list(objects)


def _apply_doppler_colour(scene):
    """Searchlight and Doppler colour in the materials, from each point's ``relativity_beta``."""
    try:
        materials.apply_doppler_colour(scene, camera_path=False)
    except (ImportError, ValueError, KeyError, RuntimeError) as error:
        _remove_doppler_colour(scene)
        message = str(error).strip().splitlines()
        raise RelativityError(
            f"Doppler colour could not be set up: {type(error).__name__}: {message[-1] if message else ''}"
        ) from error


def _remove_doppler_colour(scene):
    camera = scene.camera
    if camera is not None and camera.type == "CAMERA" and camera_module.is_applied(camera.data):
        return  # the exact camera's colour stage owns the materials now
    materials.remove_doppler_colour(scene)
    compositing.remove_unused_data()


def _remove_unused_group():
    group = bpy.data.node_groups.get(NODE_GROUP_NAME)
    if group is not None and group.users == 0:
        bpy.data.node_groups.remove(group)


def remove_apparent_geometry(scene, objects=None):
    """Remove the modifier, the caches and (if unused) the node group. Returns objects restored."""
    objects = applied_objects(scene) if objects is None else objects
    restored = [obj for obj in objects if _remove_object_effect(obj)]
    _remove_unused_group()
    if not applied_objects(scene):
        _remove_doppler_colour(scene)
    return restored


# --- handlers --------------------------------------------------------------------------------


def object_error(obj):
    """The one-line error of the object's last handler update, or None."""
    cache = cache_object(obj) if find_modifier(obj) is not None else None
    if cache is not None and cache.data is not None and cache.data.get(ERROR_KEY):
        return cache.data[ERROR_KEY]
    return None


def scene_errors(scene):
    """One-line errors of the last update of each object (empty when every cache is current)."""
    return [error for error in map(object_error, applied_objects(scene)) if error is not None]


def _update_scene_reporting(scene, depsgraph, only_changed):
    """Handler body: update each object, recording a failure on its cache instead of raising."""
    with _Computing():
        for obj in applied_objects(scene):
            cache = cache_object(obj)
            if only_changed and cache is not None and cache.data is not None and \
                    cache.data.get(SIGNATURE_KEY) == object_signature(scene, obj, depsgraph):
                continue
            try:
                update_object(scene, obj, depsgraph)
            except RelativityError as error:
                print(f"Relativity: {error}")
                cache = cache_object(obj)
                if cache is not None and cache.data is not None:
                    cache.data[ERROR_KEY] = str(error)
                    cache.data[SIGNATURE_KEY] = object_signature(scene, obj, depsgraph)


@persistent
def _frame_change_post(scene, depsgraph=None):
    if _Computing.depth:
        return
    _update_scene_reporting(scene, depsgraph, only_changed=False)


@persistent
def _depsgraph_update_post(scene, depsgraph=None):
    """Recompute objects whose inputs changed (observer velocity, camera, transforms): the
    signature stored with each cache stops the loop that writing the cache would start."""
    if _Computing.depth:
        return
    _update_scene_reporting(scene, depsgraph, only_changed=True)


def _poll_mesh(cls, context):
    obj = context.active_object
    if obj is None or obj.type != "MESH" or context.scene is None or not hasattr(context.scene, "relativity"):
        cls.poll_message_set("Select a mesh object")
        return False
    return True


class _BakeOperator:
    """Shared execute of the bake operators: set the object's motion, bake, report."""

    bl_options = {"REGISTER", "UNDO"}
    use_deformation = False
    baked = "samples"

    def execute(self, context):
        scene, obj = context.scene, context.active_object
        if self.use_deformation:
            obj.relativity.use_deformation = True
        obj.relativity.motion = "ANIMATION"
        try:
            count = self.bake(scene, obj)
        except RelativityError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Baked {count} {self.baked} of {obj.name!r}")
        return {"FINISHED"}


class RELATIVITY_OT_bake_deformation(_BakeOperator, bpy.types.Operator):
    """Sample the active object's deformed vertex positions over the scene's frame range, so each
    vertex can be shown at its own retarded time"""

    bl_idname = "relativity.bake_deformation"
    bl_label = "Bake Deformation"
    use_deformation = True
    bake = staticmethod(bake_deformation)

    @classmethod
    def poll(cls, context):
        return _poll_mesh(cls, context)


class RELATIVITY_OT_bake_motion(_BakeOperator, bpy.types.Operator):
    """Sample the active object's world transform over the scene's frame range as Blender evaluates
    it (constraints, drivers, NLA, parents), so its motion can be shown at each vertex's retarded
    time"""

    bl_idname = "relativity.bake_motion"
    bl_label = "Bake Motion"
    baked = "transforms"
    bake = staticmethod(bake_motion)

    @classmethod
    def poll(cls, context):
        if not _poll_mesh(cls, context):
            return False
        if context.active_object.relativity.use_deformation:
            cls.poll_message_set("A deforming object bakes its vertex positions: use Bake Deformation")
            return False
        return True


classes = (RELATIVITY_OT_bake_deformation, RELATIVITY_OT_bake_motion)


_HANDLERS = (
    (bpy.app.handlers.frame_change_post, _frame_change_post),
    (bpy.app.handlers.depsgraph_update_post, _depsgraph_update_post),
)


def register():
    for handlers, handler in _HANDLERS:
        if handler not in handlers:
            handlers.append(handler)


def unregister():
    for handlers, handler in _HANDLERS:
        if handler in handlers:
            handlers.remove(handler)
