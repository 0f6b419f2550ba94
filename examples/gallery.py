"""The papers' figures in one command: build each scene from code, render it through the add-on.

    python examples/gallery.py [--only NAME[,NAME...]] [--size 320x240] [--samples 32] [--out docs/gallery]

Writes ``OUT/NAME.png`` for every figure of Weiskopf et al. (1999) and Gray et al. (2020) that
the add-on can render (``--list`` names them; ``--list-file PATH`` writes the names to PATH, one a
line, away from the log lines Blender prints), ``OUT/contact_sheet.png``, the numbers measured on
the renders (``OUT/measurements.json``, also printed) and, when every figure was rendered into
docs/gallery, ``docs/gallery.md``. The measurements are made on the linear (EXR) render, the PNG
is its Standard view transform at the family's exposure; expected values come from
docs/physics.md and docs/spectral-model.md written out here (and colour-science when present).

Runs on the ``bpy`` wheel (Cycles on the CPU); the add-on is enabled from this checkout.
"""

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

try:
    import bpy
except ImportError:
    sys.exit(
        "gallery.py needs Blender's Python or the bpy module: run ./dev.sh demo (which sets up .venv-5.2), "
        "or blender -b --python examples/gallery.py -- OPTIONS"
    )
import numpy as np

EXAMPLES_DIR = Path(__file__).resolve().parent
REPO_ROOT = EXAMPLES_DIR.parent
sys.path[:0] = [str(REPO_ROOT), str(EXAMPLES_DIR)]

import gallery_doc  # noqa: E402
import gallery_scenes as gs  # noqa: E402
from demo_still import enable_addon  # noqa: E402

# name: (builder, arguments, view exposure in stops)
FIGURES = {
    "weiskopf_fig4_street_rest": (gs.street, ("REST",), 0.0),
    "weiskopf_fig5_street_geometry": (gs.street, ("GEOMETRY",), 0.0),
    "weiskopf_fig6_street_chang": (gs.street, ("CHANG",), 0.0),
    "weiskopf_fig7_street_searchlight": (gs.street, ("SEARCHLIGHT",), 0.0),
    "weiskopf_sun_rest": (gs.suns, ("REST",), -0.5),
    "weiskopf_fig8_sun_doppler": (gs.suns, ("DOPPLER",), -0.5),
    "weiskopf_fig9_sun_doppler_searchlight": (gs.suns, ("SEARCHLIGHT",), -0.5),
    "gray_fig1a_rest": (gs.tiles, ("PINHOLE", False), 0.0),
    "gray_fig1b_pinhole": (gs.tiles, ("PINHOLE", True), 0.0),
    "gray_fig1c_time_of_flight": (gs.tiles, ("PINHOLE", True, True), 0.0),
    "gray_fig1c_time_of_flight_enlarged": (gs.tiles, ("PINHOLE", True, True, 3000.0), 0.0),
    "gray_fig1_wide_aperture": (gs.tiles, ("APERTURE_PLANE", True), 0.0),
    "gray_fig3b_aperture_plane": (gs.sphere_array, ("APERTURE_PLANE", 0.05), 1.0),
    "gray_fig4_aperture_plane_huge": (gs.sphere_array, ("APERTURE_PLANE", 0.2), 1.0),
    "gray_fig5_detector_plane": (gs.sphere_array, ("DETECTOR_PLANE", 0.2), 1.0),
    "gray_fig6b_phase_hologram": (gs.sphere_array, ("DETECTOR_PLANE", 0.2, "PHASE_HOLOGRAM"), 1.0),
    "gray_fig7_focus_surface": (gs.sphere_array, ("FOCUS_SURFACE", 0.05), 1.0),
    "gray_fig8a_rest": (gs.cylinders, (False,), 0.0),
    "gray_fig8b_fixed_point_surface": (gs.cylinders, (True,), 0.0),
    "gray_fig9a_rest": (gs.portrait, ("REST",), 0.0),
    "gray_fig9b_moving": (gs.portrait, ("MOVING",), 0.0),
    "gray_fig9c_lorentz_window": (gs.portrait, ("WINDOW",), 0.0),
    "gray_fig10_window_detector_plane": (gs.portrait, ("WINDOW_DETECTOR",), 0.0),
    "gray_fig11a_stereo_rest": (gs.stereo_portrait, ("REST",), 0.0),
    "gray_fig11b_stereo_moving": (gs.stereo_portrait, ("MOVING",), 0.0),
    "gray_fig11c_stereo_lorentz_window": (gs.stereo_portrait, ("WINDOW",), 0.0),
    "cockpit_street_flythrough": (gs.street_cockpit, (), -3.0),
}


def new_scene(width, height, samples):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    enable_addon()
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.seed = 1
    # Cycles clamps indirect samples at 10 by default: the searchlight's D^4 (81 ahead at 0.8c),
    # applied to the camera ray's throughput, would have its indirect light cut (measured: 4.5 %
    # low in the street's centre); no clamping keeps the physics
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.use_file_extension = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    return scene


def read_image(path):
    """Linear float RGB [row (top first), column, channel] of an image file."""
    image = bpy.data.images.load(str(path), check_existing=False)
    width, height = image.size
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)[::-1, :, :3].astype(np.float64)


def render_figure(name, out_dir, work_dir, width, height, samples):
    """Build, render (EXR, linear) and save the PNG; return (linear image, context)."""
    from relativity_addon.blender.pipeline import effect

    builder, arguments, exposure = FIGURES[name]
    scene = new_scene(width, height, samples)
    context = builder(scene, *arguments)
    scene.view_settings.exposure = exposure
    effect.apply(scene)
    exr = Path(work_dir) / f"{name}.exr"
    settings = scene.render.image_settings
    settings.file_format, settings.color_depth = "OPEN_EXR", "32"
    if context.get("stereo"):  # Blender's anaglyph of the two views, one EXR (loads on 4.5 and 5.2)
        settings.views_format = "STEREO_3D"
        settings.stereo_3d_format.display_mode = "ANAGLYPH"
    scene.render.filepath = str(exr)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    linear = read_image(exr)
    settings.file_format, settings.color_mode, settings.color_depth = "PNG", "RGB", "8"
    settings.views_format = "INDIVIDUAL"  # the anaglyph is one image now
    image = bpy.data.images.load(str(exr))
    png = Path(out_dir) / f"{name}.png"
    image.save_render(str(png), scene=scene)
    bpy.data.images.remove(image)
    context.update(size=(width, height), window=view_window(scene, context["camera"]))
    context.pop("camera")
    context.pop("stereo", None)
    return linear, context


def view_window(scene, camera):
    bpy.context.view_layer.update()
    corners = camera.data.view_frame(scene=scene)
    xs = [c.x / -c.z for c in corners]
    ys = [c.y / -c.z for c in corners]
    return min(xs), max(xs), min(ys), max(ys)


def _label(text, width, height, size=11):
    """``text`` in white on black, drawn with Blender's own font: float RGBA [row (bottom first),
    column, channel], ``width`` x ``height``; the font shrinks until the text fits."""
    import blf
    import imbuf

    font = 0  # Blender's default font, loaded in background mode too
    buffer = imbuf.new((width, height))
    with blf.bind_imbuf(font, buffer):
        blf.size(font, size)
        while size > 6 and blf.dimensions(font, text)[0] > width - 4:
            size -= 1
            blf.size(font, size)
        blf.color(font, 1.0, 1.0, 1.0, 1.0)
        blf.position(font, 2, (height - blf.dimensions(font, "fig")[1]) // 2 + 1, 0)
        blf.draw_buffer(font, text)
    with tempfile.TemporaryDirectory() as work_dir:  # an ImBuf's pixels are read through a file
        path = Path(work_dir) / "label.png"
        imbuf.write(buffer, filepath=str(path))
        image = bpy.data.images.load(str(path), check_existing=False)
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
    coverage = pixels.reshape(height, width, 4)[..., 3:]  # the glyphs' alpha over a transparent buffer
    return np.concatenate([np.repeat(coverage, 3, axis=-1), np.ones_like(coverage)], axis=-1)


def contact_sheet(out_dir, names, columns=4, tile=(240, 180), label_height=14):
    """The PNGs side by side (row by row in ``names`` order), each with its name below it, in
    ``contact_sheet.png``."""
    rows = math.ceil(len(names) / columns)
    tw, th = tile
    cell_w, cell_h = tw + 4, th + label_height + 4
    sheet = np.zeros((rows * cell_h, columns * cell_w, 4), dtype=np.float32)
    sheet[..., 3] = 1.0
    for index, name in enumerate(names):
        image = bpy.data.images.load(str(Path(out_dir) / f"{name}.png"), check_existing=False)
        image.scale(tw, th)
        pixels = np.empty(tw * th * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
        r, c = divmod(index, columns)
        bottom = (rows - 1 - r) * cell_h + 2  # Blender's pixel rows run bottom up
        left = c * cell_w + 2
        sheet[bottom : bottom + label_height, left : left + tw] = _label(name, tw, label_height)
        sheet[bottom + label_height : bottom + label_height + th, left : left + tw] = pixels.reshape(th, tw, 4)
    image = bpy.data.images.new("Contact sheet", sheet.shape[1], sheet.shape[0])
    image.colorspace_settings.name = "sRGB"
    image.pixels.foreach_set(sheet.ravel())
    image.filepath_raw = str(Path(out_dir) / "contact_sheet.png")
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def _size(text):
    width, height = (int(part) for part in text.lower().split("x"))
    return width, height


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="comma-separated figure names (or unique parts of them)")
    parser.add_argument("--size", type=_size, default=(320, 240), help="WIDTHxHEIGHT")
    parser.add_argument("--samples", type=int, default=32)
    parser.add_argument("--out", default=str(REPO_ROOT / "docs" / "gallery"))
    parser.add_argument("--list", action="store_true", help="print the figure names and exit")
    parser.add_argument(
        "--list-file", help="write the figure names to this file, one a line, and exit (for scripts: no log lines)"
    )
    args = parser.parse_args(argv)
    if args.list_file:
        Path(args.list_file).write_text("".join(f"{name}\n" for name in FIGURES))
        return 0
    if args.list:
        print("\n".join(FIGURES))
        return 0
    names = list(FIGURES)
    if args.only:
        wanted = [part.strip() for part in args.only.split(",") if part.strip()]
        names = [n for n in FIGURES if any(w == n or w in n for w in wanted)]
        if not names:
            parser.error(f"no figure matches {args.only!r} (see --list)")
    out_dir = Path(args.out).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    images, contexts = {}, {}
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as work_dir:
        for index, name in enumerate(names):
            t0 = time.perf_counter()
            images[name], contexts[name] = render_figure(name, out_dir, work_dir, *args.size, args.samples)
            print(f"[{index + 1}/{len(names)}] {name}: {time.perf_counter() - t0:.1f} s", flush=True)
    import gallery_measure

    numbers = gallery_measure.measure_all(images, contexts)
    for name, values in numbers.items():
        print(f"{name}: " + "; ".join(f"{key} = {value:.4g}" for key, value in values.items()))
    (out_dir / "measurements.json").write_text(
        json.dumps({"size": list(args.size), "samples": args.samples, "numbers": numbers}, indent=1) + "\n"
    )
    contact_sheet(out_dir, names)
    docs_gallery = REPO_ROOT / "docs" / "gallery"
    if names == list(FIGURES) and out_dir == docs_gallery.resolve():
        gallery_doc.write(REPO_ROOT / "docs" / "gallery.md", numbers, args.size, args.samples)
        print("wrote docs/gallery.md")
    print(f"wrote {len(names)} figures and the contact sheet to {out_dir} ({time.perf_counter() - start:.0f} s)")
    return 0


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
