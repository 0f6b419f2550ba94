"""Throughput of a distributed render (Dask, one worker per core, a fresh Blender process per
frame task) against one process rendering the frames in turn, side by side in one run.

    python benchmarks/farm_throughput.py [--frames 8] [--resolution 64x48] [--samples 1,32]
        [--workers CORES] [--repeats 2]

For each sample count the two commands run alternately (single process, cluster, then again), so
that load from other processes hits them alike; each is timed from launch to exit as a user sees
it (the cluster's start included). Printed per sample count, medians over the rounds:

- wall time and frames per second of each, and their ratio (cluster / single process);
- a frame in a running process: the single process's per-frame time, frames 2..N (frame 1 also
  compiles the camera shader);
- a task: the wall time of one frame task's Blender process on a worker (start Python, import
  bpy, open the file, enable the add-on, apply the effect, render, write, exit), and the per-task
  overhead: a task minus a frame in a running process;
- the cluster's start (launch to the coordinator's "local Dask cluster" line);
- the cluster again with ``--chunk`` frames/workers (one task, one Blender start, per worker) and
  its ratio to the single process.

The single process renders with all cores (Cycles' default), each worker's Blender with
cores / workers threads.
"""

import argparse
import os
import re
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


def run(command):
    """(wall seconds, stdout lines with their arrival time since launch)."""
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
    return wall, lines


def seconds_of(text):
    match = re.search(r"in (?:(\d+)m(\d+)s|([\d.]+) s)", text)
    if match.group(3) is not None:
        return float(match.group(3))
    return 60.0 * int(match.group(1)) + int(match.group(2))


def measure(blend, work, options, samples, rounds):
    common = [
        f"--frames=1-{options.frames}",
        f"--resolution={options.resolution}",
        f"--samples={samples}",
        "--beta=0,0.48,-0.13",
    ]
    single = [sys.executable, RENDER_SCRIPT, blend, *common, f"--out={os.path.join(work, 'single', 'f.png')}"]
    cluster = [
        sys.executable,
        RENDER_SCRIPT,
        blend,
        *common,
        f"--out={os.path.join(work, 'cluster', 'f.png')}",
        f"--workers={options.workers}",
        "--no-resume",
    ]
    chunk = -(-options.frames // options.workers)
    chunked = [*cluster, f"--chunk={chunk}"]
    result = {key: [] for key in ("single", "cluster", "chunked", "frame", "task", "start")}
    run([*single[:3], "--frames=1-1", *single[4:]])  # warm-up: file cache, bytecode, kernels
    for _ in range(rounds):
        wall, lines = run(single)
        result["single"].append(wall)
        frames = [seconds_of(text) for _, text in lines if re.match(r"render\.py: frame \d+ \(", text)]
        result["frame"].append(statistics.median(frames[1:] or frames))
        wall, lines = run(cluster)
        result["cluster"].append(wall)
        tasks = [seconds_of(text) for _, text in lines if re.match(r"render\.py: frame \d+ done in", text)]
        result["task"].append(statistics.median(tasks))
        result["start"].append(next(at for at, text in lines if "local Dask cluster" in text))
        result["chunked"].append(run(chunked)[0])
    return {key: statistics.median(values) for key, values in result.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--resolution", default="64x48")
    parser.add_argument("--samples", default="1", help="comma-separated sample counts, each measured")
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
        f"{options.frames} frames of {options.resolution}, exact camera; single process (all {os.cpu_count()} "
        f"cores) vs Dask LocalCluster of {options.workers} workers (a fresh Blender per frame); "
        f"medians of {options.repeats} alternating rounds"
    )
    chunk = -(-options.frames // options.workers)
    print(
        f"  {'samples':>7s}{'single s':>10s}{'cluster s':>11s}{'ratio':>7s}{'single f/s':>12s}{'cluster f/s':>13s}"
        f"{'frame s':>9s}{'task s':>8s}{'overhead s':>12s}{'start s':>9s}{f'chunk {chunk} s':>11s}{'ratio':>7s}"
    )
    for samples in (int(value) for value in options.samples.split(",")):
        m = measure(blend, work, options, samples, options.repeats)
        print(
            f"  {samples:7d}{m['single']:10.2f}{m['cluster']:11.2f}{m['cluster'] / m['single']:7.2f}"
            f"{options.frames / m['single']:12.2f}{options.frames / m['cluster']:13.2f}{m['frame']:9.2f}"
            f"{m['task']:8.2f}{m['task'] - m['frame']:12.2f}{m['start']:9.2f}{m['chunked']:11.2f}"
            f"{m['chunked'] / m['single']:7.2f}",
            flush=True,
        )
    print(f"(load average at the end: {os.getloadavg()[0]:.2f})")


if __name__ == "__main__":
    main()
