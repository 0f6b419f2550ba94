"""Render time of a moving lamp behind the exact camera (its stand-in lamps, ``lights/stand_in_lamps.py``)
with one light datablock for all of its stand-ins (now) against one per stand-in (as before), against
the same lamp at rest behind the exact camera and against no effect at all.

    python benchmarks/stand_in_lamp_cost.py [--samples 1] [--resolution 64x48] [--repeats 5]

The floor of benchmarks/moving_light_shadows.py (white, a point lamp 1 above it at 0.5c, camera 5
above at rest, the black square 0.5 above the floor): 16 lamps drawn out into lines, 48 area lights.
Cycles JIT-compiles every distinct OSL light shader at every render, and a light datablock is one
shader: one per stand-in cost about 3 s a render whatever the samples (docs/performance.md). The
stand-ins' own datablocks are made here as before from the shared one: a copy per stand-in, its
Attribute nodes replaced by the object's values on the script node (the image is the same; it is
checked), with the add-on's handlers held off while they render (its sync would share them again);
so that the cases compare alike, every case renders with the handlers held off. The cases
are set up and rendered alternately, after one warm-up round, and the median wall-clock and CPU
times (range) are printed with the load average.
"""

import argparse
import contextlib
import os
import statistics
import sys
import tempfile

import numpy as np
import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from camera_overhead import load_average  # noqa: E402
from moving_light_shadows import build_scene, render  # noqa: E402

CASES = (
    ("no effect (Blender's lamp at rest)", "NONE"),
    ("exact camera, the lamp at rest", "STATIC"),
    ("moving lamp: one light for its 48 stand-ins (now)", "SHARED"),
    ("moving lamp: a light per stand-in (before)", "OWN"),
)
HANDLERS = ("depsgraph_update_post", "render_pre", "render_post", "frame_change_pre", "frame_change_post")


@contextlib.contextmanager
def handlers_held(bpy):
    """The persistent handlers (the add-on's sync) off for the block."""
    held = {name: list(getattr(bpy.app.handlers, name)) for name in HANDLERS}
    for name in HANDLERS:
        getattr(bpy.app.handlers, name).clear()
    try:
        yield
    finally:
        for name, handlers in held.items():
            getattr(bpy.app.handlers, name).extend(handlers)


def own_light(obj, shared):
    """A copy of the stand-ins' ``shared`` light holding ``obj``'s own inputs on its script node, as
    before (no Attribute nodes: the values are constants of the shader, as they were)."""
    from relativity_addon.blender.common import names
    from relativity_addon.blender.lights import stand_in_lights

    light = shared.copy()
    tree = light.node_tree
    node = tree.nodes[names.MOVING_LAMP_PREFIX]
    for key in stand_in_lights.PER_LAMP:
        tree.nodes.remove(tree.nodes[key])
        value = obj.get(stand_in_lights.lamp_key(key))
        if value is not None:
            node.inputs[key].default_value = value
    return light


def render_case(bpy, scene, case, path):
    """Set up ``case``, render it (handlers held off) and remove it: (wall, CPU seconds, lights, image)."""
    from relativity_addon.blender.common import names
    from relativity_addon.blender.pipeline import effect

    lamp = scene.objects["Lamp"]
    lamp.relativity.motion = "STATIC" if case in ("NONE", "STATIC") else "CONSTANT"
    if case != "NONE":
        effect.apply(scene)
    with handlers_held(bpy):
        stand_ins = [obj for obj in scene.objects if obj.name.startswith(names.MOVING_LAMP_PREFIX)]
        shared = stand_ins[0].data if stand_ins else None
        if case == "OWN":
            for obj in stand_ins:
                obj.data = own_light(obj, shared)
        lights = len({obj.data for obj in stand_ins})
        wall, cpu, image = render(bpy, scene, path, 1)
        if case == "OWN":  # the copies go with their objects; the shared light is removed by effect.remove
            for obj in stand_ins:
                copied, obj.data = obj.data, shared
                bpy.data.lights.remove(copied)
    if case != "NONE":
        effect.remove(scene)
    return wall, cpu, lights, image


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1)
    parser.add_argument("--resolution", default="64x48")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    resolution = tuple(int(v) for v in args.resolution.split("x"))

    import bpy

    import relativity_addon

    relativity_addon.register()
    scene = build_scene(bpy, resolution, args.samples)
    print(f"{resolution[0]}x{resolution[1]}, {args.samples} samples, Blender {bpy.app.version_string}")
    print(load_average(), "at the start")
    times = {case: [] for _, case in CASES}
    lights, images = {}, {}
    with tempfile.TemporaryDirectory() as folder:
        for round_index in range(args.repeats + 1):  # round 0: warm-up
            for _, case in CASES:
                wall, cpu, lights[case], images[case] = render_case(
                    bpy, scene, case, os.path.join(folder, f"{case}.exr")
                )
                if round_index:
                    times[case].append((wall, cpu))
    print(load_average(), "at the end")
    same = float(np.abs(images["OWN"] - images["SHARED"]).max() / images["SHARED"].max())
    print(f"a light per stand-in against one light: largest pixel difference {same:.1e} of the brightest")
    for label, case in CASES:
        wall = [t[0] for t in times[case]]
        cpu = [t[1] for t in times[case]]
        print(
            f"{label}: {lights[case]} light datablock(s); wall {statistics.median(wall):.2f} s "
            f"({min(wall):.2f}-{max(wall):.2f}), CPU {statistics.median(cpu):.2f} s"
        )
    relativity_addon.unregister()


if __name__ == "__main__":
    main()
