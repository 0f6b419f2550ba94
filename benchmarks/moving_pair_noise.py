"""The noise of a moving light on a moving mesh (docs/moving-lights.md, "A moving light on a moving
object"): the per-pixel error of tests/blender/lights/test_moving_light_on_moving_mesh.py's case against its
model, for variants of the stand-ins (light-linked away from the sphere) and of the pair lamps (which light it).

    python benchmarks/moving_pair_noise.py [--samples 256] [--light antiparallel|parallel] [--rest-lamp W]
                                           [--variants lines,points,...]

Variants: ``lines`` (the default), ``points`` (``stand_in_lamps.LINE = 0``), ``points-many`` (points at a
third of the spacing: 12 lamps), ``lines-one-side`` (one strip per line), ``lines-short`` (lines 0.2 lamp
spacings long), ``lines-dim`` (the strips at 1e-6 W), ``lines-dark`` (the strips at 0 W: Cycles drops them),
``lines-no-tree`` and ``points-no-tree`` (Cycles' light tree off), ``lines-point-pairs`` and
``points-point-pairs`` (the pair lamps as points, ``moving_pairs.RADIUS = 0``: the code before they had a
radius). ``--rest-lamp W``: a point lamp at rest of W watts beside the light, lighting the sphere too (the
model adds its light). The strips' power is set in a ``render_pre`` handler after the add-on's sync. Fixed
seed: variants that leave the sphere's sampling alone give the same number to the last digit. The add-on is
registered from this checkout (an extension installed in Blender's user folder is not used).
"""

import argparse
import importlib
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "tests", "blender", "lights")]

VARIANTS = (
    "lines",
    "points",
    "points-many",
    "lines-one-side",
    "lines-short",
    "lines-dim",
    "lines-dark",
    "lines-no-tree",
    "points-no-tree",
    "lines-point-pairs",
    "points-point-pairs",
)


def measure(bpy, case, modules, variant, samples, light_beta, rest_power):
    """The per-pixel error of ``variant`` (test_moving_light_on_moving_mesh's measure)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    stand_ins, pairs = modules
    saved = {name: getattr(stand_ins, name) for name in ("LINE", "LINE_SIDES", "SPACING")}
    saved_radius = pairs.RADIUS
    build = case._scene
    power = {"lines-dim": 1e-6, "lines-dark": 0.0}.get(variant)

    def scene_for(*args, **kwargs):
        scene = build(*args, **kwargs)
        scene.cycles.samples = samples
        scene.cycles.use_light_tree = not variant.endswith("no-tree")
        return scene

    def strips_power(scene, *_args):
        for obj in scene.objects:
            if power is not None and obj.type == "LIGHT" and obj.data.type == "AREA":
                obj.data.energy = power

    stand_ins.LINE = 0.0 if variant.startswith("points") else 0.2 if variant == "lines-short" else saved["LINE"]
    stand_ins.LINE_SIDES = 1 if variant == "lines-one-side" else saved["LINE_SIDES"]
    stand_ins.SPACING = saved["SPACING"] / 3.5 if variant == "points-many" else saved["SPACING"]
    pairs.RADIUS = 0.0 if variant.endswith("point-pairs") else saved_radius
    case._scene = scene_for
    bpy.app.handlers.render_pre.append(strips_power)
    try:
        with tempfile.TemporaryDirectory() as folder:
            pattern, total, shift = case._compare(
                bpy, np.array((light_beta, 0.0, 0.0)), Path(folder), variant, rest_power=rest_power
            )
    finally:
        bpy.app.handlers.render_pre.remove(strips_power)
        case._scene = build
        pairs.RADIUS = saved_radius
        for name, value in saved.items():
            setattr(stand_ins, name, value)
    return pattern, total, shift


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--light", choices=("antiparallel", "parallel"), default="antiparallel")
    parser.add_argument("--rest-lamp", type=float, default=0.0, help="a lamp at rest of this power (W) too")
    parser.add_argument("--variants", default=",".join(VARIANTS))
    options = parser.parse_args()
    import bpy

    addon = importlib.import_module("relativity_addon")  # this checkout's, first on sys.path
    if not hasattr(bpy.types.Scene, "relativity"):
        addon.register()
    case = importlib.import_module("test_moving_light_on_moving_mesh")
    case.ADDON_MODULE = "relativity_addon"  # the add-on as this checkout registers it
    modules = tuple(
        importlib.import_module(f"relativity_addon.blender.lights.{name}")
        for name in ("stand_in_lamps", "moving_pairs")
    )
    light_beta = case.BETA if options.light == "parallel" else -case.BETA
    print(
        f"Blender {bpy.app.version_string}, {options.samples} samples, {options.light} light, lamp at rest "
        f"{options.rest_lamp:g} W, load average {os.getloadavg()[0]:.1f}"
    )
    for variant in options.variants.split(","):
        pattern, total, shift = measure(bpy, case, modules, variant, options.samples, light_beta, options.rest_lamp)
        print(f"{variant:>15}: per-pixel error {pattern:.2%}, total {total:.4f}, centroid {shift:.2f} px", flush=True)
    sys.stdout.flush()
    os._exit(0)  # bpy 4.5 can hang in exit()


if __name__ == "__main__":
    main()
