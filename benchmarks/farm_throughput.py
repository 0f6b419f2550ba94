"""Throughput of a distributed render (Dask, one single-threaded worker per core, each with its
long-lived Blender process) against one process rendering the frames in turn on every core, side by
side in one run.

    python benchmarks/farm_throughput.py [--frames 16] [--resolution 160x120] [--samples 256]
        [--workers CORES] [--repeats 2]

The two commands run alternately (single process, cluster, then again), so that load from other
processes hits them alike; each is timed from launch to exit as a user sees it (the cluster's
start and every Blender start included). Printed, medians over the rounds:

- wall time and frames per second of each, and the cluster's throughput over the single
  process's (>= 1: the cluster is faster);
- a frame in a running Blender process: the render time the workers' Blender processes report
  for a frame (one Cycles thread; frames after each process's first, which also applies the effect
  and compiles the camera shader), and for comparison the single process's (all cores);
- per-task overhead: a task's time on its worker minus the frame's time in the Blender process
  (what a frame on the farm costs beyond rendering it), median and largest (the largest is a
  worker's first task, which waits for its Blender process to load the file);
- the CPU time (user + system) of all the processes of each command, and their ratio: what the
  cluster costs in CPU beyond the frames (its Dask processes, a Blender start per worker), read
  along with the wall times on a shared machine, where a session's share of the cores varies;
- start: launch to the first finished frame, and the amortised overhead per frame: the cluster's
  wall time times its workers minus the frames' render times, over the frames (everything a
  frame pays besides its own render, the cluster's and the processes' starts included).

The single process renders with ``--threads`` = cores, each worker's Blender with one thread.
Start the measurement with ``uptime`` and read the ratios: the machine may be shared.
"""

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RENDER_SCRIPT = os.path.join(REPO_ROOT, "examples", "render.py")

BUILD_SCENE = """
import sys
sys.path.insert(0, sys.argv[1])
import bpy
from camera_overhead import build_scene
build_scene(bpy, (64, 48), 1)
bpy.context.scene.frame_start, bpy.context.scene.frame_end = 1, 250
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[2], check_existing=False)
"""

ENV = dict(os.environ)
ENV.pop("PYTHONPATH", None)
SINGLE_FRAME = re.compile(r"render\.py: frame (\d+) \(\d+/\d+\) in ([\d.]+) s")
CLUSTER_FRAME = re.compile(
    r"render\.py: frame (\d+) done in ([\d.]+) s \(task ([\d.]+) s\) on (\S+), Blender pid (\d+)"
)


def _cpu_seconds():
    """CPU time (user + system) of every finished descendant process (each one waited for)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(command, cpu=None):
    """(wall seconds, stdout lines with their arrival time since launch); the CPU seconds of the
    command's processes are appended to ``cpu``."""
    cpu_before = _cpu_seconds()
    start = time.perf_counter()
    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV, cwd=REPO_ROOT
    )
    lines = []
    for line in process.stdout:
        lines.append((time.perf_counter() - start, line.rstrip("\n")))
    errors = process.stderr.read()
    process.wait()
    wall = time.perf_counter() - start
    if process.returncode != 0:
        sys.exit(f"farm_throughput: {' '.join(command[2:4])} failed ({process.returncode}): {errors[-1500:]}")
    if cpu is not None:
        cpu.append(_cpu_seconds() - cpu_before)
    return wall, lines


def measure(blend, work, options):
    common = [
        f"--frames=1-{options.frames}",
        f"--resolution={options.resolution}",
        f"--samples={options.samples}",
        "--beta=0,0.48,-0.13",
    ]
    cores = os.cpu_count() or 1
    single = [sys.executable, RENDER_SCRIPT, blend, *common, f"--out={os.path.join(work, 'single', 'f.png')}"]
    single.append(f"--threads={cores}")
    cluster = [
        sys.executable,
        RENDER_SCRIPT,
        blend,
        *common,
        f"--out={os.path.join(work, 'cluster', 'f.png')}",
        f"--workers={options.workers}",
        "--threads=1",
        "--no-resume",
    ]
    keys = (
        "single",
        "cluster",
        "single_cpu",
        "cluster_cpu",
        "single_frame",
        "frame",
        "task_overhead",
        "max_overhead",
        "start",
        "amortised",
    )
    result = {key: [] for key in keys}
    run([*single[:3], "--frames=1-1", *single[4:]])  # warm-up: file cache, bytecode, kernels
    for _ in range(options.repeats):
        wall, lines = run(single, result["single_cpu"])
        result["single"].append(wall)
        frames = [float(m.group(2)) for _, text in lines if (m := SINGLE_FRAME.match(text))]
        result["single_frame"].append(statistics.median(frames[1:] or frames))
        wall, lines = run(cluster, result["cluster_cpu"])
        result["cluster"].append(wall)
        tasks = [(at, m) for at, text in lines if (m := CLUSTER_FRAME.match(text))]
        if len(tasks) != options.frames:
            sys.exit(f"farm_throughput: {len(tasks)} frames reported by the cluster, not {options.frames}")
        first_of = {}
        for _, m in tasks:
            first_of.setdefault(m.group(5), m.group(1))
        later = [float(m.group(2)) for _, m in tasks if m.group(1) not in first_of.values()]
        result["frame"].append(statistics.median(later or [float(m.group(2)) for _, m in tasks]))
        overheads = [float(m.group(3)) - float(m.group(2)) for _, m in tasks]
        result["task_overhead"].append(statistics.median(overheads))
        result["max_overhead"].append(max(overheads))
        result["start"].append(tasks[0][0])
        rendering = sum(float(m.group(2)) for _, m in tasks)
        result["amortised"].append((wall * options.workers - rendering) / options.frames)
    return {key: statistics.median(values) for key, values in result.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=16)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="default: one per core")
    parser.add_argument("--repeats", type=int, default=2)
    options = parser.parse_args()

    work = tempfile.mkdtemp(prefix="farm-throughput-")
    ENV.pop("PYTHONDONTWRITEBYTECODE", None)  # cache bytecode as on a user's machine (see batch_overhead.py)
    ENV["PYTHONPYCACHEPREFIX"] = os.path.join(work, "pycache")
    blend = os.path.join(work, "room.blend")
    subprocess.run(
        [sys.executable, "-c", BUILD_SCENE, os.path.dirname(os.path.abspath(__file__)), blend],
        check=True,
        capture_output=True,
        env=ENV,
    )
    print(
        f"{options.frames} frames of {options.resolution}, {options.samples} samples, exact camera; one process "
        f"({os.cpu_count()} threads) vs Dask LocalCluster of {options.workers} single-threaded workers (a long-lived "
        f"Blender process each); medians of {options.repeats} alternating rounds; load average at the start "
        f"{os.getloadavg()[0]:.2f}",
        flush=True,
    )
    m = measure(blend, work, options)
    print(f"  single process:  {m['single']:7.2f} s, {options.frames / m['single']:.3f} frames/s")
    print(f"  cluster:         {m['cluster']:7.2f} s, {options.frames / m['cluster']:.3f} frames/s")
    print(f"  throughput, cluster / single process: {m['single'] / m['cluster']:.2f}")
    print(
        f"  CPU time of all their processes: single {m['single_cpu']:.1f} s, cluster {m['cluster_cpu']:.1f} s; "
        f"single / cluster {m['single_cpu'] / m['cluster_cpu']:.2f}"
    )
    print(
        f"  a frame in a running Blender process: {m['frame']:.2f} s (worker, 1 thread); "
        f"{m['single_frame']:.2f} s (single process, {os.cpu_count()} threads)"
    )
    print(f"  per-task overhead (task on its worker minus the frame in Blender): median {m['task_overhead']:.3f} s,")
    print(f"    largest {m['max_overhead']:.2f} s (a worker's first task: waits for its Blender to load the file)")
    print(f"  launch to the first finished frame: {m['start']:.2f} s")
    print(f"  amortised overhead per frame (cluster wall x workers - render times, / frames): {m['amortised']:.2f} s")
    print(f"(load average at the end: {os.getloadavg()[0]:.2f})")


if __name__ == "__main__":
    main()
