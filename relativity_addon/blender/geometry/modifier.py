"""The apparent-geometry modifier and its per-object cache.

The add-on's modifier (node group ``Relativity Apparent Geometry``) subdivides the mesh, stores
the tessellated rest positions in the point attribute ``relativity_rest``, then sets the positions
sampled by index from a cache mesh object, but only when the point counts match (so a stale cache
never scrambles the mesh); it also copies the cache's ``relativity_beta`` (each point's velocity
relative to the observer) for the Doppler shaders. ``geometry.update_object`` fills the cache.
For the closed-form motions (``motion.closed_form``: Static, Constant Velocity without an animation
of its own) the modifier computes the apparent positions itself (``Closed Form`` on, the inputs of
``motion.closed_form_inputs``), from the rest positions with vector math: a velocity change or a frame
step sets a few inputs and needs no cache and no pass over the vertices in Python.

The cache object is not linked into any scene; the modifier holds its only user, so it is saved
with the .blend and a render farm worker needs nothing else. Motion and deformation bakes are
kept on the cache mesh too (``bakes.py``), so they go with the effect when it is removed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy
import numpy as np

from ..common import compat, names
from ..common.nodes import (
    Group,
    Links,
    Literal,
    Node,
    ensure_group,
    fmath,
    interface_identifier,
    remove_unused_groups,
    vmath,
)

if TYPE_CHECKING:
    from bpy.types import ID, Depsgraph, Mesh, Modifier, NodeTree, Object, Scene

    from ...physics.arrays import FloatArray


# The closed form's inputs (object space in, object space out; every vector folded in float64 by
# ``motion.closed_form_inputs``): the point at the observer's time relative to the observer is
# ``r = Scene X * x + Scene Y * y + Scene Z * z + Scene Offset`` (scene units), its light-travel
# distance ``s = c tau`` solves ``|r - s w| = s`` (``w``: Velocity, fraction of c;
# ``Inverse Gamma Squared = 1 - w.w``) in closed form, and the apparent position in object space
# is affine in the rest position and ``s``: ``Local X * x + Local Y * y + Local Z * z + Local Offset
# + s * Delay Direction``.
CLOSED_FORM_INPUTS = (
    "Scene X",
    "Scene Y",
    "Scene Z",
    "Scene Offset",
    "Velocity",
    "Local X",
    "Local Y",
    "Local Z",
    "Local Offset",
    "Delay Direction",
    "Seen Velocity",
)


def _multiply_add(a: str, b: str, c: str) -> Node:
    return Node("ShaderNodeVectorMath", {0: a, 1: b, 2: c}, {"operation": "MULTIPLY_ADD"})


def _closed_form_nodes() -> dict[str, Node]:
    """The apparent positions of the rest positions (``position`` after ``store_rest``) for uniform
    motion (docs/physics.md, "Light-travel time": the closed form of physics/retarded.py in units of
    c, in whichever of its two equal forms avoids cancellation). Output: ``apparent.Vector``."""
    return {
        "rest_split": Node("ShaderNodeSeparateXYZ", {"Vector": "position.Position"}),
        "scene_x": _multiply_add("rest_split.X", "group.Scene X", "group.Scene Offset"),
        "scene_y": _multiply_add("rest_split.Y", "group.Scene Y", "scene_x.Vector"),
        "scene_r": _multiply_add("rest_split.Z", "group.Scene Z", "scene_y.Vector"),
        "along": vmath("DOT_PRODUCT", "scene_r.Vector", "group.Velocity"),
        "distance2": vmath("DOT_PRODUCT", "scene_r.Vector", "scene_r.Vector"),
        "along2": fmath("MULTIPLY", "along.Value", "along.Value"),
        "discriminant": fmath("MULTIPLY_ADD", "group.Inverse Gamma Squared", "distance2.Value", "along2"),
        "root": fmath("SQRT", "discriminant"),
        # moving away from the observer (r.w > 0): q / (root + r.w); else (root - r.w) / (1 - w.w)
        "root_plus": fmath("ADD", "root", "along.Value"),
        "delay_away": fmath("DIVIDE", "distance2.Value", "root_plus"),
        "root_minus": fmath("SUBTRACT", "root", "along.Value"),
        "delay_towards": fmath("DIVIDE", "root_minus", "group.Inverse Gamma Squared"),
        "away": Node(
            "FunctionNodeCompare", {"A": "along.Value", "B": 0.0}, {"data_type": "FLOAT", "operation": "GREATER_THAN"}
        ),
        "delay": Node(
            "GeometryNodeSwitch",
            {"Switch": "away.Result", "False": "delay_towards", "True": "delay_away"},
            {"input_type": "FLOAT"},
        ),
        "local_x": _multiply_add("rest_split.X", "group.Local X", "group.Local Offset"),
        "local_y": _multiply_add("rest_split.Y", "group.Local Y", "local_x.Vector"),
        "local_z": _multiply_add("rest_split.Z", "group.Local Z", "local_y.Vector"),
        "apparent": _multiply_add("delay.Output", "group.Delay Direction", "local_z.Vector"),
    }


def _subdivision_nodes() -> dict[str, Node]:
    """The subdivision: every face at Tessellation levels (``Face Codes`` 0, or not this mesh's face
    count), else only the faces whose code, read from the last ``Face Codes`` points of the cache
    (one per face of the incoming mesh), is 1; the two parts are welded again along their seam
    (``Weld Distance``). Output: ``subdivided.Output``."""
    face_code = {"data_type": "FLOAT", "domain": "FACE"}
    return {
        "in_size": Node("GeometryNodeAttributeDomainSize", {"Geometry": "group.Geometry"}, {"component": "MESH"}),
        "codes_given": Node(
            "FunctionNodeCompare", {"A": "group.Face Codes", "B": 0}, {"data_type": "INT", "operation": "GREATER_THAN"}
        ),
        "codes_fit": Node(
            "FunctionNodeCompare",
            {"A": "group.Face Codes", "B": "in_size.Face Count"},
            {"data_type": "INT", "operation": "EQUAL"},
        ),
        "adaptive": Node(
            "FunctionNodeBooleanMath", {0: "codes_given.Result", 1: "codes_fit.Result"}, {"operation": "AND"}
        ),
        "codes_start": Node(
            "FunctionNodeIntegerMath", {0: "cache_size.Point Count", 1: "group.Face Codes"}, {"operation": "SUBTRACT"}
        ),
        "face_index": Node("GeometryNodeInputIndex"),
        "code_index": Node(
            "FunctionNodeIntegerMath", {0: "codes_start.Value", 1: "face_index.Index"}, {"operation": "ADD"}
        ),
        "cache_code": Node(
            "GeometryNodeInputNamedAttribute", {"Name": Literal(names.FACE_CODE_ATTRIBUTE)}, {"data_type": "FLOAT"}
        ),
        "sample_code": Node(
            "GeometryNodeSampleIndex",
            {"Geometry": "cache_info.Geometry", "Value": "cache_code.Attribute", "Index": "code_index.Value"},
            {"data_type": "FLOAT", "domain": "POINT"},
        ),
        "store_code": Node(
            "GeometryNodeStoreNamedAttribute",
            {"Geometry": "group.Geometry", "Name": Literal(names.FACE_CODE_ATTRIBUTE), "Value": "sample_code.Value"},
            face_code,
        ),
        "code": Node(
            "GeometryNodeInputNamedAttribute", {"Name": Literal(names.FACE_CODE_ATTRIBUTE)}, {"data_type": "FLOAT"}
        ),
        "is_subdivided": Node(
            "FunctionNodeCompare",
            {"A": "code.Attribute", "B": 1.0, "Epsilon": 0.25},
            {"data_type": "FLOAT", "operation": "EQUAL"},
        ),
        "separate": Node(
            "GeometryNodeSeparateGeometry",
            {"Geometry": "store_code.Geometry", "Selection": "is_subdivided.Result"},
            {"domain": "FACE"},
        ),
        "subdivide_part": Node(
            "GeometryNodeSubdivideMesh", {"Mesh": "separate.Selection", "Level": "group.Tessellation"}
        ),
        "join": Node("GeometryNodeJoinGeometry", {"Geometry": Links(("separate.Inverted", "subdivide_part.Mesh"))}),
        # points of the faces on either side of the seam (codes 1 and 2; a code read on the points is
        # the mean of their faces'), where the two parts' copies of a vertex are welded again
        "seam_point": Node(
            "FunctionNodeCompare",
            {"A": "code.Attribute", "B": 0.05},
            {"data_type": "FLOAT", "operation": "GREATER_THAN"},
        ),
        "weld": Node(
            "GeometryNodeMergeByDistance",
            # mode All, the default on both lines (a property in 4.5, a menu socket in 5.2)
            {"Geometry": "join.Geometry", "Selection": "seam_point.Result", "Distance": "group.Weld Distance"},
        ),
        "subdivide_all": Node("GeometryNodeSubdivideMesh", {"Mesh": "group.Geometry", "Level": "group.Tessellation"}),
        "subdivided": Node(
            "GeometryNodeSwitch",
            {"Switch": "adaptive.Boolean", "False": "subdivide_all.Mesh", "True": "weld.Geometry"},
            {"input_type": "GEOMETRY"},
        ),
    }


def _seam_nodes() -> dict[str, Node]:
    """Points of the subdivided faces on the seam's edges (which the faces of code 2 across the seam
    do not have) are put on those faces' straight edges, so the surface has no crack: each takes the
    apparent position interpolated on the code-2 faces at its rest position. Input: ``store_beta``;
    output: ``unmarked.Geometry``."""
    vector = {"data_type": "FLOAT_VECTOR", "domain": "POINT"}
    return {
        "is_ring": Node(
            "FunctionNodeCompare",
            {"A": "code.Attribute", "B": 2.0, "Epsilon": 0.25},
            {"data_type": "FLOAT", "operation": "EQUAL"},
        ),
        "ring": Node(
            "GeometryNodeSeparateGeometry",
            {"Geometry": "store_beta.Geometry", "Selection": "is_ring.Result"},
            {"domain": "FACE"},
        ),
        "store_seen": Node(
            "GeometryNodeStoreNamedAttribute",
            {"Geometry": "ring.Selection", "Name": Literal(names.SEEN_ATTRIBUTE), "Value": "position.Position"},
            vector,
        ),
        "rest": Node(
            "GeometryNodeInputNamedAttribute", {"Name": Literal(names.REST_ATTRIBUTE)}, {"data_type": "FLOAT_VECTOR"}
        ),
        "ring_at_rest": Node(
            "GeometryNodeSetPosition", {"Geometry": "store_seen.Geometry", "Position": "rest.Attribute"}
        ),
        "ring_size": Node("GeometryNodeAttributeDomainSize", {"Geometry": "ring.Selection"}, {"component": "MESH"}),
        "has_ring": Node(
            "FunctionNodeCompare",
            {"A": "ring_size.Face Count", "B": 0},
            {"data_type": "INT", "operation": "GREATER_THAN"},
        ),
        "proximity": Node(
            "GeometryNodeProximity",
            {0: "ring_at_rest.Geometry", "Sample Position": "rest.Attribute"},
            {"target_element": "FACES"},
        ),
        "on_ring": Node(
            "FunctionNodeCompare",
            {"A": "proximity.Distance", "B": "group.Weld Distance"},
            {"data_type": "FLOAT", "operation": "LESS_EQUAL"},
        ),
        "snap": Node("FunctionNodeBooleanMath", {0: "on_ring.Result", 1: "has_ring.Result"}, {"operation": "AND"}),
        "snap_moved": Node("FunctionNodeBooleanMath", {0: "snap.Boolean", 1: "moved.Boolean"}, {"operation": "AND"}),
        "seen": Node(
            "GeometryNodeInputNamedAttribute", {"Name": Literal(names.SEEN_ATTRIBUTE)}, {"data_type": "FLOAT_VECTOR"}
        ),
        "interpolated": Node(
            "GeometryNodeSampleNearestSurface",
            {"Mesh": "ring_at_rest.Geometry", "Value": "seen.Attribute", "Sample Position": "rest.Attribute"},
            {"data_type": "FLOAT_VECTOR"},
        ),
        "snapped": Node(
            "GeometryNodeSetPosition",
            {"Geometry": "store_beta.Geometry", "Selection": "snap_moved.Boolean", "Position": "interpolated.Value"},
        ),
        "seamless": Node(
            "GeometryNodeSwitch",
            {"Switch": "adaptive.Boolean", "False": "store_beta.Geometry", "True": "snapped.Geometry"},
            {"input_type": "GEOMETRY"},
        ),
        "unmarked": Node(
            "GeometryNodeRemoveAttribute", {"Geometry": "seamless.Output", "Name": Literal(names.FACE_CODE_ATTRIBUTE)}
        ),
    }


def node_group_spec() -> Group:
    store = {"data_type": "FLOAT_VECTOR", "domain": "POINT"}
    mesh_size = {"component": "MESH"}
    nodes = {
        "cache_info": Node("GeometryNodeObjectInfo", {"Object": "group.Cache"}, {"transform_space": "ORIGINAL"}),
        "cache_size": Node("GeometryNodeAttributeDomainSize", {"Geometry": "cache_info.Geometry"}, mesh_size),
        **_subdivision_nodes(),
        "position": Node("GeometryNodeInputPosition"),
        "store_rest": Node(
            "GeometryNodeStoreNamedAttribute",
            {
                "Geometry": "subdivided.Output",
                "Name": Literal(names.REST_ATTRIBUTE),
                "Value": "position.Position",
            },
            store,
        ),
        "mesh_size": Node("GeometryNodeAttributeDomainSize", {"Geometry": "store_rest.Geometry"}, mesh_size),
        # the cache holds a position per point, then the face codes
        "cache_points": Node(
            "FunctionNodeIntegerMath", {0: "cache_size.Point Count", 1: "group.Face Codes"}, {"operation": "SUBTRACT"}
        ),
        "counts_match": Node(
            "FunctionNodeCompare",
            {"A": "cache_points.Value", "B": "mesh_size.Point Count"},
            {"data_type": "INT", "operation": "EQUAL"},
        ),
        "index": Node("GeometryNodeInputIndex"),
        "sample_position": Node(
            "GeometryNodeSampleIndex",
            {
                "Geometry": "cache_info.Geometry",
                "Value": "position.Position",
                "Index": "index.Index",
            },
            store,
        ),
        "cache_beta": Node(
            "GeometryNodeInputNamedAttribute", {"Name": Literal(names.BETA_ATTRIBUTE)}, {"data_type": "FLOAT_VECTOR"}
        ),
        "sample_beta": Node(
            "GeometryNodeSampleIndex",
            {
                "Geometry": "cache_info.Geometry",
                "Value": "cache_beta.Attribute",
                "Index": "index.Index",
            },
            store,
        ),
        **_closed_form_nodes(),
        # the closed form, or the cache's positions when they fit
        "moved": Node(
            "FunctionNodeBooleanMath", {0: "counts_match.Result", 1: "group.Closed Form"}, {"operation": "OR"}
        ),
        "seen_position": Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Closed Form", "False": "sample_position.Value", "True": "apparent.Vector"},
            {"input_type": "VECTOR"},
        ),
        "seen_beta": Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Closed Form", "False": "sample_beta.Value", "True": "group.Seen Velocity"},
            {"input_type": "VECTOR"},
        ),
        "set_position": Node(
            "GeometryNodeSetPosition",
            {"Geometry": "store_rest.Geometry", "Selection": "moved.Boolean", "Position": "seen_position.Output"},
        ),
        "store_beta": Node(
            "GeometryNodeStoreNamedAttribute",
            {
                "Geometry": "set_position.Geometry",
                "Selection": "moved.Boolean",
                "Name": Literal(names.BETA_ATTRIBUTE),
                "Value": "seen_beta.Output",
            },
            store,
        ),
        **_seam_nodes(),
    }
    return Group(
        names.GEOMETRY_GROUP,
        "GeometryNodeTree",
        (
            ("Geometry", "NodeSocketGeometry", None),
            ("Tessellation", "NodeSocketInt", {"min_value": 0, "max_value": 6, "default_value": 1}),
            ("Cache", "NodeSocketObject", None),
            ("Face Codes", "NodeSocketInt", {"min_value": 0, "default_value": 0}),
            ("Weld Distance", "NodeSocketFloat", {"min_value": 0.0, "default_value": 0.0}),
            ("Closed Form", "NodeSocketBool", {"default_value": False}),
            *((name, "NodeSocketVector", None) for name in CLOSED_FORM_INPUTS),
            ("Inverse Gamma Squared", "NodeSocketFloat", {"default_value": 1.0}),
        ),
        (("Geometry", "NodeSocketGeometry", "unmarked.Geometry"),),
        nodes,
    )


def ensure_node_group() -> NodeTree:
    return ensure_group(node_group_spec(), names.GEOMETRY_GROUP_VERSION_KEY, names.GEOMETRY_GROUP_VERSION)


def find_modifier(obj: Object) -> Modifier | None:
    for modifier in obj.modifiers:
        if (
            modifier.type == "NODES"
            and modifier.node_group is not None
            and modifier.node_group.name == names.GEOMETRY_GROUP
        ):
            return modifier
    return None


def is_cache(obj: Object) -> bool:
    """A cache object (its mesh records the object it serves), never an object of the user's."""
    return obj.type == "MESH" and obj.data is not None and names.OWNER_KEY in obj.data


def applied_objects(scene: Scene) -> list[Object]:
    """The scene's meshes carrying the modifier; linked objects are the library's (set up there or
    not), never this file's."""
    return [
        obj
        for obj in scene.objects
        if obj.type == "MESH" and obj.library is None and find_modifier(obj) is not None and not is_cache(obj)
    ]


def cache_object(obj: Object) -> Object | None:
    modifier = find_modifier(obj)
    if modifier is None:
        return None
    return compat.modifier_input(modifier, interface_identifier(modifier.node_group, "Cache"))


def cache_data(obj: Object) -> ID | None:
    """The cache mesh of ``obj`` (where its update state and bakes live), or None."""
    cache = cache_object(obj)
    return cache.data if cache is not None else None


def ensure_modifier(obj: Object) -> tuple[Modifier, Object]:
    """The object's modifier and cache object, created if missing. Returns (modifier, cache)."""
    group = ensure_node_group()
    modifier = find_modifier(obj)
    created = modifier is None
    if modifier is None:
        modifier = obj.modifiers.new(names.GEOMETRY_MODIFIER, "NODES")
        modifier.node_group = group
    cache = cache_object(obj)
    if cache is not None and _shared_with_another_object(obj, cache):
        cache = None  # a duplicated object copied the modifier and its cache pointer: own one
    if cache is None:
        mesh = bpy.data.meshes.new(f"{names.CACHE_PREFIX} {obj.name}")
        cache = bpy.data.objects.new(f"{names.CACHE_PREFIX} {obj.name}", mesh)
        compat.set_modifier_input(modifier, interface_identifier(group, "Cache"), cache)
    if cache.data.get(names.OWNER_KEY) != obj.name:
        cache.data[names.OWNER_KEY] = obj.name  # set on creation, and follows a rename
    # with adaptive tessellation the update sets the level (geometry/tessellation.py); a new
    # modifier starts with none, so Set Up never subdivides a large mesh it may not need to
    adaptive = bool(obj.relativity.use_adaptive_tessellation)
    if created or not adaptive:
        identifier = interface_identifier(group, "Tessellation")
        level = 0 if adaptive else int(obj.relativity.tessellation)
        if compat.modifier_input(modifier, identifier) != level:
            compat.set_modifier_input(modifier, identifier, level)
            obj.update_tag()  # a modifier input is no tagged property: re-evaluate before reading the rest
    enabled = bool(obj.relativity.enabled)
    if modifier.show_viewport != enabled or modifier.show_render != enabled:
        modifier.show_viewport = modifier.show_render = enabled
    return modifier, cache


def set_closed_form(mod: Modifier, inputs: dict[str, tuple[float, ...] | float] | None) -> bool:
    """Switch the modifier's closed form on with ``inputs`` (by interface name), or off (None: the
    cache's positions). Returns whether any input changed (the object must then be evaluated
    again). Values equal after rounding to the sockets' float32 are left as they are."""
    group = mod.node_group
    wanted: dict[str, object] = {"Closed Form": inputs is not None, **(inputs or {})}
    changed = False
    for name, value in wanted.items():
        identifier = interface_identifier(group, name)
        current = compat.modifier_input(mod, identifier)
        if isinstance(value, bool):
            same = current is not None and bool(current) == value
        else:
            new = np.asarray(value, dtype=np.float32)
            same = current is not None and np.array_equal(np.asarray(current, dtype=np.float32), new)
            value = float(new) if new.ndim == 0 else tuple(map(float, new))
        if not same:
            compat.set_modifier_input(mod, identifier, value)
            changed = True
    return changed


def closed_form_on(mod: Modifier) -> bool:
    """Whether the modifier computes the apparent positions itself (the closed form)."""
    return bool(compat.modifier_input(mod, interface_identifier(mod.node_group, "Closed Form")))


def _shared_with_another_object(obj, cache):
    """True if ``cache`` belongs to another object (its recorded owner) that still uses it."""
    owner = bpy.data.objects.get(cache.data.get(names.OWNER_KEY, "")) if cache.data is not None else None
    return owner is not None and owner != obj and cache_object(owner) == cache


def bake_mesh(obj: Object) -> Mesh | None:
    """The mesh holding the object's deformation bake, or None."""
    data = cache_data(obj)
    if data is None or names.BAKE_KEY not in data:
        return None
    return bpy.data.meshes.get(data[names.BAKE_KEY]["mesh"])


def motion_bake(obj: Object) -> tuple[float, int, FloatArray] | None:
    """``(first frame, samples per frame, matrices (K, 4, 4) float64)`` of the object's motion
    bake, or None."""
    data = cache_data(obj)
    if data is None or names.MOTION_BAKE_KEY not in data:
        return None
    info = data[names.MOTION_BAKE_KEY]
    matrices = np.array(info["matrices"], dtype=np.float64).reshape(-1, 4, 4)
    return float(info["first_frame"]), int(info["samples_per_frame"]), matrices


def motion_bake_range(obj: Object) -> tuple[float, float] | None:
    """(first, last) frame of the object's motion bake, or None (reads no matrices)."""
    data = cache_data(obj)
    if data is None or names.MOTION_BAKE_KEY not in data:
        return None
    info = data[names.MOTION_BAKE_KEY]
    first, per_frame = float(info["first_frame"]), int(info["samples_per_frame"])
    return first, first + (len(info["matrices"]) // 16 - 1) / per_frame


def object_error(obj: Object) -> str | None:
    """The one-line error of the object's last handler update, or None."""
    data = cache_data(obj) if find_modifier(obj) is not None else None
    return data.get(names.ERROR_KEY) or None if data is not None else None


def remove_object_effect(obj: Object) -> bool:
    """Remove the object's modifier, cache and bakes; the mesh data was never written."""
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
        remove_cache(cache, with_bake=False)
    return True


def remove_cache(cache: Object, with_bake: bool = True) -> None:
    """Delete a cache object, its mesh and (``with_bake``) the deformation bake it records."""
    mesh = cache.data if isinstance(cache.data, bpy.types.Mesh) else None
    bake_name = mesh.get(names.BAKE_KEY, {}).get("mesh") if with_bake and mesh is not None else None
    bpy.data.objects.remove(cache)
    if mesh is not None and mesh.users == 0:
        bpy.data.meshes.remove(mesh)
    baked = bpy.data.meshes.get(bake_name) if bake_name else None
    if baked is not None and baked.users == 0:
        bpy.data.meshes.remove(baked)


def remove_unused_group() -> None:
    remove_unused_groups((names.GEOMETRY_GROUP,))


def evaluated_rest_positions(obj: Object, depsgraph: Depsgraph, dtype: type = np.float64) -> FloatArray | None:
    """The tessellated rest positions (object space, ``(N, 3)`` of ``dtype``) the modifier stored
    on the evaluated mesh, or None without the attribute. Read from the evaluated mesh itself:
    ``to_mesh`` would copy the whole mesh first."""
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.data if obj_eval.type == "MESH" else None
    attribute = mesh.attributes.get(names.REST_ATTRIBUTE) if mesh is not None else None
    if attribute is None:
        return None
    rest = np.empty(len(attribute.data) * 3, dtype=np.float32)
    attribute.data.foreach_get("vector", rest)
    return rest.reshape(-1, 3).astype(dtype, copy=False)


def write_cache(mesh: Mesh, positions: FloatArray, beta: FloatArray, face_codes: FloatArray | None = None) -> None:
    """Object-space positions ``(N, 3)`` and observer-frame velocities ``beta`` (``(N, 3)``, or
    ``(1, 3)`` shared by every point) into the cache mesh; then, with adaptive tessellation, one
    point per face of the modifier's incoming mesh holding its code (``geometry/tessellation.py``)."""
    codes = 0 if face_codes is None else len(face_codes)
    count = len(positions) + codes
    if len(mesh.vertices) != count:
        mesh.clear_geometry()
        mesh.vertices.add(count)
    if codes:
        positions = np.concatenate((positions, np.zeros((codes, 3))))
        if len(beta) > 1:
            beta = np.concatenate((beta, np.zeros((codes, 3))))
    # The attribute API copies the float32 buffer in one go; vertices.foreach_set("co") was
    # measured 150x slower (70 ms for a million vertices).
    if count:  # an empty mesh has no position attribute
        mesh.attributes["position"].data.foreach_set(
            "vector", np.ascontiguousarray(positions, dtype=np.float32).ravel()
        )
    _write_face_codes(mesh, count, face_codes)
    attribute = mesh.attributes.get(names.BETA_ATTRIBUTE)
    if attribute is None:
        attribute = mesh.attributes.new(names.BETA_ATTRIBUTE, "FLOAT_VECTOR", "POINT")
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


def _write_face_codes(mesh, count, face_codes):
    attribute = mesh.attributes.get(names.FACE_CODE_ATTRIBUTE)
    if face_codes is None or len(face_codes) == 0:
        if attribute is not None:
            mesh.attributes.remove(attribute)
        return
    if attribute is None:
        attribute = mesh.attributes.new(names.FACE_CODE_ATTRIBUTE, "FLOAT", "POINT")
    values = np.zeros(count, dtype=np.float32)
    values[count - len(face_codes) :] = face_codes
    attribute.data.foreach_set("value", values)
