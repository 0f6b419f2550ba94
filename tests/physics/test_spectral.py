"""Tests of relativity_addon.physics.spectral against independent relations.

Reference values come from colour-science directly (Planck's law, sd_blackbody, sd_to_XYZ, its
SpectralDistribution interpolation) or from the physics (PHYSICS.md, Weiskopf et al. 1999), never
from numbers printed by the module under test.
"""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # colour warns that matplotlib is missing.
    import colour

from relativity_addon.physics import spectral

CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
VISIBLE = colour.SpectralShape(360, 830, 1)
# Linear Rec.709: sRGB primaries and D65 white with full-precision, mutually inverse matrices.
REC709 = colour.RGB_COLOURSPACES["ITU-R BT.709"]

temperatures_K = st.floats(1000.0, 50000.0)
doppler_factors = st.floats(0.01, 100.0)
moderate_doppler_factors = st.floats(0.1, 10.0)
colours = st.tuples(*[st.floats(0.0, 1.0)] * 3)

TEST_COLOURS = np.array(
    [
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 1.0],
        [1.0, 0.0, 1.0],
        [0.18, 0.18, 0.18],
        [0.8, 0.3, 0.05],
        [5.0, 2.0, 0.5],  # Emissive, brighter than 1.
    ]
)


def colour_blackbody_XYZ(temperature_K):
    """XYZ in W sr^-1 m^-2 through colour-science's own sd_blackbody and sd_to_XYZ."""

    sd = colour.sd_blackbody(temperature_K, VISIBLE)
    # sd_blackbody is per nanometre; with k = 1 and the default illuminant E (100 everywhere)
    # sd_to_XYZ returns sum(S xyzbar dlambda), dlambda in nm: W sr^-1 m^-2 as it stands.
    return colour.sd_to_XYZ(sd, CMFS, k=1, method="Integration")


def XYZ_to_linear_rec709(XYZ):
    return colour.XYZ_to_RGB(XYZ, REC709, None, None)


def linear_rec709_to_xy(RGB):
    return colour.XYZ_to_xy(colour.RGB_to_XYZ(RGB, REC709, None, None))


# --- Blackbody ----------------------------------------------------------------------------------


@settings(max_examples=50, deadline=None)
@given(temperatures_K, moderate_doppler_factors)
def test_shifted_planck_is_planck_at_DT(temperature_K, doppler_factor):
    """D^5 B(lambda D, T) = B(lambda, D T), pointwise, with colour-science's Planck law."""

    wavelength_nm = np.linspace(200.0, 3000.0, 57)
    with np.errstate(over="ignore"):  # Deep Wien tail: exp overflows, both sides are 0.
        shifted = spectral.doppler_shifted_spectral_radiance(
            wavelength_nm,
            lambda emitted_nm: colour.colorimetry.planck_law(emitted_nm * 1e-9, temperature_K),
            doppler_factor,
        )
        expected = colour.colorimetry.planck_law(
            wavelength_nm * 1e-9, doppler_factor * temperature_K
        )
    observed_T = spectral.observed_blackbody_temperature(temperature_K, doppler_factor)
    assert observed_T == pytest.approx(doppler_factor * temperature_K, rel=1e-15)
    np.testing.assert_allclose(shifted, expected, rtol=1e-10)


def test_blackbody_spectral_radiance_broadcasts_element_wise():
    wavelength_nm = np.array([400.0, 550.0, 700.0])
    temperature_K = np.array([[1500.0], [6504.0]])
    expected = np.array(
        [[colour.colorimetry.planck_law(w * 1e-9, t) for w in wavelength_nm] for t in (1500, 6504)]
    )
    np.testing.assert_allclose(
        spectral.blackbody_spectral_radiance(wavelength_nm, temperature_K), expected, rtol=1e-12
    )


@pytest.mark.parametrize("temperature_K", [1000, 1500, 2856, 4000, 5762, 6504, 10000, 3e4, 1e5])
def test_blackbody_rgb_has_colour_science_chromaticity(temperature_K):
    xy_expected = colour.XYZ_to_xy(colour_blackbody_XYZ(temperature_K))
    xy = linear_rec709_to_xy(spectral.blackbody_linear_rgb(temperature_K))
    np.testing.assert_allclose(xy, xy_expected, atol=1e-9)


def test_blackbody_rgb_is_absolute_and_white_consistent():
    temperature_K = np.array([800.0, 3000.0, 6504.0, 2e4])
    expected = np.array([XYZ_to_linear_rec709(colour_blackbody_XYZ(t)) for t in temperature_K])
    np.testing.assert_allclose(spectral.blackbody_linear_rgb(temperature_K), expected, rtol=1e-9)
    # No chromatic adaptation: the D65 spectrum itself is RGB white.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # colour notes that it aligns D65 to 360-830 nm.
        d65_XYZ = colour.sd_to_XYZ(colour.SDS_ILLUMINANTS["D65"], CMFS, method="Integration")
    d65_rgb = spectral.XYZ_to_linear_rec709(d65_XYZ)
    np.testing.assert_allclose(d65_rgb / d65_rgb[1], [1, 1, 1], atol=2e-3)


def test_blackbody_rgb_gamut_map_only_lifts_negative_components():
    rgb = spectral.blackbody_linear_rgb([1000.0, 1500.0, 6504.0])
    mapped = spectral.blackbody_linear_rgb([1000.0, 1500.0, 6504.0], gamut_map=True)
    assert rgb[0, 2] < 0 and rgb[1, 2] < 0  # Below ~1900 K blackbodies are outside Rec.709.
    assert np.all(mapped >= 0)
    np.testing.assert_allclose(mapped[2], rgb[2])
    np.testing.assert_allclose(
        spectral.luminance_linear_rec709(mapped), spectral.luminance_linear_rec709(rgb), rtol=1e-12
    )


@settings(max_examples=50, deadline=None)
@given(temperatures_K, moderate_doppler_factors)
def test_blackbody_luminance_ratio_is_Y_DT_over_Y_T(temperature_K, doppler_factor):
    expected = (
        colour_blackbody_XYZ(doppler_factor * temperature_K)[1]
        / colour_blackbody_XYZ(temperature_K)[1]
    )
    ratio = spectral.blackbody_luminance_ratio(temperature_K, doppler_factor)
    assert ratio == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("doppler_factor", [0.25, 0.5, 2.0, 4.0])
def test_blackbody_luminance_ratio_is_not_D4(doppler_factor):
    """The visible band is not the whole spectrum: the ratio is not the bolometric D^4."""

    ratio = spectral.blackbody_luminance_ratio(5762.0, doppler_factor)
    assert abs(ratio / doppler_factor**4 - 1) > 0.1


def test_blackbody_luminance_ratio_stays_finite_where_Y_underflows():
    ratio = spectral.blackbody_luminance_ratio(5000.0, 0.001)  # Seen as a 5 K blackbody.
    assert np.isfinite(ratio) and 0 <= ratio < 1e-100


# --- Up-sampled RGB Doppler matrix --------------------------------------------------------------


def test_matrix_at_rest_is_identity():
    np.testing.assert_allclose(spectral.doppler_rgb_matrix(1.0), np.eye(3), atol=1e-3)
    np.testing.assert_allclose(spectral.doppler_rgb_matrix(1.0), np.eye(3), atol=1e-12)


def test_matrix_vectorises_over_D():
    D = np.array([[0.5, 1.0], [2.0, 10.0]])
    stacked = spectral.doppler_rgb_matrix(D)
    assert stacked.shape == (2, 2, 3, 3)
    np.testing.assert_allclose(stacked[1, 0], spectral.doppler_rgb_matrix(2.0), rtol=1e-12)


@settings(max_examples=40, deadline=None)
@given(doppler_factors)
def test_matrix_is_continuous_in_D(doppler_factor):
    step = 1e-5
    here = spectral.doppler_rgb_matrix(doppler_factor)
    there = spectral.doppler_rgb_matrix(doppler_factor * (1 + step))
    white_here = spectral.luminance_linear_rec709(here.sum(-1))
    white_there = spectral.luminance_linear_rec709(there.sum(-1))
    # The luminance scale changes at most like D^~280 (Wien tail at D = 0.01); the colour slowly.
    assert abs(np.log(white_there / white_here)) < 300 * step
    np.testing.assert_allclose(there / white_there, here / white_here, atol=1e-2)


def test_white_reddens_below_one_and_blues_above():
    D = np.geomspace(0.01, 100, 801)
    white = spectral.doppler_shift_rgb([1.0, 1.0, 1.0], D)
    blue_over_red = white[:, 2] / white[:, 0]
    assert np.all(blue_over_red[D < 0.999] < 1) and np.all(blue_over_red[D > 1.001] > 1)
    assert np.all(white[D < 0.999, 0] > white[D < 0.999, 2])


def test_white_hue_moves_monotonically_toward_blue():
    """b/r of white rises with D wherever D65 has no sharp feature crossing the band.

    Known exceptions (see docs/spectral-model.md): D in ~[0.2, 0.62] where D65's ozone cut-off at
    300-330 nm sweeps through the visible band, and a 0.3 % ripple near D = 1.3 from D65's
    oxygen dip at 760 nm. Blackbodies, with no such features, are monotonic over the whole range.
    """

    D = np.concatenate([np.geomspace(0.65, 1.25, 200), np.geomspace(1.35, 100, 400)])
    white = spectral.doppler_shift_rgb([1.0, 1.0, 1.0], D, gamut_map=False)
    assert np.all(np.diff(white[:, 2] / white[:, 0]) > 0)

    # Over the whole range the chromaticity x still falls decade by decade. (b/r of the raw RGB
    # is no hue measure for D < 0.2, where the colour is outside Rec.709 near the spectral
    # locus' red end; gamut mapping then sets b by the distance from the gamut.)
    decades = spectral.doppler_shift_rgb([1.0, 1.0, 1.0], [0.01, 0.1, 1.0, 10.0, 100.0], False)
    assert np.all(np.diff(linear_rec709_to_xy(decades)[:, 0]) < 0)

    # A blackbody's chromaticity x falls monotonically with D T (Planckian locus).
    temperature_K = 5762.0 * np.geomspace(0.01, 100, 400)
    x = linear_rec709_to_xy(spectral.blackbody_linear_rgb(temperature_K))[:, 0]
    assert np.all(np.diff(x) < 0)


def test_output_is_finite_and_non_negative_over_the_whole_range():
    D = np.geomspace(0.01, 100, 1001)
    observed = spectral.doppler_shift_rgb(TEST_COLOURS[:, None, :], D[None, :])
    assert observed.shape == (len(TEST_COLOURS), len(D), 3)
    assert np.all(np.isfinite(observed)) and np.all(observed >= 0)
    np.testing.assert_array_equal(observed[0], 0.0)  # Black stays black.
    assert np.all(np.isfinite(spectral.doppler_rgb_matrix(D)))


@settings(max_examples=60, deadline=None)
@given(colours, doppler_factors)
def test_gamut_mapped_output_keeps_luminance(rgb, doppler_factor):
    raw = spectral.doppler_shift_rgb(rgb, doppler_factor, gamut_map=False)
    mapped = spectral.doppler_shift_rgb(rgb, doppler_factor)
    assert np.all(np.isfinite(mapped)) and np.all(mapped >= 0)
    luminance = spectral.luminance_linear_rec709(raw)
    assert luminance >= 0  # Luminance of a non-negative spectrum.
    assert spectral.luminance_linear_rec709(mapped) == pytest.approx(luminance, rel=1e-9, abs=1e-300)
    if np.all(raw >= 0):
        np.testing.assert_allclose(mapped, raw)


def _brute_force_observed_rgb(weights, doppler_factor):
    """RGB seen at D of the D65-lit Mallett-basis reflectance with basis weights ``weights``.

    Built with colour-science's own spectral classes: the basis as a MultiSpectralDistributions
    (linear interpolation, colour's constant extrapolation), D65 as a SpectralDistribution (linear
    interpolation) continued outside 300-780 nm by 6504 K Planck matched at each end, the shift
    L_obs(lambda) = D^5 L_emit(lambda D), and colour's sd_to_XYZ integration.
    """

    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019.copy()
    basis.interpolator = colour.LinearInterpolator
    d65 = colour.SDS_ILLUMINANTS["D65"].copy()
    d65.interpolator = colour.LinearInterpolator
    d65.extrapolator_kwargs = {"method": "Constant", "left": 0, "right": 0}
    planck = lambda nm: colour.colorimetry.planck_law(np.asarray(nm) * 1e-9, 6504.0)  # noqa: E731
    first, last = d65.wavelengths[0], d65.wavelengths[-1]

    def d65_extended(nm):
        nm = np.asarray(nm, dtype=float)
        return np.where(
            nm < first,
            planck(nm) * d65[first] / planck(first),
            np.where(nm > last, planck(nm) * d65[last] / planck(last), d65[nm]),
        )

    observed_nm = VISIBLE.wavelengths
    emitted_nm = observed_nm * doppler_factor
    reflectance = basis[emitted_nm] @ np.asarray(weights, dtype=float)
    observed = doppler_factor**5 * reflectance * d65_extended(emitted_nm)
    sd = colour.SpectralDistribution(observed, observed_nm)
    return XYZ_to_linear_rec709(colour.sd_to_XYZ(sd, CMFS, k=1, method="Integration"))


@pytest.mark.parametrize("doppler_factor", [0.45, 0.9, 1.3, 2.7, 40.0])
def test_matrix_matches_brute_force_spectral_computation(doppler_factor):
    # Basis weights that reproduce each RGB exactly at rest (the documented normalisation).
    at_rest = np.stack([_brute_force_observed_rgb(e, 1.0) for e in np.eye(3)], axis=-1)
    for rgb in TEST_COLOURS[1:6]:
        weights = np.linalg.solve(at_rest, rgb)
        expected = _brute_force_observed_rgb(weights, doppler_factor)
        observed = spectral.doppler_shift_rgb(rgb, doppler_factor, gamut_map=False)
        scale = spectral.luminance_linear_rec709(expected)
        np.testing.assert_allclose(observed, expected, atol=1e-9 * scale)


def test_extended_d65_is_continuous_and_planck_shaped_outside_its_table():
    d65 = colour.SDS_ILLUMINANTS["D65"]
    for edge, outward in ((300.0, -1e-6), (780.0, 1e-6)):
        assert spectral.illuminant_D65_extended(edge + outward) == pytest.approx(d65[edge], rel=1e-4)
    ratio = spectral.illuminant_D65_extended(2000.0) / spectral.illuminant_D65_extended(1000.0)
    expected = colour.colorimetry.planck_law(2000e-9, 6504) / colour.colorimetry.planck_law(1000e-9, 6504)
    assert ratio == pytest.approx(expected, rel=1e-12)
    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019
    np.testing.assert_allclose(spectral.reflectance_basis_Mallett2019(5000.0), basis.values[-1])
    np.testing.assert_allclose(spectral.reflectance_basis_Mallett2019(50.0), basis.values[0])


# --- Lookup tables ------------------------------------------------------------------------------


def test_doppler_matrix_lut_layout_and_nodes():
    grid = spectral.doppler_lut_log10_d_grid(64)
    lut = spectral.doppler_matrix_lut(grid)
    assert lut.dtype == np.float32 and lut.shape == (64 * 3 * 4,)
    assert np.all(np.isfinite(lut))
    pixels = lut.reshape(3, 64, 4)  # (matrix row / image row, D / image column, RGBA)
    matrices = spectral.doppler_rgb_matrix(10.0**grid)
    white_luminance = spectral.luminance_linear_rec709(matrices.sum(-1))
    np.testing.assert_allclose(pixels[..., 3], np.log(white_luminance)[None].repeat(3, 0), atol=1e-4)
    np.testing.assert_allclose(
        np.moveaxis(pixels[..., :3], 0, 1), matrices / white_luminance[:, None, None], atol=1e-6
    )


def test_doppler_matrix_lut_interpolation_error():
    """Linear interpolation in log10 D of the default 2048-column table: worst at mid-cells."""

    grid = spectral.doppler_lut_log10_d_grid()
    lut = spectral.doppler_matrix_lut(grid)
    midpoints = 10.0 ** (0.5 * (grid[1:] + grid[:-1]))
    exact = spectral.doppler_rgb_matrix(midpoints)
    sampled = spectral.sample_doppler_matrix_lut(lut, grid, midpoints)
    white_luminance = spectral.luminance_linear_rec709(exact.sum(-1))
    error = np.abs(sampled - exact).max(axis=(-1, -2)) / white_luminance
    assert error.max() < 3e-3
    assert error[midpoints > 0.6].max() < 1e-3


def test_blackbody_lut_layout_units_and_float32_range():
    grid = spectral.blackbody_lut_log10_t_grid(64)
    lut = spectral.blackbody_rgb_lut(grid)
    assert lut.dtype == np.float32 and lut.shape == (64 * 4,)
    pixels = lut.reshape(64, 4)
    assert np.all(np.isfinite(pixels)) and np.all(pixels[:, :3] >= 0)
    np.testing.assert_allclose(spectral.luminance_linear_rec709(pixels[:, :3]), 1.0, rtol=1e-6)
    for j in (20, 40, 63):  # Above ~1000 K, where colour's own sd_blackbody does not underflow.
        Y = colour_blackbody_XYZ(10.0 ** grid[j])[1]
        assert pixels[j, 3] == pytest.approx(np.log(Y), abs=1e-5)


def test_blackbody_lut_interpolation_error():
    grid = spectral.blackbody_lut_log10_t_grid()
    lut = spectral.blackbody_rgb_lut(grid)
    midpoints = 10.0 ** (0.5 * (grid[1:] + grid[:-1]))
    exact = spectral.blackbody_linear_rgb(midpoints, gamut_map=True)
    sampled = spectral.sample_blackbody_rgb_lut(lut, grid, midpoints)
    error = np.abs(sampled - exact).max(-1) / spectral.blackbody_luminance(midpoints)
    assert error.max() < 5e-3  # Worst near 100 K, where ln Y curves most in log T.
    assert error[midpoints > 1000].max() < 1e-3
    # The searchlight ratio from the alpha channel, as the shader computes it.
    T, D = 5762.0, np.array([0.3, 0.7, 1.5, 4.0])
    alpha = np.interp(np.log10([T, *(D * T)]), grid, lut.reshape(-1, 4)[:, 3].astype(float))
    np.testing.assert_allclose(
        np.exp(alpha[1:] - alpha[0]), spectral.blackbody_luminance_ratio(T, D), rtol=1e-4
    )


# --- Validation ---------------------------------------------------------------------------------

BAD_POSITIVE = [0.0, -1.0, np.nan, np.inf, -np.inf, [1.0, np.nan], [2.0, 0.0]]


@pytest.mark.parametrize("bad", BAD_POSITIVE)
def test_bad_doppler_factor_raises(bad):
    for call in (
        lambda: spectral.doppler_rgb_matrix(bad),
        lambda: spectral.doppler_shift_rgb([1, 1, 1], bad),
        lambda: spectral.observed_blackbody_temperature(5000.0, bad),
        lambda: spectral.blackbody_luminance_ratio(5000.0, bad),
        lambda: spectral.doppler_shifted_spectral_radiance(500.0, lambda nm: nm, bad),
    ):
        with pytest.raises(ValueError, match="doppler_factor"):
            call()


@pytest.mark.parametrize("bad", BAD_POSITIVE)
def test_bad_temperature_raises(bad):
    for call in (
        lambda: spectral.blackbody_linear_rgb(bad),
        lambda: spectral.blackbody_XYZ(bad),
        lambda: spectral.blackbody_luminance(bad),
        lambda: spectral.blackbody_spectral_radiance(500.0, bad),
        lambda: spectral.observed_blackbody_temperature(bad, 1.0),
        lambda: spectral.blackbody_luminance_ratio(bad, 1.0),
    ):
        with pytest.raises(ValueError, match="temperature_K"):
            call()


def test_bad_rgb_and_grids_raise():
    with pytest.raises(ValueError, match="rgb"):
        spectral.doppler_shift_rgb([1.0, np.nan, 0.0], 2.0)
    with pytest.raises(ValueError, match="log10_d_grid"):
        spectral.doppler_matrix_lut([0.0, np.inf])
    with pytest.raises(ValueError, match="log10_t_grid"):
        spectral.blackbody_rgb_lut([3.0, np.nan])
    with pytest.raises(ValueError, match="underflows"):
        spectral.doppler_matrix_lut([-4.0, 0.0])
