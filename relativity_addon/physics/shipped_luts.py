"""The spectral lookup tables shipped with the add-on, read without colour-science.

Blender bundles numpy but not colour-science (nor the scipy it needs), so the tables that the
shaders sample are computed once by :mod:`relativity_addon.physics.spectral_luts` through
``tools/build_luts.py`` and shipped as ``data/spectral_luts.npz``;
``tests/physics/test_shipped_luts.py`` checks that the shipped file equals a fresh computation.
Layouts: ``docs/spectral-model.md``.
"""

import functools
import os
from typing import Any

import numpy as np
import numpy.typing as npt

Table = npt.NDArray[Any]  # as stored in the .npz (float32 image pixels, float64 grids and tables)

LUT_PATH = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data", "spectral_luts.npz")


@functools.lru_cache(maxsize=1)
def _tables() -> dict[str, Table]:
    with np.load(LUT_PATH) as data:
        return {name: data[name] for name in data.files}


def doppler_matrix_lut() -> tuple[Table, Table]:
    """``(log10_d_grid, pixels)``: the Doppler-matrix table as float32 RGBA image pixels."""
    tables = _tables()
    return tables["doppler_log10_d_grid"], tables["doppler_matrix_lut"]


def blackbody_rgb_lut() -> tuple[Table, Table]:
    """``(log10_t_grid, pixels)``: the blackbody table as float32 RGBA image pixels."""
    tables = _tables()
    return tables["blackbody_log10_t_grid"], tables["blackbody_rgb_lut"]


def spectral_mode_tables() -> dict[str, Table]:
    """The CIE functions, the RGB basis and the matrices of the spectral mode (see
    ``physics.spectral_luts.spectral_mode_tables``), by name without the ``spectral_`` prefix."""
    return {name[len("spectral_") :]: values for name, values in _tables().items() if name.startswith("spectral_")}
