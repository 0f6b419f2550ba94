"""Lookup-table images for the Doppler colour shaders, packed into the .blend.

The tables come from ``physics/spectral.py`` (colour-science, numpy); their layouts are described
in ``docs/spectral-model.md``. They are stored as packed 32-bit float images with the
``Non-Color`` colour space, so a render (F12, a render-farm worker, the batch script) reads them
from the file alone: neither colour-science nor the add-on is needed to render.
"""

import bpy
import numpy as np

DOPPLER_LUT_NAME = "Relativity Doppler Matrix LUT"
BLACKBODY_LUT_NAME = "Relativity Blackbody LUT"
LUT_SIZE = 2048
# ID property on a LUT image: the layout version, so an outdated table is rebuilt.
LAYOUT_KEY = "relativity_lut_layout"
LAYOUT_VERSION = 1

# Grid ranges as the shaders need them: u = (log10 x - low) / (high - low) * (N - 1)/N + 0.5/N.
DOPPLER_LOG10_RANGE = (-2.0, 2.0)
BLACKBODY_LOG10_RANGE = (2.0, 6.0)


def _packed_float_image(name, width, height, pixels):
    image = bpy.data.images.get(name)
    if image is not None and (
        tuple(image.size) != (width, height)
        or image.get(LAYOUT_KEY) != LAYOUT_VERSION
        or not image.is_float
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


def _spectral():
    try:
        from ..physics import spectral
    except ImportError as error:
        raise ImportError(
            f"colour-science is needed once to build the lookup tables ({error})"
        ) from error
    return spectral


def ensure_doppler_matrix_lut():
    """The packed ``N x 3`` Doppler matrix table (``spectral.doppler_matrix_lut``)."""

    image = bpy.data.images.get(DOPPLER_LUT_NAME)
    if image is not None and image.get(LAYOUT_KEY) == LAYOUT_VERSION:
        return image
    spectral = _spectral()
    grid = spectral.doppler_lut_log10_d_grid(LUT_SIZE, DOPPLER_LOG10_RANGE)
    return _packed_float_image(DOPPLER_LUT_NAME, LUT_SIZE, 3, spectral.doppler_matrix_lut(grid))


def ensure_blackbody_lut():
    """The packed ``N x 1`` blackbody table (``spectral.blackbody_rgb_lut``)."""

    image = bpy.data.images.get(BLACKBODY_LUT_NAME)
    if image is not None and image.get(LAYOUT_KEY) == LAYOUT_VERSION:
        return image
    spectral = _spectral()
    grid = spectral.blackbody_lut_log10_t_grid(LUT_SIZE, BLACKBODY_LOG10_RANGE)
    return _packed_float_image(BLACKBODY_LUT_NAME, LUT_SIZE, 1, spectral.blackbody_rgb_lut(grid))


def texture_u_scale_offset(log10_range, size=LUT_SIZE):
    """``(scale, offset)`` with ``u = scale * log10(x) + offset`` at pixel centres of the grid."""
    low, high = log10_range
    scale = (size - 1) / size / (high - low)
    return scale, 0.5 / size - low * scale
