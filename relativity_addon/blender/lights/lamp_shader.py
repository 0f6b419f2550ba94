"""The stand-in lamps' light shader (``shaders/relativistic_moving_lamp.osl``) as the text
datablock its script nodes compile: the shipped spectral tables written into it as OSL macros (OSL
has no global arrays, and Blender has no colour-science)."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import bpy
import numpy as np

from ...errors import RelativityError
from ...physics import spectral_render
from ..common import names

if TYPE_CHECKING:
    from bpy.types import Text

SHADER_PATH = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "shaders", names.MOVING_LAMP_SHADER_TEXT)


def _cmf_defines():
    """The colour matching functions every 10 nm (360-830 nm) and XYZ -> linear Rec.709, as OSL
    macros (OSL has no global arrays): the shipped tables of the spectral mode."""
    tables = spectral_render.tables()
    rows = tables["cmfs_nm"] % 10.0 == 0.0
    cmfs = tables["cmfs"][rows]

    def array(values):
        return ", ".join(f"{float(v):.7g}" for v in values)

    declare = " ".join(
        f"float CMF_{axis}[{len(cmfs)}] = {{{array(cmfs[:, index])}}};" for index, axis in enumerate("XYZ")
    )
    declare += f" float XYZ_TO_RGB[9] = {{{array(np.asarray(tables['xyz_to_rgb']).ravel())}}};"
    return f"#define CMF_COUNT {len(cmfs)}\n#define CMF_DECLARE {declare}\n"


def basis_defines() -> str:
    """Mallett & Yuksel's basis on its 5 nm grid over its constrained band (outside it the basis
    is held at the band's edge values, ``physics.spectral_render.reflectance_matrix``) and the white's
    temperature, as OSL macros: the table the shader interpolates linearly."""
    tables = spectral_render.tables()
    low, high = (float(v) for v in tables["basis_band_nm"])
    rows = (tables["basis_nm"] >= low) & (tables["basis_nm"] <= high)
    grid, basis = tables["basis_nm"][rows], tables["basis"][rows]
    step = float(grid[1] - grid[0])
    if not (grid[0] == low and grid[-1] == high and np.allclose(np.diff(grid), step)):
        raise RelativityError("The shipped RGB basis table is not on an even grid over its band")
    values = ", ".join(f"{float(v):.9g}" for v in basis.ravel())
    return (
        f"#define BASIS_COUNT {len(grid)}\n#define BASIS_LOW {low!r}\n#define BASIS_STEP {step!r}\n"
        f"#define WHITE_TEMPERATURE {spectral_render.WHITE_TEMPERATURE_K!r}\n"
        f"#define BASIS_DECLARE float BASIS[{basis.size}] = {{{values}}};\n"
    )


def shader_text() -> Text:
    """The stand-in lamps' light shader (a text datablock), with the tables written in."""
    with open(SHADER_PATH, encoding="utf-8") as handle:
        source = handle.read().replace("/* @CMF_TABLES@ */", _cmf_defines())
        source = source.replace("/* @BASIS_TABLE@ */", basis_defines())
    text = bpy.data.texts.get(names.MOVING_LAMP_SHADER_TEXT) or bpy.data.texts.new(names.MOVING_LAMP_SHADER_TEXT)
    if text.as_string().rstrip("\n") != source.rstrip("\n"):
        text.clear()
        text.write(source)
    return text
