"""Time of flight only (Gray et al. 2020, Fig. 1c): marker positions follow the light-delay geometry
``x_e = x - beta r`` without aberration, within 0.5 px (real Cycles renders, 240x180).

The mode replaces the Lorentz transformation by the Galilean one, with light at c in the camera
frame. In that frame the static scene moves with ``-beta c``; a point is seen where it was when its
light left it, ``r / c`` before the shutter event: at ``x_seen = x + beta r`` with ``r = |x_seen|``
(``x`` its camera-frame position at the shutter event, ``beta`` the camera's velocity in the scene).
Read the other way, a point seen at ``x_seen`` lies at ``x_seen - beta r`` in the scene: that is how
the markers are placed here, for chosen pixels and apparent distances. The expected image of each
marker is the sphere's outline under the same map (a ray from the shutter event along the
camera-frame direction ``d`` meets the scene along ``d - beta``), projected by the pinhole model;
nothing comes from the shader. The shutter event is the camera's position plus ``beta c t_S``
(Galilean, no gamma): one case opens the shutter at ``t_S = -3`` with ``c = 1``, a 2.7-unit shift.

The mode must look like relativity in the large (Gray: it "shares many of the qualities of
relativistic distortion"): each marker's shift from its place at rest points the way the
aberration formula shifts it, toward the direction of motion.
"""

import math

import numpy as np
import pytest

import camera_helpers as ch

RESOLUTION = (240, 180)
APPARENT_PIXELS = [(x, y) for y in (35.0, 90.0, 145.0) for x in (40.0, 120.0, 200.0)]
APPARENT_DISTANCES = (6.0, 9.0, 12.0)
APPARENT_RADIUS_PX = 3.0
CAMERA_LOCATION = (0.3, -0.2, 0.5)
CAMERA_ROTATION = (math.radians(80.0), math.radians(10.0), math.radians(30.0))
# (speed, beta direction in camera-local axes, shutter time t_S in seconds, speed of light)
CASES = [
    pytest.param(0.9, (0.6, 0.3, -1.0), 0.0, 299792458.0, id="0.9c-oblique-forward"),
    pytest.param(0.7, (1.0, -0.2, 0.4), -3.0, 1.0, id="0.7c-sideways-backward-tS-3"),
]


def seen_direction(scene_direction, beta):
    """Camera-frame viewing direction ``d`` of a scene-frame ray direction ``s``: the unit vector
    with ``d - beta`` along ``s`` (the ray from the shutter event along ``d`` meets the scene
    along ``d - beta``)."""
    s = ch.normalized(scene_direction)
    bs = beta @ s
    return beta + (-bs + math.sqrt(bs * bs + 1.0 - beta @ beta)) * s


def expected_image(camera, event, centre, radius, beta, samples=720):
    """Area centroid (pixels) and area (square pixels) of the time-of-flight image of a sphere: its
    outline cone seen from the shutter event, each direction mapped by :func:`seen_direction`."""
    to_centre = np.asarray(centre, float) - event
    axis = ch.normalized(to_centre)
    half_angle = math.asin(radius / np.linalg.norm(to_centre))
    e1 = ch.normalized(np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0]))
    e2 = np.cross(axis, e1)
    points = []
    for phi in np.linspace(0.0, 2.0 * math.pi, samples, endpoint=False):
        edge = math.cos(half_angle) * axis + math.sin(half_angle) * (math.cos(phi) * e1 + math.sin(phi) * e2)
        points.append(camera.project_direction(seen_direction(edge, beta)))
    x, y = np.array(points).T
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2.0
    return np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6.0 * area), abs(area)


@pytest.mark.parametrize("speed,direction,shutter_time,c", CASES)
def test_markers_follow_light_delay_without_aberration(factory_blender, tmp_path, speed, direction, shutter_time, c):
    bpy = factory_blender
    scene, camera_object = ch.new_scene(
        bpy, resolution=RESOLUTION, rotation_euler=CAMERA_ROTATION, location=CAMERA_LOCATION
    )
    camera = ch.pinhole_model(bpy, scene, camera_object)
    beta = speed * ch.normalized(camera.local_to_world(direction))
    event = camera.location + beta * c * shutter_time  # Galilean: x = x' + v t'
    material = ch.emission_material(bpy)
    focal_px = camera.size[0] / (camera.window[1] - camera.window[0])

    markers = []
    for index, (px, py) in enumerate(APPARENT_PIXELS):
        r = APPARENT_DISTANCES[index % len(APPARENT_DISTANCES)]
        seen = r * camera.local_to_world(camera.pixel_direction(px, py))  # x_seen, |x_seen| = r
        centre = event + seen - beta * r  # x_e = x - beta r: the scene point seen there
        # APPARENT_RADIUS_PX in the image: the map shrinks what is ahead and magnifies what is behind
        radius = np.linalg.norm(centre - event) * math.sin(APPARENT_RADIUS_PX / focal_px)
        radius *= math.sqrt(math.pi * APPARENT_RADIUS_PX**2 / expected_image(camera, event, centre, radius, beta)[1])
        ch.add_sphere(bpy, scene, centre, radius, material, name=f"Marker{index}")
        markers.append((centre, radius, (px, py)))
    blend = ch.save_blend(bpy, tmp_path / "markers.blend")

    beta_option = ",".join(f"{b:.17g}" for b in beta)
    image = ch.render_image(
        bpy,
        blend,
        tmp_path / "markers.exr",
        f"--beta={beta_option}",
        "--shutter=pinhole",
        f"--shutter-time={shutter_time!r}",
        f"--speed-of-light={c!r}",
        "--time-of-flight",
        "--samples=4",
    )
    intensity = ch.luminance(image)

    errors, chosen, same_sense = [], [], []
    for centre, radius, pixel in markers:
        expected, _ = expected_image(camera, event, centre, radius, beta)
        measured, _ = ch.centroid(intensity, expected, half_window=10)
        assert measured is not None, f"marker expected at {expected} not found"
        errors.append(np.linalg.norm(measured - expected))
        chosen.append(np.linalg.norm(measured - np.asarray(pixel)))
        # the same sense as relativity: shift from the place at rest (seen from the event, camera at
        # rest) against the aberration formula's shift of the same point
        rest = camera.project_direction(centre - event)
        relativistic = camera.project_direction(ch.apparent_view_direction(centre, event, beta))
        if rest is not None and relativistic is not None:
            same_sense.append(float((measured - rest) @ (relativistic - rest)))
    print(
        f"|beta|={speed}, t_S={shutter_time}: max error {max(errors):.3f} px, mean {np.mean(errors):.3f} px; "
        f"centroid to the chosen pixel max {max(chosen):.3f} px; {len(same_sense)} shifts compared"
    )
    assert max(errors) < 0.5, f"position errors (px): {np.round(errors, 3)}"
    assert len(same_sense) >= 5 and min(same_sense) > 0.0, same_sense


def test_rest_colours_and_refusals(factory_blender):
    """The mode shows the delay alone (no searchlight, no Doppler colour), says so in the output's
    metadata, and refuses what it cannot render with one line: the mesh path, the Lorentz window,
    the fixed-point surface."""
    import relativity_addon
    from relativity_addon.blender.pipeline import effect
    from relativity_addon.blender.scene import snapshot
    from relativity_addon.errors import RelativityError

    relativity_addon.register()
    try:
        bpy = factory_blender
        scene, camera_object = ch.new_scene(bpy, resolution=(32, 24), samples=1)
        ch.add_sphere(bpy, scene, (0.0, 0.0, -5.0), 0.5, ch.emission_material(bpy))
        settings = scene.relativity
        settings.beta = (0.0, 0.0, -0.8)
        settings.use_time_of_flight = True
        snap = snapshot.read(scene)
        assert snap.use_time_of_flight and not snap.use_searchlight and not snap.use_doppler
        assert snap.exposure == 1.0
        for name, value, message in (
            ("use_lorentz_window", True, "Lorentz window"),
            ("shutter_model", "FIXED_POINT_SURFACE", "fixed points"),
            ("method", "GEOMETRY", "exact camera"),
        ):
            default = getattr(settings, name)
            setattr(settings, name, value)
            with pytest.raises(RelativityError, match=message):
                effect.apply(scene)
            assert camera_object.data.type == "PERSP"
            setattr(settings, name, default)
        effect.apply(scene)
        assert camera_object.data.cycles_custom["use_time_of_flight"]
        assert not camera_object.data.cycles_custom["use_searchlight"]
        assert "kinematics=galilean" in scene.render.stamp_note_text  # output files say what they show
        effect.remove(scene)
        assert camera_object.data.type == "PERSP"
    finally:
        relativity_addon.unregister()
