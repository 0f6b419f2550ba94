"""The check of every blackbody temperature a setting gives (``snapshot.read``): an object's
Blackbody Temperature, a light's own Temperature, *Lit By: Blackbody*'s Temperature and the
Blackbody nodes that make a lamp's light group (``illuminants.lit_groups``).

Blender's float settings take NaN from a script or a driver (their minimum and maximum clamp
only numbers), and a NaN temperature reaches the colour tables and the shaders as a NaN or a
huge pixel. Infinity is stored as the largest float, which the tables hold as their hottest
entry: only values that are not numbers are refused, in one line naming the object and setting.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ...errors import RelativityError
from . import census

if TYPE_CHECKING:
    from bpy.types import Scene

    from .illuminants import LitGroup


def _refuse(owner, setting, value):
    raise RelativityError(f"{owner}: {setting} is {value} K: enter a temperature in kelvin")


def check_temperatures(scene: Scene) -> None:
    """RelativityError (one line) for the first temperature setting of ``scene`` that is not a number."""
    for entry in census.entries(scene):
        obj, temperature = entry.obj, entry.temperature
        if not math.isfinite(temperature):
            _refuse(f"Object {obj.name!r}", "Blackbody Temperature", temperature)
        light = obj.data if entry.type == "LIGHT" else None
        if light is not None and light.use_temperature and not math.isfinite(float(light.temperature)):
            _refuse(f"Light {obj.name!r}", "Temperature", float(light.temperature))
    settings = scene.relativity
    if settings.fast_illuminant == "BLACKBODY" and not math.isfinite(float(settings.fast_illuminant_temperature)):
        _refuse("Lit By: Blackbody", "Temperature", float(settings.fast_illuminant_temperature))


def checked_lit_groups(groups: tuple[LitGroup, ...]) -> tuple[LitGroup, ...]:
    """``groups`` (``illuminants.LitGroup``); RelativityError (one line) naming a lamp whose
    Blackbody node's Temperature is not a number (its light group's table has no light)."""
    for group in groups:
        if not math.isfinite(group.temperature):
            lamp = next((f"Object {name!r}" for name in group.members if name), "World")
            _refuse(lamp, "a Blackbody node's Temperature", group.temperature)
    return groups
