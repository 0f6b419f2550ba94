"""Render the demo still: a small scene built from scratch, photographed by the relativistic camera.

    python examples/demo_still.py --out out/demo.png [--speed 0.9] [--doppler] [--samples 32] [--width 320 --height 240]
    python examples/demo_still.py --out out/demo.png --panels   (the README's image: the three side by side)

The camera flies toward the scene at ``--speed`` (fraction of c, along its view direction; 0
renders the photo at rest). Aberration pulls the view toward the direction of motion, so the
scene looks smaller and farther away, and the searchlight effect brightens it by D^4 (D about 4.4
straight ahead at 0.9c): the film exposure is lowered by log2(D^4) stops at the image centre, as
a photographer would, so the brightness falls off toward the edges as it really does. A 55 mm
lens replaces the 28 mm one when moving, to frame the shrunken view. Doppler colour is off unless
``--doppler`` is given: at D = 4.4 the visible band shows what surfaces reflect at 1.7-3.4 um,
which RGB says little about. The spectral model (docs/spectral-model.md) holds reflectances
flat outside 420-655 nm, so every surface takes the blue of the shifted white light and only
its brightness tells the colours apart (the red sphere, bright in the infrared, stays bright).
``--panels`` renders three stills, at rest (``--speed 0``), moving, and moving with ``--doppler``,
and writes them side by side, 4 px of white between them, as in the README (``./dev.sh demo``).

Runs on the ``bpy`` wheel (Cycles on the CPU, no GPU needed). The add-on is enabled straight from
this checkout (repository root on ``sys.path``, ``addon_utils.enable("relativity_addon")``), so the
user's Blender preferences and extensions folder are neither read nor written. Exits non-zero on
failure, which Blender would not do on its own.
"""

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

try:
    import bpy
except ImportError:
    sys.exit(
        "demo_still.py needs Blender's Python or the bpy module: run ./dev.sh demo (which sets up .venv-5.2), "
        "or blender -b --python examples/demo_still.py -- OPTIONS"
    )

EXAMPLES_DIR = Path(__file__).resolve().parent
REPO_ROOT = EXAMPLES_DIR.parent
sys.path[:0] = [str(REPO_ROOT), str(EXAMPLES_DIR)]

import addon_utils  # noqa: E402  (ships with bpy, importable once bpy is)
import numpy as np  # noqa: E402
from mathutils import Vector  # noqa: E402

from scenes import build_demo_scene  # noqa: E402


def _raise(ex):
    raise ex


def enable_addon():
    """Register the add-on from this checkout; raises if its register() fails."""
    package = sys.modules.get("relativity_addon")
    if package is not None and not hasattr(package, "__time__"):
        # Imported before (scenes.py, compat.run_main), not by addon_utils: without the load time
        # it stamps on modules it imports, enable() takes the package for changed on disk and
        # reloads its __init__ ("module changed on disk ... reloading"). Blender's addon_utils
        # stamps its own bl_pkg the same way.
        package.__time__ = os.path.getmtime(package.__file__)
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


def fly_camera(scene, camera_object, speed, lens_mm=55.0):
    """Move the camera at ``speed`` (fraction of c) along its view direction through the
    relativistic camera; compensate the searchlight brightening at the image centre.

    Aberration shrinks the view ahead (by about 1/D), so a longer lens (``lens_mm``) frames the
    objects at a useful size while the floor still shows its bend at the image edges.
    """
    from relativity_addon.blender.pipeline import effect

    camera_object.data.lens = lens_mm
    bpy.context.view_layer.update()  # matrix_world of a just-built camera is stale until then
    forward = camera_object.matrix_world.to_3x3() @ Vector((0.0, 0.0, -1.0))
    scene.relativity.beta = tuple(speed * forward.normalized())
    effect.apply(scene)
    # Doppler factor straight ahead: D = gamma (1 + beta) (docs/physics.md, observer moving).
    doppler_ahead = math.sqrt((1.0 + speed) / (1.0 - speed))
    scene.view_settings.exposure = -4.0 * math.log2(doppler_ahead)


def render_demo(out_path, width=320, height=240, samples=32, speed=0.9, doppler=False):
    """Reset Blender, build the demo scene, render it to ``out_path`` (PNG); return the path."""
    out_path = Path(out_path).resolve()
    out_path.parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    enable_addon()
    scene = bpy.context.scene
    camera_object = build_demo_scene(scene)
    configure_render(scene, out_path, width, height, samples)
    scene.relativity.use_doppler = doppler
    if speed:
        fly_camera(scene, camera_object, speed)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    if not out_path.is_file():
        raise RuntimeError(f"render finished but {out_path} was not written")
    return out_path


def _read_pixels(path):
    image = bpy.data.images.load(str(path), check_existing=False)
    width, height = image.size
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def render_panels(out_path, width=320, height=240, samples=32, speed=0.9, gap=4):
    """The README's demo image: at rest, at ``speed``, and at ``speed`` with Doppler colour, side
    by side with ``gap`` px of white between them, in ``out_path`` (PNG); return the path."""
    out_path = Path(out_path).resolve()
    with tempfile.TemporaryDirectory() as work_dir:
        runs = (("rest", 0.0, False), ("moving", speed, False), ("doppler", speed, True))
        paths = [render_demo(Path(work_dir) / f"{name}.png", width, height, samples, v, d) for name, v, d in runs]
        panels = [_read_pixels(path) for path in paths]
    sheet = np.ones((height, 3 * width + 2 * gap, 4), dtype=np.float32)
    for index, panel in enumerate(panels):
        left = index * (width + gap)
        sheet[:, left : left + width] = panel
    image = bpy.data.images.new("Demo panels", sheet.shape[1], sheet.shape[0])
    image.colorspace_settings.name = "sRGB"
    image.pixels.foreach_set(sheet.ravel())
    image.filepath_raw = str(out_path)
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)
    return out_path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/demo.png", help="PNG file to write")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--samples", type=int, default=32)
    parser.add_argument(
        "--speed", type=float, default=0.9, help="camera speed toward the scene, fraction of c (0: photo at rest)"
    )
    parser.add_argument("--doppler", action="store_true", help="also render the Doppler colour shift")
    parser.add_argument(
        "--panels",
        action="store_true",
        help="at rest, moving and moving with --doppler side by side (the README's image)",
    )
    args = parser.parse_args(argv)
    if not 0.0 <= args.speed < 1.0:
        parser.error(f"--speed must be in [0, 1), got {args.speed}")
    if args.panels and (args.doppler or not args.speed):
        parser.error(
            "--panels renders the rest, moving and --doppler stills itself: give a --speed above 0, no --doppler"
        )

    start = time.perf_counter()
    if args.panels:
        out_path = render_panels(args.out, args.width, args.height, args.samples, args.speed)
    else:
        out_path = render_demo(args.out, args.width, args.height, args.samples, args.speed, args.doppler)
    print(f"wrote {out_path} ({time.perf_counter() - start:.1f} s)")
    return 0


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
