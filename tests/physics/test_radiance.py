"""Radiance transforms against independent relations: the solid-angle ratio from a finite-
difference Jacobian of the aberration map, D^4 as the integral of the D^5 spectral law, the
blackbody identity against colour-science's Planck law, and point-light irradiance from photons
counted through the aberration map."""

import colour
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from relativity_addon.physics import doppler, lorentz, radiance
from strategies import directions, velocities

# numpy 2.0 renamed trapz to trapezoid (and 2.4 removed trapz); numpy 1.26 has only trapz.
trapezoid = getattr(np, "trapezoid", None) or np.trapz


def sphere_point(theta, phi):
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)


@given(velocities(0.95), st.floats(0.2, np.pi - 0.2), st.floats(0, 2 * np.pi))
def test_solid_angle_ratio_is_the_jacobian_of_aberration(beta, theta, phi):
    """dOmega_received / dOmega_emitted = 1 / D^2: the area a small patch of photon directions
    covers on the unit sphere after aberration, by central differences."""
    h = 1e-5
    k = sphere_point(theta, phi)
    dk_dtheta = (sphere_point(theta + h, phi) - sphere_point(theta - h, phi)) / (2 * h)
    dk_dphi = (sphere_point(theta, phi + h) - sphere_point(theta, phi - h)) / (2 * h)
    kp_dtheta = (
        lorentz.aberrate(sphere_point(theta + h, phi), beta) - lorentz.aberrate(sphere_point(theta - h, phi), beta)
    ) / (2 * h)
    kp_dphi = (
        lorentz.aberrate(sphere_point(theta, phi + h), beta) - lorentz.aberrate(sphere_point(theta, phi - h), beta)
    ) / (2 * h)
    jacobian = np.linalg.norm(np.cross(kp_dtheta, kp_dphi)) / np.linalg.norm(np.cross(dk_dtheta, dk_dphi))
    d = doppler.doppler_factor_moving_observer(k, beta)
    assert_allclose(radiance.received_solid_angle(1.0, d), jacobian, rtol=2e-5)


wavelengths_m = np.linspace(10e-9, 200e-6, 400_001)


@pytest.mark.parametrize("doppler_factor", [0.2, 0.7, 1.0, 1.9, 6.0])
@pytest.mark.parametrize("temperature", [3000.0, 5762.0])
def test_blackbody_seen_at_D_T(doppler_factor, temperature):
    """D^5 B(lambda D, T) = B(lambda, D T), with colour-science's Planck law on both sides."""
    wl = np.linspace(100e-9, 5000e-9, 500)
    shifted = radiance.transform_spectral_radiance(
        lambda w: colour.colorimetry.planck_law(w, temperature), wl, doppler_factor
    )
    assert_allclose(shifted, colour.colorimetry.planck_law(wl, doppler_factor * temperature), rtol=1e-10)


@pytest.mark.parametrize("doppler_factor", [0.3, 1.0, 2.5])
def test_integrated_radiance_is_the_integral_of_the_spectral_law(doppler_factor):
    """Integrating D^5 L(lambda D) over lambda gives D^4 times the integral of L: the D^4 of the
    searchlight effect, and not Chang et al.'s single power of D."""

    def spectrum(w):
        return np.exp(-0.5 * ((w - 600e-9) / 80e-9) ** 2) + 0.3 * np.exp(-0.5 * ((w - 1.5e-6) / 0.3e-6) ** 2)

    emitted = trapezoid(spectrum(wavelengths_m), wavelengths_m)
    observed = trapezoid(radiance.transform_spectral_radiance(spectrum, wavelengths_m, doppler_factor), wavelengths_m)
    assert_allclose(radiance.transform_integrated_radiance(emitted, doppler_factor), observed, rtol=1e-6)
    if doppler_factor != 1.0:
        assert not np.isclose(radiance.chang_integrated_radiance(emitted, doppler_factor), observed, rtol=1e-2)
    assert_allclose(
        radiance.transform_integrated_radiance(1.0, doppler_factor)
        / radiance.chang_integrated_radiance(1.0, doppler_factor),
        doppler_factor**3,
    )


@pytest.mark.parametrize("doppler_factor", [0.4, 3.0])
def test_frequency_radiance_scales_by_D_cubed(doppler_factor):
    """L_nu dnu = L_lambda dlambda: the per-frequency radiance at the shifted frequency D nu is
    D^3 the emitted one, consistent with the D^5 wavelength law."""
    nu = 5e14  # Hz
    c = 299792458.0
    emitted_lambda = lambda w: colour.colorimetry.planck_law(w, 4000.0)  # noqa: E731
    L_nu_emit = emitted_lambda(c / nu) * c / nu**2
    received_nu = doppler_factor * nu
    L_lambda_obs = radiance.transform_spectral_radiance(emitted_lambda, c / received_nu, doppler_factor)
    L_nu_obs = L_lambda_obs * c / received_nu**2
    assert_allclose(radiance.transform_frequency_radiance(L_nu_emit, doppler_factor), L_nu_obs, rtol=1e-10)


@settings(deadline=None, max_examples=10)
@given(velocities(0.9), directions)
def test_point_light_irradiance_from_counted_photons(beta_s, k):
    """A light isotropic in its own frame, moving with beta_s past a surface: send photons in a
    fine grid of source-frame directions, carry each to the surface frame by aberration, and
    count the energy per unit surface-frame solid angle and receiving time around ``k``. Each
    photon's energy scales by D and its arrival rate by D (the source-frame period shrinks to
    1/D): power per solid angle is I D^2 (solid angle) D (energy) D (rate)."""
    rng = np.random.default_rng(7)
    count = 1_000_000
    u = rng.uniform(-1, 1, size=count)
    phi = rng.uniform(0, 2 * np.pi, size=count)
    source_dirs = np.stack([np.sqrt(1 - u * u) * np.cos(phi), np.sqrt(1 - u * u) * np.sin(phi), u], axis=1)
    lab_dirs = lorentz.aberrate(source_dirs, -beta_s)  # the surface frame moves with -beta_s
    d_photon = doppler.doppler_factor_moving_source(lab_dirs, beta_s)
    cone = np.cos(0.15)
    inside = lab_dirs @ k > cone
    cone_solid_angle = 2 * np.pi * (1 - cone)
    photon_solid_angle = 4 * np.pi / count
    # intensity 1 in the source frame: each photon carries photon_solid_angle per unit source time
    power = np.sum(d_photon[inside] ** 2) * photon_solid_angle / cone_solid_angle
    # expected: the irradiance law averaged over surface-frame directions uniform in the cone
    basis = np.linalg.svd(k[None, :])[2]  # +-k and two unit vectors normal to it
    basis[0] *= np.sign(basis[0] @ k)
    cos_t = rng.uniform(cone, 1, size=200_000)
    psi = rng.uniform(0, 2 * np.pi, size=200_000)
    sin_t = np.sqrt(1 - cos_t**2)
    in_cone = cos_t[:, None] * basis[0] + sin_t[:, None] * (
        np.cos(psi)[:, None] * basis[1] + np.sin(psi)[:, None] * basis[2]
    )
    doppler_in_cone = doppler.doppler_factor_moving_source(in_cone, beta_s)
    expected = radiance.point_light_irradiance(1.0, doppler_in_cone, 1.0, 1.0).mean()
    assert_allclose(power, expected, rtol=4 / np.sqrt(inside.sum()))


def test_point_light_irradiance_geometry():
    assert_allclose(radiance.point_light_irradiance(2.0, 1.0, 0.5, 2.0), 2.0 * 0.5 / 4)
    assert radiance.point_light_irradiance(2.0, 3.0, -0.5, 2.0) == 0.0
    spectral = radiance.spectral_point_light_irradiance(lambda w: np.ones_like(w), np.array([500e-9]), 2.0, 1.0, 1.0)
    assert_allclose(spectral, 32.0)


def test_rejects_non_positive_doppler_factor():
    for bad in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(ValueError, match="doppler"):
            radiance.transform_integrated_radiance(1.0, bad)
    with pytest.raises(ValueError, match="distance"):
        radiance.point_light_irradiance(1.0, 1.0, 1.0, 0.0)
