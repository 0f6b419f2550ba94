"""Stereo through Blender's own stereoscopy (multiview, Stereo 3D) with the exact camera.

Cycles renders each eye with its own camera matrix; the shader reads the eye's offset from the
camera object (``transform("world", "camera", camera_origin)``) so that both eyes share one shutter
time, one shutter plane and one plane of spatial fixed points (Gray et al. 2020, section 4). The
expected positions come from eqs. (1) and (2) written out in numpy (camera_helpers), per eye.
"""

import math

import numpy as np
import pytest

import camera_helpers as ch
from relativity_addon.physics.shutter import fixed_point_plane

ROTATION = (math.radians(90.0), 0.0, 0.0)  # looks down world +Y: local (x, y, -z) = world (x, z, y)
GRAY_BETA = np.array([0.1, 0.99, 0.0])  # Gray's (0.1, 0, 0.99) in their axes, world axes here
SIZE = (200, 150)


def _read_png(bpy, path):
    """Linear RGB of a PNG written with the Standard view transform (sRGB-encoded). The stereo
    tests write PNG views: Blender 4.5 writes each view's EXR as a multi-view EXR, which its own
    image loader opens as an empty multilayer image."""
    encoded = ch.read_image(bpy, path)[:, :, :3].astype(float)
    return np.where(encoded <= 0.04045, encoded / 12.92, ((encoded + 0.055) / 1.055) ** 2.4)


def _eye_event(camera, eye_local, beta_world, ct_shutter):
    """Scene-frame position (world) of the eye's pinhole at camera time t_S, Gray eq. (1) with the
    camera object's origin as the shared origin."""
    beta_local = camera.rotation.T @ beta_world
    gamma = ch.gamma_of(beta_world)
    x = np.asarray(eye_local, float)
    shifted = x + gamma**2 / (gamma + 1.0) * (beta_local @ x) * beta_local + gamma * ct_shutter * beta_local
    return camera.location + camera.rotation @ shifted


def _eye_camera(camera, position):
    return ch.PinholeCamera(position, camera.rotation, camera.window, camera.size)


def test_vertical_disparity_follows_aberration_per_eye(factory_blender, tmp_path):
    """Parallel eyes 0.4 apart at Gray's beta, t_S = -1, c = 1: each eye's markers where eqs. (1),
    (2) put them (within 0.5 px), and so the vertical disparity between the eyes."""
    bpy = factory_blender
    scene, camera_object = ch.new_scene(bpy, resolution=SIZE, samples=2, rotation_euler=ROTATION)
    stereo = camera_object.data.stereo
    stereo.convergence_mode = "PARALLEL"
    stereo.pivot = "CENTER"
    stereo.interocular_distance = 0.4
    camera = ch.pinhole_model(bpy, scene, camera_object)
    eyes = {"L": (-0.2, 0.0, 0.0), "R": (0.2, 0.0, 0.0)}
    centre = _eye_camera(camera, _eye_event(camera, (0.0, 0.0, 0.0), GRAY_BETA, -1.0))
    material = ch.emission_material(bpy)
    focal_px = SIZE[0] / (camera.window[1] - camera.window[0])
    markers = []
    for index, (px, py) in enumerate([(x, y) for y in (35.0, 75.0, 115.0) for x in (40.0, 100.0, 160.0)]):
        view = camera.local_to_world(camera.pixel_direction(px, py))
        view_scene = ch.scene_direction_for_apparent(view, GRAY_BETA)
        distance = 3.0 + 0.5 * index
        radius = distance * math.sin(3.0 / focal_px * ch.doppler_factor(-view_scene, GRAY_BETA))
        center = centre.location + distance * view_scene
        ch.add_sphere(bpy, scene, center, radius, material, name=f"M{index}", segments=32, rings=16)
        markers.append((center, radius))
    blend = ch.save_blend(bpy, tmp_path / "stereo.blend")
    beta = ",".join(f"{b:.17g}" for b in GRAY_BETA)
    ch.run_render_script(
        blend,
        tmp_path / "pair.png",
        f"--beta={beta}",
        "--shutter=pinhole",
        "--shutter-time=-1",
        "--speed-of-light=1",
        "--no-searchlight",
        "--stereo=views",
    )

    measured, expected, naive = {}, {}, {}
    for eye, offset in eyes.items():
        intensity = ch.luminance(_read_png(bpy, tmp_path / f"pair_{eye}.png"))
        model = _eye_camera(camera, _eye_event(camera, offset, GRAY_BETA, -1.0))
        # The same eye without the shared origin (each eye its own Lorentz origin): what a shader
        # ignoring the eye offset would render; the test must tell the two apart.
        own_origin = _eye_event(camera, (0.0, 0.0, 0.0), GRAY_BETA, -1.0) + camera.rotation @ np.array(offset)
        expected[eye] = [ch.expected_sphere_centroid(model, c, r, GRAY_BETA) for c, r in markers]
        naive[eye] = [ch.expected_sphere_centroid(_eye_camera(camera, own_origin), c, r, GRAY_BETA) for c, r in markers]
        measured[eye] = []
        for guess in expected[eye]:
            found, _ = ch.centroid(intensity, guess, half_window=10)
            assert found is not None, f"{eye}: marker expected at {guess} not found"
            measured[eye].append(found)
    errors = [np.linalg.norm(m - e) for eye in eyes for m, e in zip(measured[eye], expected[eye], strict=True)]
    disparity = np.array([m_l[1] - m_r[1] for m_l, m_r in zip(measured["L"], measured["R"], strict=True)])
    disparity_expected = np.array([e_l[1] - e_r[1] for e_l, e_r in zip(expected["L"], expected["R"], strict=True)])
    disparity_naive = np.array([e_l[1] - e_r[1] for e_l, e_r in zip(naive["L"], naive["R"], strict=True)])
    print(
        f"per-eye position error max {max(errors):.3f} px; vertical disparity measured "
        f"{np.round(disparity, 2)} expected {np.round(disparity_expected, 2)} "
        f"(own-origin eyes would give {np.round(disparity_naive, 2)})"
    )
    assert max(errors) < 0.5
    assert np.abs(disparity - disparity_expected).max() < 0.5
    assert np.abs(disparity_expected).max() > 2.0, "the setup must show vertical parallax"
    assert np.abs(disparity_naive - disparity_expected).max() > 1.0, "the shared origin must matter here"


def test_lorentz_window_pair_equals_rest_pair(factory_blender, tmp_path):
    """Off-axis eyes converging at 5, Gray's beta, t_S = -1, c = 1, Lorentz window: each eye and the
    anaglyph equal the pair at rest. Same seed, so "within render noise" is checked against a bound
    (1e-3) far below the seed-to-seed noise of this scene at 4 samples (0.007-0.008 per eye,
    measured); the pair without the window differs from rest by 0.42 (measured once, dropped to keep
    the suite fast; test_camera_gray_section3 checks it for one camera)."""
    bpy = factory_blender
    scene, camera_object = ch.new_scene(bpy, resolution=(128, 96), samples=4, rotation_euler=ROTATION)
    stereo = camera_object.data.stereo
    stereo.convergence_mode = "OFFAXIS"
    stereo.interocular_distance = 0.4
    stereo.convergence_distance = 5.0
    for index, (x, y, z, r) in enumerate([(-1.5, 6.0, 0.5, 0.6), (1.0, 9.0, -0.5, 1.0), (0.3, 4.0, 0.8, 0.3)]):
        ch.add_sphere(bpy, scene, (x, y, z), r, ch.emission_material(bpy, name=f"E{index}", strength=1.0 + index))
    blend = ch.save_blend(bpy, tmp_path / "window.blend")
    beta = ",".join(f"{b:.17g}" for b in GRAY_BETA)
    common = ("--shutter-time=-1", "--speed-of-light=1", "--no-searchlight", "--no-doppler", "--seed=3")
    cases = (("rest", "--beta=0,0,0"), ("window", f"--beta={beta}", "--lorentz-window"))
    pairs, anaglyphs = [], []
    for name, *options in cases:
        ch.run_render_script(blend, tmp_path / f"{name}.png", *common, *options, "--stereo=views")
        pairs.append([_read_png(bpy, tmp_path / f"{name}_{eye}.png") for eye in "LR"])
        ch.run_render_script(blend, tmp_path / f"{name}-anaglyph.png", *common, *options, "--stereo=anaglyph")
        anaglyphs.append(_read_png(bpy, tmp_path / f"{name}-anaglyph.png"))
    # The window with a shutter model (Fig. 10's set-up): both eyes' arbitrary-plane shutter in the
    # window plane (eq. 6 for t_W = t_S, camera-local axes), opening at t_W; every ray of either eye
    # then crosses the window at a spatial fixed point of the shared frame, so the pair is the rest
    # pair too. An eye with its own plane (through its own pinhole) would not be.
    rotation = np.array(camera_object.matrix_world.to_3x3())
    point, normal = fixed_point_plane(-1.0, rotation.T @ GRAY_BETA, 1.0)
    plane = (
        f"--shutter-plane-point={','.join(repr(float(v)) for v in point)}",
        f"--shutter-plane-normal={','.join(repr(float(v)) for v in normal)}",
    )
    ch.run_render_script(
        blend,
        tmp_path / "shutter.png",
        *common,
        f"--beta={beta}",
        "--window-time=-1",
        "--shutter=arbitrary_plane",
        *plane,
        "--stereo=views",
    )
    shutter_pair = [_read_png(bpy, tmp_path / f"shutter_{eye}.png") for eye in "LR"]
    (rest_l, rest_r), (window_l, window_r) = pairs
    # Side by side (not squeezed): the left view, then the right one, in one image twice as wide.
    ch.run_render_script(blend, tmp_path / "window-sbs.png", *common, *cases[1][1:], "--stereo=side-by-side")
    side_by_side = _read_png(bpy, tmp_path / "window-sbs.png")
    assert side_by_side.shape[1] == 2 * window_l.shape[1]
    halves = np.split(side_by_side, 2, axis=1)
    assert np.abs(halves[0] - window_l).max() < 0.01 and np.abs(halves[1] - window_r).max() < 0.01
    differences = [np.abs(window_l - rest_l).mean(), np.abs(window_r - rest_r).mean()]
    anaglyph_difference = np.abs(anaglyphs[1] - anaglyphs[0]).mean()
    parallax = np.abs(rest_l - rest_r).mean()
    shutter_differences = [np.abs(shutter_pair[0] - rest_l).mean(), np.abs(shutter_pair[1] - rest_r).mean()]
    print(
        f"|window - rest| per eye {differences}, anaglyph {anaglyph_difference:.2g}; |L - R| at rest {parallax:.3f}; "
        f"window with the plane shutter: |pair - rest| per eye {shutter_differences}"
    )
    assert max(shutter_differences) < 1e-3
    assert rest_l.mean() > 0.005 and rest_r.mean() > 0.005
    assert parallax > 0.01, "the eyes must see different images"
    assert max(differences) < 1e-3
    assert anaglyph_difference < 1e-3
    # Blender's anaglyph: red from the left eye, green and blue from the right one.
    assert np.allclose(anaglyphs[0][..., 0], rest_l[..., 0], atol=0.02)
    assert np.allclose(anaglyphs[0][..., 1:], rest_r[..., 1:], atol=0.02)


def test_stereo_settings_reach_the_camera_and_toe_in_is_refused(factory_blender):
    """In-process: the eye-offset parameters follow Blender's stereo settings; toe-in (eyes turned
    apart) and stereo panoramas (spherical stereo) are refused in one line, the camera restored."""
    import relativity_addon
    from relativity_addon.blender.pipeline import effect

    bpy = factory_blender
    relativity_addon.register()
    try:
        scene, camera_object = ch.new_scene(
            bpy, resolution=(64, 48), samples=1, rotation_euler=ROTATION, location=(1.0, -2.0, 0.5)
        )
        scene.relativity.beta = tuple(0.5 * GRAY_BETA)
        effect.apply(scene)
        custom = camera_object.data.cycles_custom
        assert not custom["use_eye_offset"]
        scene.render.use_multiview = True
        scene.render.views_format = "STEREO_3D"
        effect.sync(scene)
        assert custom["use_eye_offset"] and custom["settings_valid"]
        assert tuple(custom["camera_origin"]) == pytest.approx((1.0, -2.0, 0.5))
        camera_object.data.stereo.convergence_mode = "TOE"
        effect.sync(scene)
        assert not custom["settings_valid"]
        assert any("toe-in" in w for w in effect.scene_warnings(scene))
        effect.remove(scene)
        with pytest.raises(effect.RelativityError, match="toe-in"):
            effect.apply(scene)
        assert camera_object.data.type == "PERSP"
        camera_object.data.stereo.convergence_mode = "OFFAXIS"
        camera_object.data.type = "PANO"
        with pytest.raises(effect.RelativityError, match="stereo panoramas"):
            effect.apply(scene)
        assert camera_object.data.type == "PANO"
    finally:
        relativity_addon.unregister()
