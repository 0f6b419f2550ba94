"""Apparent positions (physics/apparent.py) against docs/physics.md relations written out here."""

import math

import numpy as np
import pytest

from relativity_addon.physics import apparent

RNG = np.random.default_rng(4)


def light_cone_residual(x_o, tau, x_e, c):
    """(|x_o - x_e| - c tau) / (c tau), tau = t_o - t_e: zero on the past light cone."""
    distance = np.linalg.norm(x_o - x_e, axis=-1)
    return (distance - c * tau) / (c * tau)


def boost(t, x, beta, c):
    """docs/physics.md: x' = x + (gamma-1)(bhat.x) bhat - gamma beta c t, c t' = gamma (c t - beta.x)."""
    beta = np.asarray(beta, float)
    b2 = beta @ beta
    g = 1.0 / math.sqrt(1.0 - b2)
    bx = x @ beta
    xp = x + ((g - 1.0) / b2 * bx - g * c * t)[:, None] * beta
    return g * (c * t - bx) / c, xp


@pytest.mark.parametrize("c", [1.0, 10.0, 299792458.0])
def test_uniform_motion_lies_on_light_cone_and_matches_closed_form(c):
    n = 500
    t_o, x_o = 2.5, np.array([0.3, -1.0, 0.5])
    p = RNG.normal(size=(n, 3)) * 5.0
    u = RNG.normal(size=(n, 3))
    u *= (RNG.uniform(0.0, 0.95, n) / np.linalg.norm(u, axis=1))[:, None]
    result, tau, _ = apparent.apparent_positions_uniform(t_o, x_o, p, u, c)
    x_e = p - (c * tau)[:, None] * u
    np.testing.assert_allclose(result, x_e, rtol=0, atol=1e-12 * 5)
    assert np.max(np.abs(light_cone_residual(x_o, tau, result, c))) < 1e-9
    # Closed form of docs/physics.md written out independently.
    delta = x_o - p
    uu = u * c
    a = np.sum(delta * uu, 1)
    b = c * c - np.sum(uu * uu, 1)
    tau_expected = (a + np.sqrt(a * a + b * np.sum(delta * delta, 1))) / b
    np.testing.assert_allclose(tau, tau_expected, rtol=1e-6)
    # The general solver on the same world lines agrees with the closed form within 1e-6 relative.
    general, tau_general, _ = apparent.apparent_positions(
        lambda t, i: p[i] + ((t - t_o) * c)[:, None] * u[i], t_o, x_o, c, n
    )
    np.testing.assert_allclose(tau_general, tau_expected, rtol=1e-6)
    scale = np.linalg.norm(general - x_o, axis=1)
    assert np.max(np.linalg.norm(general - result, axis=1) / scale) < 1e-6


def test_moving_observer_sees_aberrated_direction_at_doppler_distance():
    c = 3.0
    beta = np.array([0.5, -0.3, 0.6])
    x_o = np.array([1.0, 2.0, -0.5])
    p = x_o + RNG.normal(size=(200, 3)) * 4.0
    seen, tau, beta_seen = apparent.apparent_positions_uniform(1.0, x_o, p, np.zeros(3), c, beta)
    r = np.linalg.norm(p - x_o, axis=1)
    k = (x_o - p) / r[:, None]  # photon propagation direction, scene frame
    g = 1.0 / math.sqrt(1.0 - beta @ beta)
    bhat = beta / np.linalg.norm(beta)
    k_prime = (k + (g - 1.0) * (k @ bhat)[:, None] * bhat - g * beta) / (g * (1.0 - k @ beta))[:, None]
    r_seen = np.linalg.norm(seen - x_o, axis=1)
    np.testing.assert_allclose((x_o - seen) / r_seen[:, None], k_prime, atol=1e-12)
    doppler = g * (1.0 - k @ beta)
    np.testing.assert_allclose(r_seen, doppler * r, rtol=1e-12)
    np.testing.assert_allclose(tau, r / c, rtol=1e-12)
    np.testing.assert_allclose(beta_seen, np.broadcast_to(-beta, (200, 3)), atol=1e-15)


def test_moving_observer_equals_scene_moving_past_observer_at_rest():
    """Seen from the camera frame, a static scene moves with -beta: solve the light cone there."""
    c = 2.0
    beta = np.array([0.0, 0.8, 0.1])
    t_o, x_o = 0.7, np.array([0.5, 0.0, 1.0])
    p = x_o + RNG.normal(size=(300, 3)) * 3.0
    seen, _, _ = apparent.apparent_positions_uniform(t_o, x_o, p, np.zeros(3), c, beta)
    # Camera-frame world lines of the scene points: x'(t') = x'_0 + (-beta c) t' after boosting the
    # events (0, p - x_o); the light-cone equation is solved by fixed-point iteration.
    t0p, x0p = boost(np.zeros(len(p)), p - x_o, beta, c)
    tp = np.zeros(len(p))
    for _ in range(400):
        position = x0p + ((tp - t0p) * c)[:, None] * (-beta)
        tp = -np.linalg.norm(position, axis=1) / c
    position = x0p + ((tp - t0p) * c)[:, None] * (-beta)
    np.testing.assert_allclose(seen - x_o, position, atol=1e-9)


def rigid_wheel(omega, radius, centre_velocity, c):
    def matrix(t):
        a = omega * t
        m = np.zeros(np.shape(t) + (4, 4))
        m[..., 0, 0], m[..., 0, 1] = np.cos(a), -np.sin(a)
        m[..., 1, 0], m[..., 1, 1] = np.sin(a), np.cos(a)
        m[..., 2, 2] = m[..., 3, 3] = 1.0
        m[..., :3, 3] = np.multiply.outer(t, centre_velocity)
        return m

    return matrix


@pytest.mark.parametrize("solver", ["newton", "bracketed"])
def test_sampled_rotating_wheel_satisfies_light_cone_with_exact_motion(solver):
    c, radius = 10.0, 1.0
    omega = 0.9 * c / radius  # rim at 0.9 c (plus the centre's drift)
    matrix = rigid_wheel(omega, radius, np.array([0.5, 0.0, 0.0]), c)  # fastest point 0.95 c
    angles = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    local = np.stack([radius * np.cos(angles), radius * np.sin(angles), np.zeros_like(angles)], 1)
    times = np.arange(-1.0, 0.6, 1.0 / 240.0)
    motion = apparent.SampledRigidMotion(times, matrix(times), local)
    t_o, x_o = 0.5, np.array([0.0, -3.0, 1.0])
    if solver == "newton":
        seen, tau, beta_seen = apparent.apparent_positions_sampled(motion, t_o, x_o, c)
    else:
        seen, tau, beta_seen = apparent.apparent_positions(
            motion.positions, t_o, x_o, c, len(local), velocity=motion.velocities
        )
    t_e = t_o - tau
    exact = np.einsum("nij,nj->ni", matrix(t_e)[:, :3, :3], local) + matrix(t_e)[:, :3, 3]
    assert np.max(np.abs(light_cone_residual(x_o, tau, exact, c))) < 1e-6
    assert np.max(np.linalg.norm(seen - exact, axis=1) / (c * tau)) < 1e-6
    # Rim speed measured from the motion: |omega x r + v| / c.
    expected_velocity = np.stack(
        [-omega * (exact[:, 1] - 0.0), omega * (exact[:, 0] - t_e * 0.5), np.zeros_like(t_e)], 1
    ) + np.array([0.5, 0.0, 0.0])
    # Velocities (for the Doppler shaders) come from the cubic's slope: 1e-3 of c is plenty.
    np.testing.assert_allclose(beta_seen, expected_velocity / c, atol=1e-3)
    assert np.max(np.linalg.norm(beta_seen, axis=1)) < 1.0


def test_velocity_seen_by_moving_observer_is_relativistic_difference():
    observer = np.array([0.6, 0.0, 0.0])
    point = np.array([[0.6, 0.0, 0.0], [-0.6, 0.0, 0.0], [0.0, 0.5, 0.0]])
    seen = apparent.velocity_seen_by_observer(point, observer)
    np.testing.assert_allclose(seen[0], 0.0, atol=1e-15)
    np.testing.assert_allclose(seen[1], [-1.2 / 1.36, 0.0, 0.0], rtol=1e-12)
    # Transverse: u'_y = u_y / (gamma (1 - v u_x)), u'_x = -v.
    np.testing.assert_allclose(seen[2], [-0.6, 0.5 * 0.8, 0.0], rtol=1e-12)


@pytest.mark.parametrize("bad", [(1.0, 0.0, 0.0), (float("nan"), 0.0, 0.0)])
def test_bad_velocities_raise(bad):
    with pytest.raises(ValueError):
        apparent.apparent_positions_uniform(0.0, np.zeros(3), np.ones((2, 3)), np.zeros(3), 1.0, bad)
    with pytest.raises(ValueError):
        apparent.apparent_positions_uniform(0.0, np.zeros(3), np.ones((2, 3)), bad, 1.0)


def test_lorentz_contraction_is_simultaneous_boost_of_rest_shape():
    """Rest-frame points, boosted into the frame where they move with beta, at equal times there."""
    beta = np.array([0.3, 0.6, -0.2])
    centre = np.array([1.0, 2.0, 3.0])
    rest = centre + RNG.normal(size=(50, 3))
    contracted = apparent.lorentz_contract(rest, centre, beta)
    # Rest frame R moves with beta in S. Event (t_R, x_R) -> S via the boost with -beta; choose t_R
    # per point so that the S times are all 0 (c t = gamma (c t_R + beta.x_R) = 0).
    c = 1.0
    x_r = rest - centre
    t_r = -(x_r @ beta) / c
    _, x_s = boost(t_r, x_r, -beta, c)
    np.testing.assert_allclose(contracted - centre, x_s, atol=1e-12)


def test_sampled_motion_with_moving_observer_matches_general_solver():
    c = 3.0
    matrix = rigid_wheel(1.0, 1.0, np.array([0.5, 0.2, 0.0]), c)
    local = RNG.uniform(-1.0, 1.0, size=(300, 3))  # fastest point below 2.0 < c
    times = np.arange(-8.0, 2.0, 1.0 / 64.0)
    motion = apparent.SampledRigidMotion(times, matrix(times), local)
    beta = (0.1, -0.6, 0.3)
    t_o, x_o = 1.0, np.array([2.0, 5.0, 1.0])
    fast = apparent.apparent_positions_sampled(motion, t_o, x_o, c, beta)
    general = apparent.apparent_positions(motion.positions, t_o, x_o, c, len(local), beta, velocity=motion.velocities)
    np.testing.assert_allclose(fast[1], general[1], rtol=1e-8)
    np.testing.assert_allclose(fast[0], general[0], atol=1e-9)
    np.testing.assert_allclose(fast[2], general[2], atol=1e-9)


@pytest.mark.parametrize("max_iterations", [1, 30])
def test_sampled_solver_in_blocks_and_its_fallback_match_general_solver(max_iterations):
    """More points than one solver block, in random order (so they are sorted across blocks);
    with a single Halley step most points finish in the bracketed fallback solver."""
    c = 10.0
    matrix = rigid_wheel(4.0, 1.0, np.array([2.0, 0.0, 0.0]), c)  # fastest point below 6.2 < c
    local = RNG.uniform(-1.0, 1.0, size=(2 * apparent._BLOCK_SIZE + 123, 3))
    times = np.arange(-2.0, 1.5, 1.0 / 192.0)
    motion = apparent.SampledRigidMotion(times, matrix(times), local)
    t_o, x_o = 1.0, np.array([0.0, 0.0, 6.0])
    fast = apparent.apparent_positions_sampled(motion, t_o, x_o, c, (0.0, 0.3, 0.0), max_iterations=max_iterations)
    general = apparent.apparent_positions(
        motion.positions, t_o, x_o, c, len(local), (0.0, 0.3, 0.0), velocity=motion.velocities
    )
    np.testing.assert_allclose(fast[1], general[1], rtol=1e-8)
    np.testing.assert_allclose(fast[0], general[0], atol=1e-9)
    np.testing.assert_allclose(fast[2], general[2], atol=1e-9)
    emitted = motion.positions(t_o - fast[1], np.arange(len(local)))
    assert np.max(np.abs(light_cone_residual(x_o, fast[1], emitted, c))) < 1e-9


def test_superluminal_sampled_motion_raises():
    matrix = rigid_wheel(20.0, 1.0, np.zeros(3), 1.0)
    times = np.arange(-5.0, 1.0, 0.01)
    motion = apparent.SampledRigidMotion(times, matrix(times), np.array([[1.0, 0.0, 0.0]]))
    with pytest.raises(ValueError, match="slower than light"):
        apparent.apparent_positions_sampled(motion, 0.0, np.array([0.0, -5.0, 0.0]), 1.0)


def test_sampled_point_motion_deforming_points_on_light_cone():
    """Points on individually accelerated paths x_i(t) = p_i + a_i t^2 / 2 (|v| < c there)."""
    c = 5.0
    p = RNG.uniform(-1.0, 1.0, (200, 3)) + np.array([0.0, 0.0, -6.0])
    acc = RNG.uniform(-1.0, 1.0, (200, 3))
    times = np.arange(-3.0, 0.5, 1.0 / 50.0)
    exact = lambda t, i: p[i] + 0.5 * acc[i] * (t**2)[:, None]  # noqa: E731
    samples = p[None] + 0.5 * acc[None] * (times**2)[:, None, None]
    motion = apparent.SampledPointMotion(times, samples)
    t_o, x_o = 0.2, np.zeros(3)
    seen, tau, beta_seen = apparent.apparent_positions(
        motion.positions, t_o, x_o, c, len(p), velocity=motion.velocities
    )
    truth = exact(t_o - tau, np.arange(len(p)))
    # Quadratic motion is reproduced exactly by Catmull-Rom: agreement at rounding level.
    assert np.max(np.linalg.norm(seen - truth, axis=1) / (c * tau)) < 1e-9
    assert np.max(np.abs(light_cone_residual(x_o, tau, truth, c))) < 1e-9
    np.testing.assert_allclose(beta_seen, acc * (t_o - tau)[:, None] / c, atol=1e-9)


def test_contraction_matrix_is_the_contraction_about_the_origin():
    beta = np.array([0.2, -0.7, 0.4])
    points = RNG.normal(size=(20, 3))
    np.testing.assert_allclose(
        points @ apparent.lorentz_contraction_matrix(beta).T,
        apparent.lorentz_contract(points, np.zeros(3), beta),
        atol=1e-14,
    )
