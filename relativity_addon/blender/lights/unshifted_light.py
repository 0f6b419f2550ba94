"""Light that no lamp carries reaching moving objects: the world and emitting meshes.

Lamps at rest reach moving objects through light-linked copies with eq. 18's Doppler factor
(``lamps_on_moving_objects.py``); the world's light and that of emitting meshes (at rest, or moving
without Lights Scene) reach them as Cycles computes it in the scene frame, unshifted. What that
leaves (docs/lamp-doppler.md, "Approximate cases": 0.86x of eq. 18 on a face across the motion at
0.5c, 0.27x and 5.1x toward and away from it) is said in one panel line; this module finds whether
a scene has such light.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..colour import world_sampling
from ..common import compat
from ..scene import emitting_meshes

if TYPE_CHECKING:
    from collections.abc import Sequence

    from bpy.types import Object, Scene, World


def sources(scene: Scene, moving: Sequence[Object]) -> str | None:
    """What lights the ``moving`` objects besides the lamps, with no Doppler factor: "the world",
    "emitting meshes" (at rest, or moving without Lights Scene; a moving object's own emission does
    not count for itself), both, or None."""
    world = scene.world is not None and world_lights(scene.world)
    emitting = {material for material in bpy.data.materials if emitting_meshes.emits(material)}
    receivers = {obj.name for obj in moving}
    meshes = bool(emitting) and any(
        any(slot.material in emitting for slot in obj.material_slots)
        for obj in scene.objects
        if receivers - {obj.name} and not obj.hide_render and not emitting_meshes.is_emitter_light(obj)
    )
    parts = [part for part, used in (("the world", world), ("emitting meshes", meshes)) if used]
    return " and ".join(parts) or None


def world_lights(world: World) -> bool:
    """Whether ``world`` sends light: anything but a black (or zero-strength) constant background."""
    if compat.rendered_node_tree(world) is None:
        return any(value > 0.0 for value in world.color)
    background = world_sampling.constant_background(world)
    if background is None:
        return True
    colour, strength = background.inputs["Color"].default_value, background.inputs["Strength"].default_value
    return strength > 0.0 and any(value > 0.0 for value in tuple(colour)[:3])
