"""The sample window around retarded times (physics/sampling.py): motions given as matrix
functions of time against the closed form for uniform motion and the light-cone condition
``|x_o - x_e(t_e)| = c (t_o - t_e)`` evaluated on the exact motion. The local points are the rest
shape: in the scene the body is contracted about its origin along the origin's velocity
(docs/architecture.md, "Motion sources and the rest shape"), written out here as ``contract``."""

import numpy as np
import pytest

from relativity_addon.physics import apparent, sampling

RNG = np.random.default_rng(21)


def light_cone_residual(x_o, tau, x_e, c):
    return (np.linalg.norm(x_o - x_e, axis=-1) - c * tau) / (c * tau)


def contract(relative, beta):
    """Rest-frame offsets from the origin -> scene frame: the component along beta shrinks by 1/gamma.
    ``beta`` is (3,) or one row per offset."""
    beta = np.broadcast_to(np.asarray(beta, float), np.shape(relative))
    speed = np.linalg.norm(beta, axis=-1, keepdims=True)
    bhat = np.divide(beta, speed, out=np.zeros_like(beta), where=speed > 0)
    along = np.sum(relative * bhat, axis=-1, keepdims=True)
    return relative - (1.0 - np.sqrt(1.0 - speed**2)) * along * bhat


def uniform_motion(start, velocity, rotation_z=0.3):
    """World matrices of a body turned by a fixed angle about Z, translated by start + v t."""
    cos, sin = np.cos(rotation_z), np.sin(rotation_z)

    def matrices(times):
        m = np.zeros((len(times), 4, 4))
        m[:, :3, :3] = [[cos, -sin, 0], [sin, cos, 0], [0, 0, 1]]
        m[:, :3, 3] = start + np.multiply.outer(times, velocity)
        m[:, 3, 3] = 1.0
        return m

    return matrices


def accelerated_spinning_motion(acceleration, omega):
    """x(t) = R_z(omega t) p + a t^2 / 2: accelerating and spinning."""

    def matrices(times):
        times = np.asarray(times, dtype=np.float64)
        m = np.zeros(times.shape + (4, 4))
        angle = omega * times
        m[..., 0, 0], m[..., 0, 1] = np.cos(angle), -np.sin(angle)
        m[..., 1, 0], m[..., 1, 1] = np.sin(angle), np.cos(angle)
        m[..., 2, 2] = m[..., 3, 3] = 1.0
        m[..., :3, 3] = 0.5 * np.multiply.outer(times**2, acceleration)
        return m

    return matrices


@pytest.mark.parametrize("c", [2.0, 299792458.0])
@pytest.mark.parametrize("observer_beta", [(0.0, 0.0, 0.0), (0.3, -0.5, 0.2)])
def test_uniform_motion_reproduces_the_closed_form(c, observer_beta):
    beta = np.array([0.2, 0.5, -0.4])
    matrices = uniform_motion(np.array([1.0, 4.0, -2.0]), beta * c)
    local = RNG.uniform(-1.0, 1.0, (300, 3))
    t_o, x_o = 3.0, np.array([0.0, -2.0, 1.0])
    seen, tau, beta_seen = sampling.apparent_positions_from_matrix_function(
        matrices, 1.0 / 96.0, local, t_o, x_o, observer_beta, c
    )
    now = matrices(np.array([t_o]))[0]
    positions_now = contract(local @ now[:3, :3].T, beta) + now[:3, 3]
    expected = apparent.apparent_positions_uniform(t_o, x_o, positions_now, beta, c, observer_beta)
    # Catmull-Rom reproduces linear motion exactly: agreement at rounding level.
    np.testing.assert_allclose(tau, expected[1], rtol=1e-9)
    scale = np.linalg.norm(positions_now - x_o, axis=1)[:, None]
    assert np.max(np.abs(seen - expected[0]) / scale) < 1e-9
    np.testing.assert_allclose(beta_seen, expected[2], atol=1e-9)


def test_accelerated_spinning_body_lies_on_the_light_cone():
    c = 10.0
    acceleration, omega = np.array([1.5, -0.5, 0.8]), 2.0
    matrices = accelerated_spinning_motion(acceleration, omega)
    local = RNG.uniform(-1.0, 1.0, (500, 3)) + np.array([0.0, 0.0, -5.0])
    t_o, x_o = 2.0, np.array([1.0, 8.0, 0.0])
    seen, tau, _ = sampling.apparent_positions_from_matrix_function(
        matrices, 1.0 / 240.0, local, t_o, x_o, (0.0, 0.0, 0.0), c
    )
    exact = matrices(t_o - tau)
    # Contracted along the origin's velocity a t_e at each point's own retarded time.
    velocity = np.multiply.outer(t_o - tau, acceleration) / c
    emitted = contract(np.einsum("nij,nj->ni", exact[:, :3, :3], local), velocity) + exact[:, :3, 3]
    assert np.max(np.abs(light_cone_residual(x_o, tau, emitted, c))) < 1e-6
    assert np.max(np.linalg.norm(seen - emitted, axis=1) / (c * tau)) < 1e-6  # observer at rest: x_e itself


def test_window_widens_for_a_fast_receding_body_and_gives_up_after_max_tries():
    """Receding at 0.9c from 10 units away (c = 1): seen at tau = (10 + y / gamma) / 1.9 (the
    rest offsets y contracted), far from the first estimate tau = 10 of the window."""
    c = 1.0
    matrices = uniform_motion(np.array([0.0, 10.0, 0.0]), np.array([0.0, 0.9, 0.0]), rotation_z=0.0)
    local = np.zeros((50, 3))
    local[:, 1] = RNG.uniform(-0.1, 0.1, 50)  # on the line of sight: c tau = 10 + y - 0.9 tau
    _, tau, _ = sampling.apparent_positions_from_matrix_function(
        matrices, 0.01, local, 0.0, np.zeros(3), (0.0, 0.0, 0.0), c
    )
    np.testing.assert_allclose(tau, (10.0 + local[:, 1] * np.sqrt(1.0 - 0.81)) / 1.9, rtol=1e-9)
    with pytest.raises(ValueError, match="did not settle"):
        sampling.apparent_positions_from_matrix_function(
            matrices, 0.01, local, 0.0, np.zeros(3), (0.0, 0.0, 0.0), c, max_tries=1
        )


def test_too_many_samples_and_bad_input_raise():
    matrices = uniform_motion(np.array([0.0, 0.0, -5.0]), np.zeros(3))
    local = RNG.uniform(-1.0, 1.0, (10, 3))
    with pytest.raises(ValueError, match="too many animation samples"):
        sampling.apparent_positions_from_matrix_function(matrices, 1e-6, local, 0.0, np.zeros(3), np.zeros(3), 1.0)
    with pytest.raises(ValueError, match="step"):
        sampling.apparent_positions_from_matrix_function(matrices, 0.0, local, 0.0, np.zeros(3), np.zeros(3), 1.0)
    with pytest.raises(ValueError, match="slower than light"):
        sampling.apparent_positions_from_matrix_function(
            uniform_motion(np.array([0.0, 0.0, -5.0]), np.array([2.0, 0.0, 0.0])),
            0.01,
            local,
            0.0,
            np.zeros(3),
            np.zeros(3),
            1.0,
        )


def test_no_points_give_empty_results():
    matrices = uniform_motion(np.zeros(3), np.zeros(3))
    seen, tau, beta_seen = sampling.apparent_positions_from_matrix_function(
        matrices, 0.1, np.zeros((0, 3)), 0.0, np.ones(3), np.zeros(3), 1.0
    )
    assert seen.shape == (0, 3) and tau.shape == (0,) and beta_seen.shape == (0, 3)


@pytest.mark.parametrize("guess", [None, 0.0, 5.0, 40.0])
def test_origin_light_travel_time_solves_the_light_cone(guess):
    """The origin's ``tau`` (issue 26: Newton's method on the knots, from any start): uniform motion
    against the closed form of docs/physics.md (Catmull-Rom is exact for it), an accelerating
    spinning body against ``|x_o - O(t_o - tau)| = c tau`` on the exact motion (within the cubic's
    interpolation error), and the window of :func:`motion_intervals` built on it holds the same
    pieces as the one built on the general solver's ``tau``."""
    c = 10.0
    velocity = np.array([0.3, -0.6, 0.2]) * c
    matrices = uniform_motion(np.array([1.0, 4.0, -30.0]), velocity)
    t_o, x_o = 3.0, np.array([0.0, -2.0, 1.0])
    tau, near = sampling.origin_light_travel_time(matrices, 1.0 / 192.0, t_o, x_o, c, guess)
    now = matrices(np.array([t_o]))[0, :3, 3]
    expected = apparent.apparent_positions_uniform(t_o, x_o, now[None], velocity / c, c, np.zeros(3))[1][0]
    assert tau == pytest.approx(expected, rel=1e-12)
    assert near.shape == (6, 4, 4)

    accelerating = accelerated_spinning_motion(np.array([1.5, -0.5, 0.8]), 2.0)
    x_o = np.array([1.0, 8.0, 0.0])
    found = sampling.origin_light_travel_time(accelerating, 1.0 / 240.0, 2.0, x_o, c, guess)
    if guess == 40.0:  # a start where this origin is faster than light: given up (the general solver then)
        assert found is None
    else:
        tau = found[0]
        emitted = accelerating(np.array([2.0 - tau]))[0, :3, 3]
        assert abs(np.linalg.norm(x_o - emitted) - c * tau) < 1e-7 * c * tau

    step, reach = 1.0 / 192.0, 0.7
    pieces = sampling.motion_intervals(matrices, step, t_o, np.array([0.0, -2.0, 1.0]), c, reach, 1024, guess)
    general = sampling.apparent_positions_from_matrix_function(
        matrices, step, np.zeros((1, 3)), t_o, np.array([0.0, -2.0, 1.0]), np.zeros(3), c
    )[1][0]
    assert pieces.start_distance == pytest.approx(c * general, rel=1e-12)
    assert pieces.first * step <= t_o - general - reach / (c * (1 - 0.7)) <= (pieces.first + 1) * step + 1.0


def test_origin_light_travel_time_gives_way_near_light_speed():
    """Knots of an origin at c around the root: None (the general solver then raises, naming it)."""
    c = 1.0
    matrices = uniform_motion(np.array([0.0, 10.0, 0.0]), np.array([0.0, 1.0, 0.0]), rotation_z=0.0)
    assert sampling.origin_light_travel_time(matrices, 0.05, 5.0, np.zeros(3), c) is None
    with pytest.raises(ValueError, match="slower than light"):
        sampling.motion_intervals(matrices, 0.05, 5.0, np.zeros(3), c, 0.5, 1024)


@pytest.mark.parametrize("seed", range(18))
def test_uniform_motion_window_holds_every_sample_the_intervals_read(seed):
    """``uniform_motion_window`` (issue 26: the window of straight keys without sampling them) against
    :func:`motion_intervals` on the same line sampled in float32 (as Blender evaluates keys): every
    sample the intervals read (their knots, the neighbours, the contraction's neighbours) lies inside
    the span, the span is at most three times as wide and a few steps, and its ``tau`` is the closed form's
    (docs/physics.md: ``c tau = |x_o - O(t_o - tau)|``)."""
    rng = np.random.default_rng(seed)
    c, step = 10.0, 1.0 / 192.0
    speed = [0.0, 0.3, 0.5, 0.8, 0.9, 0.95][seed % 6]
    direction = rng.normal(size=3)
    velocity = speed * c * direction / np.linalg.norm(direction)
    start = rng.uniform(-1.0, 1.0, 3) * [5.0, 50.0, 500.0][seed // 6]  # large values: coarse float32 samples
    angle, scale = rng.uniform(0.0, 6.0), rng.uniform(0.5, 2.0)
    shape = scale * np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0, 0, 1]])

    def matrices(times):
        m = np.zeros((len(times), 4, 4))
        m[:, :3, :3] = shape
        m[:, :3, 3] = (start + np.multiply.outer(np.asarray(times), velocity)).astype(np.float32)
        m[:, 3, 3] = 1.0
        return m

    t_o, x_o, reach = rng.uniform(-2.0, 2.0), rng.uniform(-3.0, 3.0, 3), rng.uniform(0.1, 3.0)
    low, high, tau = sampling.uniform_motion_window(start, velocity, scale, step, t_o, x_o, c, reach, 4096)
    d = start + velocity * t_o - x_o
    expected = apparent.apparent_positions_uniform(t_o, x_o, d[None] + x_o, velocity / c, c, np.zeros(3))[1][0]
    assert tau == pytest.approx(expected, rel=1e-12)
    pieces = sampling.motion_intervals(matrices, step, t_o, x_o, c, reach, 4096)
    assert pieces.start_distance / c == pytest.approx(tau, rel=1e-5, abs=1e-6)
    read_low, read_high = (pieces.first - 3) * step, (pieces.first + len(pieces.coefficients) + 3) * step
    assert low <= read_low + 1e-9 and read_high <= high + 1e-9
    assert high - low <= 3.0 * (read_high - read_low) + 20 * step  # wide where the samples round coarsely
