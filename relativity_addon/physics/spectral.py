"""Spectral Doppler and searchlight colour: blackbodies and up-sampled Rec.709 colours.

Convention (``docs/physics.md``): the Doppler factor is ``D = nu_received / nu_emitted``,
``D > 1`` is a blueshift. Spectral radiance per unit wavelength transforms as

    L_obs(lambda) = D^5 L_emit(lambda D)            (Weiskopf et al. 1999, eq. 14)

and integrated radiance as ``D^4`` (eq. 15). A blackbody at ``T`` is seen as a blackbody at
``D T``; its *visible* luminance changes by ``Y(D T) / Y(T)``, not by ``D^4``.

Colours are Blender scene linear: linear Rec.709 (= sRGB) primaries, D65 white, CIE 1931 2 degree
observer. ``XYZ <-> RGB`` uses colour-science's "ITU-R BT.709" colourspace (sRGB's primaries and
white; its matrices are derived from them at full precision and are exact inverses, whereas the
"sRGB" entry carries IEC 61966-2-1's 4-decimal matrix, whose round trip is off by ~1e-5), with *no*
chromatic adaptation and no transfer function: the colourspace white is D65, blackbody colours are
those an observer adapted to D65 (Blender's convention) sees, and up-sampled colours are lit by a
6504 K blackbody normalised to RGB (1, 1, 1) at rest.

Everything here is numpy and colour-science; no ``bpy``. The lookup tables the shaders sample are
built from these functions in :mod:`.spectral_luts`. ``docs/spectral-model.md`` describes the
model, its extension outside the visible band and the lookup-table layouts for the shader.

References
----------
- Weiskopf, D., Kraus, U., Ruder, H. (1999). Searchlight and Doppler effects in the visualization
  of special relativity: a corrected derivation of the transformation of radiance. ACM Transactions
  on Graphics 18(3), 278-292.
- Mallett, I., Yuksel, C. (2019). Spectral Primary Decomposition for Rendering with sRGB
  Reflectance. Eurographics Symposium on Rendering (DL-only track).
- Jakob, W., Hanika, J. (2019). A Low-Dimensional Function Space for Efficient Spectral
  Upsampling. Computer Graphics Forum 38(2) (the out-of-band behaviour the basis extension follows).
"""

from __future__ import annotations

import functools

import colour
import numpy as np
from colour.colorimetry import planck_law

from .arrays import ArrayLike, FloatArray, Spectrum

__all__ = [
    "CMFS_NAME",
    "WAVELENGTHS_VISIBLE_NM",
    "WHITE_TEMPERATURE_K",
    "BASIS_PLATEAU_FRACTION",
    "XYZ_to_linear_rec709",
    "linear_rec709_to_XYZ",
    "luminance_linear_rec709",
    "gamut_map_linear_rec709",
    "blackbody_spectral_radiance",
    "doppler_shifted_spectral_radiance",
    "blackbody_XYZ",
    "blackbody_linear_rgb",
    "blackbody_luminance",
    "observed_blackbody_temperature",
    "blackbody_luminance_ratio",
    "reflectance_basis_Mallett2019",
    "basis_constrained_band_nm",
    "illuminant_white",
    "doppler_rgb_matrix",
    "doppler_shift_rgb",
]

CMFS_NAME = "CIE 1931 2 Degree Standard Observer"
"""Observer for every colour in this module (Blender's scene linear is defined with it)."""

WAVELENGTHS_VISIBLE_NM = np.arange(360.0, 831.0, 1.0)
"""Integration grid (nm): the CIE 1931 colour matching functions' own 1 nm tabulation. The CMFs
vanish outside it, so no light outside 360-830 nm contributes to XYZ or RGB."""

WHITE_TEMPERATURE_K = 6504.0
"""Temperature of the blackbody that lights up-sampled colours (D65's correlated colour temperature)."""

BASIS_PLATEAU_FRACTION = 0.9
"""Fraction of its peak at which the red (blue) basis function is taken to leave its plateau."""

_WAVELENGTH_STEP_NM = 1.0

_REC709 = colour.RGB_COLOURSPACES["ITU-R BT.709"]


def _validated_positive(values: ArrayLike, name: str) -> FloatArray:
    """``values`` as a float64 array; ``ValueError`` unless every entry is finite and > 0."""

    array = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite (got NaN or inf): {values!r}")
    if not np.all(array > 0):
        raise ValueError(f"{name} must be > 0: {values!r}")
    return array


def _validated_finite(values: ArrayLike, name: str) -> FloatArray:
    array = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite (got NaN or inf): {values!r}")
    return array


@functools.lru_cache(maxsize=None)
def _cmfs_visible() -> FloatArray:
    """CIE 1931 2 degree CMFs on :data:`WAVELENGTHS_VISIBLE_NM`, shape (W, 3), read-only."""

    cmfs = colour.MSDS_CMFS[CMFS_NAME]
    values = np.stack(
        [np.interp(WAVELENGTHS_VISIBLE_NM, cmfs.wavelengths, cmfs.values[:, i]) for i in range(3)],
        axis=-1,
    )
    values.setflags(write=False)
    return values


# --- Colour space -------------------------------------------------------------------------------


def XYZ_to_linear_rec709(XYZ: ArrayLike) -> FloatArray:
    """Linear Rec.709 (Blender scene linear) RGB from CIE 1931 XYZ, shape (..., 3).

    colour-science's "ITU-R BT.709" colourspace, no chromatic adaptation (its white and ours are
    both D65), no transfer function.
    """

    return colour.XYZ_to_RGB(
        np.asarray(XYZ, dtype=np.float64),
        _REC709,
        illuminant=None,
        chromatic_adaptation_transform=None,
        apply_cctf_encoding=False,
    )


def linear_rec709_to_XYZ(RGB: ArrayLike) -> FloatArray:
    """CIE 1931 XYZ from linear Rec.709 RGB, shape (..., 3); inverse of :func:`XYZ_to_linear_rec709`."""

    return colour.RGB_to_XYZ(
        np.asarray(RGB, dtype=np.float64),
        _REC709,
        illuminant=None,
        chromatic_adaptation_transform=None,
        apply_cctf_decoding=False,
    )


@functools.lru_cache(maxsize=None)
def _rec709_luminance_weights() -> FloatArray:
    """Row Y of the Rec.709 RGB -> XYZ matrix (about 0.2126, 0.7152, 0.0722)."""

    weights = np.array(_REC709.matrix_RGB_to_XYZ[1], dtype=np.float64)
    weights.setflags(write=False)
    return weights


def luminance_linear_rec709(RGB: ArrayLike) -> FloatArray:
    """Relative luminance ``Y`` of linear Rec.709 RGB, shape (...)."""

    return np.asarray(RGB, dtype=np.float64) @ _rec709_luminance_weights()


def gamut_map_linear_rec709(RGB: ArrayLike) -> FloatArray:
    """Bring linear Rec.709 RGB into the gamut by desaturating toward grey at constant luminance.

    A strongly shifted spectrum (a blackbody below ~1900 K, white seen at ``D << 1``) is a real
    colour outside the Rec.709 triangle: some components are negative. Negative light breaks
    compositing and view transforms, so colours are moved along the line to the grey of the same
    luminance ``Y`` until the smallest component is 0:

        rgb' = Y + (rgb - Y) * Y / (Y - min(rgb))     if min(rgb) < 0, else rgb

    This keeps ``Y`` and the dominant hue, is homogeneous of degree 1 (it commutes with any
    brightness factor such as ``D^4`` or ``Y(DT)/Y(T)``), and is cheap in a shader. Colours with
    ``Y <= 0`` (impossible for a non-negative spectrum) map to black.
    """

    rgb = np.asarray(RGB, dtype=np.float64)
    luminance = luminance_linear_rec709(rgb)[..., None]
    smallest = np.min(rgb, axis=-1, keepdims=True)
    out_of_gamut = smallest < 0
    with np.errstate(divide="ignore", invalid="ignore"):
        saturation = np.where(out_of_gamut, luminance / (luminance - smallest), 1.0)
    mapped = luminance + (rgb - luminance) * saturation
    # In-gamut colours pass through bit-exact (Y + (rgb - Y) would round tiny components to 0).
    mapped = np.where(out_of_gamut, mapped, rgb)
    mapped = np.where(luminance > 0, mapped, 0.0)
    # Rounding can leave -1e-17 where the smallest component was driven to exactly 0.
    return np.maximum(mapped, 0.0)


# --- Blackbody ----------------------------------------------------------------------------------


def _planck_outer(wavelength_nm: ArrayLike, temperature_K: ArrayLike) -> FloatArray:
    """:func:`colour.colorimetry.planck_law` as an outer product, shape (W, N), W/(sr m^2 m).

    planck_law evaluates every wavelength at every temperature (flattening both); this keeps that
    shape explicit, even for a single wavelength or temperature.
    """

    wavelength_m = np.ravel(wavelength_nm) * 1e-9
    temperature_K = np.ravel(temperature_K)
    with np.errstate(over="ignore", under="ignore"):
        # exp(c2 / (lambda T)) overflows to inf deep in the Wien tail: the radiance is then 0.
        radiance = planck_law(wavelength_m, temperature_K)
    return np.reshape(radiance, (wavelength_m.size, temperature_K.size))


def blackbody_spectral_radiance(wavelength_nm: ArrayLike, temperature_K: ArrayLike) -> FloatArray:
    """Planck's law ``B_lambda(lambda, T)`` in W sr^-1 m^-2 per metre of wavelength.

    :func:`colour.colorimetry.planck_law` taking nanometres, with numpy broadcasting between
    ``wavelength_nm`` and ``temperature_K`` (element-wise, not an outer product).
    """

    temperature_K = _validated_positive(temperature_K, "temperature_K")
    wavelength_nm = _validated_positive(wavelength_nm, "wavelength_nm")
    wavelength_nm, temperature_K = np.broadcast_arrays(wavelength_nm, temperature_K)
    unique_temperatures, index = np.unique(temperature_K, return_inverse=True)
    radiance = np.empty(wavelength_nm.shape, dtype=np.float64)
    flat_wavelengths = wavelength_nm.ravel()
    flat_radiance = radiance.reshape(-1)
    for k, temperature in enumerate(unique_temperatures):
        selected = np.ravel(index) == k
        flat_radiance[selected] = _planck_outer(flat_wavelengths[selected], temperature)[:, 0]
    return radiance


def doppler_shifted_spectral_radiance(
    wavelength_nm: ArrayLike, emitted_spectral_radiance: Spectrum, doppler_factor: ArrayLike
) -> FloatArray:
    """Observed spectral radiance ``L_obs(lambda) = D^5 L_emit(lambda D)``.

    Weiskopf et al. (1999) eq. 14, written for ``D = nu_received / nu_emitted`` (their eq. 1 uses
    ``lambda' = lambda D`` with the reciprocal ``D``). ``emitted_spectral_radiance`` is a callable of
    wavelength in nm, in the emitter's rest frame; ``wavelength_nm`` and ``doppler_factor`` broadcast.
    """

    doppler = _validated_positive(doppler_factor, "doppler_factor")
    wavelength = _validated_positive(wavelength_nm, "wavelength_nm")
    return doppler**5 * np.asarray(emitted_spectral_radiance(wavelength * doppler), dtype=np.float64)


def blackbody_XYZ(temperature_K: ArrayLike) -> FloatArray:
    """CIE 1931 XYZ of a blackbody at ``temperature_K``, shape (..., 3), in W sr^-1 m^-2.

    ``X = integral B_lambda(lambda, T) xbar(lambda) dlambda`` over 360-830 nm at 1 nm (the CMFs'
    tabulation), with no 683 lm/W factor: radiometric units weighted by the dimensionless CMFs,
    absolute and consistent between temperatures.
    """

    temperature_K = _validated_positive(temperature_K, "temperature_K")
    radiance = _planck_outer(WAVELENGTHS_VISIBLE_NM, temperature_K)  # (W, N)
    XYZ = radiance.T @ _cmfs_visible() * (_WAVELENGTH_STEP_NM * 1e-9)
    return XYZ.reshape(*temperature_K.shape, 3)


def blackbody_linear_rgb(temperature_K: ArrayLike, gamut_map: bool = False) -> FloatArray:
    """Linear Rec.709 RGB of a blackbody at ``temperature_K``, shape (..., 3), in W sr^-1 m^-2.

    Exact colorimetry by default: below about 1900 K the blue component is negative (and below
    about 1000 K the green one), because those blackbodies lie outside the Rec.709 gamut. With
    ``gamut_map=True`` the colour is passed through :func:`gamut_map_linear_rec709`.
    """

    rgb = XYZ_to_linear_rec709(blackbody_XYZ(temperature_K))
    return gamut_map_linear_rec709(rgb) if gamut_map else rgb


def blackbody_luminance(temperature_K: ArrayLike) -> FloatArray:
    """CIE ``Y`` of a blackbody at ``temperature_K`` in W sr^-1 m^-2 (CMF-weighted radiance)."""

    return blackbody_XYZ(temperature_K)[..., 1]


def observed_blackbody_temperature(temperature_K: ArrayLike, doppler_factor: ArrayLike) -> FloatArray:
    """Temperature ``D T`` of the blackbody an observer sees; the emitter is at ``T`` in its frame.

    Exact because ``D^5 B_lambda(lambda D, T) = B_lambda(lambda, D T)`` (Planck's law with
    Weiskopf et al. 1999 eq. 14).
    """

    temperature_K = _validated_positive(temperature_K, "temperature_K")
    doppler_factor = _validated_positive(doppler_factor, "doppler_factor")
    return doppler_factor * temperature_K


def blackbody_luminance_ratio(temperature_K: ArrayLike, doppler_factor: ArrayLike) -> FloatArray:
    """Observed over emitted visible luminance of a blackbody: ``Y(D T) / Y(T)``.

    This is the searchlight factor for what a camera records; it differs from the bolometric
    ``D^4`` of Weiskopf et al. (1999) eq. 15 because the band shifts across the Planck curve.
    Computed as the exponential of a difference of logarithms so that it stays finite where
    ``Y(T)`` itself underflows double precision.
    """

    observed = observed_blackbody_temperature(temperature_K, doppler_factor)
    log_emitted = _log_blackbody_luminance(temperature_K)
    if not np.all(np.isfinite(log_emitted)):
        raise ValueError(f"temperature_K too low: the visible luminance is 0 even in log space: {temperature_K!r}")
    with np.errstate(over="ignore"):  # Beyond 1e308 (T of 1e-300 K...) the ratio is inf.
        return np.exp(_log_blackbody_luminance(observed) - log_emitted)


def _log_blackbody_luminance(temperature_K: ArrayLike) -> FloatArray:
    """``ln Y(T)`` computed in log space (finite even where ``Y`` underflows, e.g. T of a few K)."""

    temperature_K = np.asarray(temperature_K, dtype=np.float64)
    wavelength_m = WAVELENGTHS_VISIBLE_NM * 1e-9
    c1, c2 = 3.741771e-16, 0.014388  # The constants colour.colorimetry.planck_law uses by default.
    x = c2 / (wavelength_m * temperature_K[..., None])
    # ln B = ln(c1 / pi / lambda^5) - ln(exp(x) - 1), with ln(exp(x) - 1) = x + log1p(-exp(-x)).
    log_radiance = np.log(c1 / np.pi / wavelength_m**5) - (x + np.log1p(-np.exp(-x)))
    log_weights = np.log(_cmfs_visible()[:, 1] * (_WAVELENGTH_STEP_NM * 1e-9))
    terms = log_radiance + log_weights
    peak = np.max(terms, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore"):
        log_sum = peak[..., 0] + np.log(np.sum(np.exp(terms - peak), axis=-1))
    return np.where(np.isneginf(peak[..., 0]), -np.inf, log_sum)


# --- Up-sampled RGB: Mallett & Yuksel (2019) ----------------------------------------------------


@functools.lru_cache(maxsize=None)
def _basis_table() -> tuple[FloatArray, FloatArray]:
    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019
    return np.array(basis.wavelengths, dtype=np.float64), np.array(basis.values, dtype=np.float64)


@functools.lru_cache(maxsize=None)
def basis_constrained_band_nm() -> tuple[float, float]:
    """``(lambda_lo, lambda_hi)``: where the Mallett & Yuksel basis still says something (420, 655 nm).

    The basis was fitted to reproduce sRGB through the CIE observer, so it is only determined where
    the observer sees. Toward both ends of its 380-780 nm table, where the observer is nearly blind,
    every function drifts to ~1/3 (the fit's smoothness term, not a property of any colour). The band
    runs from where the blue function first reaches ``BASIS_PLATEAU_FRACTION`` of its peak to where
    the red function last does.
    """

    table_nm, values = _basis_table()
    red, blue = values[:, 0], values[:, 2]
    lo = table_nm[np.argmax(blue >= BASIS_PLATEAU_FRACTION * blue.max())]
    hi = table_nm[len(red) - 1 - np.argmax(red[::-1] >= BASIS_PLATEAU_FRACTION * red.max())]
    return float(lo), float(hi)


def reflectance_basis_Mallett2019(wavelength_nm: ArrayLike) -> FloatArray:
    """Mallett & Yuksel (2019) sRGB reflectance basis, extended to all wavelengths, shape (..., 3).

    ``reflectance(lambda) = sum_i w_i basis_i(lambda)``. Tabulated by colour-science at 5 nm;
    linearly interpolated inside :func:`basis_constrained_band_nm` (keeps the basis within
    [0, 1], summing to 1) and held at the band's edge values outside it: beyond 655 nm a colour
    reflects as much as its red part does at the red plateau's end, below 420 nm as much as its
    blue part does at the blue plateau's start. So reds stay bright in the infrared, blues in the
    ultraviolet, greens dark at both ends, and white reflects 1 everywhere. (Jakob & Hanika's
    sigmoid spectra of the same colours agree on those three; their parabola also turns reds up
    in the ultraviolet and blues up in the infrared, which is not followed here.)
    """

    wavelength_nm = np.asarray(wavelength_nm, dtype=np.float64)
    table_nm, values = _basis_table()
    lo, hi = basis_constrained_band_nm()
    clipped = np.clip(wavelength_nm, lo, hi)
    return np.stack([np.interp(clipped, table_nm, values[:, i]) for i in range(3)], axis=-1)


def illuminant_white(wavelength_nm: ArrayLike) -> FloatArray:
    """Relative spectral power of the white light of up-sampled colours, 1 at 560 nm, shape (...).

    A blackbody at ``WHITE_TEMPERATURE_K`` (6504 K, D65's correlated colour temperature). Not CIE
    D65 itself: D65 is daylight under Earth's atmosphere, with ozone's ultraviolet cut-off below
    320 nm and oxygen and water bands near 760 and 820 nm. A relativistic observer is in space, and
    at ``D`` between 0.2 and 0.6 (or near 1.3) those atmospheric features would sweep through the
    visible band as spurious colour. The blackbody is smooth and defined at every wavelength. Its
    colour differs slightly from D65 (it lies on the Planckian locus); the normalisation in
    :func:`doppler_rgb_matrix` makes it RGB (1, 1, 1) at rest.
    """

    wavelength_nm = np.asarray(wavelength_nm, dtype=np.float64)
    radiance = _planck_outer(wavelength_nm, WHITE_TEMPERATURE_K).reshape(wavelength_nm.shape)
    return radiance / _planck_outer(560.0, WHITE_TEMPERATURE_K)[0, 0]


def _unnormalised_doppler_rgb_matrix(doppler_factor: FloatArray) -> FloatArray:
    """``A(D)``: column ``i`` is the linear Rec.709 RGB seen at ``D`` of basis ``i`` in white light.

    ``A(D)_{:, i} = RGB(integral xyzbar(lambda) D^5 E(lambda D) basis_i(lambda D) dlambda)``
    (Weiskopf et al. 1999 eq. 14 for the shift; sum over the CMFs' 1 nm grid).
    """

    emitted_nm = WAVELENGTHS_VISIBLE_NM * doppler_factor[..., None]
    radiance = illuminant_white(emitted_nm) * doppler_factor[..., None] ** 5
    spectra = reflectance_basis_Mallett2019(emitted_nm) * radiance[..., None]  # (..., W, 3)
    XYZ_columns = np.einsum("wc,...wi->...ci", _cmfs_visible(), spectra) * _WAVELENGTH_STEP_NM
    return np.asarray(_REC709.matrix_XYZ_to_RGB) @ XYZ_columns


@functools.lru_cache(maxsize=None)
def _inverse_rest_frame_matrix() -> FloatArray:
    inverse = np.linalg.inv(_unnormalised_doppler_rgb_matrix(np.array(1.0)))
    inverse.setflags(write=False)
    return inverse


def doppler_rgb_matrix(doppler_factor: ArrayLike) -> FloatArray:
    """3x3 matrix ``M(D)``, shape (..., 3, 3): linear Rec.709 RGB emitted -> RGB observed at ``D``.

    The emitter's colour is up-sampled to a reflectance with the Mallett & Yuksel (2019) basis
    (linear in RGB, extended outside the visible band by :func:`reflectance_basis_Mallett2019`), lit
    by a 6504 K blackbody (:func:`illuminant_white`), shifted with
    ``L_obs(lambda) = D^5 L_emit(lambda D)`` (Weiskopf et al. 1999 eq. 14) and integrated with the
    CIE 1931 observer. Every step is linear in RGB, so the whole transform is ``M(D) = A(D) A(1)^-1``:
    ``A(1)^-1`` turns the input RGB into the basis weights whose lit spectrum reproduces exactly
    that RGB at rest (the bare basis is off by up to ~1e-3, the blackbody by its scale and its
    small distance from D65; white's weights are within 4 % of equal), so
    ``M(1)`` is the identity to rounding. Includes the searchlight factor: the total radiance
    scales by ``D^4`` (eq. 15), the visible luminance by what the shifted band collects (white:
    ~2e-123 at D = 0.01, 0.63 at 0.9, 1.42 at 1.1, 107 at 10, 1295 at 100).

    Entries can be negative at large shifts (the shifted colour leaves the Rec.709 gamut); use
    :func:`doppler_shift_rgb` for displayable colours. Below ``D`` of about 0.004 the visible band
    sees only the far Wien tail of the blackbody and the matrix underflows to exactly 0.
    """

    doppler_factor = _validated_positive(doppler_factor, "doppler_factor")
    return _unnormalised_doppler_rgb_matrix(doppler_factor) @ _inverse_rest_frame_matrix()


def doppler_shift_rgb(rgb: ArrayLike, doppler_factor: ArrayLike, gamut_map: bool = True) -> FloatArray:
    """Linear Rec.709 RGB seen at Doppler factor ``D`` of an emitter of colour ``rgb``, (..., 3).

    ``M(D) rgb`` (see :func:`doppler_rgb_matrix`), then, by default, :func:`gamut_map_linear_rec709`
    so that the result is finite and non-negative for any non-negative ``rgb``. ``rgb`` is the
    colour the emitter has in its own rest frame (a self-luminous surface, or a surface under a
    light at rest relative to it) and must be finite; ``rgb`` and ``D`` broadcast.
    """

    rgb = _validated_finite(rgb, "rgb")
    matrix = doppler_rgb_matrix(doppler_factor)
    observed = np.einsum("...ij,...j->...i", matrix, rgb)
    return gamut_map_linear_rec709(observed) if gamut_map else observed
