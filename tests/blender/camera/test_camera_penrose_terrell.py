"""Penrose-Terrell: a sphere passed at 0.9c keeps a circular outline (not a 1/gamma ellipse).

Circularity is measured in angle space: silhouette pixels are unprojected to viewing
directions and mapped to the tangent plane around the silhouette's own axis (a circular cone
of directions is a circle there, wherever it sits in the image); the axis ratio comes from the
second moments of that area-weighted point set.
"""

import math

import numpy as np

import camera_helpers as ch


def test_sphere_outline_stays_circular_at_0_9c(factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera_object = ch.new_scene(bpy, resolution=(320, 240), samples=4)
    camera = ch.pinhole_model(bpy, scene, camera_object)
    # Camera looks down world -Z and moves sideways (world +X) at 0.9c.
    beta = np.array([0.9, 0.0, 0.0])
    gamma = ch.gamma_of(beta)
    focal_px = camera.size[0] / (camera.window[1] - camera.window[0])
    # Seen off-axis, up and to the right in the image, with an apparent radius of ~25 px.
    view_camera = camera.local_to_world(camera.pixel_direction(215.0, 80.0))
    view_scene = ch.scene_direction_for_apparent(view_camera, beta)
    doppler = ch.doppler_factor(-view_scene, beta)
    distance = 6.0
    radius = distance * math.sin(25.0 / focal_px * doppler)
    ch.add_sphere(
        bpy, scene, camera.location + distance * view_scene, radius, ch.emission_material(bpy), segments=128, rings=64
    )
    blend = ch.save_blend(bpy, tmp_path / "sphere.blend")

    image = ch.render_image(
        bpy, blend, tmp_path / "sphere.exr", "--beta=0.9,0,0", "--shutter=pinhole", "--no-searchlight"
    )
    coverage = np.clip(ch.luminance(image), 0.0, 1.0)
    assert coverage.max() > 0.99, "sphere not fully resolved"
    ratio, axis = ch.tangent_plane_axis_ratio(camera, coverage)

    print(f"axis ratio {ratio:.4f} (Lorentz-contracted would be {1.0 / gamma:.3f})")
    assert abs(ratio - 1.0) < 0.02
    # The silhouette sits where aberration puts the sphere's centre direction (to ~1 px).
    expected_axis = ch.normalized(camera.world_to_local(view_camera))
    assert math.degrees(math.acos(min(1.0, axis @ expected_axis))) * focal_px * math.pi / 180.0 < 1.5
