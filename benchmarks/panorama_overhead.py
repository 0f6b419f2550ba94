"""Render time of the relativistic panorama and stereo pair against Blender's own cameras.

    python benchmarks/panorama_overhead.py [--samples 64] [--resolution 320x160] [--repeats 5]
                                           [--types EQUIRECTANGULAR,FISHEYE_EQUISOLID] [--room]

The lit scene of camera_overhead.py seen through a panoramic camera (the whole sphere for the
equirectangular one), Cycles on the CPU, same seed. For each panorama type the cameras are
rendered alternately (Blender's panorama, relativistic at rest, relativistic at 0.5c, then
again), each round's times divided by that round's Blender time, and the median ratio printed
next to the median times. At beta = 0 both trace the same rays: the ratio is the camera's own
cost (target <= 1.10); at speed the view changes, which is not camera overhead. STEREO renders
the perspective camera's stereo pair (Blender's multiview) both ways.

The equirectangular panorama is also rendered through a minimal OSL camera of its own (the same
rays, six lines of OSL): what any OSL camera costs in Cycles, the floor under the add-on's. With
``--room`` the scene is closed by walls and a ceiling, so that every ray meets a surface (an
interior, the usual 360-degree still) instead of the open scene's sky.
"""

import argparse
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from camera_overhead import build_scene, compare_cameras  # noqa: E402

MINIMAL_EQUIRECTANGULAR = """
shader minimal_equirectangular(output point position = point(0.0), output vector direction = vector(0.0, 0.0, 1.0),
                               output color throughput = color(1.0))
{
  point raster = camera_shader_raster_position();
  float longitude = mix(-M_PI, M_PI, raster[0]);
  float latitude = mix(-M_PI_2, M_PI_2, raster[1]);
  direction = vector(cos(latitude) * sin(longitude), sin(latitude), cos(latitude) * cos(longitude));
}
"""


def minimal_osl_camera(scene):
    """Turn the scene's camera into the minimal equirectangular OSL camera; return the undo."""
    import bpy

    from relativity_addon.blender.common import osl

    data = scene.camera.data
    text = bpy.data.texts.get("minimal_equirectangular.osl") or bpy.data.texts.new("minimal_equirectangular.osl")
    text.from_string(MINIMAL_EQUIRECTANGULAR)
    data.type, data.custom_mode, data.custom_shader = "CUSTOM", "INTERNAL", text
    errors = osl.compile_custom_camera(data)
    if errors:
        raise RuntimeError(f"minimal OSL camera: {errors[0]}")

    def undo():
        data.type = "PANO"

    return undo


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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--resolution", default="320x160")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "--types",
        default="EQUIRECTANGULAR,FISHEYE_EQUISOLID,STEREO",
        help="panorama types, and STEREO: the perspective camera's stereo pair (multiview)",
    )
    parser.add_argument("--room", action="store_true", help="close the scene with walls and a ceiling")
    options = parser.parse_args()
    resolution = tuple(int(v) for v in options.resolution.lower().split("x"))

    import bpy

    import relativity_addon

    relativity_addon.register()
    out = tempfile.mkdtemp(prefix="panorama-overhead-")
    cases = (
        ("Blender's camera", None),
        ("relativistic beta=0", (0.0, 0.0, 0.0)),
        ("relativistic beta=0.5", (0.0, 0.48, -0.13)),
    )
    print(f"{options.resolution}, {options.samples} samples, {options.repeats} alternating rounds, medians:")
    for panorama_type in options.types.split(","):
        scene = build_scene(bpy, resolution, options.samples)
        if options.room:
            close_room(bpy)
        if panorama_type == "STEREO":
            scene.render.use_multiview = True
            scene.render.views_format = "STEREO_3D"
        else:
            scene.camera.data.type = "PANO"
            scene.camera.data.panorama_type = panorama_type
        print(f" {panorama_type}{' (room)' if options.room else ''}:")
        extra = (("minimal OSL camera", minimal_osl_camera),) if panorama_type == "EQUIRECTANGULAR" else ()
        compare_cameras(bpy, scene, cases + extra, options.repeats, out, prefix=f"{panorama_type}-")


if __name__ == "__main__":
    from relativity_addon.blender.common import compat

    compat.run_main(main)
