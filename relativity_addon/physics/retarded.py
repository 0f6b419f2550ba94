"""Light-travel time: when was an emitter where the observer now sees it? (docs/physics.md,
"Light-travel time").

An observer at event ``(t_o, x_o)`` sees a point of world line ``x_e(t)`` as it was at the
retarded time ``t_e < t_o`` that solves ``|x_o - x_e(t_e)| = c (t_o - t_e)``. For a world line
slower than light the solution is unique: ``g(t) = c (t_o - t) - |x_o - x_e(t)|`` is strictly
decreasing, with slope between ``-(c + |u|)`` and ``-(c - |u|)``.
"""

from typing import Any

import numpy as np

from .arrays import ArrayLike, FloatArray, IndexArray, WorldLine
from .validation import finite_array, speed_of_light, vector_array, velocity_array


def light_travel_time_uniform(
    observer_time: ArrayLike,
    observer_position: ArrayLike,
    emitter_position: ArrayLike,
    emitter_beta: ArrayLike,
    c: float,
) -> FloatArray:
    """Closed-form light-travel time ``tau = t_o - t_e`` for uniform motion ``x_e(t) = p + u (t - t_o)``.

    ``emitter_position`` is ``p``, the emitter's position at the observer's time ``t_o`` (in the
    frame where both are given), ``emitter_beta`` is ``u / c``. With ``Delta = x_o - p``:

        tau = ((Delta·u) + sqrt((Delta·u)^2 + (c^2 - u·u) Delta·Delta)) / (c^2 - u·u)

    evaluated in whichever of its two algebraically equal forms avoids cancellation. ``tau`` is
    returned rather than ``t_e`` because with the real ``c`` it is many orders of magnitude
    smaller than scene times, and ``t_o - tau`` would round it away.
    """
    c = speed_of_light(c)
    finite_array(observer_time, "observer_time")
    delta = vector_array(observer_position, "observer_position") - vector_array(emitter_position, "emitter_position")
    u = velocity_array(emitter_beta, "emitter_beta") * c
    a = np.sum(delta * u, axis=-1)
    q = np.sum(delta * delta, axis=-1)
    b = c * c - np.sum(u * u, axis=-1)
    root = np.sqrt(a * a + b * q)
    with np.errstate(divide="ignore", invalid="ignore"):
        # (a + root) / b when a >= 0; the equal q / (root - a) when a < 0; 0 when q == 0.
        return np.where(a >= 0.0, (a + root) / b, q / np.where(root - a > 0.0, root - a, 1.0))


def retarded_time_uniform(
    observer_time: ArrayLike,
    observer_position: ArrayLike,
    emitter_position: ArrayLike,
    emitter_beta: ArrayLike,
    c: float,
) -> FloatArray:
    """Retarded time ``t_e = t_o - tau`` for uniform motion (see :func:`light_travel_time_uniform`)."""
    tau = light_travel_time_uniform(observer_time, observer_position, emitter_position, emitter_beta, c)
    return np.asarray(observer_time, dtype=np.float64) - tau


def light_travel_time(
    world_line: WorldLine,
    observer_time: ArrayLike,
    observer_position: ArrayLike,
    c: float,
    *,
    count: int | None = None,
    relative_tolerance: float = 1e-13,
    max_iterations: int = 100,
) -> FloatArray:
    """Light-travel times ``tau = t_o - t_e`` to ``count`` points on sub-luminal world lines.

    ``world_line(t, index)`` returns the positions, shape ``(M, 3)``, of the points numbered
    ``index`` (int array, shape ``(M,)``) at times ``t`` (shape ``(M,)``); the solver only asks
    for the points it is still working on. ``observer_position`` is ``(3,)`` or ``(count, 3)``,
    ``observer_time`` a scalar or ``(count,)``.

    Solves ``g(tau) = c tau - |x_o - x_e(t_o - tau)| = 0`` by secant steps kept inside a
    bracket (bisection when a step leaves it): ``g(0) <= 0`` and ``g`` increases strictly (slope
    between ``c - |u|`` and ``c + |u|``), so each evaluation narrows the bracket. Converges in a
    handful of evaluations where the plain fixed-point iteration
    ``t_e <- t_o - |x_o - x_e(t_e)| / c`` contracts only by ``|u| / c`` per step.
    """
    c = speed_of_light(c)
    observer_position = vector_array(observer_position, "observer_position")
    if count is None:
        count = observer_position.shape[0] if observer_position.ndim == 2 else 1
    x_o = np.broadcast_to(observer_position, (count, 3))
    t_o = np.broadcast_to(finite_array(observer_time, "observer_time"), (count,)).astype(np.float64)

    def g(tau: FloatArray, index: IndexArray) -> tuple[FloatArray, FloatArray]:
        """g and the size of its rounding error (a few ulps of the positions' magnitudes)."""
        positions = finite_array(world_line(t_o[index] - tau, index), "world_line positions")
        rounding = 8.0 * np.finfo(np.float64).eps * (np.abs(x_o[index]).sum(-1) + np.abs(positions).sum(-1))
        return c * tau - np.linalg.norm(x_o[index] - positions, axis=-1), rounding

    all_points = np.arange(count)
    tau = np.zeros(count)
    g_now, _ = g(tau, all_points)  # minus the distance at t_o, <= 0
    lower = np.zeros(count)  # largest tau seen with g <= 0
    upper = np.full(count, np.inf)  # smallest tau seen with g >= 0
    tau_prev, g_prev = tau.copy(), g_now.copy()
    tau_next = -g_now / c  # the first fixed-point step: exact for an emitter at rest
    active = np.flatnonzero(g_now != 0.0)
    for _ in range(max_iterations):
        if active.size == 0:
            return tau
        index = active
        tau_new = tau_next[index]
        g_new, rounding = g(tau_new, index)
        tau[index] = tau_new
        lower[index[g_new <= 0.0]] = tau_new[g_new <= 0.0]
        upper[index[g_new >= 0.0]] = tau_new[g_new >= 0.0]

        step = tau_new - tau_prev[index]
        converged = (np.abs(g_new) <= np.maximum(relative_tolerance * c * tau_new, rounding)) | (
            np.abs(step) <= relative_tolerance * tau_new
        )
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = (g_new - g_prev[index]) / step
        # The slope of g lies in [c - |u|, c + |u|]: a secant slope outside (0, 2c) is noise.
        slope = np.where(np.isfinite(slope) & (slope > 0.0) & (slope < 2.0 * c), slope, c)
        candidate = tau_new - g_new / slope
        lo, hi = lower[index], upper[index]
        outside = (candidate < lo) | (candidate > hi)
        candidate = np.where(outside & np.isfinite(hi), 0.5 * (lo + hi), np.where(outside, 2.0 * tau_new, candidate))

        tau_prev[index] = tau_new
        g_prev[index] = g_new
        tau_next[index] = candidate
        active = index[~converged]
    raise ValueError(
        f"retarded time did not converge for {active.size} point(s) in {max_iterations} iterations; "
        "is the world line slower than light, and has light from it reached the observer?"
    )


def retarded_time(
    world_line: WorldLine, observer_time: ArrayLike, observer_position: ArrayLike, c: float, **options: Any
) -> FloatArray:
    """Retarded times ``t_e = t_o - tau`` on arbitrary world lines (see :func:`light_travel_time`)."""
    tau = light_travel_time(world_line, observer_time, observer_position, c, **options)
    return np.asarray(observer_time, dtype=np.float64) - tau
