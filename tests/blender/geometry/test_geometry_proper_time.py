"""Proper time: a clock passing at 0.9c runs slow. Its hand (a keyframed rotation, the clock's own
animation) is seen at the angle ``omega tau`` of its proper time ``tau = t_e / gamma`` at the
retarded time ``t_e`` of the light that reaches the camera; at rest the angle is ``omega t_e``.

The expected picture is computed here: the hand's tip and the clock's centre move on their world
lines (centre ``p0 + beta c (t - t_o)``, tip ``centre + C R(omega t / gamma) (r, 0, 0)``, ``C``
the Lorentz contraction along ``beta``), each is seen at its own retarded time (solved here by
bisection on the light cone), and projected through the camera; the angle of the tip about the
centre in the image is compared with the render's, where each is the centroid of its marker's
colour.
"""

import math

import numpy as np
import pytest

import geometry_helpers as gh
from geometry_helpers import ch

RESOLUTION = (320, 160)
FPS = 24
C = 10.0  # scene units per second
OMEGA = 1.0  # rad/s of the clock's own hand
RADIUS = 1.0
FRAME = 48  # t_o = 2 s
DISTANCE = 8.0


def _clock(bpy, scene, location, beta):
    """One object: a red dot at its origin (the centre) and a green dot at (RADIUS, 0, 0) (the hand's
    tip), turning about its local Z at OMEGA rad/s by linear rotation keys."""
    clock = gh.clock_face(bpy, scene, RADIUS)
    clock.location = location
    for frame in (0, 240):
        clock.rotation_euler = (0.0, 0.0, OMEGA * frame / FPS)
        clock.keyframe_insert("rotation_euler", index=2, frame=frame)
    for fcurve in ch.compat.action_fcurves(clock.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
    clock.relativity.motion = "CONSTANT"
    clock.relativity.beta = beta
    return clock


def _retarded(position, t_o, camera_position):
    """Emission time t_e of the light from ``position(t)`` reaching the camera at ``t_o``."""
    low, high = t_o - 100.0, t_o
    for _ in range(200):
        middle = 0.5 * (low + high)
        ahead = np.linalg.norm(position(middle) - camera_position) - C * (t_o - middle)
        low, high = (low, middle) if ahead > 0.0 else (middle, high)
    return 0.5 * (low + high)


def _expected(bpy, scene, camera, p0, beta, dilation=True):
    """(centre pixel, tip pixel, proper time of the tip's light) of the clock in the image."""
    beta = np.asarray(beta, float)
    gamma = 1.0 / math.sqrt(1.0 - beta @ beta)
    t_o = FRAME / FPS
    contraction = np.eye(3) - (1.0 - 1.0 / gamma) * np.outer(beta, beta) / max(beta @ beta, 1e-30)
    clock_rate = 1.0 / gamma if dilation else 1.0

    def centre(t):
        return np.asarray(p0, float) + beta * C * (t - t_o)

    def tip(t):
        angle = OMEGA * t * clock_rate
        return centre(t) + contraction @ np.array([RADIUS * math.cos(angle), RADIUS * math.sin(angle), 0.0])

    model = ch.pinhole_model(bpy, scene, camera)
    pixels = []
    for position in (centre, tip):
        t_e = _retarded(position, t_o, model.location)
        pixels.append(model.project_direction(position(t_e) - model.location))
    t_tip = _retarded(tip, t_o, model.location)
    return pixels[0], pixels[1], t_tip * clock_rate


def _angle(centre, tip):
    return math.degrees(math.atan2(-(tip[1] - centre[1]), tip[0] - centre[0]))  # image y points down


@pytest.mark.parametrize("speed", [0.0, 0.9])
def test_clock_hand_shows_proper_time(relativity_addon, tmp_path, speed):
    bpy = __import__("bpy")
    scene, camera = ch.new_scene(bpy, resolution=RESOLUTION, samples=16)
    scene.render.fps = FPS
    scene.relativity.speed_of_light = C
    beta = (speed, 0.0, 0.0)
    # Drawn where the light now arriving left it: its image near the middle of the picture.
    p0 = (speed * C * DISTANCE / C, 0.0, -DISTANCE)
    _clock(bpy, scene, p0, beta)
    scene.frame_set(FRAME)
    scene.relativity.method = "GEOMETRY"
    scene.relativity.beta = (0.0, 0.0, 0.0)
    scene.relativity.use_doppler = False
    scene.relativity.use_searchlight = False
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    image = gh.render_exr(bpy, scene, tmp_path / "clock.exr") if hasattr(gh, "render_exr") else None
    if image is None:
        scene.render.filepath = str(tmp_path / "clock.exr")
        scene.render.use_file_extension = False
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        bpy.ops.render.render(write_still=True)
        image = ch.read_exr(bpy, tmp_path / "clock.exr")

    def centroid(channel, others):
        weight = np.where((image[..., channel] > 0.2) & (image[..., others].max(-1) < 0.1), image[..., channel], 0.0)
        assert weight.sum() > 3.0, "the marker is in the picture"
        rows, columns = np.indices(weight.shape)
        return np.array([(weight * (columns + 0.5)).sum(), (weight * (rows + 0.5)).sum()]) / weight.sum()

    centre, tip = centroid(0, [1, 2]), centroid(1, [0, 2])
    measured = _angle(centre, tip)
    centre_x, tip_x, tau = _expected(bpy, scene, camera, p0, beta)
    expected = _angle(centre_x, tip_x)
    _, tip_scene_time, t_e = _expected(bpy, scene, camera, p0, beta, dilation=False)
    undilated = _angle(centre_x, tip_scene_time)
    print(
        f"{speed}c: hand at {measured:.2f} deg in the render, {expected:.2f} deg expected (proper time "
        f"{tau:.3f} s at the retarded time {t_e:.3f} s); without time dilation {undilated:.2f} deg"
    )
    assert abs(measured - expected) < 1.0
    if speed > 0.0:
        assert abs(undilated - expected) > 10.0, "time dilation must be visible in this set-up"
