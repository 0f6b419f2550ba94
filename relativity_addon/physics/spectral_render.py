"""Spectral mode: the scene rendered at a few rest-frame wavelengths, then shifted per pixel.

For a scene at rest and a moving observer (the exact camera), light transport happens in the
scene frame, where every bounce is wavelength by wavelength. Cycles carries three independent
channels through every bounce, so one render pass gives the scene-frame spectral radiance
``L(mu)`` at three wavelengths ``mu`` when every material and light is given its spectral values
there. A few passes sample ``L`` over the band that the picture's Doppler factors bring into view,
and each pixel's colour is the CIE integral of Weiskopf et al. (1999) eq. 14,

    XYZ = integral xyzbar(lambda) D^5 L(lambda D) dlambda = D^4 integral xyzbar(mu / D) L(mu) dmu,

with the pixel's own ``D``. ``L`` is taken as linear in ``ln mu`` between samples (held constant
beyond the sampled band), so the integral is a weighted sum ``XYZ = D^4 sum_k V_k(D) L_k``; the
exact camera's shader already applies the ``D^4`` (searchlight), so the renders hold ``D^4 L_k``.

Spectra, the same as the fast (RGB) mode's (``docs/spectral-model.md``): a reflectance ``rgb`` is
Mallett & Yuksel's basis with weights ``rgb`` (white reflects 1 at every wavelength); an emitted
``rgb`` is that basis with the weights that reproduce ``rgb`` at rest under the 6504 K white of
:func:`.spectral.illuminant_white`; a blackbody at ``T`` with luminance ``Y`` is
``Y B(mu, T) / Y_B(T)``. Units: radiance per nanometre, integrated over the CIE 1931 observer's
1 nm grid, the fast mode's normalisation, so both modes agree for white light.

Everything here is numpy on the tables the add-on ships (``shipped_luts.spectral_mode_tables``, made
with colour-science by ``tools/build_luts.py``): it runs inside Blender, which has no
colour-science. ``tests/physics/test_spectral_render.py`` checks it against :mod:`.spectral`.
"""

from __future__ import annotations

import functools

import numpy as np

from . import shipped_luts
from .arrays import ArrayLike, FloatArray
from .shipped_luts import Table

__all__ = [
    "VISIBLE_BAND_NM",
    "CHANNELS_PER_PASS",
    "sample_wavelengths",
    "pass_wavelengths",
    "reflectance_matrix",
    "emission_matrix",
    "blackbody_samples",
    "reconstruction_table",
    "reconstruct_rgb",
]

VISIBLE_BAND_NM = (380.0, 780.0)
"""Band that counts for the picture: outside it the CIE 1931 functions are below 2e-4 of their peak."""

CHANNELS_PER_PASS = 3

ANCHOR_TEMPERATURES_K = (1500.0, 3000.0, 6000.0, 12000.0)
"""Blackbodies the reconstruction is made exact for (with every up-sampled RGB emitter), where
the samples leave room: at most ``K - 3`` of them count."""

_NM = 1e-9
PLANCK_C1, PLANCK_C2 = 3.741771e-16, 0.014388  # colour.colorimetry.planck_law's constants
WHITE_TEMPERATURE_K = 6504.0  # the white light of up-sampled colours (spectral.illuminant_white)


@functools.lru_cache(maxsize=1)
def _tables() -> dict[str, Table]:
    return shipped_luts.spectral_mode_tables()


def tables() -> dict[str, Table]:
    """The shipped tables (colour matching functions on their 1 nm grid, XYZ -> RGB, ...)."""
    return _tables()


def planck(wavelengths_nm: ArrayLike, temperature_k: float | FloatArray) -> FloatArray:
    """Planck's law per metre of wavelength (as colour-science's ``planck_law``), 0 deep in the Wien tail."""
    metres = np.asarray(wavelengths_nm, dtype=np.float64) * _NM
    with np.errstate(over="ignore"):
        return PLANCK_C1 / np.pi / metres**5 / np.expm1(PLANCK_C2 / (metres * temperature_k))


def log_blackbody_luminance(temperature_k: ArrayLike) -> FloatArray:
    """``ln Y_B(T)``, CIE ``Y`` of Planck's law over the 1 nm grid, in log space (no underflow)."""
    tables = _tables()
    metres = tables["cmfs_nm"] * _NM
    x = PLANCK_C2 / (metres * np.asarray(temperature_k, dtype=np.float64)[..., None])
    terms = np.log(PLANCK_C1 / np.pi / metres**5) - (x + np.log1p(-np.exp(-x))) + np.log(tables["cmfs"][:, 1] * _NM)
    peak = np.max(terms, axis=-1, keepdims=True)
    return peak[..., 0] + np.log(np.sum(np.exp(terms - peak), axis=-1))


def blackbody_xyz(temperature_k: ArrayLike) -> FloatArray:
    """CIE XYZ of Planck's law (per metre, summed on the 1 nm grid), shape (..., 3)."""
    tables = _tables()
    temperature_k = np.asarray(temperature_k, dtype=np.float64)
    radiance = planck(tables["cmfs_nm"], temperature_k[..., None])
    return radiance @ tables["cmfs"] * _NM


def white(wavelengths_nm: ArrayLike) -> FloatArray:
    """The 6504 K white of up-sampled colours, 1 at 560 nm."""
    return planck(wavelengths_nm, WHITE_TEMPERATURE_K) / planck(560.0, WHITE_TEMPERATURE_K)


def xyz_to_linear_rec709(xyz: ArrayLike) -> FloatArray:
    return np.asarray(xyz, dtype=np.float64) @ _tables()["xyz_to_rgb"].T


@functools.lru_cache(maxsize=1)
def _rgb_to_y() -> FloatArray:
    """The ``Y`` row of the Rec.709 -> XYZ matrix (inverted once: a LAPACK call per colour cost
    milliseconds on a loaded machine, and the lamp stage makes one per lamp and object)."""
    row = np.linalg.inv(_tables()["xyz_to_rgb"])[1]
    row.flags.writeable = False
    return row


def luminance(rgb: ArrayLike) -> FloatArray:
    """CIE ``Y`` of linear Rec.709 colours."""
    return np.asarray(rgb, dtype=np.float64) @ _rgb_to_y()


def gamut_map(rgb: ArrayLike) -> FloatArray:
    """:func:`.spectral.gamut_map_linear_rec709` in numpy alone (toward grey at constant Y)."""
    rgb = np.asarray(rgb, dtype=np.float64)
    grey = luminance(rgb)[..., None]
    smallest = np.min(rgb, axis=-1, keepdims=True)
    outside = smallest < 0
    with np.errstate(divide="ignore", invalid="ignore"):
        mapped = np.where(outside, grey + (rgb - grey) * (grey / (grey - smallest)), rgb)
    return np.maximum(np.where(grey > 0, mapped, 0.0), 0.0)


def doppler_rgb_matrix(doppler: ArrayLike) -> FloatArray:
    """:func:`.spectral.doppler_rgb_matrix` (the fast mode's exact matrix) from the shipped tables."""
    tables = _tables()
    doppler = np.asarray(doppler, dtype=np.float64)
    emitted = tables["cmfs_nm"] * doppler[..., None]
    spectra = reflectance_matrix(emitted) * (white(emitted) * doppler[..., None] ** 5)[..., None]
    columns = np.einsum("wc,...wi->...ci", tables["cmfs"], spectra)
    return tables["xyz_to_rgb"] @ columns @ tables["inverse_rest_matrix"]


def sample_wavelengths(doppler_min: float, doppler_max: float, passes: int) -> FloatArray:
    """``3 * passes`` rest-frame wavelengths (nm), evenly spaced in ``ln mu``, spanning what the
    pixels with Doppler factors in ``[doppler_min, doppler_max]`` see: ``[380 D_min, 780 D_max]``."""
    if passes < 1:
        raise ValueError(f"passes must be at least 1, got {passes}")
    if not (0.0 < doppler_min <= doppler_max and np.isfinite(doppler_max)):
        raise ValueError(f"bad Doppler range [{doppler_min}, {doppler_max}]")
    low, high = VISIBLE_BAND_NM[0] * doppler_min, VISIBLE_BAND_NM[1] * doppler_max
    return np.exp(np.linspace(np.log(low), np.log(high), CHANNELS_PER_PASS * passes))


def pass_wavelengths(wavelengths: ArrayLike, index: int) -> FloatArray:
    """The three wavelengths of pass ``index`` (channel ``c`` renders ``wavelengths[3 index + c]``)."""
    return np.asarray(wavelengths, dtype=np.float64)[CHANNELS_PER_PASS * index : CHANNELS_PER_PASS * (index + 1)]


def reflectance_matrix(wavelengths_nm: ArrayLike) -> FloatArray:
    """``(K, 3)``: reflectance at each wavelength of a surface of (linear Rec.709) colour ``rgb``
    is ``matrix @ rgb`` (Mallett & Yuksel 2019 basis, weights ``rgb``)."""
    tables = _tables()
    clipped = np.clip(np.asarray(wavelengths_nm, dtype=np.float64), *tables["basis_band_nm"])
    return np.stack([np.interp(clipped, tables["basis_nm"], tables["basis"][:, i]) for i in range(3)], axis=-1)


def emission_matrix(wavelengths_nm: ArrayLike) -> FloatArray:
    """``(K, 3)``: spectral radiance per nm at each wavelength of an emitter of colour ``rgb`` is
    ``matrix @ rgb``; its CIE integral at rest is ``rgb`` (as in :func:`.spectral.doppler_rgb_matrix`)."""
    wavelengths_nm = np.asarray(wavelengths_nm, dtype=np.float64)
    return white(wavelengths_nm)[..., None] * reflectance_matrix(wavelengths_nm) @ _tables()["inverse_rest_matrix"]


def blackbody_samples(wavelengths_nm: ArrayLike, temperature_k: float, luminance: float = 1.0) -> FloatArray:
    """Spectral radiance per nm of a blackbody at ``temperature_k`` (K) with CIE luminance ``luminance``."""
    wavelengths_nm = np.asarray(wavelengths_nm, dtype=np.float64)
    with np.errstate(divide="ignore"):
        log_radiance = np.log(planck(wavelengths_nm, float(temperature_k)))
    return luminance * np.exp(log_radiance - log_blackbody_luminance(float(temperature_k))) * _NM


def _cmfs() -> tuple[Table, Table]:
    return _tables()["cmfs_nm"], _tables()["cmfs"]


def reconstruction_table(wavelengths_nm: ArrayLike, log_doppler: ArrayLike, exact_for_rgb: bool = True) -> FloatArray:
    """``V[j, k, :]``: XYZ weight of sample ``k`` for a pixel with ``ln D = log_doppler[j]``.

    ``V_k(D) = integral xyzbar(mu / D) phi_k(mu) dmu = D integral xyzbar(lambda) phi_k(lambda D) dlambda``,
    with ``phi_k`` the hat functions of linear interpolation in ``ln mu`` (the end ones held
    constant outside the samples), summed on the CIE functions' 1 nm grid. The ``D^4`` is not in
    ``V``: the renders already hold it.
    """
    log_mu = np.log(np.asarray(wavelengths_nm, dtype=np.float64))
    log_doppler = np.atleast_1d(np.asarray(log_doppler, dtype=np.float64))
    grid, cmfs = _cmfs()
    emitted = np.log(grid)[None, :] + log_doppler[:, None]  # ln(lambda D), (J, W)
    identity = np.eye(log_mu.size)
    hats = np.stack([np.interp(emitted, log_mu, identity[k]) for k in range(log_mu.size)], axis=-1)  # (J, W, K)
    doppler = np.exp(log_doppler)[:, None, None]
    table = doppler * np.einsum("jwk,wc->jkc", hats, cmfs)
    if not exact_for_rgb:
        return table
    # Smallest change of the weights that makes chosen spectra exact despite their fine structure
    # (the RGB basis's steep flanks) that K samples cannot resolve: every up-sampled emitted colour,
    # V E = XYZ(M(D)) / D^4 (the fast mode's exact matrix, spectral.doppler_rgb_matrix), and
    # blackbodies at ANCHOR_TEMPERATURES_K, V b_T = XYZ_B(D T) / (Y_B(T) D^4).
    doppler = np.exp(log_doppler)
    spectra = [emission_matrix(np.exp(log_mu))]  # (K, 3)
    targets = [np.linalg.inv(_tables()["xyz_to_rgb"]) @ doppler_rgb_matrix(doppler)]
    for temperature in ANCHOR_TEMPERATURES_K:
        samples = blackbody_samples(np.exp(log_mu), temperature)
        norm = np.linalg.norm(samples)
        if not (np.isfinite(norm) and norm > 0.0):
            continue  # this blackbody has no light at the samples (far Wien tail)
        scale = 1.0 / norm
        spectra.append(samples[:, None] * scale)
        observed = blackbody_xyz(doppler * temperature) * np.exp(-log_blackbody_luminance(temperature))
        targets.append(observed[..., None] * scale)
    constrained = np.concatenate(spectra, axis=1)  # (K, S)
    target = np.concatenate(targets, axis=-1) / doppler[:, None, None] ** 4  # (J, 3, S)
    weights = np.swapaxes(table, 1, 2)  # (J, 3, K)
    residual = target - weights @ constrained
    # where a target under- or overflows (D far beyond the visible band's reach) that pixel keeps
    # the plain weights
    residual = np.where(np.all(np.isfinite(residual), axis=(1, 2), keepdims=True), residual, 0.0)
    corrected = weights + residual @ np.linalg.pinv(constrained, rcond=1e-6)
    return np.swapaxes(corrected, 1, 2)


def reconstruct_rgb(
    samples: ArrayLike,
    log_doppler: ArrayLike,
    wavelengths_nm: ArrayLike,
    table_size: int = 512,
    map_to_gamut: bool = True,
) -> FloatArray:
    """Linear Rec.709 colour of every pixel from its samples ``D^4 L_k``, shape ``(..., K)``, and its
    ``ln D``, shape ``(...)``: ``XYZ = sum_k V_k(D) D^4 L_k`` (:func:`reconstruction_table`, tabulated on
    ``table_size`` points of ``ln D`` over the pixels' range and interpolated linearly), then RGB,
    gamut-mapped like the fast mode (:func:`.spectral.gamut_map_linear_rec709`)."""
    samples = np.asarray(samples, dtype=np.float64)
    log_doppler = np.asarray(log_doppler, dtype=np.float64)
    if samples.shape[:-1] != log_doppler.shape:
        raise ValueError(f"samples {samples.shape} and log_doppler {log_doppler.shape} do not match")
    if not np.all(np.isfinite(log_doppler)):
        raise ValueError("log_doppler must be finite")
    low, high = float(log_doppler.min(initial=0.0)), float(log_doppler.max(initial=0.0))
    grid = np.linspace(low, high, table_size if high > low else 1)
    table = reconstruction_table(wavelengths_nm, grid)  # (J, K, 3)
    flat_log_d = log_doppler.ravel()
    flat_samples = samples.reshape(-1, samples.shape[-1])
    xyz = np.zeros((flat_log_d.size, 3))
    for k in range(flat_samples.shape[1]):
        for c in range(3):
            weight = np.interp(flat_log_d, grid, table[:, k, c]) if grid.size > 1 else table[0, k, c]
            xyz[:, c] += weight * flat_samples[:, k]
    rgb = xyz_to_linear_rec709(xyz).reshape(*log_doppler.shape, 3)
    return gamut_map(rgb) if map_to_gamut else rgb
