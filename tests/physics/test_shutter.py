"""Shutter-model ray timing and the camera-to-scene ray transform of Gray et al. (2020), checked
against the conditions that define each model (where and when the ray meets the shutter) and
against the paper's section 3 statements about stigmatic imaging."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from relativity_addon.physics import lorentz, shutter
from relativity_addon.physics.shutter import ShutterModel
from strategies import directions, vectors, velocities

C = 1.0
BETA_GRAY = np.array([0.1, 0.0, 0.99])  # Gray et al.'s test velocity (their coordinates)


def lens_disc(radius, count=9):
    """Lens points on the aperture plane z = 0 (the camera looks along +z)."""
    angles = np.linspace(0, 2 * np.pi, count, endpoint=False)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles), np.zeros(count)], axis=1)
    return np.vstack([np.zeros(3), ring, 0.5 * ring])


@given(velocities(0.999), vectors)
def test_fixed_point_time_makes_eq1_the_identity(beta, x):
    t = shutter.fixed_point_time(x, beta, C)
    assert_allclose(
        lorentz.camera_to_scene_event(t, x, beta, C)[1], x, atol=1e-9 * (1 + np.linalg.norm(x)) / (1 - beta @ beta)
    )


def test_fixed_point_time_is_gray_eq4():
    beta, x, c = BETA_GRAY, np.array([0.3, -1.0, 8.0]), 3.0
    gamma = 1 / np.sqrt(1 - beta @ beta)
    assert_allclose(shutter.fixed_point_time(x, beta, c), (1 - gamma) * (beta @ x) / (c * gamma * (beta @ beta)))


@given(
    velocities(0.999).filter(lambda b: np.linalg.norm(b) > 1e-3), st.floats(-5, 5), st.floats(-3, 3), st.floats(-3, 3)
)
def test_fixed_point_plane_is_fixed_at_the_shutter_time(beta, t_s, u, v):
    point, normal = shutter.fixed_point_plane(t_s, beta, C)
    tangent = np.cross(normal, [1.0, 0, 0] if abs(normal[0]) < 0.9 else [0, 1.0, 0])
    tangent /= np.linalg.norm(tangent)
    on_plane = point + u * tangent + v * np.cross(normal, tangent)
    gamma = 1 / np.sqrt(1 - beta @ beta)
    assert_allclose(-beta @ on_plane, (gamma + 1) / gamma * C * t_s, atol=1e-9 * (1 + abs(t_s)) * gamma)
    mapped = lorentz.camera_to_scene_event(t_s, on_plane, beta, C)[1]
    assert_allclose(mapped, on_plane, atol=1e-8 * (1 + np.linalg.norm(on_plane)) * gamma)


def test_no_fixed_point_plane_at_rest():
    with pytest.raises(ValueError, match="rest"):
        shutter.fixed_point_plane(1.0, [0, 0, 0], C)


def ray_time_at(point_on_ray, lens, t_lens):
    """Time a photo ray passing ``lens`` at ``t_lens`` was at an earlier point of its path."""
    return t_lens - np.linalg.norm(lens - point_on_ray, axis=-1) / C


@given(vectors, directions, st.floats(-3, 3))
def test_each_model_meets_its_shutter_at_the_shutter_time(lens_offset, towards, t_s):
    lens = np.array([0.05, -0.02, 0.0]) + 1e-4 * lens_offset
    focus_point = np.array([0.4, 0.2, 6.0])
    detector = np.array([-0.02, -0.01, -0.05])
    assert_allclose(shutter.lens_time("PINHOLE", np.zeros(3), focus_point, c=C, shutter_time=t_s), t_s, atol=1e-12)
    assert_allclose(
        shutter.lens_time(ShutterModel.APERTURE_PLANE, lens, focus_point, c=C, shutter_time=t_s), t_s, atol=1e-12
    )
    # ideal lens: every ray from P reaches D at t_S after the chief ray's travel time
    t_det = shutter.lens_time("DETECTOR_PLANE", lens, focus_point, c=C, shutter_time=t_s, detector_point=detector)
    chief_travel = (np.linalg.norm(focus_point) + np.linalg.norm(detector)) / C
    assert_allclose(ray_time_at(focus_point, lens, t_det) + chief_travel, t_s, atol=1e-12)
    # phase hologram of a lens: no delay, the ray reaches D straight from L at t_S
    t_holo = shutter.lens_time(
        "DETECTOR_PLANE", lens, focus_point, c=C, shutter_time=t_s, detector_point=detector, ideal_lens=False
    )
    assert_allclose(t_holo + np.linalg.norm(detector - lens) / C, t_s, atol=1e-12)
    t_focus = shutter.lens_time("FOCUS_SURFACE", lens, focus_point, c=C, shutter_time=t_s)
    assert_allclose(ray_time_at(focus_point, lens, t_focus), t_s, atol=1e-12)
    t_fixed = shutter.lens_time("FIXED_POINT_SURFACE", lens, focus_point, c=C, beta=BETA_GRAY)
    assert_allclose(
        ray_time_at(focus_point, lens, t_fixed), shutter.fixed_point_time(focus_point, BETA_GRAY, C), atol=1e-12
    )

    # arbitrary plane: find where the ray from P to L crosses it by a different route
    normal = towards if abs(towards[2]) > 0.2 else np.array([0.0, 0.3, 1.0]) / np.hypot(0.3, 1.0)
    plane_point = np.array([0.1, 0.0, 1.5])
    s = ((plane_point - focus_point) @ normal) / ((lens - focus_point) @ normal)  # P + s (L - P) on plane
    crossing = focus_point + s * (lens - focus_point)
    t_plane = shutter.lens_time(
        "ARBITRARY_PLANE", lens, focus_point, c=C, shutter_time=t_s, plane_point=plane_point, plane_normal=normal
    )
    assert_allclose(ray_time_at(crossing, lens, t_plane), t_s, atol=1e-9)


def test_arbitrary_plane_in_front_is_crossed_before_the_lens():
    """The worked case that shows the sign of eq. (B5): a plane one unit in front of the lens."""
    t = shutter.lens_time(
        "ARBITRARY_PLANE",
        np.zeros(3),
        [0, 0, 5.0],
        c=2.0,
        shutter_time=0.0,
        plane_point=[0, 0, 1.0],
        plane_normal=[0, 0, 1.0],
    )
    assert_allclose(t, 0.5)


@given(velocities(0.99), directions, st.floats(-2, 2))
def test_scene_ray_joins_the_two_transformed_events(beta, towards, t_lens):
    """Gray section 2: the scene-frame ray passes L' and P', the events of the photo ray at L and
    at P carried over by eq. (1); its direction is eq. (2)."""
    lens = np.array([0.1, -0.05, 0.0])
    obj = lens - 4.0 * towards
    scene_t, origin, direction = shutter.photo_ray_in_scene(lens, obj, t_lens, beta, C)
    _, p_scene = lorentz.camera_to_scene_event(ray_time_at(obj, lens, t_lens), obj, beta, C)
    _, l_scene = lorentz.camera_to_scene_event(t_lens, lens, beta, C)
    assert_allclose(origin, l_scene)
    expected = (l_scene - p_scene) / np.linalg.norm(l_scene - p_scene)
    assert_allclose(direction, expected, atol=1e-9)


def scene_rays(model, lenses, focus_point, detector, beta, t_s=0.0, ideal_lens=True):
    times = shutter.lens_time(
        model, lenses, focus_point, c=C, shutter_time=t_s, detector_point=detector, beta=beta, ideal_lens=ideal_lens
    )
    _, origins, directions_ = shutter.photo_ray_in_scene(lenses, focus_point, times, beta, C)
    return origins, directions_


def spread_of_closest_approach(origins, directions_):
    """Least-squares point nearest to all rays, and the rays' largest distance from it."""
    projector = np.eye(3)[None] - directions_[:, :, None] * directions_[:, None, :]
    point = np.linalg.solve(projector.sum(0), np.einsum("nij,nj->i", projector, origins))
    offsets = np.einsum("nij,nj->ni", projector, point - origins)
    return point, np.linalg.norm(offsets, axis=1).max()


def test_detector_plane_shutter_images_stigmatically_and_aperture_plane_does_not():
    """Gray et al. section 3: with the detector-plane shutter (ideal lens), the rays through one
    detector point meet in one scene point P'; with a phase hologram of the lens, or with the
    aperture-plane shutter, they do not (relativistic coma), except close to the optical axis."""
    lenses = lens_disc(0.2)
    detector_point = np.array([0.0, 0.0, -0.05])
    off_axis = np.array([3.0, 2.0, 10.0])
    on_axis = np.array([0.0, 0.0, 10.0])
    for focus_point in (off_axis, on_axis):
        detector = detector_point - 0.005 * focus_point  # conjugate point behind the lens
        rays = scene_rays("DETECTOR_PLANE", lenses, focus_point, detector, BETA_GRAY)
        point, spread = spread_of_closest_approach(*rays)
        assert spread < 1e-9
        t_p = -np.linalg.norm(detector - np.zeros(3)) / C - np.linalg.norm(focus_point) / C
        assert_allclose(point, lorentz.camera_to_scene_event(t_p, focus_point, BETA_GRAY, C)[1], atol=1e-6)
    detector = detector_point - 0.005 * off_axis
    _, spread_hologram = spread_of_closest_approach(
        *scene_rays("DETECTOR_PLANE", lenses, off_axis, detector, BETA_GRAY, ideal_lens=False)
    )
    assert spread_hologram > 1e-3
    _, spread_off = spread_of_closest_approach(*scene_rays("APERTURE_PLANE", lenses, off_axis, None, BETA_GRAY))
    _, spread_on = spread_of_closest_approach(*scene_rays("APERTURE_PLANE", lenses, on_axis, None, BETA_GRAY))
    assert spread_off > 1e-2
    assert spread_on < 0.1 * spread_off


def test_fixed_point_surface_shutter_keeps_the_focus_plane_as_at_rest():
    """Gray et al. section 3D: every ray through a focus-plane point P meets it at P's fixed-point
    time, so in the scene frame all rays pass through P itself, as for a camera at rest."""
    lenses = lens_disc(0.2)
    for focus_point in (np.array([2.0, -1.0, 8.0]), np.array([-3.0, 3.0, 8.0])):
        rays = scene_rays("FIXED_POINT_SURFACE", lenses, focus_point, None, BETA_GRAY)
        point, spread = spread_of_closest_approach(*rays)
        assert spread < 1e-9
        assert_allclose(point, focus_point, atol=1e-8)


def test_lorentz_window_gives_the_rays_of_the_camera_at_rest():
    """Gray et al. section 4: a Lorentz window in the plane of fixed points for t_S, with the
    shutter in that plane, makes every scene-frame ray the ray of the camera at rest."""
    t_s = -1.0
    window_point, window_normal = shutter.fixed_point_plane(t_s, BETA_GRAY, C)
    lenses = lens_disc(0.1)
    for obj in (np.array([0.5, 0.3, 6.0]), np.array([-1.0, 0.2, 3.0])):
        times = shutter.lens_time(
            "ARBITRARY_PLANE", lenses, obj, c=C, shutter_time=t_s, plane_point=window_point, plane_normal=window_normal
        )
        _, origins, directions_ = shutter.lorentz_window_ray(
            lenses, obj, times, BETA_GRAY, C, window_point, window_normal
        )
        at_rest = (lenses - obj) / np.linalg.norm(lenses - obj, axis=1, keepdims=True)
        assert_allclose(directions_, at_rest, atol=1e-12)
        # origins lie on the rest-frame rays: the same lines as at rest
        offsets = np.cross(origins - obj, at_rest)
        assert_allclose(offsets, 0.0, atol=1e-9)
    # without the window the same rays are bent (the window is doing the work)
    _, _, bent = shutter.photo_ray_in_scene(lenses, obj, times, BETA_GRAY, C)
    assert np.max(np.abs(bent - at_rest)) > 0.1


def test_shutter_inputs_are_checked():
    with pytest.raises(ValueError):
        shutter.lens_time("NO_SUCH_MODEL", np.zeros(3), [0, 0, 1.0], c=C)
    with pytest.raises(ValueError, match="detector_point"):
        shutter.lens_time("DETECTOR_PLANE", np.zeros(3), [0, 0, 1.0], c=C)
    with pytest.raises(ValueError, match="beta"):
        shutter.lens_time("FIXED_POINT_SURFACE", np.zeros(3), [0, 0, 1.0], c=C, beta=[0, 0, 1.0])
    with pytest.raises(ValueError, match="parallel"):
        shutter.lens_time(
            "ARBITRARY_PLANE", np.zeros(3), [0, 0, 1.0], c=C, plane_point=[0, 0, 1.0], plane_normal=[1.0, 0, 0]
        )
    with pytest.raises(ValueError, match="zero-length"):
        shutter.photo_ray_in_scene(np.zeros(3), np.zeros(3), 0.0, [0.5, 0, 0], C)
    with pytest.raises(ValueError, match="finite"):
        shutter.photo_ray_in_scene(np.zeros(3), [0, 0, 1.0], np.inf, [0.5, 0, 0], C)


def test_image_distance_is_the_thin_lens_equation():
    f = 0.05
    assert shutter.image_distance(f) == f  # depth of field off: focused at infinity, sensor at f
    assert shutter.image_distance(f, np.inf) == f
    assert_allclose(shutter.image_distance(f, 5.0), 1.0 / (1.0 / f - 1.0 / 5.0))
    for inside in (0.03, f, 1e-5):  # 1e-5: what Cycles reports as the focal distance with DoF off
        with pytest.raises(ValueError, match="no real image"):
            shutter.image_distance(f, inside)


def test_detector_plane_pinhole_ray_starts_at_the_detector_time():
    """Depth of field off (issue 25): the chief ray reaches the sensor at the focal length at t_S,
    so it passed the lens |D|/c earlier; its scene-frame origin is within gamma |D| of the lens,
    the same pinhole picture as the aperture-plane shutter at t_S - |D|/c."""
    f, beta = 0.05, np.array([0.0, 0.0, 0.5])
    direction = np.array([0.1, -0.05, 1.0])
    detector = -direction * shutter.image_distance(f)
    for focus in (1e-5, 5.0, 1e6):  # the chief ray's timing does not depend on where P is
        t_l = shutter.lens_time("DETECTOR_PLANE", np.zeros(3), focus * direction, c=C, detector_point=detector)
        assert_allclose(t_l, -np.linalg.norm(detector) / C, rtol=1e-9)
        _, origin, _ = shutter.photo_ray_in_scene(np.zeros(3), focus * direction, t_l, beta, C)
        assert np.linalg.norm(origin) <= lorentz_gamma(beta) * np.linalg.norm(detector) * (1 + 1e-9)


def lorentz_gamma(beta):
    return 1.0 / np.sqrt(1.0 - beta @ beta)
