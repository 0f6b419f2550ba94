"""The fast mode's Doppler matrix for light reflected under a known illuminant.

The fast (RGB) mode turns every pixel's colour into a spectrum and shifts it (Weiskopf et al.
1999 eq. 14, ``L_obs(lambda) = D^5 L(lambda D)``). The emitter table (``spectral.doppler_rgb_matrix``)
reads a pixel ``rgb`` as an up-sampled reflectance lit by 6504 K white, right for self-luminous
colours and the world, and for surfaces lit by white light. A surface lit by a lamp of spectrum
``S`` sends ``R(lambda) S(lambda)``: read with the white table, a white wall under a 2700 K lamp
at ``D`` = 2 comes out Delta E 2000 26 from the blackbody at ``D T`` and 13 % of its luminance
(docs/spectral-model.md). This table reads the pixel as ``R S`` instead, ``R`` Mallett & Yuksel's
basis with the weights that reproduce ``rgb`` at rest under ``S``:

    A_S(D)[:, i] = RGB(integral xyzbar(lambda) D^5 S(lambda D) basis_i(lambda D) dlambda)
    M_S(D) = A_S(D) A_S(1)^-1

For ``S`` a blackbody at ``T`` the white wall is exact: ``D^5 B(lambda D, T) = B(lambda, D T)``.
Packed like the emitter table (``spectral_luts.doppler_matrix_lut``): ``M = exp(a) N``, with
``exp(a)`` the luminance of ``M (1, 1, 1)``, so one shader reads either. Computed in log space
(Planck's law spans far beyond float64 over ``D`` in [0.01, 100]) from the tables the add-on ships,
in numpy alone: it runs inside Blender, whenever the scene's illuminant changes.
"""

from __future__ import annotations

import numpy as np

from .arrays import ArrayLike, Float32Array, FloatArray
from .spectral_render import PLANCK_C1, PLANCK_C2, WHITE_TEMPERATURE_K, luminance, reflectance_matrix, tables

TEMPERATURE_RANGE_K = (1000.0, 40000.0)
"""Illuminant temperatures the table is built for (clamped): beyond them the rest-frame inverse
asks for reflectances far outside [0, 1]."""

_NM = 1e-9


def log_planck(wavelengths_nm: ArrayLike, temperature_k: float) -> FloatArray:
    """``ln B(lambda, T)`` (Planck's law per metre, colour-science's constants), finite for any ``lambda``."""
    metres = np.asarray(wavelengths_nm, dtype=np.float64) * _NM
    x = PLANCK_C2 / (metres * float(temperature_k))
    return np.log(PLANCK_C1 / np.pi / metres**5) - x - np.log(-np.expm1(-x))


def _scaled_columns(log_doppler: FloatArray, temperature_k: float) -> tuple[FloatArray, FloatArray]:
    """``(A_S(D) exp(-m), m)``: the unnormalised matrices scaled by ``exp(-m(D))`` per ``D``."""
    shipped = tables()
    emitted = shipped["cmfs_nm"][None, :] * np.exp(log_doppler)[:, None]  # lambda D, (J, W)
    log_radiance = log_planck(emitted, temperature_k) + 5.0 * log_doppler[:, None]
    peak = log_radiance.max(axis=1)
    spectra = reflectance_matrix(emitted) * np.exp(log_radiance - peak[:, None])[..., None]  # (J, W, 3)
    columns = np.einsum("wc,jwi->jci", shipped["cmfs"], spectra)
    return shipped["xyz_to_rgb"] @ columns, peak


def normalised_matrices(log_doppler: ArrayLike, temperature_k: float | None) -> tuple[FloatArray, FloatArray]:
    """``(N, a)`` with ``M_S(D) = exp(a) N``, shapes ``(J, 3, 3)`` and ``(J,)``, for the illuminant
    a blackbody at ``temperature_k`` (None: the 6504 K white of up-sampled colours)."""
    temperature = WHITE_TEMPERATURE_K if temperature_k is None else float(np.clip(temperature_k, *TEMPERATURE_RANGE_K))
    log_doppler = np.atleast_1d(np.asarray(log_doppler, dtype=np.float64))
    scaled, peak = _scaled_columns(log_doppler, temperature)
    rest, rest_peak = _scaled_columns(np.zeros(1), temperature)
    product = scaled @ np.linalg.inv(rest[0])  # M_S(D) exp(-(m(D) - m(1)))
    white = luminance(product.sum(axis=-1))
    if not np.all(white > 0.0):
        raise ValueError(f"illuminant table: white has no light at T = {temperature} K")
    return product / white[:, None, None], peak - rest_peak[0] + np.log(white)


def doppler_matrix(doppler: ArrayLike, temperature_k: float | None) -> FloatArray:
    """``M_S(D)``, shape ``(..., 3, 3)``: pixel ``rgb`` (a reflectance under the illuminant) -> observed."""
    doppler = np.asarray(doppler, dtype=np.float64)
    normalised, log_scale = normalised_matrices(np.log(doppler).ravel(), temperature_k)
    return (normalised * np.exp(log_scale)[:, None, None]).reshape(*doppler.shape, 3, 3)


def doppler_lut(log10_d_grid: ArrayLike, temperature_k: float | None) -> Float32Array:
    """The packed table (float32, flat, ``12 N`` values), laid out as ``spectral_luts.doppler_matrix_lut``."""
    log10_d_grid = np.asarray(log10_d_grid, dtype=np.float64)
    normalised, log_scale = normalised_matrices(log10_d_grid * np.log(10.0), temperature_k)
    log_column = np.broadcast_to(log_scale[:, None, None], (len(log10_d_grid), 3, 1))
    pixels = np.concatenate([normalised, log_column], axis=-1)  # (N, row, 4)
    return np.ascontiguousarray(np.swapaxes(pixels, 0, 1)).astype(np.float32).ravel()
