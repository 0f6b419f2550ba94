"""Render time of the bounce correction between moving objects (``lights/interreflection.py``).

    .venv-4.5/bin/python benchmarks/bounce_cost.py [--samples 256] [--scale 2] [--rounds 4]

The scene of tests/blender/lights/test_interreflection.py (a sphere and a panel 0.5c apart, one
point lamp, one diffuse bounce, camera at rest), Set Up by the add-on, Cycles on the CPU, rendered
alternately per round in three set-ups so that load from other processes hits them alike:

- **SVM**: Cycles' default shading, the correction kept out (the bounce uncorrected, 1.12x the physics);
- **SVM + factor**: the add-on's node form (``lights/bounce_nodes.py``) on both objects' materials;
- **OSL, no factor**: Open Shading Language on, the correction kept out (what OSL alone costs);
- **OSL + factor**: Open Shading Language on, the add-on's script node on both objects' materials.

Prints each render's time, its ratio to the same round's SVM time, the median ratio over the
rounds, the factors over their own shading alone, and the load average before and after.
"""

import argparse
import os
import statistics
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [
    ROOT,
    os.path.join(ROOT, "tests"),
    os.path.join(ROOT, "tests", "blender", "camera"),
    os.path.join(ROOT, "tests", "blender", "lights"),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--scale", type=int, default=2, help="resolution over the test's 128 x 96")
    parser.add_argument("--rounds", type=int, default=4)
    options = parser.parse_args()

    import bpy

    from relativity_addon import batch

    batch.enable_addon()
    import test_interreflection as case

    from relativity_addon.blender.lights import interreflection
    from relativity_addon.blender.pipeline import effect

    case.RESOLUTION = (128 * options.scale, 96 * options.scale)
    case.SAMPLES = options.samples
    own_reason = interreflection._reason
    setups = {
        "SVM": (False, lambda *args: "kept out"),
        "SVM + factor": (False, own_reason),
        "OSL, no factor": (True, lambda *args: "kept out"),
        "OSL + factor": (True, own_reason),
    }
    print(f"load average before: {os.getloadavg()}")
    print(f"{case.RESOLUTION[0]} x {case.RESOLUTION[1]}, {options.samples} samples, 0.5c apart")
    ratios = {name: [] for name in setups}
    out = tempfile.mkdtemp(prefix="bounce_cost_")
    beta = np.array([-case.EACH, 0.0, 0.0])
    for round_index in range(options.rounds):
        times = {}
        for name, (use_osl, reason) in setups.items():
            bpy.ops.wm.read_factory_settings(use_empty=True)
            scene, _ = case._scene(bpy, beta, -beta)
            scene.cycles.shading_system = use_osl
            interreflection._reason = reason
            effect.apply(scene)
            carrying = sum(interreflection.MATERIAL_KEY in m for m in bpy.data.materials)
            scene.render.filepath = os.path.join(out, f"{round_index}.exr")
            scene.render.image_settings.file_format = "OPEN_EXR"
            start = time.perf_counter()
            bpy.ops.render.render(write_still=True)
            times[name] = time.perf_counter() - start
            carrying = max(carrying, sum(interreflection.MATERIAL_KEY in m for m in bpy.data.materials))
            effect.remove(scene)
            interreflection._reason = own_reason
            print(f"round {round_index}, {name}: {times[name]:.2f} s (materials with the factor: {carrying})")
        for name in setups:
            ratios[name].append(times[name] / times["SVM"])
        print("  over SVM: " + ", ".join(f"{name} {times[name] / times['SVM']:.3f}" for name in setups))
    print("median over SVM: " + ", ".join(f"{name} {statistics.median(r):.3f}" for name, r in ratios.items()))
    factor = [b / a for a, b in zip(ratios["OSL, no factor"], ratios["OSL + factor"], strict=True)]
    print(f"median OSL + factor over OSL, no factor: {statistics.median(factor):.3f}")
    print(f"median SVM + factor over SVM: {statistics.median(ratios['SVM + factor']):.3f}")
    print(f"load average after: {os.getloadavg()}", flush=True)


if __name__ == "__main__":
    main()
