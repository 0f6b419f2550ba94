"""Spectral mode in the materials: every colour as its spectral radiance at the pass's three
rest-frame wavelengths (``physics/spectral_render.py``).

``Relativity Spectral Colour`` turns the colour that feeds an emission or BSDF input into three
spectral values, one per channel, from constants that ``spectral_render`` (glue) writes into the
settings group before each pass:

- a reflectance ``rgb`` (BSDF colours): ``R rgb``, rows ``Reflectance 0..2`` (the up-sampling basis);
- an emitted ``rgb`` (emission colours, the world): ``E rgb``, rows ``Emission 0..2``;
- a blackbody at ``T`` with the luminance ``Y`` of the colour Blender's Blackbody node gives:
  ``Y B(mu, T) / Y_B(T)`` per nm, with ``ln B = ln(c1 / pi / mu^5) - x - ln(1 - exp(-x))``,
  ``x = c2 / (mu T)`` (Planck's law in log form, finite for any ``x``), the per-channel constants
  ``Planck Prefactors`` (``ln(c1 / pi / mu^5) + ln 1e-9``) and ``Planck Numerators`` (``c2 / mu``),
  and ``ln Y_B(T)`` from the blackbody lookup table's alpha.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ...physics import spectral_render
from ..common import names
from ..common.nodes import Group, Node, fmath, group_node, vmath

if TYPE_CHECKING:
    from collections.abc import Sequence
from . import lut_images

SPECTRAL_COLOUR = names.SPECTRAL_COLOUR_GROUP
# The constants colour.colorimetry.planck_law uses (as physics.spectral does).
PLANCK_C1, PLANCK_C2 = 3.741771e-16, 0.014388
LN10 = math.log(10.0)
EXP_LIMIT = 80.0

ROWS = tuple(f"Reflectance {i}" for i in range(3)) + tuple(f"Emission {i}" for i in range(3))
VECTORS = ROWS + ("Planck Prefactors", "Planck Numerators")


# The inputs of every colour group: a colour, its blackbody temperature and what it is; and the
# links that hand a group's own inputs on to an inner colour group.
COLOUR_INPUTS = (
    ("Color", "NodeSocketColor", (1.0, 1.0, 1.0, 1.0)),
    ("Temperature", "NodeSocketFloat", 5762.0),
    ("Is Blackbody", "NodeSocketFloat", 0.0),
    ("Is Emission", "NodeSocketFloat", 0.0),
)
COLOUR_LINKS = {name: f"group.{name}" for name, _kind, _default in COLOUR_INPUTS}


def settings_nodes() -> tuple[dict[str, Node], tuple[tuple[str, str, str], ...]]:
    """Nodes of the settings group for the spectral pass (outputs named like the nodes)."""
    nodes = {"Spectral Pass": Node("ShaderNodeValue")}
    nodes.update({name: Node("ShaderNodeCombineXYZ", {0: 0.0, 1: 0.0, 2: 0.0}) for name in VECTORS})
    outputs = (("Spectral Pass", "NodeSocketFloat", "Spectral Pass"),)
    outputs += tuple((name, "NodeSocketVector", name) for name in VECTORS)
    return nodes, outputs


def pass_values(wavelengths_nm: Sequence[float] | None) -> dict[str, Any]:
    """Settings values for a spectral pass at three rest-frame wavelengths (nm), or the fast mode's
    (``wavelengths_nm`` None)."""
    if wavelengths_nm is None:
        return {"Spectral Pass": 0.0, **{name: (0.0, 0.0, 0.0) for name in VECTORS}}
    mu = np.asarray(wavelengths_nm, dtype=np.float64)
    reflectance = spectral_render.reflectance_matrix(mu)
    emission = spectral_render.emission_matrix(mu)
    metres = mu * 1e-9
    values = {"Spectral Pass": 1.0}
    values.update({f"Reflectance {i}": tuple(reflectance[i]) for i in range(3)})
    values.update({f"Emission {i}": tuple(emission[i]) for i in range(3)})
    values["Planck Prefactors"] = tuple(np.log(PLANCK_C1 / math.pi / metres**5) + math.log(1e-9))
    values["Planck Numerators"] = tuple(PLANCK_C2 / metres)
    return {
        name: tuple(float(v) for v in value) if isinstance(value, tuple) else value for name, value in values.items()
    }


def spectral_colour_group() -> Group:
    """Spectral values of ``Color`` at the pass's wavelengths (see the module docstring)."""
    scale, offset = lut_images.texture_u_scale_offset(lut_images.BLACKBODY_LOG10_RANGE)
    nodes = {
        "settings": group_node(names.SETTINGS_GROUP),
        "luminance": vmath("DOT_PRODUCT", "group.Color", (0.2126729, 0.7151522, 0.0721750)),
        "safe_t": fmath("MAXIMUM", "group.Temperature", 1.0),
        "ln_t": fmath("LOGARITHM", "safe_t", math.e),
        "u_t": fmath("MULTIPLY_ADD", "ln_t", scale / LN10, offset),
        "uv_t": Node("ShaderNodeCombineXYZ", {0: "u_t", 1: 0.5, 2: 0.0}),
        "lut_t": Node(
            "ShaderNodeTexImage",
            {"Vector": "uv_t"},
            {"image": lut_images.BLACKBODY_LUT_NAME, "interpolation": "Linear", "extension": "EXTEND"},
        ),
        "safe_y": fmath("MAXIMUM", "luminance.Value", 1e-30),
        "ln_y": fmath("LOGARITHM", "safe_y", math.e),
        "ln_scale": fmath("SUBTRACT", "ln_y", "lut_t.Alpha"),  # ln(Y / Y_B(T))
        "prefactors": Node("ShaderNodeSeparateXYZ", {0: "settings.Planck Prefactors"}),
        "numerators": Node("ShaderNodeSeparateXYZ", {0: "settings.Planck Numerators"}),
    }
    for i, axis in enumerate("XYZ"):
        nodes[f"dot_r{i}"] = vmath("DOT_PRODUCT", f"settings.Reflectance {i}", "group.Color")
        nodes[f"dot_e{i}"] = vmath("DOT_PRODUCT", f"settings.Emission {i}", "group.Color")
        # ln B_i - ln Y_B + ln Y, with x = c2 / (mu_i T): prefactor - x - ln(1 - exp(-x))
        nodes[f"x{i}"] = fmath("DIVIDE", f"numerators.{axis}", "safe_t")
        nodes[f"neg_x{i}"] = fmath("MULTIPLY", f"x{i}", -1.0)
        nodes[f"exp_neg_x{i}"] = fmath("EXPONENT", f"neg_x{i}")
        nodes[f"one_minus{i}"] = fmath("SUBTRACT", 1.0, f"exp_neg_x{i}")
        nodes[f"safe_one_minus{i}"] = fmath("MAXIMUM", f"one_minus{i}", 1e-30)
        nodes[f"ln_one_minus{i}"] = fmath("LOGARITHM", f"safe_one_minus{i}", math.e)
        nodes[f"ln_b{i}"] = fmath("SUBTRACT", f"prefactors.{axis}", f"x{i}")
        nodes[f"ln_b_full{i}"] = fmath("SUBTRACT", f"ln_b{i}", f"ln_one_minus{i}")
        nodes[f"ln_value{i}"] = fmath("ADD", f"ln_b_full{i}", "ln_scale")
        nodes[f"ln_value_safe{i}"] = fmath("MINIMUM", f"ln_value{i}", EXP_LIMIT)
        nodes[f"bb{i}"] = fmath("EXPONENT", f"ln_value_safe{i}")
    nodes.update(
        {
            "reflectance": Node("ShaderNodeCombineXYZ", {0: "dot_r0.Value", 1: "dot_r1.Value", 2: "dot_r2.Value"}),
            "emission": Node("ShaderNodeCombineXYZ", {0: "dot_e0.Value", 1: "dot_e1.Value", 2: "dot_e2.Value"}),
            "blackbody": Node("ShaderNodeCombineXYZ", {0: "bb0", 1: "bb1", 2: "bb2"}),
            "rgb": Node(
                "ShaderNodeMix",
                {"Factor": "group.Is Emission", 4: "reflectance", 5: "emission"},
                {"data_type": "VECTOR"},
            ),
            "out": Node(
                "ShaderNodeMix",
                {"Factor": "group.Is Blackbody", 4: "rgb.Result", 5: "blackbody"},
                {"data_type": "VECTOR"},
            ),
        }
    )
    return Group(
        SPECTRAL_COLOUR,
        "ShaderNodeTree",
        COLOUR_INPUTS,
        (("Color", "NodeSocketColor", "out.Result"),),
        nodes,
    )


def volume_colour_group() -> Group:
    """A volume shader's colour (``volumes.attach_colours``): unchanged outside the spectral passes
    (volumes write no AOVs: the compositor shifts their pixels), its spectral values in them."""
    nodes = {
        "settings": group_node(names.SETTINGS_GROUP),
        "spectral": group_node(SPECTRAL_COLOUR, COLOUR_LINKS),
        "out": Node(
            "ShaderNodeMix",
            {"Factor": "settings.Spectral Pass", 4: "group.Color", 5: "spectral"},
            {"data_type": "VECTOR"},
        ),
    }
    return Group(
        names.VOLUME_COLOUR_GROUP,
        "ShaderNodeTree",
        COLOUR_INPUTS,
        (("Color", "NodeSocketColor", "out.Result"),),
        nodes,
    )
