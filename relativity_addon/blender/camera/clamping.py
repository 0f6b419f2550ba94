"""Cycles' sample clamping, scaled by the searchlight.

The exact camera multiplies a camera ray's throughput by ``D^4`` before Cycles clamps a sample's
contribution (Render Properties > Light Paths > Clamping), so a clamp meant for the scene at rest
cuts the searchlight's brightening (found by the gallery: the street's centre 4.5 % too dark at 0.8c
with Blender's default indirect clamp of 10). Moving objects and lights brighten what they send the
same way (``D^4`` of the source, on either path): a moving sphere's light bounced onto a panel
came out 0.49 of what Cycles was asked to render at 0.5c with that clamp
(tests/blender/lights/test_interreflection.py). While the effect is applied, each non-zero clamp
is the user's value times the brightest ``D^4`` in any direction, ``(gamma (1 + beta))^4`` of the
observer, times ``(gamma (1 + beta))^6`` of the fastest object or light with its own velocity
(``Snapshot.fastest_object``; the relative factor of two frames is at most the product, and
a lamp's light on a moving object gains eq. 18's ``D^2`` before the object's ``D^4``); a
value the user types meanwhile becomes the user's value; removing the effect gives the user's
values back.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..common import names

if TYPE_CHECKING:
    from bpy.types import Scene

    from ..scene.snapshot import Snapshot

KEY = names.CLAMP_SAVED_KEY
CLAMPS = ("sample_clamp_direct", "sample_clamp_indirect")


def factor(scene: Scene, snap: Snapshot) -> float:
    """The brightest gain the searchlight gives a sample: the observer's ``D^4`` times the fastest
    source's ``D^6`` (1 without the searchlight or motion)."""
    if not snap.use_searchlight or snap.use_time_of_flight:
        return 1.0
    observer = snap.speed if snap.method == "GEOMETRY" or snap.exact_camera else 0.0
    lights = [math.hypot(*light.beta) for light in snap.moving_lights]
    source = max([snap.fastest_object, *lights])
    return _brightest(observer, 4) * _brightest(min(source, 1.0 - 1e-9), 6)


def _brightest(speed, power):
    """``(gamma (1 + beta))^power``: the largest ``D^power`` at ``speed``."""
    return ((1.0 + speed) / (1.0 - speed)) ** (power / 2.0)


def write(scene: Scene, snap: Snapshot) -> None:
    """Scale the clamps for the snapshot (only writing what changed: a write triggers a sync)."""
    cycles = getattr(scene, "cycles", None)
    if cycles is None or (KEY not in scene and not any(getattr(cycles, name) for name in CLAMPS)):
        return  # no clamp to scale (the speeds are not even read)
    scale = factor(scene, snap)
    if KEY not in scene and scale == 1.0:
        return
    if KEY not in scene:
        scene[KEY] = {name: getattr(cycles, name) for name in CLAMPS} | {
            f"written {name}": getattr(cycles, name) for name in CLAMPS
        }
    saved = scene[KEY]
    for name in CLAMPS:
        current = getattr(cycles, name)
        if not math.isclose(current, saved[f"written {name}"], rel_tol=1e-6):
            saved[name] = current  # the user changed it since
        target = saved[name] * scale
        if not math.isclose(current, target, rel_tol=1e-6):
            setattr(cycles, name, target)
        saved[f"written {name}"] = getattr(cycles, name)


def remove(scene: Scene) -> bool:
    """Give the user's clamps back."""
    if KEY not in scene:
        return False
    saved = scene[KEY].to_dict()
    cycles = scene.cycles
    for name in CLAMPS:
        current = getattr(cycles, name)
        value = current if not math.isclose(current, saved[f"written {name}"], rel_tol=1e-6) else saved[name]
        setattr(cycles, name, value)
    del scene[KEY]
    return True
