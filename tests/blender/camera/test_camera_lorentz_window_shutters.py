"""Gray et al. (2020) section 4, Figs. 9 and 10: the Lorentz window with a shutter model.

The window sits in the plane of spatial fixed points for t_W = -1 (eq. 6), Gray's beta
(0.1, 0, 0.99) in Dr TIM axes = (0.1, 0, -0.99) in the camera's (the camera sits at the world
origin unrotated, so camera-local axes are world axes), c = 1. The shutter model times the rays
(``--window-time``, ``lorentz_window_shutter = 'SHUTTER_MODEL'``):

- arbitrary-plane shutter in the window plane, opening at t_W: every ray crosses the window at a
  spatial fixed point of eq. (1) and keeps its direction, so the photo is the photo at rest
  (Fig. 9; the markers do not move);
- detector-plane shutter (ideal lens), its shutter time chosen as in Gray's Fig. 10 (the axial
  chief ray crosses the window at t_W): the other rays cross it earlier or later than t_W, so
  the window undoes the distortion only imperfectly. Each marker is expected where the physics
  core's window ray (``shutter.lorentz_window_ray`` after ``shutter.lens_time``; the window
  keeps the ray's direction, the crossing event moves by eq. 1) passes through its centre,
  solved here by Newton's method on the pixel position; not from the shader under test.
"""

import numpy as np

import camera_helpers as ch
from relativity_addon.physics.shutter import ShutterModel, fixed_point_plane, lens_time, lorentz_window_ray

BETA = np.array([0.1, 0.0, -0.99])
WINDOW_TIME = -1.0
RESOLUTION = (160, 120)
SAMPLES = 16
LENS_MM = 50.0
FOCUS = 5.0
FOCAL_LENGTH = LENS_MM * 1e-3
IMAGE_DISTANCE = 1.0 / (1.0 / FOCAL_LENGTH - 1.0 / FOCUS)
# Markers: rest pixel (x, y) and depth; spread over the frame and 3-6 units away.
MARKERS = [(28, 24, 3.5), (80, 28, 5.0), (132, 24, 4.0), (28, 96, 4.5), (132, 96, 3.0), (56, 62, 6.0), (106, 62, 3.5)]
RADIUS = 0.04
HALF_WINDOW = 7
WINDOW_POINT, WINDOW_NORMAL = fixed_point_plane(WINDOW_TIME, BETA, 1.0)
# Gray's Fig. 10: the axial chief ray crosses the window at t_W, reaches the lens centre a
# distance `axial` later and the detector, IMAGE_DISTANCE behind the lens, at the shutter time.
_AXIAL = float(WINDOW_POINT @ WINDOW_NORMAL) / float(np.array([0.0, 0.0, -1.0]) @ WINDOW_NORMAL)
DETECTOR_SHUTTER_TIME = float(WINDOW_TIME + _AXIAL + IMAGE_DISTANCE)


def _window_ray_origin(camera, pixel):
    """Scene-frame origin and traced direction of the chief ray of ``pixel`` through the window."""
    d = camera.pixel_direction(*pixel)
    object_point = d * (FOCUS / -d[2])
    detector = -object_point * (IMAGE_DISTANCE / FOCUS)
    t_lens = lens_time(
        ShutterModel.DETECTOR_PLANE,
        np.zeros(3),
        object_point,
        c=1.0,
        shutter_time=DETECTOR_SHUTTER_TIME,
        detector_point=detector,
    )
    _, origin, forward = lorentz_window_ray(np.zeros(3), object_point, t_lens, BETA, 1.0, WINDOW_POINT, WINDOW_NORMAL)
    return origin, -forward


def expected_pixel(camera, marker):
    """The pixel whose window ray passes through ``marker``: project(marker - origin) = pixel."""
    pixel = camera.project_direction(marker)

    def mismatch(p):
        origin, direction = _window_ray_origin(camera, p)
        assert np.allclose(direction, camera.pixel_direction(*p))  # the window keeps the direction
        return camera.project_direction(marker - origin) - p

    for _ in range(30):
        f = mismatch(pixel)
        if np.linalg.norm(f) < 1e-9:
            return pixel
        h = 1e-4
        jacobian = np.column_stack([(mismatch(pixel + h * e) - f) / h for e in np.eye(2)])
        pixel = pixel - np.linalg.solve(jacobian, f)
    raise AssertionError(f"no window ray through {marker}")


def _build(bpy, tmp_path):
    scene, camera_object = ch.new_scene(bpy, resolution=RESOLUTION, samples=SAMPLES)
    data = camera_object.data
    data.lens = LENS_MM
    # A detector-plane shutter needs the focus distance; f/200 keeps the markers sharp.
    data.dof.use_dof = True
    data.dof.focus_distance = FOCUS
    data.dof.aperture_fstop = 200.0
    camera = ch.pinhole_model(bpy, scene, camera_object)
    material = ch.emission_material(bpy)
    markers = []
    for index, (px, py, depth) in enumerate(MARKERS):
        d = camera.pixel_direction(px, py)
        markers.append(d * (depth / -d[2]))
        ch.add_sphere(bpy, scene, markers[-1], RADIUS, material, name=f"M{index}", segments=24, rings=12)
    return ch.save_blend(bpy, tmp_path / "window_shutters.blend"), camera, np.array(markers)


def _vector_option(name, vector):
    return f"{name}=" + ",".join(repr(float(v)) for v in vector)


def _centroids(image, pixels):
    found = []
    for pixel in pixels:
        centre, _ = ch.centroid(image, pixel, HALF_WINDOW)
        assert centre is not None, f"no marker near {pixel}"
        found.append(centre)
    return np.array(found)


def test_window_with_detector_plane_shutter_leaves_a_residual_distortion(factory_blender, tmp_path):
    bpy = factory_blender
    blend, camera, markers = _build(bpy, tmp_path)
    common = ("--speed-of-light=1", "--no-searchlight", "--no-doppler", "--seed=2")
    moving = ("--beta=0.1,0,-0.99", f"--window-time={WINDOW_TIME!r}")
    rest = ch.luminance(ch.render_image(bpy, blend, tmp_path / "rest.exr", "--beta=0,0,0", *common))
    plane = ch.luminance(
        ch.render_image(
            bpy,
            blend,
            tmp_path / "plane.exr",
            *moving,
            *common,
            "--shutter=arbitrary_plane",
            f"--shutter-time={WINDOW_TIME!r}",
            _vector_option("--shutter-plane-point", WINDOW_POINT),
            _vector_option("--shutter-plane-normal", WINDOW_NORMAL),
        )
    )
    detector = ch.luminance(
        ch.render_image(
            bpy,
            blend,
            tmp_path / "detector.exr",
            *moving,
            *common,
            "--shutter=detector_plane",
            f"--shutter-time={DETECTOR_SHUTTER_TIME!r}",
        )
    )
    rest_pixels = np.array([camera.project_direction(m) for m in markers])
    expected = np.array([expected_pixel(camera, m) for m in markers])
    at_rest = _centroids(rest, rest_pixels)
    in_plane = _centroids(plane, rest_pixels)
    measured = _centroids(detector, expected)
    plane_shift = np.linalg.norm(in_plane - at_rest, axis=1)
    residual = measured - at_rest
    predicted = expected - rest_pixels
    error = np.linalg.norm(residual - predicted, axis=1)
    print(
        f"window, eq. 6 plane shutter: marker shift max {plane_shift.max():.4f} px, mean |image - rest| "
        f"{np.abs(plane - rest).mean():.2e}; detector-plane shutter: residual shifts "
        f"{np.array2string(np.linalg.norm(residual, axis=1), precision=2)} px, predicted "
        f"{np.array2string(np.linalg.norm(predicted, axis=1), precision=2)} px, max error {error.max():.3f} px"
    )
    # Shutter in the window plane at t_W: the photo at rest (Fig. 9), to the pixel noise.
    assert plane_shift.max() < 0.02
    assert np.abs(plane - rest).mean() < 1e-4
    # Detector-plane shutter: the window leaves a residual distortion (Fig. 10), where the
    # physics core's window rays put each marker.
    assert np.linalg.norm(predicted, axis=1).max() > 5.0
    assert error.max() < 0.3
