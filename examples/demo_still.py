"""Render the demo still: a small scene built from scratch, with the Relativity add-on enabled.

    python examples/demo_still.py --out out/demo.png [--samples 32] [--width 320 --height 240]

Runs on the ``bpy`` wheel (Cycles on the CPU, no GPU needed). The add-on is enabled straight from
this checkout (repository root on ``sys.path``, ``addon_utils.enable("relativity_addon")``), so the
user's Blender preferences and extensions folder are neither read nor written. Exits non-zero on
failure, which Blender would not do on its own.
"""

import argparse
import sys
import time
from pathlib import Path

import bpy

EXAMPLES_DIR = Path(__file__).resolve().parent
REPO_ROOT = EXAMPLES_DIR.parent
sys.path[:0] = [str(REPO_ROOT), str(EXAMPLES_DIR)]

import addon_utils  # noqa: E402  (ships with bpy, importable once bpy is)
from scenes import build_demo_scene  # noqa: E402


def _raise(ex):
    raise ex


def enable_addon():
    """Register the add-on from this checkout; raises if its register() fails."""
    if addon_utils.enable("relativity_addon", default_set=False, handle_error=_raise) is None:
        raise RuntimeError("could not enable relativity_addon")


def configure_render(scene, out_path, width, height, samples):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = True
    scene.cycles.denoiser = "OPENIMAGEDENOISE"
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = str(out_path)


def render_demo(out_path, width=320, height=240, samples=32):
    """Reset Blender, build the demo scene, render it to ``out_path`` (PNG); return the path."""
    out_path = Path(out_path).resolve()
    out_path.parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    enable_addon()
    scene = bpy.context.scene
    build_demo_scene(scene)
    configure_render(scene, out_path, width, height, samples)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    if not out_path.is_file():
        raise RuntimeError(f"render finished but {out_path} was not written")
    return out_path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/demo.png", help="PNG file to write")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--samples", type=int, default=32)
    args = parser.parse_args(argv)

    start = time.perf_counter()
    out_path = render_demo(args.out, args.width, args.height, args.samples)
    print(f"wrote {out_path} ({time.perf_counter() - start:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
