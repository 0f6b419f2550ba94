"""Tests of relativity_addon.physics.spectral against independent relations.

Reference values come from colour-science directly (Planck's law, sd_blackbody, sd_to_XYZ, its
SpectralDistribution interpolation) or from the physics (docs/physics.md, Weiskopf et al. 1999), never
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
        expected = colour.colorimetry.planck_law(wavelength_nm * 1e-9, doppler_factor * temperature_K)
    observed_T = spectral.observed_blackbody_temperature(temperature_K, doppler_factor)
    assert observed_T == pytest.approx(doppler_factor * temperature_K, rel=1e-15)
    np.testing.assert_allclose(shifted, expected, rtol=1e-10)


def test_blackbody_spectral_radiance_broadcasts_element_wise():
    wavelength_nm = np.array([400.0, 550.0, 700.0])
    temperature_K = np.array([[1500.0], [6504.0]])
    expected = np.array([[colour.colorimetry.planck_law(w * 1e-9, t) for w in wavelength_nm] for t in (1500, 6504)])
    np.testing.assert_allclose(spectral.blackbody_spectral_radiance(wavelength_nm, temperature_K), expected, rtol=1e-12)


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
    expected = colour_blackbody_XYZ(doppler_factor * temperature_K)[1] / colour_blackbody_XYZ(temperature_K)[1]
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
    """Over the whole sweep white's colour moves one way, from red through white to blue.

    Measured with colour-science: the chromaticity x falls and the correlated colour temperature
    (Ohno 2013, valid from 1000 K to 1e5 K) rises at every step. b/r of the raw RGB rises too
    wherever it is a hue measure (for D < 0.2 the colour lies outside Rec.709 near the spectral
    locus' red end).
    """

    D = np.geomspace(0.01, 100, 1601)
    white = spectral.doppler_shift_rgb([1.0, 1.0, 1.0], D, gamut_map=False)
    xy = linear_rec709_to_xy(white)
    assert np.all(np.diff(xy[:, 0]) < 0)
    in_range = (D > 0.16) & (D < 15)
    cct = colour.uv_to_CCT(colour.xy_to_UCS_uv(xy[in_range]), method="Ohno 2013")[:, 0]
    assert np.all(np.diff(cct) > 0)
    blue_over_red = white[D > 0.2, 2] / white[D > 0.2, 0]
    assert np.all(np.diff(blue_over_red) > 0)

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
    """RGB seen at D of the Mallett-basis reflectance with basis weights ``weights`` in white light.

    Built with colour-science's own spectral classes: the basis as a MultiSpectralDistributions
    trimmed to the documented 420-655 nm band (linear interpolation, colour's constant
    extrapolation beyond it), a 6504 K blackbody from colour's Planck law, the shift
    L_obs(lambda) = D^5 L_emit(lambda D), and colour's sd_to_XYZ integration.
    """

    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019.copy()
    basis.trim(colour.SpectralShape(420, 655, 5))
    basis.interpolator = colour.LinearInterpolator
    observed_nm = VISIBLE.wavelengths
    emitted_nm = observed_nm * doppler_factor
    reflectance = basis[emitted_nm] @ np.asarray(weights, dtype=float)
    with np.errstate(over="ignore"):
        white = colour.colorimetry.planck_law(emitted_nm * 1e-9, 6504.0)
    observed = doppler_factor**5 * reflectance * white
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


def test_white_light_is_a_6504_K_blackbody():
    ratio = spectral.illuminant_white(np.array([300.0, 2000.0])) / spectral.illuminant_white(1000.0)
    planck = colour.colorimetry.planck_law(np.array([300e-9, 2000e-9, 1000e-9]), 6504.0)
    np.testing.assert_allclose(ratio, planck[:2] / planck[2], rtol=1e-12)
    assert spectral.illuminant_white(560.0) == pytest.approx(1.0, rel=1e-12)


def test_basis_is_held_at_the_edges_of_its_constrained_band():
    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019.copy()
    basis.interpolator = colour.LinearInterpolator
    lo, hi = spectral.basis_constrained_band_nm()
    # The band is where the blue (red) function is within 10 % of its plateau.
    assert basis[lo][2] >= 0.9 * basis.values[:, 2].max() > basis[lo - 5][2]
    assert basis[hi][0] >= 0.9 * basis.values[:, 0].max() > basis[hi + 5][0]
    for outside in (50.0, lo - 30.0, lo - 1e-9):
        np.testing.assert_allclose(spectral.reflectance_basis_Mallett2019(outside), basis[lo], rtol=1e-12)
    for outside in (hi + 1e-9, hi + 100.0, 5000.0):
        np.testing.assert_allclose(spectral.reflectance_basis_Mallett2019(outside), basis[hi], rtol=1e-12)
    inside = np.linspace(lo, hi, 97)
    np.testing.assert_allclose(spectral.reflectance_basis_Mallett2019(inside), basis[inside], atol=1e-12)


def _reflectance_weights(rgb):
    """Basis weights of ``rgb`` (the documented A(1)^-1 normalisation), scaled so white is ~1."""

    at_rest = np.stack([_brute_force_observed_rgb(e, 1.0) for e in np.eye(3)], axis=-1)
    white = np.linalg.solve(at_rest, np.ones(3))
    return np.linalg.solve(at_rest, rgb) / white.mean()


def test_out_of_band_reflectance_agrees_with_jakob_hanika_where_both_are_sure():
    """Reds bright in the infrared, blues in the ultraviolet, greens dark at both ends.

    Compared with colour-science's Jakob & Hanika (2019) sigmoid spectra of the same colours
    (under D65, the colourspace white). Mallett & Yuksel's own table drifts to 1/3 per function at
    its ends, which would make every colour reflect the same grey out of band.
    """

    cmfs, d65 = CMFS, colour.SDS_ILLUMINANTS["D65"]
    infrared, ultraviolet = 900.0, 340.0
    reflectance = {}
    for name, rgb in {"red": [0.8, 0.1, 0.1], "green": [0.1, 0.6, 0.1], "blue": [0.1, 0.1, 0.8]}.items():
        XYZ = colour.RGB_to_XYZ(np.array(rgb), REC709, illuminant=None)
        coefficients, _ = colour.recovery.find_coefficients_Jakob2019(XYZ, cmfs, d65)
        jakob = colour.recovery.sd_Jakob2019(coefficients, colour.SpectralShape(300, 1000, 10))
        ours = spectral.reflectance_basis_Mallett2019([infrared, ultraviolet]) @ _reflectance_weights(rgb)
        reflectance[name] = {"jakob": jakob[[infrared, ultraviolet]], "ours": ours}
    for model in ("jakob", "ours"):
        red, green, blue = (reflectance[name][model] for name in ("red", "green", "blue"))
        assert red[0] > 3 * green[0] and red[0] > 0.5  # Infrared.
        assert blue[1] > 3 * green[1] and blue[1] > 0.5  # Ultraviolet.
        assert green[0] < 0.2 and green[1] < 0.2


def test_colours_keep_their_contrast_when_shifted_far():
    """At D = 2 the visible band shows 760-1560 nm: a red surface looks brighter than a green one."""

    red, green = spectral.doppler_shift_rgb([[0.8, 0.1, 0.1], [0.1, 0.6, 0.1]], 2.0)
    luminance = spectral.luminance_linear_rec709(np.stack([red, green]))
    assert luminance[0] > 3 * luminance[1]


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


def test_bad_rgb_raises():
    with pytest.raises(ValueError, match="rgb"):
        spectral.doppler_shift_rgb([1.0, np.nan, 0.0], 2.0)
