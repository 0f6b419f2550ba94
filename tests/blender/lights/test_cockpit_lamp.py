"""A lamp moving with the camera (issue 28 part 1: *Moves With Camera* on a lamp parented to the
camera) lights the floor ahead with eq. 19's beaming from its retarded positions, the camera's
velocity being the lamp's: the same measurement as ``test_moving_lights_moving_observer`` (each
pixel ``D_o^4`` times the floor's scene-frame radiance from ``test_moving_point_light``'s numpy
fixed-point solution, seen through aberration), with the observer and the lamp at one velocity.

Before this change the lamp, parented to the camera but with no velocity of its own, lit the floor
as a lamp at rest in the scene (no beaming, no retarded position).
"""

import numpy as np
import pytest
import test_keyframed_light as kl
import test_moving_blackbody_light as bb
import test_moving_lights_moving_observer as mo
import test_moving_point_light as mp

SUBPIXELS = mo.SUBPIXELS


def _reference(bpy, scene, camera, observer, lamp_beta=None):
    """``D_o^4`` times the floor's radiance from a point lamp moving with ``observer`` (or with
    ``lamp_beta``), averaged over each pixel, and ``D_o``."""
    lamp_beta = observer if lamp_beta is None else lamp_beta
    seen, doppler = [], []
    for offset in ((x, y) for y in SUBPIXELS for x in SUBPIXELS):
        points, observer_doppler = bb._observed_floor_points(bpy, scene, camera, observer, offset, mp.CAMERA)
        seen.append(observer_doppler**4 * mp._expected_radiance(points, lamp_beta)[0])
        doppler.append(observer_doppler)
    return np.mean(seen, axis=0), np.mean(doppler, axis=0)


@pytest.mark.parametrize(
    ("observer", "samples"), [((0.5, 0.0, 0.0), 256), ((0.0, 0.0, -0.9), 512)], ids=["sideways-0.5c", "ahead-0.9c"]
)
def test_lamp_moving_with_the_camera_follows_eq_19(relativity_addon, factory_blender, tmp_path, observer, samples):
    bpy = factory_blender
    observer = np.array(observer)
    scene, camera, lamp = mp._floor_scene(bpy, beta=None)
    lamp.parent = camera
    lamp.matrix_parent_inverse = camera.matrix_world.inverted()
    lamp.relativity["moves_with_camera"] = True  # by its stored value: the test runs on the code before it too
    bpy.context.view_layer.update()
    assert np.allclose(lamp.matrix_world.translation, mp.LAMP)
    scene.render.resolution_x, scene.render.resolution_y = mo.RESOLUTION
    scene.cycles.samples = samples
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = tuple(observer)
    scene.relativity.use_doppler = False
    mp._effect().apply(scene)
    image = mp.ch.luminance(mp._render(bpy, scene, tmp_path / "lamp.exr"))
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    expected, observer_doppler = _reference(bpy, scene, camera, observer)
    label = f"lamp moving with the camera at {observer}"
    error, offset = mo._compare(image, expected, label)
    # the lamp at rest in the scene (what it was before): no beaming, no retarded position
    at_rest = _reference(bpy, scene, camera, observer, lamp_beta=np.zeros(3))[0]
    rest_error = mo._compare(image, at_rest, f"{label}, against the lamp at rest")[0]
    assert error < 0.05
    assert offset <= 2
    assert rest_error > 0.3


def test_accelerating_camera_lamp_follows_its_keyframed_path(relativity_addon, factory_blender, tmp_path):
    """The velocity from the camera's keyframes: the camera, and the lamp parented to it, at 0.3c
    until frame 31 and 0.6c after (``test_keyframed_light``'s path, linear keyframes), frame 50. The
    floor against eq. 19 from the lamp's retarded positions on that path (``test_keyframed_light``'s
    numpy solution), seen at the frame's 0.6c through aberration with ``D_o^4``. Before this change
    the lamp moved uniformly at the frame's velocity over its light's travel time (Blender 5.2
    crashed at frame changes with the keyframed path: stand-ins made there with the cockpit's
    Render Layers node in the compositor)."""
    bpy = factory_blender
    scene, camera, lamp = mp._floor_scene(bpy, beta=None)
    scene.render.fps = kl.FPS
    lamp.parent = camera
    lamp.matrix_parent_inverse = camera.matrix_world.inverted()
    lamp.relativity["moves_with_camera"] = True
    shift = mp.CAMERA[0] - mp.LAMP[0]
    kink_x = mp.LAMP[0] + kl.FAST * kl.C * (kl.KINK_FRAME - kl.FRAME) / kl.FPS
    for frame, x in (
        (1, kink_x + kl.SLOW * kl.C * (1 - kl.KINK_FRAME) / kl.FPS),
        (kl.KINK_FRAME, kink_x),
        (100, mp.LAMP[0] + kl.FAST * kl.C * (100 - kl.FRAME) / kl.FPS),
    ):
        camera.location = (x + shift, mp.CAMERA[1], mp.CAMERA[2])
        camera.keyframe_insert("location", frame=frame)
    for curve in mp.ch.compat.action_fcurves(camera.animation_data):
        for point in curve.keyframe_points:
            point.interpolation = "LINEAR"
    scene.relativity.speed_of_light = kl.C
    scene.relativity.velocity_source = "CAMERA_ANIMATION"
    scene.frame_set(kl.FRAME)
    assert np.allclose(lamp.matrix_world.translation, mp.LAMP, atol=1e-5)
    scene.render.resolution_x, scene.render.resolution_y = mo.RESOLUTION
    scene.cycles.samples = 512
    scene.relativity.method = "CAMERA"
    scene.relativity.use_doppler = False
    mp._effect().apply(scene)
    observer = np.array([kl.FAST, 0.0, 0.0])
    keyframed, uniform = [], []
    for offset in ((x, y) for y in SUBPIXELS for x in SUBPIXELS):
        points, observer_doppler = bb._observed_floor_points(bpy, scene, camera, observer, offset, mp.CAMERA)
        keyframed.append(observer_doppler**4 * kl._expected(points))
        uniform.append(observer_doppler**4 * mp._expected_radiance(points, observer)[0])
    expected, constant = np.mean(keyframed, axis=0), np.mean(uniform, axis=0)
    # The velocity jumps at the kink; the stand-in lamps' straight piece across it has the chord's
    # velocity (as in test_keyframed_light): judged apart, the pixels whose retarded position lies
    # between the two stand-ins around the kink
    points = bb._observed_floor_points(bpy, scene, camera, observer, (0.5, 0.5), mp.CAMERA)[0]
    retarded_x = kl._path(kl._retarded(points))[0][..., 0]
    lamp_x = np.unique([obj.location.x for obj in scene.objects if obj.type == "LIGHT" and not obj.hide_render])
    at = np.searchsorted(lamp_x, kink_x)
    chord = lamp_x[max(at - 1, 0) : at + 1]
    away = (retarded_x < chord[0]) | (retarded_x > chord[-1])
    row = int(np.unravel_index(np.argmax(expected), expected.shape)[0])
    band = slice(row - mo.BAND // 2, row + mo.BAND - mo.BAND // 2)  # through the pool, along the motion
    mp._render_rows(scene, band)  # the rows compared
    image = mp.ch.luminance(mp._render(bpy, scene, tmp_path / "accelerating.exr"))
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    peak = expected[band].mean(0).max()
    keep = away[band].all(axis=0)
    error = np.abs(image[band].mean(0) - expected[band].mean(0))[keep].max() / peak
    uniform_error = np.abs(image[band].mean(0) - constant[band].mean(0))[keep].max() / peak
    chord_error = np.abs(image[band].mean(0) - expected[band].mean(0))[~keep].mean() / peak
    print(
        f"lamp moving with an accelerating camera: peak {peak:.3f} (rendered {image[band].mean(0).max():.3f}); "
        f"profile error {error:.4f} of the peak off the stand-ins' piece across the kink ({np.sum(~keep)} px, "
        f"mean error {chord_error:.4f} there); uniform motion at 0.6c differs by {uniform_error:.4f}"
    )
    assert error < 0.05
    assert np.sum(~keep) < 12
    assert uniform_error > 0.2  # the keyframed path matters
