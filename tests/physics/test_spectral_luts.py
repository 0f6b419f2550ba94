"""Tests of relativity_addon.physics.spectral_luts: layouts, units and interpolation error.

The tables are compared with the exact functions of relativity_addon.physics.spectral (tested
against colour-science in test_spectral.py) and with colour-science directly, never with numbers
printed by the module under test.
"""

import warnings

import numpy as np
import pytest

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # colour warns that matplotlib is missing.
    import colour

from relativity_addon.physics import spectral, spectral_luts

CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
VISIBLE = colour.SpectralShape(360, 830, 1)


def colour_blackbody_XYZ(temperature_K):
    """XYZ in W sr^-1 m^-2 through colour-science's own sd_blackbody and sd_to_XYZ."""

    sd = colour.sd_blackbody(temperature_K, VISIBLE)
    # sd_blackbody is per nanometre; with k = 1 and the default illuminant E (100 everywhere)
    # sd_to_XYZ returns sum(S xyzbar dlambda), dlambda in nm: W sr^-1 m^-2 as it stands.
    return colour.sd_to_XYZ(sd, CMFS, k=1, method="Integration")


# --- Doppler matrix table -----------------------------------------------------------------------


def test_doppler_matrix_lut_layout_and_nodes():
    grid = spectral_luts.doppler_lut_log10_d_grid(64)
    lut = spectral_luts.doppler_matrix_lut(grid)
    assert lut.dtype == np.float32 and lut.shape == (64 * 3 * 4,)
    assert np.all(np.isfinite(lut))
    pixels = lut.reshape(3, 64, 4)  # (matrix row / image row, D / image column, RGBA)
    matrices = spectral.doppler_rgb_matrix(10.0**grid)
    white_luminance = spectral.luminance_linear_rec709(matrices.sum(-1))
    np.testing.assert_allclose(pixels[..., 3], np.log(white_luminance)[None].repeat(3, 0), atol=1e-4)
    np.testing.assert_allclose(np.moveaxis(pixels[..., :3], 0, 1), matrices / white_luminance[:, None, None], atol=1e-6)


def test_doppler_matrix_lut_interpolation_error():
    """Linear interpolation in log10 D of the default 2048-column table: worst at mid-cells."""

    grid = spectral_luts.doppler_lut_log10_d_grid()
    lut = spectral_luts.doppler_matrix_lut(grid)
    midpoints = 10.0 ** (0.5 * (grid[1:] + grid[:-1]))
    exact = spectral.doppler_rgb_matrix(midpoints)
    sampled = spectral_luts.sample_doppler_matrix_lut(lut, grid, midpoints)
    white_luminance = spectral.luminance_linear_rec709(exact.sum(-1))
    error = np.abs(sampled - exact).max(axis=(-1, -2)) / white_luminance
    # Worst near D = 0.01, where the band sees the CIE table's truncated red end (1e-123 of white).
    assert error.max() < 5e-3
    assert error[midpoints > 0.1].max() < 1e-3


# --- Blackbody table ---------------------------------------------------------------------------


def test_blackbody_lut_layout_units_and_float32_range():
    grid = spectral_luts.blackbody_lut_log10_t_grid(64)
    lut = spectral_luts.blackbody_rgb_lut(grid)
    assert lut.dtype == np.float32 and lut.shape == (64 * 4,)
    pixels = lut.reshape(64, 4)
    assert np.all(np.isfinite(pixels)) and np.all(pixels[:, :3] >= 0)
    np.testing.assert_allclose(spectral.luminance_linear_rec709(pixels[:, :3]), 1.0, rtol=1e-6)
    for j in (20, 40, 63):  # Above ~1000 K, where colour's own sd_blackbody does not underflow.
        Y = colour_blackbody_XYZ(10.0 ** grid[j])[1]
        assert pixels[j, 3] == pytest.approx(np.log(Y), abs=1e-5)


def test_blackbody_lut_interpolation_error():
    grid = spectral_luts.blackbody_lut_log10_t_grid()
    lut = spectral_luts.blackbody_rgb_lut(grid)
    midpoints = 10.0 ** (0.5 * (grid[1:] + grid[:-1]))
    exact = spectral.blackbody_linear_rgb(midpoints, gamut_map=True)
    sampled = spectral_luts.sample_blackbody_rgb_lut(lut, grid, midpoints)
    error = np.abs(sampled - exact).max(-1) / spectral.blackbody_luminance(midpoints)
    assert error.max() < 5e-3  # Worst near 100 K, where ln Y curves most in log T.
    assert error[midpoints > 1000].max() < 1e-3
    # The searchlight ratio from the alpha channel, as the shader computes it.
    T, D = 5762.0, np.array([0.3, 0.7, 1.5, 4.0])
    alpha = np.interp(np.log10([T, *(D * T)]), grid, lut.reshape(-1, 4)[:, 3].astype(float))
    np.testing.assert_allclose(np.exp(alpha[1:] - alpha[0]), spectral.blackbody_luminance_ratio(T, D), rtol=1e-4)


# --- Validation ---------------------------------------------------------------------------------


def test_bad_grids_raise():
    with pytest.raises(ValueError, match="log10_d_grid"):
        spectral_luts.doppler_matrix_lut([0.0, np.inf])
    with pytest.raises(ValueError, match="log10_t_grid"):
        spectral_luts.blackbody_rgb_lut([3.0, np.nan])
    with pytest.raises(ValueError, match="underflows"):
        spectral_luts.doppler_matrix_lut([-4.0, 0.0])
