"""A rigid motion's Catmull-Rom pieces over the window of its retarded times
(:class:`sampling.MotionIntervals`) replaced by ONE polynomial in time, where one fits them to the
samples' own float32 rounding, and the retarded-time solve the modifier runs on it
(``blender/geometry/keyframed_nodes.py``; docs/physics.md, "Light-travel time (retarded positions)").

Blender's default keys (Bezier, auto handles) are cubic in time between two keys, and the rest shape's
contraction changes slowly with the speed: over a window inside one key segment a cubic follows the
sampled motion to the rounding of the samples (``fcurve.evaluate`` is float32). Then the modifier
needs no per-point interval read: each point's position relative to the observer is
``x(u) = sum_i u**i (C_i[:, :3] p + C_i[:, 3])`` with ``u = (centre - sigma) / half`` (``sigma = c tau``,
the light-travel distance; ``u`` in [-1, 1] over the window, increasing with time), and
``sigma = |x(u(sigma))|`` is solved as the modifier does it (:func:`modifier_solve`): the polynomial
re-expanded about the middle of the points' light-travel distances, in units of length
(:class:`SolveForm`), a start on uniform motion along the line that best follows it there (its
quadratic and cubic terms' best straight lines over the points' span), then closed-form steps:
uniform motion through the point with its velocity there, solved exactly (one step is exact for
uniform motion; its error is the acceleration's alone, where a Newton step's also has the light
cone's curvature).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .arrays import FloatArray
from .sampling import MotionIntervals

DEGREE = 3  # cubic: Bezier segments with auto handles are cubic in time (the contraction is smooth)
SAMPLES_PER_INTERVAL = 8  # where the fit is made and its residual measured
STEPS = 2  # closed-form steps after the start: the modifier's most (choose_steps picks 1 where that converges)
CHECK_SHARE = 0.1  # the modifier's solve may leave the root by this share of the fit's tolerance
SPAN_MARGIN = 0.1  # the start's span: the check points' light-travel distances widened by this share each side
FLOAT32_ROUNDING = 2.0**-24  # half an ulp, relative
ABSOLUTE_FLOOR = 1e-6  # relative to the window's size: the tolerance where the samples round to nothing


@dataclass(frozen=True)
class WindowPolynomial:
    """``x(u)`` of the module docstring: ``coefficients`` ``(DEGREE + 1, 3, 4)`` (affine maps of the
    object-space point, relative to the observer), ``u = (centre - sigma) / half``; ``residual`` the
    largest departure from the Catmull-Rom pieces found over the window (scene units, for points
    within ``reach`` of the origin) and ``tolerance`` what it was allowed."""

    centre: float
    half: float
    coefficients: FloatArray
    residual: float
    tolerance: float


def rounding_tolerance(intervals: MotionIntervals, x_o: FloatArray, reach: float, step: float, c: float) -> float:
    """How far the sampled motion may depart from a smooth one by the float32 rounding of its samples
    (scene units): a translation ``T`` rounds by ``eps |T|``; the central differences that give each
    sample's contraction then move by ``eps |T| / step`` in velocity, which turns and shortens the
    contraction by up to about ``2 gamma`` times that over ``c``, over ``reach``."""
    translations = intervals.coefficients[:, 0, :, 3] + np.asarray(x_o, dtype=np.float64)
    largest = float(np.max(np.linalg.norm(translations, axis=1), initial=0.0))
    gamma = 1.0 / np.sqrt(max(1.0 - intervals.fastest**2, 1e-12))
    rounding = FLOAT32_ROUNDING * largest * (1.0 + 2.0 * gamma * reach / (c * step))
    size = float(np.max(np.linalg.norm(intervals.coefficients[:, 0, :, 3], axis=1), initial=0.0)) + reach
    return rounding + ABSOLUTE_FLOOR * size


def fit_window(
    intervals: MotionIntervals, grid_now: float, grid_per_distance: float, reach: float, tolerance: float
) -> WindowPolynomial | None:
    """One polynomial of DEGREE in time over all the intervals (grid coordinate ``s`` in ``[0, K]``,
    ``s = grid_now - sigma * grid_per_distance``), fitted by least squares in float64 on
    SAMPLES_PER_INTERVAL points of each interval; None when its residual there (``|dT| + |dA| reach``,
    ``|dA|`` the Frobenius norm of the 3x3's departure) is above ``tolerance`` (scene units)."""
    pieces = np.asarray(intervals.coefficients, dtype=np.float64)
    count = len(pieces)
    if count == 0:
        return None
    fractions = np.arange(SAMPLES_PER_INTERVAL) / SAMPLES_PER_INTERVAL
    powers = fractions[:, None] ** np.arange(4)  # (S, 4)
    maps = np.einsum("si,kiab->ksab", powers, pieces).reshape(-1, 12)
    end = np.einsum("i,iab->ab", np.ones(4), pieces[-1]).reshape(1, 12)  # f = 1 of the last interval
    maps = np.concatenate([maps, end])  # at _least_squares' samples
    half_grid = 0.5 * count
    vandermonde, inverse = _least_squares(count)
    solution = inverse @ maps
    departure = (maps - vandermonde @ solution).reshape(-1, 3, 4)
    residual = float(
        np.max(np.linalg.norm(departure[:, :, 3], axis=1) + reach * np.linalg.norm(departure[:, :, :3], axis=(1, 2)))
    )
    if not residual <= tolerance:
        return None
    centre = (grid_now - half_grid) / grid_per_distance
    return WindowPolynomial(
        centre, half_grid / grid_per_distance, solution.reshape(DEGREE + 1, 3, 4), residual, tolerance
    )


@functools.lru_cache(maxsize=16)
def _least_squares(count: int) -> tuple[FloatArray, FloatArray]:
    """The fit's Vandermonde matrix over ``count`` intervals' samples and its pseudo-inverse (the
    least-squares solve), kept per count: a frame step or an observer change fits the same count."""
    s = np.append((np.arange(count)[:, None] + np.arange(SAMPLES_PER_INTERVAL) / SAMPLES_PER_INTERVAL).ravel(), count)
    u = (s - 0.5 * count) / (0.5 * count)
    vandermonde = u[:, None] ** np.arange(DEGREE + 1)
    return vandermonde, np.linalg.pinv(vandermonde)


def solve(polynomial: WindowPolynomial, points: FloatArray, steps: int = 24) -> tuple[FloatArray, FloatArray]:
    """The root in float64 for object-space ``points`` ``(N, 3)`` (the reference the modifier's solve is
    checked against): the light-travel distances ``sigma`` ``(N,)`` after the closed-form start at the
    window's centre velocity and up to ``steps`` Newton steps on ``|x|^2 - sigma^2`` (fewer where the
    last moved no ``sigma`` by more than 1e-13 of the largest), and ``u`` there."""
    affine = np.column_stack((np.asarray(points, dtype=np.float64), np.ones(len(points))))
    terms = np.einsum("iab,nb->ina", polynomial.coefficients, affine)  # P_i per point
    rate = 1.0 / polynomial.half
    # uniform motion through P0 at the centre with velocity w = P1 / half: |r - sigma w| = sigma
    w = terms[1] * rate
    sigma = _closed_form(terms[0] + polynomial.centre * w, w)
    for _ in range(steps):
        u = (polynomial.centre - sigma) * rate
        value, slope = _horner(terms, u)
        m = (sigma * sigma - np.einsum("ij,ij->i", value, value)) / (np.einsum("ij,ij->i", value, slope) * rate + sigma)
        sigma = sigma - 0.5 * m
        if not np.max(np.abs(m), initial=0.0) > 2e-13 * np.max(np.abs(sigma), initial=1.0):
            break  # converged (or NaN, which more steps would keep)
    return sigma, (polynomial.centre - sigma) * rate


def _closed_form(r: FloatArray, w: FloatArray) -> FloatArray:
    """``sigma`` of ``|r - sigma w| = sigma`` (uniform motion; in whichever form avoids cancellation)."""
    a, q, b = np.einsum("ij,ij->i", r, w), np.einsum("ij,ij->i", r, r), 1.0 - np.einsum("ij,ij->i", w, w)
    root = np.sqrt(b * q + a * a)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a > 0.0, q / (root + a), (root - a) / b)


def _horner(terms: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``sum_i u**i terms[i]`` and its derivative in ``u`` (Horner's scheme, the derivative alongside)."""
    value, slope = terms[-1], np.zeros_like(terms[-1])
    for term in terms[-2::-1]:
        slope = slope * u[:, None] + value
        value = value * u[:, None] + term
    return value, slope


@dataclass(frozen=True)
class SolveForm:
    """The polynomial as the modifier solves it: ``x(v) = sum_i v**i Q_i``, ``Q_i = coefficients[i]``
    applied to ``(p, 1)``, ``v = centre - sigma`` (scene units: ``dx/dv`` is the velocity, fraction of
    c), re-expanded about ``centre``, the middle of the span of the points' light-travel distances.
    The start: uniform motion through ``Q_0 + start_offset Q_2`` at ``v = 0`` with the velocity
    ``Q_1 + start_slope Q_3`` (the best straight lines of ``v**2`` and ``v**3`` over the span's
    half-width ``h``: ``h**2 / 2`` and ``3 h**2 v / 4``, Chebyshev's)."""

    centre: float
    coefficients: FloatArray
    start_offset: float
    start_slope: float


def solve_form(polynomial: WindowPolynomial, low: float, high: float) -> SolveForm:
    """:class:`SolveForm` of ``polynomial`` for light-travel distances spanning ``low`` to ``high``."""
    centre, half_width = 0.5 * (low + high), 0.5 * (high - low)
    shift = (polynomial.centre - centre) / polynomial.half  # u at the new centre
    old = np.asarray(polynomial.coefficients, dtype=np.float64)
    degree = len(old) - 1
    shifted = np.zeros_like(old)
    for i in range(degree + 1):  # Taylor's shift: u = shift + v / half
        for k in range(i, degree + 1):
            shifted[i] += math.comb(k, i) * shift ** (k - i) * old[k]
    scaled = shifted / polynomial.half ** np.arange(degree + 1)[:, None, None]
    return SolveForm(centre, scaled, 0.5 * half_width**2, 0.75 * half_width**2)


def modifier_solve(form: SolveForm, points: FloatArray, steps: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The modifier's solve in float64 for object-space ``points`` ``(N, 3)``: the light-travel
    distances ``sigma``, the emission points (relative to the observer: on the last step's uniform
    motion) and the velocities there (the polynomial's, at the last ``sigma``; fraction of c)."""
    affine = np.column_stack((np.asarray(points, dtype=np.float64), np.ones(len(points))))
    terms = np.einsum("iab,nb->ina", form.coefficients, affine)  # Q_i per point
    w = terms[1] + form.start_slope * terms[3]
    r = terms[0] + form.start_offset * terms[2] + form.centre * w
    sigma = _closed_form(r, w)
    for _ in range(steps):
        x, w = _horner(terms, form.centre - sigma)
        r = x + sigma[:, None] * w
        sigma = _closed_form(r, w)
    emission = r - sigma[:, None] * w
    _x, velocity = _horner(terms, form.centre - sigma)
    return sigma, emission, velocity


def choose_steps(polynomial: WindowPolynomial, points: FloatArray) -> tuple[SolveForm, int] | None:
    """The modifier's form and the fewest closed-form steps (1 up to STEPS) whose light-travel
    distances and emission points reach the root's to CHECK_SHARE of the tolerance, and velocities
    to that over the window's half-size, at the check ``points`` (``box_points``), each point's
    retarded time inside the window; None when STEPS do not. The start's error is the departure of
    the motion from a straight line over the span (the span widened by SPAN_MARGIN each side, for
    points between the check points), a step's error grows with the square of the error it starts
    from and with the acceleration."""
    exact, u = solve(polynomial, points)
    if not np.all(np.abs(u) <= 1.0):
        return None
    affine = np.column_stack((np.asarray(points, dtype=np.float64), np.ones(len(points))))
    x, slope = _horner(np.einsum("iab,nb->ina", polynomial.coefficients, affine), u)
    velocity = slope / polynomial.half
    margin = SPAN_MARGIN * float(np.ptp(exact)) + 1e-6 * polynomial.half
    form = solve_form(polynomial, float(np.min(exact)) - margin, float(np.max(exact)) + margin)
    allowed = CHECK_SHARE * polynomial.tolerance
    for steps in range(1, STEPS + 1):
        sigma, emission, found_velocity = modifier_solve(form, points, steps)
        if (
            np.all(np.abs(sigma - exact) <= allowed)
            and np.all(np.linalg.norm(emission - x, axis=1) <= allowed)
            and np.all(np.linalg.norm(found_velocity - velocity, axis=1) <= allowed / polynomial.half)
        ):
            return form, steps
    return None


def box_points(low: FloatArray, high: FloatArray, polynomial: WindowPolynomial) -> FloatArray:
    """Where :func:`choose_steps` checks a rest box (object space, ``low`` to ``high``): its corners,
    edges' middles, faces' centres and centre, and its point nearest the observer at the window's
    centre (the polynomial's ``x(0) = A p + b = 0`` at ``p = -A^-1 b``, clamped to the box): the
    farthest light-travel distance lies at a corner, the nearest near that point."""
    low, high = np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64)
    thirds = np.stack([low, 0.5 * (low + high), high])  # (3, 3): each axis' low, middle, high
    grid = np.stack(np.meshgrid(*thirds.T, indexing="ij"), axis=-1).reshape(-1, 3)
    centre_map = np.asarray(polynomial.coefficients[0], dtype=np.float64)
    try:
        nearest = np.clip(np.linalg.solve(centre_map[:, :3], -centre_map[:, 3]), low, high)[None, :]
    except np.linalg.LinAlgError:  # a flat map (a zero scale): the grid alone
        nearest = np.zeros((0, 3))
    return np.concatenate([grid, nearest])
