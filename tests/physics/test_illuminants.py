"""The fast mode's table for light reflected under an illuminant (physics/illuminants.py), against
colour-science: Planck's law, Mallett & Yuksel's basis and the CIE 1931 observer integrated here,
with ``L_obs(lambda) = D^5 L(lambda D)`` (Weiskopf et al. 1999 eq. 14, docs/physics.md)."""

import colour
import numpy as np
import pytest

from relativity_addon.physics import illuminants, spectral, spectral_luts

CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(colour.SpectralShape(360, 830, 1))
WAVELENGTHS = CMFS.wavelengths


def _observed_rgb(weights, temperature, doppler):
    """Linear Rec.709 of ``D^5 R(lambda D) B(lambda D, T)``, ``R`` the basis with ``weights``."""
    emitted = WAVELENGTHS * doppler
    basis = spectral.reflectance_basis_Mallett2019(emitted)  # colour-science's basis, held beyond its band
    radiance = doppler**5 * colour.colorimetry.planck_law(emitted * 1e-9, temperature) * (basis @ weights)
    return spectral.XYZ_to_linear_rec709(radiance @ CMFS.values)


def test_white_illuminant_is_the_emitter_table():
    """With 6504 K white the table is the one shipped for emitters (built with colour-science)."""
    grid = spectral_luts.doppler_lut_log10_d_grid(256)
    np.testing.assert_allclose(
        illuminants.doppler_lut(grid, None), spectral_luts.doppler_matrix_lut(grid), rtol=2e-6, atol=2e-6
    )


@pytest.mark.parametrize("temperature", [1800.0, 2700.0, 5762.0, 15000.0])
@pytest.mark.parametrize("doppler", [0.3, 0.8, 1.0, 1.7, 4.0])
def test_reflected_light_is_shifted_as_reflectance_times_illuminant(temperature, doppler):
    """A surface of basis weights ``w`` under a blackbody: its pixel at rest, through ``M_S(D)``,
    is the observed colour of the shifted ``R B`` spectrum (to 1e-6 of the brightest channel)."""
    for weights in (np.ones(3), np.array([0.8, 0.15, 0.1]), np.array([0.1, 0.2, 0.7])):
        rest = _observed_rgb(weights, temperature, 1.0)
        expected = _observed_rgb(weights, temperature, doppler)
        observed = illuminants.doppler_matrix(doppler, temperature) @ rest
        np.testing.assert_allclose(observed, expected, rtol=0, atol=1e-6 * np.abs(expected).max())


def test_white_wall_is_the_blackbody_at_d_t():
    """The white wall (``R`` = 1) under a blackbody lamp is exactly the blackbody at ``D T``."""
    for temperature in (2700.0, 4000.0):
        for doppler in (0.5, 2.0):
            rest = spectral.XYZ_to_linear_rec709(spectral.blackbody_XYZ(temperature))
            observed = illuminants.doppler_matrix(doppler, temperature) @ rest
            expected = spectral.XYZ_to_linear_rec709(spectral.blackbody_XYZ(doppler * temperature))
            np.testing.assert_allclose(observed, expected, rtol=1e-6)


def test_table_is_finite_over_the_whole_range():
    grid = spectral_luts.doppler_lut_log10_d_grid(2048)
    for temperature in (1000.0, 2700.0, 40000.0):
        table = illuminants.doppler_lut(grid, temperature)
        assert np.all(np.isfinite(table))
