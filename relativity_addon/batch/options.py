"""The batch script's command line (``examples/render.py``): the parser, how the arguments are
found in either invocation form (the ``bpy`` wheel, or inside Blender after ``--``), and every check
of the options that needs no scene (:func:`check_before_loading`), run before ``import bpy`` so a typo
costs no Blender load."""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import struct

from ..errors import BatchError
from ..physics.shutter import ShutterModel
from .frame_files import output_problem


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise BatchError(f"bad option: {message}")


def _vector3(text):
    parts = text.split(",")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z, got {text!r}")
    try:
        return tuple(float(part) for part in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three numbers X,Y,Z, got {text!r}") from None


def _resolution(text):
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from None
    if width < 1 or height < 1:
        raise argparse.ArgumentTypeError(f"resolution must be positive, got {text!r}")
    return width, height


def _positive_int(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def _frame_range(text):
    import re

    match = re.fullmatch(r"\s*(-?\d+)\s*-\s*(-?\d+)\s*", text)
    if not match:
        raise argparse.ArgumentTypeError(f"expected FIRST-LAST, got {text!r}")
    first, last = int(match.group(1)), int(match.group(2))
    if last < first:
        raise argparse.ArgumentTypeError(f"last frame before first in {text!r}")
    return first, last


SHUTTER_CHOICES = tuple(model.name.lower() for model in ShutterModel)
LENS_CHOICES = {"ideal": "IDEAL_LENS", "phase-hologram": "PHASE_HOLOGRAM"}
STEREO_CHOICES = ("anaglyph", "side-by-side", "views")


def build_parser(with_blend_file: bool) -> argparse.ArgumentParser:
    parser = _Parser(
        prog="render.py",
        description="Render a .blend with the relativistic camera (Cycles, CPU).",
    )
    if with_blend_file:
        parser.add_argument("blend_file", help=".blend file to render")
    parser.add_argument(
        "--beta",
        type=_vector3,
        help="observer velocity X,Y,Z (world axes, fraction of c); write --beta=-0.5,0,0 when a value starts with '-'",
    )
    parser.add_argument(
        "--method",
        choices=("camera", "geometry"),
        help="render method (default: the file's setting, Exact Camera in a new file)",
    )
    parser.add_argument(
        "--reference", action="store_true", help="render the file's own camera unchanged (no relativistic camera)"
    )
    parser.add_argument("--samples", type=_positive_int)
    parser.add_argument("--resolution", type=_resolution, help="WIDTHxHEIGHT in pixels")
    parser.add_argument("--out", help="output image: .png, or .exr for linear float (required unless --bake-to)")
    parser.add_argument(
        "--bake-to",
        metavar="BAKED.blend",
        help="render nothing: set up, bake --frames (default: the scene's range) and save as BAKED.blend, "
        "which plain Blender renders without the add-on (blender -b BAKED.blend -a); exact camera only",
    )
    parser.add_argument("--no-doppler", action="store_true")
    parser.add_argument("--no-searchlight", action="store_true")
    parser.add_argument("--no-geometry", action="store_true", help="no aberration (testing aid)")
    parser.add_argument("--lorentz-window", action="store_true")
    parser.add_argument(
        "--time-of-flight",
        action="store_true",
        help="light-travel time only, Galilean (Gray et al. 2020 Fig. 1c; no searchlight or Doppler)",
    )
    parser.add_argument("--shutter", type=str.lower, choices=SHUTTER_CHOICES)
    parser.add_argument("--shutter-time", type=float, help="shutter time t_S in seconds")
    parser.add_argument(
        "--shutter-plane-point",
        type=_vector3,
        metavar="X,Y,Z",
        help="a point of the arbitrary shutter plane, camera-local axes (the camera looks down -Z)",
    )
    parser.add_argument(
        "--shutter-plane-normal",
        type=_vector3,
        metavar="X,Y,Z",
        help="the arbitrary shutter plane's normal, camera-local axes",
    )
    parser.add_argument(
        "--lens",
        choices=LENS_CHOICES,
        help="the detector-plane shutter's lens: ideal, or its phase hologram (Gray Fig. 6b)",
    )
    parser.add_argument(
        "--window-time",
        type=float,
        metavar="T_W",
        help="Lorentz window in the plane of spatial fixed points for T_W (seconds), the shutter "
        "model timing the rays (Gray Fig. 10); implies --lorentz-window",
    )
    parser.add_argument("--speed-of-light", type=float, help="scene units per second")
    frames = parser.add_mutually_exclusive_group()
    frames.add_argument("--frame", type=int, help="render this frame (default: the file's current frame)")
    frames.add_argument(
        "--frames",
        type=_frame_range,
        help="render frames A-B (inclusive); the frame "
        "number is inserted before the extension of --out, or replaces a run of '#'",
    )
    parser.add_argument(
        "--velocity-from-animation",
        action="store_true",
        help="observer velocity from the active camera's keyframed motion",
    )
    parser.add_argument("--seed", type=int)
    parser.add_argument(
        "--stereo",
        choices=STEREO_CHOICES,
        help="render Blender's stereo pair (the camera's Stereoscopy settings): one anaglyph or "
        "side-by-side image, or the two views as OUT_L and OUT_R",
    )
    parser.add_argument(
        "--spectral",
        type=_positive_int,
        metavar="PASSES",
        help="spectral colour (exact camera): PASSES renders of three wavelengths each, plus "
        "per-pixel integration; exact for lit scenes at rest (default: the fast RGB colour)",
    )
    parser.add_argument(
        "--proper-time",
        action="store_true",
        help="step frames in the traveller's proper time: frame K is rendered at the scene time "
        "where the observer's clock (0 at frame 0) reads K / fps",
    )
    parser.add_argument("--threads", type=_positive_int, help="Cycles render threads (default: all cores)")
    parser.add_argument(
        "--resume",
        action=argparse.BooleanOptionalAction,
        help="skip frames whose output exists and reads back as a complete image "
        "(default: on with --workers/--scheduler, off otherwise)",
    )
    cluster = parser.add_argument_group("distributed rendering (Dask; docs/farm.md)")
    where = cluster.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=_positive_int,
        help="render on a local Dask cluster of N worker processes, one frame task each",
    )
    where.add_argument("--scheduler", metavar="ADDRESS", help="render on a running Dask cluster, e.g. tcp://HOST:8786")
    cluster.add_argument("--chunk", type=_positive_int, default=1, help="frames per task (default 1)")
    cluster.add_argument(
        "--retries",
        type=int,
        default=2,
        help="times a task whose worker or Blender process died is run again (default 2)",
    )
    return parser


def _running_inside_blender(argv):
    return "--python" in argv or "-P" in argv or "--python-expr" in argv


def _split_argv(argv):
    if _running_inside_blender(argv):
        return (argv[argv.index("--") + 1 :] if "--" in argv else []), False
    return argv[1:], True


def check_blend_file(path: str) -> None:
    if not os.path.isfile(path):
        raise BatchError(f"no such .blend file: {path}")


def check_out_suffix(out_path: str) -> None:
    if os.path.splitext(out_path)[1].lower() not in (".png", ".exr"):
        raise BatchError(f"--out must end in .png or .exr, got {out_path!r}")


def _check_finite(values, option):
    if not all(math.isfinite(v) for v in values):
        raise BatchError(f"{option} must be finite")


def _stored_speed(beta):
    """|beta| as the scene will check it: of the components stored as Blender's 32-bit floats
    (None past the float range: the scene's own check reports that)."""
    try:
        stored = struct.unpack("3f", struct.pack("3f", *beta))
    except OverflowError:
        return None
    return math.sqrt(sum(b * b for b in stored))


def check_combinations(options: argparse.Namespace) -> None:
    """Options that contradict each other or carry numbers no scene accepts (BatchError, one line)."""
    if options.stereo and options.spectral:
        raise BatchError("--stereo and --spectral cannot be combined")
    if options.spectral and options.reference:
        raise BatchError("--spectral needs the exact camera (--method camera), not --reference")
    if options.proper_time and options.reference:
        raise BatchError("--proper-time steps a relativistic observer's clock, not with --reference")
    if options.reference:  # the file's own camera: the relativistic settings are not applied
        return
    if options.beta is not None:
        if options.velocity_from_animation:
            raise BatchError("give either --beta or --velocity-from-animation, not both")
        _check_finite(options.beta, "--beta")
        speed = _stored_speed(options.beta)
        if speed is not None and speed >= 1.0:  # in the words of blender/scene/snapshot.check_velocity
            raise BatchError(f"Observer velocity beta: speed |beta| = {speed:.6g} must be below 1 (the speed of light)")
    for name in ("shutter_plane_point", "shutter_plane_normal"):
        if getattr(options, name) is not None:
            _check_finite(getattr(options, name), f"--{name.replace('_', '-')}")
    if options.window_time is not None:
        _check_finite([options.window_time], "--window-time")


def check_before_loading(options: argparse.Namespace, inside_blender: bool) -> None:
    """Every check that needs no Blender, in the order the script meets them: the output's folder,
    the .blend file, the output's type, the options' combinations and numbers, and what a distributed
    render needs. BatchError with a one-line reason; the scene's own checks come after the load."""
    if options.out is not None:
        problem = output_problem(options.out)
        if problem is not None:
            raise BatchError(problem)
    if not inside_blender:
        check_blend_file(options.blend_file)
    if options.bake_to is None:
        check_out_suffix(options.out)
    check_combinations(options)
    if options.workers is not None or options.scheduler is not None:
        if inside_blender:
            raise BatchError(
                "--workers and --scheduler need the bpy wheel form: python examples/render.py FILE.blend ..."
            )
        if any(importlib.util.find_spec(name) is None for name in ("dask", "distributed")):
            raise BatchError("--workers and --scheduler need Dask: pip install 'dask[distributed]'")
