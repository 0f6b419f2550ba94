"""Render time of the exact camera (perspective, panoramas, stereo pair) against Blender's own
cameras and against a minimal OSL camera, in an open scene and in a room.

    python benchmarks/panorama_overhead.py [--samples 64] [--resolution 320x160] [--repeats 5]
                                           [--types PERSP,EQUIRECTANGULAR] [--scenes open,room]
                                           [--no-ops]

The lit scene of camera_overhead.py seen through the camera, Cycles on the CPU, same seed. For
each camera type and scene the cameras are rendered alternately (Blender's camera, relativistic
at rest, relativistic at 0.5c, the minimal OSL camera, then again), each round's times divided by
that round's Blender time and by its minimal OSL camera's time, and the median ratios printed
next to the median times, wall clock and CPU (camera_overhead.compare_cameras), with the load
average. At beta = 0 the cameras trace the same rays: the ratio to the minimal OSL camera (the
same rays in three to six lines of OSL, ``tools/osl_camera_ops.py``: what Cycles charges any OSL
camera) is the add-on's own cost per render, camera shader, colour stage, compositor and
handlers together (target <= 1.03, issue 26); at speed the view changes, which is not camera
overhead. ``PERSP`` is the perspective camera, the other types Blender's panoramas (the minimal
camera exists for PERSP and EQUIRECTANGULAR); STEREO renders the perspective camera's stereo
pair (Blender's multiview) both ways. Scene ``open``: most of the sphere is sky; ``room``: walls
and a ceiling close the scene, so that every ray meets a surface (an interior, the usual
360-degree still).

Unless ``--no-ops``, the operations Cycles runs per camera sample after OSL's runtime optimiser
are counted first (``tools/osl_camera_ops.py``): the exact camera at rest against the minimal
camera, a check that the machine's load cannot disturb.
"""

import argparse
import math
import os
import sys
import tempfile

import user_resources  # noqa: F401  (before bpy: this checkout's add-on, not an installed copy)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))

from camera_overhead import MINIMAL, build_scene, compare_cameras, load_average, minimal_osl_camera  # noqa: E402
from osl_camera_ops import MINIMAL_SHADERS, optimised_camera_ops, work_ops  # noqa: E402


def close_room(bpy):
    """Walls and a ceiling around the open scene (a 20 x 20 x 8 box on its floor)."""
    for location, rotation in (
        ((0, 10, 4), (math.pi / 2, 0, 0)),
        ((0, -10, 4), (math.pi / 2, 0, 0)),
        ((10, 0, 4), (0, math.pi / 2, 0)),
        ((-10, 0, 4), (0, math.pi / 2, 0)),
        ((0, 0, 8), (0, 0, 0)),
    ):
        bpy.ops.mesh.primitive_plane_add(size=20.0, location=location, rotation=rotation)


def print_operation_counts(types):
    """Operations per camera sample after OSL's runtime optimiser, exact camera at rest against
    the minimal camera (fresh processes; independent of the machine's load)."""
    print("Operations per camera sample (OSL's optimised code; tools/osl_camera_ops.py):")
    for camera_type in types:
        if camera_type not in MINIMAL_SHADERS:
            continue
        counts = {camera: work_ops(optimised_camera_ops(camera_type, camera)) for camera in ("exact", "minimal")}
        extra = counts["exact"] - counts["minimal"]
        print(
            f"  {camera_type}: exact camera at rest {sum(counts['exact'].values())}, minimal "
            f"{sum(counts['minimal'].values())}; beyond the minimal: {dict(extra) or 'none'}"
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--resolution", default="320x160")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "--types",
        default="PERSP,EQUIRECTANGULAR",
        help="PERSP (the perspective camera), panorama types (EQUIRECTANGULAR, FISHEYE_EQUISOLID, ...) "
        "and STEREO: the perspective camera's stereo pair (multiview)",
    )
    parser.add_argument("--scenes", default="open,room", help="open, room or both")
    parser.add_argument("--room", action="store_true", help="the room only (as --scenes room)")
    parser.add_argument("--no-ops", action="store_true", help="do not count the optimised operations")
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))
    types = options.types.split(",")
    scenes = ["room"] if options.room else options.scenes.split(",")

    if not options.no_ops:
        print_operation_counts(types)

    import bpy

    import relativity_addon

    relativity_addon.register()
    out = tempfile.mkdtemp(prefix="panorama-overhead-")
    cases = (
        ("Blender's camera", None),
        ("relativistic beta=0", (0.0, 0.0, 0.0)),
        ("relativistic beta=0.5", (0.0, 0.48, -0.13)),
    )
    rounds = f"{options.repeats} alternating rounds"
    print(f"{options.resolution}, {options.samples} samples, {rounds}, medians ({load_average()}):")
    for scene_kind in scenes:
        for camera_type in types:
            scene = build_scene(bpy, resolution, options.samples)
            if scene_kind == "room":
                close_room(bpy)
            if camera_type == "STEREO":
                scene.render.use_multiview = True
                scene.render.views_format = "STEREO_3D"
            elif camera_type != "PERSP":
                scene.camera.data.type = "PANO"
                scene.camera.data.panorama_type = camera_type
            print(f" {camera_type} ({scene_kind}):")
            extra = ((MINIMAL, minimal_osl_camera(camera_type)),) if camera_type in MINIMAL_SHADERS else ()
            compare_cameras(bpy, scene, cases + extra, options.repeats, out, prefix=f"{camera_type}-{scene_kind}-")


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
