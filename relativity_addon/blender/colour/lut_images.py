"""Lookup-table images for the Doppler colour shaders, packed into the .blend.

The tables are computed by ``physics/spectral_luts.py`` (colour-science) once, at development time,
and shipped with the add-on (``relativity_lut_data``, built by ``tools/build_luts.py``), because
Blender bundles numpy but not colour-science; their layouts are described in
``docs/spectral-model.md``. They are stored as packed 32-bit float images with the
``Non-Color`` colour space, so a render (F12, a render-farm worker, the batch script) reads them
from the file alone: neither colour-science nor the add-on is needed to render.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy
import numpy as np

from ...physics import illuminants, shipped_luts
from ..common import names

if TYPE_CHECKING:
    from bpy.types import Image

DOPPLER_LUT_NAME = names.DOPPLER_LUT_IMAGE
BLACKBODY_LUT_NAME = names.BLACKBODY_LUT_IMAGE
ILLUMINANT_LUT_NAMES = names.ILLUMINANT_LUT_IMAGES
LUT_SIZE = 2048
# ID property on a LUT image: the layout version, so an outdated table is rebuilt.
LAYOUT_KEY = names.LUT_LAYOUT_KEY
LAYOUT_VERSION = names.LUT_LAYOUT_VERSION

# Grid ranges as the shaders need them: u = (log10 x - low) / (high - low) * (N - 1)/N + 0.5/N.
DOPPLER_LOG10_RANGE = (-2.0, 2.0)
BLACKBODY_LOG10_RANGE = (2.0, 6.0)


def _packed_float_image(name, width, height, pixels):
    image = bpy.data.images.get(name)
    if image is not None and (
        tuple(image.size) != (width, height) or image.get(LAYOUT_KEY) != LAYOUT_VERSION or not image.is_float
    ):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True, is_data=True)
        image.colorspace_settings.name = "Non-Color"
        image.alpha_mode = "CHANNEL_PACKED"  # alpha holds a log scale: never premultiply
        image.pixels.foreach_set(np.asarray(pixels, dtype=np.float32))
        image.file_format = "OPEN_EXR"
        image.pack()
        image[LAYOUT_KEY] = LAYOUT_VERSION
    # Kept in the file even while no material uses it (removing the effect, re-applying).
    image.use_fake_user = True
    return image


def _shipped_table(load, log10_range):
    try:
        grid, pixels = load()
    except OSError as error:
        raise RuntimeError(f"the add-on's spectral lookup tables cannot be read ({error})") from error
    if grid.size != LUT_SIZE or not np.allclose((grid[0], grid[-1]), log10_range):
        raise RuntimeError("the add-on's spectral lookup tables do not match this version; reinstall it")
    return pixels


def _ensure_lut(name, table, log10_range, height):
    image = bpy.data.images.get(name)
    if image is not None and image.get(LAYOUT_KEY) == LAYOUT_VERSION:
        return image
    return _packed_float_image(name, LUT_SIZE, height, _shipped_table(table, log10_range))


def ensure_doppler_matrix_lut() -> Image:
    """The packed ``N x 3`` Doppler matrix table (``spectral_luts.doppler_matrix_lut``)."""

    return _ensure_lut(DOPPLER_LUT_NAME, shipped_luts.doppler_matrix_lut, DOPPLER_LOG10_RANGE, 3)


def ensure_blackbody_lut() -> Image:
    """The packed ``N x 1`` blackbody table (``spectral_luts.blackbody_rgb_lut``)."""

    return _ensure_lut(BLACKBODY_LUT_NAME, shipped_luts.blackbody_rgb_lut, BLACKBODY_LOG10_RANGE, 1)


def ensure_illuminant_lut(name: str, temperature_k: float) -> Image:
    """The packed ``N x 3`` table ``name`` for light reflected under a blackbody at
    ``temperature_k`` (0: white), laid out as the Doppler matrix table (``physics/illuminants.py``);
    rebuilt in place (0.1-0.5 s) only when the illuminant changes, packed so that the file renders alone."""
    image = bpy.data.images.get(name)
    stamp = round(float(temperature_k), 3)
    if image is not None and image.get(names.ILLUMINANT_KEY) == stamp and image.get(LAYOUT_KEY) == LAYOUT_VERSION:
        return image
    pixels = illuminants.doppler_lut(np.linspace(*DOPPLER_LOG10_RANGE, LUT_SIZE), stamp or None)
    if image is not None and tuple(image.size) == (LUT_SIZE, 3) and image.get(LAYOUT_KEY) == LAYOUT_VERSION:
        image.pixels.foreach_set(pixels)  # in place: the compositor's Image node keeps pointing at it
        image.update()
        image.pack()
    else:
        image = _packed_float_image(name, LUT_SIZE, 3, pixels)
    image[names.ILLUMINANT_KEY] = stamp
    return image


def texture_u_scale_offset(log10_range: tuple[float, float], size: int = LUT_SIZE) -> tuple[float, float]:
    """``(scale, offset)`` with ``u = scale * log10(x) + offset`` at pixel centres of the grid."""
    low, high = log10_range
    scale = (size - 1) / size / (high - low)
    return scale, 0.5 / size - low * scale
