"""A lamp at rest in the scene lights an object moving with the camera (issue 28 part 1, docs/cockpit.md)
as eq. 18 says a lamp at rest lights a moving object (docs/physics.md, "Radiance"; docs/lamp-doppler.md):
in the object's frame its light arrives along the aberrated direction ``k'`` with ``D^2`` the
scene-frame irradiance at the same scene-frame distance, ``D = gamma (1 - beta . k)``.

A white plate moving with a camera at 0.9c sideways, facing the camera; a point lamp at rest
behind and to the side. The plate's brightness over Blender's own render of the same plate lit
by the same lamp at rest (same distance) is ``D^2 cos(alpha') / cos(alpha)``, written out here
from docs/physics.md. Before this change the cockpit's rest render had no scene lamp: black.
"""

import importlib

import numpy as np
import pytest

import camera_helpers as ch
from blender_support import ADDON_MODULE

BETA = np.array([0.9, 0.0, 0.0])  # the camera (looking down -Z) moves to its right
LAMP = np.array([3.0, 0.0, 3.0])
PLATE = np.array([0.0, 0.0, -1.0])  # facing +Z, the camera
NORMAL = np.array([0.0, 0.0, 1.0])


def _effect():
    return importlib.import_module(f"{ADDON_MODULE}.blender.pipeline.effect")


def _cockpit_plate(bpy, scene, camera):
    """A 0.2 m plate parented to the camera at PLATE, moving with it (the cockpit)."""
    mesh = bpy.data.meshes.new("Plate")
    mesh.from_pydata([(-0.1, -0.1, 0.0), (0.1, -0.1, 0.0), (0.1, 0.1, 0.0), (-0.1, 0.1, 0.0)], [], [(0, 1, 2, 3)])
    plate = bpy.data.objects.new("Plate", mesh)
    scene.collection.objects.link(plate)
    plate.parent = camera
    plate.location = tuple(PLATE)
    plate.relativity.moves_with_camera = True
    return plate


def expected_ratio(lamp=LAMP, plate=PLATE, beta=BETA, normal=NORMAL):
    """``D^2 cos(alpha') / cos(alpha)`` at the plate's centre, ``alpha`` the angle of incidence
    (scene frame, the lamp at rest) and ``alpha'`` the plate's frame one (aberrated ``k'``)."""
    k = ch.normalized(plate - lamp)
    doppler = ch.doppler_factor(k, beta)
    k_moving = ch.normalized(ch.aberrate(k, beta))
    return doppler**2 * (-k_moving @ normal) / (-k @ normal), doppler, -k_moving @ normal


def test_scene_lamp_lights_the_cockpit_by_eq_18(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera = ch.new_scene(bpy, resolution=(64, 48), samples=32)
    scene.cycles.seed = 0
    mesh = bpy.data.meshes.new("Plate")
    h = 0.1
    mesh.from_pydata([(-h, -h, 0.0), (h, -h, 0.0), (h, h, 0.0), (-h, h, 0.0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(ch.diffuse_material(bpy, "White", (0.8, 0.8, 0.8)))
    plate = bpy.data.objects.new("Plate", mesh)
    scene.collection.objects.link(plate)
    plate.parent = camera
    plate.location = tuple(PLATE)
    plate.relativity["moves_with_camera"] = True  # by its stored value: the test runs on the code before it too
    light = bpy.data.lights.new("Lamp", "POINT")
    light.energy = 400.0
    light.shadow_soft_size = 0.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = tuple(LAMP)
    scene.collection.objects.link(lamp)
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = tuple(BETA)
    scene.relativity.use_doppler = False
    scene.relativity.use_searchlight = True
    bpy.context.view_layer.update()
    rest = ch.render_exr(bpy, scene, tmp_path / "rest.exr")  # Blender's own render, at rest
    centre = (slice(21, 27), slice(29, 35))  # the plate's middle (64 x 48, the plate about 18 px wide)
    assert rest[centre].min() > 0.01
    _effect().apply(scene)
    moving = ch.render_exr(bpy, scene, tmp_path / "moving.exr")
    assert np.all(np.isfinite(moving))
    ratio = moving[centre].mean() / rest[centre].mean()
    expected, doppler, cosine = expected_ratio()
    print(
        f"plate lit by a lamp at rest, camera at 0.9c: {moving[centre].mean():.4f} against "
        f"{rest[centre].mean():.4f} at rest, ratio {ratio:.4f}; eq. 18: D^2 cos(alpha')/cos(alpha) = "
        f"{expected:.4f} (D = {doppler:.4f}, cos alpha' = {cosine:.4f}; without aberration "
        f"{doppler**2:.3f})"
    )
    assert ratio == pytest.approx(expected, rel=0.03)
    _effect().remove(scene)
    assert not [obj for obj in bpy.data.objects if obj.name.startswith("Relativity")]
    assert not [light for light in bpy.data.lights if light.name.startswith("Relativity")]


def test_remove_gives_the_file_back_with_sky_and_lamps(relativity_addon, factory_blender, tmp_path):
    """A cockpit under a textured sky with a point lamp and a sun at rest, Doppler colour on: Set Up
    (the sky's copy, the lamps' copies, the colour stage in the world), a sync, Remove: the file as
    it was (``scene_dump``)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "pipeline"))
    import scene_dump

    bpy = factory_blender
    scene, camera = ch.new_scene(bpy, resolution=(32, 24), samples=4)
    tree = scene.world.node_tree
    gradient = tree.nodes.new("ShaderNodeTexGradient")
    tree.links.new(gradient.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    _cockpit_plate(bpy, scene, camera)
    for kind, location in (("POINT", LAMP), ("SUN", (0.0, 5.0, 5.0))):
        lamp = bpy.data.objects.new(kind.title(), bpy.data.lights.new(kind.title(), kind))
        lamp.location = tuple(location)
        scene.collection.objects.link(lamp)
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = tuple(BETA)
    scene.relativity.use_doppler = True
    bpy.context.view_layer.update()
    before = scene_dump.dump(bpy)
    _effect().apply(scene)
    _effect().sync(scene)
    rest_scene = bpy.data.scenes[f"Relativity Cockpit {scene.name}"]
    assert rest_scene.world is not None and rest_scene.world != scene.world
    assert sorted(obj.data.type for obj in rest_scene.objects if obj.type == "LIGHT") == ["POINT", "SUN"]
    _effect().remove(scene)
    lines = scene_dump.differences(before, scene_dump.dump(bpy))
    assert not lines, "\n".join(lines[:20])


def test_sun_copy_has_the_disc_the_cockpit_sees(relativity_addon, factory_blender):
    """A sun of 20 degrees seen from the cockpit at 0.9c: its copy's disc is the angle between the
    disc's two edges (in the plane of k and beta) each aberrated (docs/physics.md): 40.5 degrees
    here (light from behind the motion, D = 0.51, the disc about 1/D as wide); before, the copy
    kept the sun's 20."""
    import math

    bpy = factory_blender
    scene, camera = ch.new_scene(bpy, resolution=(32, 24), samples=4)
    _cockpit_plate(bpy, scene, camera)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.angle = math.radians(20.0)
    sun.rotation_euler = (0.0, math.radians(-60.0), 0.0)  # light along +x and down: from behind
    scene.collection.objects.link(sun)
    scene.relativity.method = "CAMERA"
    scene.relativity.beta = tuple(BETA)
    bpy.context.view_layer.update()
    _effect().apply(scene)
    copy = next(obj for obj in bpy.data.scenes[f"Relativity Cockpit {scene.name}"].objects if obj.type == "LIGHT")
    k = -np.array(sun.matrix_world.col[2][:3])  # the sun's light travels along its -Z
    across = np.cross(np.cross(k, BETA), k)
    across /= np.linalg.norm(across)
    half = 0.5 * sun.data.angle
    edges = [ch.aberrate(math.cos(half) * k + sign * math.sin(half) * across, BETA) for sign in (1.0, -1.0)]
    expected = math.acos(np.clip(edges[0] @ edges[1] / np.prod([np.linalg.norm(e) for e in edges]), -1.0, 1.0))
    print(f"sun 20 deg, copy {math.degrees(copy.data.angle):.3f} deg, expected {math.degrees(expected):.3f} deg")
    assert abs(expected - sun.data.angle) > 0.2 * sun.data.angle  # the case tells the two apart
    assert copy.data.angle == pytest.approx(expected, rel=1e-4)
    _effect().remove(scene)
