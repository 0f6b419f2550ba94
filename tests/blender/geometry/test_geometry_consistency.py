"""A static scene seen by a camera at beta = 0.8: the exact OSL camera (--method camera) and the
apparent-geometry mesh path (--method geometry) put marker spheres at the same pixels (320x240)."""

import numpy as np

from geometry_helpers import ch


def test_markers_match_exact_camera_within_one_pixel(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera_object = ch.new_scene(bpy, resolution=(320, 240), samples=4)
    camera = ch.pinhole_model(bpy, scene, camera_object)
    beta = np.array([0.5, 0.2, -0.58])  # |beta| = 0.79
    beta *= 0.8 / np.linalg.norm(beta)
    targets = [(60.0, 50.0), (250.0, 70.0), (160.0, 120.0), (90.0, 190.0), (270.0, 200.0)]
    material = ch.emission_material(bpy)
    markers = []
    for i, (px, py) in enumerate(targets):
        view = ch.scene_direction_for_apparent(camera.local_to_world(camera.pixel_direction(px, py)), beta)
        location = camera.location + (4.0 + i) * view
        ch.add_sphere(bpy, scene, location, 0.05 * (4.0 + i), material, name=f"Marker{i}", segments=24, rings=12)
        markers.append(camera.project_direction(ch.apparent_view_direction(location, camera.location, beta)))
    scene.relativity.speed_of_light = 5.0  # slow light: light-travel times are seconds
    scene.frame_current = 12
    blend = ch.save_blend(bpy, tmp_path / "markers.blend")

    options = (f"--beta={beta[0]},{beta[1]},{beta[2]}", "--no-searchlight", "--no-doppler", "--shutter=pinhole")
    exact = ch.luminance(ch.render_image(bpy, blend, tmp_path / "camera.exr", "--method=camera", *options))
    mesh = ch.luminance(ch.render_image(bpy, blend, tmp_path / "geometry.exr", "--method=geometry", *options))
    ch.run_render_script(blend, tmp_path / "geometry.png", "--method=geometry", *options)

    for expected in markers:
        assert expected is not None
        exact_centre, exact_total = ch.centroid(exact, expected, 14)
        mesh_centre, mesh_total = ch.centroid(mesh, expected, 14)
        assert exact_total > 0.0 and mesh_total > 0.0
        print(f"expected {expected}, camera {exact_centre}, geometry {mesh_centre}")
        assert np.linalg.norm(exact_centre - expected) < 1.0
        assert np.linalg.norm(mesh_centre - exact_centre) < 1.0
