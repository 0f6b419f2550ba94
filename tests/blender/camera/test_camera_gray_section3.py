"""Gray et al. (2020) sections 3D and 4: fixed-point-surface shutter and Lorentz window.

Both make (parts of) the photo taken by the moving camera identical to the photo at rest:
- fixed-point-surface shutter: objects in the focus plane keep their image positions (eq. 4);
- shutter plus Lorentz window in the plane of spatial fixed points for t_S (eq. 6): the
  whole photo equals the photo at rest (Fig. 9).
Gray's standard velocity (0.1, 0, 0.99) in Dr TIM coordinates (x right, y up, z into the page)
is, for a Blender camera looking down world -Z with +Y up, the world vector (0.1, 0, -0.99).
"""

import math

import numpy as np

import camera_helpers as ch

GRAY_BETA = "--beta=0.1,0,-0.99"


def test_fixed_point_surface_keeps_focus_plane_images(factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera_object = ch.new_scene(bpy, resolution=(320, 240), samples=16)
    camera_object.data.dof.use_dof = True
    camera_object.data.dof.focus_distance = 8.0
    camera_object.data.dof.aperture_fstop = 8.0
    camera = ch.pinhole_model(bpy, scene, camera_object)
    material = ch.emission_material(bpy)
    positions = []
    for px in (60.0, 160.0, 260.0):
        for py in (50.0, 120.0, 190.0):
            direction = camera.pixel_direction(px, py)
            center = direction / -direction[2] * 8.0  # on the camera-frame focus plane z = -8
            # Flat discs lying in the focus plane: with c = 1 any depth off the plane would be
            # Lorentz-shifted by about gamma * depth and blur the comparison.
            bpy.ops.mesh.primitive_circle_add(vertices=48, radius=0.05, fill_type="NGON", location=center)
            bpy.context.object.data.materials.append(material)
            positions.append((px, py))
    blend = ch.save_blend(bpy, tmp_path / "focus_plane.blend")

    rest = ch.luminance(
        ch.render_image(
            bpy, blend, tmp_path / "rest.exr", "--beta=0,0,0", "--shutter=aperture_plane", "--no-searchlight"
        )
    )
    moving = ch.luminance(
        ch.render_image(
            bpy,
            blend,
            tmp_path / "moving.exr",
            GRAY_BETA,
            "--shutter=fixed_point_surface",
            "--speed-of-light=1",
            "--no-searchlight",
        )
    )
    control = ch.luminance(
        ch.render_image(
            bpy,
            blend,
            tmp_path / "control.exr",
            GRAY_BETA,
            "--shutter=aperture_plane",
            "--speed-of-light=1",
            "--no-searchlight",
        )
    )

    errors = []
    for pixel in positions:
        at_rest, _ = ch.centroid(rest, pixel, 10)
        moved, _ = ch.centroid(moving, pixel, 10)
        assert at_rest is not None and moved is not None
        errors.append(np.linalg.norm(moved - at_rest))
    print(
        f"fixed-point surface: max shift {max(errors):.3f} px; "
        f"control (aperture plane) mean |diff| {np.abs(control - rest).mean():.4f}"
    )
    assert max(errors) < 0.5
    assert np.abs(control - rest).mean() > 10 * np.abs(moving - rest).mean()


def test_lorentz_window_photo_equals_photo_at_rest(factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera_object = ch.new_scene(
        bpy, resolution=(160, 120), samples=4, rotation_euler=(math.radians(90.0), 0.0, 0.0)
    )
    # The camera looks down world +Y here; Gray's beta is then (0.1, 0.99, 0) in world axes.
    for index, (x, y, z, r) in enumerate([(-1.5, 6.0, 0.5, 0.6), (1.0, 9.0, -0.5, 1.0), (0.3, 4.0, 0.8, 0.3)]):
        ch.add_sphere(bpy, scene, (x, y, z), r, ch.emission_material(bpy, name=f"E{index}", strength=1.0 + index))
    blend = ch.save_blend(bpy, tmp_path / "window.blend")
    # The window restores directions, not frequencies: compare without Doppler colour/searchlight.
    common = ("--shutter-time=-1", "--speed-of-light=1", "--no-searchlight", "--no-doppler", "--seed=3")
    rest = ch.render_image(bpy, blend, tmp_path / "rest.exr", "--beta=0,0,0", *common)
    window = ch.render_image(bpy, blend, tmp_path / "window.exr", "--beta=0.1,0.99,0", "--lorentz-window", *common)
    plain = ch.render_image(bpy, blend, tmp_path / "plain.exr", "--beta=0.1,0.99,0", *common)
    other_seed = ch.render_image(bpy, blend, tmp_path / "rest4.exr", "--beta=0,0,0", *common[:-1], "--seed=4")
    noise = np.abs(other_seed - rest).mean()
    print(
        f"Lorentz window: |window - rest| {np.abs(window - rest).mean():.5f}, "
        f"|moving - rest| {np.abs(plain - rest).mean():.5f}, seed noise {noise:.5f}"
    )
    assert rest.mean() > 0.01
    assert np.abs(window - rest).mean() < 0.5 * noise
    assert np.abs(plain - rest).mean() > 5 * noise
