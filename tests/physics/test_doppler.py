"""Doppler factors against wave crests counted on world lines, the two-sided relation
D = gamma (1 - beta·k) = 1 / (gamma (1 + beta·k')), and the apparent distance from a boosted
emission event."""

import numpy as np
import pytest
from hypothesis import given
from numpy.testing import assert_allclose

from relativity_addon.physics import doppler, lorentz
from strategies import directions, velocities


def crest_arrival_proper_times(observer_beta, observer_start, k, period, count=3):
    """A plane wave along ``k`` (source at rest, crests at k·x = c (t - n T), c = 1) met by an
    observer on x = x0 + beta t: the observer's proper times at the crests."""
    beta = np.asarray(observer_beta)
    n = np.arange(count)
    t = (k @ observer_start + n * period) / (1 - beta @ k)
    return t * np.sqrt(1 - beta @ beta)


@given(velocities(), directions)
def test_moving_observer_counts_crests_faster_by_D(beta, k):
    period = 1e-3
    proper = crest_arrival_proper_times(beta, np.array([0.3, -0.2, 0.1]), k, period)
    measured = period / np.diff(proper)
    assert_allclose(doppler.doppler_factor_moving_observer(k, beta), measured, rtol=1e-7)


@given(velocities(), directions)
def test_both_sides_of_the_observer_relation_agree(beta, k):
    k_prime = lorentz.aberrate(k, beta)
    assert_allclose(
        doppler.doppler_factor_moving_observer(k, beta),
        doppler.doppler_factor_from_observed_direction(k_prime, beta),
        rtol=1e-9,
    )


@given(velocities(0.99), directions)
def test_moving_source_from_emission_and_arrival_events(beta_s, k):
    """A source on x = u t emits crests every proper period T; an observer at rest far away along
    k receives them. Arrival times are emission times plus distance / c; distance to the far
    observer shrinks by u·k per unit time, which is what D encodes."""
    far = 1e9 * k
    proper_period = 1e-3
    gamma = 1 / np.sqrt(1 - beta_s @ beta_s)
    emission_t = np.arange(3) * proper_period * gamma
    emission_x = emission_t[:, None] * beta_s
    a, b = far - emission_x[1:], far - emission_x[:-1]
    # |a| - |b| written without cancellation: (|a|^2 - |b|^2) / (|a| + |b|)
    path_difference = np.sum(-np.diff(emission_x, axis=0) * (a + b), axis=1) / (
        np.linalg.norm(a, axis=1) + np.linalg.norm(b, axis=1)
    )
    measured = proper_period / (np.diff(emission_t) + path_difference)
    # the photon direction at the far observer is k up to 1e-9 rad
    assert_allclose(doppler.doppler_factor_moving_source(k, beta_s), measured, rtol=1e-6)


@given(velocities(0.95), velocities(0.95), directions)
def test_source_and_observer_both_moving(beta_o, beta_s, k):
    """Seen from the source's rest frame the source is still; D is then the moving-observer D
    of the observer's velocity and the photon direction in that frame."""
    k_source_frame = lorentz.aberrate(k, beta_s)
    beta_o_source_frame = lorentz.compose_velocities(-beta_s, beta_o)
    expected = doppler.doppler_factor_moving_observer(k_source_frame, beta_o_source_frame)
    assert_allclose(doppler.doppler_factor(k, beta_o, beta_s), expected, rtol=1e-7)
    assert_allclose(doppler.doppler_factor(k, beta_o, np.zeros(3)), doppler.doppler_factor_moving_observer(k, beta_o))
    assert_allclose(doppler.doppler_factor(k, np.zeros(3), beta_s), doppler.doppler_factor_moving_source(k, beta_s))


def test_head_on_values():
    # approaching at 0.6c: D = sqrt((1 + 0.6) / (1 - 0.6)) = 2
    assert_allclose(doppler.doppler_factor_moving_observer([0, 0, -1.0], [0, 0, 0.6]), 2.0)
    assert_allclose(doppler.doppler_factor_moving_source([0, 0, 1.0], [0, 0, 0.6]), 2.0)
    assert_allclose(doppler.doppler_factor_moving_source([0, 0, -1.0], [0, 0, 0.6]), 0.5)


@given(velocities(), directions)
def test_apparent_distance_is_D_times_the_distance(beta, k):
    """Observer at the origin at t = 0 (scene frame), source at rest at distance r: the emission
    event is (-r/c, -r k). Boosted into the observer frame its distance is c |t'| = D r."""
    r = 7.5
    t_e, x_e = lorentz.boost_event(-r, -r * k, beta, 1.0)
    d = doppler.doppler_factor_moving_observer(k, beta)
    assert_allclose(doppler.apparent_distance(r, d), -t_e, rtol=1e-9)
    assert_allclose(np.linalg.norm(x_e), -t_e, rtol=1e-9)


def test_rejects_bad_input():
    with pytest.raises(ValueError, match="beta_observer"):
        doppler.doppler_factor_moving_observer([0, 0, 1.0], [0, 0, 1.0])
    with pytest.raises(ValueError, match="beta_source"):
        doppler.doppler_factor(np.array([0, 0, 1.0]), [0, 0, 0.1], [0, np.nan, 0])
    with pytest.raises(ValueError, match="zero-length"):
        doppler.doppler_factor_moving_source([0, 0, 0.0], [0, 0, 0.1])
    with pytest.raises(ValueError, match="positive"):
        doppler.apparent_distance(1.0, 0.0)
