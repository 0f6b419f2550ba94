"""Keyframed motion that one polynomial in time covers over the window of its retarded times
(``physics/polynomial_motion.py``; ``keyframed.py`` decides): the modifier's small solve, linked by
``keyframed_nodes.py`` under its ``Keyframed`` switch when ``Polynomial`` is on. No interval is read
per point (no Sample Index) and no verdict is taken over the points: ``keyframed.py`` checked in
Python that the polynomial follows the sampled motion to its rounding and that the steps converge.

Per point: ``P_i = C_i p`` (multiply-adds on the rest position's parts, the columns single values),
the closed form of uniform motion through ``P_0`` at the window's centre with velocity ``P_1 / half``
(``|r - sigma w| = sigma``), then Newton steps on ``|x(u)|^2 - sigma^2`` (one with ``Polynomial One
Step``, which ``keyframed.py`` sets where one converges: ``polynomial_motion.newton_steps``; else
NEWTON_STEPS), ``x`` and its rate by Horner's scheme; the emission point moved to the last ``sigma``
along the velocity there.
"""

from __future__ import annotations

from ...physics.polynomial_motion import DEGREE, NEWTON_STEPS
from ..common.nodes import Node, fmath, vmath

_PARTS = ("X", "Y", "Z", "Offset")
POLYNOMIAL_INPUTS = (
    ("Polynomial", "NodeSocketBool", {"default_value": False}),
    ("Polynomial One Step", "NodeSocketBool", {"default_value": False}),
    ("Polynomial Centre", "NodeSocketFloat", {"default_value": 0.0}),
    ("Polynomial Rate", "NodeSocketFloat", {"default_value": 1.0}),
    *((f"Polynomial {power} {part}", "NodeSocketVector", None) for power in range(DEGREE + 1) for part in _PARTS),
)


def _multiply_add(a: object, b: object, c: object) -> Node:
    return Node("ShaderNodeVectorMath", {0: a, 1: b, 2: c}, {"operation": "MULTIPLY_ADD"})


def polynomial_nodes(step_nodes: object) -> tuple[dict[str, Node], str, str, str]:
    """The solve's nodes on ``position`` (the rest positions); ``step_nodes(nodes, tag, sigma, x,
    rate, scale)`` adds the closed form of uniform motion (``keyframed_nodes._step``). Returns the
    nodes and the references of the emission point relative to the observer, its light-travel
    distance and its velocity (fraction of c)."""
    nodes: dict[str, Node] = {
        "kp_minus_rate": fmath("MULTIPLY", "group.Polynomial Rate", -1.0),
        "kp_offset": fmath("MULTIPLY", "group.Polynomial Centre", "group.Polynomial Rate"),
        "kp_rest": Node("ShaderNodeSeparateXYZ", {"Vector": "position.Position"}),
    }
    terms = []
    for power in range(DEGREE + 1):  # P_i = X_i x + Y_i y + Z_i z + Offset_i (no Transform Point)
        term = f"group.Polynomial {power} Offset"
        for axis in "XYZ":
            nodes[f"kp_p{power}{axis}"] = _multiply_add(f"kp_rest.{axis}", f"group.Polynomial {power} {axis}", term)
            term = f"kp_p{power}{axis}.Vector"
        terms.append(term)
    # the start: uniform motion through P_0 at the centre with the velocity P_1 / half
    sigma = step_nodes(nodes, "kp_start", "group.Polynomial Centre", terms[0], terms[1], "group.Polynomial Rate")
    ends = []
    for step in range(NEWTON_STEPS):
        ends.append(_newton_step(nodes, f"kp{step}", sigma, terms))
        sigma = ends[-1][1]
    one, last = ends[0], ends[-1]
    for name, kind, index in (("kp_x", "VECTOR", 0), ("kp_sigma", "FLOAT", 1), ("kp_w", "VECTOR", 2)):
        nodes[name] = Node(
            "GeometryNodeSwitch",
            {"Switch": "group.Polynomial One Step", "False": last[index], "True": one[index]},
            {"input_type": kind},
        )
    return nodes, "kp_x.Output", "kp_sigma.Output", "kp_w.Output"


def _newton_step(nodes: dict[str, Node], tag: str, sigma: str, terms: list[str]) -> tuple[str, str, str]:
    """One Newton step on ``|x(u)|^2 - sigma^2`` from ``sigma``, ``x`` and its rate by Horner's scheme.
    Returns the references of the emission point at the new ``sigma`` (``x`` moved along the velocity
    there), the new ``sigma`` and the velocity (fraction of c)."""
    u = f"{tag}_u"
    nodes[u] = fmath("MULTIPLY_ADD", sigma, "kp_minus_rate", "kp_offset")
    value, slope = terms[-1], terms[-1]
    for power in range(DEGREE - 1, -1, -1):  # Horner's scheme, the derivative alongside
        if power < DEGREE - 1:
            nodes[f"{tag}_d{power}"] = _multiply_add(slope, u, value)
            slope = f"{tag}_d{power}.Vector"
        nodes[f"{tag}_v{power}"] = _multiply_add(value, u, terms[power])
        value = f"{tag}_v{power}.Vector"
    x = value
    nodes.update(
        {
            f"{tag}_xx": vmath("DOT_PRODUCT", x, x),
            f"{tag}_xr": vmath("DOT_PRODUCT", x, slope),
            f"{tag}_ss": fmath("MULTIPLY", sigma, sigma),
            f"{tag}_num": fmath("SUBTRACT", f"{tag}_ss", f"{tag}_xx.Value"),
            f"{tag}_den": fmath("MULTIPLY_ADD", f"{tag}_xr.Value", "group.Polynomial Rate", sigma),
            f"{tag}_m": fmath("DIVIDE", f"{tag}_num", f"{tag}_den"),
            f"{tag}_sigma": fmath("MULTIPLY_ADD", f"{tag}_m", -0.5, sigma),
            # the velocity (fraction of c) where the step evaluated; the emission point moved to the
            # new sigma along it: x(sigma') = x - (sigma' - sigma) w, sigma' - sigma = -m / 2
            f"{tag}_w": vmath("SCALE", slope, scale="group.Polynomial Rate"),
            f"{tag}_half_m": fmath("MULTIPLY", f"{tag}_m", 0.5),
            f"{tag}_x": _multiply_add(f"{tag}_w.Vector", f"{tag}_half_m", x),
        }
    )
    return f"{tag}_x.Vector", f"{tag}_sigma", f"{tag}_w.Vector"
