"""Moving lights seen by a MOVING observer on the exact camera path (stand-in lamps): a point lamp
and a glowing sphere that Lights the Scene, both at 0.5c along +X above a white floor, the camera
moving at 0.5c against the light, sideways and toward the floor.

The floor is at rest in the scene frame and its light reaches the camera at the reception event
``(t_o, x_cam)`` whatever the observer's velocity, so its scene-frame radiance is eq. 19 from the
light's retarded positions exactly as for an observer at rest (``test_moving_point_light``'s numpy
fixed-point solution, not the add-on's). The moving observer sees it through aberration (each
pixel's direction in its frame aberrated into the scene frame finds the floor point:
``test_moving_blackbody_light._observed_floor_points``) and the searchlight ``D_o^4`` (Weiskopf et
al. eq. 14). The observer's Doppler colour is off here (white light, white floor) and the pixels'
luminance is compared (a moving light's colour shifts with its own ``D``, eq. 18; its brightness
follows eq. 19): each pixel is ``D_o^4`` times the floor's scene-frame radiance, averaged over
the pixel (a 3 x 3 grid in it: the box filter; the pool is a few pixels wide). Also checked: a
shutter time (Gray eq. 1's reception event), the stand-ins' span and a shadow.
"""

import numpy as np
import pytest
import test_moving_blackbody_light as bb
import test_moving_emitter_lights as em
import test_moving_light_shadows as sh
import test_moving_point_light as mp

OBSERVER = np.array([-0.26, 0.21, -0.37])  # 0.5c: against the light, sideways and toward the floor
RESOLUTION = (80, 60)
SAMPLES = 64  # 32: up to 4.5 % of the peak (noise)
SUBPIXELS = (1.0 / 6.0, 0.5, 5.0 / 6.0)
BAND = 4  # pixels
SHUTTER_TIME = 0.2  # s: c t_S = 2
SHADOW_SAMPLES = 64  # 32: the noise breaks the dark runs (edges 21 px off)


def _reception_event(shutter_time):
    """Gray eq. (1): the pinhole's event (t_S, 0) in the camera frame is (gamma t_S,
    x_cam + gamma beta c t_S) in the scene frame (scene seconds after t_o, position)."""
    gamma = 1.0 / np.sqrt(1.0 - OBSERVER @ OBSERVER)
    return gamma * shutter_time, mp.CAMERA + gamma * OBSERVER * mp.C * shutter_time


def _observe(bpy, scene, camera, tmp_path, name, shutter_time=0.0):
    """Render the scene seen by the moving observer (searchlight on, Doppler colour off); the
    reference (``D_o^4`` times the floor's scene-frame radiance for a point lamp of power
    ``mp.POWER``, the light received at :func:`_reception_event`) and ``D_o``, both averaged over
    each pixel."""
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.cycles.samples = SAMPLES
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = tuple(OBSERVER)
    scene.relativity.use_doppler = False
    scene.relativity.shutter_time = shutter_time
    mp._effect().apply(scene)
    image = mp.ch.luminance(mp._render(bpy, scene, tmp_path / f"{name}.exr"))
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    return (image, *_reference(bpy, scene, camera, *_reception_event(shutter_time)))


def _reference(bpy, scene, camera, time, position):
    """``D_o^4`` times the floor's radiance (the light received at ``(time, position)``) and
    ``D_o``, averaged over each pixel."""
    seen, doppler = [], []
    for offset in ((x, y) for y in SUBPIXELS for x in SUBPIXELS):
        points, observer_doppler = bb._observed_floor_points(bpy, scene, camera, OBSERVER, offset, position)
        seen.append(
            observer_doppler**4 * mp._expected_radiance(points, mp.BETA, reception_time=time, camera=position)[0]
        )
        doppler.append(observer_doppler)
    return np.mean(seen, axis=0), np.mean(doppler, axis=0)


def _compare(image, expected, label):
    """The largest error of the profiles along and across the light's motion (``BAND``-pixel bands
    through the expected peak) as a fraction of the peak, and the pool's peak (column, row) in them."""
    row, column = np.unravel_index(np.argmax(expected), expected.shape)
    rows, columns = (slice(centre - BAND // 2, centre + BAND - BAND // 2) for centre in (row, column))
    profile, wanted = image[rows].mean(0), expected[rows].mean(0)
    across, across_wanted = image[:, columns].mean(1), expected[:, columns].mean(1)
    error = max(np.abs(profile - wanted).max(), np.abs(across - across_wanted).max()) / wanted.max()
    peak = np.array([int(np.argmax(profile)), int(np.argmax(across))])
    expected_peak = np.array([int(np.argmax(wanted)), int(np.argmax(across_wanted))])
    print(
        f"{label}: peak {wanted.max():.3f} (rendered {profile.max():.3f}); profile error {error:.4f} of the "
        f"peak; pool at {peak} (expected {expected_peak})"
    )
    return error, np.abs(peak - expected_peak).max()


def _check(image, expected, observer_doppler, label):
    error, offset = _compare(image, expected, label)
    assert error < 0.05
    assert offset <= 2
    # the test tells the searchlight applied once from none or twice
    for power, wrong in ((0, "no searchlight"), (8, "D_o^8")):
        assert _compare(image, expected * observer_doppler ** (power - 4), f"{label}, {wrong}")[0] > 0.5


def test_moving_lamp_seen_by_a_moving_observer(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, _lamp = mp._floor_scene(bpy)
    image, expected, observer_doppler = _observe(bpy, scene, camera, tmp_path, "lamp")
    print(f"D_o over the view {observer_doppler.min():.3f} .. {observer_doppler.max():.3f}")
    _check(image, expected, observer_doppler, "lamp")


@pytest.mark.parametrize("window", [False, True])
def test_stand_ins_span_what_the_moving_camera_sees(relativity_addon, factory_blender, window):
    """The stand-ins span the retarded positions of the floor points the camera sees (those that get
    at least 1 % of the brightest one's ``D^4 / r^2``, as moving_lamps.py chooses): its pixels'
    directions aberrated into the scene frame, or kept as they are behind a Lorentz window at
    ``t_W = 0`` (Gray eq. 6: a plane through the camera whose rays keep their camera-frame
    directions). Before the fix the stand-ins were placed for the view aberrated the wrong way
    (x -4.63 .. -1.61 where the camera sees -15.13 .. -1.61) and aberrated behind the window
    (-15.11 .. -1.62 where it sees -7.60 .. -1.61)."""
    bpy = factory_blender
    scene, camera, _lamp = mp._floor_scene(bpy)
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.relativity.beta = tuple(OBSERVER)
    scene.relativity.use_lorentz_window = window
    mp._effect().apply(scene)
    points, _ = bb._observed_floor_points(bpy, scene, camera, np.zeros(3) if window else OBSERVER)
    _radiance, source, lamp_doppler = mp._expected_radiance(points, mp.BETA)
    irradiance = lamp_doppler**4 / np.sum((points - source) ** 2, axis=-1)
    wanted = source[irradiance >= 0.01 * irradiance.max()][:, 0]
    placed = [obj.location.x for obj in bpy.data.objects if obj.name.startswith("Relativity Lamp")]
    print(
        f"window {window}: stand-ins from x = {min(placed):.2f} to {max(placed):.2f}; the seen floor's retarded "
        f"positions {wanted.min():.2f} .. {wanted.max():.2f}"
    )
    assert min(placed) < wanted.min() + 0.1 and max(placed) > wanted.max() - 0.1
    assert min(placed) > wanted.min() - 1.0 and max(placed) < wanted.max() + 1.0  # the grid is 5 % wider


def test_moving_emitter_seen_by_a_moving_observer(relativity_addon, factory_blender, tmp_path):
    """A sphere of radius R and radiance L that Lights the Scene: a point light of intensity
    ``L pi R^2`` (test_moving_emitter_lights), here seen by the moving observer."""
    bpy = factory_blender
    scene, camera, _sphere = em._scene(bpy, lights_scene=True)
    image, expected, observer_doppler = _observe(bpy, scene, camera, tmp_path, "emitter")
    _check(
        image, expected * em.RADIANCE * np.pi * em.RADIUS**2 / (mp.POWER / (4.0 * np.pi)), observer_doppler, "emitter"
    )


def test_shutter_time_with_a_moving_observer(relativity_addon, factory_blender, tmp_path):
    """With shutter time t_S the moving camera receives the light at Gray eq. (1)'s event: later
    (gamma t_S) and elsewhere (gamma beta c t_S on); the pool is where that event says."""
    bpy = factory_blender
    scene, camera, _lamp = mp._floor_scene(bpy)
    image, expected, observer_doppler = _observe(bpy, scene, camera, tmp_path, "shutter", SHUTTER_TIME)
    _check(image, expected, observer_doppler, "shutter time")
    time, position = _reception_event(SHUTTER_TIME)
    for label, when, where in (("at t_o", 0.0, position), ("from x_cam", time, mp.CAMERA)):
        wrong, _ = _reference(bpy, scene, camera, when, where)
        assert _compare(image, wrong, f"shutter time, the light received {label}")[0] > 0.3


def test_shadow_seen_by_a_moving_observer(relativity_addon, factory_blender, tmp_path):
    """test_moving_light_shadows' black square 0.5 above the floor, seen by the moving observer
    (160 x 120): the exact shadow is where the segment from each floor point's retarded lamp position
    crosses the square, at the floor points the aberrated pixels see."""
    bpy = factory_blender
    scene, camera, _lamp = mp._floor_scene(bpy, occluder=True, samples=SHADOW_SAMPLES)
    scene.relativity.beta = tuple(OBSERVER)
    scene.relativity.use_doppler = False
    mp._effect().apply(scene)
    image = mp.ch.luminance(mp._render(bpy, scene, tmp_path / "shadow.exr"))
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    points, observer_doppler = bb._observed_floor_points(bpy, scene, camera, OBSERVER)
    lit, source, _d = mp._expected_radiance(points, mp.BETA)
    clear_error, deficit, edge_error, one_lamp_error, wrong, size = sh.measure(
        image, points, observer_doppler**4 * lit, source, "moving observer"
    )
    assert clear_error < 0.02
    assert abs(deficit - 1.0) < 0.4
    assert edge_error < 0.5 * one_lamp_error
    assert wrong < 0.3 * size
    # the pixels' floor points without aberration put the shadow elsewhere
    points, _ = bb._observed_floor_points(bpy, scene, camera, np.zeros(3))
    lit, source, _d = mp._expected_radiance(points, mp.BETA)
    unaberrated = sh.measure(image, points, observer_doppler**4 * lit, source, "the view not aberrated")
    assert wrong < 0.3 * unaberrated[4]
