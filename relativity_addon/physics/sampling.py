"""Apparent positions of a rigid motion given as a function of time: choose the window of sample
times that holds every point's retarded time, sample the motion there, solve
(docs/physics.md, "Light-travel time (retarded positions)").

The apparent-geometry path knows an animated object's world matrix at any time (from keyframes)
but sampling a whole animation would be wasteful: light seen at ``t_o`` left each vertex at its
own retarded time ``t_e = t_o - tau``, all of them within about ``2 reach / c`` of the object
centre's light-travel time (``reach``: the largest distance of a vertex from the centroid). This
module samples the motion on a uniform grid around that estimate, solves with
:func:`apparent.apparent_positions_sampled`, and widens the window while some retarded time falls
outside it (a point receding or approaching fast is seen much earlier or later than the estimate).
"""

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .apparent import SampledRigidMotion, apparent_positions_sampled
from .arrays import ArrayLike, BoolArray, FloatArray
from .rest_shape import check_samples_used, contracted_rigid_samples
from .validation import finite_array, positive_array, speed_of_light, vector_array

# Most sample times one window may hold: 200000 matrices of 4x4 float64 are 25 MB.
MAX_SAMPLES = 200_000

# world_matrices_at_times(t): object-to-world matrices (K, 4, 4) at scene times t (K,), seconds.
MatrixFunction = Callable[[FloatArray], ArrayLike]


def apparent_positions_from_matrix_function(
    world_matrices_at_times: MatrixFunction,
    step: float,
    rest_local: ArrayLike,
    t_o: float,
    x_o: ArrayLike,
    beta_o: ArrayLike,
    c: float,
    max_tries: int = 4,
    *,
    world_matrix_now: ArrayLike | None = None,
    max_samples: int = MAX_SAMPLES,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Apparent positions of points ``rest_local`` (``(N, 3)``, object space, the body's rest shape)
    of a rigid body whose object-to-world matrices at scene times ``t`` (seconds, shape ``(K,)``)
    are ``world_matrices_at_times(t)`` (shape ``(K, 4, 4)``), seen from the event ``(t_o, x_o)`` by
    an observer moving with ``beta_o`` (fraction of c, world axes); ``c`` in scene units per second.
    The rest shape is Lorentz-contracted about the origin along the origin's velocity at each
    sample (:func:`rest_shape.contracted_rigid_samples`), so at each point's retarded time.

    The motion is sampled at multiples of ``step`` (seconds; e.g. one animation sub-frame): first
    around ``t_o - |x_o - centroid| / c`` (the centroid's travel time) widened by ``2 reach / c``
    and two steps each side, ``reach`` being the largest distance of a point from the centroid at
    ``t_o`` (``world_matrix_now``, default ``world_matrices_at_times([t_o])[0]``). Between samples
    the motion is a Catmull-Rom cubic (:class:`apparent.SampledRigidMotion`); each sample is
    contracted with the central difference of its neighbours (one sample more is read beyond each
    end of the window), so the motion does not depend on the window: it is the one
    :func:`motion_intervals` gives the modifier. When a retarded time
    falls outside the inner samples (not between the second and the second-last), the window is
    stretched to hold all of them with four steps to spare, and solved again, up to ``max_tries``
    windows in all.

    Returns ``(apparent, tau, beta_seen)`` as :func:`apparent.apparent_positions_sampled`: world
    positions ``(N, 3)``, light-travel times ``t_o - t_e`` ``(N,)`` and the points' velocities in
    the observer frame ``(N, 3)``. Raises ``ValueError`` when a window would need more than
    ``max_samples`` samples, when the retarded times do not settle inside the window after
    ``max_tries`` windows, or for bad input (the motion, or the origin at a sample a retarded time
    uses, not slower than light, NaN, ...).
    """
    c = speed_of_light(c)
    step = float(positive_array(step, "step"))
    t_o = float(finite_array(t_o, "t_o"))
    x_o = vector_array(x_o, "x_o")
    rest_local = vector_array(rest_local, "rest_local").reshape(-1, 3)
    if max_tries < 1:
        raise ValueError("max_tries must be at least 1")
    if world_matrix_now is None:
        world_matrix_now = np.asarray(world_matrices_at_times(np.array([t_o])), dtype=np.float64)[0]
    matrix_now = finite_array(world_matrix_now, "world_matrix_now")
    if matrix_now.shape != (4, 4):
        raise ValueError(f"world matrices must be 4x4, got shape {matrix_now.shape}")
    world_now = rest_local @ matrix_now[:3, :3].T + matrix_now[:3, 3]
    if len(world_now):
        centroid = world_now.mean(0)
        reach = float(np.max(np.linalg.norm(world_now - centroid, axis=1)))
        centre_tau = float(np.linalg.norm(x_o - centroid)) / c
    else:
        reach = centre_tau = 0.0
    low = t_o - centre_tau - 2.0 * reach / c - 2 * step
    high = t_o - centre_tau + 2.0 * reach / c + 2 * step
    for _ in range(max_tries):
        low_index, high_index = math.floor(low / step) - 2, math.ceil(high / step) + 2
        if high_index - low_index > max_samples:
            raise ValueError(
                f"light-travel times span too many animation samples ({high_index - low_index + 1} > {max_samples}"
                f" samples of {step:.4g} s, from {low:.4g} s to {high:.4g} s)"
            )
        times = np.arange(low_index, high_index + 1) * step
        matrices, superluminal = _contracted_window(world_matrices_at_times, low_index, high_index, step, c)
        result = apparent_positions_sampled(SampledRigidMotion(times, matrices, rest_local), t_o, x_o, c, beta_o)
        t_e = t_o - result[1]
        if t_e.size == 0 or (t_e.min() >= times[1] and t_e.max() <= times[-2]):
            check_samples_used(t_e, times[0], step, superluminal)
            return result
        margin = 4 * step
        low, high = min(low, t_e.min() - margin), max(high, t_e.max() + margin)
    raise ValueError(
        f"retarded times did not settle inside the sampled animation in {max_tries} windows "
        f"(last retarded times {t_e.min():.4g}..{t_e.max():.4g} s, window {times[1]:.4g}..{times[-2]:.4g} s)"
    )


def _contracted_window(
    world_matrices_at_times: MatrixFunction, first: int, last: int, step: float, c: float
) -> tuple[FloatArray, BoolArray]:
    """The contracted samples ``first..last`` (grid indices) and their superluminal mask: read with
    one sample more each side, so every sample's velocity is the central difference."""
    times = np.arange(first - 1, last + 2) * step
    matrices, superluminal = contracted_rigid_samples(world_matrices_at_times(times), step, c)
    return matrices[1:-1], superluminal[1:-1]


@dataclass(frozen=True)
class MotionIntervals:
    """A rigid motion's Catmull-Rom pieces over the sample intervals that hold every retarded time
    of a body (:func:`motion_intervals`): interval ``j`` runs from grid index ``first + j`` to the
    next (times ``k step``), and on it the world position of the object-space point ``p`` is
    ``sum_i f**i (coefficients[j, i, :, :3] @ p + coefficients[j, i, :, 3])`` minus ``x_o``
    (``f`` in [0, 1] across the interval). ``start_distance``: ``c tau`` of the origin."""

    first: int
    coefficients: FloatArray  # (K, 4, 3, 4)
    start_distance: float
    fastest: float  # the origin's largest knot speed over the intervals, fraction of c


def motion_intervals(
    world_matrices_at_times: MatrixFunction,
    step: float,
    t_o: float,
    x_o: ArrayLike,
    c: float,
    reach: float,
    max_intervals: int,
    guess: float | None = None,
) -> MotionIntervals | None:
    """The pieces of the motion of :func:`apparent_positions_from_matrix_function` (the same samples,
    contraction and Catmull-Rom cubic) over the intervals where the retarded times of every point
    within ``reach`` of the object's origin (object space: scaled by the largest singular value of
    the matrices' 3x3) lie, seen from ``(t_o, x_o)``; None when they span more than
    ``max_intervals`` intervals or the origin is not slower than light there.

    The bound: with ``g(tau) = c tau - |O(t_o - tau) - x_o|`` (``O``: the origin), ``g' >= c - v``
    (``v``: the origin's largest speed) and a point's ``|g| <= reach``, so its ``tau`` lies within
    ``reach / (c - v)`` of the origin's. ``v`` is the largest knot speed of the window (the bound
    widened by 5% and two steps for the cubic between knots; the modifier checks that every
    retarded time it finds lies inside); the window is widened until it holds its own bound. The
    origin's ``tau`` comes from :func:`origin_light_travel_time` (``guess``: a light-travel time
    to start from, e.g. the last one), the window's speed and size bounds start from the knots
    around it; where that solve does not settle, from the general solver and zero speed."""
    c = speed_of_light(c)
    step = float(positive_array(step, "step"))
    x_o = vector_array(x_o, "x_o")
    found = origin_light_travel_time(world_matrices_at_times, step, t_o, x_o, c, guess)
    if found is None:  # not settled on the knots read, or a knot not slower than light: the general solver
        origin = apparent_positions_from_matrix_function(
            world_matrices_at_times, step, np.zeros((1, 3)), t_o, x_o, np.zeros(3), c
        )
        tau = float(origin[1][0])
        speed = 0.0
        now = np.asarray(world_matrices_at_times(np.array([t_o])), dtype=np.float64)[0, :3, :3]
        size = float(np.linalg.svd(now, compute_uv=False)[0])
    else:
        # started from the knots around the origin's retarded time: their speed with the loop's
        # room, and the cubic's bound on their 3x3 (a uniform motion's window settles at once)
        tau, near = found
        near_speed = float(np.max(np.linalg.norm(near[2:, :3, 3] - near[:-2, :3, 3], axis=1))) / (2.0 * step * c)
        speed = near_speed + 0.1 * (1.0 - near_speed) if near_speed > 0.0 else 0.0
        size = 1.25 * float(np.max(np.linalg.svd(near[1:-1, :3, :3], compute_uv=False)[:, 0]))
    for _ in range(8):
        if speed >= 1.0:
            return None
        half = 1.05 * reach * size / (c * (1.0 - speed)) + 2.0 * step
        first = math.floor((t_o - tau - half) / step)
        last = math.ceil((t_o - tau + half) / step)
        if last - first > max_intervals:
            return None
        # knots first - 1 .. last + 1 (every interval's Catmull-Rom neighbours)
        knots, superluminal = _contracted_window(world_matrices_at_times, first - 1, last + 1, step, c)
        if np.any(superluminal):
            return None
        origins = knots[:, :3, 3]
        fastest = float(np.max(np.linalg.norm(origins[2:] - origins[:-2], axis=1))) / (2.0 * step * c)
        # the cubic's weights sum to at most 1.25 in magnitude: the interpolated 3x3 stays below
        largest = 1.25 * float(np.max(np.linalg.svd(knots[:, :3, :3], compute_uv=False)[:, 0]))
        if fastest <= speed and largest <= size:
            break
        speed = max(speed, fastest + 0.1 * (1.0 - fastest))  # some room: fewer widenings
        size = max(size, largest)
    else:
        return None
    affine = knots[:, :3, :].copy()
    affine[:, :, 3] -= x_o
    p0, p1, p2, p3 = affine[:-3], affine[1:-2], affine[2:-1], affine[3:]
    coefficients = np.stack(
        [p1, 0.5 * (p2 - p0), p0 - 2.5 * p1 + 2.0 * p2 - 0.5 * p3, 0.5 * (p3 - p0) + 1.5 * (p1 - p2)], axis=1
    )
    return MotionIntervals(first, coefficients, c * tau, speed)


def origin_light_travel_time(
    world_matrices_at_times: MatrixFunction,
    step: float,
    t_o: float,
    x_o: FloatArray,
    c: float,
    guess: float | None = None,
    max_iterations: int = 40,
) -> tuple[float, FloatArray] | None:
    """The light-travel time ``tau`` (seconds) of the origin of the motion of
    :func:`apparent_positions_from_matrix_function` seen from ``(t_o, x_o)`` (docs/physics.md,
    "Light-travel time (retarded positions)": ``c tau = |x_o - O(t_o - tau)|``), with the origin
    ``O`` the Catmull-Rom cubic through the sampled matrices' translations (which the contraction
    keeps), and the knots ``k - 2 .. k + 3`` around its interval ``k`` (``(6, 4, 4)``, not
    contracted). Newton's method on ``g(tau) = c tau - |O(t_o - tau) - x_o|`` (``g' >= c - |O'| > 0``)
    from ``guess`` (default: the origin's distance at ``t_o`` over ``c``), reading knots a few at a
    time (one call per block, so a kept grid costs a lookup). None when it does not settle in
    ``max_iterations``, or an interval's knots around the root are not slower than light (the
    general solver then, which says why)."""
    block: dict[int, FloatArray] = {}

    def knots(first: int, last: int) -> FloatArray:
        missing = [k for k in range(first, last + 1) if k not in block]
        if missing:
            low, high = min(missing), max(missing)
            values = np.asarray(world_matrices_at_times(np.arange(low, high + 1) * step), dtype=np.float64)
            block.update(zip(range(low, high + 1), values, strict=True))
        return np.stack([block[k] for k in range(first, last + 1)])

    def origin(t: float) -> tuple[FloatArray, FloatArray, int]:
        s = t / step
        k = math.floor(s)
        f = s - k
        p0, p1, p2, p3 = knots(k - 1, k + 2)[:, :3, 3]
        c1, c2, c3 = 0.5 * (p2 - p0), p0 - 2.5 * p1 + 2.0 * p2 - 0.5 * p3, 0.5 * (p3 - p0) + 1.5 * (p1 - p2)
        return p1 + (c1 + (c2 + c3 * f) * f) * f, (c1 + (2.0 * c2 + 3.0 * c3 * f) * f) / step, k

    if guess is None or not math.isfinite(guess) or guess < 0.0:
        guess = float(np.linalg.norm(origin(t_o)[0] - x_o)) / c
    tau = float(guess)
    for _ in range(max_iterations):
        position, velocity, k = origin(t_o - tau)
        offset = position - x_o
        distance = float(np.sqrt(offset @ offset))
        slope = c + (float(offset @ velocity) / distance if distance > 0.0 else 0.0)
        if slope <= 0.0:
            return None
        change = (c * tau - distance) / slope
        tau = max(tau - change, 0.0)
        if abs(change) <= 1e-13 * (1.0 + abs(tau)):
            break
    else:
        return None
    k = math.floor((t_o - tau) / step)
    near = knots(k - 2, k + 3)
    speeds = np.linalg.norm(near[2:, :3, 3] - near[:-2, :3, 3], axis=1) / (2.0 * step)
    if not np.all(speeds < c):
        return None
    return tau, near


# The relative rounding of a sampled motion's translations the window of :func:`uniform_motion_window`
# allows for (Blender evaluates F-curves in float32: about four ulps of 2**-23).
SAMPLE_ROUNDING = 5e-7


def uniform_motion_window(
    origin: ArrayLike,
    velocity: ArrayLike,
    size: float,
    step: float,
    t_o: float,
    x_o: ArrayLike,
    c: float,
    reach: float,
    max_intervals: int,
) -> tuple[float, float, float] | None:
    """For a motion whose origin is ``origin + velocity t`` (scene units, seconds) and whose 3x3 is
    one matrix of largest singular value ``size``: ``(low, high, tau)`` with ``tau`` the origin's
    light-travel time seen from ``(t_o, x_o)`` (docs/physics.md, "Light-travel time (retarded
    positions)": ``c tau = |d - velocity tau|``, ``d`` the origin at ``t_o`` relative to ``x_o``,
    the root of a quadratic), and ``[low, high]`` (seconds) a span that holds every sample
    :func:`motion_intervals` reads for this motion sampled on the grid ``k step`` with each sample's
    translation off the line by at most :data:`SAMPLE_ROUNDING` of its size (float32 keys): its
    intervals' knots with their neighbours, four steps to spare. None where those samples might not
    give intervals (the speed within that rounding of c, or more than ``max_intervals`` intervals):
    without sampling, a caller can tell that the motion over every knot of the window is this line
    (the keys draw it over ``[low, high]``) and take its closed form.

    The bound is :func:`motion_intervals`' own, ``reach size / (c (1 - v))`` widened by 5% and two
    steps, with the largest speed ``v`` its knots may show (the line's, plus the rounding over two
    steps, plus its tenth of room) and its ``tau`` moved by the rounding over ``c (1 - v)``."""
    # in float scalars: called per keyframed object and update (issue 26: 1,000 objects)
    origin, velocity, x_o = _vector3(origin, "origin"), _vector3(velocity, "velocity"), _vector3(x_o, "x_o")
    c, step, t_o = float(c), float(step), float(t_o)
    if not (0.0 < c < math.inf and 0.0 < step < math.inf and math.isfinite(t_o)):
        raise ValueError("c and step must be positive and finite, t_o finite")
    d = [o + u * t_o - x for o, u, x in zip(origin, velocity, x_o, strict=True)]
    u2, du, d2 = (
        math.fsum(a * b for a, b in zip(p, q, strict=True)) for p, q in ((velocity, velocity), (d, velocity), (d, d))
    )
    speed = math.sqrt(u2) / c
    if speed >= 1.0:
        return None
    # (c^2 - u^2) tau^2 + 2 (d.u) tau - d^2 = 0, the positive root in the form without cancellation
    root = math.sqrt(du * du + (c * c - u2) * d2)
    tau = d2 / (root + du) if du > 0.0 else (root - du) / (c * c - u2)
    extent = 0.0  # the window's largest |t - t_o|: the samples' size, so their rounding, grows with it
    for _ in range(2):
        size_there = max(map(abs, origin)) + math.sqrt(u2) * (abs(t_o) + tau + extent)
        rounding = SAMPLE_ROUNDING * (1.0 + size_there)
        fastest = speed + rounding / (step * c)
        room = fastest + 0.1 * (1.0 - fastest)
        if room >= 1.0 - 1e-9:
            return None
        half = 1.05 * reach * 1.25 * size * (1.0 + 1e-6) / (c * (1.0 - room)) + 2.0 * step
        shift = 2.0 * rounding / (c * (1.0 - fastest))
        extent = 2.0 * (half + shift + 8.0 * step)  # twice: the second pass's rounding covers its own window
    first = math.floor((t_o - tau - shift - half) / step) - 4
    last = math.ceil((t_o - tau + shift + half) / step) + 4
    if last - first - 8 > max_intervals:
        return None
    return first * step, last * step, tau


def _vector3(value: ArrayLike, name: str) -> list[float]:
    values = [float(v) for v in np.asarray(value, dtype=np.float64).reshape(-1)]
    if len(values) != 3 or not all(map(math.isfinite, values)):
        raise ValueError(f"{name} must be a finite 3-vector")
    return values
