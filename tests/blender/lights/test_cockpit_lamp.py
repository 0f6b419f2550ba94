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
