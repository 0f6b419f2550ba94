"""Observer velocity from the camera's keyframes: finite difference in scene time t = frame / fps,
checked against slopes known from the keyframes and against Blender's own evaluated matrices."""

import math

import numpy as np
import pytest

import pipeline_helpers as wh


@pytest.fixture
def animation(relativity_addon, factory_blender):
    import importlib

    return importlib.import_module(f"{relativity_addon}.blender.scene.animation")


@pytest.fixture
def snapshot(relativity_addon, factory_blender):
    import importlib

    return importlib.import_module(f"{relativity_addon}.blender.scene.snapshot")


def test_linear_keys_give_slope_over_c(snapshot, factory_blender):
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy)
    scene.render.fps, scene.render.fps_base = 30, 1.001  # NTSC: 29.97 frames per second
    fps = 30 / 1.001
    wh.keyframe_camera_path(camera, [(1, (0.0, 0.0, 0.0)), (11, (3.0, -4.0, 0.0)), (21, (3.0, -4.0, -2.0))])
    settings = scene.relativity
    settings.speed_of_light = 25.0
    first = np.array([3.0, -4.0, 0.0]) / (10 / fps) / 25.0  # 0.5994 c along (3, -4, 0)/5
    second = np.array([0.0, 0.0, -2.0]) / (10 / fps) / 25.0
    for frame in (2.0, 5.5, 10.25):
        np.testing.assert_allclose(snapshot.camera_beta_at(scene, frame), first, atol=1e-5)
    np.testing.assert_allclose(snapshot.camera_beta_at(scene, 15.0), second, atol=1e-5)
    assert snapshot.check_animation_speed(scene, 1, 21) == pytest.approx(np.linalg.norm(first), abs=1e-5)

    # The snapshot takes it at each frame, the frame-change handler writes it into the shader.
    settings.velocity_source = "CAMERA_ANIMATION"
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    scene.frame_set(4)
    # Unrotated camera: shader axes are (x, y, -z) of the world.
    np.testing.assert_allclose(tuple(camera.data.cycles_custom["beta"]), first * [1, 1, -1], atol=1e-5)
    scene.frame_set(16)
    np.testing.assert_allclose(tuple(camera.data.cycles_custom["beta"]), second * [1, 1, -1], atol=1e-5)

    settings.speed_of_light = 0.5 * 25.0 * np.linalg.norm(second)  # second segment now at 2 c
    with pytest.raises(snapshot.RelativityError, match=r"moves at 2 c at frame 12:"):
        snapshot.check_animation_speed(scene, 12, 21)
    # From rest before frame 1: at frame 1 the central difference sees half the first segment's
    # 5 units / (10 / 29.97 s) = 14.99 units/s, i.e. 7.49 / 2.997 = 2.5 c: refused at frame 1.
    scene.frame_start, scene.frame_end = 1, 21
    with pytest.raises(RuntimeError, match=r"moves at 2.5 c at frame 1:"):
        bpy.ops.relativity.check_animation()
    settings.speed_of_light = 25.0
    assert bpy.ops.relativity.check_animation() == {"FINISHED"}


def test_keyframe_evaluation_matches_blender_world_matrices(animation, factory_blender):
    """Parented, rotated, quaternion and Euler channels, delta transforms, Bezier easing: the
    world matrix from keyframes equals Blender's evaluated matrix_world at whole and sub-frames."""
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy)
    rig = bpy.data.objects.new("Rig", None)
    scene.collection.objects.link(rig)
    rig.rotation_mode = "QUATERNION"
    rig.delta_location = (0.5, 0.0, 0.2)
    for frame, location, angle in ((1, (0, 0, 0), 0.0), (9, (4, 1, 0), 1.0)):
        rig.location = location
        rig.rotation_quaternion = (math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2))
        rig.keyframe_insert("location", frame=frame)
        rig.keyframe_insert("rotation_quaternion", frame=frame)
    camera.parent = rig
    camera.rotation_mode = "YXZ"
    camera.scale = (1.0, 2.0, 1.0)
    camera.delta_rotation_euler = (0.1, 0.0, 0.0)
    for frame, location, rotation in ((1, (0, 1, 0), (0, 0, 0)), (9, (1, 2, -3), (0.4, 0.2, -0.3))):
        camera.location, camera.rotation_euler = location, rotation
        camera.keyframe_insert("location", frame=frame)
        camera.keyframe_insert("rotation_euler", frame=frame)
    for frame, subframe in ((1, 0.0), (3, 0.5), (6, 0.25), (9, 0.0)):
        scene.frame_set(frame, subframe=subframe)
        expected = np.array(camera.matrix_world)
        computed = np.array(animation.world_matrix_at(camera, frame + subframe))
        np.testing.assert_allclose(computed, expected, atol=1e-5)


def test_constraints_are_refused_not_guessed(snapshot, factory_blender):
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy)
    wh.keyframe_camera_path(camera, [(1, (0, 0, 0)), (5, (0, 0, -1))])
    camera.constraints.new("COPY_LOCATION")
    with pytest.raises(snapshot.RelativityError, match="has constraints"):
        snapshot.check_animation_speed(scene)
    scene.relativity.velocity_source = "CAMERA_ANIMATION"
    with pytest.raises(RuntimeError, match="has constraints"):
        bpy.ops.relativity.setup_scene()
    assert camera.data.type == "PERSP"
