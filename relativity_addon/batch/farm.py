"""Render a frame range on a Dask cluster: ``render.py FILE.blend --frames A-B --workers N`` (a local
cluster of N worker processes) or ``--scheduler tcp://HOST:8786`` (a running one).

Each worker keeps a long-lived Blender process (the ``bpy`` wheel of the worker's Python) that
loads the file once and renders the frames of its tasks (one frame, or ``--chunk`` frames, each)
on request (``farm_worker.py``, ``blender_pool.py``, ``frame_server.py``); a process that dies is
replaced and its frame rendered again. Each frame is written to a hidden partial name and renamed
when complete, so an output file is either whole or absent. A task whose worker dies, or whose
Blender process dies twice, is run again (Dask's ``retries`` and the scheduler's
``allowed-failures``); a frame that fails for a reason of its own (a one-line reason: bad scene,
speed above c at that frame) is reported once and not retried. Frames whose output already reads
back as a complete image are skipped (``--resume``, on by default here). The coordinator (this
module) imports neither bpy nor, before it is called, Dask: the single-process path stays free of both.
"""

from __future__ import annotations

import glob
import importlib.util
import os
import sys
import time
from typing import TYPE_CHECKING

from ..errors import BatchError
from . import frame_files, notes
from .options import check_blend_file, check_out_suffix

if TYPE_CHECKING:
    import argparse
    from collections.abc import Callable, Iterable

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

# Dask's settings for a local cluster (``--workers``), whose processes share the machine with the
# Blender processes doing the work: Dask's defaults watch a cluster several times a second, which on
# a few cores takes CPU from the renders. A worker that dies while running a task counts against
# the task as one failure (``allowed-failures``, set from --retries); a lost worker is seen when its
# connection closes, not by any of these monitors.
LOCAL_CLUSTER_SETTINGS = {
    # The statistical profiler samples every worker's stacks every 10 ms, for a dashboard page.
    "distributed.worker.profile.enabled": False,
    # Event-loop health checks (default every 20 ms in the scheduler, each nanny and each worker).
    "distributed.admin.tick.interval": "1s",
    # CPU, memory, network and disk counters of each process (default every 500 ms), for dashboards.
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.admin.system-monitor.disk": False,
    # Replicas of results: a task's result is a few numbers, held once.
    "distributed.scheduler.active-memory-manager.start": False,
    # Workers forked from one process that has imported Dask once (default: each worker a fresh
    # Python importing Dask and the main script again).
    "distributed.worker.multiprocessing-method": "forkserver",
    # One task per worker at a time (default 1.1: two per single-threaded worker, one waiting
    # behind the other's frame), so the last frames go to whichever worker is free first.
    "distributed.scheduler.worker-saturation": 1.0,
}


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


def _connect(options, log, arguments, job_name, setup_frame=None, handover=None):
    """(client, cluster or None) for --workers or --scheduler, every worker with the job's
    Blender processes (``farm_worker.BlenderProcesses`` for the task ``arguments``, named
    ``job_name``, the effect applied at ``setup_frame``): a local cluster's workers take over the
    processes offered at ``handover`` or start loading the file as they start, a running
    cluster's when the plugin is registered; any worker that joins later, when it joins."""
    try:
        import dask
        from distributed import Client, LocalCluster

        from . import farm_worker
    except ImportError:
        raise BatchError("--workers and --scheduler need Dask: pip install 'dask[distributed]'") from None
    import logging

    plugin = farm_worker.BlenderProcesses(arguments, job_name, setup_frame, handover)

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
        client.register_plugin(plugin, name=job_name)
        return client, None
    dashboard = importlib.util.find_spec("bokeh") is not None  # Dask's dashboard needs bokeh
    settings = {"distributed.scheduler.allowed-failures": options.retries, **LOCAL_CLUSTER_SETTINGS}
    with dask.config.set(settings):
        cluster = LocalCluster(
            n_workers=options.workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0" if dashboard else None,
            silence_logs=logging.CRITICAL,
            plugins=(plugin,),
            memory_limit=0,  # no memory monitors: a worker holds no data, its Blender is another process
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
        self.said: set[str] = set()  # the N-panel's lines printed as notes, once per job
        self.started = time.monotonic()
        # A frame counts as rendered only if its file was replaced during the job (the rename
        # gives it a new inode): an old output of a frame a failed chunk never reached is no result.
        self.before = {frame: _identity(path) for frame, path in paths.items()}

    def finished(self, results, task_seconds, worker):
        """A task ended; ``results``: per frame, its ``reason`` (None when the Blender process says
        it wrote the frame), ``seconds`` and ``pid`` in Blender, ``lost`` (why a Blender process
        was replaced before it)."""
        for result in results:
            frame, reason = result["frame"], result["reason"]
            if result.get("lost"):
                self.log(f"render.py: on {worker}: {result['lost']}; frame {frame} rendered again", flush=True)
            notes.say(result.get("notes") or (), self.said, self.log)
            path = self.paths[frame]
            problem = frame_files.problem(path)
            if problem is None and _identity(path) == self.before[frame]:
                problem = "not written by this job"
            if reason is None and problem is None:
                self.rendered.append(frame)
            else:
                self.failed[frame] = reason or f"no complete output ({problem}): {path}"
            done = len(self.rendered) + len(self.failed)
            todo = self.total - self.skipped
            elapsed = time.monotonic() - self.started
            left = elapsed / done * (todo - done) if done else 0.0
            status = "failed" if frame in self.failed else "done"
            where = f" on {worker}" if worker else ""
            if worker and result.get("pid"):
                where = f" in {result['seconds']:.2f} s (task {task_seconds:.2f} s){where}, Blender pid {result['pid']}"
            self.log(
                f"render.py: frame {frame} {status}{where} ({done}/{todo}; {len(self.failed)} failed), "
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
    check_blend_file(options.blend_file)
    blend = os.path.abspath(options.blend_file)
    if options.retries < 0:
        raise BatchError("--retries must be 0 or more")
    frames = _frames(options)
    check_out_suffix(options.out)
    out = os.path.abspath(options.out)
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
    job_name = f"relativistic-render-{os.getpid()}-{time.time_ns()}"
    started = None
    if options.scheduler is None and sys.platform.startswith("linux"):
        # A local cluster's Blender processes load while Dask starts (not after: Dask's start
        # leaves a core idle for a second); each worker takes one over as it starts. Linux only:
        # a taken-over process dies with its worker through a lifeline the kernel watches.
        from .blender_pool import PreStarted

        started = PreStarted(options.workers, common, todo[0])
    try:
        client, cluster = _connect(options, log, common, job_name, todo[0], started and started.address)
    except BaseException:
        if started is not None:
            started.close()
        raise
    try:
        from distributed import as_completed

        from . import farm_worker

        futures = {}
        for run in chunks(todo, options.chunk):
            future = client.submit(
                farm_worker.render_task,
                job_name,
                run,
                retries=options.retries,
                pure=False,
                key=f"{job_name}-{run[0]}-{run[-1]}",
            )
            futures[future] = run
        for future in as_completed(futures):
            run = futures[future]
            try:
                results, seconds, worker = future.result()
            except Exception as error:  # noqa: BLE001 - lost workers (KilledWorker), lost processes
                message = (str(error).strip().splitlines() or [""])[-1]
                reason = f"given up after {options.retries + 1} attempts: {type(error).__name__}: {message}"
                results, seconds, worker = [{"frame": frame, "reason": reason} for frame in run], 0.0, None
            job.finished(results, seconds, worker)
    finally:
        if cluster is None:  # a running cluster: its workers stop the job's Blender processes
            try:
                client.unregister_worker_plugin(job_name)
            except Exception:  # noqa: BLE001, S110 - a cluster going away stops its workers' processes too
                pass
        client.close()
        if cluster is not None:
            cluster.close()
        if started is not None:
            started.close()
        remove_partials(paths.values())
    return job.summary(error_log)
