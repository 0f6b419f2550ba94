"""Per receiving point: the light node tree of the stand-in lamps that light a moving object for a
lamp at rest (Weiskopf et al. eq. 18; ``physics/lamp_doppler.py``, docs/lamp-doppler.md).

A point ``x`` of an object moving with ``beta`` sees a lamp at rest, in its own frame, along the
aberrated direction ``-k'`` from ``lamp + u bhat`` (``lamp_doppler.apparent_lamp_offset``), a point
on the line through the lamp parallel to ``beta``. ``lamps_on_moving_objects.py`` puts a few copies
of the lamp on that line (offsets ``u_i``); this group, in each copy's light node tree, evaluates
per receiving point (Cycles' SVM nodes, no OSL):

- ``x = P + I t`` (``P`` the point on the copy, ``I`` Geometry > Incoming, from the light toward
  the point, ``t`` Light Path > Ray Length); ``P - u_i bhat`` the matching point of the lamp itself;
- ``k``, ``r`` from there to ``x``, ``D = gamma (1 - beta . k)``, ``u = r ((1 - gamma) (k . bhat) +
  gamma |beta|)``, and the copy's linear weight ``w`` between its neighbours' offsets;
- strength ``w (t / r)^2 t / (D r)``: the point's apparent lamp ``x - D r k'`` lies between the two
  copies around it on their line, at ``sum w_i P_i``, so ``-k' = sum w_i (t_i / (D r)) e_i`` (``e_i``
  toward copy ``i``) and Cycles' ``cos_i / t_i^2`` toward them (on the rest normal) sums to
  ``cos(alpha') / r^2`` exactly, with the point's own aberrated direction (but near the terminator,
  where one copy's cosine is clamped at 0); a spot's cone of the true ``k``
  (the copies are point lamps); an area lamp's emitter cosine of ``k`` over the copy's;
- colour ``exp(s l + q l^2)`` per channel, ``l = ln(D / D_c)``: eq. 18's colour factor
  (``lamp_doppler.lamp_rgb_factor``, ``D^2`` with the searchlight alone), relative to its value at
  the centre's ``D_c`` (the copy's colour), fitted through three values of ``D`` over the object;
- ``Scale``: the inverse of the factor on the copy's own power, which is set for renderers that do
  not run light trees (EEVEE: the stand-ins' plain powers then sum to the lamp's eq. 18 light at
  the object's centre, one ``D`` and direction per object).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..common import compat, names, nodes

if TYPE_CHECKING:
    from bpy.types import Light, NodeTree

GROUP = names.LAMP_STAND_IN_GROUP
NODE = names.LAMP_STAND_IN_GROUP
FAR = 1.0e6  # the offset "neighbour" of an end copy: it takes all beyond its end


def _group_spec():
    fmath, vmath = nodes.fmath, nodes.vmath
    return nodes.Group(
        name=GROUP,
        tree_type="ShaderNodeTree",
        inputs=(
            ("Offset", "NodeSocketFloat", 0.0),
            ("Previous", "NodeSocketFloat", -FAR),
            ("Next", "NodeSocketFloat", FAR),
            ("Direction", "NodeSocketVector", (1.0, 0.0, 0.0)),
            ("Speed", "NodeSocketFloat", 0.0),
            ("Gamma", "NodeSocketFloat", 1.0),
            ("Log Doppler", "NodeSocketFloat", 0.0),
            ("Slope", "NodeSocketVector", (0.0, 0.0, 0.0)),
            ("Curvature", "NodeSocketVector", (0.0, 0.0, 0.0)),
            ("Axis", "NodeSocketVector", (0.0, 0.0, -1.0)),
            ("Cone", "NodeSocketFloat", -2.0),
            ("Blend", "NodeSocketFloat", 1.0e-6),
            ("Lambert", "NodeSocketFloat", 0.0),
            ("Scale", "NodeSocketFloat", 1.0),
        ),
        outputs=(("Color", "NodeSocketColor", "colour"), ("Strength", "NodeSocketFloat", "strength")),
        nodes={
            "geometry": nodes.Node("ShaderNodeNewGeometry"),
            "path": nodes.Node("ShaderNodeLightPath"),
            "toward": vmath("SCALE", "geometry.Incoming", scale="path.Ray Length"),
            "x": vmath("ADD", "geometry.Position", "toward"),
            "shift": vmath("SCALE", "group.Direction", scale="group.Offset"),
            "element": vmath("SUBTRACT", "geometry.Position", "shift"),
            "d": vmath("SUBTRACT", "x", "element"),
            "r": vmath("LENGTH", "d"),
            "k": vmath("NORMALIZE", "d"),
            "mu": vmath("DOT_PRODUCT", "k", "group.Direction"),
            # D = gamma (1 - |beta| mu)
            "beta_mu": fmath("MULTIPLY", "group.Speed", "mu.Value"),
            "one_minus": fmath("SUBTRACT", 1.0, "beta_mu"),
            "doppler": fmath("MULTIPLY", "group.Gamma", "one_minus"),
            # u = r ((1 - gamma) mu + gamma |beta|)
            "one_minus_gamma": fmath("SUBTRACT", 1.0, "group.Gamma"),
            "gamma_beta": fmath("MULTIPLY", "group.Gamma", "group.Speed"),
            "slope_u": fmath("MULTIPLY_ADD", "one_minus_gamma", "mu.Value", "gamma_beta"),
            "u": fmath("MULTIPLY", "r.Value", "slope_u"),
            # linear weight between the neighbours' offsets
            "above_previous": fmath("SUBTRACT", "u", "group.Previous"),
            "span_previous": fmath("SUBTRACT", "group.Offset", "group.Previous"),
            "rising": fmath("DIVIDE", "above_previous", "span_previous"),
            "below_next": fmath("SUBTRACT", "group.Next", "u"),
            "span_next": fmath("SUBTRACT", "group.Next", "group.Offset"),
            "falling": fmath("DIVIDE", "below_next", "span_next"),
            "weight": fmath("MINIMUM", "rising", "falling", clamp=True),
            # (t / r)^2: Cycles divides by the copy's t^2, eq. 18 by the lamp's r^2
            "ratio": fmath("DIVIDE", "path.Ray Length", "r.Value"),
            "ratio2": fmath("MULTIPLY", "ratio", "ratio"),
            # a spot's cone, of the true direction k (Cycles: smoothstep over the blend)
            "cos_axis": vmath("DOT_PRODUCT", "k", "group.Axis"),
            "cone_end": fmath("ADD", "group.Cone", "group.Blend"),
            "mask": nodes.Node(
                "ShaderNodeMapRange",
                {"Value": "cos_axis.Value", "From Min": "group.Cone", "From Max": "cone_end"},
                {"interpolation_type": "SMOOTHSTEP", "clamp": True},
            ),
            # an area lamp: emitter cosine of k over the copy's (a Lambertian panel)
            "true_cos": fmath("MAXIMUM", "cos_axis.Value", 0.0),
            "copy_cos_raw": vmath("DOT_PRODUCT", "geometry.Incoming", "group.Axis"),
            "copy_cos": fmath("MAXIMUM", "copy_cos_raw.Value", 1.0e-4),
            "emitter_ratio": fmath("DIVIDE", "true_cos", "copy_cos"),
            "emitter_less_one": fmath("SUBTRACT", "emitter_ratio", 1.0),
            "emitter": fmath("MULTIPLY_ADD", "group.Lambert", "emitter_less_one", 1.0),
            # t / (D r): the two stand-ins' directions, so weighted, sum to -k' exactly
            "apparent_distance": fmath("MULTIPLY", "doppler", "r.Value"),
            "direction_weight": fmath("DIVIDE", "path.Ray Length", "apparent_distance"),
            "ratio3": fmath("MULTIPLY", "ratio2", "direction_weight"),
            "weighted": fmath("MULTIPLY", "weight", "ratio3"),
            "masked": fmath("MULTIPLY", "weighted", "mask.Result"),
            "unscaled": fmath("MULTIPLY", "masked", "emitter"),
            "strength": fmath("MULTIPLY", "unscaled", "group.Scale"),
            # colour: exp(s l + q l^2), l = ln D - ln D_c
            "log_doppler": fmath("LOGARITHM", "doppler", math.e),
            "l": fmath("SUBTRACT", "log_doppler", "group.Log Doppler"),
            "poly": nodes.Node(
                "ShaderNodeVectorMath", {0: "group.Curvature", 1: "l", 2: "group.Slope"}, {"operation": "MULTIPLY_ADD"}
            ),
            "exponent": vmath("MULTIPLY", "poly", "l"),
            "channels": nodes.Node("ShaderNodeSeparateXYZ", {0: "exponent"}),
            "red": fmath("EXPONENT", "channels.X"),
            "green": fmath("EXPONENT", "channels.Y"),
            "blue": fmath("EXPONENT", "channels.Z"),
            "colour": nodes.Node("ShaderNodeCombineXYZ", {0: "red", 1: "green", 2: "blue"}),
        },
    )


def group() -> NodeTree:
    return nodes.ensure_group(_group_spec(), names.GROUP_VERSION_KEY, names.LAMP_STAND_IN_GROUP_VERSION)


def make_tree(light: Light) -> None:
    """Replace ``light``'s node tree by the group -> Emission -> Light Output."""
    tree = compat.empty_light_tree(light)
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group()
    node.name = node.label = NODE
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.location = (250.0, 0.0)
    output = tree.nodes.new("ShaderNodeOutputLight")
    output.location = (450.0, 0.0)
    tree.links.new(node.outputs["Color"], emission.inputs["Color"])
    tree.links.new(node.outputs["Strength"], emission.inputs["Strength"])
    tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])


def inputs(light: Light) -> dict:
    """The group node's inputs in ``light``'s tree, by name."""
    return {socket.name: socket for socket in light.node_tree.nodes[NODE].inputs}


def colour_fit(dopplers: tuple[float, float, float], factors: list) -> tuple[tuple, tuple]:
    """``(slope, curvature)`` per channel of ``ln(f(D) / f(D_c)) = s l + q l^2`` through the three
    ``(D, f)`` (low, centre, high; ``l = ln(D / D_c)``); 0 for a channel the lamp does not emit."""
    low, centre, high = (math.log(value) for value in dopplers)
    a, b = low - centre, high - centre
    slope, curvature = [], []
    for channel in range(3):
        values = [float(factor[channel]) for factor in factors]
        if min(values) <= 0.0 or abs(a - b) < 1e-12 or a == 0.0 or b == 0.0:
            slope.append(0.0)
            curvature.append(0.0)
            continue
        fa, fb = (math.log(values[i] / values[1]) for i in (0, 2))
        q = (fa / a - fb / b) / (a - b)
        slope.append(fa / a - q * a)
        curvature.append(q)
    return tuple(slope), tuple(curvature)
