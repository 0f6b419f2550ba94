"""A glowing sphere moving at 0.5c above a white floor lights it as a moving light (eq. 19):
``Object.relativity.lights_scene`` (blender/scene/emitting_meshes.py), Apparent Geometry, camera at rest.

A sphere of radius R and radiance L is, seen from outside, a point source of intensity
``I = L pi R^2`` in every direction, so the floor's radiance is eq. 19's ``a / pi D^4 I cos / r^2``
from the sphere centre's retarded positions (``test_moving_point_light``'s numpy solution, not the
add-on's). Without the setting Cycles lights the floor from the sphere where the apparent geometry
draws it, with no beaming (the old behaviour, measured and printed here).
"""

import math

import numpy as np
import test_moving_point_light as mp

from relativity_addon.blender.common import compat

RADIUS = 0.15
RADIANCE = 400.0  # W m^-2 sr^-1, white
RESOLUTION = (80, 60)
ROWS = slice(28, 32)


def _scene(bpy, lights_scene):
    scene, camera = mp.ch.new_scene(bpy, resolution=RESOLUTION, samples=16, location=tuple(mp.CAMERA))
    camera.data.lens = 25.0
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    mp._quad(bpy, scene, "Floor", (0.0, 0.0, 0.0), 100.0, mp.ch.diffuse_material(bpy, "White", (mp.ALBEDO,) * 3))
    material = bpy.data.materials.new("Glow")
    tree = compat.material_node_tree(material)
    tree.nodes.clear()
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = RADIANCE
    tree.links.new(emission.outputs[0], tree.nodes.new("ShaderNodeOutputMaterial").inputs["Surface"])
    import bmesh  # after bpy

    mesh = bpy.data.meshes.new("Sphere")
    builder = bmesh.new()
    bmesh.ops.create_uvsphere(builder, u_segments=64, v_segments=32, radius=RADIUS)
    builder.to_mesh(mesh)
    builder.free()
    mesh.materials.append(material)
    sphere = bpy.data.objects.new("Sphere", mesh)
    sphere.location = tuple(mp.LAMP)
    sphere.visible_camera = False  # the floor under it in full; its light is what is measured
    scene.collection.objects.link(sphere)
    sphere.relativity.motion = "CONSTANT"
    sphere.relativity.beta = tuple(mp.BETA)
    sphere.relativity.lights_scene = lights_scene
    scene.relativity.speed_of_light = mp.C
    scene.relativity.method = "GEOMETRY"
    return scene, camera, sphere


def _profile_error(bpy, scene, camera, image):
    points = mp._floor_points(bpy, scene, camera)
    expected, _source, _d = mp._expected_radiance(points, mp.BETA)
    expected *= RADIANCE * math.pi * RADIUS**2 / (mp.POWER / (4.0 * math.pi))  # I = L pi R^2
    measured, wanted = image[ROWS, :, 1].mean(0), expected[ROWS].mean(0)
    return np.abs(measured - wanted).max() / wanted.max(), int(np.argmax(measured)), int(np.argmax(wanted))


def test_moving_emitter_lights_the_floor_by_eq_19(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, sphere = _scene(bpy, lights_scene=False)
    mp._effect().apply(scene)
    old = _profile_error(bpy, scene, camera, mp._render(bpy, scene, tmp_path / "old.exr"))
    print(f"without Lights the Scene: max error {old[0]:.3f} of the peak, peak at {old[1]} (eq. 19: {old[2]})")

    sphere.relativity.lights_scene = True
    assert not sphere.visible_diffuse and not sphere.visible_glossy, "its own light reaches camera rays only"
    image = mp._render(bpy, scene, tmp_path / "new.exr")
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    error, peak, expected_peak = _profile_error(bpy, scene, camera, image)
    print(f"Lights the Scene: max error {error:.3f} of the peak, peak at {peak} (eq. 19: {expected_peak})")
    assert error < 0.05
    assert abs(peak - expected_peak) <= 1
    assert old[0] > 0.2, "the test must be able to tell the two apart"

    mp._effect().remove(scene)
    assert sphere.visible_diffuse and sphere.visible_glossy and not sphere.hide_render
