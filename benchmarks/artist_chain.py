"""What the artist waits for on the Apparent Geometry path, against Blender doing the same work.

    python benchmarks/artist_chain.py [--sizes 0.5M,2M,8M] [--scenes grid,objects]
        [--motions constant,keyframed,eased] [--tessellation default|0|N] [--rounds 3]
        [--resolution 64x48] [--samples 4] [--lamp] [--no-memory] [--profile chain.prof] [--parts 12]

Generated scenes: one grid mesh of about SIZE vertices, or SIZE / 2,000 small grids of 2,025
vertices each (1,000 objects at 2M), each a mesh of its own, 5 m in front of the camera, with
their own velocity: Constant Velocity (0.5c along x), or Animation (location keys: the same
motion keyframed). Two scenes in one file: ``Effect`` (set up on Apparent Geometry, the context
scene) and ``Plain`` (the same meshes, nothing set up); the add-on's handlers are taken out while
the plain scene is measured. In ONE process, rounds alternate between the two; each round's time
is divided by that round's plain time, and the median ratio is printed with the issue 26 target:

(a) velocity change: the panel's way (the property set from Python runs its update callback),
    until a vertex of the evaluated mesh is read after ``evaluated_depsgraph_get``: constant
    motion changes the velocity of the grid (of one object in the many-object scene); keyframed
    motion, whose velocity is its keys, changes the observer's velocity (every object moves).
    ``keyframed``: two linear location keys (uniform motion); ``eased``: the same keys with Blender's
    default Bezier interpolation (the motion eases in and out: accelerating at every frame).
    Plain: ``foreach_set`` of the same vertex positions (the objects the change moves) on the
    plain meshes, ``mesh.update()``, the plain scene's depsgraph updated, a vertex read.
    With constant motion also (a') the observer's velocity changed (every object moves) against the
    plain rewrite of every vertex; its target is keyframed motion's (twice the velocity change's).
(b) frame step (``frame_set`` to the next frame, a vertex read) against the plain rewrite of
    every vertex (a frame step moves every vertex).
(c) Set Up (the operator) against the plain rewrite.
(d) F12: ``render.render`` of each scene (small resolution, few samples), the observer at rest.
(e) peak memory (``VmHWM``, else ``ru_maxrss``) of a separate process that builds the scene,
    sets it up, changes the velocity, steps a frame and renders, against one doing the plain
    scene's equivalent (each builds its own scene only).

``--tessellation`` says what the meshes get (``default``: the add-on's default; ``0``: none);
the printed rows name it. ``--lamp`` adds a sun to both scenes: the lamp stage then adds a
light-linked copy of it per moving object (Blender links at most 64). ``--profile FILE`` writes
a cProfile of a Set Up, a velocity change and a frame step of the first case (read it with
``python -m pstats FILE``), and one of each step alone in ``FILE.setup``, ``FILE.velocity``, ``FILE.frame``.
``--parts N`` times N more velocity changes and N frame steps of the first case, each with the
add-on's parts (:data:`PARTS`) timed by ``time.perf_counter`` around them, unprofiled, and prints
the milliseconds per step each took (nested: a sync holds the others).
"""

import argparse
import cProfile
import math
import os
import pstats
import resource
import statistics
import subprocess
import sys
import time
from contextlib import contextmanager

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import numpy as np  # noqa: E402

SMALL_SIDE = 45  # 2,025 vertices per small object
C = 10.0  # speed of light, scene units per second
BETA = 0.5
# Issue 26's acceptance (2M vertices, tessellation at its default; keyframed: twice these).
TARGETS = {"velocity change": 3.0, "frame step": 3.0, "Set Up": None, "F12": 1.3, "peak memory": 1.5}


def parse_size(text):
    text = text.strip().upper()
    scale = {"K": 1e3, "M": 1e6}.get(text[-1:], 1.0)
    return int(float(text.rstrip("KM")) * scale)


def grid_mesh(bpy, name, side, size):
    """A flat ``side`` x ``side`` vertex grid (quads), ``size`` units wide, in the xy plane."""
    u = np.linspace(-size / 2, size / 2, side, dtype=np.float32)
    x, y = np.meshgrid(u, u)
    positions = np.stack([x.ravel(), y.ravel(), np.zeros(side * side, np.float32)], axis=1)
    i = np.arange(side - 1)
    corner = (i[None, :] + side * i[:, None]).ravel()
    loops = np.stack([corner, corner + 1, corner + side + 1, corner + side], axis=1).ravel()
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(side * side)
    mesh.attributes["position"].data.foreach_set("vector", positions.ravel())
    mesh.loops.add(len(loops))
    mesh.loops.foreach_set("vertex_index", loops.astype(np.int32))
    mesh.polygons.add(len(loops) // 4)
    mesh.polygons.foreach_set("loop_start", np.arange(0, len(loops), 4, dtype=np.int32))
    mesh.update(calc_edges=True)
    return mesh


def layout(kind, size):
    """[(side, width, location)] of the scene's meshes: one grid, or a 2-D array of small grids."""
    if kind == "grid":
        return [(int(math.ceil(math.sqrt(size))), 4.0, (0.0, 0.0, 0.0))]
    count = max(1, round(size / SMALL_SIDE**2))
    across = int(math.ceil(math.sqrt(count)))
    pitch = 4.0 / across
    return [
        (SMALL_SIDE, 0.8 * pitch, ((k % across + 0.5) * pitch - 2.0, (k // across + 0.5) * pitch - 2.0, 0.0))
        for k in range(count)
    ]


def build_objects(bpy, scene, kind, size, motion, tessellation):
    objects = []
    template = {}
    for k, (side, width, location) in enumerate(layout(kind, size)):
        if (side, width) not in template:
            template[(side, width)] = grid_mesh(bpy, f"{scene.name} grid", side, width)
        mesh = template[(side, width)] if not objects else template[(side, width)].copy()
        obj = bpy.data.objects.new(f"{scene.name} {k:05d}", mesh)
        obj.location = location
        scene.collection.objects.link(obj)
        objects.append(obj)
        if motion in ("keyframed", "eased"):
            for frame in (-240, 480):  # keys around every retarded time the rounds use
                obj.location.x = location[0] + BETA * C * (frame - 1) / scene.render.fps
                obj.keyframe_insert("location", index=0, frame=frame)
            if motion == "keyframed":
                _linear(obj)  # "eased": Blender's default Bezier keys, accelerating everywhere
    return objects


def _linear(obj):
    """Linear interpolation of the location keys (4.5: action.fcurves; 5.x: layered actions)."""
    action = obj.animation_data.action
    curves = getattr(action, "fcurves", None)
    if curves is None or not len(curves):
        curves = [
            curve
            for layer in getattr(action, "layers", ())
            for strip in layer.strips
            for bag in strip.channelbags
            for curve in bag.fcurves
        ]
    for curve in curves:
        for point in curve.keyframe_points:
            point.interpolation = "LINEAR"


def build(bpy, kind, size, motion, tessellation, resolution, samples, only=None, lamp=False):
    """The ``Effect`` scene (context scene, not set up yet) and the ``Plain`` scene (``only``: the
    one named; the other is empty)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    effect_scene = bpy.context.scene
    effect_scene.name = "Effect"
    plain_scene = bpy.data.scenes.new("Plain")
    scenes = {"Effect": [], "Plain": []}
    for scene in (effect_scene, plain_scene):
        if only not in (None, scene.name):
            continue
        scene.render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = samples
        scene.cycles.use_denoising = False
        scene.render.resolution_x, scene.render.resolution_y = resolution
        scene.render.resolution_percentage = 100
        scene.render.fps = 24
        scene.frame_start, scene.frame_end = 1, 240
        camera = bpy.data.objects.new(f"{scene.name} camera", bpy.data.cameras.new(f"{scene.name} camera"))
        camera.location = (0.0, 0.0, 5.0)
        scene.collection.objects.link(camera)
        scene.camera = camera
        if lamp:  # the lamp stage then adds a light-linked copy per moving object
            light = bpy.data.objects.new(f"{scene.name} sun", bpy.data.lights.new(f"{scene.name} sun", "SUN"))
            scene.collection.objects.link(light)
        scene.frame_set(12)
        scenes[scene.name] = build_objects(bpy, scene, kind, size, motion, tessellation)
    effect_scene.relativity.speed_of_light = C
    effect_scene.relativity.method = "GEOMETRY"
    for obj in scenes["Effect"]:
        settings = obj.relativity
        if tessellation is not None:
            settings.tessellation = tessellation
        settings.motion = "CONSTANT" if motion == "constant" else "ANIMATION"
        if motion == "constant":
            settings.beta = (BETA, 0.0, 0.0)
    return effect_scene, plain_scene, scenes["Effect"], scenes["Plain"]


@contextmanager
def without_addon_handlers(bpy):
    """The add-on's handlers out of Blender's lists (the plain scene is Blender without it)."""
    taken = []
    for name in dir(bpy.app.handlers):
        handlers = getattr(bpy.app.handlers, name)
        if isinstance(handlers, list):
            for handler in list(handlers):
                if getattr(handler, "__module__", "").endswith("pipeline.handlers"):
                    handlers.remove(handler)
                    taken.append((handlers, handler))
    try:
        yield
    finally:
        for handlers, handler in taken:
            handlers.append(handler)


def read_vertex(bpy, obj, depsgraph):
    return obj.evaluated_get(depsgraph).data.vertices[0].co.x


def plain_rewrite(bpy, scene, objects, offset):
    """The plain equivalent: every vertex of ``objects`` rewritten (foreach_set), updated, read."""
    for obj in objects:
        mesh = obj.data
        positions = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.attributes["position"].data.foreach_get("vector", positions)
        positions[0::3] += offset
        mesh.attributes["position"].data.foreach_set("vector", positions)
        mesh.update()
    depsgraph = scene.view_layers[0].depsgraph
    depsgraph.update()
    return read_vertex(bpy, objects[0], depsgraph)


# (module under relativity_addon.blender, function): the add-on's parts ``--parts`` times.
PARTS = (
    ("pipeline.effect", "sync"),
    ("pipeline.records", "record"),
    ("scene.snapshot", "read"),
    ("geometry.apparent_meshes", "update"),
    ("geometry.apparent_meshes", "update_object"),
    ("geometry.straight_steps", "step"),
    ("geometry.clip_end", "clip_end_warnings"),
    ("geometry.instancing", "check_instancing"),
    ("geometry.changes", "cache_notes"),
    ("scene.moving_objects", "fastest_speed"),
    ("scene.animation", "_keyframes_signature"),
)


@contextmanager
def timed_parts():
    """Inside: every function of :data:`PARTS` adds its wall time and calls to the yielded
    {name: [seconds, calls]} (module attributes replaced: callers look them up at each call)."""
    import importlib

    totals = {}
    replaced = []
    for module_name, name in PARTS:
        module = importlib.import_module(f"relativity_addon.blender.{module_name}")
        original = getattr(module, name)
        total = totals[f"{module_name.split('.')[-1]}.{name}"] = [0.0, 0]

        def timed_part(*args, _original=original, _total=total, **kwargs):
            start = time.perf_counter()
            try:
                return _original(*args, **kwargs)
            finally:
                _total[0] += time.perf_counter() - start
                _total[1] += 1

        setattr(module, name, timed_part)
        replaced.append((module, name, original))
    try:
        yield totals
    finally:
        for module, name, original in replaced:
            setattr(module, name, original)


def print_parts(label, steps, walls, totals):
    print(f"\n{label}: {steps} steps, median {statistics.median(walls):.3f} s (parts in ms per step, calls per step)")
    for name, (seconds, calls) in sorted(totals.items(), key=lambda item: -item[1][0]):
        if calls:
            print(f"  {name:40s} {seconds / steps * 1e3:8.1f} ms  {calls / steps:8.1f}")


def timed(function, *args):
    start = time.perf_counter()
    function(*args)
    return time.perf_counter() - start


def measure_case(bpy, options, kind, size, motion):
    """{step: (median effect s, median plain s, median ratio)} of one scene, alternating rounds."""
    from relativity_addon.blender.pipeline import effect

    effect_scene, plain_scene, movers, plain = build(
        bpy, kind, size, motion, options.tessellation, options.resolution, options.samples, lamp=options.lamp
    )
    results = {}

    def alternate(step, run_effect, run_plain):
        rows = []
        for round_ in range(options.rounds):
            with without_addon_handlers(bpy):
                plain_time = timed(run_plain, round_)
            rows.append((timed(run_effect, round_), plain_time))
        results[step] = (
            statistics.median(e for e, _ in rows),
            statistics.median(p for _, p in rows),
            statistics.median(e / p for e, p in rows),
        )

    set_up = bpy.ops.relativity.setup_scene

    def run_setup(_round):
        effect.remove(effect_scene)
        assert set_up() == {"FINISHED"}, "Set Up failed"
        read_vertex(bpy, movers[0], bpy.context.evaluated_depsgraph_get())

    alternate("Set Up", run_setup, lambda r: plain_rewrite(bpy, plain_scene, plain, 1e-3 * (r + 1)))
    changed = movers[:1] if motion == "constant" else movers
    plain_changed = plain[: len(changed)]

    def velocity_change(round_):
        value = BETA + 0.01 * (round_ % 2 + 1)
        if motion == "constant":
            movers[0].relativity.beta = (value, 0.0, 0.0)
        else:
            effect_scene.relativity.beta = (0.0, 0.0, 0.01 * (round_ % 2 + 1))
        read_vertex(bpy, changed[0], bpy.context.evaluated_depsgraph_get())

    alternate("velocity change", velocity_change, lambda r: plain_rewrite(bpy, plain_scene, plain_changed, 1e-3))
    if motion == "constant":  # (keyframed motion's velocity change is the observer's already)

        def observer_change(round_):
            effect_scene.relativity.beta = (0.0, 0.0, 0.01 * (round_ % 2 + 1))
            read_vertex(bpy, movers[-1], bpy.context.evaluated_depsgraph_get())

        alternate("observer change", observer_change, lambda r: plain_rewrite(bpy, plain_scene, plain, 1e-3))
    effect_scene.relativity.beta = (0.0, 0.0, 0.0)
    bpy.context.evaluated_depsgraph_get()  # as the viewport's redraw: the frame step does not pay for it

    def frame_step(round_):
        effect_scene.frame_set(13 + round_)
        read_vertex(bpy, movers[-1], bpy.context.evaluated_depsgraph_get())

    alternate("frame step", frame_step, lambda r: plain_rewrite(bpy, plain_scene, plain, 1e-3))
    if options.profile:
        # one file per step (FILE.setup, FILE.velocity, FILE.frame) and FILE with the three together
        files = []
        for suffix, step, argument in (
            ("setup", run_setup, 0),
            ("velocity", velocity_change, 0),
            ("frame", frame_step, options.rounds + 1),
        ):
            profile = cProfile.Profile()
            profile.runcall(step, argument)
            files.append(f"{options.profile}.{suffix}")
            profile.dump_stats(files[-1])
        pstats.Stats(*files).dump_stats(options.profile)
        options.profile = None
        effect_scene.relativity.beta = (0.0, 0.0, 0.0)  # (the profiled velocity change's): F12 at rest
        bpy.context.evaluated_depsgraph_get()
    if options.parts:
        steps = (("velocity change", velocity_change, 0), ("frame step", frame_step, options.rounds + 2))
        for label, step, first in steps:
            with timed_parts() as totals:
                walls = [timed(step, first + k) for k in range(options.parts)]
            print_parts(f"{kind}, {motion} motion, {label}", options.parts, walls, totals)
        options.parts = 0
        effect_scene.relativity.beta = (0.0, 0.0, 0.0)
        bpy.context.evaluated_depsgraph_get()
    alternate(
        "F12",
        lambda r: bpy.ops.render.render(scene=effect_scene.name),
        lambda r: bpy.ops.render.render(scene=plain_scene.name),
    )
    vertices = sum(len(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.vertices) for obj in movers)
    return results, vertices


def child_memory(bpy, options, kind, size, motion, with_effect):
    """Peak resident memory (bytes) of a process doing the case with or without the effect."""
    effect_scene, plain_scene, movers, plain = build(
        bpy,
        kind,
        size,
        motion,
        options.tessellation,
        options.resolution,
        options.samples,
        only="Effect" if with_effect else "Plain",
        lamp=options.lamp,
    )
    if with_effect:
        assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
        movers[0].relativity.beta = (BETA + 0.01, 0.0, 0.0)
        read_vertex(bpy, movers[0], bpy.context.evaluated_depsgraph_get())
        effect_scene.frame_set(13)
        read_vertex(bpy, movers[0], bpy.context.evaluated_depsgraph_get())
        bpy.ops.render.render(scene=effect_scene.name)
    else:
        with without_addon_handlers(bpy):
            plain_rewrite(bpy, plain_scene, plain, 1e-3)
            plain_scene.frame_set(13)
            plain_rewrite(bpy, plain_scene, plain, 1e-3)
            bpy.ops.render.render(scene=plain_scene.name)
    return peak_resident_bytes()


def peak_resident_bytes():
    """This process's peak resident memory: ``VmHWM`` (Linux), else ``ru_maxrss``. A child started
    from a large process inherits that process's ``ru_maxrss`` across exec (measured: every case
    read the parent's 2.06 GB); ``VmHWM`` is its own address space's high-water mark."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # kilobytes on Linux


def peak_memory(options, kind, size, motion):
    peaks = []
    for with_effect in (False, True):
        command = [
            sys.executable,
            os.path.abspath(__file__),
            "--child-memory",
            f"{kind},{size},{motion},{int(with_effect)}",
        ]
        command += ["--tessellation", options.tessellation_text, "--samples", str(options.samples)]
        command += ["--resolution", "x".join(map(str, options.resolution))] + ["--lamp"] * options.lamp
        output = subprocess.run(command, capture_output=True, text=True, check=False).stdout
        lines = [line for line in output.splitlines() if line.startswith("peak_bytes ")]
        if not lines:
            return None
        peaks.append(int(lines[-1].split()[1]))
    return peaks[1], peaks[0], peaks[1] / peaks[0]


def print_case(label, results, vertices):
    print(f"\n{label}: {vertices:,} evaluated vertices of moving meshes")
    print(f"{'':<18}{'effect':>10}{'plain':>10}{'ratio':>8}{'target':>8}")
    for step, (effect_value, plain_value, ratio) in results.items():
        target = TARGETS.get(step) if step != "observer change" else 2.0 * TARGETS["velocity change"]
        unit = "GB" if step == "peak memory" else "s"
        scale = 1e-9 if step == "peak memory" else 1.0
        target_text = f"{target:.1f}" if target else "-"
        print(
            f"{step:<18}{effect_value * scale:>9.3f}{unit[0]}{plain_value * scale:>9.3f}{unit[0]}"
            f"{ratio:>8.2f}{target_text:>8}"
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="0.5M")
    parser.add_argument("--scenes", default="grid,objects")
    parser.add_argument("--motions", default="constant,keyframed")
    parser.add_argument("--tessellation", default="default")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--resolution", default="64x48")
    parser.add_argument("--samples", type=int, default=4)
    parser.add_argument("--no-memory", action="store_true")
    parser.add_argument("--lamp", action="store_true", help="a sun in each scene (the lamp stage's copies)")
    parser.add_argument("--profile", default=None)
    parser.add_argument("--parts", type=int, default=0, help="time the add-on's parts over N more steps")
    parser.add_argument("--child-memory", default=None, help=argparse.SUPPRESS)
    options = parser.parse_args()
    options.tessellation_text = options.tessellation
    options.tessellation = None if options.tessellation == "default" else int(options.tessellation)
    options.resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy

    from relativity_addon import batch

    batch.enable_addon()
    if options.child_memory:
        kind, size, motion, with_effect = options.child_memory.split(",")
        print("peak_bytes", child_memory(bpy, options, kind, int(size), motion, bool(int(with_effect))), flush=True)
        return 0
    load = os.getloadavg()
    print(f"Blender {bpy.app.version_string}, tessellation {options.tessellation_text}, {options.rounds} rounds")
    print(f"load average at start: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    for size in map(parse_size, options.sizes.split(",")):
        for kind in options.scenes.split(","):
            for motion in options.motions.split(","):
                results, vertices = measure_case(bpy, options, kind, size, motion)
                if not options.no_memory:
                    memory = peak_memory(options, kind, size, motion)
                    if memory is not None:
                        results["peak memory"] = memory
                count = len(layout(kind, size))
                label = f"{kind} ({count:,} object{'s' * (count > 1)}), {size:,} vertices, {motion} motion"
                print_case(label, results, vertices)
                sys.stdout.flush()
    load = os.getloadavg()
    print(f"\nload average at end: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print("targets (issue 26, 2M vertices, tessellation at its default): keyframed motion twice the figures")
    return 0


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
