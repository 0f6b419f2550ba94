"""Render time of the scene's light on a cockpit (the sky and the lamps at rest reaching the objects
that move with the camera: ``colour/cockpit_sky.py``, ``lights/cockpit_lamps.py``) against the same
cockpit lit only by its own lamp, and against no cockpit.

    python benchmarks/cockpit_light_cost.py [--samples 64] [--resolution 160x120] [--repeats 5]

A floor, boxes, a sun and a sky (a gradient, so the world varies with the direction as a sky
does) at rest; the exact camera at 0.9c with a cockpit (a frame with a window, a lamp moving with
the camera). The cases are set up and rendered alternately, after one warm-up round, so that
load from other processes hits them alike; each round's times are divided by that round's time
without the scene's light on the cockpit, and the median ratios (range) are printed with the
median times, wall clock and CPU (user + system), and the load average (camera_overhead.py's
measures).
"""

import argparse
import os
import statistics
import sys
import tempfile

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from camera_overhead import empty_cycles_scene, load_average, timed_render_clocks  # noqa: E402

LIGHT_STAGES = ("the cockpit's sky", "the scene's lamps on the cockpit")


def build_scene(bpy, resolution, samples):
    from relativity_addon.blender.common import compat

    scene = empty_cycles_scene(bpy, resolution, samples)
    scene.world = bpy.data.worlds.new("Sky")
    tree = compat.world_node_tree(scene.world)
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    gradient = tree.nodes.new("ShaderNodeTexGradient")
    tree.links.new(coordinates.outputs["Generated"], gradient.inputs["Vector"])
    tree.links.new(gradient.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (0.0, -6.0, 1.5)
    camera.rotation_euler = (1.5708, 0.0, 0.0)  # looks down +Y
    scene.collection.objects.link(camera)
    scene.camera = camera
    bpy.ops.mesh.primitive_plane_add(size=40.0)
    for x, y in ((-2.0, 2.0), (2.5, 5.0), (-1.0, 9.0)):
        bpy.ops.mesh.primitive_cube_add(size=1.5, location=(x, y, 0.75))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.6, 0.3, 0.0)
    scene.collection.objects.link(sun)
    mesh = bpy.data.meshes.new("Frame")
    o, i = (0.5, 0.4), (0.2, 0.12)
    verts = [(-o[0], -o[1], 0), (o[0], -o[1], 0), (o[0], o[1], 0), (-o[0], o[1], 0)]
    verts += [(-i[0], -i[1], 0), (i[0], -i[1], 0), (i[0], i[1], 0), (-i[0], i[1], 0)]
    mesh.from_pydata(verts, [], [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)])
    frame = bpy.data.objects.new("Frame", mesh)
    scene.collection.objects.link(frame)
    lamp = bpy.data.objects.new("Cockpit lamp", bpy.data.lights.new("Cockpit lamp", "POINT"))
    lamp.data.energy = 5.0
    scene.collection.objects.link(lamp)
    for obj, location in ((frame, (0.0, 0.0, -0.4)), (lamp, (0.0, 0.15, -0.2))):
        obj.parent = camera
        obj.location = location
        obj.relativity.moves_with_camera = True
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = (0.0, 0.9, 0.0)
    return scene, frame, lamp


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--repeats", type=int, default=5)
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy

    import relativity_addon

    relativity_addon.register()
    from relativity_addon.blender.pipeline import effect

    scene, frame, lamp = build_scene(bpy, resolution, options.samples)
    every_stage = effect.STAGES
    unlit = tuple(stage for stage in every_stage if stage.name not in LIGHT_STAGES)
    cockpit_objects = (frame, lamp)

    def set_up(label):
        effect.remove(scene)
        effect.STAGES = unlit if label == "cockpit, own lamp only" else every_stage
        for obj in cockpit_objects:
            obj.relativity.moves_with_camera = label != "no cockpit"
            obj.hide_render = label == "no cockpit"
        effect.apply(scene)

    labels = ("cockpit, own lamp only", "cockpit, sky and sun too", "no cockpit")
    out = tempfile.mkdtemp(prefix="cockpit-light-")
    times = {label: [] for label in labels}
    for round_index in range(-1, options.repeats):  # round -1: the warm-up
        for label in labels:
            set_up(label)
            seconds = timed_render_clocks(bpy, scene, os.path.join(out, f"{round_index}.png"))
            if round_index >= 0:
                times[label].append(seconds)
    effect.remove(scene)
    effect.STAGES = every_stage
    print(f"{options.resolution}, {options.samples} samples, {options.repeats} alternating rounds, medians:")
    print(f"  {'':26s} {'wall s':>7s} {'cpu s':>7s}   {'wall / own lamp only':22s} cpu / own lamp only")
    for label in labels:
        ratios = [
            [mine[clock] / theirs[clock] for mine, theirs in zip(times[label], times[labels[0]], strict=True)]
            for clock in (0, 1)
        ]
        columns = "".join(
            f"   {statistics.median(values):5.3f} ({min(values):.3f}-{max(values):.3f})   " for values in ratios
        )
        wall = statistics.median(t[0] for t in times[label])
        cpu = statistics.median(t[1] for t in times[label])
        print(f"  {label:26s} {wall:7.3f} {cpu:7.3f}{columns}")
    print(f"  ({load_average()})")


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
