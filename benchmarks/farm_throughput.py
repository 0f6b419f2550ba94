"""Throughput of a distributed render (Dask, one single-threaded worker per core, each with its
long-lived Blender process) against one process rendering the frames in turn on every core, side by
side in one run.

    python benchmarks/farm_throughput.py [--frames 16] [--resolution 160x120] [--samples 256]
        [--workers CORES] [--cluster-threads 1] [--repeats 2] [--compare-with OTHER_CHECKOUT]

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
  along with the wall times on a shared machine, where a session's share of the cores varies.
  Read with psutil from every process of the command's tree every 0.1 s (a process's last tenth
  of a second may be missed), since not every process of a cluster is waited for by its parent
  (a forkserver's workers); for the cluster also per kind of process: the coordinator (with the
  scheduler and the nannies), the Dask worker processes (with a forkserver), the Blender processes;
- start: launch to the first finished frame, and the amortised overhead per frame: the cluster's
  wall time times its workers minus the frames' render times, over the frames (everything a
  frame pays besides its own render, the cluster's and the processes' starts included).

``--parts`` instead accounts for a Blender process's CPU, part by part (one process each, in
turn): importing ``bpy``, opening the file with the add-on, applying the effect, then per frame
the threads that rendered it (ended with it), the main thread (the add-on's handlers apart) and
the threads that lived before the frame (Blender's thread pool and the like, which should be idle):
for a worker's process of one Cycles thread as ``blender_pool`` starts it, the same without its
start on one CPU (as before ``blender_pool.start_cpus``), and the single process's (all cores).

``--compare-with DIR`` runs the cluster a second time in each round from another checkout (its
``examples/render.py``, e.g. the main branch's), after this one's, under the same load.

The single process renders with ``--threads`` = cores, each worker's Blender with
``--cluster-threads`` (default one).
Start the measurement with ``uptime`` and read the ratios: the machine may be shared.
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time

import psutil
import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

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

PARTS = """
import json, os, resource, sys, time
repo, threads, start_on_one, frames = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1", int(sys.argv[4])
arguments = ["parts", *sys.argv[5:], f"--threads={threads}"]
everywhere = os.sched_getaffinity(0)
if start_on_one and threads < len(everywhere):  # as blender_pool.LAUNCH does
    os.sched_setaffinity(0, sorted(everywhere)[:threads])
sys.path.insert(0, repo)
TICK = os.sysconf("SC_CLK_TCK")

def cpu():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime

def threads_cpu():
    found = {}
    for thread in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{thread}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        found[int(thread)] = (int(fields[11]) + int(fields[12])) / TICK
    return found

parts, started = {}, cpu()
import bpy
for thread in os.listdir("/proc/self/task"):
    os.sched_setaffinity(int(thread), everywhere)
parts["import bpy"] = cpu() - started
from relativity_addon.batch import frame_server
started = cpu()
server = frame_server._Frames(arguments)
parts["file, add-on"] = cpu() - started
started = cpu()
server.set_up_at(1)
parts["effect"] = cpu() - started
handlers = [0.0]

def timed(function):
    def wrapper(*args):
        started = cpu()
        try:
            return function(*args)
        finally:
            handlers[0] += cpu() - started
    return wrapper

for name in ("frame_change_pre", "frame_change_post", "render_init", "render_pre", "render_post", "render_complete"):
    listed = getattr(bpy.app.handlers, name)
    for index, function in enumerate(list(listed)):
        listed[index] = timed(function)
for frame in range(1, frames + 1):
    before, started, handlers[0], wall = threads_cpu(), cpu(), 0.0, time.perf_counter()
    reason, _ = server.render(frame)
    wall, total, after = time.perf_counter() - wall, cpu() - started, threads_cpu()
    main = after[os.getpid()] - before[os.getpid()]
    lived = sum(after[t] - before[t] for t in after if t in before and t != os.getpid())
    print(json.dumps({"frame": frame, "wall": wall, "cpu": total, "handlers": handlers[0], "main": main - handlers[0],
                      "lived": lived, "ended": total - main - lived, "reason": reason, **parts}), flush=True)
os._exit(0)
"""

ENV = dict(os.environ)
ENV.pop("PYTHONPATH", None)
SINGLE_FRAME = re.compile(r"render\.py: frame (\d+) \(\d+/\d+\) in ([\d.]+) s")
CLUSTER_FRAME = re.compile(
    r"render\.py: frame (\d+) done in ([\d.]+) s \(task ([\d.]+) s\) on (\S+), Blender pid (\d+)"
)


def _kind(process):
    """coordinator, dask (a worker process or a forkserver) or blender, from the command line; None
    while it cannot be read (a process just started, or ended and not yet reaped)."""
    try:
        command = " ".join(process.cmdline())
    except psutil.Error:
        return None
    if not command:
        return None
    if "frame_server" in command:
        return "blender"
    if "multiprocessing" in command:
        return "dask"
    return "coordinator"


def _sample_tree(root, cpu, stop):
    """Until ``stop`` is set: the CPU seconds (user + system) of every process under ``root``
    (pid: [kind, seconds]), read every 0.1 s into ``cpu``."""
    while not stop.is_set():
        try:
            processes = [root, *root.children(recursive=True)]
        except psutil.Error:
            processes = []
        for process in processes:
            try:
                times = process.cpu_times()
            except psutil.Error:
                continue
            entry = cpu.setdefault(process.pid, [None, 0.0])
            entry[0] = _kind(process) or entry[0]  # read again: a child not yet exec'd shows its parent's
            entry[1] = max(entry[1], times.user + times.system)
        stop.wait(0.1)


def run(command, cpu=None):
    """(wall seconds, stdout lines with their arrival time since launch); the CPU seconds of the
    command's processes per kind (coordinator, dask, blender, total) are appended to ``cpu``."""
    start = time.perf_counter()
    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV, cwd=REPO_ROOT
    )
    per_process, stop = {}, threading.Event()
    sampler = threading.Thread(target=_sample_tree, args=(psutil.Process(process.pid), per_process, stop))
    sampler.start()
    lines = []
    for line in process.stdout:
        lines.append((time.perf_counter() - start, line.rstrip("\n")))
    errors = process.stderr.read()
    process.wait()
    wall = time.perf_counter() - start
    stop.set()
    sampler.join()
    if process.returncode != 0:
        sys.exit(f"farm_throughput: {' '.join(command[2:4])} failed ({process.returncode}): {errors[-1500:]}")
    if cpu is not None:
        kinds = {"coordinator": 0.0, "dask": 0.0, "blender": 0.0}
        for kind, seconds in per_process.values():
            kinds[kind or "dask"] += seconds
        cpu.append({**kinds, "total": sum(kinds.values())})
    return wall, lines


def _cluster_round(command, options, into):
    """One run of the cluster ``command``; its figures appended to the lists of ``into``."""
    cpu = []
    wall, lines = run(command, cpu)
    into["wall"].append(wall)
    for kind, seconds in cpu[0].items():
        into[f"cpu_{kind}"].append(seconds)
    tasks = [(at, m) for at, text in lines if (m := CLUSTER_FRAME.match(text))]
    if len(tasks) != options.frames:
        sys.exit(f"farm_throughput: {len(tasks)} frames reported by the cluster, not {options.frames}")
    first_of = {}
    for _, m in tasks:
        first_of.setdefault(m.group(5), m.group(1))
    later = [float(m.group(2)) for _, m in tasks if m.group(1) not in first_of.values()]
    into["frame"].append(statistics.median(later or [float(m.group(2)) for _, m in tasks]))
    overheads = [float(m.group(3)) - float(m.group(2)) for _, m in tasks]
    into["task_overhead"].append(statistics.median(overheads))
    into["max_overhead"].append(max(overheads))
    into["start"].append(tasks[0][0])
    last_worker = tasks[-1][1].group(4)
    others_done = max((at for at, m in tasks if m.group(4) != last_worker), default=tasks[-1][0])
    into["tail"].append(tasks[-1][0] - others_done)
    rendering = sum(float(m.group(2)) for _, m in tasks)
    into["amortised"].append((wall * options.workers - rendering) / options.frames)
    into["blender_beyond_frames"].append(cpu[0]["blender"] - rendering * options.cluster_threads)


def measure(blend, work, options):
    """Medians over the rounds: ``single`` (wall, cpu_total, frame) and per cluster command
    (``cluster``, and ``other`` with --compare-with) its wall time, CPU per kind and task figures."""
    common = [
        f"--frames=1-{options.frames}",
        f"--resolution={options.resolution}",
        f"--samples={options.samples}",
        "--beta=0,0.48,-0.13",
    ]
    cores = os.cpu_count() or 1
    single = [sys.executable, RENDER_SCRIPT, blend, *common, f"--out={os.path.join(work, 'single', 'f.png')}"]
    single.append(f"--threads={cores}")
    clusters = {"cluster": RENDER_SCRIPT}
    if options.compare_with:
        clusters["other"] = os.path.join(os.path.abspath(options.compare_with), "examples", "render.py")
    commands = {
        name: [
            sys.executable,
            script,
            blend,
            *common,
            f"--out={os.path.join(work, name, 'f.png')}",
            f"--workers={options.workers}",
            f"--threads={options.cluster_threads}",
            "--no-resume",
        ]
        for name, script in clusters.items()
    }
    keys = ("wall", "cpu_coordinator", "cpu_dask", "cpu_blender", "cpu_total", "frame", "task_overhead")
    keys += ("max_overhead", "start", "tail", "amortised", "blender_beyond_frames")
    results = {name: {key: [] for key in keys} for name in ["single", *commands]}
    run([*single[:3], "--frames=1-1", *single[4:]])  # warm-up: file cache, bytecode, kernels
    for _ in range(options.repeats):
        cpu = []
        wall, lines = run(single, cpu)
        results["single"]["wall"].append(wall)
        results["single"]["cpu_total"].append(cpu[0]["total"])
        frames = [float(m.group(2)) for _, text in lines if (m := SINGLE_FRAME.match(text))]
        results["single"]["frame"].append(statistics.median(frames[1:] or frames))
        for name, command in commands.items():
            _cluster_round(command, options, results[name])
    return {
        name: {key: statistics.median(values) for key, values in figures.items() if values}
        for name, figures in results.items()
    }


def _report(name, m, single, options):
    print(f"  {name}: {m['wall']:7.2f} s, {options.frames / m['wall']:.3f} frames/s")
    print(f"    throughput, cluster / single process: {single['wall'] / m['wall']:.2f}")
    print(
        f"    CPU: {m['cpu_total']:.1f} s (coordinator with scheduler and nannies {m['cpu_coordinator']:.1f} s, "
        f"Dask worker processes {m['cpu_dask']:.1f} s, Blender processes {m['cpu_blender']:.1f} s)"
    )
    ratio = single["cpu_total"] / m["cpu_total"]
    verdict = "met" if ratio >= 0.93 else "not met"
    print(f"    CPU ratio, single process / cluster: {ratio:.3f} (target >= 0.93: {verdict})")
    print(
        f"    Blender processes' CPU beyond their frames' times x {options.cluster_threads} thread(s): "
        f"{m['blender_beyond_frames']:.1f} s (starts, and threads busy beside the render; idle machine only)"
    )
    print(f"    a frame in a running Blender process: {m['frame']:.2f} s (worker, {options.cluster_threads} thread(s))")
    print(f"    per-task overhead (task on its worker minus the frame in Blender): median {m['task_overhead']:.3f} s,")
    print(f"      largest {m['max_overhead']:.2f} s (a worker's first task: waits for its Blender to be set up)")
    print(f"    launch to the first finished frame: {m['start']:.2f} s; tail (last frame after the")
    print(f"      other workers' last): {m['tail']:.2f} s")
    print(f"    amortised overhead per frame (cluster wall x workers - render times, / frames): {m['amortised']:.2f} s")


def parts(blend, work, options):
    """Print where a Blender process's CPU goes (``--parts``)."""
    common = [blend, f"--resolution={options.resolution}", f"--samples={options.samples}", "--beta=0,0.48,-0.13"]
    cores = os.cpu_count() or 1
    cases = [
        (f"worker's process, {options.cluster_threads} thread(s), as started now", options.cluster_threads, "1"),
        (f"the same, {options.cluster_threads} thread(s), bpy imported on every CPU", options.cluster_threads, "0"),
        (f"single process, {cores} threads", cores, "0"),
    ]
    print("CPU seconds per part; per frame: median of the frames after the first (first frame in brackets)")
    for label, threads, start_on_one in cases:
        out = os.path.join(work, f"parts-{threads}-{start_on_one}", "f_####.png")
        command = [sys.executable, "-c", PARTS, REPO_ROOT, str(threads), start_on_one, str(options.frames)]
        command += [*common, f"--out={out}"]
        result = subprocess.run(command, capture_output=True, text=True, env=ENV, cwd=REPO_ROOT, check=False)
        rows = [json.loads(line) for line in result.stdout.splitlines() if line.startswith("{")]
        if result.returncode != 0 or len(rows) != options.frames or any(row["reason"] for row in rows):
            sys.exit(f"farm_throughput: --parts failed: {result.stderr[-1500:]} {rows}")
        print(
            f"  {label}: import bpy {rows[0]['import bpy']:.2f}, file and add-on {rows[0]['file, add-on']:.2f}, ",
            end="",
        )
        print(f"effect {rows[0]['effect']:.2f}")
        for key, text in (
            ("wall", "frame's wall time"),
            ("cpu", "frame's CPU"),
            ("ended", "threads that ended with the frame (the render's)"),
            ("main", "main thread, the add-on's handlers apart"),
            ("handlers", "the add-on's handlers"),
            ("lived", "threads that lived before the frame"),
        ):
            later = statistics.median(row[key] for row in rows[1:]) if len(rows) > 1 else rows[0][key]
            print(f"    {text}: {later:.3f} ({rows[0][key]:.3f})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=16)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="default: one per core")
    parser.add_argument("--cluster-threads", type=int, default=1, help="Cycles threads of each worker's Blender")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--compare-with", help="another checkout whose cluster runs too, after this one's")
    parser.add_argument("--parts", action="store_true", help="where a Blender process's CPU goes, part by part")
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
    if options.parts:
        print(
            f"--parts: {options.frames} frames of {options.resolution}, {options.samples} samples, exact camera; load "
            f"average at the start {os.getloadavg()[0]:.2f}"
        )
        parts(blend, work, options)
        print(f"(load average at the end: {os.getloadavg()[0]:.2f})")
        return
    print(
        f"{options.frames} frames of {options.resolution}, {options.samples} samples, exact camera; one process "
        f"({os.cpu_count()} threads) vs Dask LocalCluster of {options.workers} single-threaded workers (a long-lived "
        f"Blender process each, {options.cluster_threads} Cycles thread(s)); medians of {options.repeats} alternating "
        f"rounds; load average at the start {os.getloadavg()[0]:.2f}",
        flush=True,
    )
    m = measure(blend, work, options)
    single = m["single"]
    print(f"  single process:  {single['wall']:7.2f} s, {options.frames / single['wall']:.3f} frames/s")
    print(f"    CPU: {single['cpu_total']:.1f} s; a frame {single['frame']:.2f} s ({os.cpu_count()} threads)")
    _report("cluster", m["cluster"], single, options)
    if "other" in m:
        _report(f"cluster of {options.compare_with}", m["other"], single, options)
    print(f"(load average at the end: {os.getloadavg()[0]:.2f})")


if __name__ == "__main__":
    main()
