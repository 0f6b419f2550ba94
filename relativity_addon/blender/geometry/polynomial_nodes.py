"""Keyframed motion that one polynomial in time covers over the window of its retarded times
(``physics/polynomial_motion.py``; ``keyframed.py`` decides): the modifier's small solve, linked by
``keyframed_nodes.py`` under its ``Keyframed`` switch when ``Polynomial`` is on. No interval is read
per point (no Sample Index) and no verdict is taken over the points: ``keyframed.py`` checked in
Python that the polynomial follows the sampled motion to its rounding and that the steps converge.

Per point (``polynomial_motion.modifier_solve``, the same in float64): ``Q_i = C_i p`` (multiply-adds
on the rest position's parts, the columns single values; the polynomial in ``v = Centre - sigma``,
scene units, so that its derivative is the velocity), the closed form of uniform motion along the
start's line (``Q_0 + Start Offset Q_2`` at ``v = 0``, velocity ``Q_1 + Start Slope Q_3``), then
closed-form steps: uniform motion through ``x(v)`` with the velocity there, ``x`` and its rate by
Horner's scheme (one with ``Polynomial One Step``, which ``keyframed.py`` sets where one converges:
``polynomial_motion.choose_steps``; else STEPS); the emission point on the last step's uniform
motion and the velocity the polynomial's at the last ``sigma``. With ``Folded`` (the window slower
than ``uniform_motion.FOLD_LIMIT`` allows) each closed form takes its towards form on every point.
"""

from __future__ import annotations

from ...physics.polynomial_motion import DEGREE, STEPS
from ..common.nodes import Node, fmath, vmath

_PARTS = ("X", "Y", "Z", "Offset")
POLYNOMIAL_INPUTS = (
    ("Polynomial", "NodeSocketBool", {"default_value": False}),
    ("Polynomial One Step", "NodeSocketBool", {"default_value": False}),
    ("Polynomial Centre", "NodeSocketFloat", {"default_value": 0.0}),
    ("Polynomial Start Offset", "NodeSocketFloat", {"default_value": 0.0}),
    ("Polynomial Start Slope", "NodeSocketFloat", {"default_value": 0.0}),
    *((f"Polynomial {power} {part}", "NodeSocketVector", None) for power in range(DEGREE + 1) for part in _PARTS),
)


def _multiply_add(a: object, b: object, c: object) -> Node:
    return Node("ShaderNodeVectorMath", {0: a, 1: b, 2: c}, {"operation": "MULTIPLY_ADD"})


def polynomial_nodes() -> tuple[dict[str, Node], str, str, str]:
    """The solve's nodes on ``position`` (the rest positions). Returns the nodes and the references
    of the emission point relative to the observer, its light-travel distance and its velocity
    (fraction of c)."""
    nodes: dict[str, Node] = {"kp_rest": Node("ShaderNodeSeparateXYZ", {"Vector": "position.Position"})}
    terms = []
    for power in range(DEGREE + 1):  # Q_i = X_i x + Y_i y + Z_i z + Offset_i (no Transform Point)
        term = f"group.Polynomial {power} Offset"
        for axis in "XYZ":
            nodes[f"kp_p{power}{axis}"] = _multiply_add(f"kp_rest.{axis}", f"group.Polynomial {power} {axis}", term)
            term = f"kp_p{power}{axis}.Vector"
        terms.append(term)
    # the start: uniform motion along the line that best follows the polynomial over the points' span
    nodes["kp_start_w"] = _multiply_add(terms[3], "group.Polynomial Start Slope", terms[1])
    nodes["kp_start_x"] = _multiply_add(terms[2], "group.Polynomial Start Offset", terms[0])
    nodes["kp_start_r"] = _multiply_add("kp_start_w.Vector", "group.Polynomial Centre", "kp_start_x.Vector")
    sigma = _closed_form(nodes, "kp_start", "kp_start_r.Vector", "kp_start_w.Vector")
    ends = []
    for step in range(STEPS):
        tag = f"kp{step}"
        nodes[f"{tag}_v"] = fmath("SUBTRACT", "group.Polynomial Centre", sigma)
        x, w = _horner(nodes, tag, f"{tag}_v", terms)
        nodes[f"{tag}_r"] = _multiply_add(w, sigma, x)
        sigma = _closed_form(nodes, tag, f"{tag}_r.Vector", w)
        ends.append((f"{tag}_r.Vector", sigma, w))
    one, last = ends[0], ends[-1]
    for name, kind, index in (("kp_r", "VECTOR", 0), ("kp_sigma", "FLOAT", 1), ("kp_step_w", "VECTOR", 2)):
        nodes[name] = Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Polynomial One Step", "False": last[index], "True": one[index]},
            {"input_type": kind},
        )
    # the emission point on the last step's uniform motion: r - sigma w
    nodes["kp_minus_sigma"] = fmath("MULTIPLY", "kp_sigma.Output", -1.0)
    nodes["kp_x"] = _multiply_add("kp_step_w.Output", "kp_minus_sigma", "kp_r.Output")
    # the velocity at the last sigma: Q_1 + 2 v (Q_2 + 3/2 v (Q_3 + ...)), the derivative by Horner's scheme
    nodes["kp_v"] = fmath("SUBTRACT", "group.Polynomial Centre", "kp_sigma.Output")
    velocity = terms[DEGREE]
    for power in range(DEGREE, 1, -1):
        nodes[f"kp_v{power}"] = fmath("MULTIPLY", "kp_v", power / (power - 1))
        nodes[f"kp_w{power}"] = _multiply_add(velocity, f"kp_v{power}", terms[power - 1])
        velocity = f"kp_w{power}.Vector"
    return nodes, "kp_x.Vector", "kp_sigma.Output", velocity


def _horner(nodes: dict[str, Node], tag: str, v: str, terms: list[str]) -> tuple[str, str]:
    """``x(v)`` and its derivative (the velocity) by Horner's scheme, the derivative alongside."""
    value, slope = terms[-1], terms[-1]
    for power in range(DEGREE - 1, -1, -1):
        if power < DEGREE - 1:
            nodes[f"{tag}_d{power}"] = _multiply_add(slope, v, value)
            slope = f"{tag}_d{power}.Vector"
        nodes[f"{tag}_h{power}"] = _multiply_add(value, v, terms[power])
        value = f"{tag}_h{power}.Vector"
    return value, slope


def _closed_form(nodes: dict[str, Node], tag: str, r: str, w: str) -> str:
    """``sigma`` of ``|r - sigma w| = sigma`` (uniform motion): the towards form ``(root - r.w) /
    (1 - w.w)`` with ``Folded``, else whichever of the two forms avoids cancellation per point."""
    nodes.update(
        {
            f"{tag}_a": vmath("DOT_PRODUCT", r, w),
            f"{tag}_q": vmath("DOT_PRODUCT", r, r),
            f"{tag}_ww": vmath("DOT_PRODUCT", w, w),
            f"{tag}_b": fmath("SUBTRACT", 1.0, f"{tag}_ww.Value"),
            f"{tag}_a2": fmath("MULTIPLY", f"{tag}_a.Value", f"{tag}_a.Value"),
            f"{tag}_disc": fmath("MULTIPLY_ADD", f"{tag}_b", f"{tag}_q.Value", f"{tag}_a2"),
            f"{tag}_root": fmath("SQRT", f"{tag}_disc"),
            f"{tag}_minus": fmath("SUBTRACT", f"{tag}_root", f"{tag}_a.Value"),
            f"{tag}_towards": fmath("DIVIDE", f"{tag}_minus", f"{tag}_b"),
            f"{tag}_plus": fmath("ADD", f"{tag}_root", f"{tag}_a.Value"),
            f"{tag}_away": fmath("DIVIDE", f"{tag}_q.Value", f"{tag}_plus"),
            f"{tag}_receding": Node(
                "FunctionNodeCompare",
                {"A": f"{tag}_a.Value", "B": 0.0},
                {"data_type": "FLOAT", "operation": "GREATER_THAN"},
            ),
            f"{tag}_per_point": Node(
                "GeometryNodeSwitch",
                {"Switch": f"{tag}_receding.Result", "False": f"{tag}_towards", "True": f"{tag}_away"},
                {"input_type": "FLOAT"},
            ),
            # a single value: only the side chosen is computed
            f"{tag}_sigma": Node(
                "GeometryNodeSwitch",
                {"Switch": "group.Folded", "False": f"{tag}_per_point.Output", "True": f"{tag}_towards"},
                {"input_type": "FLOAT"},
            ),
        }
    )
    return f"{tag}_sigma.Output"
