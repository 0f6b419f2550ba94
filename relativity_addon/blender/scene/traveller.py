"""The traveller's clock: the observer's proper time at a frame (shown in the panel beside the
scene's time), and the scene frames at which a fly-through steps in proper time
(``render.py --proper-time``: output frame ``k`` at the traveller's time ``k / fps``).

The clock reads 0 at scene time 0 (frame 0), like the objects' clocks (``world_lines``); the
observer's speed comes from ``snapshot.observer_speeds`` (the setting or the camera's keyframes)
and ``physics/proper_time.py`` integrates ``dt / gamma``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...errors import RelativityError
from ...physics import proper_time
from . import animation, snapshot

if TYPE_CHECKING:
    import numpy.typing as npt
    from bpy.types import Scene

SAMPLES_PER_FRAME = 4
MAX_SAMPLES = 200_000
_cache = {}


def _grid(scene, first_frame, last_frame):
    """Frames from ``first_frame`` to ``last_frame`` and the clock's readings there (0 at the first)."""
    count = int(min(MAX_SAMPLES, max(2, abs(last_frame - first_frame) * SAMPLES_PER_FRAME + 1)))
    frames = np.linspace(float(first_frame), float(last_frame), count)
    fps = animation.frames_per_second(scene)
    return frames, proper_time.proper_times(frames / fps, snapshot.observer_speeds(scene, frames))


def proper_time_at(scene: Scene, frame: float) -> float:
    """The traveller's time (seconds) at ``frame`` (negative before frame 0), interpolated in a
    table of the scene's frame range sampled SAMPLES_PER_FRAME times a frame, which is computed
    again only when the motion changes (the panel shows it at every sync). RelativityError for an
    observer at or above c."""
    settings = scene.relativity
    camera = scene.camera
    first = min(0.0, float(scene.frame_start), float(frame))
    last = max(1.0, float(scene.frame_end), float(frame))
    animated = camera is not None and settings.velocity_source == "CAMERA_ANIMATION"
    key = (
        scene.name,
        first,
        last,
        settings.velocity_source,
        tuple(settings.beta),
        settings.speed_of_light,
        animation.frames_per_second(scene),
        animation.keyframes_signature(camera) if animated else (),
    )
    if _cache.get("key") != key:
        frames, taus = _grid(scene, first, last)
        _cache.update(key=key, frames=frames, taus=taus - np.interp(0.0, frames, taus))
    return float(np.interp(frame, _cache["frames"], _cache["taus"]))


def frames_at_proper_times(scene: Scene, taus: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Scene frames (floats) at which the traveller's clock reads ``taus`` (seconds, >= 0)."""
    taus = np.asarray(taus, dtype=np.float64)
    if taus.min() < 0.0:
        raise RelativityError("Proper-time frames start at frame 0 (the traveller's clock reads 0 there)")
    fps = animation.frames_per_second(scene)
    last = max(2.0, taus.max() * fps * 1.5 + 2.0)
    for _ in range(12):
        frames, grid_taus = _grid(scene, 0.0, last)
        if grid_taus[-1] >= taus.max():
            return proper_time.scene_times(taus, frames, grid_taus)
        last *= 2.0
    raise RelativityError(f"The traveller's clock does not reach {taus.max():.6g} s by frame {last:g}")
