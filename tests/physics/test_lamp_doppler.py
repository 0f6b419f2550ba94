"""Lamps at rest lighting moving objects (physics/lamp_doppler.py) against docs/physics.md written
out here: the Lorentz boost of the photon's four-momentum and of the emission-absorption
separation, eq. 18 with r' measured in the object's frame, and colour-science for the spectra."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from relativity_addon.physics import lamp_doppler, spectral
from strategies import directions, velocities


def _boost(ct, x, beta):
    """The event (ct, x) of the scene frame in the frame moving with ``beta`` (docs/physics.md)."""
    speed2 = beta @ beta
    gamma = 1.0 / math.sqrt(1.0 - speed2)
    along = (gamma - 1.0) * (beta @ x) / speed2 if speed2 > 0.0 else 0.0
    return gamma * (ct - beta @ x), x + along * beta - gamma * beta * ct


@settings(max_examples=200, deadline=None)
@given(directions, velocities(0.99))
def test_doppler_and_aberration_are_the_boosted_photon(k, beta):
    """A photon (energy 1, direction k) boosted into the object's frame: energy D, direction k'."""
    energy, momentum = _boost(1.0, k, beta)
    assert lamp_doppler.lamp_to_object_doppler(k, beta) == pytest.approx(energy, rel=1e-9)
    np.testing.assert_allclose(lamp_doppler.aberrated_direction(k, beta), momentum / energy, atol=1e-9)


@settings(max_examples=200, deadline=None)
@given(directions, velocities(0.99), directions)
def test_irradiance_factor_is_eq_18_with_the_object_frame_distance(k, beta, normal):
    """Eq. 18 (bolometric) writes E' = D^4 cos(alpha') I / r'^2 with r' in the object's frame. The
    emission (lamp) and absorption events are light-like separated by (r, r k) in the scene frame;
    boosted, their separation is r' = c dt': E'/E = D^2 at the same cos(alpha')."""
    r = 7.0
    ct_object, _ = _boost(r, r * k, beta)
    doppler = lamp_doppler.lamp_to_object_doppler(k, beta)
    eq_18 = doppler**4 / ct_object**2
    assert lamp_doppler.irradiance_factor(doppler) / r**2 == pytest.approx(eq_18, rel=1e-9)


def test_ahead_and_behind_at_half_c():
    """The issue's numbers: D = sqrt(3) ahead, 1/sqrt(3) behind; at a given scene distance the
    irradiance is 3x and 1/3x (9x and 1/9x at a given object-frame distance)."""
    beta = (0.5, 0.0, 0.0)
    ahead = lamp_doppler.lamp_to_object_doppler((-1.0, 0.0, 0.0), beta)
    behind = lamp_doppler.lamp_to_object_doppler((1.0, 0.0, 0.0), beta)
    assert ahead == pytest.approx(math.sqrt(3.0)) and behind == pytest.approx(1.0 / math.sqrt(3.0))
    assert lamp_doppler.irradiance_factor(ahead) == pytest.approx(3.0)
    assert lamp_doppler.irradiance_factor(behind) == pytest.approx(1.0 / 3.0)
    assert ahead**4 == pytest.approx(9.0) and behind**4 == pytest.approx(1.0 / 9.0)


@pytest.mark.parametrize("doppler", [0.3, 0.577, 1.0, 1.732, 3.0])
def test_white_lamp_colour_is_the_shifted_spectrum(doppler):
    """A white lamp (up-sampled like every RGB colour: 6504 K white) reaches the object as
    ``D^3 I(lambda D)`` per wavelength: its RGB is ``D^-2`` times what eq. 14's ``D^5 L(lambda D)``
    gives, which colour-science's integral (physics/spectral.py) computes."""
    factor = lamp_doppler.lamp_rgb_factor(doppler, rgb=(1.0, 1.0, 1.0))
    np.testing.assert_allclose(
        factor, spectral.doppler_shift_rgb((1.0, 1.0, 1.0), doppler) / doppler**2, rtol=2e-3, atol=1e-9
    )


@pytest.mark.parametrize("temperature, doppler", [(3000.0, 1.732), (3000.0, 0.577), (5762.0, 1.5), (12000.0, 0.4)])
def test_blackbody_lamp_is_a_blackbody_at_d_t(temperature, doppler):
    """D^5 B(lambda D, T) = B(lambda, D T): the object receives a blackbody at D T with luminance
    D^-2 Y(D T)/Y(T) times the lamp's (colour-science)."""
    factor = lamp_doppler.lamp_rgb_factor(doppler, temperature_k=temperature)
    rest = spectral.blackbody_linear_rgb(temperature, gamut_map=True)
    rest = rest / spectral.luminance_linear_rec709(rest)
    shifted = spectral.blackbody_linear_rgb(doppler * temperature, gamut_map=True)
    shifted = shifted / spectral.luminance_linear_rec709(shifted)
    expected = shifted * spectral.blackbody_luminance_ratio(temperature, doppler) / doppler**2
    np.testing.assert_allclose(factor * rest, expected, rtol=5e-3, atol=1e-12)


def test_switches():
    """Doppler off: total energy, D^2 in every channel; searchlight off: the lamp's luminance kept."""
    np.testing.assert_allclose(lamp_doppler.lamp_rgb_factor(1.7, use_doppler=False), [1.7**2] * 3)
    np.testing.assert_allclose(lamp_doppler.lamp_rgb_factor(1.7, use_doppler=False, use_searchlight=False), [1.0] * 3)
    rgb = np.array([0.2, 0.5, 0.9])
    shifted = rgb * lamp_doppler.lamp_rgb_factor(1.7, rgb=rgb, use_searchlight=False)
    assert spectral.luminance_linear_rec709(shifted) == pytest.approx(spectral.luminance_linear_rec709(rgb))


@pytest.mark.parametrize("doppler", [0.01, 0.1, 1.0, 10.0, 100.0])
def test_factor_finite_and_non_negative(doppler):
    for kwargs in ({"rgb": (1.0, 0.0, 0.3)}, {"temperature_k": 800.0}, {"temperature_k": 20000.0}):
        factor = lamp_doppler.lamp_rgb_factor(doppler, **kwargs)
        assert np.all(np.isfinite(factor)) and np.all(factor >= 0.0)


def test_one_factor_per_object_converges_with_distance():
    """One D per lamp and object (at the centre): the D^2 spread over a unit sphere's lit side
    falls as 1/distance; at the point facing a lamp straight ahead or behind the render is exact
    (no aberration on the axis, normals along the motion are not tilted by the contraction)."""
    beta = np.array([0.5, 0.0, 0.0])
    spreads = []
    for distance in (3.0, 10.0, 30.0):
        points, scene_normals, rest_normals = lamp_doppler.contracted_sphere(1.0, (0.0, 0.0, 0.0), beta)
        lamp = np.array([0.0, -distance, 0.0])
        lit = lamp_doppler.one_factor_irradiance(points, scene_normals, lamp, (0.0, 0.0, 0.0), beta) > 0.0
        k = points[lit] - lamp
        per_point = lamp_doppler.lamp_to_object_doppler(k, beta)
        centre = lamp_doppler.lamp_to_object_doppler(-lamp, beta)
        spreads.append(np.max(np.abs(centre**2 / per_point**2 - 1.0)))
        for ahead in (distance, -distance):
            lamp_axis = np.array([ahead, 0.0, 0.0])
            facing = np.array([[math.copysign(1.0, ahead), 0.0, 0.0]])
            point = facing * math.sqrt(0.75)  # the contracted sphere's pole toward the lamp (radius 1/gamma)
            exact = lamp_doppler.exact_irradiance(point, facing, lamp_axis, beta)
            one = lamp_doppler.one_factor_irradiance(point, facing, lamp_axis, (0.0, 0.0, 0.0), beta)
            assert one == pytest.approx(exact, rel=1e-12)
    assert spreads[0] > spreads[1] > spreads[2] and spreads[2] < 0.03


@settings(max_examples=100, deadline=None)
@given(directions, velocities(0.95))
def test_turned_lamp_is_seen_along_the_aberrated_direction(k, beta):
    """The copy turned about the centre: same distance, seen from the centre along -k' where k' is
    the photon direction boosted into the object's frame; its axes turned by the same rotation."""
    centre = np.array([1.0, -2.0, 0.5])
    lamp = np.eye(4)
    lamp[:3, :3] = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    lamp[:3, 3] = centre - 6.0 * k
    turned = lamp_doppler.aberrated_lamp_matrix(lamp, centre, k, beta)
    energy, momentum = _boost(1.0, k, beta)
    offset = centre - turned[:3, 3]
    assert np.linalg.norm(offset) == pytest.approx(6.0, rel=1e-9)
    np.testing.assert_allclose(offset / 6.0, momentum / energy, atol=1e-7)
    rotation = turned[:3, :3] @ lamp[:3, :3].T
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-9)
    np.testing.assert_allclose(rotation @ k, momentum / energy, atol=1e-7)


@settings(max_examples=200, deadline=None)
@given(directions, velocities(0.95), st.floats(min_value=0.1, max_value=100.0))
def test_apparent_offset_is_where_the_point_sees_the_lamp(k, beta, r):
    """A point x lit along k from a lamp r away sees the lamp, in its own frame, along the boosted
    photon direction at the boosted emission-absorption distance: lamp + u bhat is exactly there."""
    x = np.array([0.3, -1.0, 2.0])
    lamp = x - r * k
    u = lamp_doppler.apparent_lamp_offset(x, lamp, beta)
    speed = float(np.linalg.norm(beta))
    seen = lamp + (u * beta / speed if speed > 0.0 else 0.0)
    energy, momentum = _boost(1.0, k, beta)
    ct_object, _ = _boost(r, r * k, beta)
    np.testing.assert_allclose(x - seen, ct_object * momentum / energy, atol=1e-7 * max(r, 1.0))


@settings(max_examples=100, deadline=None)
@given(st.lists(st.floats(-50.0, 50.0), min_size=1, max_size=8, unique=True), st.floats(-80.0, 80.0))
def test_stand_in_weights_interpolate_linearly(stand_ins, u):
    """The weights sum to 1, are non-negative, at most two are nonzero, and they reproduce the
    offset itself inside the span (linear interpolation); beyond an end the end one takes all."""
    stand_ins = np.sort(np.array(stand_ins))
    weights = lamp_doppler.stand_in_weights(u, stand_ins)
    assert np.all(weights >= 0.0) and weights.sum() == pytest.approx(1.0)
    assert np.count_nonzero(weights) <= 2
    if stand_ins[0] <= u <= stand_ins[-1]:
        assert weights @ stand_ins == pytest.approx(u, abs=1e-9)
    else:
        assert weights[0 if u < stand_ins[0] else -1] == 1.0


def test_stand_ins_converge_to_eq_18_per_point():
    """On a unit sphere at 0.5c with a lamp 3 radii to the side: with two or three stand-ins (0.2 rad
    apart at most, as the stage places them) the rendered irradiance is eq. 18 per point within
    0.5 % (mean over the lit side), and exactly wherever both stand-ins' cosines are positive;
    one copy per lamp and object was 42 % off."""
    beta = np.array([0.5, 0.0, 0.0])
    points, scene_normals, rest_normals = lamp_doppler.contracted_sphere(1.0, (0.0, 0.0, 0.0), beta, 4000)
    lamp = np.array([0.0, -3.0, 0.0])
    exact = lamp_doppler.exact_irradiance(points, rest_normals, lamp, beta)
    lit = exact > 0.0
    offsets = lamp_doppler.apparent_lamp_offset(points[lit], lamp, beta)
    distances = lamp_doppler.lamp_to_object_doppler(points[lit] - lamp, beta) * np.linalg.norm(
        points[lit] - lamp, axis=-1
    )
    stand_ins = lamp_doppler.stand_in_offsets(offsets, distances, 0.2, 3)
    assert 1 < len(stand_ins) <= 3
    rendered = lamp_doppler.stand_in_irradiance(points, rest_normals, lamp, beta, stand_ins)
    one = lamp_doppler.one_factor_irradiance(points, rest_normals, lamp, (0.0, 0.0, 0.0), beta)
    assert np.sum(np.abs(rendered - exact)) / np.sum(exact) < 0.005
    well_lit = exact > 0.2 * exact.max()
    np.testing.assert_allclose(rendered[well_lit], exact[well_lit], rtol=1e-9)
    assert np.sum(np.abs(one - exact)) / np.sum(exact) > 0.3


@settings(max_examples=40, deadline=None)
@given(directions, velocities(0.9), st.floats(0.001, 1.5))
def test_sun_disc_is_seen_at_its_aberrated_size(k, beta, angle):
    """A disc of angular diameter ``angle`` is seen by the moving object as the disc through its
    edge directions boosted one by one (docs/physics.md, aberration): the diameter is the largest
    angle between two of 720 boosted edge photons, and ``angle / D`` when small."""
    k = np.asarray(k) / np.linalg.norm(k)
    across = np.cross(k, np.eye(3)[int(np.argmin(np.abs(k)))])
    across /= np.linalg.norm(across)
    other = np.cross(k, across)
    phi = np.linspace(0.0, 2.0 * math.pi, 720, endpoint=False)[:, None]
    edge = math.cos(angle / 2) * k + math.sin(angle / 2) * (np.cos(phi) * across + np.sin(phi) * other)
    seen = np.array([momentum / energy for energy, momentum in (_boost(1.0, e, np.asarray(beta)) for e in edge)])
    widest = float(np.max(np.arccos(np.clip(seen @ seen.T, -1.0, 1.0))))
    expected = lamp_doppler.aberrated_disc_angle(k, beta, angle)
    assert expected == pytest.approx(widest, rel=1e-4, abs=1e-6)
    if angle < 0.01:
        doppler = float(lamp_doppler.lamp_to_object_doppler(k, beta))
        assert expected == pytest.approx(angle / doppler, rel=0.01)
