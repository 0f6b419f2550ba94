"""Fly-through frames stepped in the traveller's proper time (``render.py --proper-time``).

The camera accelerates along -Z with constant proper acceleration ``a`` from rest at frame 0
(keyframed at every frame, linear in between): ``z(t) = -(c^2 / a)(sqrt(1 + (a t / c)^2) - 1)``,
whose clock reads ``tau = (c / a) asinh(a t / c)`` (docs/physics.md). Output frame ``k`` must be
rendered at the scene time ``t_k = (c / a) sinh(a tau_k / c)`` with ``tau_k = k / fps``: read back
from each file's metadata (the scene frame it was rendered at) and from the camera's keyframes
there.
"""

import math
import re

import pytest

import pipeline_helpers as wh

ch = wh.ch
C = 10.0
ACCELERATION = 5.0
FPS = 24


def _z(t):
    return -(C * C / ACCELERATION) * (math.sqrt(1.0 + (ACCELERATION * t / C) ** 2) - 1.0)


def test_frames_step_in_proper_time(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, _sphere = wh.new_scene(bpy, resolution=(16, 12), samples=1)
    scene.render.fps = FPS
    wh.keyframe_camera_path(camera, [(frame, (0.0, 0.0, _z(frame / FPS))) for frame in range(0, 121)])
    scene.relativity.speed_of_light = C
    scene.frame_end = 120
    blend = wh.save_blend(bpy, tmp_path / "accelerating.blend")
    result = wh.run_render_script(
        blend, f"--out={tmp_path / 'f.png'}", "--frames=70-72", "--proper-time", "--velocity-from-animation"
    )
    assert result.returncode == 0, result.stderr[-2000:]
    for k in (70, 71, 72):
        header = (tmp_path / f"f_{k:04d}.png").read_bytes()
        scene_frame = float(re.search(rb"relativity: .* frame=([0-9.eE+-]+)", header).group(1))
        tau = k / FPS
        expected_time = C / ACCELERATION * math.sinh(ACCELERATION * tau / C)
        curves = ch.compat.action_fcurves(camera.animation_data)
        z_at_frame = next(f for f in curves if f.data_path == "location" and f.array_index == 2).evaluate(scene_frame)
        print(
            f"frame {k}: traveller {tau:.4f} s, rendered at scene frame {scene_frame:.4f} "
            f"(t {scene_frame / FPS:.5f} s, expected {expected_time:.5f} s); camera z {z_at_frame:.4f} "
            f"(world line {_z(expected_time):.4f})"
        )
        assert scene_frame / FPS == pytest.approx(expected_time, abs=2e-3)
        assert z_at_frame == pytest.approx(_z(expected_time), abs=2e-2)
        assert scene_frame > k + 25, "the traveller's clock runs slow: scene frames run ahead"
