"""Keyframed rigid motion in the apparent-geometry modifier (``node_group.py`` links these nodes):
each point's retarded time solved on the Catmull-Rom pieces of its motion that
``geometry/keyframed.py`` writes into the cache's first points, the same motion and relation the
Python path solves (``physics/sampling.py``; docs/physics.md, "Light-travel time").

In units of scene length: a point's light-travel distance ``sigma = c tau`` puts it at grid
coordinate ``s = Grid Now - sigma * Grid Per Distance`` (sample interval ``j = floor(s)``,
``f = s - j``), where it is at ``x = y0 + f y1 + f^2 y2 + f^3 y3`` relative to the observer,
``y_i`` the interval's coefficient ``i`` (a 4x4 affine map, Sample Index from the cache) applied to
the rest position. The first step's single interval is clamped to those given (beyond the first or
last the end's slope continues, as in ``apparent.SampledRigidMotion``); the later steps' are not:
a point whose ``s`` lies outside the intervals at the last step is not found (the verdict).
Each step moves ``sigma`` to the closed form of uniform motion through ``x`` with the velocity
there (``|r - sigma w| = sigma``, ``r = x + sigma w``: one step for uniform motion, quadratic
convergence otherwise); ``STEPS`` of them from the origin's ``Start Distance`` reach float32
rounding for a body turning and accelerating at 0.9c
(``tests/blender/geometry/test_geometry_keyframed_modifier.py``). The apparent position in object
space is affine in the emission point and ``sigma`` (``Emission X/Y/Z/Offset/Delay``: the
observer's boost and the object's inverse matrix, folded in float64), and the velocity the
shaders read is the point's own at its retarded time seen by the observer (relativistic addition
of ``Observer Velocity``, which is minus the observer's).
"""

from __future__ import annotations

from ..common import names
from ..common.nodes import Literal, Node, fmath, vmath
from .polynomial_nodes import POLYNOMIAL_INPUTS, polynomial_nodes

# Closed-form steps from the origin's light-travel distance: the first reads one interval for all
# points and sums its cubic into two 4x4 maps (two Transform Points per point); each other reads
# each point's own interval by Sample Index (four reads, four Transform Points and the cubic per
# point), most of the modifier's cost (benchmarks/keyframed_modifier_profile.py). Two steps leave
# the accelerating bodies of test_geometry_keyframed_modifier.py above RESIDUAL (the verdict then
# sends them to the Python path at every update).
STEPS = 3
# A retarded time counts as found when the last step moved sigma by at most this fraction (+ 1e-6).
RESIDUAL = 1e-4

KEYFRAMED_INPUTS = (
    ("Keyframed", "NodeSocketBool", {"default_value": False}),
    ("Last Interval", "NodeSocketFloat", {"default_value": 0.0}),
    ("Grid Now", "NodeSocketFloat", {"default_value": 0.0}),
    ("Grid Per Distance", "NodeSocketFloat", {"default_value": 0.0}),
    ("Start Distance", "NodeSocketFloat", {"default_value": 0.0}),
    *(
        (name, "NodeSocketVector", None)
        for name in ("Emission X", "Emission Y", "Emission Z", "Emission Offset", "Emission Delay", "Observer Velocity")
    ),
    ("Observer Inverse Gamma", "NodeSocketFloat", {"default_value": 1.0}),
    ("Observer Factor", "NodeSocketFloat", {"default_value": 0.5}),
    ("Observer Moving", "NodeSocketBool", {"default_value": True}),
    *POLYNOMIAL_INPUTS,
)


def _multiply_add(a: object, b: object, c: object) -> Node:
    return Node("ShaderNodeVectorMath", {0: a, 1: b, 2: c}, {"operation": "MULTIPLY_ADD"})


def _interval(nodes: dict[str, Node], tag: str, sigma: object) -> None:
    """Nodes for the interval of light-travel distance ``sigma``: ``{tag}_s`` (grid coordinate),
    ``{tag}_j`` (the interval, clamped to those given), ``{tag}_g`` (the fraction inside it) and
    ``{tag}_beyond`` (how far past its end, where the end's slope continues)."""
    nodes.update(
        {
            f"{tag}_s": fmath("MULTIPLY_ADD", sigma, "kf_minus_kappa", "group.Grid Now"),
            f"{tag}_floor": fmath("FLOOR", f"{tag}_s"),
            f"{tag}_low": fmath("MAXIMUM", f"{tag}_floor", 0.0),
            f"{tag}_j": fmath("MINIMUM", f"{tag}_low", "group.Last Interval"),
            f"{tag}_f": fmath("SUBTRACT", f"{tag}_s", f"{tag}_j"),
            f"{tag}_g": fmath("ADD", f"{tag}_f", 0.0, clamp=True),
            f"{tag}_beyond": fmath("SUBTRACT", f"{tag}_f", f"{tag}_g"),
        }
    )
    for power in range(4):
        nodes[f"{tag}_m{power}"] = Node(
            "GeometryNodeSampleIndex",
            {"Geometry": "cache_info.Geometry", "Value": f"kf_coefficient{power}.Attribute", "Index": f"{tag}_j"},
            {"data_type": "FLOAT4X4", "domain": "POINT"},
        )


def _first_guess(nodes: dict[str, Node], tag: str, sigma: object) -> tuple[str, str]:
    """Nodes for the motion at the single light-travel distance ``sigma`` (the origin's): one
    interval for every point, so the cubic and its rate are summed once as 4x4 maps (single values)
    and each point pays two Transform Points; returns the references of the position relative to
    the observer and the rate per grid unit. Only the first step's guess: the later steps fix the
    result, so summing the matrices first (another float32 rounding) changes nothing they find."""
    _interval(nodes, tag, sigma)
    g, beyond = f"{tag}_g", f"{tag}_beyond"
    nodes[f"{tag}_g3"] = fmath("MULTIPLY", g, 3.0)
    for power in range(4):
        nodes[f"{tag}_e{power}"] = Node("FunctionNodeSeparateMatrix", {"Matrix": f"{tag}_m{power}.Value"})
    at, rate = {}, {}
    for column in range(1, 5):
        for row in range(1, 4):  # Transform Point ignores the fourth row
            entry = f"Column {column} Row {row}"
            m0, m1, m2, m3 = (f"{tag}_e{power}.{entry}" for power in range(4))
            key = f"{tag}_{column}{row}"
            nodes.update(
                {
                    f"{key}_p2": fmath("MULTIPLY_ADD", m3, g, m2),
                    f"{key}_p1": fmath("MULTIPLY_ADD", f"{key}_p2", g, m1),
                    f"{key}_p0": fmath("MULTIPLY_ADD", f"{key}_p1", g, m0),
                    f"{key}_m2x2": fmath("ADD", m2, m2),
                    f"{key}_r1": fmath("MULTIPLY_ADD", m3, f"{tag}_g3", f"{key}_m2x2"),
                    f"{key}_rate": fmath("MULTIPLY_ADD", f"{key}_r1", g, m1),
                    f"{key}_at": fmath("MULTIPLY_ADD", f"{key}_rate", beyond, f"{key}_p0"),
                }
            )
            at[entry], rate[entry] = f"{key}_at", f"{key}_rate"
    nodes[f"{tag}_at_matrix"] = Node("FunctionNodeCombineMatrix", at)
    nodes[f"{tag}_rate_matrix"] = Node("FunctionNodeCombineMatrix", rate)
    nodes[f"{tag}_x"] = Node(
        "FunctionNodeTransformPoint", {"Vector": "position.Position", "Transform": f"{tag}_at_matrix.Matrix"}
    )
    nodes[f"{tag}_rate"] = Node(
        "FunctionNodeTransformPoint", {"Vector": "position.Position", "Transform": f"{tag}_rate_matrix.Matrix"}
    )
    return f"{tag}_x.Vector", f"{tag}_rate.Vector"


def _evaluate(nodes: dict[str, Node], tag: str, sigma: object) -> tuple[str, str, str]:
    """Nodes for the motion at light-travel distance ``sigma`` (a field: each point's own interval,
    ``j = floor(s)``, read by Sample Index); returns the references of the position relative to the
    observer, the rate per grid unit and ``s``. Unlike the first step's, the interval is not clamped
    to those given: an ``s`` outside them reads another interval's (or no) coefficients, and the
    verdict, which checks the last step's ``s``, sends such a point to the Python path; inside, the
    result is the same."""
    nodes.update(
        {
            f"{tag}_s": fmath("MULTIPLY_ADD", sigma, "kf_minus_kappa", "group.Grid Now"),
            f"{tag}_j": fmath("FLOOR", f"{tag}_s"),
            f"{tag}_g": fmath("SUBTRACT", f"{tag}_s", f"{tag}_j"),
        }
    )
    for power in range(4):
        nodes[f"{tag}_m{power}"] = Node(
            "GeometryNodeSampleIndex",
            {"Geometry": "cache_info.Geometry", "Value": f"kf_coefficient{power}.Attribute", "Index": f"{tag}_j"},
            {"data_type": "FLOAT4X4", "domain": "POINT"},
        )
        nodes[f"{tag}_y{power}"] = Node(
            "FunctionNodeTransformPoint", {"Vector": "position.Position", "Transform": f"{tag}_m{power}.Value"}
        )
    g = f"{tag}_g"
    nodes.update(
        {
            f"{tag}_p2": _multiply_add(f"{tag}_y3.Vector", g, f"{tag}_y2.Vector"),
            f"{tag}_p1": _multiply_add(f"{tag}_p2.Vector", g, f"{tag}_y1.Vector"),
            f"{tag}_x": _multiply_add(f"{tag}_p1.Vector", g, f"{tag}_y0.Vector"),
            # the rate y1 + 2 g y2 + 3 g^2 y3 = p1 + g (p2 + g y3) (Horner's scheme for the derivative)
            f"{tag}_t": _multiply_add(f"{tag}_y3.Vector", g, f"{tag}_p2.Vector"),
            f"{tag}_rate": _multiply_add(f"{tag}_t.Vector", g, f"{tag}_p1.Vector"),
        }
    )
    return f"{tag}_x.Vector", f"{tag}_rate.Vector", f"{tag}_s"


def _step(
    nodes: dict[str, Node], tag: str, sigma: object, x: str, rate: str, scale: str = "group.Grid Per Distance"
) -> str:
    """Nodes for the next light-travel distance: uniform motion through ``x`` with its velocity
    ``w = rate * scale`` (units of c) solved in closed form (in whichever form avoids cancellation)."""
    nodes.update(
        {
            f"{tag}_w": vmath("SCALE", rate, scale=scale),
            f"{tag}_r": _multiply_add(f"{tag}_w.Vector", sigma, x),
            f"{tag}_a": vmath("DOT_PRODUCT", f"{tag}_r.Vector", f"{tag}_w.Vector"),
            f"{tag}_q": vmath("DOT_PRODUCT", f"{tag}_r.Vector", f"{tag}_r.Vector"),
            f"{tag}_ww": vmath("DOT_PRODUCT", f"{tag}_w.Vector", f"{tag}_w.Vector"),
            f"{tag}_b": fmath("SUBTRACT", 1.0, f"{tag}_ww.Value"),
            f"{tag}_a2": fmath("MULTIPLY", f"{tag}_a.Value", f"{tag}_a.Value"),
            f"{tag}_disc": fmath("MULTIPLY_ADD", f"{tag}_b", f"{tag}_q.Value", f"{tag}_a2"),
            f"{tag}_root": fmath("SQRT", f"{tag}_disc"),
            f"{tag}_plus": fmath("ADD", f"{tag}_root", f"{tag}_a.Value"),
            f"{tag}_away": fmath("DIVIDE", f"{tag}_q.Value", f"{tag}_plus"),
            f"{tag}_minus": fmath("SUBTRACT", f"{tag}_root", f"{tag}_a.Value"),
            f"{tag}_towards": fmath("DIVIDE", f"{tag}_minus", f"{tag}_b"),
            f"{tag}_receding": Node(
                "FunctionNodeCompare",
                {"A": f"{tag}_a.Value", "B": 0.0},
                {"data_type": "FLOAT", "operation": "GREATER_THAN"},
            ),
            f"{tag}_sigma": Node(
                "GeometryNodeSwitch",
                {"Switch": f"{tag}_receding.Result", "False": f"{tag}_towards", "True": f"{tag}_away"},
                {"input_type": "FLOAT"},
            ),
        }
    )
    return f"{tag}_sigma.Output"


def _seen(nodes: dict[str, Node], tag: str, x: str, sigma: object, w: str) -> tuple[str, str]:
    """Nodes for what the observer sees of the emission point ``x`` (relative to the observer) at
    light-travel distance ``sigma`` moving with ``w`` (fraction of c): the apparent position in
    object space and the velocity seen (references)."""
    nodes.update(
        {
            # the apparent position, object space: Emission (x, y, z) + Offset + sigma Delay
            f"{tag}_e": Node("ShaderNodeSeparateXYZ", {"Vector": x}),
            f"{tag}_lx": _multiply_add(f"{tag}_e.X", "group.Emission X", "group.Emission Offset"),
            f"{tag}_ly": _multiply_add(f"{tag}_e.Y", "group.Emission Y", f"{tag}_lx.Vector"),
            f"{tag}_lz": _multiply_add(f"{tag}_e.Z", "group.Emission Z", f"{tag}_ly.Vector"),
            f"{tag}_local": _multiply_add(sigma, "group.Emission Delay", f"{tag}_lz.Vector"),
            # u' = [u / gamma + v (1 + F v.u)] / (1 + v.u), v = Observer Velocity, F = gamma / (gamma + 1)
            f"{tag}_vu": vmath("DOT_PRODUCT", w, "group.Observer Velocity"),
            f"{tag}_along": fmath("MULTIPLY_ADD", "group.Observer Factor", f"{tag}_vu.Value", 1.0),
            f"{tag}_slow": vmath("SCALE", w, scale="group.Observer Inverse Gamma"),
            f"{tag}_sum": _multiply_add("group.Observer Velocity", f"{tag}_along", f"{tag}_slow.Vector"),
            f"{tag}_denominator": fmath("ADD", f"{tag}_vu.Value", 1.0),
            f"{tag}_inverse": fmath("DIVIDE", 1.0, f"{tag}_denominator"),
            f"{tag}_beta_seen": vmath("SCALE", f"{tag}_sum.Vector", scale=f"{tag}_inverse"),
            # an observer at rest (a single value: only the side chosen is computed): no delay term
            # (Emission Delay is zero) and no addition of velocities (the boost is the identity)
            f"{tag}_local_moving": Node(
                "GeometryNodeSwitch",
                {"Switch": "group.Observer Moving", "False": f"{tag}_lz.Vector", "True": f"{tag}_local.Vector"},
                {"input_type": "VECTOR"},
            ),
            f"{tag}_beta_moving": Node(
                "GeometryNodeSwitch",
                {"Switch": "group.Observer Moving", "False": w, "True": f"{tag}_beta_seen.Vector"},
                {"input_type": "VECTOR"},
            ),
        }
    )
    return f"{tag}_local_moving.Output", f"{tag}_beta_moving.Output"


def keyframed_nodes() -> dict[str, Node]:
    """The keyframed motion's fields on the rest positions (``position``), captured in one
    evaluation on ``store_rest`` (``kf_capture``) and, for the adaptive check's whole mesh, on
    ``whole_rest`` (``kf_capture_whole``): ``Seen`` (object space), ``Beta`` (the velocity attribute)
    and ``Inside`` (1 where the retarded time was found inside the intervals given). Outputs for
    ``node_group``: ``kf_geometry``, ``kf_whole_geometry``, ``kf_seen``, ``kf_beta``, ``kf_whole_seen``,
    ``kf_whole_beta`` and ``kf_inside`` (the verdict over the output's points)."""
    nodes: dict[str, Node] = {
        f"kf_coefficient{power}": Node(
            "GeometryNodeInputNamedAttribute", {"Name": Literal(name)}, {"data_type": "FLOAT4X4"}
        )
        for power, name in enumerate(names.MOTION_ATTRIBUTES)
    }
    nodes["kf_minus_kappa"] = fmath("MULTIPLY", "group.Grid Per Distance", -1.0)
    sigma: object = "group.Start Distance"
    s = "kf0_s"
    for step in range(STEPS):
        last = sigma
        if step == 0:
            _x, rate = _first_guess(nodes, "kf0", sigma)
        else:
            _x, rate, s = _evaluate(nodes, f"kf{step}", sigma)
        sigma = _step(nodes, f"kf{step}", sigma, _x, rate)
    # the emission point on the last step's uniform motion (r - sigma w): its error is the cubic's
    # departure over the last step, far below float32 rounding once the steps converge (checked below)
    tag = f"kf{STEPS - 1}"
    x = "kf_x.Vector"
    nodes.update(
        {
            "kf_minus_sigma": fmath("MULTIPLY", sigma, -1.0),
            "kf_x": _multiply_add(f"{tag}_w.Vector", "kf_minus_sigma", f"{tag}_r.Vector"),
            # found: s within the intervals, and the last step small
            "kf_s_high": fmath("ADD", "group.Last Interval", 1.0),
            "kf_after_start": Node(
                "FunctionNodeCompare", {"A": s, "B": 0.0}, {"data_type": "FLOAT", "operation": "GREATER_EQUAL"}
            ),
            # strictly: at s = Last Interval + 1 the last step read past the intervals
            "kf_before_end": Node(
                "FunctionNodeCompare", {"A": s, "B": "kf_s_high"}, {"data_type": "FLOAT", "operation": "LESS_THAN"}
            ),
            "kf_residual": fmath("SUBTRACT", sigma, last),
            "kf_residual_size": fmath("ABSOLUTE", "kf_residual"),
            "kf_allowed": fmath("MULTIPLY_ADD", sigma, RESIDUAL, 1e-6),
            "kf_converged": Node(
                "FunctionNodeCompare",
                {"A": "kf_residual_size", "B": "kf_allowed"},
                {"data_type": "FLOAT", "operation": "LESS_EQUAL"},
            ),
            "kf_in_window": Node(
                "FunctionNodeBooleanMath",
                {0: "kf_after_start.Result", 1: "kf_before_end.Result"},
                {"operation": "AND"},
            ),
            "kf_found": Node(
                "FunctionNodeBooleanMath", {0: "kf_in_window.Boolean", 1: "kf_converged.Result"}, {"operation": "AND"}
            ),
        }
    )
    local, beta = _seen(nodes, "kf", x, sigma, f"{tag}_w.Vector")
    polynomial, kp_x, kp_sigma, kp_w = polynomial_nodes()
    nodes.update(polynomial)
    kp_local, kp_beta = _seen(nodes, "kp", kp_x, kp_sigma, kp_w)
    items = {"capture_items": (("VECTOR", "Seen"), ("VECTOR", "Beta"), ("FLOAT", "Inside"))}
    captured = {"Seen": local, "Beta": beta, "Inside": "kf_found.Boolean"}
    kp_items = {"capture_items": (("VECTOR", "Seen"), ("VECTOR", "Beta"))}
    kp_captured = {"Seen": kp_local, "Beta": kp_beta}
    nodes.update(
        {
            "kf_capture": Node("GeometryNodeCaptureAttribute", {"Geometry": "store_rest.Geometry", **captured}, items),
            "kf_capture_whole": Node(
                "GeometryNodeCaptureAttribute", {"Geometry": "whole_rest.Geometry", **captured}, items
            ),
            "kp_capture": Node(
                "GeometryNodeCaptureAttribute", {"Geometry": "store_rest.Geometry", **kp_captured}, kp_items
            ),
            "kp_capture_whole": Node(
                "GeometryNodeCaptureAttribute", {"Geometry": "whole_rest.Geometry", **kp_captured}, kp_items
            ),
            "kf_beta": _switch("edges_short.Output", "kf_capture.Beta", "kf_capture_whole.Beta", "VECTOR"),
            "kp_beta": _switch("edges_short.Output", "kf_capture.Beta", "kf_capture_whole.Beta", "VECTOR", "kp"),
            "kf_inside_field": Node(
                "GeometryNodeSwitch",
                {"Switch": "edges_short.Output", "False": "kf_capture.Inside", "True": "kf_capture_whole.Inside"},
                {"input_type": "FLOAT"},
            ),
            "in_modifier": Node(
                "FunctionNodeBooleanMath", {0: "group.Closed Form", 1: "group.Keyframed"}, {"operation": "OR"}
            ),
        }
    )
    # Switches on single values: only the side asked for is computed (Keyframed, then Polynomial)
    for name, off, solved, kind in _ROUTES:
        polynomial_side = solved.replace("kf_capture", "kp_capture").replace("kf_beta", "kp_beta")
        nodes[f"{name}_solved"] = _switch("group.Polynomial", solved, polynomial_side, kind)
        nodes[name] = _switch("group.Keyframed", off, f"{name}_solved.Output", kind)
    return nodes


# (output, without Keyframed, the general solve's): the polynomial's is the same with kp_ for kf_
_ROUTES = (
    ("kf_geometry", "store_rest.Geometry", "kf_capture.Geometry", "GEOMETRY"),
    ("kf_whole_geometry", "whole_rest.Geometry", "kf_capture_whole.Geometry", "GEOMETRY"),
    ("kf_whole_seen", "apparent.Vector", "kf_capture_whole.Seen", "VECTOR"),
    ("kf_seen", "sample_position.Value", "kf_capture.Seen", "VECTOR"),
    ("kf_cache_beta", "sample_beta.Value", "kf_beta.Output", "VECTOR"),
)


def _switch(switch: str, false: object, true: object, kind: str, prefix: str = "kf") -> Node:
    """A Switch on ``switch`` (``prefix`` ``kp``: both sides the polynomial's captures)."""
    if prefix == "kp":
        false, true = (str(side).replace("kf_capture", "kp_capture") for side in (false, true))
    return Node("GeometryNodeSwitch", {"Switch": switch, "False": false, "True": true}, {"input_type": kind})


def window_verdict_nodes(geometry: str) -> dict[str, Node]:
    """The verdict stored on the output ``geometry`` (read by ``keyframed.window_found``): every
    point's retarded time found inside the intervals given (only with Keyframed on). Output:
    ``store_window.Geometry``."""
    return {
        # the count of points not found: Attribute Statistic sorts every value for its Min, not for its Sum
        "kf_outside": fmath("SUBTRACT", 1.0, "kf_inside_field.Output"),
        "kf_outside_count": Node(
            "GeometryNodeAttributeStatistic",
            {"Geometry": geometry, "Attribute": "kf_outside"},
            {"data_type": "FLOAT", "domain": "POINT"},
        ),
        "kf_all_inside": Node(
            "FunctionNodeCompare",
            {"A": "kf_outside_count.Sum", "B": 0.5},
            {"data_type": "FLOAT", "operation": "LESS_THAN"},
        ),
        # the polynomial's window and convergence were checked in Python (keyframed.py): no statistic
        "kf_window_ok": _switch("group.Polynomial", "kf_all_inside.Result", True, "BOOLEAN"),
        "kf_store_window": Node(
            "GeometryNodeStoreNamedAttribute",
            {"Geometry": geometry, "Name": Literal(names.WINDOW_OK_ATTRIBUTE), "Value": "kf_window_ok.Output"},
            {"data_type": "BOOLEAN", "domain": "FACE"},
        ),
        "store_window": Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Keyframed", "False": geometry, "True": "kf_store_window.Geometry"},
            {"input_type": "GEOMETRY"},
        ),
    }
