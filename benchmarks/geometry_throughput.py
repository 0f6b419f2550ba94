"""Apparent-geometry throughput and render overhead of the mesh path.

    python benchmarks/geometry_throughput.py [--vertices 1000000] [--samples 32]
        [--resolution 160x120] [--repeats 3]

1. Physics core (``physics/apparent.py``), numpy only: apparent positions of N vertices for
   constant velocity (closed form) and for a keyframed rigid motion (rotation + translation
   sampled on a sub-frame grid, per-vertex retarded times by ``apparent_positions_sampled``'s Halley
   iteration).
2. The add-on's full update (``snapshot.read`` and ``geometry.update_object``): read the tessellated rest
   positions
   from the evaluated mesh, compute, write the cache mesh; N-vertex grid, constant velocity and
   keyframed rotation.
3. Render time of a small lit scene with the mesh path applied (observer at 0.8c) against the
   plain render of the same scene, rendered alternately; the median ratio is printed.

Throughputs are printed next to the targets of issue 4 (on a 2-core machine): keyframed motion at
least 2 M vertices/s in both the physics core and the add-on update, constant velocity at least
10 M vertices/s for the add-on's whole update (read the evaluated rest positions, compute, write
the cache mesh). Timings are the best of ``--repeats`` runs.
"""

import argparse
import math
import os
import statistics
import sys
import tempfile
import time

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import numpy as np  # noqa: E402

# Issue 4, vertices per second for 1M vertices a frame: keyframed motion in both the physics core
# and the add-on update; constant velocity for the add-on's whole update.
KEYFRAMED_TARGET = 2e6
CONSTANT_VELOCITY_TARGET = 10e6


def print_throughput_table(rows):
    """``rows``: (label, vertices, measured vertices/s, target vertices/s or None)."""
    print(f"{'throughput, M vertices/s':<56}{'measured':>9}{'target':>8}")
    for label, vertices, measured, target in rows:
        target_text = "-" if target is None else f"{target / 1e6:.0f}"
        verdict = "" if target is None else ("  met" if measured >= target else "  MISSED")
        print(f"{f'{label}, {vertices} vertices':<56}{measured / 1e6:>9.2f}{target_text:>8}{verdict}")


def best_time(function, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def core_throughput(count, repeats):
    from relativity_addon.physics import apparent

    rng = np.random.default_rng(1)
    points = rng.uniform(-1.0, 1.0, (count, 3)) + np.array([0.0, 0.0, -6.0])
    c, t_o, x_o = 10.0, 1.0, np.zeros(3)
    uniform = best_time(
        lambda: apparent.apparent_positions_uniform(t_o, x_o, points, (0.9, 0.0, 0.0), c, (0.0, 0.3, 0.0)), repeats
    )
    # Wheel-like rigid motion: spin about z at 4 rad/s while drifting (|v| < 0.9 c); 24 fps, 8 samples a frame.
    times = np.arange(-2.0, 1.5, 1.0 / 192.0)
    angle = 4.0 * times
    matrices = np.zeros((len(times), 4, 4))
    matrices[:, 0, 0], matrices[:, 0, 1] = np.cos(angle), -np.sin(angle)
    matrices[:, 1, 0], matrices[:, 1, 1] = np.sin(angle), np.cos(angle)
    matrices[:, 2, 2] = matrices[:, 3, 3] = 1.0
    matrices[:, 0, 3] = 2.0 * times
    matrices[:, 2, 3] = -6.0
    local = points - np.array([0.0, 0.0, -6.0])
    motion = apparent.SampledRigidMotion(times, matrices, local)
    keyframed = best_time(lambda: apparent.apparent_positions_sampled(motion, t_o, x_o, c, (0.0, 0.3, 0.0)), repeats)
    general = best_time(
        lambda: apparent.apparent_positions(
            motion.positions, t_o, x_o, c, count, (0.0, 0.3, 0.0), velocity=motion.velocities
        ),
        1,
    )
    return count / uniform, count / keyframed, count / general


def addon_throughput(bpy, count, repeats):
    from relativity_addon.blender.geometry import apparent_meshes as geometry
    from relativity_addon.blender.pipeline import effect
    from relativity_addon.blender.scene import snapshot

    side = int(math.ceil(math.sqrt(count)))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.relativity.speed_of_light = 10.0
    bpy.ops.mesh.primitive_grid_add(
        x_subdivisions=side - 1, y_subdivisions=side - 1, size=2.0, location=(0.0, 0.0, -6.0)
    )
    grid = bpy.context.object
    vertices = len(grid.data.vertices)
    grid.relativity.tessellation = 0
    grid.relativity.motion = "CONSTANT"
    grid.relativity.beta = (0.9, 0.0, 0.0)
    scene.relativity.method = "GEOMETRY"
    effect.apply(scene)
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def update():
        return geometry.update_object(scene, grid, snapshot.read(scene, depsgraph), depsgraph)

    uniform = best_time(update, repeats)
    grid.keyframe_insert("rotation_euler", index=2, frame=0)
    grid.rotation_euler.z = 5.0 * 24 / scene.render.fps  # 5 rad/s: rim at 0.71 c
    grid.keyframe_insert("rotation_euler", index=2, frame=24)
    grid.relativity.motion = "ANIMATION"
    scene.frame_set(12)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    keyframed = best_time(update, repeats)
    return vertices, vertices / uniform, vertices / keyframed


def build_render_scene(bpy, resolution, samples):
    """The camera benchmark's lit room (plane, cube, sphere, point light), with a fixed seed."""
    from camera_overhead import build_scene

    scene = build_scene(bpy, resolution, samples)
    scene.cycles.seed = 0
    scene.relativity.speed_of_light = 299792458.0
    return scene


def render_overhead(bpy, resolution, samples, repeats):
    from relativity_addon.blender.pipeline import effect

    scene = build_render_scene(bpy, resolution, samples)
    path = os.path.join(tempfile.mkdtemp(prefix="relativity-bench-"), "frame.png")
    scene.render.filepath = path

    def render():
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        return time.perf_counter() - start

    plain, mesh, ratios = [], [], []
    for _ in range(repeats):
        effect.remove(scene)
        scene.relativity.beta = (0.0, 0.0, 0.0)
        plain.append(render())
        scene.relativity.beta = (0.0, 0.8, 0.0)
        for obj in scene.objects:
            if obj.type == "MESH":
                obj.relativity.tessellation = 3  # the 20-unit floor needs it to bend
        scene.relativity.method = "GEOMETRY"
        effect.apply(scene)
        mesh.append(render())
        ratios.append(mesh[-1] / plain[-1])
    return statistics.median(plain), statistics.median(mesh), statistics.median(ratios)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vertices", type=int, default=1_000_000)
    parser.add_argument("--samples", type=int, default=32)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--repeats", type=int, default=3)
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    core_uniform, core_keyframed, general = core_throughput(options.vertices, options.repeats)
    print(f"physics core: the generic bracketed solver on the keyframed motion: {general / 1e6:.2f} M vertices/s")

    import bpy

    from relativity_addon import batch

    batch.enable_addon()

    grid_vertices, addon_uniform, addon_keyframed = addon_throughput(bpy, options.vertices, options.repeats)
    print_throughput_table(
        [
            ("physics core, constant velocity", options.vertices, core_uniform, None),
            ("physics core, keyframed rigid motion", options.vertices, core_keyframed, KEYFRAMED_TARGET),
            ("add-on update, constant velocity", grid_vertices, addon_uniform, CONSTANT_VELOCITY_TARGET),
            ("add-on update, keyframed", grid_vertices, addon_keyframed, KEYFRAMED_TARGET),
        ]
    )

    batch.enable_addon()
    plain, mesh, ratio = render_overhead(bpy, resolution, options.samples, options.repeats)
    print(
        f"render {resolution[0]}x{resolution[1]}, {options.samples} samples: plain {plain:.2f} s, "
        f"mesh path at 0.8c {mesh:.2f} s, ratio {ratio:.2f} (median of {options.repeats} alternating rounds)"
    )


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
