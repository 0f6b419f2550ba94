"""Moving lights against docs/physics.md written out again: the light cone from the light's world
line to the surface point and on to the camera, the Doppler factor of a moving source, eq. 19,
aberration into the light's frame, and closed cases worked by hand."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from relativity_addon.physics import lorentz, moving_lights
from strategies import speeds_of_light, velocities

coordinates = st.floats(-20.0, 20.0)
points = st.tuples(coordinates, coordinates, coordinates).map(np.array)


def _bisect_emission_time(x, t_x, light_at_t_o, beta, c, t_o):
    """t_e with |x - x_L(t_e)| = c (t_x - t_e) by plain bisection (the defining equation),
    solved for tau = t_x - t_e (t_x - tau would round tau away with the real c)."""

    def g(tau):
        return c * tau - np.linalg.norm(x - (light_at_t_o + beta * c * ((t_x - t_o) - tau)))

    low, high = 0.0, 1e6 / c  # g(0) <= 0, g(high) > 0 for any light slower than c
    for _ in range(200):
        middle = 0.5 * (low + high)
        low, high = (low, middle) if g(middle) > 0.0 else (middle, high)
    return t_x - 0.5 * (low + high)


@settings(max_examples=200, deadline=None)
@given(points, points, points, velocities(0.95), speeds_of_light)
def test_retarded_position_is_on_the_world_line_and_the_light_cone(x, camera, light, beta, c):
    """With the scene time written out: t_x = t_o - |x - x_cam| / c, then x_e = x_L(t_e) and
    |x - x_e| = c (t_x - t_e), t_e found here by bisection."""
    if np.linalg.norm(x - camera) < 1e-3 or np.linalg.norm(x - light) < 1e-3:
        return
    result = moving_lights.retarded_light(x, camera, light, beta)
    delay = np.linalg.norm(x - camera) / c  # t_o - t_x
    t_e = _bisect_emission_time(x, -delay, light, beta, c, 0.0)  # times relative to t_o
    on_world_line = light + beta * c * t_e
    scale = 1.0 + np.abs(x).max() + np.abs(light).max() + np.abs(camera).max()
    assert_allclose(result.position, on_world_line, atol=1e-8 * scale)
    assert result.distance == pytest.approx(c * (-delay - t_e), abs=1e-8 * scale)
    assert_allclose(result.direction, (x - on_world_line) / np.linalg.norm(x - on_world_line), atol=1e-6)


@given(velocities(0.95), st.floats(-1.0, 1.0), st.floats(0.0, 2.0 * math.pi))
def test_doppler_factor_is_that_of_a_moving_source(beta, cos_theta, phi):
    """D = 1 / (gamma (1 - beta . n)), and D = gamma (1 + beta . n') with n' the same photon
    in the light's own frame (docs/physics.md, "Aberration and Doppler factor")."""
    sin_theta = math.sqrt(1.0 - cos_theta * cos_theta)
    n = np.array([sin_theta * math.cos(phi), sin_theta * math.sin(phi), cos_theta])
    result = moving_lights.retarded_light(n, n, (0.0, 0.0, 0.0), beta)
    gamma = 1.0 / math.sqrt(1.0 - beta @ beta)
    # the camera sits on the surface point: no delay, so the light was on its world line behind
    assert result.doppler == pytest.approx(1.0 / (gamma * (1.0 - beta @ result.direction)), rel=1e-12)
    n_light = moving_lights.light_frame_direction(result.direction, beta)
    assert_allclose(n_light, lorentz.aberrate(result.direction, beta), atol=1e-12)
    assert np.linalg.norm(n_light) == pytest.approx(1.0, rel=1e-12)
    assert result.doppler == pytest.approx(gamma * (1.0 + beta @ n_light), rel=1e-10)


@pytest.mark.parametrize("speed", [0.1, 0.5, 0.9])
def test_point_ahead_and_behind_on_the_line_of_motion(speed):
    """A light at distance d behind (ahead of) the lit point, moving toward (away from) it, as the
    point sees it: r = d / (1 - beta) (r = d / (1 + beta)), D = sqrt((1 + beta)/(1 - beta)) (its
    inverse). The camera at the point removes the camera-to-surface delay."""
    d = 3.0
    beta = np.array([speed, 0.0, 0.0])
    x_ahead = np.array([d, 0.0, 0.0])
    ahead = moving_lights.retarded_light(x_ahead, x_ahead, (0.0, 0.0, 0.0), beta)
    assert ahead.distance == pytest.approx(d / (1.0 - speed), rel=1e-12)
    assert ahead.doppler == pytest.approx(math.sqrt((1.0 + speed) / (1.0 - speed)), rel=1e-12)
    x_behind = -x_ahead
    behind = moving_lights.retarded_light(x_behind, x_behind, (0.0, 0.0, 0.0), beta)
    assert behind.distance == pytest.approx(d / (1.0 + speed), rel=1e-12)
    assert behind.doppler == pytest.approx(math.sqrt((1.0 - speed) / (1.0 + speed)), rel=1e-12)


def test_camera_delay_moves_the_light_further_back():
    """A point 10 units from the camera sends it its light 10 units of c t before t_o: at beta
    = 0.5 it is lit as if the light were drawn 5 units behind and the camera were at the point."""
    x = np.array([0.0, 0.0, 0.0])
    light = np.array([0.0, 0.0, 2.0])
    beta = np.array([0.5, 0.0, 0.0])
    far = moving_lights.retarded_light(x, (0.0, 0.0, 10.0), light, beta)
    shifted = moving_lights.retarded_light(x, x, light - [5.0, 0.0, 0.0], beta)
    assert_allclose(far.position, shifted.position, atol=1e-12)
    assert far.position[0] < -5.0


@given(points, points, st.floats(0.1, 100.0))
def test_light_at_rest_is_the_inverse_square_law(x, light, intensity):
    if abs(x[2] - light[2]) < 1e-2:
        return
    normal = np.array([0.0, 0.0, 1.0 if light[2] > x[2] else -1.0])
    e = moving_lights.moving_point_light_irradiance(x, normal, (0.0, 0.0, 50.0), light, (0.0, 0.0, 0.0), intensity)
    r = np.linalg.norm(light - x)
    assert e == pytest.approx(intensity * abs(light[2] - x[2]) / r**3, rel=1e-12)


def test_eq_19_on_a_floor_written_out():
    """E = D^4 cos(alpha) I / r^2 at floor points, with the retarded position found by bisection
    and D, alpha, r written out here from it."""
    camera = np.array([0.3, -0.2, 6.0])
    light = np.array([0.0, 0.0, 1.5])
    beta = np.array([0.5, 0.1, 0.0])
    c = 2.0
    xs = np.linspace(-4.0, 4.0, 9)
    floor = np.stack([xs, 0.5 * xs, np.zeros_like(xs)], axis=-1)
    expected = []
    for x in floor:
        t_x = -np.linalg.norm(x - camera) / c
        t_e = _bisect_emission_time(x, t_x, light, beta, c, 0.0)
        source = light + beta * c * t_e
        r = np.linalg.norm(x - source)
        n = (x - source) / r
        d = 1.0 / ((1.0 / math.sqrt(1.0 - beta @ beta)) * (1.0 - beta @ n))
        expected.append(d**4 * (-n[2]) * 7.0 / r**2)
    measured = moving_lights.irradiance_on_plane(floor[:, :2], 0.0, camera, light, beta, 7.0)
    assert_allclose(measured, expected, rtol=1e-9)


def test_rejects_light_at_or_above_c():
    with pytest.raises(ValueError, match="below 1"):
        moving_lights.retarded_light((1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, 2.0), (1.0, 0.0, 0.0))


# --- the stand-in lamps' placement (blender/lights/stand_in_lamps.py) ---------------------------------------


def _bisect_on_path(x, camera, position_at):
    """s = c (t_e - t_o) with |x - x_L(s)| = -|x - camera| - s, by bisection (the defining equation)."""
    c_tx = -np.linalg.norm(x - camera)

    def g(s):  # > 0 when s is before the emission time
        return (c_tx - s) - np.linalg.norm(x - position_at(s))

    low, high = c_tx - 1e4, c_tx
    for _ in range(200):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if g(middle) > 0.0 else (low, middle)
    return 0.5 * (low + high)


def test_retarded_times_on_a_straight_path_match_the_closed_form():
    rng = np.random.default_rng(3)
    x = rng.uniform(-5.0, 5.0, (50, 3))
    camera, light, beta = np.array([0.0, 0.0, 5.0]), np.array([1.5, 0.0, 1.0]), np.array([0.5, 0.2, 0.0])
    closed, irradiance = moving_lights.retarded_times(x, camera, light, beta)
    knots = np.linspace(-60.0, 0.0, 7)
    on_path, irradiance_path = moving_lights.retarded_times_on_path(x, camera, knots, light + knots[:, None] * beta)
    bisected = [_bisect_on_path(p, camera, lambda s: light + s * beta) for p in x]
    assert_allclose(closed, bisected, atol=1e-9)
    assert_allclose(on_path, bisected, atol=1e-9)
    assert_allclose(irradiance_path, irradiance, rtol=1e-6)
    light_then = moving_lights.retarded_light(x, camera, light, beta)
    assert_allclose(irradiance, light_then.doppler**4 / light_then.distance**2)


def test_retarded_times_on_a_bent_path_and_its_doppler_factor():
    """A light at 0.3c until s = -8, 0.6c after: the retarded time by bisection, D from the piece."""
    kink = -8.0

    def position_at(s):
        return np.array([1.5 + 0.6 * s if s >= kink else 1.5 + 0.6 * kink + 0.3 * (s - kink), 0.0, 1.0])

    knots = np.array([-80.0, kink, 0.0])
    path = np.array([position_at(s) for s in knots])
    x = np.stack([np.linspace(-4.0, 4.0, 41), np.zeros(41), np.zeros(41)], axis=-1)
    camera = np.array([0.0, 0.0, 5.0])
    times, irradiance = moving_lights.retarded_times_on_path(x, camera, knots, path)
    expected = np.array([_bisect_on_path(p, camera, position_at) for p in x])
    assert_allclose(times, expected, atol=1e-9)
    assert np.any(times > kink) and np.any(times < kink)
    speed = np.where(expected >= kink, 0.6, 0.3)
    source = np.array([position_at(s) for s in expected])
    r = np.linalg.norm(x - source, axis=-1)
    n_x = (x - source)[:, 0] / r
    d = np.sqrt(1.0 - speed**2) / (1.0 - speed * n_x)
    assert_allclose(irradiance, d**4 / r**2, rtol=1e-6)


def test_lamp_times_span_the_lit_points_evenly():
    times = np.array([-10.0, -8.0, -5.0, -2.0, -1.0])
    irradiance = np.array([1e-4, 0.5, 1.0, 0.2, 0.02])  # the first gets under 1 % of the brightest
    placed = moving_lights.lamp_times(times, irradiance, spacing=1.0, max_lamps=16)
    assert placed[0] == -8.0 and placed[-1] == -1.0
    assert_allclose(np.diff(placed), 1.0)
    assert len(moving_lights.lamp_times(times, irradiance, spacing=0.01, max_lamps=5)) == 5
    assert_allclose(moving_lights.lamp_times(times[:1], irradiance[:1], 1.0, 16), [-10.0])
    assert_allclose(moving_lights.lamp_times(times, np.zeros(5), 1.0, 16), [0.0])  # nothing lit


def test_path_position_is_straight_between_and_beyond_its_samples():
    knots = np.array([-2.0, 0.0])
    points = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 0.0]])
    assert_allclose(
        moving_lights.path_position(np.array([-1.0, -4.0, 2.0]), knots, points),
        [[0.5, 1.0, 0.0], [-1.0, -2.0, 0.0], [2.0, 4.0, 0.0]],
    )


def test_end_on_share_counts_the_light_arriving_along_the_path():
    """A light on the x axis: points on the axis beyond it see the path end on, points below it
    broadside; the share is theirs of the irradiance (the dim point under 1 % is left out)."""
    path_times, path = np.array([-2.0, 0.0]), np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    points = np.array([[3.0, 0.0, 0.0], [3.0, 0.05, 0.0], [0.0, 0.0, -1.0], [-0.5, 0.0, -2.0], [9.0, 0.0, 0.0]])
    times = np.array([0.0, 0.0, 0.0, -1.0, 0.0])  # on the path: the light at (0, 0, 0), or (-0.5, 0, 0)
    irradiance = np.array([1.0, 2.0, 3.0, 4.0, 0.001])
    # sines: 0, 0.05 / 3.0004, 1, 1, 0
    assert moving_lights.end_on_share(times, irradiance, points, path_times, path, sin_limit=0.1) == 0.3
    assert moving_lights.end_on_share(times, irradiance, points, path_times, path, sin_limit=0.01) == 0.1
    assert moving_lights.end_on_share(times, irradiance, points, path_times[:1], path[:1]) == 0.0
