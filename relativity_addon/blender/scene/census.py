"""Each object's relativity settings read once a sync, in one pass over the scene (issue 26).

A sync asks about every object of the scene in many places: which have their own velocity (the
snapshot's check, the clamping stage's fastest speed), which are lights or emitters (the moving
lights), which move with the camera (the cockpit), their blackbody temperatures (the checks, the
colour stage), which Static meshes may be keyframed (the panel). Each pass read the same settings
again: on 1,000 objects, about a millisecond each. Inside :func:`taken` (``snapshot.read`` and
``records.record`` open it) :func:`entries` reads them once per scene; outside it every call reads
the scene afresh. Neither changes a setting, so what it reads stays true while it runs (not kept
across the stages' writes, which add and delete objects).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple

from ..common import once

if TYPE_CHECKING:
    from contextlib import AbstractContextManager

    from bpy.types import Object, Scene


class Entry(NamedTuple):
    """One object of the scene and what a sync reads of its settings."""

    obj: Object
    type: str
    settings: Any  # obj.relativity
    motion: str  # the setting ("STATIC", "CONSTANT", "ANIMATION"), also where not enabled
    beta: tuple[float, float, float]  # the Constant Velocity setting, fraction of c
    own_velocity: bool  # enabled, with Constant Velocity of nonzero beta or with Animation
    temperature: float  # the Blackbody Temperature setting (0: none)
    with_camera: bool  # Moves With Camera
    emitter_light: bool  # a mesh of Constant Velocity that Lights the Scene (``emitting_meshes.is_emitter_light``)
    linked: bool  # from a library


_taken = once.Once()  # scene name -> its entries, inside taken()


def taken() -> AbstractContextManager[None]:
    """Inside: :func:`entries` reads each scene's objects once."""
    return _taken.kept()


def entries(scene: Scene) -> tuple[Entry, ...]:
    """Every object of ``scene`` (``scene.objects``, in its order) with its settings read."""
    kept = _taken.values()
    if kept is not None:
        found = kept.get(scene.name)
        if found is None:
            found = kept[scene.name] = _read(scene)
        return found
    return _read(scene)


def own_velocity(settings: Any, motion: str | None = None, beta: tuple[float, ...] | None = None) -> bool:
    """Whether an object's settings give it its own motion (``moving_objects.has_own_velocity``);
    ``motion`` and ``beta``: the settings' own, when already read."""
    if not settings.enabled:
        return False
    motion = settings.motion if motion is None else motion
    return motion == "ANIMATION" or (motion == "CONSTANT" and any(settings.beta if beta is None else beta))


def _read(scene: Scene) -> tuple[Entry, ...]:
    found = []
    for obj in scene.objects:
        settings, kind = obj.relativity, obj.type
        motion, beta = settings.motion, settings.beta[:]
        found.append(
            Entry(
                obj,
                kind,
                settings,
                motion,
                beta,
                own_velocity(settings, motion, beta),
                float(settings.temperature),
                bool(settings.moves_with_camera),
                kind == "MESH" and motion == "CONSTANT" and bool(settings.lights_scene),
                obj.library is not None,
            )
        )
    return tuple(found)
