"""Pixel Doppler factors and the compensated exposure (physics/exposure.py) against the Lorentz
transformation of a photon's wave four-vector done here."""

import numpy as np
import pytest

from relativity_addon.physics import exposure

WINDOW = (-0.36, 0.36, -0.27, 0.27)


def _boost_frequency_ratio(direction_camera, beta):
    """``D = omega_camera / omega_scene`` for a photon arriving from camera-frame direction ``d'``:
    its wave four-vector in the camera frame, ``(1, -d')``, boosted into the scene frame (which
    moves with ``-beta`` relative to the camera), gives ``omega_scene``."""
    beta = np.asarray(beta, float)
    gamma = 1.0 / np.sqrt(1.0 - beta @ beta)
    k_camera = -np.asarray(direction_camera, float)
    omega_scene = gamma * (1.0 + beta @ k_camera)  # time component of the boost by -beta
    return 1.0 / omega_scene


@pytest.mark.parametrize("beta", [(0.0, 0.0, -0.6), (0.3, -0.2, 0.5), (0.9, 0.0, 0.0)])
def test_log_doppler_is_the_boosted_photon_frequency(beta):
    directions = exposure.pixel_directions(WINDOW, (8, 6))
    measured = np.exp(exposure.log_doppler(directions, beta))
    expected = np.array([[_boost_frequency_ratio(d, beta) for d in row] for row in directions])
    assert np.allclose(measured, expected, rtol=1e-12)


def test_pixel_directions_run_through_the_pixel_centres_bottom_row_first():
    directions = exposure.pixel_directions(WINDOW, (4, 2))
    first = np.array([-0.36 + 0.09, -0.27 + 0.135, -1.0])
    assert np.allclose(directions[0, 0], first / np.linalg.norm(first))
    assert np.allclose(np.linalg.norm(directions, axis=-1), 1.0)


def test_without_aberration_the_ray_is_the_scene_direction():
    beta = np.array([0.0, 0.5, -0.5])
    directions = exposure.pixel_directions(WINDOW, (5, 5))
    gamma = 1.0 / np.sqrt(1.0 - beta @ beta)
    assert np.allclose(
        np.exp(exposure.log_doppler(directions, beta, aberration=False)), gamma * (1.0 + directions @ beta)
    )


def test_compensation_undoes_the_log_average_searchlight():
    beta = (0.2, 0.0, -0.8)
    size = (48, 36)
    k = exposure.compensation(beta, WINDOW, size=size)
    d4 = np.array(
        [[_boost_frequency_ratio(d, beta) ** 4 for d in row] for row in exposure.pixel_directions(WINDOW, size)]
    )
    assert k * np.exp(np.mean(np.log(d4))) == pytest.approx(1.0, rel=1e-9)
    assert k < 1.0, "looking ahead at 0.82c the frame is brighter: the exposure darkens it"
    assert exposure.compensation((0.0, 0.0, 0.0), WINDOW) == 1.0
    assert exposure.compensation((0.0, 0.0, 0.8), WINDOW) > 1.0  # looking back


# --- Blender's panoramas: the lens models (Blender manual, Cameras > Panoramic) -----------------


def _angle_from_forward(directions):
    return np.arccos(np.clip(-directions[..., 2], -1.0, 1.0))


def test_equirectangular_directions_span_the_sphere():
    directions, inside = exposure.panorama_directions("EQUIRECTANGULAR", (8, 4))
    assert inside.all() and np.allclose(np.linalg.norm(directions, axis=-1), 1.0)
    lon = np.arctan2(directions[..., 0], -directions[..., 2])  # 0 ahead, +pi/2 to the right
    lat = np.arcsin(directions[..., 1])  # rows bottom first: latitude grows with the row
    assert np.allclose(lon[0], -np.pi + (np.arange(8) + 0.5) * np.pi / 4)
    assert np.allclose(lat[:, 0], -np.pi / 2 + (np.arange(4) + 0.5) * np.pi / 4)


def test_fisheye_equidistant_angle_grows_with_the_radius():
    fov = np.radians(180.0)
    directions, inside = exposure.panorama_directions("FISHEYE_EQUIDISTANT", (9, 9), fov=fov)
    u = (np.arange(9) + 0.5) / 9 * 2.0 - 1.0
    radius = np.hypot(u[None, :], u[:, None])
    assert np.array_equal(inside, radius <= 1.0)
    assert np.allclose(_angle_from_forward(directions)[inside], (radius * fov / 2.0)[inside])
    assert np.all(directions[4, 8:, 0] > 0) and np.all(directions[8:, 4, 1] > 0)  # right is +X, up +Y


def test_fisheye_equisolid_radius_is_two_f_sin_half_angle():
    lens, sensor = 8.0, (36.0, 24.0)
    directions, inside = exposure.panorama_directions("FISHEYE_EQUISOLID", (12, 8), fov=np.pi, lens=lens, sensor=sensor)
    x = ((np.arange(12) + 0.5) / 12 - 0.5) * sensor[0]
    y = ((np.arange(8) + 0.5) / 8 - 0.5) * sensor[1]
    radius = np.hypot(x[None, :], y[:, None])
    theta = _angle_from_forward(directions)
    assert np.allclose((2.0 * lens * np.sin(theta / 2.0))[inside], radius[inside])
    assert np.array_equal(inside, radius <= 2.0 * lens * np.sin(np.pi / 4.0))


def test_mirror_ball_centre_looks_ahead_rim_behind():
    directions, inside = exposure.panorama_directions("MIRRORBALL", (9, 9))
    assert np.allclose(directions[4, 4], (0.0, 0.0, -1.0))
    nx = (np.arange(9) + 0.5) / 9 * 2.0 - 1.0
    # a normal at angle a from the axis reflects the view by 2a: a = asin(r)
    radius = np.hypot(nx[None, :], nx[:, None])
    assert np.allclose(_angle_from_forward(directions)[inside], 2.0 * np.arcsin(radius[inside]))
    with pytest.raises(ValueError):
        exposure.panorama_directions("CENTRAL_CYLINDRICAL", (4, 4))
