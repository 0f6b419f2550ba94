"""Where a moving light's stand-in lamps go (``stand_in_lamps.py``): the surface points the camera
sees, their retarded times on the light's path (straight, or its keyframes), and the lamps' times
and positions spread over them (``physics.moving_lights``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import bpy
import numpy as np

from ...errors import RelativityError
from ...physics.lorentz import camera_to_scene_direction
from ...physics.moving_lights import lamp_times, retarded_times, retarded_times_on_path
from ..scene import animation, lens

if TYPE_CHECKING:
    from collections.abc import Mapping

    import numpy.typing as npt
    from bpy.types import Depsgraph, Object, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import MovingLight, Snapshot

MAX_LAMPS = 16  # per moving light: each costs Cycles light samples (only two light a point); more: sharper shadows
SPACING = 0.1  # wanted distance between neighbouring lamps, as a fraction of the median light distance


def view_directions(
    scene: Scene, snap: Snapshot, columns: int = 32, rows: int = 24, margin: float = 0.05
) -> FloatArray:
    """Scene-frame directions of a grid over the camera's view, widened by ``margin`` (the exact
    camera's rays: the pinhole direction in the camera frame, aberrated into the scene frame unless
    a Lorentz window keeps it, Gray eq. 6)."""
    left, right, bottom, top = lens.view_window(scene, scene.objects[snap.camera])
    widen_x, widen_y = margin * (right - left), margin * (top - bottom)
    x = np.linspace(left - widen_x, right + widen_x, columns)
    y = np.linspace(bottom - widen_y, top + widen_y, rows)
    local = np.stack(np.broadcast_arrays(x[None, :], y[:, None], -1.0), axis=-1).reshape(-1, 3)
    world = local @ np.array(snap.camera_matrix)[:3, :3].T
    world /= np.linalg.norm(world, axis=-1, keepdims=True)
    if snap.exact_camera and snap.use_geometry and not snap.use_lorentz_window and any(snap.beta):
        # Gray eq. (2) carries photon directions: the photon arriving along a view direction
        # travels the other way (as the camera shader's scene_ray_direction does)
        world = -camera_to_scene_direction(-world, snap.beta)
    return world


def visible_points(
    scene: Scene, snap: Snapshot, depsgraph: Depsgraph | None, origin: npt.ArrayLike
) -> npt.NDArray[Any]:
    """Surface points the camera sees (the first hit of each ray of :func:`view_directions`)."""
    if depsgraph is None:
        try:
            depsgraph = bpy.context.evaluated_depsgraph_get()
        except (AttributeError, RuntimeError):
            return np.zeros((0, 3))
    start = [float(v) for v in np.asarray(origin, dtype=np.float64)]
    points: list[list[float]] = []
    for direction in view_directions(scene, snap):
        hit, location, *_rest = scene.ray_cast(depsgraph, start, [float(v) for v in direction])
        if hit:
            points.append([location.x, location.y, location.z])
    return np.array(points, dtype=np.float64).reshape(-1, 3)


def _spacing(times, irradiance, speed):
    """Wanted ``c t`` between lamps: SPACING of the median distance of the lit points, over the speed."""
    lit = np.isfinite(irradiance) & (irradiance >= 0.01 * np.nanmax(irradiance))
    distance = float(np.median(1.0 / np.sqrt(irradiance[lit])))  # ~ r (D^4 ~ 1 for a typical point)
    return SPACING * distance / max(speed, 1e-9)


def keyframe_path(obj: Object, snap: Snapshot, reception_time: float, times: npt.ArrayLike) -> FloatArray:
    """The animated light's world positions at the times ``c (t - t_reception)`` (keyframes)."""
    frames = snap.frame + (reception_time + np.asarray(times, float)) / snap.speed_of_light * snap.fps
    return animation.world_matrices(obj, frames)[:, :3, 3]


def lamp_path(
    scene: Scene,
    snap: Snapshot,
    light: MovingLight,
    values: Mapping[str, Any],
    reception_time: float,
    points: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Where the stand-in lamps go: their times ``c (t - t_reception)`` on the light's path (ascending)
    and positions, for these surface points (the lit ones' retarded times; at least one lamp)."""
    camera_position = values["camera_position"]
    if light.motion != "ANIMATION":
        origin, beta = np.array(values["light_position"], float), np.array(light.beta, float)
        speed = float(np.linalg.norm(beta))
        if len(points) == 0 or speed == 0.0:
            return np.zeros(1), origin[None, :]
        times, irradiance = retarded_times(points, camera_position, origin, beta)
        times = lamp_times(times, irradiance, _spacing(times, irradiance, speed), MAX_LAMPS)
        return times, origin + times[:, None] * beta
    obj = scene.objects[light.name]  # its keyframes were checked by snapshot.moving_lights
    here = keyframe_path(obj, snap, reception_time, [0.0])[0]
    if len(points) == 0:
        return np.zeros(1), here[None, :]
    reach = float(np.max(np.linalg.norm(points - camera_position, axis=-1) + np.linalg.norm(points - here, axis=-1)))
    knots = np.linspace(-4.0 * reach, 0.0, 257)
    path = keyframe_path(obj, snap, reception_time, knots)
    speed = float(np.max(np.linalg.norm(np.diff(path, axis=0), axis=-1)) / (knots[1] - knots[0]))
    if speed >= 1.0:
        raise RelativityError(f"Light {light.name!r} moves at {speed:.3f}c on its keyframes (must be below c)")
    if speed == 0.0:
        return np.zeros(1), here[None, :]
    knots = np.linspace(-reach * 2.0 / (1.0 - speed), 0.0, 513)
    times, irradiance = retarded_times_on_path(
        points, camera_position, knots, keyframe_path(obj, snap, reception_time, knots)
    )
    times = lamp_times(times, irradiance, _spacing(times, irradiance, speed), MAX_LAMPS)
    return times, keyframe_path(obj, snap, reception_time, times)


def path_positions(
    scene: Scene, snap: Snapshot, light: MovingLight, values: Mapping[str, Any], reception_time: float, times: Any
) -> FloatArray:
    """The light's positions at the times ``c (t - t_reception)``."""
    if light.motion == "ANIMATION":
        return np.asarray(keyframe_path(scene.objects[light.name], snap, reception_time, times), dtype=np.float64)
    path = np.array(values["light_position"], float) + np.outer(times, np.array(light.beta, float))
    return np.asarray(path, dtype=np.float64)
