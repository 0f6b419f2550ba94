"""A farm worker's long-lived Blender processes (the worker side; no bpy, no Dask).

Each process runs ``frame_server.serve``: it loads the .blend once and renders frames on request,
so a frame costs about what it costs in a running Blender. A pool keeps one process per task
running at once on the worker (one, with one Dask thread per worker), for one job:

- **Dies with the worker**: the process asks Linux to kill it when the thread that started it ends
  (``PR_SET_PDEATHSIG``); every process is started from one thread of the pool that lives as long
  as the worker, so a lost worker leaves no Blender writing behind it.
- **Restarted if it dies**: a process lost while it renders a frame (killed, out of memory) is
  replaced by a fresh one and the frame rendered again, once in the task; lost a second time, the
  task raises :class:`LostProcessError` and Dask's retries run it again, elsewhere if they can.
- **Retired after an unclean failure**: a frame that failed after the scene changed (a failed
  render or apparent-geometry update) ends its process; the next frame gets a fresh one.
- A set-up failure (the file cannot be opened, a bad option) is the same for every frame of the
  job: it is reported for each frame without starting Blender again.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Sequence

PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# The process: dies with the thread that started it (Linux), then serves frames from the worker's
# own copy of the add-on. argv: parent pid, package root, reply file descriptor, the frame to apply
# the effect at ("" for the first frame asked for), script options.
LAUNCH = """
import os, sys
parent = int(sys.argv.pop(1))
root = sys.argv.pop(1)
reply_fd = int(sys.argv.pop(1))
setup_frame = sys.argv.pop(1)
if sys.platform.startswith("linux"):
    import ctypes, signal
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:
        sys.exit("render.py: error: the worker that started this process is gone")
sys.path.insert(0, root)
from relativity_addon.batch import frame_server
from relativity_addon.blender.common import compat
compat.run_main(lambda: frame_server.serve(sys.argv, reply_fd, int(setup_frame) if setup_frame else None))
"""


class LostProcessError(Exception):
    """A Blender process ended while it owed a reply (killed by a signal, out of memory, a crash):
    Dask runs the task again, elsewhere if it can."""


def _log_tail(path, lines=3):
    try:
        with open(path, encoding="utf-8", errors="replace") as log:
            return " | ".join(line.strip() for line in log.readlines()[-lines:] if line.strip())
    except OSError:
        return ""


class BlenderProcess:
    """One Blender process serving frames; its output goes to a log file in the temp folder."""

    def __init__(self, arguments: Sequence[str], setup_frame: int | None = None) -> None:
        read_fd, write_fd = os.pipe()
        handle, self.log_path = tempfile.mkstemp(prefix="relativity-blender-", suffix=".log")
        setup = "" if setup_frame is None else str(setup_frame)
        command = [sys.executable, "-c", LAUNCH, str(os.getpid()), PACKAGE_ROOT, str(write_fd), setup, *arguments]
        env = dict(os.environ)
        env.pop("PYTHONPATH", None)
        # Dask's nanny sets this for its workers (``distributed.nanny.pre-spawn-environ``); in Blender
        # it makes malloc hand memory back all the time: measured 15-17 % more CPU per frame.
        env.pop("MALLOC_TRIM_THRESHOLD_", None)
        try:
            self.process = subprocess.Popen(
                command,
                stdin=subprocess.PIPE,
                stdout=handle,
                stderr=subprocess.STDOUT,
                env=env,
                pass_fds=(write_fd,),
                text=True,
            )
        finally:
            os.close(write_fd)
            os.close(handle)
        self.pid = self.process.pid
        self.replies = os.fdopen(read_fd, encoding="utf-8")
        self.setup: dict[str, Any] | None = None

    def alive(self) -> bool:
        return self.process.poll() is None

    def _read(self):
        line = self.replies.readline()
        if not line:
            status = self.process.wait()
            how = f"killed by signal {-status}" if status < 0 else f"exit status {status}"
            tail = _log_tail(self.log_path)
            raise LostProcessError(f"Blender process {self.pid} ended ({how})" + (f": {tail}" if tail else ""))
        return json.loads(line)

    def setup_failure(self) -> str | None:
        """Waits until the file is loaded and set up: None, or the one-line reason it could not be."""
        if self.setup is None:
            self.setup = self._read()
        return None if self.setup.get("ready") else str(self.setup.get("reason"))

    def render(self, frame: int) -> dict[str, Any]:
        """The reply for ``frame``: reason (None when written), clean, seconds, pid."""
        try:
            self.process.stdin.write(json.dumps({"frame": frame}) + "\n")
            self.process.stdin.flush()
        except (BrokenPipeError, OSError):
            pass  # gone: the read below says how
        return self._read()

    def stop(self, timeout: float = 10.0) -> None:
        """Asked to stop (it finishes a frame in progress), killed after ``timeout`` seconds."""
        try:
            self.process.stdin.write(json.dumps({"stop": True}) + "\n")
            self.process.stdin.close()
        except (BrokenPipeError, OSError, ValueError):
            pass
        try:
            self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.replies.close()
        try:
            os.remove(self.log_path)
        except FileNotFoundError:
            pass


class BlenderPool:
    """A worker's Blender processes for one job (the batch-script ``arguments`` without frames),
    each with the effect applied at ``setup_frame`` as it starts (None: at its first frame)."""

    def __init__(self, arguments: Sequence[str], setup_frame: int | None = None) -> None:
        self.arguments = list(arguments)
        self.setup_frame = setup_frame
        self._idle: list[BlenderProcess] = []
        self._started: list[BlenderProcess] = []
        self._lock = threading.Lock()
        self._setup_failure: str | None = None
        # Every process is started from this one thread, which lives as long as the pool: the
        # process's PR_SET_PDEATHSIG fires when the thread that started it ends.
        self._spawner = ThreadPoolExecutor(max_workers=1, thread_name_prefix="relativity-blender")

    def _start(self) -> BlenderProcess:
        process = self._spawner.submit(BlenderProcess, self.arguments, self.setup_frame).result()
        with self._lock:
            self._started.append(process)
        return process

    def prestart(self) -> None:
        """Start loading a process now (the worker's set-up), before the first task asks for it."""
        process = self._start()
        with self._lock:
            self._idle.append(process)

    def _take(self) -> BlenderProcess:
        while True:
            with self._lock:
                process = self._idle.pop() if self._idle else None
            if process is None:
                return self._start()
            if process.alive():
                return process
            self._retire(process)  # ended on its own (idle too long)

    def _retire(self, process):
        process.stop()
        with self._lock:
            if process in self._started:
                self._started.remove(process)

    def _render(self, process, frame):
        """(reply, process to go on with, lost: why an earlier process was replaced, or None)."""
        lost = None
        for attempt in range(2):
            try:
                failure = process.setup_failure()
                if failure is not None:
                    self._setup_failure = failure
                    return {"frame": frame, "reason": failure, "clean": False, "pid": process.pid}, process, lost
                return process.render(frame), process, lost
            except LostProcessError as error:
                self._retire(process)
                if attempt == 1:
                    raise LostProcessError(f"frame {frame}: {lost}; then {error}") from None
                lost = str(error)
                process = self._start()
        raise AssertionError("unreachable")

    def render(self, frames: Sequence[int]) -> list[dict[str, Any]]:
        """Render ``frames`` in turn; per frame a dict: frame, reason (None when written), seconds
        (in Blender), pid (of the Blender process), lost (why a process was replaced, or None)."""
        results: list[dict[str, Any]] = []
        process = None
        try:
            for frame in frames:
                if self._setup_failure is not None:
                    results.append({"frame": frame, "reason": self._setup_failure, "pid": None, "lost": None})
                    continue
                process = process or self._take()
                reply, process, lost = self._render(process, frame)
                results.append({**reply, "lost": lost})
                if reply["reason"] is not None and not reply.get("clean"):
                    self._retire(process)
                    process = None
        except BaseException:
            if process is not None:
                self._retire(process)
            raise
        if process is not None:
            with self._lock:
                self._idle.append(process)
        return results

    def close(self) -> None:
        """Stop every process of the pool (the worker closes, or the job is over)."""
        with self._lock:
            started, self._started, self._idle = self._started, [], []
        for process in started:
            process.stop()
        self._spawner.shutdown(wait=False)
