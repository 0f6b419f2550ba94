"""Cost and noise of the moving-light shadow renderers (docs/moving-lights.md): Blended Lamps as
lines (the default), the same lamps as points (``stand_in_lamps.LINE = 0``, the default before) and
Continuous.

    python benchmarks/moving_light_shadows.py [--samples 64] [--resolution 160x120] [--repeats 3]

The floor of tests/blender/lights/test_moving_point_light.py (white, a point lamp 1 above it at
0.5c, camera 5 above at rest, exact camera) with the black square 0.5 above the floor. The
variants are rendered in turn, each at two seeds per round, so that load from other processes
hits them alike; per round each render's wall-clock and CPU time are divided by the point lamps'
, and the median ratios are printed with the load average. Noise, measured without a reference:
the two seeds' difference over the lit floor (at least a tenth of the brightest pixel, both
renders), ``std(a - b) / sqrt(2)`` over the mean, per variant; its ratio to the point lamps' says
how many more samples a variant needs for their noise (the square of it).
"""

import argparse
import math
import os
import resource
import statistics
import sys
import tempfile
import time

import numpy as np
import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "tools"))

from camera_overhead import empty_cycles_scene  # noqa: E402

VARIANTS = ("points", "lines", "continuous")  # Blended Lamps as points, as lines (the default); Continuous


def _quad(bpy, scene, name, centre, half, colour):
    from relativity_addon.blender.common import compat

    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(
        [(-half, -half, 0.0), (half, -half, 0.0), (half, half, 0.0), (-half, half, 0.0)], [], [(0, 1, 2, 3)]
    )
    material = bpy.data.materials.new(name)
    tree = compat.material_node_tree(material)
    tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*colour, 1.0)
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = centre
    scene.collection.objects.link(obj)


def build_scene(bpy, resolution, samples):
    scene = empty_cycles_scene(bpy, resolution, samples)
    scene.view_settings.view_transform = "Standard"
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = 25.0
    camera.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    _quad(bpy, scene, "Floor", (0.0, 0.0, 0.0), 100.0, (0.8, 0.8, 0.8))
    _quad(bpy, scene, "Occluder", (-1.3, 0.4, 0.5), 0.2, (0.0, 0.0, 0.0))
    light = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    light.data.energy = 1000.0
    light.data.shadow_soft_size = 0.0
    light.location = (1.5, 0.0, 1.0)
    scene.collection.objects.link(light)
    light.relativity.motion = "CONSTANT"
    light.relativity.beta = (0.5, 0.0, 0.0)
    scene.relativity.speed_of_light = 10.0
    scene.relativity.method = "CAMERA"
    return scene


def _cpu_seconds():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def render(bpy, scene, path, seed):
    """Wall-clock and CPU seconds of one render, and its green channel (top row first)."""
    scene.cycles.seed = seed
    scene.render.filepath = path
    scene.render.use_file_extension = False
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    wall, cpu = time.perf_counter(), _cpu_seconds()
    bpy.ops.render.render(write_still=True)
    wall, cpu = time.perf_counter() - wall, _cpu_seconds() - cpu
    image = bpy.data.images.load(path, check_existing=False)
    width, height = image.size
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return wall, cpu, pixels.reshape(height, width, 4)[::-1, :, 1].astype(float)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    resolution = tuple(int(v) for v in args.resolution.split("x"))

    import bpy

    import relativity_addon

    relativity_addon.register()
    from relativity_addon.blender.pipeline import effect

    scene = build_scene(bpy, resolution, args.samples)
    from relativity_addon.blender.lights import stand_in_lamps

    line = stand_in_lamps.LINE
    load = os.getloadavg()
    times = {variant: [] for variant in VARIANTS}
    noise = {variant: [] for variant in VARIANTS}
    with tempfile.TemporaryDirectory() as folder:
        for round_index in range(args.repeats):
            for variant in VARIANTS:
                scene.relativity.moving_light_shadows = "CONTINUOUS" if variant == "continuous" else "BLENDED"
                stand_in_lamps.LINE = 0.0 if variant == "points" else line
                effect.apply(scene)
                runs = [render(bpy, scene, os.path.join(folder, f"{variant}_{seed}.exr"), seed) for seed in (1, 2)]
                effect.remove(scene)
                times[variant].append((runs[0][0] + runs[1][0], runs[0][1] + runs[1][1]))
                a, b = runs[0][2], runs[1][2]
                lit = (a > 0.1 * a.max()) & (b > 0.1 * b.max())
                noise[variant].append(float(np.std((a - b)[lit]) / math.sqrt(2.0) / np.mean(0.5 * (a + b)[lit])))
            summary = ", ".join(f"{v} {times[v][-1][0]:.1f} s" for v in VARIANTS)
            print(f"round {round_index + 1}: {summary}", flush=True)
    stand_in_lamps.LINE = line
    end_load = os.getloadavg()
    print(f"{resolution[0]}x{resolution[1]}, {args.samples} samples, {args.repeats} rounds of two seeds per variant")
    print(f"load average {load[0]:.1f} at the start, {end_load[0]:.1f} at the end")
    points = statistics.median(noise["points"])
    for variant in VARIANTS[1:]:
        pairs = list(zip(times["points"], times[variant], strict=True))
        wall = statistics.median(v[0] / p[0] for p, v in pairs)
        cpu = statistics.median(v[1] / p[1] for p, v in pairs)
        ratio = statistics.median(noise[variant]) / points
        print(
            f"{variant} / points: render time wall {wall:.2f}x, CPU {cpu:.2f}x; noise (relative, lit floor) "
            f"{statistics.median(noise[variant]):.3f} against {points:.3f}: ratio {ratio:.2f} "
            f"(about {ratio**2:.1f}x the samples for the same noise)"
        )
    relativity_addon.unregister()


if __name__ == "__main__":
    main()
