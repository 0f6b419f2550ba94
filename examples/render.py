"""Render a .blend with the relativistic camera, from a shell.

    python examples/render.py scene.blend --beta=0,0.9,0 --out out/frame.exr
    blender -b scene.blend --python examples/render.py -- --beta=0,0.9,0 --out out/frame.png
    python examples/render.py flythrough.blend --frames 1-24 --velocity-from-animation --out out/fly.png

Options: --beta=X,Y,Z (world axes, fraction of c), --velocity-from-animation (the active camera's
keyframed motion; refused with the frame number if it reaches c), --method camera|geometry,
--samples N, --resolution WxH, --out PATH (.png, or .exr for linear float), --no-doppler,
--no-searchlight, --shutter MODEL, --shutter-time S, --shutter-plane-point X,Y,Z,
--shutter-plane-normal X,Y,Z (camera-local axes), --lens ideal|phase-hologram, --lorentz-window,
--window-time T_W (the window in the plane of fixed points for T_W, the shutter model timing the
rays), --time-of-flight (light delay only, Gray Fig. 1c), --speed-of-light C, --frame N or
--frames A-B (several frames: the frame number goes before the extension, out/fly_0001.png, or
replaces a run of '#' in PATH), --seed N, --reference (render the file's own camera unchanged),
--proper-time (frame K at the traveller's time K / fps), --threads N, --resume (skip frames whose
output is already a complete image). Prints one progress line per frame with the time left.
Exits non-zero with a one-line reason on any failure; an option wrong without looking at the scene
is refused before Blender loads.

On a Dask cluster (docs/farm.md): --workers N (a local cluster of N worker processes) or
--scheduler tcp://HOST:8786, with --chunk N (frames per task) and --retries N; each worker renders
its tasks in one long-lived Blender process (restarted if it dies), --resume is on, and the exit
status is 1 if any frame failed:

    python examples/render.py flythrough.blend --frames 1-240 --out out/f.png --workers 4
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from relativity_addon import batch  # noqa: E402

if __name__ == "__main__":
    batch.command_line()
