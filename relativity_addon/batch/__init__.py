"""Batch rendering: the logic behind ``examples/render.py``.

Runs the same way with the ``bpy`` wheel (``python examples/render.py file.blend [options]``)
and inside Blender (``blender -b file.blend --python examples/render.py -- [options]``).
Every failure ends in ``BatchError`` with a one-line reason; ``main`` turns it into exit code 1.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import sys
from typing import TYPE_CHECKING, NoReturn

from ..errors import BatchError, RelativityError
from . import bake_to, notes
from .frame_files import format_seconds, frame_output_path, partial_path
from .options import (
    LENS_CHOICES,
    _running_inside_blender,
    _split_argv,
    build_parser,
    check_before_loading,
    check_blend_file,
    check_combinations,
    check_out_suffix,
)

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from types import ModuleType

    from bpy.types import Scene

ADDON_PACKAGE = "relativity_addon"


def enable_addon() -> None:
    """Register the add-on unless it already is (installed extension or this source tree)."""
    import bpy

    if hasattr(bpy.types.Scene, "relativity"):
        return
    import addon_utils

    for module in addon_utils.modules():
        if module.__name__.split(".")[-1] == ADDON_PACKAGE:
            addon_utils.enable(module.__name__, default_set=True)
            if hasattr(bpy.types.Scene, "relativity"):
                return
    repo_root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    if repo_root not in sys.path:
        sys.path.insert(0, repo_root)
    import importlib

    importlib.import_module(ADDON_PACKAGE).register()


def addon_module(name: str) -> ModuleType:
    """The add-on's ``blender.<name>`` module as registered in this Blender: the installed extension
    (``bl_ext....relativity_addon``) when it is enabled, which may be another copy than this file's
    package. Its handlers keep per-render state (the spectral pass), so the modules this script
    drives must be the registered ones."""
    import importlib

    import bpy

    props_module = type(bpy.context.scene.relativity).__module__
    package = props_module.rsplit(".blender.", 1)[0]
    return importlib.import_module(f"{package}.blender.{name}")


def _apply_options(scene, options):
    """``options`` onto the scene's settings; checked first by :func:`options.check_combinations`."""
    settings = scene.relativity
    if options.beta is not None:
        settings.velocity_source = "MANUAL"
        settings.beta = options.beta
    if options.velocity_from_animation:
        settings.velocity_source = "CAMERA_ANIMATION"
    if options.method is not None:
        settings.method = options.method.upper()
    if options.shutter:
        settings.shutter_model = options.shutter.upper()
    if options.shutter_time is not None:
        settings.shutter_time = options.shutter_time
    if options.speed_of_light is not None:
        settings.speed_of_light = options.speed_of_light
    if options.no_doppler:
        settings.use_doppler = False
    if options.no_searchlight:
        settings.use_searchlight = False
    if options.no_geometry:
        settings.use_geometry = False
    if options.lorentz_window:
        settings.use_lorentz_window = True
    for name in ("shutter_plane_point", "shutter_plane_normal"):
        value = getattr(options, name)
        if value is not None:
            setattr(settings, name, value)
    if options.lens is not None:
        settings.imaging_element = LENS_CHOICES[options.lens]
    if options.window_time is not None:
        settings.use_lorentz_window = True
        settings.lorentz_window_shutter = "SHUTTER_MODEL"
        settings.lorentz_window_time = options.window_time
    if options.time_of_flight:
        settings.use_time_of_flight = True


def animation_fps(scene: Scene) -> float:
    return scene.render.fps / scene.render.fps_base


def _stereo_output(scene, mode):
    """Blender's own stereoscopy (multiview, Stereo 3D), written as one image or as two views."""
    render = scene.render
    render.use_multiview = True
    render.views_format = "STEREO_3D"
    for view in render.stereo_views:
        view.use = True
    image_settings = render.image_settings
    if mode == "views":
        image_settings.views_format = "INDIVIDUAL"
        return
    image_settings.views_format = "STEREO_3D"
    image_settings.stereo_3d_format.display_mode = "ANAGLYPH" if mode == "anaglyph" else "SIDEBYSIDE"


def view_paths(path: str) -> list[str]:
    """The files Blender writes for the two views of ``path`` (``--stereo views``)."""
    stem, extension = os.path.splitext(path)
    return [f"{stem}_L{extension}", f"{stem}_R{extension}"]


def _output_format(scene, out_path):
    check_out_suffix(out_path)
    extension = os.path.splitext(out_path)[1].lower()
    image_settings = scene.render.image_settings
    if extension == ".png":
        image_settings.file_format = "PNG"
        image_settings.color_mode = "RGBA"
    else:
        image_settings.file_format = "OPEN_EXR"
        image_settings.color_depth = "32"
        image_settings.color_mode = "RGBA"
    scene.render.use_file_extension = False


def _frames(scene, options):
    if options.frames is not None:
        first, last = options.frames
        return list(range(first, last + 1))
    if options.frame is not None:
        return [options.frame]
    return [scene.frame_current]


def _render_spectral(scene, path, passes):
    spectral_render = addon_module("pipeline.spectral_render")
    try:
        pixels, _info = spectral_render.render(scene, passes)
    except spectral_render.RelativityError as error:
        raise BatchError(str(error)) from None
    spectral_render.store_image(pixels).save_render(path, scene=scene)


def _set_frame(scene, frame):
    """Go to ``frame`` (sub-frames allowed), unless the scene is there already: not for the first
    frame, which applying the effect computed: setting it again would only repeat the frame-change
    handlers (measured: 4 s of a 1M-vertex frame in the geometry path)."""
    whole = math.floor(frame)
    if (scene.frame_current, scene.frame_subframe) != (whole, frame - whole):
        scene.frame_set(whole, subframe=frame - whole)
        if addon_module("geometry.apparent_meshes").deferred():  # left by the frame change to a sync
            addon_module("pipeline.effect").sync(scene)


def _render_frame(bpy, scene, frame, path, relativistic, spectral_passes=None, scene_frame=None):
    """Render output ``frame`` (at ``scene_frame``, default the same: they differ with --proper-time)."""
    _set_frame(scene, frame if scene_frame is None else scene_frame)
    if relativistic:
        # The frame-change handler records a failed apparent-geometry update on the object
        # instead of raising; rendering then would show the previous frame's shapes.
        geometry = addon_module("geometry.apparent_meshes")
        errors = geometry.scene_errors(scene)
        if errors:
            raise BatchError(f"frame {frame}: {errors[0]}")
    views = scene.render.use_multiview and scene.render.image_settings.views_format == "INDIVIDUAL"
    targets = view_paths(path) if views else [path]
    for old in targets:
        if os.path.exists(old):
            os.remove(old)
    partial = partial_path(path)
    partials = view_paths(partial) if views else [partial]
    scene.render.filepath = partial
    try:
        try:
            if spectral_passes:
                _render_spectral(scene, partial, spectral_passes)
            else:
                bpy.ops.render.render(write_still=True)
        except RuntimeError as error:
            raise BatchError(f"render of frame {frame} failed: {str(error).strip().splitlines()[-1]}") from None
        if relativistic and scene.relativity.method == "CAMERA":
            cam = scene.camera.data
            if not cam.cycles_custom.get("settings_valid", False):
                raise BatchError(f"relativistic camera became invalid during the render of frame {frame}")
        effect = addon_module("pipeline.effect")
        if relativistic and scene.relativity.method == "GEOMETRY" and not effect.final_render_was_valid(scene):
            warnings = effect.scene_warnings(scene)
            raise BatchError(f"frame {frame}: {warnings[0] if warnings else 'the exact camera became invalid'}")
        for written, target in zip(partials, targets, strict=True):
            if not os.path.isfile(written):
                raise BatchError(f"render wrote no file at {target}")
        for written, target in zip(partials, targets, strict=True):
            os.replace(written, target)
    finally:
        for written in partials:
            if os.path.exists(written):
                os.remove(written)


def parse(argv: Sequence[str]) -> tuple[argparse.Namespace, argparse.ArgumentParser]:
    """(options, parser) for the command line ``argv`` (either invocation form)."""
    arguments, with_blend_file = _split_argv(argv)
    parser = build_parser(with_blend_file)
    options = parser.parse_args(arguments)
    bake_to.check_options(options, parser)
    return options, parser


def prepare(options: argparse.Namespace, with_blend_file: bool) -> Scene:
    """Open the file (if given), enable the add-on, set the scene up as ``options`` say; the effect
    comes later (:func:`apply_effect`). Shared by the batch script and the farm's Blender process."""
    import bpy

    check_combinations(options)  # again: the farm's Blender processes come here without check_before_loading
    if with_blend_file:
        check_blend_file(options.blend_file)
        try:
            bpy.ops.wm.open_mainfile(filepath=os.path.abspath(options.blend_file))
        except RuntimeError as error:
            raise BatchError(f"cannot open {options.blend_file}: {str(error).strip().splitlines()[-1]}") from None
    enable_addon()
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    if options.samples is not None:
        scene.cycles.samples = options.samples
    if options.seed is not None:
        scene.cycles.seed = options.seed
    if options.resolution is not None:
        scene.render.resolution_x, scene.render.resolution_y = options.resolution
        scene.render.resolution_percentage = 100
    if options.threads is not None:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = options.threads
    if options.bake_to is None:
        _output_format(scene, options.out)
    if options.stereo:
        _stereo_output(scene, options.stereo)
    if not options.reference:
        _apply_options(scene, options)
    return scene


def scene_frames_of(scene: Scene, options: argparse.Namespace, frames: Sequence[int]) -> list[float]:
    """Scene frames of output ``frames``: the same, or with --proper-time where the clock reads frame / fps."""
    if not options.proper_time:
        return list(frames)
    traveller = addon_module("scene.traveller")
    try:
        return [float(f) for f in traveller.frames_at_proper_times(scene, [f / animation_fps(scene) for f in frames])]
    except (RelativityError, traveller.RelativityError) as error:
        raise BatchError(str(error)) from None


def apply_effect(scene: Scene, options: argparse.Namespace, first: float, last: float) -> None:
    """Apply the effect at scene frame ``first`` (the camera's speed checked up to ``last``); --reference: remove it."""
    effect = addon_module("pipeline.effect")
    try:
        if options.reference:
            effect.remove(scene)
            if scene.camera is None:
                raise BatchError("scene has no active camera")
        else:
            _set_frame(scene, first)
            effect.apply(scene, frame_range=(first, last))
    except (RelativityError, effect.RelativityError) as error:
        raise BatchError(str(error)) from None


def panel_lines(scene: Scene) -> list[str]:
    """The N-panel's lines for set-up ``scene`` as of its last sync (what it leaves approximate or
    out): the scene's, then each set-up object's, named."""
    effect = addon_module("pipeline.effect")
    mesh_notes = addon_module("pipeline.mesh_notes")
    lines = list(effect.scene_warnings(scene))
    for obj in scene.objects:
        notes = mesh_notes.object_warnings(scene, obj)
        lines += [line if obj.name in line else f"{obj.name!r}: {line}" for line in notes]
    return lines


def run(argv: Sequence[str], log: Callable[..., object] = print) -> list[str]:
    import time

    import bpy

    options, _ = parse(argv)
    out_path = os.path.abspath(options.out or options.bake_to)  # bake_to.check_options: one of them
    relativistic = not options.reference
    scene = prepare(options, with_blend_file=not _running_inside_blender(argv))
    frames = bake_to.frames(scene, options) or _frames(scene, options)
    scene_frames = scene_frames_of(scene, options, frames)
    apply_effect(scene, options, scene_frames[0], scene_frames[-1])
    said: set[str] = set()
    if relativistic:
        notes.say(panel_lines(scene), said, log)
    if options.bake_to is not None:
        return [bake_to.bake(bpy, scene, addon_module("pipeline.effect"), options.bake_to, frames, log)]
    several = len(frames) > 1
    paths = [frame_output_path(out_path, frame, several) for frame in frames]
    os.makedirs(os.path.dirname(out_path), exist_ok=True)
    if options.resume:
        from . import frame_files

        complete = [path for path in paths if frame_files.is_complete(path)]
        if complete:
            log(f"render.py: --resume: {len(complete)} of {len(paths)} frames already complete, skipped", flush=True)
        keep = [path not in complete for path in paths]
        frames, scene_frames, paths = (
            [item for item, kept in zip(items, keep, strict=True) if kept] for items in (frames, scene_frames, paths)
        )
    started = time.monotonic()
    for done, (frame, scene_frame, path) in enumerate(zip(frames, scene_frames, paths, strict=True), start=1):
        frame_started = time.monotonic()
        _render_frame(bpy, scene, frame, path, relativistic, options.spectral, scene_frame)
        if relativistic:
            notes.say(panel_lines(scene), said, log)  # a frame may bring its own (a light that starts to move)
        now = time.monotonic()
        left = (now - started) / done * (len(frames) - done)
        log(
            f"render.py: frame {frame} ({done}/{len(frames)}) in {format_seconds(now - frame_started)}, "
            f"about {format_seconds(left)} left: {path}",
            flush=True,
        )
    return paths


def command_line() -> None:
    """The entry point of ``examples/render.py``. Every check that needs no scene runs before
    ``import bpy`` (a bad option costs no Blender load; ``--help`` neither); a distributed render's
    coordinator never imports bpy (its worker processes, which start by importing the main script,
    neither). Without bpy, a single-process run says so first, whatever else is wrong."""
    if _running_inside_blender(sys.argv):  # Blender is loaded already
        _run_in_blender()
        return
    try:
        options, _ = parse(sys.argv)
    except BatchError as error:
        options, bad_option = None, error
    if options is not None and (options.workers is not None or options.scheduler is not None):
        sys.exit(main())
    if importlib.util.find_spec("bpy") is None:
        _no_bpy()
    try:
        if options is None:
            raise bad_option
        check_before_loading(options, inside_blender=False)
    except BatchError as error:
        sys.exit(f"render.py: error: {error}")
    _run_in_blender()


def _no_bpy() -> NoReturn:
    sys.exit(
        "render.py: error: needs Blender's Python or the bpy module: run it with the bpy wheel's "
        "Python (./dev.sh demo sets one up in .venv-5.2), or blender -b FILE.blend --python "
        "examples/render.py -- OPTIONS"
    )


def _run_in_blender() -> None:
    try:
        import bpy  # noqa: F401
    except ImportError:
        _no_bpy()
    from ..blender.common import compat

    compat.run_main(main)


def main(argv: Sequence[str] | None = None) -> int:
    argv = sys.argv if argv is None else argv
    try:
        options, parser = parse(argv)
        check_before_loading(options, inside_blender=_running_inside_blender(argv))
        if options.workers is not None or options.scheduler is not None:
            from . import farm

            return farm.render(options, parser)
        paths = run(argv)
    except BatchError as error:
        print(f"render.py: error: {error}", file=sys.stderr)
        return 1
    except Exception as error:  # noqa: BLE001 - a batch tool reports one line, never a traceback
        message = str(error).strip().splitlines()
        print(f"render.py: error: {type(error).__name__}: {message[-1] if message else ''}", file=sys.stderr)
        return 1
    print(f"render.py: wrote {len(paths)} file{'s' if len(paths) != 1 else ''}")
    return 0
