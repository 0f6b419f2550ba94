"""What of a lamp's own node tree its copies on moving objects carry (eq. 18), and what not.

The stand-ins of point, spot and area lamps render with the add-on's tree (``lamp_stand_ins.py``)
and a sun's copy keeps the lamp's tree with eq. 18's factor on its Color. So a lamp's tree is
carried when its Light Output shows one Emission node with an unlinked Strength and either an
unlinked Color (any RGB: the factor is taken for the lamp's Color times it, docs/lamp-doppler.md)
or a Blackbody at one temperature (times a constant). Anything else (a linked Strength: a Light
Falloff, a texture; a colour made by other nodes) is not, and the panel says so
(:func:`warnings`): the stand-ins emit without it, a sun's copy keeps it unshifted.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from ...physics import lamp_doppler
from ..common import compat
from ..scene import sources

if TYPE_CHECKING:
    from collections.abc import Iterable

    from bpy.types import Light, Object

    from ...physics.arrays import FloatArray


def problem(light: Light) -> str | None:
    """Why the lamp's tree is not carried to its copies (a few words), or None (it is)."""
    tree = compat.light_node_tree(light)
    if tree is None:
        return None
    node = sources.light_emission_node(tree)
    if node is None:
        return "its Light Output shows no Emission node"
    if node.inputs["Strength"].is_linked:
        return "a linked Emission Strength"
    colour = node.inputs["Color"]
    if not colour.is_linked:
        return None
    source = sources.blackbody_source(colour)
    if source is None or not isinstance(source.scale, float) or sources.light_blackbody(light) is None:
        return "an Emission Color made by nodes other than one Blackbody"
    return None


def tree_factor(light: Light) -> FloatArray:
    """``sources.light_tree_factor``: the tree's Strength times its unlinked Color or a Blackbody's
    constant (linear RGB); ones without a tree, the Strength alone where the tree is not carried
    (:func:`problem`)."""
    return np.array(sources.light_tree_factor(light), dtype=np.float64)


def tree_colour(light: Light) -> FloatArray:
    """What the lamp's tree multiplies its Color by (linear RGB): :func:`tree_factor`, times a
    Blackbody in it (Blender's luminance-1 colour)."""
    temperature = sources.light_blackbody(light)
    if temperature is not None and sources.light_tree_blackbody(light) is not None:
        return tree_factor(light) * lamp_doppler.blackbody_unit_rgb(temperature)
    return tree_factor(light)


def rest_emission(light: Light) -> tuple[FloatArray, float | None]:
    """``(colour, temperature or None)``: the lamp as a copy without its tree emits it (a moving
    sun's stand-in): its Color times :func:`tree_factor`, and the temperature of its blackbody, its
    own or a Blackbody in its tree (``sources.light_blackbody``)."""
    return np.array(light.color[:3], dtype=np.float64) * tree_factor(light), sources.light_blackbody(light)


def doppler_rgb(light: Light) -> tuple[float, float, float]:
    """The colour eq. 18's factor is taken for: the lamp's Color times its tree's unlinked Emission
    Color (the factor is per channel, so a red tree under a white lamp is shifted as red)."""
    colour = np.array(light.color, dtype=np.float64)
    node = sources.light_tree_emission(light)
    if node is not None and not node.inputs["Color"].is_linked:
        colour = colour * np.array(node.inputs["Color"].default_value[:3], dtype=np.float64)
    return (float(colour[0]), float(colour[1]), float(colour[2]))


def warnings(lamps: Iterable[Object]) -> list[str]:
    """One line per lamp (with copies on moving objects) whose tree is not carried."""
    found = []
    for lamp in lamps:
        light = cast("Light", lamp.data)
        reason = problem(light)
        if reason is None:
            continue
        if light.type == "SUN":
            found.append(
                f"Light {lamp.name!r}: its node tree ({reason}) is not Doppler shifted on moving objects "
                "(eq. 18 shifts its Color only)"
            )
        else:
            found.append(
                f"Light {lamp.name!r}: its node tree ({reason}) is left out of its light on moving objects "
                "(eq. 18's stand-ins emit its Color and Strength only)"
            )
    return found
