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
``sigma = |x(u(sigma))|`` is solved from the closed form of uniform motion at the window's centre
velocity (exact for uniform motion) by Newton steps on ``|x|^2 - sigma^2``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arrays import FloatArray
from .sampling import MotionIntervals

DEGREE = 3  # cubic: Bezier segments with auto handles are cubic in time (the contraction is smooth)
SAMPLES_PER_INTERVAL = 8  # where the fit is made and its residual measured
NEWTON_STEPS = 2  # after the closed-form start: the modifier's most (newton_steps picks 1 where that converges)
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
    s = (np.arange(count)[:, None] + fractions).ravel()
    end = np.einsum("i,iab->ab", np.ones(4), pieces[-1]).reshape(1, 12)  # f = 1 of the last interval
    maps, s = np.concatenate([maps, end]), np.append(s, float(count))
    half_grid = 0.5 * count
    u = (s - half_grid) / half_grid
    vandermonde = u[:, None] ** np.arange(DEGREE + 1)
    solution, *_ = np.linalg.lstsq(vandermonde, maps, rcond=None)
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


def solve(polynomial: WindowPolynomial, points: FloatArray, steps: int = NEWTON_STEPS) -> tuple[FloatArray, FloatArray]:
    """The modifier's solve for object-space ``points`` ``(N, 3)`` in float64: the light-travel
    distances ``sigma`` ``(N,)`` after the closed-form start and ``steps`` Newton steps, and ``u`` there."""
    affine = np.column_stack((np.asarray(points, dtype=np.float64), np.ones(len(points))))
    terms = np.einsum("iab,nb->ina", polynomial.coefficients, affine)  # P_i per point
    rate = 1.0 / polynomial.half
    # uniform motion through P0 at the centre with velocity w = P1 / half: |r - sigma w| = sigma
    w = terms[1] * rate
    r = terms[0] + polynomial.centre * w
    a, q, b = np.einsum("ij,ij->i", r, w), np.einsum("ij,ij->i", r, r), 1.0 - np.einsum("ij,ij->i", w, w)
    root = np.sqrt(b * q + a * a)
    with np.errstate(divide="ignore", invalid="ignore"):
        sigma = np.where(a > 0.0, q / (root + a), (root - a) / b)
    for _ in range(steps):
        u = (polynomial.centre - sigma) * rate
        value, slope = terms[-1], np.zeros_like(terms[-1])
        for term in terms[-2::-1]:  # Horner's scheme, the derivative alongside
            slope = slope * u[:, None] + value
            value = value * u[:, None] + term
        m = (sigma * sigma - np.einsum("ij,ij->i", value, value)) / (np.einsum("ij,ij->i", value, slope) * rate + sigma)
        sigma = sigma - 0.5 * m
    return sigma, (polynomial.centre - sigma) * rate


def newton_steps(polynomial: WindowPolynomial, corners: FloatArray) -> int | None:
    """The fewest Newton steps (1 up to NEWTON_STEPS, the modifier's choices) that reach the root to a
    tenth of the tolerance at the rest box's corners, each corner's retarded time inside the window;
    None when NEWTON_STEPS do not. The start's error, the departure from uniform motion, is affine in
    the point (largest at a corner), and a step's error grows with the error it starts from (Newton's
    ``e' = f'' e^2 / (2 f')``): the corners bound the points."""
    exact, u = solve(polynomial, corners, steps=NEWTON_STEPS + 20)
    if not np.all(np.abs(u) <= 1.0):
        return None
    for steps in range(1, NEWTON_STEPS + 1):
        found, _u = solve(polynomial, corners, steps=steps)
        if np.all(np.abs(found - exact) <= 0.1 * polynomial.tolerance):
            return steps
    return None
