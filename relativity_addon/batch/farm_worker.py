"""What a Dask worker runs for a distributed render (imports Dask; the coordinator, ``farm.py``,
imports this module only once it has decided to use Dask).

The coordinator gives every worker one :class:`BlenderProcesses` plugin per job (a local
cluster's workers when they start, a running cluster's when it registers the plugin, and any worker
that joins later, a lost worker's replacement too): it starts a Blender process loading the file
at once (``blender_pool.py``), and when the job is over (the plugin is unregistered, or the local
cluster closed) or the worker closes, it stops them. A task (:func:`render_task`) renders its frames in that process.
"""

from __future__ import annotations

import os
import socket
import time
from typing import TYPE_CHECKING, Any

from distributed import WorkerPlugin, get_worker

from .blender_pool import BlenderPool, take_over

if TYPE_CHECKING:
    from collections.abc import Sequence

    from distributed import Worker


class BlenderProcesses(WorkerPlugin):
    """A worker's Blender processes for one job; ``arguments``: the batch-script command line
    every frame shares (file, --out pattern, options; no frames); ``name``: the job's, unique;
    ``setup_frame``: the frame each process applies the effect at as it starts (the job's first);
    ``handover``: where a local cluster's coordinator offers the processes it started for the
    workers before the cluster (``blender_pool.PreStarted``), or None."""

    def __init__(
        self, arguments: Sequence[str], name: str, setup_frame: int | None = None, handover: str | None = None
    ) -> None:
        self.arguments = list(arguments)
        self.setup_frame = setup_frame
        self.name = name  # the key of ``worker.plugins`` (Dask reads the attribute)
        self.handover = handover
        self.pool: BlenderPool | None = None

    def setup(self, worker: Worker) -> None:
        self.pool = BlenderPool(self.arguments, self.setup_frame)
        process = take_over(self.handover) if self.handover else None
        if process is not None:
            self.pool.adopt(process)
        else:
            self.pool.prestart()

    def teardown(self, worker: Worker) -> None:
        if self.pool is not None:
            self.pool.close()


def render_task(plugin_name: str, frames: Sequence[int]) -> tuple[list[dict[str, Any]], float, str]:
    """Run on a worker: render ``frames`` in the worker's Blender process for the job. Returns (per
    frame: frame, reason, seconds, pid, lost; the task's own seconds; the worker as host:pid);
    raises blender_pool.LostProcessError when the process died twice, so Dask retries the task."""
    started = time.monotonic()
    plugin = get_worker().plugins[plugin_name]
    results = plugin.pool.render(frames)
    return results, time.monotonic() - started, f"{socket.gethostname()}:{os.getpid()}"
