"""The Blender side of a farm worker's long-lived Blender process (``blender_pool.py`` starts it).

It opens the .blend and sets the scene up once, as the batch script does for its options, then
renders one frame per request, so a frame on a farm costs what it costs in a running Blender and
not a process start, an import of ``bpy``, a file load and a camera compile. Requests are JSON
lines on stdin (``{"frame": 7}``); replies are JSON lines on the file descriptor given (stdout and
stderr stay Blender's, for its log):

- ``{"ready": true, "pid": P, "applied_at": F}`` once set up (``F``: the frame the effect was
  applied at, or null), or ``{"ready": false, "reason": ...}`` and exit 1;
- per request ``{"frame": N, "reason": null, "seconds": S, "pid": P}`` when the frame is
  written (partial name, renamed when whole: ``batch._render_frame``), or with the one-line
  ``reason`` it failed and ``"clean"``: whether the scene is as before the request (a refused
  speed or a refused Set Up). After an unclean failure the worker starts a fresh process.

The effect is applied while the process starts, at the job's first frame (``setup_frame``), so a
worker's first task does not wait for it; where it cannot be applied there (the camera at or above
c at that frame), it is applied at the first frame asked for, with the camera's speed checked at
that frame only. Later frames check their own speed first. That is what a fresh process per frame
did, and frames come out pixel for pixel the same in any order, whatever frame the effect was
applied at (``tests/blender/pipeline/test_farm_processes.py``).
"""

from __future__ import annotations

import json
import os
import select
import sys
import time
from typing import TYPE_CHECKING

from ..errors import BatchError, RelativityError

if TYPE_CHECKING:
    from collections.abc import Sequence

# An idle process ends itself after this long without a request (a coordinator that died without
# stopping it must not leave a loaded Blender behind on a long-running cluster).
IDLE_SECONDS = 600.0


def _reply(channel, **message):
    channel.write(json.dumps(message) + "\n")
    channel.flush()


def _one_line(error):
    lines = str(error).strip().splitlines()
    return f"{type(error).__name__}: {lines[-1] if lines else ''}"


class _Frames:
    """The scene once set up, rendering frames on request."""

    def __init__(self, argv):
        from .. import batch

        self.batch = batch
        self.options, _ = batch.parse(argv)
        self.scene = batch.prepare(self.options, with_blend_file=True)
        self.pattern = os.path.abspath(self.options.out)
        self.applied = False

    def _check_speed(self, scene_frame):
        """The camera's speed at this frame (what applying the effect at it would check)."""
        if self.options.reference or self.scene.relativity.velocity_source != "CAMERA_ANIMATION":
            return
        snapshot = self.batch.addon_module("scene.snapshot")
        try:
            snapshot.check_animation_speed(self.scene, scene_frame, scene_frame)
        except (RelativityError, snapshot.RelativityError) as error:
            raise BatchError(str(error)) from None

    def set_up_at(self, frame):
        """Apply the effect at output ``frame`` before any request; left for the first request to
        do (and report) when it cannot be applied there. Returns the frame, or None."""
        try:
            scene_frame = self.batch.scene_frames_of(self.scene, self.options, [frame])[0]
            self.batch.apply_effect(self.scene, self.options, scene_frame, scene_frame)
        except BatchError:
            return None
        self.applied = True
        return frame

    def notes(self):
        """The N-panel's lines after the last frame (``batch.panel_lines``); none before Set Up or
        when they cannot be read (the frame's own reason says what failed)."""
        if not self.applied or self.options.reference:
            return []
        try:
            return self.batch.panel_lines(self.scene)
        except Exception:  # noqa: BLE001 - notes are extra: never cost a frame
            return []

    def render(self, frame):
        """(reason or None, clean): render output ``frame`` to its file."""
        import bpy

        batch = self.batch
        try:
            scene_frame = batch.scene_frames_of(self.scene, self.options, [frame])[0]
            if self.applied:
                self._check_speed(scene_frame)
            else:
                batch.apply_effect(self.scene, self.options, scene_frame, scene_frame)
                self.applied = True
        except BatchError as error:
            return str(error), True
        path = batch.frame_output_path(self.pattern, frame, several=False)
        try:
            os.makedirs(os.path.dirname(path), exist_ok=True)
            batch._render_frame(
                bpy, self.scene, frame, path, not self.options.reference, self.options.spectral, scene_frame
            )
        except BatchError as error:
            return str(error), False
        except Exception as error:  # noqa: BLE001 - reported in one line, and the process is retired
            return _one_line(error), False
        return None, True


def _requests(fd):
    """Request lines read from ``fd`` (stdin) until it closes, a stop request or IDLE_SECONDS
    without one. Read from the descriptor, not through a buffered file: a line already in a
    buffer would not wake ``select``."""
    pending = b""
    while True:
        while b"\n" not in pending:
            readable, _, _ = select.select([fd], [], [], IDLE_SECONDS)
            chunk = os.read(fd, 65536) if readable else b""
            if not chunk:
                return
            pending += chunk
        line, pending = pending.split(b"\n", 1)
        request = json.loads(line)
        if request.get("stop"):
            return
        yield request


def serve(argv: Sequence[str], reply_fd: int, setup_frame: int | None = None) -> int:
    """Set up from the batch-script command line ``argv`` (``render.py FILE.blend --out=PATTERN
    ...``) with the effect applied at output frame ``setup_frame`` (None: at the first frame asked
    for), then answer frame requests until told to stop; the exit status."""
    channel = os.fdopen(reply_fd, "w", encoding="utf-8")
    try:
        frames = _Frames(argv)
        applied_at = None if setup_frame is None else frames.set_up_at(setup_frame)
    except BatchError as error:
        _reply(channel, ready=False, reason=str(error))
        return 1
    except Exception as error:  # noqa: BLE001 - a batch tool reports one line, never a traceback
        _reply(channel, ready=False, reason=_one_line(error))
        return 1
    _reply(channel, ready=True, pid=os.getpid(), applied_at=applied_at)
    for request in _requests(sys.stdin.fileno()):
        frame = int(request["frame"])
        started = time.monotonic()
        reason, clean = frames.render(frame)
        seconds = time.monotonic() - started
        _reply(channel, frame=frame, reason=reason, clean=clean, seconds=seconds, pid=os.getpid(), notes=frames.notes())
        print(
            f"render.py: frame {frame} {'done' if reason is None else 'failed: ' + reason} in {seconds:.2f} s",
            flush=True,
        )
    return 0
