"""Compensated exposure: one factor per frame, nothing else, and the factor in the output's
metadata (the EXR header's Note).

The expected factor is computed here from the camera's own pixel grid and keyframes:
``k = exp(-4 <ln D>)`` with ``D = 1 / (gamma (1 - beta.d'))`` per pixel direction ``d'`` (docs/physics.md).
"""

import re

import numpy as np
import pytest

import camera_helpers as ch

RESOLUTION = (64, 48)
FPS = 24
C = 24.0  # scene units per second: one unit per frame is beta 1


def _scene(bpy):
    scene, camera = ch.new_scene(bpy, resolution=RESOLUTION, samples=4)
    scene.render.fps = FPS
    material = ch.emission_material(bpy)
    for x, y, z in ((-1.5, 0.5, -6.0), (0.0, 0.0, -5.0), (1.2, -0.6, -4.0)):
        ch.add_sphere(bpy, scene, (x, y, z), 0.5, material, segments=24, rings=12)
    scene.relativity.speed_of_light = C
    return scene, camera


def _expected_exposure(bpy, scene, camera, beta_world):
    model = ch.pinhole_model(bpy, scene, camera)
    width, height = model.size
    px, py = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    directions = model.pixel_direction(px, py)  # camera-local, unit
    beta = model.world_to_local(beta_world)
    gamma = 1.0 / np.sqrt(1.0 - beta @ beta)
    log_d = -np.log(gamma * (1.0 - directions @ beta))
    return float(np.exp(-4.0 * log_d.mean()))


def _note_exposure(path):
    header = path.read_bytes()[:20000]
    match = re.search(rb"relativity: exposure=([0-9.eE+-]+)", header)
    assert match, "the exposure is in the file's metadata"
    return float(match.group(1))


def _render(bpy, scene, path):
    return ch.render_exr(bpy, scene, path)


def test_compensation_scales_the_frame_by_one_factor(relativity_addon, tmp_path):
    bpy = __import__("bpy")
    scene, camera = _scene(bpy)
    beta = np.array([0.3, 0.0, -0.6])
    scene.relativity.beta = beta
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    fixed = _render(bpy, scene, tmp_path / "fixed.exr")
    assert _note_exposure(tmp_path / "fixed.exr") == 1.0
    scene.relativity.exposure_mode = "COMPENSATED"
    compensated = _render(bpy, scene, tmp_path / "compensated.exr")
    lit = fixed[..., :3].sum(-1) > 1e-3
    assert lit.sum() > 100
    ratio = compensated[..., :3][lit] / fixed[..., :3][lit]
    expected = _expected_exposure(bpy, scene, camera, beta)
    noted = _note_exposure(tmp_path / "compensated.exr")
    print(
        f"exposure: expected {expected:.6g}, in the metadata {noted:.6g}, rendered ratio {np.median(ratio):.6g} "
        f"(spread {ratio.min():.6g}..{ratio.max():.6g})"
    )
    assert np.allclose(ratio, noted, rtol=1e-4), "one factor for every pixel"
    assert noted == pytest.approx(expected, rel=5e-3)
    assert np.all(compensated[..., :3][~lit] == 0.0)
    bpy.ops.relativity.remove_all()
    assert scene.render.stamp_note_text == "" and not scene.render.use_stamp_note, "the user's note is back"


def test_each_frame_of_an_animation_has_its_own_exposure(relativity_addon, tmp_path):
    """The camera speeds up (linear keys, 0.3c then 0.7c along -Z): each frame's file carries the
    exposure of that frame's velocity (not one frame late; the camera's parameters, which scale
    the pixels, are written in the same handler)."""
    bpy = __import__("bpy")
    scene, camera = _scene(bpy)
    speeds = {1: 0.3, 2: 0.7}
    keys = ((0.0, 0.0), (1.5, -0.3 * 1.5), (3.0, -0.3 * 1.5 - 0.7 * 1.5))  # (frame, z): C / FPS = 1 unit per frame
    for frame, z in keys:
        camera.location = (0.0, 0.0, z)
        camera.keyframe_insert("location", frame=frame)
    for fcurve in ch.compat.action_fcurves(camera.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
    scene.relativity.velocity_source = "CAMERA_ANIMATION"
    scene.relativity.exposure_mode = "COMPENSATED"
    scene.frame_start, scene.frame_end = 1, 2
    scene.frame_set(1)
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    scene.render.filepath = str(tmp_path / "frame_#")
    scene.render.image_settings.file_format = "OPEN_EXR"
    bpy.ops.render.render(animation=True)
    for frame, speed in speeds.items():
        path = tmp_path / f"frame_{frame}.exr"
        scene.frame_set(frame)
        expected = _expected_exposure(bpy, scene, camera, np.array([0.0, 0.0, -speed]))
        noted = _note_exposure(path)
        print(f"frame {frame}: {speed}c, exposure expected {expected:.6g}, in the metadata {noted:.6g}")
        assert noted == pytest.approx(expected, rel=5e-3)
