"""The lookup tables shipped for Blender (which has no colour-science) equal a fresh computation
with colour-science, and reading them needs neither colour-science nor bpy."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))

import build_luts  # noqa: E402


def test_shipped_tables_equal_a_fresh_computation():
    assert build_luts.stale_tables() == []


def test_a_changed_table_is_detected(tmp_path):
    fresh = build_luts.compute_tables()
    fresh["doppler_matrix_lut"] = fresh["doppler_matrix_lut"] * np.float32(1.001)
    np.savez_compressed(tmp_path / "luts.npz", **fresh)
    assert build_luts.stale_tables(tmp_path / "luts.npz") == ["doppler_matrix_lut"]


@pytest.fixture(scope="module")
def fresh_tables():
    return build_luts.compute_tables()


def _stale_after(tmp_path, tables, name, change):
    changed = dict(tables)
    changed[name] = change(tables[name].copy())
    np.savez_compressed(tmp_path / "luts.npz", **changed)
    return build_luts.stale_tables(tmp_path / "luts.npz")


def test_the_rounding_residual_of_gamut_mapped_zeros_is_tolerated(tmp_path, fresh_tables):
    """numpy 1.26 and 2.x differ by 0 vs 1.1e-16 in components the gamut mapping drives to zero."""

    def residual(table):
        table[np.abs(table) < 1e-15] += np.float32(2.0**-53)
        return table

    assert _stale_after(tmp_path, fresh_tables, "blackbody_rgb_lut", residual) == []


@pytest.mark.parametrize("change", ["one colour by 2e-6", "one zero to 1e-11", "one ln Y by 1e-4"])
def test_a_small_change_to_the_blackbody_table_is_detected(tmp_path, fresh_tables, change):
    rgba = fresh_tables["blackbody_rgb_lut"].reshape(-1, 4)
    red = int(np.argmax(rgba[:, 0] > 0.5)) * 4  # a red component near 1
    zero = int(np.flatnonzero(fresh_tables["blackbody_rgb_lut"] == 0.0)[0])
    log_luminance = 4 * (len(rgba) // 2) + 3

    def modify(table):
        if change == "one colour by 2e-6":
            table[red] *= np.float32(1.0 + 2e-6)
        elif change == "one zero to 1e-11":
            table[zero] = np.float32(1e-11)
        else:
            table[log_luminance] += np.float32(1e-4)
        return table

    assert _stale_after(tmp_path, fresh_tables, "blackbody_rgb_lut", modify) == ["blackbody_rgb_lut"]


def test_reading_the_tables_needs_no_colour_science():
    script = (
        "import sys; sys.modules['colour'] = None; sys.modules['bpy'] = None\n"
        "from relativity_addon.physics import shipped_luts as lut_data\n"
        "grid, pixels = lut_data.doppler_matrix_lut()\n"
        "assert pixels.dtype.name == 'float32' and pixels.size == grid.size * 3 * 4\n"
        "grid, pixels = lut_data.blackbody_rgb_lut()\n"
        "assert pixels.size == grid.size * 4\n"
    )
    subprocess.run([sys.executable, "-c", script], cwd=ROOT, check=True)
