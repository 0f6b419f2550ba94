"""Lookup tables of the spectral model for the shaders: the blackbody colour and the Doppler matrix.

Blender's shaders cannot call colour-science, so the two functions of one variable they need are
tabulated here, once, at development time (``tools/build_luts.py`` writes them to
``data/spectral_luts.npz``, which :mod:`relativity_addon.physics.shipped_luts` reads without colour-science):

- :func:`blackbody_rgb_lut`: the gamut-mapped colour and ``ln Y`` of a blackbody against
  ``log10 T`` (from :func:`.spectral.blackbody_XYZ`);
- :func:`doppler_matrix_lut`: the RGB Doppler matrix ``M(D)`` against ``log10 D`` (from
  :func:`.spectral.doppler_rgb_matrix`).

Both are float32 RGBA image pixels in Blender ``Image.pixels`` order, with brightness stored as a
logarithm because it spans more than float32 holds. :func:`sample_blackbody_rgb_lut` and
:func:`sample_doppler_matrix_lut` read them as the shader does (linear interpolation, clamped at
the ends) and are the reference the tests compare with the exact functions. Layouts and accuracy:
``docs/spectral-model.md``. Colour conventions: :mod:`.spectral`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from .arrays import ArrayLike, Float32Array, FloatArray
from .spectral import (
    XYZ_to_linear_rec709,
    _log_blackbody_luminance,
    _validated_finite,
    _validated_positive,
    blackbody_XYZ,
    doppler_rgb_matrix,
    gamut_map_linear_rec709,
    luminance_linear_rec709,
)

__all__ = [
    "BLACKBODY_LUT_LOG10_T_RANGE",
    "DOPPLER_LUT_LOG10_D_RANGE",
    "blackbody_lut_log10_t_grid",
    "blackbody_rgb_lut",
    "sample_blackbody_rgb_lut",
    "doppler_lut_log10_d_grid",
    "doppler_matrix_lut",
    "sample_doppler_matrix_lut",
]

BLACKBODY_LUT_LOG10_T_RANGE = (2.0, 6.0)
"""Default log10 temperature range (K) of the blackbody table: 100 K to 1e6 K, which covers ``D T``
for ``D`` in [0.01, 100] for emitters of 1e4 K, and D in [0.1, 20] for 1000-50000 K."""

DOPPLER_LUT_LOG10_D_RANGE = (-2.0, 2.0)
"""Default log10 Doppler factor range of the matrix table: D from 0.01 to 100."""


# --- Blackbody --------------------------------------------------------------------------------


def blackbody_lut_log10_t_grid(
    size: int = 2048, log10_t_range: tuple[float, float] = BLACKBODY_LUT_LOG10_T_RANGE
) -> FloatArray:
    """Evenly spaced ``log10 T`` grid (K) for :func:`blackbody_rgb_lut`."""

    return np.linspace(log10_t_range[0], log10_t_range[1], int(size))


def blackbody_rgb_lut(log10_t_grid: ArrayLike | None = None) -> Float32Array:
    """Blackbody colour table for the shader, float32, flat, ``4 * N`` values.

    Layout: an ``N x 1`` RGBA float image (Blender ``Image.pixels`` order), pixel ``j`` for
    ``T_j = 10 ** log10_t_grid[j]``:

        pixels[4 j + 0:3] = gamut-mapped linear Rec.709 RGB of the blackbody at T_j / Y(T_j)
        pixels[4 j + 3]   = ln Y(T_j), Y in W sr^-1 m^-2 (CMF-weighted, see blackbody_XYZ)

    The RGB has unit luminance and ``ln Y`` carries the brightness, because ``Y`` spans ~1e-75
    (100 K) to ~1e10 (1e6 K), which no single float32 scale holds. Absolute RGB is
    ``rgb * exp(a)``; the searchlight ratio of an emitter at ``T`` seen at ``D`` is
    ``exp(a(D T) - a(T))``. Interpolate all four channels linearly in ``log10 T`` (see
    :func:`sample_blackbody_rgb_lut`).
    """

    if log10_t_grid is None:
        log10_t_grid = blackbody_lut_log10_t_grid()
    log10_t_grid = _validated_finite(log10_t_grid, "log10_t_grid")
    temperature_K = 10.0**log10_t_grid
    log_luminance = _log_blackbody_luminance(temperature_K)
    # Rescale before converting: the unit-luminance colour is scale-free and never underflows.
    XYZ = blackbody_XYZ(temperature_K)
    with np.errstate(divide="ignore", invalid="ignore"):
        chromatic = XYZ / XYZ[..., 1:2]
    underflowed = ~np.isfinite(chromatic).all(axis=-1)
    if np.any(underflowed):
        raise ValueError(
            "blackbody_rgb_lut: the visible radiance underflows at "
            f"T = {temperature_K[underflowed].min():.4g} K; start the grid at a higher T"
        )
    rgb = gamut_map_linear_rec709(XYZ_to_linear_rec709(chromatic))
    table = np.concatenate([rgb, log_luminance[..., None]], axis=-1)
    return table.astype(np.float32).ravel()


def sample_blackbody_rgb_lut(lut: ArrayLike, log10_t_grid: FloatArray, temperature_K: ArrayLike) -> FloatArray:
    """Absolute gamut-mapped RGB at ``temperature_K`` read from :func:`blackbody_rgb_lut`.

    Reference for the shader: linear interpolation in ``log10 T``, clamped at the ends (an image
    texture with *Linear* interpolation and *Extend* extension sampled at pixel centres).
    """

    temperature_K = _validated_positive(temperature_K, "temperature_K")
    table = np.asarray(lut, dtype=np.float64).reshape(-1, 4)
    x = np.log10(temperature_K)
    channels = [np.interp(x, log10_t_grid, table[:, c]) for c in range(4)]
    rgb = np.stack(channels[:3], axis=-1)
    return rgb * np.exp(channels[3])[..., None]


# --- Doppler matrix ----------------------------------------------------------------------------


def doppler_lut_log10_d_grid(
    size: int = 2048, log10_d_range: tuple[float, float] = DOPPLER_LUT_LOG10_D_RANGE
) -> FloatArray:
    """Evenly spaced ``log10 D`` grid for :func:`doppler_matrix_lut` (default 0.01 to 100)."""

    return np.linspace(log10_d_range[0], log10_d_range[1], int(size))


def doppler_matrix_lut(log10_d_grid: ArrayLike | None = None) -> Float32Array:
    """Doppler matrix table for the shader, float32, flat, ``12 * N`` values.

    Layout: an ``N x 3`` (width x height) RGBA float image in Blender ``Image.pixels`` order
    (rows bottom to top, RGBA per pixel). Column ``j`` is ``D_j = 10 ** log10_d_grid[j]``; row
    ``i`` is row ``i`` of the matrix, ``M(D) = N(D) exp(a(D))``:

        pixels[4 (i N + j) + k] = N(D_j)[i, k]      k = 0, 1, 2
        pixels[4 (i N + j) + 3] = a(D_j) = ln Y(M(D_j) (1, 1, 1))   (same in the three rows)

    ``exp(a)`` is the luminance of white seen at ``D`` (white at rest has ``Y = 1``), and ``N`` is
    ``M`` divided by it: the entries of ``M`` span ~1e-126 to ~1e3 over D in [0.01, 100], beyond
    float32, while ``N`` is of order 1 and ``a`` lies in about [-290, 7.3]. Interpolate all
    channels linearly in ``log10 D`` and clamp at the ends (image texture, *Linear*, *Extend*,
    ``u = (j + 0.5) / N``, ``v = (i + 0.5) / 3``); :func:`sample_doppler_matrix_lut` is the
    reference. In the shader: ``rgb_obs = gamut_map(exp(a) * N rgb)``.
    """

    if log10_d_grid is None:
        log10_d_grid = doppler_lut_log10_d_grid()
    log10_d_grid = _validated_finite(log10_d_grid, "log10_d_grid")
    matrices = doppler_rgb_matrix(10.0**log10_d_grid)
    white_luminance = luminance_linear_rec709(matrices.sum(axis=-1))
    if not np.all(white_luminance > 0):
        bad = 10.0 ** log10_d_grid[~(white_luminance > 0)]
        raise ValueError(
            f"doppler_matrix_lut: white underflows to black at D = {bad.min():.4g}; use a narrower log10_d_grid"
        )
    normalised = matrices / white_luminance[..., None, None]  # (N, 3, 3)
    log_scale = np.broadcast_to(np.log(white_luminance)[:, None, None], (len(log10_d_grid), 3, 1))
    pixels = np.concatenate([normalised, log_scale], axis=-1)  # (N, row i, 4)
    return np.ascontiguousarray(np.swapaxes(pixels, 0, 1)).astype(np.float32).ravel()


def sample_doppler_matrix_lut(lut: ArrayLike, log10_d_grid: FloatArray, doppler_factor: ArrayLike) -> FloatArray:
    """``M(D)``, shape (..., 3, 3), read from :func:`doppler_matrix_lut` as the shader does it.

    Linear interpolation in ``log10 D`` of ``N`` and of ``a = ln Y(white)``, clamped at the ends.
    """

    doppler_factor = _validated_positive(doppler_factor, "doppler_factor")
    size = len(log10_d_grid)
    pixels = np.asarray(lut, dtype=np.float64).reshape(3, size, 4)
    x = np.log10(doppler_factor)
    sampled = np.stack(
        [np.stack([np.interp(x, log10_d_grid, pixels[i, :, k]) for k in range(4)], axis=-1) for i in range(3)],
        axis=-2,
    )  # (..., 3, 4)
    return sampled[..., :3] * np.exp(sampled[..., :1, 3:4])


def spectral_mode_tables() -> dict[str, npt.NDArray[Any]]:
    """What the spectral mode (:mod:`.spectral_render`) needs at render time, where Blender has no
    colour-science: the CIE 1931 functions on the 1 nm grid, Mallett & Yuksel's basis table and its
    constrained band, the rest-frame inverse matrix of the up-sampled colours and the Rec.709 matrices."""
    from .spectral import (
        _REC709,
        WAVELENGTHS_VISIBLE_NM,
        _basis_table,
        _cmfs_visible,
        _inverse_rest_frame_matrix,
        basis_constrained_band_nm,
    )

    basis_nm, basis_values = _basis_table()
    return {
        "spectral_cmfs_nm": WAVELENGTHS_VISIBLE_NM.copy(),
        "spectral_cmfs": np.array(_cmfs_visible()),
        "spectral_basis_nm": basis_nm,
        "spectral_basis": basis_values,
        "spectral_basis_band_nm": np.array(basis_constrained_band_nm()),
        "spectral_inverse_rest_matrix": np.array(_inverse_rest_frame_matrix()),
        "spectral_xyz_to_rgb": np.array(_REC709.matrix_XYZ_to_RGB, dtype=np.float64),
    }
