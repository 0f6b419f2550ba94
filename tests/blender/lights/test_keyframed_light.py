"""A keyframed (ANIMATION) point light behind the exact camera: its path from its keyframes, its
velocity from their slope. The lamp of test_moving_point_light.py's floor moves along +x with linear
keyframes at 0.3c until frame 31 and 0.6c after; frame 50 is rendered. Expected: eq. 19 with
retarded positions on that path, written out here in numpy (fixed-point iteration in time, the
velocity of the piece the retarded time falls on), independently of the add-on.
"""

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import test_moving_point_light as floor  # noqa: E402

FPS = 24
FRAME = 50
KINK_FRAME = 31
SLOW, FAST = 0.3, 0.6  # fractions of c before and after the kink
C = floor.C


def _path(s):
    """The lamp at c (t - t_o) = s (t_o: frame 50) and its velocity over c."""
    kink = C * (KINK_FRAME - FRAME) / FPS
    late = s >= kink
    x = np.where(late, floor.LAMP[0] + FAST * s, floor.LAMP[0] + FAST * kink + SLOW * (s - kink))
    position = np.stack([x, np.full_like(x, floor.LAMP[1]), np.full_like(x, floor.LAMP[2])], axis=-1)
    return position, np.where(late, FAST, SLOW)


def _retarded(points):
    c_tx = -np.linalg.norm(points - floor.CAMERA, axis=-1)
    s = c_tx.copy()
    for _ in range(120):  # contracts by the speed, at most 0.6 per step
        s = c_tx - np.linalg.norm(points - _path(s)[0], axis=-1)
    return s


def _expected(points):
    c_tx = -np.linalg.norm(points - floor.CAMERA, axis=-1)
    s = c_tx.copy()
    for _ in range(120):  # contracts by the speed, at most 0.6 per step
        s = c_tx - np.linalg.norm(points - _path(s)[0], axis=-1)
    source, speed = _path(s)
    r = c_tx - s
    n = (points - source) / r[..., None]
    d = 1.0 / ((1.0 / np.sqrt(1.0 - speed**2)) * (1.0 - speed * n[..., 0]))
    return floor.ALBEDO / math.pi * d**4 * np.maximum(-n[..., 2], 0.0) * (floor.POWER / (4.0 * math.pi)) / r**2


def _keyframe(lamp, frame, x):
    lamp.location = (x, floor.LAMP[1], floor.LAMP[2])
    lamp.keyframe_insert("location", frame=frame)


def test_keyframed_light_follows_its_keyframes(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, lamp = floor._floor_scene(bpy, beta=None, samples=floor.SAMPLES_LAMPS)
    scene.render.fps = FPS
    kink_x = floor.LAMP[0] + FAST * C * (KINK_FRAME - FRAME) / FPS
    _keyframe(lamp, 1, kink_x + SLOW * C * (1 - KINK_FRAME) / FPS)
    _keyframe(lamp, KINK_FRAME, kink_x)
    _keyframe(lamp, 100, floor.LAMP[0] + FAST * C * (100 - FRAME) / FPS)
    for curve in floor.ch.compat.action_fcurves(lamp.animation_data):
        for point in curve.keyframe_points:
            point.interpolation = "LINEAR"
    lamp.relativity.motion = "ANIMATION"
    scene.frame_set(FRAME)
    assert abs(lamp.matrix_world.translation.x - floor.LAMP[0]) < 1e-5
    floor._effect().apply(scene)
    assert lamp.hide_render
    image = floor._render(bpy, scene, tmp_path / "keyframed.exr")[..., 1]
    points = floor._floor_points(bpy, scene, camera)
    expected = _expected(points)[floor.ROWS].mean(0)
    constant, _, _ = floor._expected_radiance(points, np.array([FAST, 0.0, 0.0]))
    constant = constant[floor.ROWS].mean(0)
    measured = image[floor.ROWS].mean(0)
    peak = expected.max()
    # The velocity jumps at the kink, so D and the brightness jump where the retarded time crosses it;
    # the stand-in lamps' straight piece across the kink has the chord's velocity: judged apart (the
    # pixels whose retarded position lies between the two lamps around the kink).
    jump = int(np.argmax(np.abs(np.diff(expected)))) + 1
    kink_x = floor.LAMP[0] + FAST * C * (KINK_FRAME - FRAME) / FPS
    lamp_x = np.unique([obj.location.x for obj in scene.objects if obj.type == "LIGHT" and not obj.hide_render])
    chord = lamp_x[np.searchsorted(lamp_x, kink_x) - 1 : np.searchsorted(lamp_x, kink_x) + 1]
    retarded_x = _path(_retarded(points))[0][floor.ROWS, :, 0].mean(0)
    away = (retarded_x < chord[0]) | (retarded_x > chord[-1])
    error = np.abs(measured - expected)[away].max() / peak
    chord_error = np.abs(measured - expected)[~away].mean() / peak
    ratio, expected_ratio = (measured[jump + 3] / measured[jump - 4]), (expected[jump + 3] / expected[jump - 4])
    print(
        f"keyframed light: peak {peak:.3f} at {np.argmax(expected)} (rendered {measured.max():.3f} at "
        f"{np.argmax(measured)}); max error {error:.4f} of the peak off the lamps' piece across the kink "
        f"({np.sum(~away)} px, mean error {chord_error:.4f} there); jump at pixel {jump}, "
        f"across it {ratio:.3f} (expected {expected_ratio:.3f}); a constant {FAST}c light differs "
        f"by {np.abs(constant - expected).max() / peak:.3f} of the peak"
    )
    assert error < 0.05
    assert np.sum(~away) < 20
    assert abs(ratio - expected_ratio) < 0.15 * expected_ratio  # 4 px before the jump: on the piece across the kink
    assert expected_ratio < 0.5  # the jump is there
    assert np.abs(constant - expected).max() > 0.2 * peak  # the keyframes matter
