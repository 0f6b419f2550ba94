"""Aberration: marker image positions match docs/physics.md within 0.5 px (320x240, pinhole, t_S = 0).

Static scene, pinhole shutter at t_S = 0: every photo ray passes the lens centre at the camera's
event (t = 0, camera position), so each marker is seen along the aberrated direction of the
light that reaches that event from it. The expected positions come from the aberration formula
and the pinhole projection written out in camera_helpers, not from the shader.
"""

import math

import numpy as np
import pytest

import camera_helpers as ch

# (speed, world-space direction of beta) -- forward, oblique, sideways and backward-up cases.
CASES = [
    (0.0, (0.0, 0.0, 0.0)),
    (0.5, "forward"),
    (0.9, (1.0, 0.6, -0.3)),
    (0.99, (-0.3, 1.0, 0.2)),
    (0.9, "backward-up"),
]
# Apparent pixel positions chosen for the markers (then placed where they must be in the scene).
APPARENT_PIXELS = [(x, y) for y in (45.0, 120.0, 195.0) for x in (50.0, 160.0, 270.0)]
APPARENT_RADIUS_PX = 3.0
DISTANCE = 10.0
CAMERA_LOCATION = (0.3, -0.2, 0.5)
CAMERA_ROTATION = (math.radians(80.0), math.radians(10.0), math.radians(30.0))


def _beta(camera, speed, direction):
    if speed == 0.0:
        return np.zeros(3)
    if direction == "forward":
        world = camera.local_to_world([0.0, 0.0, -1.0])
    elif direction == "backward-up":
        world = camera.local_to_world([0.0, 0.5, 1.0])
    else:
        world = np.asarray(direction, float)
    return speed * ch.normalized(world)


@pytest.mark.parametrize("speed,direction", CASES)
def test_marker_positions_follow_aberration(factory_blender, tmp_path, speed, direction):
    bpy = factory_blender
    scene, camera_object = ch.new_scene(bpy, rotation_euler=CAMERA_ROTATION, location=CAMERA_LOCATION)
    camera = ch.pinhole_model(bpy, scene, camera_object)
    beta = _beta(camera, speed, direction)
    material = ch.emission_material(bpy)
    focal_px = camera.size[0] / (camera.window[1] - camera.window[0])

    markers = []
    for index, (px, py) in enumerate(APPARENT_PIXELS):
        view_camera = camera.local_to_world(camera.pixel_direction(px, py))
        view_scene = ch.scene_direction_for_apparent(view_camera, beta)
        # Apparent angular size shrinks by 1/D: size markers so they all look ~3 px in radius.
        doppler = ch.doppler_factor(-view_scene, beta)
        radius = DISTANCE * math.sin(APPARENT_RADIUS_PX / focal_px * doppler)
        center = camera.location + DISTANCE * view_scene
        ch.add_sphere(bpy, scene, center, radius, material, name=f"Marker{index}")
        markers.append((center, radius))
    blend = ch.save_blend(bpy, tmp_path / "markers.blend")

    beta_option = ",".join(f"{b:.17g}" for b in beta)
    image = ch.render_image(
        bpy,
        blend,
        tmp_path / "markers.exr",
        f"--beta={beta_option}",
        "--shutter=pinhole",
        "--no-searchlight",
        "--samples=4",
    )
    intensity = ch.luminance(image)

    errors = []
    for center, radius in markers:
        expected = ch.expected_sphere_centroid(camera, center, radius, beta)
        measured, total = ch.centroid(intensity, expected, half_window=12)
        assert measured is not None, f"marker expected at {expected} not found"
        errors.append(np.linalg.norm(measured - expected))
    print(f"|beta|={speed}: max error {max(errors):.3f} px, mean {np.mean(errors):.3f} px")
    assert max(errors) < 0.5, f"position errors (px): {np.round(errors, 3)}"
