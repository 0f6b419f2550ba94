"""What the kept node groups save at Set Up (``common/nodes.ensure_group``). Timed in one process.

    python benchmarks/setup_groups.py [--rounds 5]

A small Apparent Geometry scene (a cube with its own velocity of 0.5c, a lamp at rest, a
material) is set up and removed in alternating rounds: with the folder of kept groups emptied
first (every group built from Python, as before this cache) and with it as the previous round
left it (the groups appended). Remove deletes the groups, so each Set Up makes them again.
Prints the medians, their ratio, and the Set Up of the same scene with Exact Camera (no geometry
group) beside them.
"""

import argparse
import os
import shutil
import statistics
import sys
import time

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def build(bpy, method):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    from relativity_addon import batch

    batch.enable_addon()
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (0.0, -8.0, 0.0)
    camera.rotation_euler = (1.5707963, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    mesh = bpy.data.meshes.new("Cube")
    corners = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh.from_pydata(corners, [], faces)
    mesh.materials.append(bpy.data.materials.new("Paint"))
    cube = bpy.data.objects.new("Cube", mesh)
    scene.collection.objects.link(cube)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.location = (0.0, -6.0, 4.0)
    scene.collection.objects.link(lamp)
    scene.relativity.method = method
    if method == "GEOMETRY":
        cube.relativity.enabled = True
        cube.relativity.motion = "CONSTANT"
        cube.relativity.beta = (0.5, 0.0, 0.0)
    else:
        scene.relativity.beta = (0.0, 0.5, 0.0)
    bpy.context.view_layer.update()
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    options = parser.parse_args()
    import bpy

    from relativity_addon.blender.pipeline import effect

    folder = bpy.utils.user_resource("DATAFILES", path=os.path.join("relativity_addon", "node_groups"))
    times = {"built": [], "appended": [], "exact camera": []}
    for _round in range(options.rounds):
        for variant in times:
            scene = build(bpy, "CAMERA" if variant == "exact camera" else "GEOMETRY")
            if variant == "built":
                shutil.rmtree(folder, ignore_errors=True)
            start = time.perf_counter()
            effect.apply(scene)
            times[variant].append(time.perf_counter() - start)
            effect.remove(scene)
    medians = {variant: statistics.median(values) for variant, values in times.items()}
    print(f"Blender {bpy.app.version_string}, {options.rounds} alternating rounds, load {os.getloadavg()[0]:.1f}")
    for variant, median in medians.items():
        rounds = ", ".join(f"{t:.3f}" for t in times[variant])
        print(f"  Set Up, {variant:13s} median {median:.3f} s  (rounds: {rounds})")
    print(f"  built / appended: {medians['built'] / medians['appended']:.1f}x")
    sys.stdout.flush()
    os._exit(0)  # bpy 4.5 can hang in exit()


if __name__ == "__main__":
    main()
