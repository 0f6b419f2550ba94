"""``render.py --bake-to BAKED.blend``: set the file up, bake the frames for rendering anywhere, save.

The bake (``blender/pipeline/bake.py``, through ``effect.bake_for_render_anywhere``) writes what the
add-on's handlers compute per frame into keyframes, image sequences and (Apparent Geometry) meshes
played back by frame, so that plain Blender renders the saved file's frames with no add-on and
scripts disabled (``blender -b BAKED.blend -a``).
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any

from ..errors import BatchError

NOT_WITH = ("spectral", "stereo", "reference", "proper_time", "workers", "scheduler", "resume")


def check_options(options: argparse.Namespace, parser: argparse.ArgumentParser) -> None:
    """``--out`` or ``--bake-to``; no option that renders with ``--bake-to`` (one line through
    ``parser.error``)."""
    if options.bake_to is None:
        if options.out is None:
            parser.error("the following arguments are required: --out (or --bake-to)")
        return
    conflicts = [name for name in NOT_WITH if getattr(options, name)]
    if conflicts:
        parser.error(f"--bake-to renders nothing: not with --{conflicts[0].replace('_', '-')}")
    if not options.bake_to.endswith(".blend"):
        parser.error(f"--bake-to must name a .blend file, got {options.bake_to!r}")


def frames(scene: Any, options: argparse.Namespace) -> list[int]:
    """The frames to bake: ``--frame``/``--frames``, else the scene's range; none without ``--bake-to``."""
    if options.bake_to is None:
        return []
    if options.frames is not None:
        return list(range(options.frames[0], options.frames[1] + 1))
    if options.frame is not None:
        return [options.frame]
    return list(range(scene.frame_start, scene.frame_end + 1))


def bake(
    bpy: Any, scene: Any, effect: ModuleType, path: str, frame_numbers: Sequence[float], log: Callable[..., object]
) -> str:
    """Bake ``frame_numbers`` of the set-up scene and save it at ``path`` (saved first too: the bake writes
    its image sequences beside the file). Returns the absolute path; BatchError (one line)."""
    path = os.path.abspath(path)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=path, check_existing=False)
    first, last = int(frame_numbers[0]), int(frame_numbers[-1])
    try:
        counts = effect.bake_for_render_anywhere(scene, first, last)
    except effect.RelativityError as error:
        raise BatchError(str(error)) from None
    bpy.ops.wm.save_as_mainfile(filepath=path, check_existing=False)
    log(
        f"render.py: baked frames {first}-{last} ({counts['fcurves']} animated values, {counts['sequences']} "
        f"image sequences, {counts.get('meshes', 0)} meshes played back by frame) into {path}: it renders "
        f"without the add-on (blender -b {path} -a)",
        flush=True,
    )
    return path
