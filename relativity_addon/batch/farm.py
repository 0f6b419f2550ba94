"""Render a frame range on a Dask cluster: ``render.py FILE.blend --frames A-B --workers N`` (a local
cluster of N worker processes) or ``--scheduler tcp://HOST:8786`` (a running one).

Each task (one frame, or ``--chunk`` frames) runs the batch script in a fresh Blender process (the
``bpy`` wheel of the worker's Python), so a crash takes down one task, not the worker. The batch
script writes each frame to a hidden partial name and renames it when complete, so an output
file is either whole or absent. A task whose Blender process or worker dies is run again (Dask's
``retries`` and the scheduler's ``allowed-failures``); a frame that fails for a reason of its own
(exit status 1 with a one-line reason: bad scene, speed above c at that frame) is reported once and
not retried. Frames whose output already reads back as a complete image are skipped (``--resume``,
on by default here). The coordinator (this module) imports neither bpy nor, before it is called,
Dask: the single-process path stays free of both.
"""

from __future__ import annotations

import glob
import importlib.util
import os
import sys
import time
from typing import TYPE_CHECKING

from ..errors import BatchError
from . import frame_files

if TYPE_CHECKING:
    import argparse
    from collections.abc import Callable, Iterable, Sequence

# Options of the coordinator, not passed on to the per-task batch script.
COORDINATOR_OPTIONS = {
    "help",
    "blend_file",
    "out",
    "frame",
    "frames",
    "workers",
    "scheduler",
    "chunk",
    "resume",
    "retries",
    "threads",
}
ERROR_PREFIX = "render.py: error: "

# The per-task process: dies with the worker thread that started it (Linux), then runs the batch
# script from the worker's own copy of the add-on. argv: parent pid, package root, script options.
LAUNCH = """
import os, sys
parent = int(sys.argv.pop(1))
root = sys.argv.pop(1)
if sys.platform.startswith("linux"):
    import ctypes, signal
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:
        sys.exit("render.py: error: the worker that started this task is gone")
sys.path.insert(0, root)
from relativity_addon import batch
from relativity_addon.blender.common import compat
compat.run_main(batch.main)
"""


class LostProcessError(Exception):
    """The Blender process of a task was killed by a signal (out of memory, a lost machine, a
    user): Dask runs the task again, elsewhere if it can."""


def render_task(arguments: Sequence[str], label: str) -> tuple[int, str | None, float, str]:
    """Run on a worker: render ``arguments`` (batch script options, ``--frames`` included) in a
    fresh Blender process. Returns (exit status, one-line reason or None, seconds, worker host:pid);
    raises LostProcessError when the process was killed, so Dask retries it."""
    import socket
    import subprocess

    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    command = [sys.executable, "-c", LAUNCH, str(os.getpid()), root, *arguments]
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    started = time.monotonic()
    process = subprocess.run(command, capture_output=True, text=True, env=env, stdin=subprocess.DEVNULL)
    seconds = time.monotonic() - started
    if process.returncode < 0:
        raise LostProcessError(f"{label}: the Blender process was killed by signal {-process.returncode}")
    reason = None
    if process.returncode != 0:
        errors = [line[len(ERROR_PREFIX) :] for line in process.stderr.splitlines() if line.startswith(ERROR_PREFIX)]
        last = (process.stderr.strip().splitlines() or ["no output"])[-1]
        reason = errors[-1] if errors else f"exit status {process.returncode}: {last}"
    return process.returncode, reason, seconds, f"{socket.gethostname()}:{os.getpid()}"


def output_pattern(out_path: str, several: bool) -> str:
    """The --out path with a run of '#' for the frame number: each task renders its frames to the
    names a single-process ``--frames`` render gives them (``shot_0001.png``)."""
    directory, name = os.path.split(out_path)
    if "#" in name or not several:
        return out_path
    stem, extension = os.path.splitext(name)
    return os.path.join(directory, f"{stem}_####{extension}")


def _option_text(dest, value):
    if dest == "beta":
        return ",".join(repr(float(v)) for v in value)
    if dest == "resolution":
        return f"{value[0]}x{value[1]}"
    return str(value)


def task_options(parser: argparse.ArgumentParser, options: argparse.Namespace) -> list[str]:
    """The batch script options of ``options`` that every task repeats (scene, camera, samples...),
    as command-line text; the coordinator's own options are left out."""
    arguments = []
    for action in parser._actions:
        value = getattr(options, action.dest, None)
        if action.dest in COORDINATOR_OPTIONS or not action.option_strings or value is None or value is False:
            continue
        flag = max(action.option_strings, key=len)
        arguments.append(flag if value is True else f"{flag}={_option_text(action.dest, value)}")
    return arguments


def chunks(frames: Iterable[int], size: int) -> list[list[int]]:
    """Runs of at most ``size`` consecutive frames."""
    runs, current = [], []
    for frame in frames:
        if current and (frame != current[-1] + 1 or len(current) == size):
            runs.append(current)
            current = []
        current.append(frame)
    return runs + ([current] if current else [])


def _label(frames):
    return f"frame {frames[0]}" if len(frames) == 1 else f"frames {frames[0]}-{frames[-1]}"


def remove_partials(paths: Iterable[str]) -> None:
    """Partial files of these frames left by killed Blender processes."""
    for path in paths:
        directory, name = os.path.split(path)
        stem, extension = os.path.splitext(name)
        for partial in glob.glob(os.path.join(glob.escape(directory), f".{glob.escape(stem)}.*.partial{extension}")):
            try:
                os.remove(partial)
            except FileNotFoundError:
                pass


def _frames(options):
    if options.frames is not None:
        first, last = options.frames
        return list(range(first, last + 1))
    if options.frame is not None:
        return [options.frame]
    raise BatchError("--workers and --scheduler need --frames A-B or --frame N")


def _connect(options, log):
    """(client, cluster or None) for --workers or --scheduler."""
    try:
        import dask
        from distributed import Client, LocalCluster
    except ImportError:
        raise BatchError("--workers and --scheduler need Dask: pip install 'dask[distributed]'") from None
    import logging

    if options.scheduler is not None:
        try:
            client = Client(options.scheduler, timeout="20s")
        except (OSError, TimeoutError) as error:
            raise BatchError(f"cannot reach the Dask scheduler at {options.scheduler}: {error}") from None
        services = client.scheduler_info().get("services", {})
        workers = len(client.scheduler_info().get("workers", {}))
        log(f"render.py: Dask scheduler {options.scheduler}, {workers} worker(s)", flush=True)
        if "dashboard" in services:
            log(f"render.py: dashboard {client.dashboard_link}", flush=True)
        return client, None
    dashboard = importlib.util.find_spec("bokeh") is not None  # Dask's dashboard needs bokeh
    # A worker that dies while running a task counts against the task as one failure; after
    # ``retries`` more the task is given up (KilledWorker).
    with dask.config.set({"distributed.scheduler.allowed-failures": options.retries}):
        cluster = LocalCluster(
            n_workers=options.workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0" if dashboard else None,
            silence_logs=logging.CRITICAL,
        )
    client = Client(cluster)
    log(
        f"render.py: local Dask cluster, {options.workers} worker process(es) at {cluster.scheduler_address}"
        + (f", dashboard {client.dashboard_link}" if dashboard else " (no dashboard: install bokeh for one)"),
        flush=True,
    )
    return client, cluster


def _identity(path):
    try:
        status = os.stat(path)
    except FileNotFoundError:
        return None
    return status.st_ino, status.st_mtime_ns


class _Job:
    """Progress and the final account of a distributed render."""

    def __init__(self, paths, skipped, log):
        self.paths, self.log = paths, log
        self.total, self.skipped = len(paths), len(skipped)
        self.rendered, self.failed = [], {}
        self.started = time.monotonic()
        # A frame counts as rendered only if its file was replaced during the job (the rename
        # gives it a new inode): an old output of a frame a failed chunk never reached is no result.
        self.before = {frame: _identity(path) for frame, path in paths.items()}

    def finished(self, frames, reason, seconds, worker):
        """A task of ``frames`` ended; ``reason``: why it failed (a chunk fails at its first bad
        frame; the frames before it are complete)."""
        for frame in frames:
            path = self.paths[frame]
            problem = frame_files.problem(path)
            if problem is None and _identity(path) == self.before[frame]:
                problem = "not written by this job"
            if problem is None:
                self.rendered.append(frame)
            else:
                self.failed[frame] = reason or f"no complete output ({problem}): {path}"
        done = len(self.rendered) + len(self.failed)
        todo = self.total - self.skipped
        elapsed = time.monotonic() - self.started
        left = elapsed / done * (todo - done) if done else 0.0
        status = "failed" if any(frame in self.failed for frame in frames) else "done"
        where = f" in {frame_files.format_seconds(seconds)} on {worker}" if worker else ""
        self.log(
            f"render.py: {_label(frames)} {status}{where} ({done}/{todo}; {len(self.failed)} failed), "
            f"about {frame_files.format_seconds(left)} left",
            flush=True,
        )

    def summary(self, error_log):
        elapsed = time.monotonic() - self.started
        self.log(
            f"render.py: {self.total} frames: {len(self.rendered)} rendered, {self.skipped} skipped "
            f"(already complete), {len(self.failed)} failed, in {frame_files.format_seconds(elapsed)}",
            flush=True,
        )
        reasons = {}
        for frame in sorted(self.failed):
            reasons.setdefault(self.failed[frame], []).append(frame)
        for reason, frames in reasons.items():
            error_log(f"render.py: error: {_label(frames) if len(frames) > 1 else f'frame {frames[0]}'}: {reason}")
        return 1 if self.failed else 0


def render(
    options: argparse.Namespace,
    parser: argparse.ArgumentParser,
    log: Callable[..., object] = print,
    error_log: Callable[[str], object] | None = None,
) -> int:
    """Run the distributed render; returns the exit status (1 if any frame failed)."""
    error_log = error_log or (lambda line: print(line, file=sys.stderr, flush=True))
    blend = os.path.abspath(options.blend_file)
    if not os.path.isfile(blend):
        raise BatchError(f"no such .blend file: {options.blend_file}")
    if options.retries < 0:
        raise BatchError("--retries must be 0 or more")
    frames = _frames(options)
    out = os.path.abspath(options.out)
    if os.path.splitext(out)[1].lower() not in (".png", ".exr"):
        raise BatchError(f"--out must end in .png or .exr, got {options.out!r}")
    pattern = output_pattern(out, len(frames) > 1)
    paths = {frame: frame_files.frame_output_path(pattern, frame, several=False) for frame in frames}
    os.makedirs(os.path.dirname(out), exist_ok=True)
    remove_partials(paths.values())
    resume = options.resume is not False
    skipped = [frame for frame in frames if resume and frame_files.is_complete(paths[frame])]
    todo = [frame for frame in frames if frame not in skipped]
    if skipped:
        log(f"render.py: resume: {len(skipped)} of {len(frames)} frames already complete, skipped", flush=True)
    job = _Job(paths, skipped, log)
    if not todo:
        return job.summary(error_log)

    common = [blend, f"--out={pattern}", *task_options(parser, options), "--no-resume"]
    threads = options.threads
    if threads is None and options.workers is not None:
        threads = max(1, (os.cpu_count() or 1) // options.workers)
    if threads is not None:
        common.append(f"--threads={threads}")
    client, cluster = _connect(options, log)
    try:
        from distributed import as_completed

        futures = {}
        for run in chunks(todo, options.chunk):
            arguments = [*common, f"--frames={run[0]}-{run[-1]}"]
            future = client.submit(
                render_task,
                arguments,
                _label(run),
                retries=options.retries,
                pure=False,
                key=f"relativistic-render-{run[0]}-{run[-1]}-{os.getpid()}-{time.time_ns()}",
            )
            futures[future] = run
        for future in as_completed(futures):
            run = futures[future]
            try:
                _status, reason, seconds, worker = future.result()
            except Exception as error:  # noqa: BLE001 - lost workers (KilledWorker), lost processes
                message = (str(error).strip().splitlines() or [""])[-1]
                reason = f"given up after {options.retries + 1} attempts: {type(error).__name__}: {message}"
                seconds, worker = 0.0, None
            job.finished(run, reason, seconds, worker)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
        remove_partials(paths.values())
    return job.summary(error_log)
