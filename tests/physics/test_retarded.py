"""Retarded times satisfy |x_o - x_e(t_e)| = c (t_o - t_e) for uniform, circular and accelerated
world lines, and the closed form agrees with the iterative solver."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from relativity_addon.physics import retarded
from strategies import vectors, velocities


def light_cone_residual(tau, positions, observer_position, c):
    """(|x_o - x_e(t_o - tau)| - c tau) relative to the light-travel distance c tau."""
    distance = np.linalg.norm(observer_position - positions, axis=-1)
    return np.abs(distance - c * tau) / np.maximum(c * tau, 1e-300)


@given(velocities(0.999), vectors, vectors, st.sampled_from([1.0, 299792458.0]))
def test_uniform_closed_form_is_on_the_light_cone(beta, observer, emitter, c):
    t_o = 2.0
    if np.linalg.norm(observer - emitter) < 1e-6:
        return
    tau = retarded.light_travel_time_uniform(t_o, observer, emitter, beta, c)
    assert tau > 0
    position = emitter - beta * c * tau
    assert light_cone_residual(tau, position, observer, c) < 1e-9
    assert retarded.retarded_time_uniform(t_o, observer, emitter, beta, c) == t_o - tau


def test_uniform_observer_on_the_emitter_sees_it_now():
    assert retarded.retarded_time_uniform(1.5, [1.0, 2, 3], [1.0, 2, 3], [0.5, 0, 0], 1.0) == 1.5


@settings(deadline=None)
@given(velocities(0.99), st.integers(0, 1000))
def test_iterative_solver_matches_the_closed_form(beta, seed):
    rng = np.random.default_rng(seed)
    rest = rng.normal(scale=10.0, size=(200, 3))
    c = 3.0
    t_o = 0.25
    observer = np.array([0.5, -1.0, 2.0])

    def world_line(t, index):
        return rest[index] + beta * c * (t - t_o)[:, None]

    tau = retarded.light_travel_time(world_line, t_o, observer, c, count=len(rest))
    expected = retarded.light_travel_time_uniform(t_o, observer, rest, beta, c)
    assert np.all(np.abs(tau - expected) <= 1e-9 * expected)
    assert_allclose(retarded.retarded_time(world_line, t_o, observer, c, count=len(rest)), t_o - tau)


def test_rotating_wheel_rim_at_0_9c():
    """Points on a wheel rim (radius 1, rim speed 0.9c, rotating in the xy plane) seen from a
    camera off the axis: each point satisfies the light-cone condition at its own retarded time."""
    c = 1.0
    radius = 1.0
    omega = 0.9 * c / radius
    phase = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    centre = np.array([0.0, 0.0, 0.0])
    observer = np.array([3.0, 1.0, 2.0])

    def world_line(t, index):
        angle = phase[index] + omega * t
        return centre + radius * np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], axis=-1)

    t_o = 10.0
    tau = retarded.light_travel_time(world_line, t_o, observer, c, count=phase.size)
    residual = light_cone_residual(tau, world_line(t_o - tau, np.arange(phase.size)), observer, c)
    assert residual.max() < 1e-9


def test_accelerated_world_line_from_rest_to_near_c():
    """Hyperbolic motion (constant proper acceleration a, rest at t = 0):
    x(t) = (c^2/a) (sqrt(1 + (a t / c)^2) - 1) for t > 0, at rest before; speed -> c; observers
    ahead, behind and aside."""
    c, a = 2.0, 5.0
    observers = np.array([[50.0, 0, 0], [-20.0, 0, 0], [3.0, 4.0, -1.0], [0.0, 0.0, 1e-3]])
    t_o = np.array([4.0, 8.0, 1.0, 0.5])

    def world_line(t, index):
        x = (c * c / a) * (np.sqrt(1.0 + (a * np.maximum(t, 0.0) / c) ** 2) - 1.0)
        return np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=-1)

    tau = retarded.light_travel_time(world_line, t_o, observers, c)
    residual = light_cone_residual(tau, world_line(t_o - tau, np.arange(4)), observers, c)
    assert residual.max() < 1e-9
    assert np.all(tau > 0)


def test_oscillating_world_line_and_vectorised_observer_times():
    """A point oscillating at up to 0.95c along y, seen by many observers at many times."""
    c = 1.0
    amplitude, omega = 2.0, 0.95 / 2.0

    def world_line(t, index):
        return np.stack([np.zeros_like(t), amplitude * np.sin(omega * t), np.ones_like(t)], axis=-1)

    rng = np.random.default_rng(3)
    observers = rng.normal(scale=5.0, size=(500, 3))
    t_o = rng.uniform(-10, 10, size=500)
    tau = retarded.light_travel_time(world_line, t_o, observers, c)
    residual = light_cone_residual(tau, world_line(t_o - tau, np.zeros(500, dtype=int)), observers, c)
    assert residual.max() < 1e-9


def test_faster_than_light_world_line_is_reported():
    def world_line(t, index):  # receding at 3c: its light never reaches the observer at the origin
        return np.stack([10.0 - 3.0 * t, np.zeros_like(t), np.zeros_like(t)], axis=-1)

    with pytest.raises(ValueError, match="slower than light"):
        retarded.light_travel_time(world_line, 0.0, [0.0, 0.0, 0.0], 1.0, max_iterations=30)


def test_bad_input_is_rejected():
    with pytest.raises(ValueError, match="emitter_beta"):
        retarded.retarded_time_uniform(0.0, [0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], 1.0)
    with pytest.raises(ValueError, match="finite"):
        retarded.retarded_time_uniform(np.nan, [0, 0, 0], [1.0, 0, 0], [0.1, 0, 0], 1.0)
    with pytest.raises(ValueError, match="world_line"):
        retarded.retarded_time(lambda t, i: np.full((len(t), 3), np.nan), 0.0, [0, 0, 0.0], 1.0)
