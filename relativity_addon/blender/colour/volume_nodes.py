"""The volume blackbody group: a Principled Volume's blackbody seen at ``D T`` (``volumes.py`` puts
it in; the model and the measurements are in its docstring and docs/spectral-model.md)."""

from __future__ import annotations

import math

from ..common import names
from ..common.nodes import Group, Node, fmath, group_node, vmath
from . import materials, spectral_nodes

GROUP = names.VOLUME_BLACKBODY_GROUP
SIGMA = 5.670373e-8 * 1e-6 / math.pi  # Cycles' Stefan-Boltzmann factor for the Principled Volume


def volume_blackbody_group() -> Group:
    """``Color``: the emission to add to the volume (``X - E`` for camera rays on the exact camera's
    path under the visible rule, 0 otherwise; in a spectral pass ``E``'s spectral values); ``Done``:
    1 where the boundary marks the pixel as shifted; ``Intensity``, ``Temperature`` and ``Tint``:
    the Principled Volume's Blackbody Intensity (0 in a spectral pass), Temperature and Blackbody
    Tint, which for camera rays under the bolometric rule (temperature grids) make Cycles' own
    emission the shifted one: its Temperature times ``D``, its tint times the rule's gain."""
    nodes = {
        "settings": group_node(materials.SETTINGS),
        # Cycles' T: the Temperature input times max(grid, 0) where the object has the grid
        # (an Attribute node's Fac and Alpha; Grid Alpha 0: no grid, T is the input)
        "grid_clamped": fmath("MAXIMUM", "group.Grid", 0.0),
        "grid_minus_one": fmath("SUBTRACT", "grid_clamped", 1.0),
        "grid_factor": fmath("MULTIPLY_ADD", "group.Grid Alpha", "grid_minus_one", 1.0),
        "temperature": fmath("MULTIPLY", "group.Temperature", "grid_factor"),
        # the volume's own emission: tint sigma mix(1, T^4, intensity) B(T)
        "t4": fmath("POWER", "temperature", 4.0),
        "t4m1": fmath("SUBTRACT", "t4", 1.0),
        "mixed": fmath("MULTIPLY_ADD", "group.Intensity", "t4m1", 1.0),
        "sigma": fmath("MULTIPLY", "mixed", SIGMA),
        "strength": fmath("MULTIPLY", "sigma", "group.Tint"),
        "planck": Node("ShaderNodeBlackbody", {"Temperature": "temperature"}),
        "rest": vmath("SCALE", "planck.Color", scale="strength"),
        # ln D = ln(1 - beta_o . k) - ln(1 - beta_o^2) / 2: the observer's factor only (a volume at
        # rest; the materials' factor group also reads the emitter's velocity attribute, which a
        # volume shader does not read as 0 where it is missing: measured ln D != 0 at rest)
        "geometry": Node("ShaderNodeNewGeometry"),
        "bo_k": vmath("DOT_PRODUCT", "settings.Observer Beta", "geometry.Incoming"),
        "bo_bo": vmath("DOT_PRODUCT", "settings.Observer Beta", "settings.Observer Beta"),
        "ns_bo_k": fmath("SUBTRACT", 1.0, "bo_k.Value"),
        "one_bo_k": fmath("MAXIMUM", "ns_bo_k", 1e-12),
        "ns_bo2": fmath("SUBTRACT", 1.0, "bo_bo.Value"),
        "one_bo2": fmath("MAXIMUM", "ns_bo2", 1e-12),
        "ln_num": fmath("LOGARITHM", "one_bo_k", math.e),
        "ln_go2": fmath("LOGARITHM", "one_bo2", math.e),
        "ln_d": fmath("MULTIPLY_ADD", "ln_go2", -0.5, "ln_num"),
        # what a blackbody emitter of that colour emits for camera rays (as the materials' Doppler
        # colour group): the blackbody at D T with the rest luminance times exp(E)
        "shift": group_node(materials.BLACKBODY_SHIFT, {"Temperature": "temperature", "Log Doppler": "ln_d"}),
        "luminance": vmath("DOT_PRODUCT", "rest", materials.LUMINANCE_WEIGHTS),
        "shifted": vmath("SCALE", "shift.Color", scale="luminance.Value"),
        "base": Node(
            "ShaderNodeMix", {"Factor": "settings.Use Doppler", 4: "rest", 5: "shifted"}, {"data_type": "VECTOR"}
        ),
        "power": fmath("SUBTRACT", "settings.Power of D", "settings.Camera Power"),
        "power_term": fmath("MULTIPLY", "power", "ln_d"),
        "log_gain": fmath("MULTIPLY_ADD", "shift.Log Luminance Ratio", "settings.Spectral Searchlight", "power_term"),
        "safe_log_gain": fmath("MINIMUM", "log_gain", materials.EXP_LIMIT),
        "gain": fmath("EXPONENT", "safe_log_gain"),
        "visible_emitter": vmath("SCALE", "base.Result", scale="gain"),
        # the bolometric rule (temperature grids): Cycles' own emission at D T, times D^(p - 4)
        # over the camera's D^p_cam: log gain (4 SS + p - p_cam - 4 Use Doppler) ln D
        "d": fmath("EXPONENT", "ln_d"),
        "undoppled": fmath("SUBTRACT", 1.0, "settings.Use Doppler"),
        "d_used": fmath("MULTIPLY_ADD", "d", "settings.Use Doppler", "undoppled"),
        "dt": fmath("MULTIPLY", "temperature", "d_used"),
        "dt4": fmath("POWER", "dt", 4.0),
        "dt4m1": fmath("SUBTRACT", "dt4", 1.0),
        "dt_mixed": fmath("MULTIPLY_ADD", "group.Intensity", "dt4m1", 1.0),
        "ss4": fmath("MULTIPLY", "settings.Spectral Searchlight", 4.0),
        "bolometric_power": fmath("ADD", "ss4", "power"),
        "bolometric_exponent": fmath("MULTIPLY_ADD", "settings.Use Doppler", -4.0, "bolometric_power"),
        # only camera rays on the exact camera's path, never in a spectral pass
        "light_path": Node("ShaderNodeLightPath"),
        "fast": fmath("SUBTRACT", 1.0, "settings.Spectral Pass"),
        "camera_ray": fmath("MULTIPLY", "light_path.Is Camera Ray", "settings.Camera Path"),
        "fast_camera_ray": fmath("MULTIPLY", "camera_ray", "fast"),
        "switch": fmath("MULTIPLY", "fast_camera_ray", "group.Fast Part"),  # 0: inside a node group
        # the visible rule: X - E added to Cycles' own E (which the group's E matches to 2e-4 for
        # a constant or node-driven T). The bolometric rule (a grid, Bolometric 1) is Cycles' own
        # emission at D T: the Principled Volume itself shifts it (the Temperature and Tint outputs),
        # reading the grid as it does at rest (Blender 5.2 reads a grid in the Principled Volume
        # otherwise than an Attribute node does, sigma T^4 2.4-2.9 % apart), and under 5.x's null
        # scattering Cycles evaluates the volume shader at 128^3 x 16 points per render for its
        # majorant grid: no second grid read and Blackbody node there (docs/performance.md)
        "visible_part": fmath("SUBTRACT", 1.0, "group.Bolometric"),
        "visible_switch": fmath("MULTIPLY", "switch", "visible_part"),
        "difference": vmath("SUBTRACT", "visible_emitter", "rest"),
        "fast_out": vmath("SCALE", "difference", scale="visible_switch"),
        # per point as few nodes as Cycles leaves after folding the settings' constants: D as
        # gamma (1 - beta_o . k), raised to the switch (D or 1), to Use Doppler and to the gain's
        # exponent (4 SS + p - p_cam - 4 Use Doppler; 0 with the searchlight on: no node)
        "gamma_o": fmath("POWER", "one_bo2", -0.5),
        "d_direct": fmath("MULTIPLY", "ns_bo_k", "gamma_o"),
        "bolometric_switch": fmath("MULTIPLY", "switch", "group.Bolometric"),
        "d_switched": fmath("POWER", "d_direct", "bolometric_switch"),
        "d_shifted": fmath("POWER", "d_switched", "settings.Use Doppler"),
        "camera_temperature": fmath("MULTIPLY", "group.Temperature", "d_shifted"),
        "tint_gain": fmath("POWER", "d_switched", "bolometric_exponent"),
        "safe_tint_gain": fmath("MINIMUM", "tint_gain", math.exp(materials.EXP_LIMIT)),
        "camera_tint": fmath("MULTIPLY", "group.Tint", "safe_tint_gain"),
        # a spectral pass, every ray: E's spectral values (the blackbody at T with E's luminance, as
        # a surface blackbody's) instead of Cycles' RGB E, which the Intensity output switches off
        # (adding the difference instead loses the Wien tail: E's RGB is ~1e3 times its values there)
        # With a grid, camera rays: the spectrum whose shift is the bolometric rule, E's times
        # mix(1, (D T)^4, I) / mix(1, T^4, I) Y_B(T) / Y_B(D T) (in logs); other rays: E up-sampled
        # as an RGB emitter (no Wien tail to explode where the grid fades to 0 K)
        "bolometric_camera": fmath("MULTIPLY", "group.Bolometric", "camera_ray"),
        "grid_light": fmath("SUBTRACT", "group.Bolometric", "bolometric_camera"),
        "spectral_blackbody": fmath("SUBTRACT", 1.0, "grid_light"),
        "spectral": group_node(
            spectral_nodes.SPECTRAL_COLOUR,
            {"Color": "rest", "Temperature": "temperature", "Is Blackbody": "spectral_blackbody", "Is Emission": 1.0},
        ),
        "safe_dt_mixed": fmath("MAXIMUM", "dt_mixed", 1e-30),
        "safe_mixed": fmath("MAXIMUM", "mixed", 1e-30),
        "ln_dt_mixed": fmath("LOGARITHM", "safe_dt_mixed", math.e),
        "ln_mixed": fmath("LOGARITHM", "safe_mixed", math.e),
        "ln_total_ratio": fmath("SUBTRACT", "ln_dt_mixed", "ln_mixed"),
        "ln_spectral_ratio": fmath("SUBTRACT", "ln_total_ratio", "shift.Log Luminance Ratio"),
        "spectral_log_gain": fmath("MULTIPLY", "ln_spectral_ratio", "bolometric_camera"),
        "spectral_safe_gain": fmath("MINIMUM", "spectral_log_gain", materials.EXP_LIMIT),
        "spectral_gain": fmath("EXPONENT", "spectral_safe_gain"),
        "spectral_scale": fmath("MULTIPLY", "spectral_gain", "settings.Spectral Pass"),
        "spectral_out": vmath("SCALE", "spectral", scale="spectral_scale"),
        "out": vmath("ADD", "fast_out", "spectral_out"),
        # Cycles' own blackbody off in a spectral pass
        "intensity": fmath("MULTIPLY", "group.Intensity", "fast"),
        # the boundary where a camera ray enters the volume
        "front": fmath("SUBTRACT", 1.0, "geometry.Backfacing"),
        "done": fmath("MULTIPLY", "switch", "front"),
    }
    return Group(
        GROUP,
        "ShaderNodeTree",
        (
            ("Temperature", "NodeSocketFloat", 1000.0),
            ("Intensity", "NodeSocketFloat", 1.0),
            ("Tint", "NodeSocketFloat", 1.0),
            ("Grid", "NodeSocketFloat", 1.0),  # the temperature grid's value (an Attribute node's Fac)
            ("Grid Alpha", "NodeSocketFloat", 0.0),  # 1 where the object has that grid
            ("Bolometric", "NodeSocketFloat", 0.0),  # 1: Cycles' own emission at D T (temperature grids)
            ("Fast Part", "NodeSocketFloat", 1.0),  # 0: the spectral passes' part only (no done mask there)
        ),
        (
            ("Color", "NodeSocketColor", "out"),
            ("Done", "NodeSocketFloat", "done"),
            ("Intensity", "NodeSocketFloat", "intensity"),
            ("Temperature", "NodeSocketFloat", "camera_temperature"),
            ("Tint", "NodeSocketFloat", "camera_tint"),
        ),
        nodes,
    )
