"""Render time of the relativistic panorama and stereo pair against Blender's own cameras.

    python benchmarks/panorama_overhead.py [--samples 64] [--resolution 320x160] [--repeats 5]
                                           [--types EQUIRECTANGULAR,FISHEYE_EQUISOLID]

The lit scene of camera_overhead.py seen through a panoramic camera (the whole sphere for the
equirectangular one), Cycles on the CPU, same seed. For each panorama type the cameras are
rendered alternately (Blender's panorama, relativistic at rest, relativistic at 0.5c, then
again), each round's times divided by that round's Blender time, and the median ratio printed
next to the median times. At beta = 0 both trace the same rays: the ratio is the camera's own
cost (target <= 1.10); at speed the view changes, which is not camera overhead. STEREO renders
the perspective camera's stereo pair (Blender's multiview) both ways.
"""

import argparse
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from camera_overhead import build_scene, compare_cameras  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--resolution", default="320x160")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--types", default="EQUIRECTANGULAR,FISHEYE_EQUISOLID,STEREO",
                        help="panorama types, and STEREO: the perspective camera's stereo pair (multiview)")
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy

    import relativity_addon

    relativity_addon.register()
    out = tempfile.mkdtemp(prefix="panorama-overhead-")
    cases = (("Blender's camera", None), ("relativistic beta=0", (0.0, 0.0, 0.0)),
             ("relativistic beta=0.5", (0.0, 0.48, -0.13)))
    print(f"{options.resolution}, {options.samples} samples, {options.repeats} alternating rounds, medians:")
    for panorama_type in options.types.split(","):
        scene = build_scene(bpy, resolution, options.samples)
        if panorama_type == "STEREO":
            scene.render.use_multiview = True
            scene.render.views_format = "STEREO_3D"
        else:
            scene.camera.data.type = "PANO"
            scene.camera.data.panorama_type = panorama_type
        print(f" {panorama_type}:")
        compare_cameras(bpy, scene, cases, options.repeats, out, prefix=f"{panorama_type}-")


if __name__ == "__main__":
    from relativity_addon.blender import compat

    compat.run_main(main)
