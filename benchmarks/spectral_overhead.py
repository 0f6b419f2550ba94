"""Render time of the spectral mode against a plain render of the same frame.

    python benchmarks/spectral_overhead.py [--samples 128] [--resolution 160x120] [--passes 4] [--repeats 3]

The camera_overhead scene (a lit floor, a cube and a sphere under a point lamp), exact camera at
0.5c. Rendered alternately: the relativistic fast (RGB) F12 render, then the spectral render of
``passes`` colour passes (plus its Doppler pass); each round's spectral time is divided by that
round's fast time, and the median ratio is printed next to ``passes x 1.05``, the target.
"""

import argparse
import os
import statistics
import sys
import tempfile
import time

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=128)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--passes", type=int, default=4)
    parser.add_argument("--repeats", type=int, default=3)
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy
    from camera_overhead import build_scene, timed_render

    import relativity_addon
    from relativity_addon.blender.pipeline import effect, spectral_render

    relativity_addon.register()
    scene = build_scene(bpy, resolution, options.samples)
    scene.relativity.beta = (0.0, 0.48, -0.13)
    effect.apply(scene)
    out = tempfile.mkdtemp(prefix="spectral-overhead-")

    def spectral():
        start = time.perf_counter()
        spectral_render.render(scene, options.passes)
        return time.perf_counter() - start

    timed_render(bpy, scene, os.path.join(out, "warmup.png"))  # shader compilation, kernels
    spectral()
    fast_times, spectral_times = [], []
    for round_index in range(options.repeats):
        fast_times.append(timed_render(bpy, scene, os.path.join(out, f"{round_index}.png")))
        spectral_times.append(spectral())
    ratios = [s / f for s, f in zip(spectral_times, fast_times, strict=True)]
    print(
        f"{options.resolution}, {options.samples} samples, {options.passes} passes, "
        f"{options.repeats} alternating rounds, medians:"
    )
    print(f"  fast (RGB) render   {statistics.median(fast_times):7.3f} s")
    print(
        f"  spectral render     {statistics.median(spectral_times):7.3f} s   ratio {statistics.median(ratios):5.2f}"
        f"   (ratios {min(ratios):.2f}-{max(ratios):.2f}; target {options.passes * 1.05:.2f})"
    )


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
