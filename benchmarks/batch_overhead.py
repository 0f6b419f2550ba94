"""Fixed cost per frame of the batch script against a plain render, each in a fresh process.

    python benchmarks/batch_overhead.py [--repeats 5] [--resolution 64x48] [--samples 1]
        [--beta=0,0.48,-0.13] [--grid VERTICES] [--phases] [--as-environment]

A tiny frame (64x48, 1 sample) makes the render itself negligible, so what is left is the cost a
user pays per invocation of ``examples/render.py FILE.blend --out X.png ...``: start Python and
Blender, open the file, enable the add-on, apply the effect (OSL compilation, lookup-table
images, node groups), render and write. It is measured against a plain render of the same file in
a fresh process (open it with bpy, render, write the PNG), for ``--method camera`` and
``--method geometry``. The three commands run alternately (plain, camera, geometry, then again),
so that load from other processes hits them alike; per round the differences to that round's
plain run are taken, and medians over the rounds are printed. Peak memory is the child's peak
resident set size (``os.wait4``'s ``ru_maxrss``).

``--phases`` also runs one instrumented fresh process per method that times each phase of the
batch script and reads the resident set size (VmRSS) and its peak (VmHWM) after it, and lists the
heaviest modules the add-on imports.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RENDER_SCRIPT = os.path.join(REPO_ROOT, "examples", "render.py")

BUILD_SCENE = """
import sys
sys.path.insert(0, sys.argv[1])
import bpy
from camera_overhead import build_scene
build_scene(bpy, (64, 48), 1)
side = int(int(sys.argv[3]) ** 0.5)
if side > 1:  # a heavy mesh in view: the geometry method's per-frame update scales with it
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=side - 1, y_subdivisions=side - 1, size=3.0,
                                    location=(-0.5, 1.5, 1.5))
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[2], check_existing=False)
"""

PLAIN_RENDER = """
import sys
import bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = int(sys.argv[3])
scene.render.resolution_x, scene.render.resolution_y = (int(v) for v in sys.argv[4].split("x"))
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "PNG"
scene.render.use_file_extension = False
scene.render.filepath = sys.argv[2]
bpy.ops.render.render(write_still=True)
"""

# One batch run, phase by phase, in the order of batch.run; sub-phases of applying the effect are
# timed by wrapping the add-on functions that do them (self time: nested calls are subtracted).
PHASES = r"""
import os, sys, time
started_epoch = time.time()
sys.path.insert(0, sys.argv[1])
blend, out, method, beta, samples, resolution = sys.argv[2:8]

def memory():
    fields = {}
    with open("/proc/self/status") as status:
        for line in status:
            key, _, value = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                fields[key] = int(value.split()[0]) / 1024.0
    return fields["VmRSS"], fields["VmHWM"]

rows = []
start = time.perf_counter()
last = [start]

def phase(label):
    now = time.perf_counter()
    rss, hwm = memory()
    rows.append((label, now - last[0], rss, hwm))
    last[0] = now

def render_and_write(scene, subphases=None):
    scene.render.filepath = out
    bpy.ops.render.render(write_still=False)
    phase("render (64x48)")
    bpy.data.images["Render Result"].save_render(out)
    phase("write the PNG")
    for label, seconds, rss, hwm in rows:
        print(f"PHASE\t{label}\t{seconds:.4f}\t{rss:.1f}\t{hwm:.1f}")
        if subphases and label == "apply the effect":
            for sub in sorted(subphases):
                print(f"SUB\t{sub}\t{subphases[sub]:.4f}")

phase("python start (to first line)")
rows.clear()
before = set(sys.modules)
import bpy
phase("import bpy")
bpy.ops.wm.open_mainfile(filepath=blend)
phase("open .blend")
if method == "plain":
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = int(samples)
    scene.render.resolution_x, scene.render.resolution_y = (int(v) for v in resolution.split("x"))
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    render_and_write(scene)
    print(f"EPOCHS\t{started_epoch}\t{time.time()}", flush=True)
    sys.exit(0)
before_addon = set(sys.modules)
from relativity_addon import batch
phase("import relativity_addon.batch")
batch.enable_addon()
phase("enable the add-on (register)")
addon_modules = sorted(set(sys.modules) - before_addon)

from relativity_addon.blender.camera import exact_camera as camera
from relativity_addon.blender.colour import compositing, lut_images as luts, materials
from relativity_addon.blender.pipeline import effect
from relativity_addon.blender.geometry import modifier
timers = {}
stack = []

def wrap(module, name, label):
    function = getattr(module, name)
    def timed(*args, **kwargs):
        stack.append(0.0)
        begun = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            spent = time.perf_counter() - begun
            nested = stack.pop()
            if stack:
                stack[-1] += spent
            timers[label] = timers.get(label, 0.0) + spent - nested
    setattr(module, name, timed)

wrap(camera, "compile_shader", "  OSL compile")
wrap(luts, "ensure_doppler_matrix_lut", "  LUT images (load + pack)")
wrap(luts, "ensure_blackbody_lut", "  LUT images (load + pack)")
wrap(materials, "ensure_node_groups", "  node groups")
wrap(compositing, "ensure_compositor_group", "  node groups")
wrap(modifier, "ensure_node_group", "  node groups")

options = batch.build_parser(True).parse_args(
    [blend, "--out", out, "--method", method, "--beta=" + beta, "--samples", samples, "--resolution", resolution])
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = options.samples
scene.render.resolution_x, scene.render.resolution_y = options.resolution
scene.render.resolution_percentage = 100
batch._output_format(scene, out)
batch._apply_options(scene, options)
scene.frame_set(scene.frame_current)
stack.append(0.0)
begun = time.perf_counter()
effect.apply(scene, frame_range=(scene.frame_current, scene.frame_current))
timers["  rest of applying"] = time.perf_counter() - begun - stack.pop()
phase("apply the effect")
apply_row = rows[-1]
render_and_write(scene, timers)
print("MODULES\t" + " ".join(addon_modules))
print(f"EPOCHS\t{started_epoch}\t{time.time()}", flush=True)
"""


ENV = dict(os.environ)
ENV.pop("PYTHONPATH", None)


def run_child(command, out_path=None):
    """Run ``command``; return (wall seconds, peak RSS MiB, stdout)."""
    if out_path and os.path.exists(out_path):
        os.remove(out_path)
    env = ENV
    with tempfile.TemporaryFile() as stdout, tempfile.TemporaryFile() as stderr:
        start = time.perf_counter()
        process = subprocess.Popen(command, stdout=stdout, stderr=stderr, env=env, cwd=REPO_ROOT)
        _, status, usage = os.wait4(process.pid, 0)
        seconds = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        stdout.seek(0)
        stderr.seek(0)
        output, errors = stdout.read().decode(), stderr.read().decode()
    if process.returncode != 0 or (out_path and not os.path.isfile(out_path)):
        sys.exit(f"batch_overhead: {command[1]} failed ({process.returncode}): {(errors or output)[-800:]}")
    return seconds, usage.ru_maxrss / 1024.0, output


def print_phases(blend, out_dir, method, options):
    launched = time.time()
    _, peak, output = run_child(
        [
            sys.executable,
            "-c",
            PHASES,
            REPO_ROOT,
            blend,
            os.path.join(out_dir, "phases.png"),
            method,
            options.beta,
            str(options.samples),
            options.resolution,
        ]
    )
    title = "plain render" if method == "plain" else f"batch script, --method {method}"
    print(f"\n{title}, one fresh process phase by phase (peak RSS {peak:.0f} MiB):")
    print(f"  {'phase':36s}{'time s':>8s}{'RSS MiB':>9s}{'peak MiB':>10s}")
    ended = time.time()
    first, last = (float(v) for v in output.split("EPOCHS\t")[1].splitlines()[0].split())
    print(f"  {'interpreter start (before line 1)':36s}{first - launched:8.3f}")
    for line in output.splitlines():
        fields = line.split("\t")
        if fields[0] == "PHASE":
            print(f"  {fields[1]:36s}{float(fields[2]):8.3f}{float(fields[3]):9.0f}{float(fields[4]):10.0f}")
        elif fields[0] == "SUB":
            print(f"  {fields[1]:36s}{float(fields[2]):8.3f}")
        elif fields[0] == "MODULES":
            modules = fields[1].split()
            roots = sorted({name.split(".")[0] for name in modules})
            print(f"  modules imported by enabling the add-on: {len(modules)}; top-level packages: {', '.join(roots)}")
    print(f"  {'exit (after the last line)':36s}{ended - last:8.3f}")


def print_table(seconds, peaks):
    plain_s, plain_m = seconds["plain render"], peaks["plain render"]
    print(f"  {'command':30s}{'wall s':>8s}{'+s vs plain':>13s}{'ratio':>7s}{'peak MiB':>10s}{'+MiB':>7s}{'ratio':>7s}")
    for label in seconds:
        extra_s = statistics.median(a - b for a, b in zip(seconds[label], plain_s, strict=True))
        ratio_s = statistics.median(a / b for a, b in zip(seconds[label], plain_s, strict=True))
        extra_m = statistics.median(a - b for a, b in zip(peaks[label], plain_m, strict=True))
        ratio_m = statistics.median(a / b for a, b in zip(peaks[label], plain_m, strict=True))
        print(
            f"  {label:30s}{statistics.median(seconds[label]):8.2f}{extra_s:+13.2f}{ratio_s:7.2f}"
            f"{statistics.median(peaks[label]):10.0f}{extra_m:+7.0f}{ratio_m:7.2f}"
        )
        if label != "plain render":
            print(
                f"  {'':30s}{'(range':>8s}{min(seconds[label]):5.2f}-{max(seconds[label]):.2f} s, "
                f"{min(peaks[label]):.0f}-{max(peaks[label]):.0f} MiB)"
            )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--resolution", default="64x48")
    parser.add_argument("--samples", type=int, default=1)
    parser.add_argument("--beta", default="0,0.48,-0.13", help="observer velocity for the batch script")
    parser.add_argument(
        "--grid",
        type=int,
        default=0,
        help="add a grid of about this many vertices to the scene (before the add-on's tessellation)",
    )
    parser.add_argument("--phases", action="store_true", help="also time each phase of the batch script")
    parser.add_argument(
        "--as-environment",
        action="store_true",
        help="keep PYTHONDONTWRITEBYTECODE if set (default: cache bytecode, as on a user's machine)",
    )
    options = parser.parse_args()

    work = tempfile.mkdtemp(prefix="batch-overhead-")
    if not options.as_environment:
        # A user's Python caches compiled bytecode; with PYTHONDONTWRITEBYTECODE set, every fresh
        # process compiles the add-on's sources again (the bpy wheel's own .pyc come with the
        # wheel). The cache goes to a scratch folder, never into the source tree.
        ENV.pop("PYTHONDONTWRITEBYTECODE", None)
        ENV["PYTHONPYCACHEPREFIX"] = os.path.join(work, "pycache")
    blend = os.path.join(work, "room.blend")
    subprocess.run(
        [sys.executable, "-c", BUILD_SCENE, os.path.dirname(os.path.abspath(__file__)), blend, str(options.grid)],
        check=True,
        capture_output=True,
    )
    out = os.path.join(work, "frame.png")
    common = [
        "--out",
        out,
        "--resolution",
        options.resolution,
        "--samples",
        str(options.samples),
        f"--beta={options.beta}",
    ]
    commands = {
        "plain render": [sys.executable, "-c", PLAIN_RENDER, blend, out, str(options.samples), options.resolution],
        "render.py --method camera": [sys.executable, RENDER_SCRIPT, blend, "--method", "camera", *common],
        "render.py --method geometry": [sys.executable, RENDER_SCRIPT, blend, "--method", "geometry", *common],
    }
    for command in commands.values():  # warm-up: file cache, OSL and kernel caches on disk
        run_child(command, out)
    seconds = {label: [] for label in commands}
    peaks = {label: [] for label in commands}
    for _ in range(options.repeats):
        for label, command in commands.items():
            wall, peak, _ = run_child(command, out)
            seconds[label].append(wall)
            peaks[label].append(peak)

    if options.repeats > 0:
        print(
            f"{options.resolution}, {options.samples} sample(s), fresh process each, {options.repeats} alternating "
            f"rounds, medians (load {os.getloadavg()[0]:.2f}):"
        )
        print_table(seconds, peaks)

    if options.phases:
        for method in ("plain", "camera", "geometry"):
            print_phases(blend, work, method, options)


if __name__ == "__main__":
    main()
