"""Compute the spectral lookup tables with colour-science and write the file the add-on ships.

.venv/bin/python tools/build_luts.py            # writes relativity_addon/data/spectral_luts.npz
.venv/bin/python tools/build_luts.py --check    # exits 1 if the shipped file is stale
"""

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from relativity_addon.physics import (
    shipped_luts,  # noqa: E402
    spectral_luts,  # noqa: E402
)


def compute_tables():
    d_grid = spectral_luts.doppler_lut_log10_d_grid()
    t_grid = spectral_luts.blackbody_lut_log10_t_grid()
    return {
        "doppler_log10_d_grid": d_grid,
        "doppler_matrix_lut": spectral_luts.doppler_matrix_lut(d_grid),
        "blackbody_log10_t_grid": t_grid,
        "blackbody_rgb_lut": spectral_luts.blackbody_rgb_lut(t_grid),
        **spectral_luts.spectral_mode_tables(),
    }


# How far a shipped table may be from a fresh computation and still be current. The tables are
# float32 (one ulp is 6e-8 to 1.2e-7 of a value): RTOL is about 8 ulps, so any change of the
# computation that survives the rounding to float32 is caught. ATOL is for the gamut-mapped RGB
# components that the mapping drives to zero: the float64 rounding there leaves 0 or 1.1e-16
# (2**-53, at unit luminance) depending on numpy's summation order; numpy 1.26 and numpy 2.x
# differ in 117 such components of blackbody_rgb_lut and nowhere else (measured with
# colour-science 0.4.6 and 0.4.7 alike). 1e-12 is 9000 times that residual and about 2 float32
# ulps of the smallest genuine component of any table (4.4e-6, in doppler_matrix_lut).
RTOL = 1e-6
ATOL = 1e-12


def stale_tables(path=shipped_luts.LUT_PATH, rtol=RTOL, atol=ATOL):
    """Names of the tables whose shipped values differ from a fresh computation."""
    if not os.path.exists(path):
        return ["(file missing)"]
    fresh = compute_tables()
    with np.load(path) as shipped:
        return [
            name
            for name, values in fresh.items()
            if name not in shipped.files
            or shipped[name].shape != values.shape
            or not np.allclose(shipped[name], values, rtol=rtol, atol=atol)
        ]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true", help="only check that the shipped tables are current")
    args = parser.parse_args(argv)
    if args.check:
        stale = stale_tables()
        if stale:
            print(f"stale spectral tables: {', '.join(stale)}; run tools/build_luts.py", file=sys.stderr)
            return 1
        print("spectral tables are current")
        return 0
    np.savez_compressed(shipped_luts.LUT_PATH, **compute_tables())
    print(f"wrote {shipped_luts.LUT_PATH}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
