"""Adaptive tessellation on issue 26's grid: how many vertices the default settings make, and what
measuring the edges costs.

The grid: 1415 x 1415 vertices (2,002,225), 2 m wide, 6 m in front of a 50 mm camera at rest,
rendered at 1920 x 1080, with its own velocity 0.9c across the view (as in issue 26). Prints the
evaluated vertex count at the default settings (Adaptive, Tolerance 0.5 px, Tessellation 4) against
the grid's own and against every face at Tessellation 1 (the old default: about 4x), and the time
of one update (``apparent_meshes.update_object``: measure, subdivide, solve, write) with Adaptive
on against Adaptive off at Tessellation 0 (the same 2M vertices, nothing measured), alternating,
as a ratio measured side by side in one run.

    .venv-5.2/bin/python benchmarks/adaptive_tessellation.py [--side 1415] [--repeats 3]
"""

import argparse
import os
import statistics
import sys
import time

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def build(bpy, side):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 1920, 1080, 100
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = 50.0
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.relativity.speed_of_light = 10.0
    bpy.ops.mesh.primitive_grid_add(
        x_subdivisions=side - 1, y_subdivisions=side - 1, size=2.0, location=(0.0, 0.0, -6.0)
    )
    grid = bpy.context.object
    grid.relativity.motion = "CONSTANT"
    grid.relativity.beta = (0.9, 0.0, 0.0)
    return scene, grid


def evaluated_count(bpy, obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    return len(obj.evaluated_get(depsgraph).data.vertices)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=1415, help="vertices per side of the grid")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--old-default", action="store_true", help="also build every face at Tessellation 1")
    options = parser.parse_args()

    import bpy

    from relativity_addon import batch

    batch.enable_addon()
    from relativity_addon.blender.geometry import apparent_meshes
    from relativity_addon.blender.pipeline import effect
    from relativity_addon.blender.scene import snapshot

    print(f"load average before: {os.getloadavg()}")
    scene, grid = build(bpy, options.side)
    own = len(grid.data.vertices)
    scene.relativity.method = "GEOMETRY"
    start = time.perf_counter()
    effect.apply(scene)
    setup = time.perf_counter() - start
    adaptive = evaluated_count(bpy, grid)
    print(
        f"grid: {own:,} vertices; default settings (Adaptive, Tolerance "
        f"{grid.relativity.tessellation_tolerance} px, Tessellation {grid.relativity.tessellation}): "
        f"{adaptive:,} evaluated = {adaptive / own:.3f}x (Set Up {setup:.1f} s)"
    )

    def update():
        depsgraph = bpy.context.evaluated_depsgraph_get()
        start = time.perf_counter()
        apparent_meshes.update_object(scene, grid, snapshot.read(scene, depsgraph), depsgraph)
        return time.perf_counter() - start

    times = {True: [], False: []}
    for _ in range(options.repeats):
        for on in (True, False):
            # each setting syncs at once: never every face at 4 levels on the way
            if on:
                grid.relativity.use_adaptive_tessellation = True
                grid.relativity.tessellation = 4
            else:
                grid.relativity.tessellation = 0
                grid.relativity.use_adaptive_tessellation = False
            update()  # the switch itself (a new subdivision) is not what is timed
            times[on].append(update())
    ratio = statistics.median(a / b for a, b in zip(times[True], times[False], strict=True))
    print(
        f"update: Adaptive {statistics.median(times[True]):.2f} s, Tessellation 0 without it "
        f"{statistics.median(times[False]):.2f} s: {ratio:.2f}x (median of {options.repeats} alternating rounds)"
    )

    if options.old_default:
        grid.relativity.tessellation = 1
        grid.relativity.use_adaptive_tessellation = False
        update()
        uniform = evaluated_count(bpy, grid)
        print(f"every face at Tessellation 1 (the old default): {uniform:,} = {uniform / own:.3f}x")
    else:
        uniform = (2 * options.side - 1) ** 2  # one level halves every edge of the grid
        print(
            f"every face at Tessellation 1 (the old default) would make {uniform:,} = {uniform / own:.3f}x "
            "(--old-default builds it: 8M vertices for the full grid)"
        )
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
