"""Render time and noise of the per-point stand-ins for a lamp at rest lighting a moving object.

    python benchmarks/lamp_doppler_cost.py [--samples 64] [--resolution 160x120] [--repeats 4]

The 3-radii scene of tests/blender/lights/test_lamp_doppler_per_point.py (a unit sphere at 0.5c, a
point lamp 3 radii away across the motion, camera at rest, direct light only), Cycles on the CPU,
rendered alternately in three set-ups so that load from other processes hits them alike:

- **at rest**: the sphere at rest where the moving one is seen (no copies: the lamp alone);
- **at most n stand-ins** per lamp and object (``--counts``; 1: the former single copy's cost plus
  the light tree; the stage ships ``MAX_STAND_INS``); how many it places for this scene is printed.

Per round and set-up: the render time, divided by that round's time at rest (median over the rounds),
and the noise: the RMS difference of two rounds' renders (seeds differ) over the lit sphere, over
its mean, divided by sqrt(2) (median over consecutive pairs). Equal noise costs ``time x noise^2``.
"""

import argparse
import math
import os
import statistics
import sys
import tempfile
import time

import numpy as np
import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from camera_overhead import empty_cycles_scene  # noqa: E402


def build_scene(bpy, resolution, samples):
    scene = empty_cycles_scene(bpy, resolution, samples)
    scene.cycles.max_bounces = 0
    scene.render.image_settings.file_format = "OPEN_EXR"
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (0.0, -6.0, 0.0)
    camera.rotation_euler = (math.pi / 2.0, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=1.0, location=(3.0, 0.0, 0.0))
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    sphere.relativity.enabled = True
    sphere.relativity.motion = "CONSTANT"
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.data.energy = 2000.0
    lamp.data.shadow_soft_size = 0.0
    lamp.location = (0.0, -2.1213, 2.1213)
    scene.collection.objects.link(lamp)
    scene.relativity.speed_of_light = 10.0
    scene.relativity.method = "GEOMETRY"
    scene.relativity.use_doppler = False
    return scene, sphere


def render(bpy, scene, path):
    scene.render.filepath = path
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - start
    image = bpy.data.images.load(path)
    pixels = np.array(image.pixels[:], dtype=np.float64).reshape(image.size[1], image.size[0], 4)[..., :3]
    bpy.data.images.remove(image)
    return seconds, pixels.mean(axis=-1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--repeats", type=int, default=4)
    parser.add_argument("--counts", default="1,2,4,6", help="the stage's largest numbers of stand-ins to compare")
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy

    import relativity_addon

    relativity_addon.register()
    from relativity_addon.blender.lights import lamps_on_moving_objects as stage
    from relativity_addon.blender.pipeline import effect

    shipped = stage.MAX_STAND_INS
    scene, sphere = build_scene(bpy, resolution, options.samples)
    out = tempfile.mkdtemp(prefix="lamp-doppler-cost-")
    counts = [int(v) for v in options.counts.split(",")]
    cases = (("at rest", 0.0, shipped), *((f"at most {n} stand-ins", 0.5, n) for n in counts))
    times = {label: [] for label, _, _ in cases}
    placements = {}
    images = {label: [] for label, _, _ in cases}
    for round_index in range(options.repeats + 1):  # round 0: warm-up (kernels, shader compilation)
        scene.cycles.seed = round_index
        for label, beta, count in cases:
            stage.MAX_STAND_INS = count
            effect.remove(scene)
            sphere.relativity.beta = (beta, 0.0, 0.0)
            sphere.location = (6.0 * beta, 0.0, 0.0)  # seen at the origin (light-travel time, c = 10 m/s)
            effect.apply(scene)
            placements[label] = sum(1 for obj in scene.objects if stage.is_copy(obj))
            seconds, image = render(bpy, scene, os.path.join(out, f"{round_index}-{len(times[label])}.exr"))
            if round_index > 0:
                times[label].append(seconds)
                images[label].append(image)
    effect.remove(scene)
    stand_ins = sum(1 for obj in scene.objects if stage.is_copy(obj))
    print(f"{options.resolution}, {options.samples} samples, {options.repeats} alternating rounds, medians:")
    for label, _, _ in cases:
        ratios = [t / r for t, r in zip(times[label], times["at rest"], strict=True)]
        lit = images[label][0] > 0.05 * images[label][0].max()
        noise = [
            float(np.sqrt(np.mean((a[lit] - b[lit]) ** 2)) / np.mean(a[lit]) / math.sqrt(2.0))
            for a, b in zip(images[label], images[label][1:], strict=False)
        ]
        placed = placements[label]
        print(
            f"  {label:20s} {statistics.median(times[label]):7.3f} s   time ratio {statistics.median(ratios):5.2f}"
            f"   noise {statistics.median(noise):6.2%} per pixel ({lit.sum()} lit pixels, {placed} copies)"
        )
    print(f"  (copies left after Remove: {stand_ins})")


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
