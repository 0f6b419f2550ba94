"""Render a .blend with the relativistic camera, from a shell.

    python examples/render.py scene.blend --beta=0,0.9,0 --out out/frame.exr
    blender -b scene.blend --python examples/render.py -- --beta=0,0.9,0 --out out/frame.png

Options: --beta=X,Y,Z (world axes, fraction of c), --method camera|geometry, --samples N,
--resolution WxH, --out PATH (.png, or .exr for linear float), --no-doppler, --no-searchlight,
--shutter MODEL, --shutter-time S, --lorentz-window, --frame N, --seed N, --reference (render the
file's own camera unchanged). Exits non-zero with a one-line reason on any failure.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from relativity_addon import batch  # noqa: E402

if __name__ == "__main__":
    sys.exit(batch.main())
