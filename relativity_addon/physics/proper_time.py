"""Proper time along a world line: ``tau = integral dt / gamma(t)`` (docs/physics.md), and its
inverse, the scene time at which a traveller's clock reads a given time.

A moving observer's (or object's) clock runs slow by ``1 / gamma``; a fly-through whose frames
step in the traveller's proper time shows frame ``k`` at the scene time ``t_k`` with
``tau(t_k) = k / fps``.
"""

import numpy as np
from numpy.typing import ArrayLike

from .arrays import FloatArray
from .validation import finite_array


def proper_times(times: ArrayLike, speeds: ArrayLike) -> FloatArray:
    """``tau`` at each of ``times`` (increasing, seconds) for speeds ``|beta|`` there, ``tau = 0`` at
    ``times[0]``: the trapezoidal integral of ``sqrt(1 - beta^2)``."""
    times = finite_array(times, "times")
    speeds = finite_array(speeds, "speeds")
    if times.shape != speeds.shape or times.ndim != 1 or len(times) < 2:
        raise ValueError("times and speeds must be matching 1-D arrays of at least two samples")
    if np.any(np.diff(times) <= 0.0):
        raise ValueError("times must increase")
    if np.any(np.abs(speeds) >= 1.0):
        raise ValueError("speeds must be below 1 (the speed of light)")
    rate = np.sqrt(1.0 - speeds * speeds)
    return np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(times))])


def scene_times(tau: ArrayLike, times: ArrayLike, taus: ArrayLike) -> FloatArray:
    """The scene times at which the clock reads ``tau``, from its readings ``taus`` at ``times``
    (``tau`` increases strictly with t: linear interpolation between samples). ValueError outside
    the sampled range."""
    tau = np.atleast_1d(finite_array(tau, "tau"))
    taus = finite_array(taus, "taus")
    if tau.min() < taus[0] or tau.max() > taus[-1]:
        raise ValueError(
            f"proper time {tau.min():.6g}..{tau.max():.6g} s outside the sampled {taus[0]:.6g}..{taus[-1]:.6g} s"
        )
    return np.interp(tau, taus, np.asarray(times, dtype=np.float64))


def path_proper_times(times: ArrayLike, positions: ArrayLike, c: float, zero_time: float = 0.0) -> FloatArray:
    """``tau`` at each of ``times`` (increasing, seconds) along the world line through ``positions``
    (``(K, 3)``, scene units) there, taken straight between samples (the exact integral of
    ``dt / gamma`` for that piecewise-uniform motion), ``c`` in scene units per second; the clock
    reads 0 at ``zero_time`` (inside the samples). ValueError for a step at or above c."""
    times = finite_array(times, "times")
    positions = finite_array(positions, "positions").reshape(len(times), -1)
    if times.ndim != 1 or len(times) < 2:
        raise ValueError("times must be a 1-D array of at least two samples")
    steps = np.diff(times)
    if np.any(steps <= 0.0):
        raise ValueError("times must increase")
    speeds = np.linalg.norm(np.diff(positions, axis=0), axis=1) / (steps * float(c))
    if np.any(speeds >= 1.0):
        raise ValueError(f"the world line moves at {speeds.max():.6g} c between samples: not slower than light")
    taus = np.concatenate([[0.0], np.cumsum(np.sqrt(1.0 - speeds * speeds) * steps)])
    if not times[0] <= zero_time <= times[-1]:
        raise ValueError(f"the clock's zero {zero_time:.6g} s lies outside the samples")
    return taus - np.interp(zero_time, times, taus)


def own_animation_at_proper_time(times: ArrayLike, positions: ArrayLike, origins: ArrayLike, c: float) -> FloatArray:
    """Sampled points of a body (``positions`` ``(K, N, 3)`` at ``times`` ``(K,)``, its origin at
    ``origins`` ``(K, 3)``) with everything but the origin's path played at the body's proper time:
    at ``t_k`` the points keep the origin ``origins[k]`` and take the arrangement about the origin
    that they had at the scene time ``tau(t_k)`` (linear between samples), ``tau`` along the
    origin's path with 0 at scene time 0 (:func:`path_proper_times`). Before the first sample
    (after the last) the clock is taken to run at its rate of the first (last) step, and an
    arrangement asked for before the first sample is the first sample's."""
    times = finite_array(times, "times")
    positions = finite_array(positions, "positions")
    origins = finite_array(origins, "origins").reshape(len(times), 3)
    if positions.ndim != 3 or positions.shape[0] != len(times) or positions.shape[2] != 3:
        raise ValueError("positions must have shape (K, N, 3) with K the number of times")
    zero = min(max(0.0, float(times[0])), float(times[-1]))
    taus = path_proper_times(times, origins, c, zero_time=zero)
    rates = np.diff(taus) / np.diff(times)
    taus = taus + (zero * rates[0] if zero > 0.0 else 0.0) + (zero * rates[-1] if zero < 0.0 else 0.0)
    index = np.clip(np.searchsorted(times, taus, side="right") - 1, 0, len(times) - 2)
    weight = np.clip((taus - times[index]) / (times[index + 1] - times[index]), 0.0, 1.0)[:, None, None]
    relative = positions - origins[:, None, :]
    arranged = (1.0 - weight) * relative[index] + weight * relative[index + 1]
    return origins[:, None, :] + arranged
