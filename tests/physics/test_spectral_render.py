"""Spectral mode's core (physics/spectral_render.py): its shipped-table numpy against colour-science
(physics/spectral.py), and the accuracy of the per-pixel integral against direct integration."""

import numpy as np
import pytest

from relativity_addon.physics import spectral, spectral_render

MU = np.geomspace(190.0, 3000.0, 97)


def test_shipped_tables_reproduce_colour_science():
    np.testing.assert_allclose(
        spectral_render.reflectance_matrix(MU), spectral.reflectance_basis_Mallett2019(MU), rtol=1e-12, atol=1e-15
    )
    np.testing.assert_allclose(spectral_render.white(MU), spectral.illuminant_white(MU), rtol=1e-9)
    temperatures = np.array([800.0, 2700.0, 5762.0, 20000.0])
    np.testing.assert_allclose(
        spectral_render.blackbody_xyz(temperatures), spectral.blackbody_XYZ(temperatures), rtol=1e-9
    )
    np.testing.assert_allclose(
        np.exp(spectral_render.log_blackbody_luminance(temperatures)),
        spectral.blackbody_luminance(temperatures),
        rtol=1e-9,
    )
    doppler = np.array([0.3, 0.9, 1.0, 1.7, 4.0])
    np.testing.assert_allclose(
        spectral_render.doppler_rgb_matrix(doppler), spectral.doppler_rgb_matrix(doppler), rtol=1e-9, atol=1e-12
    )
    rgb = np.array([[0.2, -0.1, 0.5], [1.0, 0.5, 0.0], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(spectral_render.gamut_map(rgb), spectral.gamut_map_linear_rec709(rgb), atol=1e-12)


def _delta_e(rgb_a, rgb_b):
    import colour

    lab = [
        colour.XYZ_to_Lab(spectral.linear_rec709_to_XYZ(c) / spectral.linear_rec709_to_XYZ(c)[1])
        for c in (rgb_a, rgb_b)
    ]
    return float(colour.delta_E(*lab, method="CIE 2000"))


@pytest.mark.parametrize("doppler", [0.6, 1.0, 1.5, 2.5])
@pytest.mark.parametrize("temperature", [2200.0, 4500.0, 9000.0])
def test_blackbody_seen_at_d_t(doppler, temperature):
    """Samples ``D^4 L(mu)`` of a blackbody reconstruct the blackbody at ``D T`` with ``Y(DT)/Y(T)``
    (docs/physics.md), at 4 passes: Delta E 2000 < 0.5, luminance within 1 %."""
    wavelengths = spectral_render.sample_wavelengths(doppler * 0.97, doppler * 1.03, 4)
    samples = doppler**4 * spectral_render.blackbody_samples(wavelengths, temperature)
    rgb = spectral_render.reconstruct_rgb(samples[None], np.array([np.log(doppler)]), wavelengths, map_to_gamut=False)[
        0
    ]
    expected = spectral.XYZ_to_linear_rec709(
        spectral.blackbody_XYZ(doppler * temperature) / spectral.blackbody_luminance(temperature)
    )
    assert spectral.luminance_linear_rec709(rgb) / spectral.luminance_linear_rec709(expected) == pytest.approx(
        1.0, abs=0.01
    )
    assert _delta_e(rgb, expected) < 0.5


@pytest.mark.parametrize("doppler", [0.5, 1.0, 1.9])
def test_rgb_emitters_match_the_fast_modes_exact_matrix(doppler):
    """An up-sampled emitted colour: the same as spectral.doppler_shift_rgb (direct integration).
    Exact by construction where the samples resolve the three basis spectra; at D = 1.9 all samples
    lie beyond 655 nm, where the basis is flat and the constraint nearly degenerate: 3e-5 measured."""
    wavelengths = spectral_render.sample_wavelengths(doppler, doppler, 3)
    colours = np.array([[0.2, 0.5, 0.8], [0.9, 0.1, 0.05], [1.0, 1.0, 1.0]])
    samples = doppler**4 * colours @ spectral_render.emission_matrix(wavelengths).T
    rgb = spectral_render.reconstruct_rgb(samples, np.full(3, np.log(doppler)), wavelengths)
    np.testing.assert_allclose(rgb, spectral.doppler_shift_rgb(colours, doppler), rtol=1e-4, atol=1e-9)


def test_reflectance_product_two_bounces_against_direct_integration():
    """Two coloured reflectances under a 4000 K sun at D = 1.4: the product spectrum (which no RGB
    matrix holds) reconstructed from 4 passes within Delta E 0.5 of direct integration."""
    doppler, temperature = 1.4, 4000.0
    wall, floor = (0.2, 0.5, 0.8), (0.9, 0.6, 0.2)

    def spectrum(mu):
        basis = spectral.reflectance_basis_Mallett2019(mu)
        return (basis @ wall) * (basis @ floor) * spectral.blackbody_spectral_radiance(mu, temperature)

    grid = spectral.WAVELENGTHS_VISIBLE_NM
    expected_xyz = (doppler**5 * spectrum(grid * doppler)) @ spectral._cmfs_visible()
    wavelengths = spectral_render.sample_wavelengths(doppler, doppler, 4)
    rgb = spectral_render.reconstruct_rgb(
        (doppler**4 * spectrum(wavelengths))[None], np.array([np.log(doppler)]), wavelengths, map_to_gamut=False
    )[0]
    expected = spectral.XYZ_to_linear_rec709(expected_xyz)
    assert _delta_e(rgb, expected) < 0.5
    assert spectral.luminance_linear_rec709(rgb) / expected_xyz[1] == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize("d_range", [(0.01, 0.02), (0.01, 100.0), (50.0, 100.0)])
def test_no_nan_or_negative_pixel_for_d_from_0_01_to_100(d_range):
    """A blackbody plus an RGB emitter over the whole Doppler range: finite, non-negative colours,
    brighter toward larger D (the searchlight)."""
    low, high = d_range
    wavelengths = spectral_render.sample_wavelengths(low, high, 4)
    log_d = np.linspace(np.log(low), np.log(high), 40)
    emitted = spectral_render.blackbody_samples(wavelengths, 5000.0) + spectral_render.emission_matrix(
        wavelengths
    ) @ np.array([0.3, 0.5, 0.2])
    samples = np.exp(4.0 * log_d)[:, None] * emitted
    rgb = spectral_render.reconstruct_rgb(samples, log_d, wavelengths)
    assert np.all(np.isfinite(rgb)) and rgb.min() >= 0.0
    luminance = spectral_render.luminance(rgb)
    assert luminance[-1] > luminance[0]
