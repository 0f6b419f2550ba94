"""At rest the relativistic camera is Blender's perspective camera; the searchlight is D^4."""

import math

import numpy as np
import pytest

import camera_helpers as ch


def _lit_scene(bpy, use_dof):
    """A small lit room-corner: diffuse floor and wall, a cube, an emitter, a point light."""
    scene, camera = ch.new_scene(
        bpy,
        resolution=(160, 120),
        samples=8,
        rotation_euler=(math.radians(75.0), 0.0, math.radians(20.0)),
        location=(1.5, -6.0, 2.0),
    )
    camera.data.lens = 35.0
    camera.data.shift_x = 0.07
    camera.data.shift_y = -0.04
    camera.data.sensor_fit = "VERTICAL"
    if use_dof:
        camera.data.dof.use_dof = True
        camera.data.dof.focus_distance = 5.0
        camera.data.dof.aperture_fstop = 1.4
        camera.data.dof.aperture_blades = 6
        camera.data.dof.aperture_ratio = 1.5
    diffuse = bpy.data.materials.new("Diffuse")
    bpy.ops.mesh.primitive_plane_add(size=20.0)
    bpy.context.object.data.materials.append(diffuse)
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 4.0, 0.0), rotation=(math.radians(90.0), 0.0, 0.0))
    bpy.context.object.data.materials.append(diffuse)
    bpy.ops.mesh.primitive_cube_add(size=1.5, location=(0.5, 0.0, 0.75), rotation=(0.0, 0.0, 0.4))
    bpy.context.object.data.materials.append(diffuse)
    ch.add_sphere(bpy, scene, (-1.5, 1.0, 1.0), 0.4, ch.emission_material(bpy, strength=4.0))
    light = bpy.data.lights.new("Light", "POINT")
    light.energy = 800.0
    light_object = bpy.data.objects.new("Light", light)
    light_object.location = (2.0, -2.0, 4.0)
    scene.collection.objects.link(light_object)
    return scene


@pytest.mark.parametrize("use_dof,shutter", [(False, "pinhole"), (True, "aperture_plane")])
def test_rest_equals_perspective_camera(factory_blender, tmp_path, use_dof, shutter):
    bpy = factory_blender
    _lit_scene(bpy, use_dof)
    blend = ch.save_blend(bpy, tmp_path / "room.blend")

    reference = ch.render_image(bpy, blend, tmp_path / "persp0.exr", "--reference", "--seed=0")
    other_seed = ch.render_image(bpy, blend, tmp_path / "persp1.exr", "--reference", "--seed=1")
    relativistic = ch.render_image(
        bpy, blend, tmp_path / "rel0.exr", "--beta=0,0,0", f"--shutter={shutter}", "--seed=0"
    )
    noise = np.abs(other_seed - reference).mean()
    difference = np.abs(relativistic - reference).mean()
    print(f"dof={use_dof}: mean |rel - persp| = {difference:.5f}, seed noise = {noise:.5f}")
    assert reference.mean() > 0.01, "reference render is black"
    assert noise > 0.0
    assert difference < 0.25 * noise


def test_searchlight_ratio_is_doppler_fourth_power(factory_blender, tmp_path):
    """Two identical emitters seen at different angles: radiance ratio = ratio of D^4."""
    bpy = factory_blender
    scene, camera_object = ch.new_scene(bpy, resolution=(320, 240), samples=4)
    camera = ch.pinhole_model(bpy, scene, camera_object)
    beta = 0.5 * ch.normalized([0.6, 0.0, -1.0])  # world; camera looks down -Z
    material = ch.emission_material(bpy, strength=1.0)
    focal_px = camera.size[0] / (camera.window[1] - camera.window[0])
    emitters = []
    for index, pixel in enumerate([(70.0, 120.0), (250.0, 120.0)]):
        view_camera = camera.local_to_world(camera.pixel_direction(*pixel))
        view_scene = ch.scene_direction_for_apparent(view_camera, beta)
        k = -view_scene
        doppler = ch.doppler_factor(k, beta)
        radius = 10.0 * math.sin(9.0 / focal_px * doppler)  # about 9 px apparent radius
        ch.add_sphere(bpy, scene, camera.location + 10.0 * view_scene, radius, material, name=f"E{index}")
        emitters.append((np.array(pixel), doppler))
    blend = ch.save_blend(bpy, tmp_path / "emitters.blend")
    beta_option = ",".join(f"{b:.17g}" for b in beta)
    image = ch.render_image(
        bpy, blend, tmp_path / "emitters.exr", f"--beta={beta_option}", "--shutter=pinhole", "--no-doppler"
    )  # integrated radiance: D^4 holds with colours unshifted
    intensity = ch.luminance(image)

    ys, xs = np.mgrid[0 : intensity.shape[0], 0 : intensity.shape[1]]
    radiances = []
    for pixel, _doppler in emitters:
        inside = np.hypot(xs + 0.5 - pixel[0], ys + 0.5 - pixel[1]) < 4.0
        radiances.append(intensity[inside].mean())
    measured = radiances[0] / radiances[1]
    expected = (emitters[0][1] / emitters[1][1]) ** 4
    print(
        f"D = {emitters[0][1]:.4f}, {emitters[1][1]:.4f}; radiances {radiances}; "
        f"ratio measured {measured:.4f}, expected D^4 ratio {expected:.4f}"
    )
    # Each emitter alone: radiance = D^4 times the emitted radiance (1).
    for radiance, (_, doppler) in zip(radiances, emitters, strict=True):
        assert radiance == pytest.approx(doppler**4, rel=0.02)
    assert measured == pytest.approx(expected, rel=0.02)
    assert abs(math.log(expected)) > 0.5, "test emitters must differ clearly in D"
