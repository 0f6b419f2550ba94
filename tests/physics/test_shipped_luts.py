"""The lookup tables shipped for Blender (which has no colour-science) equal a fresh computation
with colour-science, and reading them needs neither colour-science nor bpy."""

import subprocess
import sys
from pathlib import Path

import numpy as np

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


def test_reading_the_tables_needs_no_colour_science():
    script = (
        "import sys; sys.modules['colour'] = None; sys.modules['bpy'] = None\n"
        "from relativity_addon import lut_data\n"
        "grid, pixels = lut_data.doppler_matrix_lut()\n"
        "assert pixels.dtype.name == 'float32' and pixels.size == grid.size * 3 * 4\n"
        "grid, pixels = lut_data.blackbody_rgb_lut()\n"
        "assert pixels.size == grid.size * 4\n"
    )
    subprocess.run([sys.executable, "-c", script], cwd=ROOT, check=True)
