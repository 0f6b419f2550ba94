"""A sun's disc as a moving object sees it: the penumbra of a shadow on the object (eq. 18's
copy of the sun, docs/lamp-doppler.md), a real Cycles render against a model from docs/physics.md.

A wall (the plane x = 0, facing -X) and a plate 1 m in front of it (x = -1, above z = 0, its edge
along Y) are one object moving at 0.8c along Y, the edge's direction: the motion moves, contracts
and delays the geometry only along the edge, so the wall stays the plane x = 0 and the plate's
height over the wall's z is what it is at rest. A 10-degree sun shines along +X. In the object's
frame (docs/physics.md, aberration) its light arrives along ``k' = (k - gamma beta) / gamma`` =
(0.6, -0.8, 0) and its disc is ``alpha / D`` across, ``D = gamma = 5/3``: the penumbra below the
plate's edge is the part of that disc the edge hides, over the ray's 1 / 0.6 m from the edge to
the wall. The camera at rest looks up at the wall from below the plate; each row of the image's
middle columns is a height z on the wall (the ray meets x = 0).
"""

import importlib
import math

import numpy as np
import pytest

import camera_helpers as ch
from blender_support import ADDON_MODULE

RESOLUTION = (32, 96)
SAMPLES = 8  # the width 1.002 of the model at 8 samples, 0.994 at 32, 1.012 at 128: noise under a third of the bar
BETA = np.array([0.0, 0.8, 0.0])
C = 10.0
GAP = 1.0  # m between the plate and the wall (across the motion: not contracted)
SUN_ANGLE = math.radians(10.0)
CAMERA = np.array([-3.0, 0.0, -3.0])


def _quad(corners):
    return [tuple(c) for c in corners]


def _scene(bpy):
    import mathutils  # with bpy

    scene, camera = ch.new_scene(bpy, resolution=RESOLUTION, samples=SAMPLES, location=tuple(CAMERA))
    look = mathutils.Vector(tuple(-CAMERA)).to_track_quat("-Z", "Y")
    camera.rotation_euler = look.to_euler()
    camera.data.sensor_fit = "VERTICAL"
    camera.data.sensor_height = 36.0
    camera.data.lens = 180.0  # 0.2 rad tall: the wall from z = -0.5 to 0.5
    scene.cycles.max_bounces = 0
    scene.cycles.pixel_filter_type = "BOX"
    mesh = bpy.data.meshes.new("Wall")
    wall = _quad([(0, -3, -1), (0, 3, -1), (0, 3, 1), (0, -3, 1)])  # normal -X (toward the sun's side)
    plate = _quad([(-GAP, -6, 0), (-GAP, 6, 0), (-GAP, 6, 1.5), (-GAP, -6, 1.5)])
    mesh.from_pydata(wall + plate, [], [(0, 3, 2, 1), (4, 7, 6, 5)])
    mesh.materials.append(ch.diffuse_material(bpy, "White", (0.8, 0.8, 0.8)))
    obj = bpy.data.objects.new("Wall", mesh)
    obj.location = tuple(BETA * float(np.linalg.norm(CAMERA)))  # seen about the origin, 0.42 s ago
    scene.collection.objects.link(obj)
    obj.relativity.enabled = True
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = tuple(BETA)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 5.0
    sun.data.angle = SUN_ANGLE
    sun.rotation_euler = (0.0, -math.pi / 2.0, 0.0)  # its -Z along +X
    scene.collection.objects.link(sun)
    scene.relativity.speed_of_light = C
    scene.relativity.method = "GEOMETRY"
    scene.relativity.use_doppler = False
    scene.relativity.use_searchlight = False
    bpy.context.view_layer.update()
    return scene, camera


def _rows_to_heights(bpy, scene, camera):
    """The height z on the wall (x = 0) each row's centre ray meets."""
    model = ch.pinhole_model(bpy, scene, camera)
    rows = np.arange(RESOLUTION[1]) + 0.5
    local = model.pixel_direction(np.full_like(rows, RESOLUTION[0] / 2.0), rows)
    world = local @ model.rotation.T
    distance = -model.location[0] / world[:, 0]
    return model.location[2] + distance * world[:, 2]


def _visible_fraction(z):
    """The part of the object-frame sun disc the plate's edge leaves visible from height z."""
    k = np.array([1.0, 0.0, 0.0])
    speed = float(np.linalg.norm(BETA))
    gamma = 1.0 / math.sqrt(1.0 - speed**2)
    doppler = gamma * (1.0 - BETA @ k)
    k_object = (k + (gamma - 1.0) * (BETA @ k) / speed**2 * BETA - gamma * BETA) / doppler
    radius = SUN_ANGLE / doppler / 2.0  # alpha / D across (10 degrees: 1e-3 from the exact edges)
    # a ray toward the sun tilted by delta in z meets the plate's plane at z + delta GAP / k'_x
    u = np.clip(-z * k_object[0] / GAP / radius, -1.0, 1.0)
    return 1.0 - (np.arccos(u) - u * np.sqrt(1.0 - u * u)) / math.pi


def _width(z, profile):
    """The 10-90 % width (m of z) of a profile falling from 1 (low z) to 0 (high z): where it
    first falls below 0.9 and below 0.1, interpolated between rows."""
    order = np.argsort(z)
    z, profile = z[order], profile[order]
    crossings = []
    for level in (0.9, 0.1):
        i = int(np.argmax(profile < level))
        crossings.append(z[i - 1] + (profile[i - 1] - level) / (profile[i - 1] - profile[i]) * (z[i] - z[i - 1]))
    return float(crossings[1] - crossings[0])


def test_sun_penumbra_on_a_moving_object_is_the_aberrated_disc(relativity_addon, factory_blender, tmp_path):
    """The penumbra's 10-90 % width within 8 % of the object-frame disc's (before: the sun's own
    10 degrees, 1.67x)."""
    bpy = factory_blender
    scene, camera = _scene(bpy)
    importlib.import_module(f"{ADDON_MODULE}.blender.pipeline.effect").apply(scene)
    image = ch.luminance(ch.render_exr(bpy, scene, tmp_path / "penumbra.exr"))
    z = _rows_to_heights(bpy, scene, camera)
    profile = image[:, 8:24].mean(axis=1)
    lit = float(np.median(profile[z < -0.3]))
    rendered = _width(z, profile / lit)
    expected = _width(z, _visible_fraction(z))
    print(f"penumbra 10-90 %: rendered {rendered:.4f} m, object-frame disc {expected:.4f} m, {rendered / expected:.3f}")
    assert rendered / expected == pytest.approx(1.0, abs=0.08)
