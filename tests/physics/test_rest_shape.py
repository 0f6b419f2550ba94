"""The rest-shape convention (physics/rest_shape.py): a body given by sampled world matrices
(keyframes, motion bake) or sampled points (deformation bake) is its rest shape contracted along
its origin's velocity, so uniform keyframed motion gives the CONSTANT path's result. Expected
values are docs/physics.md written out here: the contraction (component along beta times
1/gamma), the closed-form light-travel time of uniform motion, the far-field apparent length."""

import math

import numpy as np
import pytest

from relativity_addon.physics import apparent, rest_shape, sampling

RNG = np.random.default_rng(11)


def contract(relative, beta):
    """Scene-frame offsets from the origin of a body with rest offsets ``relative`` moving with
    ``beta`` ((3,) or one row per offset): the component along beta shrinks by 1/gamma."""
    beta = np.broadcast_to(np.asarray(beta, float), np.shape(relative))
    speed = np.linalg.norm(beta, axis=-1, keepdims=True)
    bhat = np.divide(beta, speed, out=np.zeros_like(beta), where=speed > 0)
    along = np.sum(relative * bhat, axis=-1, keepdims=True)
    return relative - (1.0 - np.sqrt(1.0 - speed**2)) * along * bhat


def closed_form_apparent(x_o, positions_now, u):
    """docs/physics.md, observer at rest: tau = ((D.u) + sqrt((D.u)^2 + (c^2 - u.u) D.D)) / (c^2 - u.u)
    with D = x_o - p (here with c folded into u: u in units per second, c = |u| / |beta|);
    the point is seen at p - u tau."""

    def solve(c):
        delta = x_o - positions_now
        a = delta @ u
        b = c * c - u @ u
        tau = (a + np.sqrt(a * a + b * np.sum(delta * delta, axis=1))) / b
        return positions_now - np.outer(tau, u), tau

    return solve


def rod(length=1.0, count=41, width=0.02):
    """Points of a thin box along local x: its axis and four long edges."""
    x = np.linspace(-0.5 * length, 0.5 * length, count)
    points = [np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=1)]
    for sy, sz in ((-1, -1), (-1, 1), (1, -1), (1, 1)):
        points.append(np.stack([x, np.full_like(x, sy * width / 2), np.full_like(x, sz * width / 2)], axis=1))
    return np.concatenate(points)


def keyframed(start, velocity, rotation):
    """World matrices of linear keyframes: fixed rotation and scale, origin start + v t."""

    def matrices(times):
        m = np.zeros((len(times), 4, 4))
        m[:, :3, :3] = rotation
        m[:, :3, 3] = start + np.multiply.outer(times, velocity)
        m[:, 3, 3] = 1.0
        return m

    return matrices


def rotation_about_z(angle, scale=(1.0, 1.0, 1.0)):
    cos, sin = math.cos(angle), math.sin(angle)
    return np.array([[cos, -sin, 0.0], [sin, cos, 0.0], [0.0, 0.0, 1.0]]) @ np.diag(scale)


@pytest.mark.parametrize("c", [3.0, 299792458.0])
@pytest.mark.parametrize("direction", [(1.0, 0.0, 0.0), (0.3, -0.8, 0.5)])
def test_rod_at_constant_keyframed_velocity_equals_the_closed_form(c, direction):
    """A 1 m rod at 0.9c: keyframe-like matrices (sampling window) and a bake-like matrix grid
    give the CONSTANT path's apparent positions, the contracted rod's closed form, to 1e-9."""
    beta = 0.9 * np.asarray(direction) / np.linalg.norm(direction)
    rotation = rotation_about_z(0.4, scale=(1.0, 1.5, 0.8))
    # t_o = 0 keeps the sampled positions near the origin with the real c (at t_o = 2 s they are
    # 5e8 m away and their rounding, 1e-7 m, would be all that is measured).
    t_o, x_o = 0.0, np.array([0.2, -0.1, 0.3])
    start = np.array([-1.0, 0.5, -4.0]) - t_o * beta * c
    matrices = keyframed(start, beta * c, rotation)
    local = rod()
    origin_now = start + t_o * beta * c
    positions_now = contract(local @ rotation.T, beta) + origin_now
    expected, expected_tau = closed_form_apparent(x_o, positions_now, beta * c)(c)
    step = 1.0 / 96.0
    # 1e-9 relative; with the real c the samples lie c step = 3e6 m apart, and float64 rounding of
    # positions that far out (1e-14 of it, 3e-8 m) is the floor of any sampled motion.
    scale = np.linalg.norm(positions_now - x_o, axis=1) + 1e-5 * c * step

    seen, tau, beta_seen = sampling.apparent_positions_from_matrix_function(
        matrices, step, local, t_o, x_o, (0.0, 0.0, 0.0), c
    )
    assert np.max(np.linalg.norm(seen - expected, axis=1) / scale) < 1e-9
    assert np.max(c * np.abs(tau - expected_tau) / scale) < 1e-9
    np.testing.assert_allclose(beta_seen, np.broadcast_to(beta, seen.shape), atol=1e-9)
    # The CONSTANT path: the contracted mesh through apparent_positions_uniform.
    constant, _, _ = apparent.apparent_positions_uniform(
        t_o, x_o, (apparent.lorentz_contraction_matrix(beta) @ rotation @ local.T).T + origin_now, beta, c
    )
    assert np.max(np.linalg.norm(seen - constant, axis=1) / scale) < 1e-9

    span = 3.0 * np.max(expected_tau) + 3 * step  # a bake over frames around the retarded times
    times = t_o + step * np.arange(-round(span / step), 4)
    baked, baked_tau, _ = rest_shape.apparent_positions_rigid_rest_shape(times, matrices(times), local, t_o, x_o, c)
    assert np.max(np.linalg.norm(baked - expected, axis=1) / scale) < 1e-9
    assert np.max(c * np.abs(baked_tau - expected_tau) / scale) < 1e-9


@pytest.mark.parametrize("observer_beta", [(0.5, 0.0, 0.0), (-0.2, 0.4, 0.6)])
def test_moving_observer_sees_the_constant_path_result(observer_beta):
    c = 5.0
    beta = np.array([0.0, 0.9, 0.0])
    rotation = rotation_about_z(1.1)
    t_o, x_o = 1.0, np.zeros(3)
    matrices = keyframed(np.array([2.0, -3.0, -6.0]), beta * c, rotation)
    local = rod(length=2.0)
    now = matrices(np.array([t_o]))[0]
    constant = apparent.apparent_positions_uniform(
        t_o, x_o, contract(local @ rotation.T, beta) + now[:3, 3], beta, c, observer_beta
    )
    seen = sampling.apparent_positions_from_matrix_function(matrices, 1.0 / 24.0, local, t_o, x_o, observer_beta, c)
    scale = np.linalg.norm(constant[0] - x_o, axis=1)
    assert np.max(np.linalg.norm(seen[0] - constant[0], axis=1) / scale) < 1e-9
    np.testing.assert_allclose(seen[2], constant[2], atol=1e-9)


def test_far_rod_appears_contracted_and_stretched_by_light_travel_time():
    """A rod along its motion, far away, seen at angle theta between its velocity and the line of
    sight towards the observer: apparent length L0 / gamma / (1 - beta cos theta)."""
    c, beta, length = 1.0, 0.9, 1.0
    gamma = 1.0 / math.sqrt(1.0 - beta * beta)
    distance = 1e5
    local = np.array([[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0]])
    for theta in (0.5 * math.pi, 1.2, 2.3):
        # Retarded position of the origin at `distance` along direction -(cos theta, sin theta, 0)
        # from the observer at the origin; at t_o = 0 it has moved on by beta c tau = beta distance.
        retarded = -distance * np.array([math.cos(theta), math.sin(theta), 0.0])
        start = retarded + np.array([beta * distance, 0.0, 0.0])
        matrices = keyframed(start, np.array([beta * c, 0.0, 0.0]), np.eye(3))
        seen, _, _ = sampling.apparent_positions_from_matrix_function(
            matrices, 1.0, local, 0.0, np.zeros(3), (0.0, 0.0, 0.0), c
        )
        apparent_length = np.linalg.norm(seen[1] - seen[0])
        expected = length / gamma / (1.0 - beta * math.cos(theta))
        print(f"theta {theta:.3f}: apparent length {apparent_length:.6f}, far-field {expected:.6f}")
        assert abs(apparent_length - expected) < 1e-4 * expected
    assert abs(1.0 / gamma - 0.43589) < 1e-5  # the 0.436 m of a 1 m rod at 0.9c seen side-on


def test_accelerating_rod_is_contracted_with_beta_at_each_point_retarded_time():
    """x(t) = a t^2 / 2 along the rod (speed 0.2c..0.85c while light leaves it), exact world line
    T(t) + C(beta(t)) x_rest: the solution lies on the light cone of the exact motion to 1e-7,
    where contracting with beta at the observer's time, or at the centre's retarded time, is off
    by far more."""
    c = 1.0
    acceleration = np.array([0.05, 0.0, 0.0])
    local = rod(length=4.0, count=81)
    x_o = np.array([2.0, 3.0, 0.0])
    t_o = 20.0  # 1.0 c at t = 20: light seen now left the rod ~3-4 s earlier, at 0.8-0.85 c

    def exact(t):
        origin = 0.5 * np.multiply.outer(t**2, acceleration)
        return origin, np.multiply.outer(t, acceleration) / c

    matrices = keyframed(np.zeros(3), np.zeros(3), np.eye(3))
    accelerated = lambda times: _translate(matrices(times), exact(np.asarray(times))[0])  # noqa: E731
    seen, tau, beta_seen = sampling.apparent_positions_from_matrix_function(
        accelerated, 1.0 / 48.0, local, t_o, x_o, (0.0, 0.0, 0.0), c
    )
    t_e = t_o - tau
    origin, beta_e = exact(t_e)
    emitted = contract(local, beta_e) + origin
    residual = np.abs(np.linalg.norm(x_o - emitted, axis=1) - c * tau) / (c * tau)
    mismatch = np.linalg.norm(seen - emitted, axis=1) / (c * tau)
    speeds = np.linalg.norm(beta_e, axis=1)
    print(
        f"speeds at retarded times {speeds.min():.3f}..{speeds.max():.3f} c, residual {residual.max():.1e}, "
        f"mismatch {mismatch.max():.1e}"
    )
    assert np.ptp(speeds) > 0.03
    assert residual.max() < 1e-7 and mismatch.max() < 1e-7
    # One contraction for all points (beta of the centre's retarded time) misplaces the ends.
    centre = np.argmin(np.abs(local[:, 0]) + np.abs(local[:, 1]) + np.abs(local[:, 2]))
    one_beta = contract(local, beta_e[centre]) + origin
    assert np.max(np.linalg.norm(seen - one_beta, axis=1) / (c * tau)) > 100 * mismatch.max()
    # The points move with the contracted shape: their velocity is the exact world line's.
    dt = 1e-5
    ahead = contract(local, exact(t_e + dt)[1]) + exact(t_e + dt)[0]
    behind = contract(local, exact(t_e - dt)[1]) + exact(t_e - dt)[0]
    np.testing.assert_allclose(beta_seen, (ahead - behind) / (2 * dt) / c, atol=1e-6)


def _translate(matrices, origins):
    matrices = matrices.copy()
    matrices[:, :3, 3] = origins
    return matrices


def test_deformation_bake_is_contracted_about_the_origin():
    """Baked world positions of a mesh carried rigidly at 0.6c (as a deformation bake samples
    them): contracted about the baked origin along its velocity, as the rigid path does."""
    c = 2.0
    beta = np.array([0.6, 0.0, -0.3])
    local = RNG.uniform(-0.5, 0.5, (60, 3))
    rotation = rotation_about_z(0.7)
    step = 1.0 / 24.0
    times = step * np.arange(6 * 24)
    origins = np.array([1.0, 0.0, -8.0]) + np.multiply.outer(times, beta * c)
    positions = (local @ rotation.T)[None] + origins[:, None, :]
    t_o, x_o = 5.0, np.zeros(3)
    seen, tau, _ = rest_shape.apparent_positions_deforming_rest_shape(times, positions, origins, t_o, x_o, c)
    origin_now = origins[0] + t_o * beta * c
    expected, expected_tau = closed_form_apparent(x_o, contract(local @ rotation.T, beta) + origin_now, beta * c)(c)
    np.testing.assert_allclose(tau, expected_tau, rtol=1e-9)
    assert np.max(np.linalg.norm(seen - expected, axis=1) / np.linalg.norm(expected - x_o, axis=1)) < 1e-9


def test_origin_velocities_and_contraction_matrices():
    step = 0.1
    t = step * np.arange(7)
    origins = np.stack([t**2, 3.0 * t, -(t**2) + t], axis=1)  # quadratic: central differences are exact
    velocities = rest_shape.origin_velocities(origins, step)
    np.testing.assert_allclose(velocities[1:-1], np.stack([2 * t, 3.0 + 0 * t, 1 - 2 * t], 1)[1:-1], atol=1e-12)
    np.testing.assert_allclose(velocities[0], (origins[1] - origins[0]) / step)  # linear end padding
    betas = np.array([[0.0, 0.0, 0.0], [0.9, 0.0, 0.0], [0.1, -0.5, 0.3], [0.8, 0.8, 0.0]])
    matrices, superluminal = rest_shape.contraction_matrices(betas)
    assert superluminal.tolist() == [False, False, False, True]
    for beta, matrix in zip(betas[:3], matrices[:3], strict=True):
        np.testing.assert_allclose(matrix, apparent.lorentz_contraction_matrix(beta), atol=1e-15)
    np.testing.assert_array_equal(matrices[3], np.eye(3))


def test_superluminal_origin_fails_only_where_a_retarded_time_uses_it():
    """Keys that jump (a teleport, 100c for one sample interval) far from the retarded times are
    harmless; near them the sampled motion is not slower than light, a ValueError."""
    c, step = 1.0, 0.25
    times = step * np.arange(200)
    origins = np.zeros((200, 3))
    origins[:, 2] = -5.0
    origins[150:, 0] = 25.0  # a jump of 25 units between t = 37.25 and 37.5
    matrices = np.broadcast_to(np.eye(4), (200, 4, 4)).copy()
    matrices[:, :3, 3] = origins
    local = rod()
    seen, tau, _ = rest_shape.apparent_positions_rigid_rest_shape(times, matrices, local, 20.0, np.zeros(3), c)
    np.testing.assert_allclose(seen, local + origins[0], atol=1e-12)  # at rest, not contracted
    with pytest.raises(ValueError, match="slower than light"):
        rest_shape.apparent_positions_rigid_rest_shape(times, matrices, local, 41.9, np.zeros(3), c)
