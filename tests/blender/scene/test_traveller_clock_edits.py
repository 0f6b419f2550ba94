"""The traveller's clock (``scene/traveller.py``, the panel's proper time) follows an edit of the
camera's motion at the same frame, also one made through an F-curve modifier: its table was kept
under the camera's keys' signature, which gave None for a curve with modifiers, so editing the
modifier left the clock reading the old motion (found: 1.14481 s against 1.14406 s after a Noise
modifier's strength changed). Against docs/physics.md's ``tau = t / gamma`` for a constant speed."""

import math

import pytest

C = 10.0
FPS = 24


@pytest.fixture
def traveller(relativity_addon, factory_blender):
    import importlib

    return importlib.import_module(f"{relativity_addon}.blender.scene.traveller")


def test_the_clock_follows_an_edit_of_the_cameras_f_curve_modifier(traveller, factory_blender):
    bpy = factory_blender
    compat = traveller.animation.compat
    scene = bpy.context.scene
    scene.render.fps = FPS
    scene.frame_start, scene.frame_end = 1, 48
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.relativity.speed_of_light = C
    scene.relativity.velocity_source = "CAMERA_ANIMATION"
    for frame in (1, 48):
        camera.keyframe_insert("location", index=0, frame=frame)  # held at 0: the modifier moves it
    curve = next(c for c in compat.action_fcurves(camera.animation_data) if c.data_path == "location")
    generator = curve.modifiers.new("GENERATOR")  # x = a0 + a1 * frame, the keys replaced
    frame = 30
    scene.frame_set(frame)
    for beta in (0.3, 0.6):
        generator.coefficients = (0.0, beta * C / FPS)  # units per frame at beta c
        expected = frame / FPS * math.sqrt(1.0 - beta * beta)
        assert traveller.proper_time_at(scene, frame) == pytest.approx(expected, rel=1e-6), beta
