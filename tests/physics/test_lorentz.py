"""Boosts of events, photon directions and velocities against relations that do not use the
formulas under test: the textbook 1-D boost plus rotation covariance, invariance of the interval,
composition of collinear boosts, and photon directions read off boosted light-like events."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from relativity_addon.physics import lorentz
from strategies import directions, speeds_of_light, vectors, velocities


def random_rotation(seed):
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def test_gamma_of_known_speeds():
    assert_allclose(lorentz.lorentz_factor([0.6, 0.0, 0.0]), 1.25)
    assert_allclose(lorentz.lorentz_factor([0.0, 0.0, 0.0]), 1.0)
    assert_allclose(lorentz.lorentz_factor([[0.0, 0.8, 0.0], [0.0, 0.0, -0.6]]), [5 / 3, 1.25])


@given(st.floats(-0.99, 0.99), st.floats(-100, 100), vectors, st.integers(0, 10_000), speeds_of_light)
def test_boost_is_the_textbook_boost_rotated(speed, t, x, seed, c):
    """Along x the boost is x' = gamma (x - v t), t' = gamma (t - v x / c^2), y' = y, z' = z; any
    other direction is that boost seen through a rotation."""
    rotation = random_rotation(seed)
    gamma = 1 / np.sqrt(1 - speed**2)
    v = speed * c
    expected_t = gamma * (t - v * x[0] / c**2)
    expected_x = np.array([gamma * (x[0] - v * t), x[1], x[2]])
    t_prime, x_prime = lorentz.boost_event(t, rotation @ x, rotation @ np.array([speed, 0, 0]), c)
    scale = abs(t) + np.linalg.norm(x) / c + 1e-9
    assert_allclose(t_prime, expected_t, atol=1e-9 * gamma * scale)
    assert_allclose(x_prime, rotation @ expected_x, atol=1e-9 * gamma * scale * c)


@given(velocities(), st.floats(-100, 100), vectors, speeds_of_light)
def test_inverse_boost_round_trip(beta, t, x, c):
    t1, x1 = lorentz.boost_event(t, x, beta, c)
    t2, x2 = lorentz.inverse_boost_event(t1, x1, beta, c)
    gamma = lorentz.lorentz_factor(beta)
    scale = gamma**2 * (abs(t) * c + np.linalg.norm(x) + 1e-9)
    assert_allclose(t2 * c, t * c, atol=1e-10 * scale)
    assert_allclose(x2, x, atol=1e-10 * scale)


@given(velocities(), vectors, vectors, speeds_of_light)
def test_interval_is_invariant(beta, x1, x2, c):
    t = np.array([0.3, -2.0])
    x = np.stack([x1, x2])
    t_prime, x_prime = lorentz.boost_event(t, x, beta, c)
    interval = (c * (t[1] - t[0])) ** 2 - np.sum((x[1] - x[0]) ** 2)
    interval_prime = (c * (t_prime[1] - t_prime[0])) ** 2 - np.sum((x_prime[1] - x_prime[0]) ** 2)
    gamma = lorentz.lorentz_factor(beta)
    scale = gamma**2 * (np.sum((x[1] - x[0]) ** 2) + (c * (t[1] - t[0])) ** 2 + 1.0)
    assert abs(interval_prime - interval) <= 1e-9 * scale


@given(velocities(), directions, st.floats(0.01, 100), vectors, speeds_of_light)
def test_light_like_intervals_stay_light_like(beta, k, duration, start, c):
    t = np.array([0.0, duration])
    x = np.stack([start, start + c * duration * k])
    t_prime, x_prime = lorentz.boost_event(t, x, beta, c)
    travelled = np.linalg.norm(x_prime[1] - x_prime[0])
    assert c * (t_prime[1] - t_prime[0]) > 0
    # The boosted events carry rounding of their own size (gamma^2 (|x| + c t)); their difference
    # can be far smaller (a short ray far from the origin), so an absolute floor in those units.
    gamma = lorentz.lorentz_factor(beta)
    floor = 1e-13 * gamma**2 * (np.linalg.norm(start) + c * duration)
    assert_allclose(travelled, c * (t_prime[1] - t_prime[0]), rtol=1e-9, atol=floor)


@given(st.floats(-0.99, 0.99), st.floats(-0.99, 0.99), directions, st.floats(-10, 10), vectors)
def test_collinear_boosts_compose_by_velocity_addition(b1, b2, axis, t, x):
    """Boosting by b1 and then (in the new frame) by b2 along the same axis is one boost by
    (b1 + b2) / (1 + b1 b2)."""
    t1, x1 = lorentz.boost_event(t, x, b1 * axis, 1.0)
    t2, x2 = lorentz.boost_event(t1, x1, b2 * axis, 1.0)
    combined = (b1 + b2) / (1 + b1 * b2)
    t3, x3 = lorentz.boost_event(t, x, combined * axis, 1.0)
    scale = lorentz.lorentz_factor(combined * axis) ** 2 * (abs(t) + np.linalg.norm(x) + 1)
    scale *= lorentz.lorentz_factor(b1 * axis) * lorentz.lorentz_factor(b2 * axis)
    assert_allclose(t2, t3, atol=1e-9 * scale)
    assert_allclose(x2, x3, atol=1e-9 * scale)


@given(velocities(0.99), velocities(0.99))
def test_velocity_addition_matches_a_boosted_world_line(frame, body):
    """A body moving with ``body`` in S': two events on its world line, carried back to S, give
    the composed velocity; this holds for non-collinear velocities too."""
    events_t = np.array([0.0, 1.0])
    events_x = np.stack([np.zeros(3), body])  # c = 1
    t, x = lorentz.inverse_boost_event(events_t, events_x, frame, 1.0)
    expected = (x[1] - x[0]) / (t[1] - t[0])
    assert_allclose(lorentz.compose_velocities(frame, body), expected, atol=1e-9)
    assert np.linalg.norm(lorentz.compose_velocities(frame, body)) < 1.0


@given(velocities(), directions, speeds_of_light)
def test_aberration_is_the_direction_of_a_boosted_photon(beta, k, c):
    """k' is read off two events on the photon's world line, boosted."""
    t_prime, x_prime = lorentz.boost_event(np.array([0.0, 1.0]), np.stack([np.zeros(3), c * k]), beta, c)
    expected = (x_prime[1] - x_prime[0]) / np.linalg.norm(x_prime[1] - x_prime[0])
    assert_allclose(lorentz.aberrate(k, beta), expected, atol=1e-7)
    assert_allclose(np.linalg.norm(lorentz.aberrate(k, beta)), 1.0, rtol=1e-12)


@given(st.floats(0.0, 0.999), st.floats(0.0, np.pi), directions)
def test_view_ahead_compresses_toward_the_motion(speed, theta, axis):
    """cos theta' = (cos theta + beta) / (1 + beta cos theta) for the angle between the viewing
    direction (opposite the photon's) and the observer's motion."""
    other = np.cross(axis, [1.0, 0.0, 0.0])
    if np.linalg.norm(other) < 0.1:
        other = np.cross(axis, [0.0, 1.0, 0.0])
    other /= np.linalg.norm(other)
    view = np.cos(theta) * axis + np.sin(theta) * other
    view_prime = -lorentz.aberrate(-view, speed * axis)
    expected = (np.cos(theta) + speed) / (1 + speed * np.cos(theta))
    assert_allclose(view_prime @ axis, expected, atol=1e-9)


@given(velocities(), directions)
def test_gray_eq2_carries_camera_directions_to_the_scene(beta, d):
    """Gray eq. (2) is the photon-direction transform from the camera frame (moving with beta in
    the scene) to the scene frame: undoing it with the boost gives d back."""
    d_scene = lorentz.camera_to_scene_direction(d, beta)
    assert_allclose(lorentz.aberrate(d_scene, beta), d, atol=1e-8)
    gamma = lorentz.lorentz_factor(beta)
    unnormalised = d + (gamma - 1) * (np.dot(beta, d) / max(np.dot(beta, beta), 1e-300)) * beta + gamma * beta
    if np.dot(beta, beta) > 1e-12:
        assert_allclose(d_scene, unnormalised / np.linalg.norm(unnormalised), atol=1e-9)


def test_gray_eq1_is_the_inverse_boost():
    beta = np.array([0.1, 0.0, 0.99])
    t, x = 0.7, np.array([1.0, 2.0, 3.0])
    gamma = 1 / np.sqrt(1 - beta @ beta)
    expected = x + (gamma - 1) * (beta @ x) * beta / (beta @ beta) + gamma * beta * t
    assert_allclose(lorentz.camera_to_scene_event(t, x, beta, 1.0)[1], expected, rtol=1e-12)


def test_vectorised_over_arrays_of_events_and_velocities():
    rng = np.random.default_rng(1)
    x = rng.normal(size=(50, 3))
    t = rng.normal(size=50)
    beta = rng.uniform(-0.5, 0.5, size=(50, 3))
    t_all, x_all = lorentz.boost_event(t, x, beta, 2.0)
    for i in (0, 17, 49):
        t_one, x_one = lorentz.boost_event(t[i], x[i], beta[i], 2.0)
        assert_allclose(t_all[i], t_one)
        assert_allclose(x_all[i], x_one)
    assert lorentz.aberrate(rng.normal(size=(4, 5, 3)), [0.3, 0, 0]).shape == (4, 5, 3)


@pytest.mark.parametrize("beta", [[1.0, 0, 0], [0.6, 0.8, 0.0], [2, 0, 0], [np.nan, 0, 0], [np.inf, 0, 0]])
def test_superluminal_or_non_finite_velocity_is_rejected(beta):
    with pytest.raises(ValueError, match="beta"):
        lorentz.boost_event(0.0, [1.0, 0, 0], beta, 1.0)
    with pytest.raises(ValueError, match="beta"):
        lorentz.aberrate([0, 0, 1.0], beta)
    with pytest.raises(ValueError, match="beta"):
        lorentz.lorentz_factor(beta)


def test_bad_events_directions_and_c_are_rejected():
    with pytest.raises(ValueError, match="direction"):
        lorentz.aberrate([0.0, 0.0, 0.0], [0.5, 0, 0])
    with pytest.raises(ValueError, match="direction"):
        lorentz.camera_to_scene_direction([[0, 0, 1.0], [0, 0, 0]], [0.5, 0, 0])
    with pytest.raises(ValueError, match="finite"):
        lorentz.boost_event(np.nan, [1.0, 0, 0], [0.5, 0, 0], 1.0)
    with pytest.raises(ValueError, match="finite"):
        lorentz.boost_event(0.0, [1.0, np.inf, 0], [0.5, 0, 0], 1.0)
    with pytest.raises(ValueError, match="3 components"):
        lorentz.boost_event(0.0, [1.0, 0], [0.5, 0, 0], 1.0)
    for c in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(ValueError, match="c must"):
            lorentz.boost_event(0.0, [1.0, 0, 0], [0.5, 0, 0], c)
