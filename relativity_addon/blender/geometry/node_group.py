"""The apparent-geometry modifier's node group (``Relativity Apparent Geometry``), as data for
``common/nodes.py``: the subdivision (adaptive tessellation's face codes), the rest positions, the
apparent positions (sampled from the cache, or the closed form computed here) and the seam.
``modifier.py`` attaches it and fills its inputs."""

from __future__ import annotations

from ..common import names
from ..common.nodes import Group, Links, Literal, Node, fmath, vmath
from .keyframed_nodes import KEYFRAMED_INPUTS, keyframed_nodes, window_verdict_nodes

# The closed form's inputs (object space in, object space out; every vector folded in float64 by
# ``uniform_motion.closed_form_inputs``): the point at the observer's time relative to the observer is
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
        "delay_per_point": Node(
            "GeometryNodeSwitch",
            {"Switch": "away.Result", "False": "delay_towards", "True": "delay_away"},
            {"input_type": "FLOAT"},
        ),
        # Folded (a single value: only the side chosen is computed): the towards form on every point,
        # its cancellation on receding points bounded by uniform_motion.FOLD_LIMIT
        "delay": Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Folded", "False": "delay_per_point.Output", "True": "delay_towards"},
            {"input_type": "FLOAT"},
        ),
        "local_x": _multiply_add("rest_split.X", "group.Local X", "group.Local Offset"),
        "local_y": _multiply_add("rest_split.Y", "group.Local Y", "local_x.Vector"),
        "local_z": _multiply_add("rest_split.Z", "group.Local Z", "local_y.Vector"),
        "apparent": _multiply_add("delay.Output", "group.Delay Direction", "local_z.Vector"),
    }


# Adaptive tessellation's shortcut for the closed form (tessellation.edge_measure_inputs): the
# camera's view of object-space points, ``Camera X * x + Camera Y * y + Camera Z * z + Camera
# Offset`` (camera space, looking down -Z), and its pixels, ``(view / depth - Window Low) * Pixel Scale``
# (render resolution; the z component is then the same for every point).
EDGE_MEASURE_INPUTS = ("Camera X", "Camera Y", "Camera Z", "Camera Offset", "Pixel Scale", "Window Low")


def _edge_verdict_nodes() -> dict[str, Node]:
    """Whether every edge of the incoming mesh has an image (between the images of its ends'
    apparent positions, the closed form's) no longer than ``Tolerance`` pixels, both ends in front
    of the camera: then no edge needs subdividing (physics/tessellation.edge_levels measures no
    such edge) and the mesh is left whole (``whole_seen``, the closed form on the incoming mesh).
    Output: ``edges_short.Output`` (only with ``Measure Edges`` and the closed form on); with ``Edges
    Proven Short`` (a bound shows every image short) the edges are not visited."""
    return {
        # the incoming mesh moved by the closed form, once: the output when it stays whole
        "whole_rest": Node(
            "GeometryNodeStoreNamedAttribute",
            {"Geometry": "group.Geometry", "Name": Literal(names.REST_ATTRIBUTE), "Value": "position.Position"},
            {"data_type": "FLOAT_VECTOR", "domain": "POINT"},
        ),
        "whole_seen": Node(
            "GeometryNodeSetPosition", {"Geometry": "kf_whole_geometry.Output", "Position": "kf_whole_seen.Output"}
        ),
        "view_split": Node("ShaderNodeSeparateXYZ", {"Vector": "position.Position"}),
        "view_x": _multiply_add("view_split.X", "group.Camera X", "group.Camera Offset"),
        "view_y": _multiply_add("view_split.Y", "group.Camera Y", "view_x.Vector"),
        "view": _multiply_add("view_split.Z", "group.Camera Z", "view_y.Vector"),
        "view_parts": Node("ShaderNodeSeparateXYZ", {"Vector": "view.Vector"}),
        "depth": fmath("MULTIPLY", "view_parts.Z", -1.0),
        "in_front": Node(
            "FunctionNodeCompare", {"A": "depth", "B": 0.0}, {"data_type": "FLOAT", "operation": "GREATER_THAN"}
        ),
        "inverse_depth": fmath("DIVIDE", 1.0, "depth"),
        "on_plane": vmath("SCALE", "view.Vector", scale="inverse_depth"),
        "from_corner": vmath("SUBTRACT", "on_plane.Vector", "group.Window Low"),
        "pixels": vmath("MULTIPLY", "from_corner.Vector", "group.Pixel Scale"),
        # each point put at its pixels, or far off the picture's plane when behind the camera: an
        # edge with one end there is long; with both, like an edge the camera cannot see, it is
        # left as it is (as physics/tessellation.edge_levels does)
        "behind": Node(
            "GeometryNodeSwitch",
            {"Switch": "in_front.Result", "False": (0.0, 0.0, 1e10), "True": (0.0, 0.0, 0.0)},
            {"input_type": "VECTOR"},
        ),
        "image_point": vmath("ADD", "pixels.Vector", "behind.Output"),
        "at_pixels": Node(
            "GeometryNodeSetPosition", {"Geometry": "whole_seen.Geometry", "Position": "image_point.Vector"}
        ),
        "edge_ends": Node("GeometryNodeInputMeshEdgeVertices"),
        "image_length": vmath("DISTANCE", "edge_ends.Position 1", "edge_ends.Position 2"),
        "short": Node(
            "FunctionNodeCompare",
            {"A": "image_length.Value", "B": "group.Tolerance"},
            {"data_type": "FLOAT", "operation": "LESS_EQUAL"},
        ),
        "edge_long_value": Node(
            "GeometryNodeSwitch", {"Switch": "short.Result", "False": 1.0, "True": 0.0}, {"input_type": "FLOAT"}
        ),
        # the sum of the long edges' ones: Attribute Statistic sorts every value for its Min, not for its Sum
        "edges_long": Node(
            "GeometryNodeAttributeStatistic",
            {"Geometry": "at_pixels.Geometry", "Attribute": "edge_long_value.Output"},
            {"data_type": "FLOAT", "domain": "EDGE"},
        ),
        "all_fine": Node(
            "FunctionNodeCompare",
            {"A": "edges_long.Sum", "B": 0.5},
            {"data_type": "FLOAT", "operation": "LESS_THAN"},
        ),
        "measured": Node(
            "FunctionNodeBooleanMath", {0: "group.Measure Edges", 1: "in_modifier.Boolean"}, {"operation": "AND"}
        ),
        # every edge short by tessellation.edge_measure_inputs' bound: no edge is visited
        "proven_or_checked": Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Edges Proven Short", "False": "all_fine.Result", "True": True},
            {"input_type": "BOOLEAN"},
        ),
        # a Switch asks for the check only when it is on (Boolean Math would always compute it)
        "edges_short": Node(
            "GeometryNodeSwitch",
            {"Switch": "measured.Boolean", "False": False, "True": "proven_or_checked.Output"},
            {"input_type": "BOOLEAN"},
        ),
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
        "snap_moved": Node("FunctionNodeBooleanMath", {0: "snap.Boolean", 1: "moved.Output"}, {"operation": "AND"}),
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
        # the edges' verdict, read back by tessellation.edges_short (one value per face)
        "store_verdict": Node(
            "GeometryNodeStoreNamedAttribute",
            {
                "Geometry": "unmarked.Geometry",
                "Name": Literal(names.EDGES_SHORT_ATTRIBUTE),
                "Value": "edges_short.Output",
            },
            {"data_type": "BOOLEAN", "domain": "FACE"},
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
        **_edge_verdict_nodes(),
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
        **keyframed_nodes(),
        # the closed form, the keyframed motion, or the cache's positions when they fit
        # Switches, not Boolean Math: only what the chosen side needs is computed
        "moved": Node(
            "GeometryNodeSwitch",
            {"Switch": "in_modifier.Boolean", "False": "counts_match.Result", "True": True},
            {"input_type": "BOOLEAN"},
        ),
        "seen_position": Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Closed Form", "False": "kf_seen.Output", "True": "apparent.Vector"},
            {"input_type": "VECTOR"},
        ),
        "seen_beta": Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Closed Form", "False": "kf_cache_beta.Output", "True": "group.Seen Velocity"},
            {"input_type": "VECTOR"},
        ),
        "set_position": Node(
            "GeometryNodeSetPosition",
            {"Geometry": "kf_geometry.Output", "Selection": "moved.Output", "Position": "seen_position.Output"},
        ),
        "seen_geometry": Node(
            "GeometryNodeSwitch",
            {"Switch": "edges_short.Output", "False": "set_position.Geometry", "True": "whole_seen.Geometry"},
            {"input_type": "GEOMETRY"},
        ),
        "store_beta": Node(
            "GeometryNodeStoreNamedAttribute",
            {
                "Geometry": "seen_geometry.Output",
                "Selection": "moved.Output",
                "Name": Literal(names.BETA_ATTRIBUTE),
                "Value": "seen_beta.Output",
            },
            store,
        ),
        **_seam_nodes(),
        **window_verdict_nodes("store_verdict.Geometry"),
    }
    return Group(
        names.GEOMETRY_GROUP,
        "GeometryNodeTree",
        _INPUTS,
        (("Geometry", "NodeSocketGeometry", "store_window.Output"),),
        nodes,
    )


_INPUTS = (
    ("Geometry", "NodeSocketGeometry", None),
    ("Tessellation", "NodeSocketInt", {"min_value": 0, "max_value": 6, "default_value": 1}),
    ("Cache", "NodeSocketObject", None),
    ("Face Codes", "NodeSocketInt", {"min_value": 0, "default_value": 0}),
    ("Weld Distance", "NodeSocketFloat", {"min_value": 0.0, "default_value": 0.0}),
    ("Closed Form", "NodeSocketBool", {"default_value": False}),
    *((name, "NodeSocketVector", None) for name in CLOSED_FORM_INPUTS),
    ("Inverse Gamma Squared", "NodeSocketFloat", {"default_value": 1.0}),
    ("Folded", "NodeSocketBool", {"default_value": False}),
    ("Measure Edges", "NodeSocketBool", {"default_value": False}),
    *((name, "NodeSocketVector", None) for name in EDGE_MEASURE_INPUTS),
    ("Tolerance", "NodeSocketFloat", {"default_value": 0.5}),
    *KEYFRAMED_INPUTS,
    ("Edges Proven Short", "NodeSocketBool", {"default_value": False}),
)

# The full group runs only the closed form on the incoming mesh, stores the rest positions, the
# velocity and the verdict "every edge short", and nothing else, when its inputs hold these values
# (the edges' bound clears them: no edge visited, no subdivision, no cache read); then the modifier
# gets the lean group instead (``modifier.set_inputs``). Its fixed cost per evaluation grows with the
# group's nodes and inputs (benchmarks/lean_group.py: 323 nodes against 26, about 2.5x).
LEAN_WHEN = {"Closed Form": True, "Keyframed": False, "Measure Edges": True, "Edges Proven Short": True}
# The lean group's inputs: the full group's that it reads, and those it keeps for the full group
# (the values go with a swap, by name): the cache, the tessellation's, the edge check's and
# LEAN_WHEN's, which the add-on reads back. Not the keyframed solve's: they are set with Keyframed.
_LEAN_INPUTS: tuple[str, ...] = ("Geometry", "Cache", "Tessellation", "Face Codes", "Weld Distance")
_LEAN_INPUTS += (*CLOSED_FORM_INPUTS, "Inverse Gamma Squared", "Folded", *EDGE_MEASURE_INPUTS, "Tolerance", *LEAN_WHEN)


def lean_node_group_spec() -> Group:
    """The lean group (``names.LEAN_GEOMETRY_GROUP``): what the full group computes with
    ``LEAN_WHEN``'s inputs, with the same nodes on that path (the same output, attributes included)."""
    vector = {"data_type": "FLOAT_VECTOR", "domain": "POINT"}
    nodes = {
        "position": Node("GeometryNodeInputPosition"),
        "whole_rest": Node(
            "GeometryNodeStoreNamedAttribute",
            {"Geometry": "group.Geometry", "Name": Literal(names.REST_ATTRIBUTE), "Value": "position.Position"},
            vector,
        ),
        **_closed_form_nodes(),
        "whole_seen": Node(
            "GeometryNodeSetPosition", {"Geometry": "whole_rest.Geometry", "Position": "apparent.Vector"}
        ),
        "store_beta": Node(
            "GeometryNodeStoreNamedAttribute",
            {"Geometry": "whole_seen.Geometry", "Name": Literal(names.BETA_ATTRIBUTE), "Value": "group.Seen Velocity"},
            vector,
        ),
        "store_verdict": Node(
            "GeometryNodeStoreNamedAttribute",
            {"Geometry": "store_beta.Geometry", "Name": Literal(names.EDGES_SHORT_ATTRIBUTE), "Value": True},
            {"data_type": "BOOLEAN", "domain": "FACE"},
        ),
    }
    inputs = tuple(item for item in _INPUTS if item[0] in _LEAN_INPUTS)
    return Group(
        names.LEAN_GEOMETRY_GROUP,
        "GeometryNodeTree",
        inputs,
        (("Geometry", "NodeSocketGeometry", "store_verdict.Geometry"),),
        nodes,
    )
