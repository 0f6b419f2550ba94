"""Render time of the relativistic OSL camera against Blender's perspective camera.

    python benchmarks/camera_overhead.py [--samples 128] [--resolution 160x120] [--repeats 5]

Same lit scene (with Blender's default constant world), same seed, Cycles on the CPU. The
cameras are rendered alternately (perspective, relativistic at rest, relativistic at speed, the
minimal OSL camera, then again) so that load from other processes hits all of them alike; each
round's times are divided by that round's perspective time and by its minimal OSL camera's time,
and the median ratios over the rounds are printed, next to the median times: wall-clock time and
the process's CPU time (user + system, all threads: less disturbed by other processes than the
wall clock, though not free of them on a loaded machine). The load average is printed with them.
At beta = 0 the cameras trace the same rays, so the ratio is the camera's own cost; at speed
the view itself changes (more or less geometry in frame), which is not camera overhead. The
minimal OSL camera (``tools/osl_camera_ops.py``) traces the perspective camera's rays in three
lines of OSL: what Cycles charges any OSL camera, the floor under the exact camera's cost.
"""

import argparse
import math
import os
import resource
import statistics
import sys
import tempfile
import time

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "tools"))

MINIMAL = "minimal OSL camera"


def empty_cycles_scene(bpy, resolution, samples):
    """Blender's empty factory scene rendered by Cycles on the CPU at ``resolution``, ``samples``
    samples, no denoising or adaptive sampling (what every benchmark compares)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    return scene


def build_scene(bpy, resolution, samples):
    scene = empty_cycles_scene(bpy, resolution, samples)
    from relativity_addon.blender.common import compat

    scene.world = bpy.data.worlds.new("World")  # Blender's default: a constant grey Background
    compat.world_node_tree(scene.world).nodes["Background"].inputs["Color"].default_value = (0.05, 0.05, 0.05, 1.0)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (1.5, -6.0, 2.0)
    camera.rotation_euler = (math.radians(75.0), 0.0, math.radians(20.0))
    scene.collection.objects.link(camera)
    scene.camera = camera
    bpy.ops.mesh.primitive_plane_add(size=20.0)
    bpy.ops.mesh.primitive_cube_add(size=1.5, location=(0.5, 0.0, 0.75))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, location=(-1.5, 1.0, 0.7))
    light = bpy.data.objects.new("Light", bpy.data.lights.new("Light", "POINT"))
    light.data.energy = 800.0
    light.location = (2.0, -2.0, 4.0)
    scene.collection.objects.link(light)
    return scene


def _cpu_seconds():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def timed_render_clocks(bpy, scene, path):
    """Wall-clock and CPU seconds of one render (handlers, synchronisation, compositor included)."""
    scene.render.filepath = path
    start, cpu_start = time.perf_counter(), _cpu_seconds()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - start, _cpu_seconds() - cpu_start


def timed_render(bpy, scene, path):
    return timed_render_clocks(bpy, scene, path)[0]


def load_average():
    return "load average " + ", ".join(f"{value:.2f}" for value in os.getloadavg())


def minimal_osl_camera(projection):
    """The case function of the minimal OSL camera for ``projection`` (``PERSP`` or ``EQUIRECTANGULAR``)."""
    from osl_camera_ops import minimal_camera

    return lambda scene: minimal_camera(scene, projection)


def compare_cameras(bpy, scene, cases, repeats, out, prefix=""):
    """Renders ``cases`` (label and beta: None for Blender's own camera, or a function of the scene
    that sets up another camera and returns the function undoing it; the first case is the
    reference) alternately ``repeats`` times after one warm-up round (shader compilation, kernel
    loading, caches) and prints each case's median time and its median ratio to the reference's
    time of that round, wall clock and CPU, and to the minimal OSL camera's (a case labelled
    ``MINIMAL``) where there is one."""
    from relativity_addon.blender.pipeline import effect

    def render(beta, name):
        undo = None
        if beta is None or callable(beta):
            effect.remove(scene)
            undo = beta(scene) if beta is not None else None
        else:
            scene.relativity.beta = beta
            effect.apply(scene)
        seconds = timed_render_clocks(bpy, scene, os.path.join(out, prefix + name))
        if undo is not None:
            undo()
        return seconds

    for _, beta in cases:
        render(beta, "warmup.png")
    times = {label: [] for label, _ in cases}
    for round_index in range(repeats):
        for label, beta in cases:
            times[label].append(render(beta, f"{round_index}.png"))
    effect.remove(scene)
    labels = [label for label, _ in cases]
    references = [labels[0]] + ([MINIMAL] if MINIMAL in labels else [])

    def ratios(label, reference, clock):
        return [mine[clock] / theirs[clock] for mine, theirs in zip(times[label], times[reference], strict=True)]

    def spread(values):
        return f"{statistics.median(values):5.3f} ({min(values):.3f}-{max(values):.3f})"

    short = [reference.split()[0].removesuffix("'s") for reference in references]
    header = "".join(f"   {'wall / ' + name:21s} {'cpu / ' + name:21s}" for name in short)
    print(f"  {'':24s} {'wall s':>7s} {'cpu s':>7s}{header}")
    for label in labels:
        columns = "".join(
            f"   {spread(ratios(label, reference, 0))}   {spread(ratios(label, reference, 1))}"
            for reference in references
        )
        wall = statistics.median(t[0] for t in times[label])
        cpu = statistics.median(t[1] for t in times[label])
        print(f"  {label:24s} {wall:7.3f} {cpu:7.3f}{columns}")
    print(f"  ({load_average()})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=128)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--repeats", type=int, default=5)
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy

    import relativity_addon

    relativity_addon.register()
    scene = build_scene(bpy, resolution, options.samples)
    out = tempfile.mkdtemp(prefix="camera-overhead-")
    cases = (
        ("perspective", None),
        ("relativistic beta=0", (0.0, 0.0, 0.0)),
        ("relativistic beta=0.5 fwd", (0.0, 0.48, -0.13)),
        (MINIMAL, minimal_osl_camera("PERSP")),
    )
    rounds = f"{options.repeats} alternating rounds"
    print(f"{options.resolution}, {options.samples} samples, {rounds}, medians ({load_average()}):")
    compare_cameras(bpy, scene, cases, options.repeats, out)


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
