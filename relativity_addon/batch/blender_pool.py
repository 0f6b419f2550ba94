"""A farm worker's long-lived Blender processes (the worker side; no bpy, no Dask).

Each process runs ``frame_server.serve``: it loads the .blend once and renders frames on request,
so a frame costs about what it costs in a running Blender. A pool keeps one process per task
running at once on the worker (one, with one Dask thread per worker), for one job:

- **Dies with the worker**: the kernel kills the process when the last copy of its lifeline's write
  end closes, which the worker holds (also for a process a local cluster's coordinator started
  before Dask and the worker took over, :class:`PreStarted`); and when the thread that started it
  ends (``PR_SET_PDEATHSIG``): every process is started from one thread of the pool that lives as
  long as the worker. A lost worker leaves no Blender writing behind it.
- **Restarted if it dies**: a process lost while it renders a frame (killed, out of memory) is
  replaced by a fresh one and the frame rendered again, once in the task; lost a second time, the
  task raises :class:`LostProcessError` and Dask's retries run it again, elsewhere if they can.
- **Retired after an unclean failure**: a frame that failed after the scene changed (a failed
  render or apparent-geometry update) ends its process; the next frame gets a fresh one.
- A set-up failure (the file cannot be opened, a bad option) is the same for every frame of the
  job: it is reported for each frame without starting Blender again.
"""

from __future__ import annotations

import itertools
import json
import os
import select
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Sequence

PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# The process: dies with the thread that started it (Linux) and with whoever holds the write end of
# its lifeline (the worker it renders for, which need not be its parent: the kernel kills it when
# the last copy closes, whatever it is doing, no thread of its own involved), then serves frames
# from the worker's own copy of the add-on. argv: parent pid, package root, reply file descriptor,
# lifeline file descriptor, the frame to apply the effect at ("" for the first frame asked for),
# the CPUs to import Blender on ("" for all: ``start_cpus``), script options.
LAUNCH = """
import os, sys
parent = int(sys.argv.pop(1))
root = sys.argv.pop(1)
reply_fd = int(sys.argv.pop(1))
lifeline = int(sys.argv.pop(1))
setup_frame = sys.argv.pop(1)
start_cpus = sys.argv.pop(1)
everywhere = os.sched_getaffinity(0) if start_cpus else None
if start_cpus:
    os.sched_setaffinity(0, [int(cpu) for cpu in start_cpus.split(",")])
if sys.platform.startswith("linux"):
    import ctypes, fcntl, select, signal
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:
        sys.exit("render.py: error: the worker that started this process is gone")
    fcntl.fcntl(lifeline, fcntl.F_SETOWN, os.getpid())
    fcntl.fcntl(lifeline, fcntl.F_SETSIG, signal.SIGKILL)
    fcntl.fcntl(lifeline, fcntl.F_SETFL, fcntl.fcntl(lifeline, fcntl.F_GETFL) | os.O_ASYNC)
    if select.select([lifeline], [], [], 0)[0]:  # closed before it was armed
        sys.exit("render.py: error: the worker this process was started for is gone")
sys.path.insert(0, root)
from relativity_addon.batch import frame_server
from relativity_addon.blender.common import compat
if everywhere:  # Blender's thread pool is sized now: every thread back on every CPU
    for thread in os.listdir("/proc/self/task"):
        try:
            os.sched_setaffinity(int(thread), everywhere)
        except OSError:
            pass
compat.run_main(lambda: frame_server.serve(sys.argv, reply_fd, int(setup_frame) if setup_frame else None))
"""


class LostProcessError(Exception):
    """A Blender process ended while it owed a reply (killed by a signal, out of memory, a crash):
    Dask runs the task again, elsewhere if it can."""


_STARTS = itertools.count()


def start_cpus(arguments: Sequence[str]) -> list[int]:
    """The CPUs a Blender process rendering with ``--threads=N`` (in ``arguments``) imports ``bpy``
    on: N of those this process may use, a different N for each process started here; none (no
    limit) when N is not fewer. Blender sizes its thread pool (TBB) to the CPUs it may use when
    ``bpy`` is imported and keeps that size when the process is allowed on every CPU again (the
    launch code does that right after the import). Without it, on Blender 4.5 a process rendering
    with one Cycles thread on two cores kept TBB's second thread spinning (in ``sched_yield``) for the
    whole frame: twice the frame's CPU on an idle machine, and CPU taken from the other worker's
    render on a busy one (``docs/farm.md``, Throughput; the pattern of oneTBB issue 1417: threads
    beyond a lowered ``max_allowed_parallelism`` spin). Not seen on Blender 5.2."""
    threads = None
    for argument in arguments:
        if argument.startswith("--threads="):
            threads = int(argument.split("=", 1)[1])
    if threads is None or threads < 1 or not hasattr(os, "sched_getaffinity"):
        return []
    allowed = sorted(os.sched_getaffinity(0))
    if threads >= len(allowed):
        return []
    first = next(_STARTS) * threads
    return [allowed[(first + index) % len(allowed)] for index in range(threads)]


def _log_tail(path, lines=3):
    try:
        with open(path, encoding="utf-8", errors="replace") as log:
            return " | ".join(line.strip() for line in log.readlines()[-lines:] if line.strip())
    except OSError:
        return ""


def _exit_status(pid, timeout=2.0):
    """The exit status (negative: the signal) of ``pid``, which is not this process's child, read
    from /proc while it waits to be reaped by its parent (Linux); None when it cannot be read."""
    until = time.monotonic() + timeout
    while True:
        try:
            with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            return None
        if fields[0] == "Z" and len(fields) > 49:
            return os.waitstatus_to_exitcode(int(fields[49]))  # field 52, exit_code
        if time.monotonic() > until:
            return None
        time.sleep(0.01)


class BlenderProcess:
    """One Blender process serving frames; its output goes to a log file in the temp folder. A
    process started by another process (a local cluster's coordinator, ``PreStarted``) and handed
    over (``take_over``) has no ``process`` here, only its pid."""

    process: subprocess.Popen[str] | None

    def __init__(self, arguments: Sequence[str], setup_frame: int | None = None) -> None:
        read_fd, write_fd = os.pipe()
        life_read, self.lifeline = os.pipe()
        handle, self.log_path = tempfile.mkstemp(prefix="relativity-blender-", suffix=".log")
        setup = "" if setup_frame is None else str(setup_frame)
        cpus = ",".join(str(cpu) for cpu in start_cpus(arguments))
        launch = [str(os.getpid()), PACKAGE_ROOT, str(write_fd), str(life_read), setup, cpus]
        command = [sys.executable, "-c", LAUNCH, *launch, *arguments]
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
                pass_fds=(write_fd, life_read),
                text=True,
            )
        finally:
            os.close(write_fd)
            os.close(life_read)
            os.close(handle)
        self.pid = self.process.pid
        self.requests = self.process.stdin
        self.replies = os.fdopen(read_fd, encoding="utf-8")
        self.setup: dict[str, Any] | None = None

    def hand_over(self, connection: socket.socket) -> None:
        """Give this process to the process at the other end of ``connection`` (``take_over``): its
        requests, replies and lifeline, this side's copies closed, so it now dies with that one."""
        message = json.dumps({"pid": self.pid, "log": self.log_path}).encode()
        socket.send_fds(connection, [message], [self.requests.fileno(), self.replies.fileno(), self.lifeline])
        self.requests.close()
        self.replies.close()
        os.close(self.lifeline)
        self.lifeline = -1

    @classmethod
    def taken_over(cls, message: bytes, fds: Sequence[int]) -> BlenderProcess:
        """The process described by ``message`` whose requests, replies and lifeline are ``fds``."""
        process = cls.__new__(cls)
        info = json.loads(message)
        process.process, process.pid, process.log_path, process.setup = None, int(info["pid"]), str(info["log"]), None
        process.requests = os.fdopen(fds[0], "w", encoding="utf-8")
        process.replies = os.fdopen(fds[1], encoding="utf-8")
        process.lifeline = fds[2]
        return process

    def alive(self) -> bool:
        if self.process is not None:
            return self.process.poll() is None
        try:
            os.kill(self.pid, 0)
        except ProcessLookupError:
            return False
        return _exit_status(self.pid, timeout=0.0) is None

    def _read(self):
        line = self.replies.readline()
        if not line:
            status = self.process.wait() if self.process is not None else _exit_status(self.pid)
            how = "exit status unknown" if status is None else None
            how = how or (f"killed by signal {-status}" if status < 0 else f"exit status {status}")
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
            self.requests.write(json.dumps({"frame": frame}) + "\n")
            self.requests.flush()
        except (BrokenPipeError, OSError):
            pass  # gone: the read below says how
        return self._read()

    def stop(self, timeout: float = 10.0) -> None:
        """Asked to stop (it finishes a frame in progress), killed after ``timeout`` seconds."""
        try:
            self.requests.write(json.dumps({"stop": True}) + "\n")
            self.requests.close()
        except (BrokenPipeError, OSError, ValueError):
            pass
        if self.process is not None:
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        else:  # not this process's child: ended when its replies end
            until = time.monotonic() + timeout
            while select.select([self.replies], [], [], max(0.0, until - time.monotonic()))[0]:
                if not os.read(self.replies.fileno(), 65536):
                    break
            else:
                try:
                    os.kill(self.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        if self.lifeline >= 0:
            os.close(self.lifeline)
            self.lifeline = -1
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
        self.adopt(self._start())

    def adopt(self, process: BlenderProcess) -> None:
        """Render with ``process`` (started here, or by another process and taken over)."""
        with self._lock:
            if process not in self._started:
                self._started.append(process)
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


class PreStarted:
    """Blender processes a local cluster's coordinator starts before its Dask processes, so that
    loading them (``bpy``, the file, the effect) overlaps the cluster's start instead of following
    it. Each worker's plugin takes one over as it starts (:func:`take_over`, through a Unix socket
    in a private folder: the process's pipes and lifeline are passed, not the process), and from
    then on it renders for that worker and dies with it; a worker that finds none left (one that
    replaced a lost worker) starts its own. The processes stay this process's children: it reaps
    them when the job is over (:meth:`close`)."""

    def __init__(self, count: int, arguments: Sequence[str], setup_frame: int | None = None) -> None:
        self._folder = tempfile.mkdtemp(prefix="relativity-handover-")
        self.address = os.path.join(self._folder, "socket")
        self._server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._server.bind(self.address)
        self._server.listen()
        self._server.settimeout(0.2)
        # Started from the thread that lives as long as the job (the coordinator's), for PR_SET_PDEATHSIG.
        self._waiting = [BlenderProcess(arguments, setup_frame) for _ in range(count)]
        self._all = list(self._waiting)
        self._closing = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="relativity-handover", daemon=True)
        self._thread.start()

    def _serve(self):
        while not self._closing.is_set():
            try:
                connection, _ = self._server.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            with connection:
                connection.settimeout(10.0)
                process = self._waiting.pop(0) if self._waiting else None
                try:
                    if process is not None:
                        process.hand_over(connection)
                    else:
                        connection.sendall(b"{}")
                except OSError:  # the worker went away while asking
                    if process is not None:
                        process.stop()

    def close(self, timeout: float = 20.0) -> None:
        """Stop the processes no worker took, and reap every one (the workers stop theirs)."""
        self._closing.set()
        self._thread.join()
        self._server.close()
        for process in self._waiting:
            process.stop()
        self._waiting = []
        until = time.monotonic() + timeout
        for process in self._all:
            popen = process.process
            if popen is None:
                continue
            try:
                popen.wait(max(0.1, until - time.monotonic()))
            except subprocess.TimeoutExpired:
                popen.kill()
                popen.wait()
        try:
            os.remove(self.address)
            os.rmdir(self._folder)
        except OSError:
            pass


def take_over(address: str) -> BlenderProcess | None:
    """A process started for this worker by ``PreStarted`` at ``address``, or None (none left, or
    no coordinator there)."""
    try:
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as connection:
            connection.settimeout(10.0)
            connection.connect(address)
            message, fds, _, _ = socket.recv_fds(connection, 4096, 3, getattr(socket, "MSG_CMSG_CLOEXEC", 0))
    except OSError:
        return None
    if len(fds) != 3:
        for fd in fds:
            os.close(fd)
        return None
    return BlenderProcess.taken_over(message, fds)
