"""One polynomial over the window of retarded times (physics/polynomial_motion.py): on a body eased
along a cubic in time (Blender's two Bezier keys with auto handles), the modifier's solve must meet
the light-cone condition ``|x_o - x_e(t_e)| = c (t_o - t_e)`` (docs/physics.md, "Light-travel
time") evaluated on the exact motion, contracted about its origin along the origin's velocity there
(``contract`` of test_sampling.py); a motion whose acceleration jumps inside the window is refused."""

import numpy as np
import pytest
from test_sampling import contract

from relativity_addon.physics import polynomial_motion, sampling

C = 10.0
STEP = 1.0 / 192.0
X_O = np.array([0.3, -0.2, 5.0])
POINTS = np.array([[x, y, 0.0] for x in (-2.0, 0.0, 2.0) for y in (-2.0, 0.0, 2.0)])
REACH = float(np.max(np.linalg.norm(POINTS, axis=1)))


def _eased(kink=None, duration=30.0):
    """Origin along x: a smoothstep from -50 m to 100 m over ``duration`` s (0.75c at the middle at
    30 s; at 60 s the same motion twice as long, 0.375c, half the speed and a quarter of the
    acceleration); with
    ``kink`` (seconds) the velocity turns by 0.2c there (inside the window of ``t_o = 0.5``: the
    origin is seen as it was at about -1.9 s) (acceleration jumping)."""

    def origin(times):
        u = np.clip((np.asarray(times) + 10.0) / duration, 0.0, 1.0)
        x = -50.0 + 150.0 * (3.0 * u**2 - 2.0 * u**3)
        y = np.zeros_like(x) if kink is None else 2.0 * np.maximum(np.asarray(times) - kink, 0.0)
        return np.stack([x, y, np.zeros_like(x)], axis=1)

    def matrices(times):
        m = np.tile(np.eye(4), (len(times), 1, 1))
        m[:, :3, 3] = origin(times)
        return m

    return origin, matrices


def _window(matrices, t_o, reach=REACH):
    pieces = sampling.motion_intervals(matrices, STEP, t_o, X_O, C, reach, 1024)
    grid_now, per_distance = t_o / STEP - pieces.first, 1.0 / (C * STEP)
    tolerance = polynomial_motion.rounding_tolerance(pieces, X_O, reach, STEP, C)
    return pieces, grid_now, per_distance, tolerance


def _emitted(origin, t_e, points):
    """The points at times ``t_e`` (one each): the origin there plus the point contracted along the
    origin's velocity there."""
    h = 1e-4  # the origin's velocity at each retarded time, for the contraction
    velocity = (origin(t_e + h) - origin(t_e - h)) / (2.0 * h * C)
    return origin(t_e) + contract(points, velocity)


def _light_cone_departure(origin, t_o, sigma, points=POINTS):
    """``|x_e(t_o - sigma / c) - x_o| - sigma`` of the exact motion (scene units)."""
    return np.linalg.norm(_emitted(origin, t_o - sigma / C, points) - X_O, axis=1) - sigma


@pytest.mark.parametrize(("duration", "size", "steps"), [(30.0, 2.0, 1), (60.0, 2.0, 1), (30.0, 4.0, 2)])
def test_eased_motion_meets_the_light_cone(duration, size, steps):
    """The modifier's solve (``modifier_solve``, the steps ``choose_steps`` picks, checked at
    ``box_points``) on a flat square ``2 size`` wide: one closed-form step after the start's line for
    the 4 m square (the 30 s motion took two Newton steps before: one left the root by about 0.85 of
    the tolerance) and for the gentler 60 s motion; two for the 8 m square at 30 s, whose points'
    retarded times spread twice as far, where one step alone leaves the light cone by more than the
    check allows. The light-travel distances, emission points and velocities are checked against the
    exact motion on a 9 x 9 grid of the square (its points between the check points)."""
    points = np.array([[x, y, 0.0] for x in np.linspace(-size, size, 9) for y in np.linspace(-size, size, 9)])
    reach = float(np.max(np.linalg.norm(points, axis=1)))
    origin, matrices = _eased(duration=duration)
    t_o = 0.5
    pieces, grid_now, per_distance, tolerance = _window(matrices, t_o, reach)
    polynomial = polynomial_motion.fit_window(pieces, grid_now, per_distance, reach, tolerance)
    # the exact motion (no float32 samples here): the cubic follows it inside the tolerance (1.5e-6 for
    # the 4 m square, 7.7e-5 for the 8 m one: a window twice as long)
    assert polynomial is not None and polynomial.residual <= 0.2 * tolerance
    low, high = np.array([-size, -size, 0.0]), np.array([size, size, 0.0])
    form, found = polynomial_motion.choose_steps(polynomial, polynomial_motion.box_points(low, high, polynomial))
    assert found == steps
    sigma, emission, velocity = polynomial_motion.modifier_solve(form, points, steps)
    # the solve within CHECK_SHARE of the tolerance of the polynomial's root, the polynomial within its residual
    allowed = polynomial_motion.CHECK_SHARE * tolerance + polynomial.residual
    np.testing.assert_allclose(_light_cone_departure(origin, t_o, sigma, points), 0.0, atol=allowed)
    t_e = t_o - sigma / C
    np.testing.assert_allclose(emission, _emitted(origin, t_e, points) - X_O, atol=allowed)
    # the points' own velocities: the origin's plus the contraction's rate (up to 0.007c here)
    h = 1e-3
    exact_velocity = (_emitted(origin, t_e + h, points) - _emitted(origin, t_e - h, points)) / (2.0 * h * C)
    np.testing.assert_allclose(velocity, exact_velocity, atol=allowed / polynomial.half)
    if steps > 1:  # one step is not enough there: it leaves the polynomial's root (Newton's, to
        # convergence) by more than the check allows (2.8e-4 against 7.1e-5)
        one, _emission, _velocity = polynomial_motion.modifier_solve(form, points, 1)
        root, _u = polynomial_motion.solve(polynomial, points)
        assert np.max(np.abs(one - root)) > 2.0 * polynomial_motion.CHECK_SHARE * tolerance


def test_a_jump_of_acceleration_in_the_window_is_refused():
    _origin, matrices = _eased(kink=-1.9)
    pieces, grid_now, per_distance, tolerance = _window(matrices, 0.5)
    assert polynomial_motion.fit_window(pieces, grid_now, per_distance, REACH, tolerance) is None
