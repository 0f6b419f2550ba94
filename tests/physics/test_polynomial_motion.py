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


def _window(matrices, t_o):
    pieces = sampling.motion_intervals(matrices, STEP, t_o, X_O, C, REACH, 1024)
    grid_now, per_distance = t_o / STEP - pieces.first, 1.0 / (C * STEP)
    tolerance = polynomial_motion.rounding_tolerance(pieces, X_O, REACH, STEP, C)
    return pieces, grid_now, per_distance, tolerance


def _light_cone_departure(origin, t_o, sigma):
    """``|x_e(t_o - sigma / c) - x_o| - sigma`` of the exact motion (scene units)."""
    t_e = t_o - sigma / C
    h = 1e-4  # the origin's velocity at each retarded time, for the contraction
    velocity = (origin(t_e + h) - origin(t_e - h)) / (2.0 * h * C)
    emitted = origin(t_e) + contract(POINTS, velocity)
    return np.linalg.norm(emitted - X_O, axis=1) - sigma


@pytest.mark.parametrize(("duration", "steps"), [(30.0, 2), (60.0, 1)])
def test_eased_motion_meets_the_light_cone(duration, steps):
    """The modifier's steps (``newton_steps``): two for the 30 s motion, where one step alone leaves
    the root by more than a tenth of the tolerance (about 0.85 of it), one for the gentler 60 s motion."""
    origin, matrices = _eased(duration=duration)
    t_o = 0.5
    pieces, grid_now, per_distance, tolerance = _window(matrices, t_o)
    polynomial = polynomial_motion.fit_window(pieces, grid_now, per_distance, REACH, tolerance)
    # the exact motion (no float32 samples here): the cubic follows it far inside the tolerance
    assert polynomial is not None and polynomial.residual <= 1e-5 < tolerance
    assert polynomial_motion.newton_steps(polynomial, POINTS) == steps
    sigma, u = polynomial_motion.solve(polynomial, POINTS, steps=steps)
    assert np.all(np.abs(u) <= 1.0)
    np.testing.assert_allclose(_light_cone_departure(origin, t_o, sigma), 0.0, atol=2e-5)
    if steps > 1:  # one step is not enough there: the light cone missed by more than the bound allows
        one, _u = polynomial_motion.solve(polynomial, POINTS, steps=1)
        assert np.max(np.abs(_light_cone_departure(origin, t_o, one))) > 0.1 * tolerance


def test_a_jump_of_acceleration_in_the_window_is_refused():
    _origin, matrices = _eased(kink=-1.9)
    pieces, grid_now, per_distance, tolerance = _window(matrices, 0.5)
    assert polynomial_motion.fit_window(pieces, grid_now, per_distance, REACH, tolerance) is None
