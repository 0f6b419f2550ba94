"""A moving light behind the exact camera through Render Animation (the observer moving at 0.1c):
each frame shows the light where that frame's physics puts it, as an F12 render of that frame does.

The light is keyframed (Motion: Animation), at rest at x = 0 until frame 1, then along +X at 0.5c
(1.25 per frame at 4 fps, c = 10): frames 1 to 3 see it still at rest (its light takes longer than
that to reach the floor and the camera), frame 4 already moving. Found: Render Animation kept the
stand-in lamps' count of its first frame (none are made between its frames: Blender 5.2 crashed),
here one lamp, which drew frames 2 to 4 wrong (the pool at pixel 76 where the frame's F12 render
has it at 40); and a lone stand-in carried the light on at the frame's velocity where its path is
at rest (frame 1: the pool 13 px behind Blender's own lamp at rest)."""

import importlib
import sys
from pathlib import Path

import numpy as np

from blender_support import ADDON_MODULE

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "camera"))
import camera_helpers as ch  # noqa: E402

C = 10.0
FPS = 4
BETA = 0.5


def _compat():
    return importlib.import_module(f"{ADDON_MODULE}.blender.common.compat")


def _scene(bpy, motion="ANIMATION"):
    """A white floor, camera 5 above looking down, a 1 kW point light 1 above the floor keyframed at
    x = 0 on frame 1 and x = 3.75 on frame 4 (linear, constant before and after)."""
    scene, camera = ch.new_scene(bpy, resolution=(80, 60), samples=16, location=(0.0, 0.0, 5.0))
    camera.data.lens = 25.0  # the floor from x = -3.6 to 3.6 in view
    scene.render.fps = FPS
    scene.frame_start, scene.frame_end = 1, 4
    mesh = bpy.data.meshes.new("Floor")
    mesh.from_pydata([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(ch.diffuse_material(bpy, "White", (0.8, 0.8, 0.8)))
    scene.collection.objects.link(bpy.data.objects.new("Floor", mesh))
    light = bpy.data.lights.new("Lamp", "POINT")
    light.energy = 1000.0
    light.shadow_soft_size = 0.0
    lamp = bpy.data.objects.new("Lamp", light)
    scene.collection.objects.link(lamp)
    for frame in (1, 4):
        lamp.location = (BETA * C * (frame - 1) / FPS, 0.0, 1.0)
        lamp.keyframe_insert("location", frame=frame)
    for curve in _compat().action_fcurves(lamp.animation_data):
        for point in curve.keyframe_points:
            point.interpolation = "LINEAR"
    lamp.relativity.motion = motion
    scene.relativity.speed_of_light = C
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = (0.0, 0.1, 0.0)  # the observer moves: the exact camera
    scene.frame_set(1)
    return scene


def _still(bpy, scene, path):
    return ch.render_exr(bpy, scene, path)[..., :3]


def _centroid_x(image):
    """The pool's centre along the motion, in pixels (the pixels above a fifth of the brightest)."""
    lum = ch.luminance(image)
    lum = np.where(lum > 0.2 * lum.max(), lum, 0.0)
    return float((lum.sum(0) * (np.arange(lum.shape[1]) + 0.5)).sum() / lum.sum())


def test_render_animation_frames_are_their_own_frames(relativity_addon, factory_blender, tmp_path):
    """Render Animation (frames 1-4) against an F12 render of each frame (the same seed: the same
    image when the same lamps render it): within 2 % of the mean; the pool moves on by frame 4."""
    bpy = factory_blender
    scene = _scene(bpy)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    scene.render.filepath = str(tmp_path / "frame_####")
    scene.render.use_file_extension = True
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    bpy.ops.render.render(animation=True)
    animated = [ch.read_exr(bpy, tmp_path / f"frame_{frame:04d}.exr")[..., :3] for frame in range(1, 5)]
    stills = []
    for frame in range(1, 5):
        scene.frame_set(frame)
        stills.append(_still(bpy, scene, tmp_path / f"still_{frame}.exr"))
    for frame, (image, still) in enumerate(zip(animated, stills, strict=True), start=1):
        difference = np.abs(image - still).mean() / still.mean()
        print(
            f"frame {frame}: pool at {_centroid_x(image):.1f} px (F12: {_centroid_x(still):.1f}), "
            f"mean |difference| {difference:.4f} of the mean"
        )
        assert still.mean() > 1e-3
        assert difference < 0.02, f"frame {frame} of Render Animation is not that frame's image"
    assert _centroid_x(animated[3]) > _centroid_x(animated[0]) + 5.0


def test_keyframed_light_at_rest_until_the_frame_lights_as_a_lamp_at_rest(relativity_addon, factory_blender, tmp_path):
    """Frame 1: the light has been at rest at x = 0 over all the time its light takes to reach the
    floor and the camera, so the floor is lit as by Blender's own lamp at rest there (the same light
    with Motion Static): the pool within 1 px of it and the total light within 3 %."""
    bpy = factory_blender
    scene = _scene(bpy, motion="STATIC")
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    at_rest = _still(bpy, scene, tmp_path / "rest.exr")
    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    bpy.data.objects["Lamp"].relativity.motion = "ANIMATION"
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    keyed = _still(bpy, scene, tmp_path / "keyed.exr")
    ratio = ch.luminance(keyed).sum() / ch.luminance(at_rest).sum()
    print(f"pool at {_centroid_x(keyed):.1f} px (lamp at rest: {_centroid_x(at_rest):.1f}); total light {ratio:.4f}")
    assert abs(_centroid_x(keyed) - _centroid_x(at_rest)) < 1.0
    assert abs(ratio - 1.0) < 0.03
