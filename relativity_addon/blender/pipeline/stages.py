"""The stages: every part of the effect written after the render path, listed once.

Set Up applies the scene's render path (``exact_camera`` or ``apparent_meshes``, chosen by the
Method), then every stage of :data:`STAGES` in order; each sync writes them in the same order, and
Remove (or a failed Set Up) removes them in reverse. Every stage answers the same four verbs:

``apply(scene, snap)``
    at Set Up, after the render path;
``write(scene, snap, sync)``
    at every sync (handlers, property callbacks, before each render), from the snapshot and what the
    sync knows (:class:`Sync`); writes only what changed;
``remove(scene)``
    gives back everything the stage added or changed; safe when nothing was applied;
``warnings(scene, snap)``
    one-line problems for the panel (computed at sync, shown by the panel);
``render_init(scene)`` (optional)
    once when a render job starts (F12 or Render Animation), before its first frame's sync: what
    the job's frames need that must not be made between them (:func:`render_init`).

``docs/architecture.md`` lists the same stages in the same order (a test checks it).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..camera import clamping, cockpit
from ..colour import cockpit_sky, doppler_colour, light_groups, volumes, world_doppler
from ..lights import (
    cockpit_lamps,
    interreflection,
    lamps_on_moving_objects,
    lamps_seen_directly,
    moving_lights,
    stand_in_lamps,
    turning_receivers,
)
from . import metadata

if TYPE_CHECKING:
    from bpy.types import Scene

    from ..scene.snapshot import Snapshot


@dataclass(frozen=True)
class Sync:
    """What a sync hands every stage's ``write`` besides the scene and its snapshot."""

    depsgraph: Any = None  # the depsgraph of a depsgraph_update_post handler, or None
    attach_new_materials: bool = False  # attach the Doppler colour to materials added since Set Up
    before_render: bool = False  # render_pre: also write what only a render reads


def _none(scene: Scene, snap: Snapshot) -> list[str]:
    return []


def _no_render_init(scene: Scene) -> None:
    """Most stages need nothing before a render job beyond the syncs of its frames."""


@dataclass(frozen=True)
class Stage:
    """One stage: its name in the docs, the module that holds it, and its four verbs."""

    name: str
    module: Any
    apply: Callable[[Scene, Snapshot], object]
    write: Callable[[Scene, Snapshot, Sync], object]
    remove: Callable[[Scene], object]
    warnings: Callable[[Scene, Snapshot], list[str]] = _none
    render_init: Callable[[Scene], object] = _no_render_init


def _colour_warnings(scene: Scene, snap: Snapshot) -> list[str]:
    if not snap.exact_camera:
        return []
    return volumes.warnings(scene) + light_groups.warnings(scene, snap)


def _lamp_warnings(scene: Scene, snap: Snapshot) -> list[str]:
    return lamps_on_moving_objects.warnings(scene, snap) + turning_receivers.warnings(scene, snap)


def _world_pixels(scene: Scene, snap: Snapshot, pixels: bool = True) -> None:
    if snap.colour.camera_path:
        world_doppler.write(scene, snap, pixels=pixels)


def _nothing(scene: Scene) -> None:
    """The world's ln D image goes with the colour stage (``doppler_colour.remove``)."""


STAGES: tuple[Stage, ...] = (
    Stage(
        "moving lights",
        moving_lights,
        apply=moving_lights.apply,  # before the colour stage: it reads the materials' own colours
        write=lambda scene, snap, sync: moving_lights.write(scene, snap, sync.attach_new_materials, sync.depsgraph),
        remove=moving_lights.remove,
        warnings=moving_lights.warnings,
        render_init=stand_in_lamps.reserve,  # no stand-ins are made between Render Animation's frames
    ),
    Stage(
        "Doppler colour",
        doppler_colour,
        apply=doppler_colour.apply,
        write=lambda scene, snap, sync: doppler_colour.write(scene, snap, sync.attach_new_materials),
        remove=doppler_colour.remove,
        warnings=_colour_warnings,
    ),
    Stage(
        "world pixels",
        world_doppler,
        apply=_world_pixels,
        write=lambda scene, snap, sync: _world_pixels(scene, snap, pixels=sync.before_render),
        remove=_nothing,
    ),
    Stage(
        "metadata",
        metadata,
        apply=metadata.write,
        write=lambda scene, snap, sync: metadata.write(scene, snap),
        remove=metadata.remove,
    ),
    Stage(
        "clamping",
        clamping,
        apply=clamping.write,
        write=lambda scene, snap, sync: clamping.write(scene, snap),
        remove=clamping.remove,
    ),
    Stage(
        "lamps on moving objects",
        lamps_on_moving_objects,
        apply=lamps_on_moving_objects.apply,
        write=lambda scene, snap, sync: lamps_on_moving_objects.write(scene, snap),
        remove=lamps_on_moving_objects.remove,
        warnings=_lamp_warnings,
    ),
    Stage(
        "light bounced between moving objects",
        interreflection,
        apply=interreflection.apply,
        write=lambda scene, snap, sync: interreflection.write(scene, snap),
        remove=interreflection.remove,
        warnings=interreflection.warnings,
    ),
    Stage(
        "lamps seen directly",
        lamps_seen_directly,
        apply=lamps_seen_directly.write,
        write=lambda scene, snap, sync: lamps_seen_directly.write(scene, snap),
        remove=lamps_seen_directly.remove,
        warnings=lamps_seen_directly.warnings,
    ),
    Stage(
        "objects moving with the camera",
        cockpit,
        apply=cockpit.apply,  # last: it lays its render over the output of every other compositor node
        write=lambda scene, snap, sync: cockpit.write(scene, snap, structural=sync.depsgraph is None),
        remove=cockpit.remove,
        warnings=cockpit.warnings,
    ),
    Stage(
        "the cockpit's sky",
        cockpit_sky,
        apply=cockpit_sky.apply,
        write=lambda scene, snap, sync: cockpit_sky.write(scene, snap, structural=sync.depsgraph is None),
        remove=cockpit_sky.remove,
    ),
    Stage(
        "the scene's lamps on the cockpit",
        cockpit_lamps,
        apply=cockpit_lamps.apply,
        write=lambda scene, snap, sync: cockpit_lamps.write(scene, snap, structural=sync.depsgraph is None),
        remove=cockpit_lamps.remove,
    ),
)


def render_init(scene: Scene) -> None:
    """Every stage's ``render_init``, in order (the ``render_init`` handler, once per render job)."""
    for stage in STAGES:
        stage.render_init(scene)
