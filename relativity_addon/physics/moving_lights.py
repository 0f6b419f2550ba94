"""Surfaces lit by a light in uniform motion: retarded light position, Doppler factor, irradiance
(docs/moving-lights.md; Weiskopf, Kraus, Ruder 1999, eq. 19).

Frames and conventions: everything is in the scene frame, where the lit surface and the camera
are at rest. The light moves with constant velocity ``beta c`` (world axes) and is at
``light_position`` at the observer's time ``t_o`` (where Blender draws it at the frame). A
surface point ``x`` is seen by the camera at ``x_cam`` (the reception event ``(t_o, x_cam)``) as
it was at ``t_x = t_o - |x - x_cam| / c``, and is then lit by the light as it was at the emission
time ``t_e`` with ``|x - x_L(t_e)| = c (t_x - t_e)``. For uniform motion every time enters only
as ``c t``, so nothing here depends on the value of ``c``.
"""

from dataclasses import dataclass

import numpy as np

from .arrays import ArrayLike, FloatArray
from .lorentz import aberrate
from .radiance import point_light_irradiance
from .retarded import light_travel_time_uniform
from .validation import finite_array, unit_vectors, vector_array, velocity_array


@dataclass(frozen=True)
class RetardedLight:
    """Where a moving light was when it emitted the light a surface point receives.

    ``position`` ``(..., 3)``: the light at the emission time; ``distance`` ``r = c (t_x - t_e)``
    from there to the surface point; ``direction`` the unit photon direction from the light to
    the point (scene frame); ``doppler`` ``D = 1 / (gamma (1 - beta . n))`` of that photon
    (light to surface, both frames' frequencies: ``D = nu_surface / nu_light``).
    """

    position: FloatArray
    distance: FloatArray
    direction: FloatArray
    doppler: FloatArray


def retarded_light(
    surface_points: ArrayLike, camera_position: ArrayLike, light_position: ArrayLike, light_beta: ArrayLike
) -> RetardedLight:
    """The light's retarded position for each surface point (closed form, a quadratic).

    ``surface_points`` ``(..., 3)``, ``camera_position`` and ``light_position`` ``(3,)`` (the
    light at ``t_o``), ``light_beta`` ``(3,)`` its velocity over c. The light at ``t_x`` is
    ``p = light_position - beta |x - x_cam|``; from there the light-travel time is
    :func:`.retarded.light_travel_time_uniform` with the surface point as the receiver.
    """
    x = vector_array(surface_points, "surface_points")
    camera = vector_array(camera_position, "camera_position")
    beta = velocity_array(light_beta, "light_beta")
    light = vector_array(light_position, "light_position")
    delay = np.linalg.norm(x - camera, axis=-1, keepdims=True)  # c (t_o - t_x)
    at_surface_time = light - beta * delay
    # with c = 1 the light-travel time is the distance travelled, r = c (t_x - t_e)
    distance = light_travel_time_uniform(0.0, x, at_surface_time, beta, 1.0)
    position = at_surface_time - beta * distance[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        direction = (x - position) / distance[..., None]
    direction = np.where(distance[..., None] > 0.0, direction, 0.0)
    gamma = 1.0 / np.sqrt(1.0 - np.sum(beta * beta, axis=-1))
    doppler = 1.0 / (gamma * (1.0 - np.sum(beta * direction, axis=-1)))
    return RetardedLight(position, distance, direction, doppler)


def moving_point_light_irradiance(
    surface_points: ArrayLike,
    surface_normals: ArrayLike,
    camera_position: ArrayLike,
    light_position: ArrayLike,
    light_beta: ArrayLike,
    intensity: ArrayLike,
) -> FloatArray:
    """Irradiance ``E = D^4 cos(alpha) I / r^2`` (Weiskopf et al. eq. 19) from a moving point light.

    ``intensity`` I is the light's isotropic radiant intensity in its own frame (W/sr; a
    Blender point light of power P has ``P / (4 pi)``), ``alpha`` the angle between the surface
    normal and the direction toward the retarded position. No occlusion.
    """
    normals = unit_vectors(surface_normals, "surface_normals")
    light = retarded_light(surface_points, camera_position, light_position, light_beta)
    cosine = -np.sum(normals * light.direction, axis=-1)
    return point_light_irradiance(finite_array(intensity, "intensity"), light.doppler, cosine, light.distance)


def light_frame_direction(direction: ArrayLike, light_beta: ArrayLike) -> FloatArray:
    """The photon direction ``n'`` in the light's rest frame for scene-frame direction ``n``
    (aberration, docs/physics.md, with the frame S' moving with the light): what a spot light's
    cone, defined in the light's own frame, is evaluated on."""
    n = unit_vectors(direction, "direction")
    beta = velocity_array(light_beta, "light_beta")
    b2 = np.sum(beta * beta, axis=-1)
    gamma = 1.0 / np.sqrt(1.0 - b2)
    bn = np.sum(beta * n, axis=-1)[..., None]
    # (gamma - 1) (bhat . n) bhat = gamma^2 / (gamma + 1) (beta . n) beta, finite at beta = 0
    shifted = n + (gamma * gamma / (gamma + 1.0))[..., None] * bn * beta - gamma[..., None] * beta
    return shifted / (gamma[..., None] * (1.0 - bn))


def irradiance_on_plane(
    points_along: ArrayLike,
    plane_height: float,
    camera_position: ArrayLike,
    light_position: ArrayLike,
    light_beta: ArrayLike,
    intensity: float,
) -> FloatArray:
    """Irradiance on the horizontal plane ``z = plane_height`` (normal +Z, lit from above) at the
    points ``(x, y)`` ``(..., 2)``: the profile a camera at rest sees on a floor."""
    xy = finite_array(points_along, "points_along")
    points = np.concatenate([xy, np.full(xy.shape[:-1] + (1,), float(plane_height))], axis=-1)
    return moving_point_light_irradiance(
        points, np.broadcast_to([0.0, 0.0, 1.0], points.shape), camera_position, light_position, light_beta, intensity
    )


def retarded_times(
    surface_points: ArrayLike, camera_position: ArrayLike, light_position: ArrayLike, light_beta: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """``c (t_e - t_o)`` for each surface point (the light's position then is
    ``light_position + beta c (t_e - t_o)``) and the irradiance ``D^4 / r^2`` per unit intensity
    (no cosine, no occlusion): the points' retarded times and how much light they get."""
    x = vector_array(surface_points, "surface_points")
    light = retarded_light(x, camera_position, light_position, light_beta)
    delay = np.linalg.norm(x - vector_array(camera_position, "camera_position"), axis=-1)
    with np.errstate(divide="ignore"):
        irradiance = light.doppler**4 / light.distance**2
    return -delay - light.distance, irradiance


def lamp_times(
    times: ArrayLike, irradiance: ArrayLike, spacing: float, max_lamps: int, relevance: float = 0.01
) -> FloatArray:
    """Where on its path (``c (t - t_o)``, ascending) to put the point lamps that stand in for a
    moving light: evenly over the retarded times of the points that get at least ``relevance`` of
    the brightest point's irradiance, at most ``spacing`` apart (in ``c t``, a length along the path
    times 1 / beta), at most ``max_lamps`` of them. A point outside that span is lit from the end lamp."""
    times = finite_array(times, "times").ravel()
    irradiance = np.asarray(irradiance, float).ravel()
    keep = np.isfinite(irradiance) & (irradiance > 0.0)
    if not np.any(keep):
        return np.zeros(1)
    keep &= irradiance >= relevance * irradiance[keep].max()
    low, high = float(times[keep].min()), float(times[keep].max())
    if not high - low > 0.0:
        return np.array([low])
    count = int(min(max(np.ceil((high - low) / max(spacing, 1e-12)) + 1, 2), max(max_lamps, 2)))
    return np.linspace(low, high, count)


def end_on_share(
    times: ArrayLike,
    irradiance: ArrayLike,
    surface_points: ArrayLike,
    path_times: ArrayLike,
    path_positions: ArrayLike,
    sin_limit: float = 0.25,
    relevance: float = 0.01,
) -> float:
    """The share of the lit points' irradiance (those getting at least ``relevance`` of the
    brightest's, as :func:`lamp_times` counts them) that sees the light's path nearly end on: the
    direction from the light's retarded position (``times``, on the path of :func:`path_position`)
    to the point within ``asin(sin_limit)`` of the path's piece there. A thin strip along the path
    lights nothing from which it is seen edge on."""
    times = finite_array(times, "times").ravel()
    irradiance = np.asarray(irradiance, float).ravel()
    x = vector_array(surface_points, "surface_points").reshape(-1, 3)
    knots = finite_array(path_times, "path_times")
    path = vector_array(path_positions, "path_positions")
    keep = np.isfinite(irradiance) & (irradiance > 0.0)
    if knots.size < 2 or not np.any(keep):
        return 0.0
    keep &= irradiance >= relevance * irradiance[keep].max()
    index = np.clip(np.searchsorted(knots, times[keep]) - 1, 0, knots.size - 2)
    along = path[index + 1] - path[index]
    along /= np.maximum(np.linalg.norm(along, axis=-1, keepdims=True), 1e-300)
    seen = x[keep] - path_position(times[keep], knots, path)
    sine = np.linalg.norm(np.cross(seen, along), axis=-1) / np.maximum(np.linalg.norm(seen, axis=-1), 1e-300)
    weight = irradiance[keep]
    return float(weight[sine < sin_limit].sum() / weight.sum())


def path_position(times: ArrayLike, path_times: ArrayLike, path_positions: ArrayLike) -> FloatArray:
    """The light's position at ``times`` on a path sampled at ascending ``path_times`` (``c t``),
    straight between samples and extended straight beyond the first and last."""
    s = np.asarray(times, float)
    knots = finite_array(path_times, "path_times")
    points = vector_array(path_positions, "path_positions")
    if knots.size == 1:
        return np.broadcast_to(points[0], s.shape + (3,)).copy()
    index = np.clip(np.searchsorted(knots, s) - 1, 0, knots.size - 2)
    fraction = (s - knots[index]) / (knots[index + 1] - knots[index])
    return points[index] + fraction[..., None] * (points[index + 1] - points[index])


def retarded_times_on_path(
    surface_points: ArrayLike,
    camera_position: ArrayLike,
    path_times: ArrayLike,
    path_positions: ArrayLike,
    iterations: int = 400,
) -> tuple[FloatArray, FloatArray]:
    """:func:`retarded_times` for a light on a sampled path (:func:`path_position`): the retarded
    time ``s = -|x - camera| - |x - x_L(s)|`` by fixed-point iteration (it contracts by the light's
    speed, which must stay below c), and ``D^4 / r^2`` with the velocity of the path's piece."""
    x = vector_array(surface_points, "surface_points")
    knots = finite_array(path_times, "path_times")
    points = vector_array(path_positions, "path_positions")
    delay = np.linalg.norm(x - vector_array(camera_position, "camera_position"), axis=-1)
    s = -delay
    for _ in range(iterations):
        s = -delay - np.linalg.norm(x - path_position(s, knots, points), axis=-1)
    step = 1e-4 * max(float(knots.max() - knots.min()), 1e-9)
    beta = (path_position(s + step, knots, points) - path_position(s - step, knots, points)) / (2.0 * step)
    r = -delay - s
    with np.errstate(divide="ignore", invalid="ignore"):
        n = (x - path_position(s, knots, points)) / r[..., None]
        gamma = 1.0 / np.sqrt(1.0 - np.sum(beta * beta, axis=-1))
        doppler = 1.0 / (gamma * (1.0 - np.sum(beta * n, axis=-1)))
        irradiance = doppler**4 / r**2
    return s, irradiance


def sun_in_scene_frame(axis: ArrayLike, beta: ArrayLike) -> tuple[FloatArray, float]:
    """A sun (plane wave) moving with ``beta``: the photon direction in the scene frame (its own
    frame's ``axis`` aberrated) and ``D = 1 / (gamma (1 - beta . k))``; the irradiance on a surface
    facing it scales by ``D^2`` (radiance ``D^4`` times the disc's solid angle ``1 / D^2``) and its
    angular diameter by ``1 / D``."""
    beta = np.array(beta, float)
    k = aberrate(np.array(axis, float), -beta)
    gamma = 1.0 / float(np.sqrt(1.0 - float(beta @ beta)))
    return k, 1.0 / (gamma * (1.0 - float(beta @ k)))
