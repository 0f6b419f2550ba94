"""Apparent positions of moving points: where a (possibly moving) observer sees them
(docs/physics.md, "Light-travel time (retarded positions)").

Every world line is given in the scene frame S. The observer event is ``(t_o, x_o)`` in S and the
observer moves with ``observer_beta`` (fraction of c, world axes) through S. A point is seen as it
was at its retarded time ``t_e`` (``|x_o - x_e(t_e)| = c (t_o - t_e)``, solved in S: the light cone
is invariant). The emission event, taken relative to the observer event, is then boosted into the
observer frame S' (axes parallel to world); the apparent position is ``x_o + x'``. A renderer at
rest placed at ``x_o`` sees that point along the aberrated direction, at the distance ``r' = D r``.

Functions return world-axis positions and the point velocity relative to the observer
(fraction of c, observer frame), which the Doppler shaders need: ``D = 1 / (gamma (1 - beta·k))``.
"""

from typing import Any

import numpy as np

from .arrays import ArrayLike, FloatArray, WorldLine
from .lorentz import _boost, compose_velocities
from .retarded import light_travel_time, light_travel_time_uniform
from .validation import finite_array, speed_of_light, vector_array, velocity_array


def boost_emission_events(
    tau: ArrayLike, emission_positions: ArrayLike, observer_position: ArrayLike, observer_beta: ArrayLike, c: float
) -> FloatArray:
    """Emission events ``(t_o - tau, x_e)`` seen from the observer event ``(t_o, x_o)``.

    Boosts the relative event ``(-tau, x_e - x_o)`` into the frame moving with ``observer_beta``
    (docs/physics.md, "Lorentz boost") and returns ``x_o + x'`` (shape ``(N, 3)``), the position at
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


def velocity_seen_by_observer(point_beta: ArrayLike, observer_beta: ArrayLike) -> FloatArray:
    """Velocity (fraction of c) of points moving with ``point_beta`` in S, measured in the frame
    of an observer moving with ``observer_beta`` in S: S moves with ``-observer_beta`` there."""
    point_beta = velocity_array(point_beta, "point_beta")
    observer_beta = velocity_array(observer_beta, "observer_beta")
    if not np.any(observer_beta):
        return np.array(np.broadcast_to(point_beta, np.broadcast_shapes(point_beta.shape, (1, 3))))
    return compose_velocities(-observer_beta, point_beta)


def apparent_positions_uniform(
    observer_time: float,
    observer_position: ArrayLike,
    positions_now: ArrayLike,
    point_beta: ArrayLike,
    c: float,
    observer_beta: ArrayLike = (0.0, 0.0, 0.0),
) -> tuple[FloatArray, FloatArray, FloatArray]:
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
    finite_array(observer_time, "observer_time")
    if u.ndim == 1:
        return _apparent_positions_one_velocity(observer_position, p, u, c, observer_beta)
    tau = light_travel_time_uniform(observer_time, observer_position, p, u, c)
    emitted = p - (tau * c)[:, None] * u
    apparent = boost_emission_events(tau, emitted, observer_position, observer_beta, c)
    beta_seen = np.broadcast_to(velocity_seen_by_observer(u, observer_beta), p.shape)
    return apparent, tau, beta_seen


def _apparent_positions_one_velocity(observer_position, p, u, c, observer_beta):
    """Fast path of :func:`apparent_positions_uniform` when every point shares one velocity:
    the same closed form and boost, on contiguous coordinate rows ``(3, N)`` with in-place
    operations (about 5x fewer memory passes than the general path)."""
    x_o = vector_array(observer_position, "observer_position")
    beta_o = velocity_array(observer_beta, "observer_beta")
    velocity = u * c
    rows = np.ascontiguousarray(p.T) - x_o[:, None]  # emitter minus observer, -Delta
    tau = _light_travel_time_rows(rows, velocity, c)
    for k in range(3):  # emission event relative to the observer event
        if velocity[k]:
            rows[k] -= tau * velocity[k]
    _boost_rows(tau, rows, beta_o, c)
    rows += x_o[:, None]
    beta_seen = np.broadcast_to(velocity_seen_by_observer(u, beta_o), p.shape)
    return rows.T, tau, beta_seen


def _light_travel_time_rows(rows, velocity, c):
    """Closed form of :func:`retarded.light_travel_time_uniform` on coordinate rows: ``rows``
    (``(3, n)``) are the emitters at ``t_o`` minus the observer, ``velocity`` (scene units per
    second) is one 3-vector or rows ``(3, n)``; the caller has checked ``|velocity| < c``."""
    a = -_row_dot(rows, velocity)  # Delta·u
    q = _row_dot(rows, rows)
    b = c * c - _row_dot(velocity, velocity)
    root = a * a
    root += b * q
    np.sqrt(root, out=root)
    # (a + root) / b when a >= 0; the equal q / (root - a) when a < 0 (no cancellation); 0 at q = 0.
    tau = np.zeros_like(a)
    ahead = a >= 0.0
    root_plus_a = a + root
    np.divide(root_plus_a, b, out=tau, where=ahead)
    root -= a
    np.divide(q, root, out=tau, where=~ahead & (root > 0.0))
    return tau


def _boost_rows(tau, rows, beta_o, c):
    """:func:`boost_emission_events` in place on rows ``(3, n)`` of emission positions minus the
    observer position (events ``(-tau, rows)``); the observer's ``beta_o`` is already checked."""
    if not np.any(beta_o):
        return
    gamma = 1.0 / np.sqrt(1.0 - float(beta_o @ beta_o))
    # x' = x + (gamma^2/(gamma+1)) (beta·x) beta - gamma beta c t, with t = -tau.
    coefficient = (gamma * gamma / (gamma + 1.0)) * _row_dot(rows, beta_o)
    coefficient += (gamma * c) * tau
    for k in range(3):
        if beta_o[k]:
            rows[k] += coefficient * beta_o[k]


def _velocity_seen_rows(point_beta, beta_o):
    """:func:`velocity_seen_by_observer` in place on rows ``(3, n)`` of checked velocities
    (fractions of c): relativistic addition of ``-beta_o`` (lorentz.compose_velocities)."""
    if not np.any(beta_o):
        return
    v = -beta_o
    gamma = 1.0 / np.sqrt(1.0 - float(v @ v))
    v_u = _row_dot(point_beta, v)
    # u' = [u / gamma + v (1 + (gamma / (gamma + 1)) v·u)] / (1 + v·u)
    along = (gamma / (gamma + 1.0)) * v_u
    along += 1.0
    v_u += 1.0
    np.reciprocal(v_u, out=v_u)
    along *= v_u
    point_beta *= v_u / gamma
    for k in range(3):
        if v[k]:
            point_beta[k] += along * v[k]


def _row_dot(rows, vector):
    """Dot products of coordinate rows ``(3, N)`` with a 3-vector or other rows."""
    return rows[0] * vector[0] + rows[1] * vector[1] + rows[2] * vector[2]


def lorentz_contract(points: ArrayLike, centre: ArrayLike, beta: ArrayLike) -> FloatArray:
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


def lorentz_contraction_matrix(beta: ArrayLike) -> FloatArray:
    """The linear map of :func:`lorentz_contract` (about the origin): ``I - (1 - 1/gamma) bhat bhat^T``."""
    beta = velocity_array(beta, "beta")
    speed_squared = float(np.dot(beta, beta))
    if speed_squared == 0.0:
        return np.eye(3)
    gamma = 1.0 / np.sqrt(1.0 - speed_squared)
    bhat = beta / np.sqrt(speed_squared)
    return np.eye(3) - (1.0 - 1.0 / gamma) * np.outer(bhat, bhat)


def _uniform_grid(times: FloatArray) -> tuple[float, float, int]:
    """``(start, step, intervals)`` of increasing, uniformly spaced sample ``times``."""
    steps = np.diff(times)
    if np.any(steps <= 0.0) or np.ptp(steps) > 1e-9 * max(abs(times[-1]), abs(steps[0]), 1.0):
        raise ValueError("sample times must be increasing and uniformly spaced")
    return float(times[0]), float(steps[0]), times.size - 1


class SampledRigidMotion:
    """A rigid motion ``x(t) = A(t) p + b(t)`` sampled on a uniform time grid.

    ``times`` are uniformly spaced, ``matrices`` has shape ``(K, 4, 4)`` (object-to-world at each
    time). Between samples each matrix element follows a Catmull-Rom cubic (C1, exact for
    quadratics, so rotations stay accurate with a few samples per radian); beyond the grid the
    end slopes continue linearly (a cubic would run away and make trial points superluminal).
    ``local_points`` (``(N, 3)``) are the points in object space.

    Internally points are handled as ``(3, N)`` rows (contiguous coordinate arrays), grouped by
    sample interval, so each group costs one dense ``(12, 3) @ (3, n)`` product and a few
    in-place row operations instead of a gather of a 3x4 matrix per point.
    """

    def __init__(self, times: ArrayLike, matrices: ArrayLike, local_points: ArrayLike) -> None:
        times = finite_array(times, "times")
        matrices = finite_array(matrices, "matrices")
        if times.ndim != 1 or times.size < 2 or matrices.shape != (times.size, 4, 4):
            raise ValueError("need at least 2 sample times and one 4x4 matrix per time")
        self.start, self.step, self.intervals = _uniform_grid(times)
        affine = matrices[:, :3, :]  # (K, 3, 4)
        # Pad one sample each side (linear extrapolation) so every interval has 4 neighbours.
        padded = np.concatenate([2 * affine[:1] - affine[1:2], affine, 2 * affine[-1:] - affine[-2:-1]])
        p0, p1, p2, p3 = padded[:-3], padded[1:-2], padded[2:-1], padded[3:]
        # Catmull-Rom in power form per interval: A(f) = c0 + c1 f + c2 f^2 + c3 f^3, f in [0, 1].
        coefficients = np.stack(
            [
                p1,
                0.5 * (p2 - p0),
                p0 - 2.5 * p1 + 2.0 * p2 - 0.5 * p3,
                0.5 * (p3 - p0) + 1.5 * (p1 - p2),
            ],
            axis=1,
        )  # (intervals, 4, 3, 4)
        # Rows 3j..3j+2 of linear @ p + offset are coefficient j applied to p.
        self._coefficients = coefficients
        self._linear = np.ascontiguousarray(coefficients[..., :3].reshape(self.intervals, 12, 3))
        self._offset = np.ascontiguousarray(coefficients[..., 3].reshape(self.intervals, 12, 1))
        self.local_points = vector_array(local_points, "local_points")
        self._rows = np.ascontiguousarray(self.local_points.T)

    def _grid(self, t):
        return (np.asarray(t, dtype=np.float64) - self.start) / self.step

    def _interval_keys(self, s):
        interval = np.clip(np.floor(s), 0, self.intervals - 1)
        return interval.astype(np.int16 if self.intervals < 32000 else np.int64)

    def _affine_maps(self, s):
        """Position and velocity (per second) at the single grid coordinate ``s`` as affine maps
        of the local point ``p``, each ``(3, 4)``: ``x = M[:, :3] p + M[:, 3]``."""
        interval = int(self._interval_keys(s))
        f = float(s) - interval
        g = min(max(f, 0.0), 1.0)
        c0, c1, c2, c3 = self._coefficients[interval]
        rate = c1 + (2.0 * c2 + 3.0 * c3 * g) * g
        position = c0 + (c1 + (c2 + c3 * g) * g) * g + (f - g) * rate
        return position, rate / self.step

    def _evaluate_rows(self, s, keys, rows, with_acceleration=False):
        """Positions, velocities (per second) and optionally accelerations, each ``(3, n)``, at
        grid coordinates ``s`` for points ``rows`` (``(3, n)``) sorted by interval ``keys``."""
        count = len(s)
        positions = np.empty((3, count))
        velocities = np.empty((3, count))
        accelerations = np.empty((3, count)) if with_acceleration else None
        edges = np.concatenate([[0], np.flatnonzero(keys[1:] != keys[:-1]) + 1, [count]]) if count else [0]
        for a, b in zip(edges[:-1], edges[1:], strict=True):
            interval = int(keys[a])
            y = self._linear[interval] @ rows[:, a:b]
            y += self._offset[interval]
            f = s[a:b] - interval
            g = np.clip(f, 0.0, 1.0)
            y0, y1, y2, y3 = y[0:3], y[3:6], y[6:9], y[9:12]
            # Horner, written into the output slices: no temporaries of shape (3, n).
            position, rate = positions[:, a:b], velocities[:, a:b]
            np.multiply(y3, g, out=position)
            position += y2
            position *= g
            position += y1
            position *= g
            position += y0
            np.multiply(y3, 3.0 * g, out=rate)
            rate += y2
            rate += y2
            rate *= g
            rate += y1
            beyond = f - g
            if np.any(beyond):
                position += beyond * rate
            if with_acceleration:
                curvature = accelerations[:, a:b]
                np.multiply(y3, 6.0 * g, out=curvature)
                curvature += y2
                curvature += y2
                curvature[:, beyond != 0.0] = 0.0
        velocities /= self.step
        if accelerations is not None:
            accelerations /= self.step * self.step
            return positions, velocities, accelerations
        return positions, velocities

    def positions_and_velocities(self, t: ArrayLike, index: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """World positions and velocities (scene units per second), each ``(M, 3)``, of points
        ``index`` at times ``t``."""
        index = np.asarray(index)
        s = np.broadcast_to(self._grid(t), index.shape)
        keys = self._interval_keys(s)
        order = np.argsort(keys, kind="stable")  # radix sort for small integer keys
        positions, velocities = self._evaluate_rows(s[order], keys[order], self._rows[:, index[order]])
        result_positions = np.empty((len(index), 3))
        result_velocities = np.empty((len(index), 3))
        result_positions[order] = positions.T
        result_velocities[order] = velocities.T
        return result_positions, result_velocities

    def positions(self, t: ArrayLike, index: ArrayLike) -> FloatArray:
        """World positions of points ``index`` at times ``t`` (a ``world_line`` for the solver)."""
        return self.positions_and_velocities(t, index)[0]

    def velocities(self, t: ArrayLike, index: ArrayLike) -> FloatArray:
        """World velocities (scene units per second) of points ``index`` at times ``t``."""
        return self.positions_and_velocities(t, index)[1]


class SampledPointMotion:
    """Arbitrary (deforming) motion of N points sampled on a uniform time grid: ``positions`` has
    shape ``(K, N, 3)`` (world positions at each of the K ``times``). Each coordinate follows a
    Catmull-Rom cubic in time between samples and continues linearly beyond the grid, like
    :class:`SampledRigidMotion`. Use with :func:`apparent_positions` (``positions`` is its
    ``world_line``, ``velocities`` its ``velocity``)."""

    def __init__(self, times: ArrayLike, positions: ArrayLike) -> None:
        times = finite_array(times, "times")
        positions = finite_array(positions, "positions")
        if (
            times.ndim != 1
            or times.size < 2
            or positions.ndim != 3
            or positions.shape[0] != times.size
            or positions.shape[2] != 3
        ):
            raise ValueError("need at least 2 sample times and positions of shape (times, points, 3)")
        self.start, self.step, self.intervals = _uniform_grid(times)
        self._samples = np.concatenate(
            [2 * positions[:1] - positions[1:2], positions, 2 * positions[-1:] - positions[-2:-1]]
        )

    def positions_and_velocities(self, t: ArrayLike, index: ArrayLike) -> tuple[FloatArray, FloatArray]:
        index = np.asarray(index)
        s = (np.broadcast_to(np.asarray(t, dtype=np.float64), index.shape) - self.start) / self.step
        k = np.clip(np.floor(s), 0, self.intervals - 1).astype(np.int64)
        f = s - k
        g = np.clip(f, 0.0, 1.0)[:, None]
        p0, p1, p2, p3 = (self._samples[k + j, index] for j in range(4))
        c1 = 0.5 * (p2 - p0)
        c2 = p0 - 2.5 * p1 + 2.0 * p2 - 0.5 * p3
        c3 = 0.5 * (p3 - p0) + 1.5 * (p1 - p2)
        rate = (3.0 * c3 * g + 2.0 * c2) * g + c1
        position = ((c3 * g + c2) * g + c1) * g + p1 + (f[:, None] - g) * rate
        return position, rate / self.step

    def positions(self, t: ArrayLike, index: ArrayLike) -> FloatArray:
        return self.positions_and_velocities(t, index)[0]

    def velocities(self, t: ArrayLike, index: ArrayLike) -> FloatArray:
        return self.positions_and_velocities(t, index)[1]


# Points the sampled solver handles together: the temporaries of a block stay in the CPU caches
# (whole-array passes over a million points spend most of their time on memory) and its small
# matrix products stay single-threaded (larger ones make BLAS start threads on a busy machine).
_BLOCK_SIZE = 1 << 14


def apparent_positions_sampled(
    motion: SampledRigidMotion,
    observer_time: float,
    observer_position: ArrayLike,
    c: float,
    observer_beta: ArrayLike = (0.0, 0.0, 0.0),
    relative_tolerance: float = 1e-10,
    max_iterations: int = 30,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Apparent positions of the points of a :class:`SampledRigidMotion` (per-point retarded times).

    Solves ``g(tau) = c tau - |x_o - x(t_o - tau)| = 0`` by Halley's method with the motion's own
    velocity and acceleration (Newton where the curvature would misguide it): ``g' = c - (D·v)/|D|``
    lies in ``[c - |v|, c + |v|]``, positive for sub-luminal motion. The start is the retarded
    time ``t_c`` of the points' centroid plus, per point, the closed form for uniform motion with
    its velocity at ``t_c``, so two or three steps reach ``relative_tolerance``; each step
    evaluates only the points not yet converged. Points are sorted by the sample interval of
    their start and solved in blocks of consecutive points (re-sorted within a block only when
    one changes interval); points left over after ``max_iterations`` go to
    :func:`retarded.light_travel_time`. Returns ``(apparent, tau, beta_seen)``.
    """
    c = speed_of_light(c)
    x_o = vector_array(observer_position, "observer_position")
    beta_o = velocity_array(observer_beta, "observer_beta")
    t_o = float(finite_array(observer_time, "observer_time"))
    count = len(motion.local_points)
    apparent = np.empty((count, 3))
    tau = np.empty(count)
    beta_seen = np.empty((count, 3))
    if count == 0:
        return apparent, tau, beta_seen
    start = _uniform_motion_start(motion, t_o, x_o, c)
    order = np.argsort(motion._interval_keys(motion._grid(t_o) - start / motion.step), kind="stable")
    for first in range(0, count, _BLOCK_SIZE):
        block = order[first : first + _BLOCK_SIZE]
        for index, block_tau, emitted, velocity in _retarded_emissions(
            motion, block, start[block], t_o, x_o, c, relative_tolerance, max_iterations
        ):
            emitted -= x_o[:, None]
            _boost_rows(block_tau, emitted, beta_o, c)
            emitted += x_o[:, None]
            velocity /= c
            _velocity_seen_rows(velocity, beta_o)
            tau[index] = block_tau
            for k in range(3):  # one coordinate at a time: numpy's fast path for a scatter
                apparent[:, k][index] = emitted[k]
                beta_seen[:, k][index] = velocity[k]
    return apparent, tau, beta_seen


def _uniform_motion_start(motion, t_o, x_o, c):
    """Start values of the light-travel times, shape ``(N,)``: each point moving uniformly with
    its velocity at the retarded time of the points' centroid (found by Newton steps first)."""
    grid = float(motion._grid(t_o))
    centroid = motion._rows.mean(axis=1)
    tau_c = 0.0
    for _ in range(60):
        position_map, velocity_map = motion._affine_maps(grid - tau_c / motion.step)
        d_c = x_o - (position_map[:, :3] @ centroid + position_map[:, 3])
        r_c = float(np.sqrt(d_c @ d_c))
        v_c = velocity_map[:, :3] @ centroid + velocity_map[:, 3]
        slope = c - float(d_c @ v_c) / r_c if r_c > 0.0 else c
        step = (c * tau_c - r_c) / (slope if slope > 0.0 else c)
        tau_c = max(tau_c - step, 0.0)
        if abs(step) <= 1e-12 * (tau_c + 1e-300):
            break
    position_map, velocity_map = motion._affine_maps(grid - tau_c / motion.step)
    position_map = position_map + tau_c * velocity_map  # uniform extrapolation to t_o
    position_map[:, 3] -= x_o  # relative to the observer
    start = np.empty(len(motion.local_points))
    for first in range(0, len(start), _BLOCK_SIZE):
        rows = motion._rows[:, first : first + _BLOCK_SIZE]
        velocity = velocity_map[:, :3] @ rows
        velocity += velocity_map[:, 3:]
        if np.any(_row_dot(velocity, velocity) >= c * c):
            raise ValueError("the sampled motion is not slower than light")
        relative = position_map[:, :3] @ rows
        relative += position_map[:, 3:]
        start[first : first + _BLOCK_SIZE] = _light_travel_time_rows(relative, velocity, c)
    return start


def _retarded_emissions(motion, index, tau, t_o, x_o, c, relative_tolerance, max_iterations):
    """Halley iteration of :func:`apparent_positions_sampled` for the points ``index`` from the
    start values ``tau``. Yields ``(index, tau, emitted, velocity)`` for the points as they
    converge: their light-travel times, emission positions and velocities (scene units per
    second) as rows ``(3, n)``."""
    xo = x_o[:, None]
    grid = float(motion._grid(t_o))
    tolerance = relative_tolerance + 16.0 * np.finfo(float).eps
    rounding = 8.0 * np.finfo(float).eps * np.abs(x_o).sum()
    rows = np.take(motion.local_points, index, axis=0).T
    for _ in range(max_iterations):
        s = grid - tau / motion.step
        keys = motion._interval_keys(s)
        if np.any(keys[1:] < keys[:-1]):
            resort = np.argsort(keys, kind="stable")
            index, tau, s, keys = index[resort], tau[resort], s[resort], keys[resort]
            rows = np.take(rows, resort, axis=1)
        position, rate, acceleration = motion._evaluate_rows(s, keys, rows, with_acceleration=True)
        speed_squared = _row_dot(rate, rate)
        if np.any(speed_squared >= c * c):
            raise ValueError("the sampled motion is not slower than light")
        delta = xo - position
        distance = np.sqrt(_row_dot(delta, delta))
        g = c * tau - distance
        pending = np.abs(g) > tolerance * distance + rounding
        if not np.any(pending):
            yield index, tau, position, rate
            return
        done = ~pending
        if np.any(done):
            yield index[done], tau[done], np.compress(done, position, axis=1), np.compress(done, rate, axis=1)
        # Halley: g' = c - D·v/|D|, g'' = -[(v·v - D·a)/|D| - (D·v/|D|)^2/|D|], D = x_o - x(t_o - tau).
        with np.errstate(divide="ignore", invalid="ignore"):
            d_v = _row_dot(delta, rate) / distance
            slope = c - d_v
            curvature = -((speed_squared - _row_dot(delta, acceleration)) - d_v * d_v) / distance
            slope = np.where(slope > 0.0, slope, c)
            denominator = 2.0 * slope * slope - g * curvature
            step = np.where(denominator > slope * slope, 2.0 * g * slope / denominator, g / slope)
        index, rows = index[pending], np.compress(pending, rows, axis=1)
        tau = np.maximum(tau[pending] - step[pending], 0.0)
    tau = light_travel_time(lambda t, i: motion.positions(t, index[i]), t_o, x_o, c, count=index.size)
    position, rate = (np.ascontiguousarray(array.T) for array in motion.positions_and_velocities(t_o - tau, index))
    if np.any(_row_dot(rate, rate) >= c * c):
        raise ValueError("the sampled motion is not slower than light")
    yield index, tau, position, rate


def apparent_positions(
    world_line: WorldLine,
    observer_time: float,
    observer_position: ArrayLike,
    c: float,
    count: int,
    observer_beta: ArrayLike = (0.0, 0.0, 0.0),
    velocity: WorldLine | None = None,
    **solver_options: Any,
) -> tuple[FloatArray, FloatArray, FloatArray]:
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
