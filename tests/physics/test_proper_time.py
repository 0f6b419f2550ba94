"""Proper time against the closed forms of docs/physics.md: uniform motion (tau = t / gamma) and
constant proper acceleration (tau = (c / a) asinh(a t / c), v = a t / sqrt(1 + (a t / c)^2))."""

import numpy as np
import pytest

from relativity_addon.physics import proper_time


def test_uniform_motion():
    times = np.linspace(0.0, 10.0, 11)
    taus = proper_time.proper_times(times, np.full(11, 0.8))
    assert np.allclose(taus, times * 0.6)
    assert proper_time.scene_times(3.0, times, taus)[0] == pytest.approx(5.0)


def test_constant_proper_acceleration():
    c, a = 10.0, 4.0
    times = np.linspace(0.0, 8.0, 4001)
    at = a * times / c
    speeds = at / np.sqrt(1.0 + at * at)
    taus = proper_time.proper_times(times, speeds)
    assert np.allclose(taus, c / a * np.arcsinh(at), atol=1e-6)
    tau_k = np.arange(1, 40) / 24.0
    assert np.allclose(proper_time.scene_times(tau_k, times, taus), c / a * np.sinh(a * tau_k / c), atol=1e-6)


@pytest.mark.parametrize("speeds, message", [(np.full(3, 1.0), "below 1"), (np.array([0.1, np.nan, 0.1]), "finite")])
def test_bad_input(speeds, message):
    with pytest.raises(ValueError, match=message):
        proper_time.proper_times(np.arange(3.0), speeds)


def test_outside_the_samples():
    times = np.linspace(0.0, 1.0, 3)
    with pytest.raises(ValueError, match="outside"):
        proper_time.scene_times(2.0, times, proper_time.proper_times(times, np.zeros(3)))


def test_path_proper_times_constant_proper_acceleration():
    """Along the hyperbolic world line x = (c^2 / a)(sqrt(1 + (a t / c)^2) - 1), sampled from its
    positions alone, tau = (c / a) asinh(a t / c), also before t = 0 (negative there)."""
    c, a = 10.0, 7.0
    times = np.linspace(-3.0, 5.0, 8001)
    at = a * times / c
    x = c * c / a * (np.sqrt(1.0 + at * at) - 1.0)
    positions = np.stack([x, 0.5 * x, np.zeros_like(x)], axis=1) / np.sqrt(1.25)  # along a tilted line
    taus = proper_time.path_proper_times(times, positions, c)
    exact = c / a * np.arcsinh(at)
    print(f"largest error {np.abs(taus - exact).max():.2e} s")
    assert np.abs(taus - exact).max() < 1e-5
    assert abs(exact[-1] - times[-1]) > 2.0  # the clock really fell behind


def test_path_proper_times_uniform_and_zero():
    times = np.array([1.0, 2.0, 4.0])
    positions = np.outer(times, [0.0, 8.0, 0.0])  # 0.8 c for c = 10
    assert np.allclose(proper_time.path_proper_times(times, positions, 10.0, zero_time=2.0), [-0.6, 0.0, 1.2])
    with pytest.raises(ValueError, match="slower than light"):
        proper_time.path_proper_times(times, positions, 8.0, zero_time=2.0)
    with pytest.raises(ValueError, match="outside"):
        proper_time.path_proper_times(times, positions, 10.0)


def test_own_animation_at_proper_time():
    """A body moving at 0.8 c (gamma 5/3) whose points turn about its origin at 1 rad/s of scene
    time in the samples: played at proper time they turn by t / gamma; the origin's path is kept."""
    c, speed, gamma = 10.0, 0.8, 5.0 / 3.0
    times = np.linspace(-1.0, 4.0, 2001)
    origins = np.outer(times, [speed * c, 0.0, 0.0]) + [0.0, 2.0, -5.0]
    radii = np.array([0.5, 1.0, 2.0])

    def points(angles):
        return np.stack(
            [np.cos(angles)[:, None] * radii, np.sin(angles)[:, None] * radii, np.zeros((len(angles), 3))], axis=2
        )

    result = proper_time.own_animation_at_proper_time(times, origins[:, None, :] + points(times), origins, c)
    expected = origins[:, None, :] + points(times / gamma)
    print(f"largest error {np.abs(result - expected).max():.2e}")
    assert np.abs(result - expected).max() < 1e-5
    # A bake starting after t = 0: the clock ran at its first rate before (tau = t / gamma still).
    late = times >= 0.5
    result = proper_time.own_animation_at_proper_time(
        times[late], (origins[:, None, :] + points(times))[late], origins[late], c
    )
    inside = times[late] / gamma >= 0.5  # arrangements from inside the samples
    assert np.abs(result - expected[late])[inside].max() < 1e-5
