"""Cycles' sample clamping, scaled by the searchlight while the exact camera renders.

The exact camera multiplies a camera ray's throughput by ``D^4`` before Cycles clamps a sample's
contribution (Render Properties > Light Paths > Clamping), so a clamp meant for the scene at rest
cuts the searchlight's brightening (found by the gallery: the street's centre 4.5 % too dark at 0.8c
with Blender's default indirect clamp of 10). While the effect is applied, each non-zero clamp is
the user's value times the brightest ``D^4`` in any direction, ``(gamma (1 + beta))^4``; a value the
user types meanwhile becomes the user's value; removing the effect gives the user's values back.
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


def factor(snap: Snapshot) -> float:
    if not (snap.exact_camera and snap.use_searchlight and snap.speed > 0.0):
        return 1.0
    return (snap.gamma * (1.0 + snap.speed)) ** 4


def write(scene: Scene, snap: Snapshot) -> None:
    """Scale the clamps for the snapshot (only writing what changed: a write triggers a sync)."""
    cycles = getattr(scene, "cycles", None)
    scale = factor(snap)
    if cycles is None or (KEY not in scene and scale == 1.0):
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
