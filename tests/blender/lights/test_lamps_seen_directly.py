"""Lamps seen directly by the exact camera (fast mode): colour-shifted like an emitter mesh.

A 3000 K lamp at rest (an area light, or a point light with a radius, visible to camera rays)
beside a 3000 K emitter mesh, observer moving toward them at 0.5c. Both are blackbodies at rest
in the scene frame, so both must be seen as blackbodies at ``D T`` with luminance
``Y(D T) / Y(T)`` times their rest luminance (Weiskopf et al. 1999 eq. 14, docs/physics.md), ``D``
from each pixel's viewing direction. References: colour-science's Planck spectra; the rest
luminances are measured on a render without the effect. Before lamps got emitter faces the lamp
came out on the RGB matrix: Delta E 2000 of 26 from the blackbody at ``D T``.
"""

import math

import numpy as np
import pytest

import colour_helpers as dh

TEMPERATURE = 3000.0
RESOLUTION = (64, 48)
LAMP = (slice(20, 28), slice(12, 18))  # pixels inside the lamp's image at rest and moving
MESH = (slice(20, 28), slice(46, 52))
BETA = (0.0, 0.0, -0.5)


def _scene(bpy, kind):
    scene, camera = dh.emitter_scene(bpy, samples=8, resolution=RESOLUTION)
    dh.add_emitter_plane(
        bpy, scene, "Mesh", (0.3, 2.5), (-1.0, 1.0), colour=(1.0, 1.0, 1.0), beta=None, temperature=TEMPERATURE
    )
    light = bpy.data.lights.new("Lamp", kind)
    light.energy = 100.0
    light.use_temperature = True
    light.temperature = TEMPERATURE
    if kind == "AREA":
        light.size = 2.0
    else:
        light.shadow_soft_size = 1.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = (-1.4, 0.0, -5.0)
    lamp.rotation_euler = (math.pi, 0.0, 0.0)  # area and spot lights emit along local -Z: toward the camera
    lamp.visible_camera = True
    scene.collection.objects.link(lamp)
    return scene, camera, lamp


def _xyz(image, window):
    return dh.linear_rec709_to_xyz(image[window].reshape(-1, 3)).mean(axis=0)


def _expected(doppler, y_rest):
    """Mean XYZ of blackbodies at ``D T`` scaled to ``y_rest`` times ``Y(D T) / Y(T)``."""
    y_t = dh.blackbody_xyz_colour_science(TEMPERATURE)[1]
    return np.mean(dh.blackbody_xyz_colour_science(np.asarray(doppler) * TEMPERATURE) / y_t * y_rest, axis=0)


def _render_moving(bpy, scene, camera, lamp, tmp_path):
    """The exact camera at ``BETA`` (c = 1): its render and each pixel's ``D``."""
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    assert not lamp.visible_camera, "the lamp is drawn by its face while applied"
    moving = dh.render(bpy, scene, tmp_path / "moving.exr")
    assert np.all(np.isfinite(moving)) and moving.min() >= 0.0
    view = -dh.pixel_photon_directions(bpy, scene, camera)
    gamma = 1.0 / math.sqrt(1.0 - np.dot(BETA, BETA))
    return moving, 1.0 / (gamma * (1.0 - view @ np.asarray(BETA)))


@pytest.mark.parametrize("kind", ["AREA", "POINT", "SPOT"])
def test_visible_blackbody_lamp_is_seen_at_d_t_like_an_emitter(relativity_addon, tmp_path, kind):
    bpy = __import__("bpy")
    scene, camera, lamp = _scene(bpy, kind)
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = {name: _xyz(rest, window)[1] for name, window in (("lamp", LAMP), ("mesh", MESH))}
    assert y_rest["lamp"] > 1.0 and y_rest["mesh"] > 0.5

    moving, doppler = _render_moving(bpy, scene, camera, lamp, tmp_path)
    measured = {}
    for name, window in (("lamp", LAMP), ("mesh", MESH)):
        xyz = _xyz(moving, window)
        expected = _expected(doppler[window].ravel(), y_rest[name])
        measured[name] = xyz
        delta_e = dh.delta_e_2000_normalised(xyz, expected)
        ratio = xyz[1] / expected[1]
        print(f"{kind} {name}: D {doppler[window].mean():.3f}, Delta E {delta_e:.3f}, Y / expected {ratio:.4f}")
        assert delta_e < 1.0, name
        assert ratio == pytest.approx(1.0, abs=0.02), name
    between = dh.delta_e_2000_normalised(measured["lamp"], measured["mesh"])
    print(f"{kind}: lamp against emitter mesh, Delta E {between:.3f}")
    assert between < 1.0

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert lamp.visible_camera
    assert not [obj for obj in bpy.data.objects if obj.name.startswith("Relativity Lamp Face")]
    assert not [material for material in bpy.data.materials if material.name.startswith("Relativity Lamp Face")]


def test_visible_sun_disc_is_seen_at_d_t(relativity_addon, tmp_path):
    """A 5762 K sun with a 20 degree disc straight ahead (Cycles draws it for camera rays, with
    radiance ``E / (pi sin^2(theta/2))``), observer at 0.5c toward it: the disc's centre is the
    blackbody at ``D T`` with ``Y(D T) / Y(T)`` times its luminance at rest in Cycles' own drawing."""
    bpy = __import__("bpy")
    scene, camera = dh.emitter_scene(bpy, samples=8, resolution=RESOLUTION)
    scene.world = None
    light = bpy.data.lights.new("Sun", "SUN")
    light.energy = 5.0
    light.angle = math.radians(20.0)
    light.use_temperature = True
    light.temperature = 5762.0
    sun = bpy.data.objects.new("Sun", light)
    sun.rotation_euler = (math.pi, 0.0, 0.0)  # shining along +Z, into the camera looking down -Z
    sun.visible_camera = True
    scene.collection.objects.link(sun)
    centre = (slice(20, 28), slice(28, 36))
    rest = dh.render(bpy, scene, tmp_path / "rest.exr")
    y_rest = _xyz(rest, centre)[1]
    disc = 5.0 / (math.pi * math.sin(math.radians(10.0)) ** 2)
    print(f"sun at rest: Y {y_rest:.2f}, E / (pi sin^2) {disc:.2f}")
    assert y_rest == pytest.approx(disc, rel=0.01)

    moving, doppler = _render_moving(bpy, scene, camera, sun, tmp_path)
    doppler = doppler[centre].ravel()
    gamma = 1.0 / math.sqrt(1.0 - np.dot(BETA, BETA))
    y_t = dh.blackbody_xyz_colour_science(5762.0)[1]
    expected = np.mean(dh.blackbody_xyz_colour_science(doppler * 5762.0) / y_t * y_rest, axis=0)
    xyz = _xyz(moving, centre)
    delta_e = dh.delta_e_2000_normalised(xyz, expected)
    print(f"sun at 0.5c: D {doppler.mean():.3f}, Delta E {delta_e:.3f}, Y / expected {xyz[1] / expected[1]:.4f}")
    assert delta_e < 1.0
    assert xyz[1] / expected[1] == pytest.approx(1.0, abs=0.02)
    # The aberrated disc: half-angle 10 degrees seen at 0.5c head-on shrinks to
    # atan(sin / (gamma (cos + beta))), so its width in pixels shrinks by about that ratio.
    lit = [int((image[24, :, :3].sum(axis=1) > 0.5 * image[24, 32, :3].sum()).sum()) for image in (rest, moving)]
    half = math.radians(10.0)
    shrink = math.atan(math.sin(half) / (gamma * (math.cos(half) + 0.5))) / half
    print(f"disc width {lit[0]} px at rest, {lit[1]} px moving (expected about {lit[0] * shrink:.1f})")
    assert abs(lit[1] - lit[0] * shrink) <= 2.0

    assert bpy.ops.relativity.remove_all() == {"FINISHED"}
    assert sun.visible_camera
    assert not [obj for obj in bpy.data.objects if obj.name.startswith("Relativity Lamp Face")]
