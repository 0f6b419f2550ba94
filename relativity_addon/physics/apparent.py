"""Apparent positions of moving points: where a (possibly moving) observer sees them
(PHYSICS.md, "Light-travel time (retarded positions)").

Every world line is given in the scene frame S. The observer event is ``(t_o, x_o)`` in S and the
observer moves with ``observer_beta`` (fraction of c, world axes) through S. A point is seen as it
was at its retarded time ``t_e`` (``|x_o - x_e(t_e)| = c (t_o - t_e)``, solved in S: the light cone
is invariant). The emission event, taken relative to the observer event, is then boosted into the
observer frame S' (axes parallel to world); the apparent position is ``x_o + x'``. A renderer at
rest placed at ``x_o`` sees that point along the aberrated direction, at the distance ``r' = D r``.

Functions return world-axis positions and the point velocity relative to the observer
(fraction of c, observer frame), which the Doppler shaders need: ``D = 1 / (gamma (1 - beta·k))``.
"""

import numpy as np

from .lorentz import _boost, compose_velocities
from .retarded import light_travel_time, light_travel_time_uniform
from .validation import finite_array, speed_of_light, vector_array, velocity_array


def boost_emission_events(tau, emission_positions, observer_position, observer_beta, c):
    """Emission events ``(t_o - tau, x_e)`` seen from the observer event ``(t_o, x_o)``.

    Boosts the relative event ``(-tau, x_e - x_o)`` into the frame moving with ``observer_beta``
    (PHYSICS.md, "Lorentz boost") and returns ``x_o + x'`` (shape ``(N, 3)``), the position at
    which a renderer at rest at ``x_o`` must draw the point. ``tau`` is kept small-and-relative
    so that the real ``c`` does not round it away.
    """
    c = speed_of_light(c)
    beta = velocity_array(observer_beta, "observer_beta")
    x_o = vector_array(observer_position, "observer_position")
    relative = np.asarray(emission_positions, dtype=np.float64) - x_o
    if not np.any(beta):
        return relative + x_o
    _, boosted = _boost(-np.asarray(tau, dtype=np.float64), relative, beta, c)
    return boosted + x_o


def velocity_seen_by_observer(point_beta, observer_beta):
    """Velocity (fraction of c) of points moving with ``point_beta`` in S, measured in the frame
    of an observer moving with ``observer_beta`` in S: S moves with ``-observer_beta`` there."""
    point_beta = velocity_array(point_beta, "point_beta")
    observer_beta = velocity_array(observer_beta, "observer_beta")
    if not np.any(observer_beta):
        return np.array(np.broadcast_to(point_beta, np.broadcast_shapes(point_beta.shape, (1, 3))))
    return compose_velocities(-observer_beta, point_beta)


def apparent_positions_uniform(observer_time, observer_position, positions_now, point_beta, c,
                               observer_beta=(0.0, 0.0, 0.0)):
    """Apparent positions of points in uniform motion ``x_e(t) = p + u (t - t_o)``.

    ``positions_now`` (``p``, shape ``(N, 3)``) are the points' positions in S at the observer's
    time ``t_o``; ``point_beta`` is ``u / c``, shape ``(3,)`` or ``(N, 3)``. The light-travel time
    is the closed form of :func:`retarded.light_travel_time_uniform`.

    Returns ``(apparent, tau, beta_seen)``: apparent positions (world axes, see
    :func:`boost_emission_events`), light-travel times ``t_o - t_e`` in S, and the points'
    velocities in the observer frame.
    """
    c = speed_of_light(c)
    p = vector_array(positions_now, "positions_now")
    u = velocity_array(point_beta, "point_beta")
    tau = light_travel_time_uniform(observer_time, observer_position, p, u, c)
    emitted = p - (tau * c)[:, None] * u
    apparent = boost_emission_events(tau, emitted, observer_position, observer_beta, c)
    beta_seen = np.broadcast_to(velocity_seen_by_observer(u, observer_beta), p.shape)
    return apparent, tau, beta_seen


def lorentz_contract(points, centre, beta):
    """Rest-frame shape -> its shape in a frame where it moves with ``beta``: the component of
    ``points - centre`` along ``beta`` shrinks by ``1 / gamma`` (simultaneity in that frame)."""
    points = vector_array(points, "points")
    beta = velocity_array(beta, "beta")
    speed_squared = float(np.dot(beta, beta))
    if speed_squared == 0.0:
        return points.copy()
    gamma = 1.0 / np.sqrt(1.0 - speed_squared)
    bhat = beta / np.sqrt(speed_squared)
    relative = points - centre
    along = relative @ bhat
    return points - ((1.0 - 1.0 / gamma) * along)[:, None] * bhat


class SampledRigidMotion:
    """A rigid motion ``x(t) = A(t) p + b(t)`` sampled on a uniform time grid.

    ``times`` are uniformly spaced, ``matrices`` has shape ``(K, 4, 4)`` (object-to-world at each
    time). Between samples each matrix element is interpolated with a Catmull-Rom cubic (error
    O(h^4), so rotations stay accurate with a few samples per radian); outside the grid the end
    intervals are extrapolated. ``local_points`` (``(N, 3)``) are the points in object space.
    """

    def __init__(self, times, matrices, local_points):
        times = finite_array(times, "times")
        matrices = finite_array(matrices, "matrices")
        if times.ndim != 1 or times.size < 2 or matrices.shape != (times.size, 4, 4):
            raise ValueError("need at least 2 sample times and one 4x4 matrix per time")
        steps = np.diff(times)
        if np.any(steps <= 0.0) or np.ptp(steps) > 1e-9 * max(abs(times[-1]), abs(steps[0]), 1.0):
            raise ValueError("sample times must be increasing and uniformly spaced")
        self.start = float(times[0])
        self.step = float(steps[0])
        # Pad one sample each side (linear extrapolation) so every interval has 4 neighbours.
        affine = matrices[:, :3, :].reshape(times.size, 12)
        self._samples = np.concatenate(
            [2 * affine[:1] - affine[1:2], affine, 2 * affine[-1:] - affine[-2:-1]])
        self.local_points = vector_array(local_points, "local_points")

    def _weights(self, t):
        s = (np.asarray(t, dtype=np.float64) - self.start) / self.step
        last = self._samples.shape[0] - 3  # index of the last original sample
        clamped = np.clip(s, 0.0, float(last))
        index = np.minimum(np.floor(clamped).astype(np.int64), last - 1)
        f = clamped - index
        f2 = f * f
        f3 = f2 * f
        # Catmull-Rom basis for samples index-1 .. index+2 (padded arrays start one earlier).
        weights = np.stack([
            0.5 * (-f3 + 2.0 * f2 - f),
            0.5 * (3.0 * f3 - 5.0 * f2 + 2.0),
            0.5 * (-3.0 * f3 + 4.0 * f2 + f),
            0.5 * (f3 - f2),
        ], axis=-1)
        return index, weights, s - clamped

    def affine_at(self, t):
        """Interpolated 3x4 object-to-world matrices, shape ``t.shape + (3, 4)``. Outside the
        sampled range the end intervals continue linearly (a cubic would run away and make the
        retarded-time solver's trial points superluminal)."""
        index, weights, beyond = self._weights(t)
        samples = self._samples
        result = weights[..., 0, None] * samples[index]
        for j in range(1, 4):
            result += weights[..., j, None] * samples[index + j]
        if np.any(beyond):
            start_slope = samples[2] - samples[1]
            end_slope = samples[-2] - samples[-3]
            slope = np.where((beyond < 0.0)[..., None], start_slope, end_slope)
            result += beyond[..., None] * slope
        return result.reshape(np.shape(t) + (3, 4))

    def positions(self, t, index):
        """World positions of points ``index`` at times ``t`` (the solver's ``world_line``)."""
        affine = self.affine_at(t)
        p = self.local_points[index]
        return np.einsum("nij,nj->ni", affine[..., :3], p) + affine[..., 3]

    def velocities(self, t, index, delta=None):
        """World velocities (scene units per second) by a central difference of the cubic."""
        delta = self.step * 1e-3 if delta is None else delta
        t = np.asarray(t, dtype=np.float64)
        return (self.positions(t + delta, index) - self.positions(t - delta, index)) / (2.0 * delta)


def apparent_positions(world_line, observer_time, observer_position, c, count,
                       observer_beta=(0.0, 0.0, 0.0), velocity=None, **solver_options):
    """Apparent positions of ``count`` points on arbitrary sub-luminal world lines.

    ``world_line(t, index)`` returns positions ``(M, 3)`` (see :func:`retarded.light_travel_time`);
    each point is evaluated at its own retarded time. ``velocity(t, index)`` (optional) returns
    velocities in scene units per second; without it ``beta_seen`` is the observer's motion only.

    Returns ``(apparent, tau, beta_seen)`` as :func:`apparent_positions_uniform`.
    """
    c = speed_of_light(c)
    tau = light_travel_time(world_line, observer_time, observer_position, c, count=count, **solver_options)
    index = np.arange(count)
    t_e = np.asarray(observer_time, dtype=np.float64) - tau
    emitted = finite_array(world_line(np.broadcast_to(t_e, (count,)), index), "world_line positions")
    apparent = boost_emission_events(tau, emitted, observer_position, observer_beta, c)
    if velocity is None:
        point_beta = np.zeros((count, 3))
    else:
        point_beta = finite_array(velocity(np.broadcast_to(t_e, (count,)), index), "velocity") / c
    beta_seen = velocity_seen_by_observer(point_beta, observer_beta)
    return apparent, tau, np.broadcast_to(beta_seen, (count, 3))


def retarded_times_from_apparent(observer_time, observer_position, apparent, c):
    """For an observer at rest in S: ``t_e = t_o - |x_o - x_apparent| / c`` (checking aid)."""
    c = speed_of_light(c)
    distance = np.linalg.norm(vector_array(apparent, "apparent") - vector_array(observer_position, "observer_position"), axis=-1)
    return np.asarray(observer_time, dtype=np.float64) - distance / c
