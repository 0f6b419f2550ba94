"""Apparent Geometry's final render under a lamp, observer moving: the pool of light a point lamp
makes on a wall at rest lands where the exact camera puts it, as bright.

Apparent Geometry's final render photographs the scene-frame retarded meshes with the exact
camera (``effect.begin_final_render``), so lamps light the surfaces where they are. The boosted-mesh
preview (``geometry_final_render = 'PREVIEW'``) lights the meshes where they appear and is measured
here too, to show that the test tells the two apart.
"""

import numpy as np
import pytest

import colour_helpers as dh
from colour_helpers import ch

RESOLUTION = (160, 120)
BETA = (0.45, 0.0, -0.45)  # |beta| 0.64, sideways and toward the wall


def _pool_scene(bpy):
    scene, camera = dh.emitter_scene(bpy, samples=16, resolution=RESOLUTION)
    camera.data.lens = 24.0
    scene.cycles.max_bounces = 0  # direct light only: the pool itself
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=64, y_subdivisions=64, size=16.0, location=(0.0, 0.0, -6.0))
    wall = bpy.context.active_object
    wall.data.materials.append(ch.diffuse_material(bpy, "White", (0.8, 0.8, 0.8)))
    light = bpy.data.lights.new("Lamp", "POINT")
    light.energy = 300.0
    light.shadow_soft_size = 0.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = (1.0, 0.5, -5.0)
    scene.collection.objects.link(lamp)
    return scene


def _pool(luminance):
    """Centroid (x, y pixels) and mean luminance of the pool: the pixels above half its peak."""
    peak = np.percentile(luminance, 99.5)
    mask = luminance > 0.5 * peak
    rows, columns = np.nonzero(mask)
    weights = luminance[mask]
    return np.array([np.average(columns + 0.5, weights=weights), np.average(rows + 0.5, weights=weights)]), float(
        weights.mean()
    )


def _render(bpy, scene, method, tmp_path, final_render="EXACT"):
    scene.relativity.method = method
    scene.relativity.geometry_final_render = final_render
    scene.relativity.beta = BETA
    scene.relativity.speed_of_light = 1.0
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    image = dh.render(bpy, scene, tmp_path / f"{method}_{final_render}.exr")
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    bpy.ops.relativity.remove_all()
    return ch.luminance(image)


def test_pool_of_light_matches_the_exact_camera(relativity_addon, tmp_path):
    bpy = __import__("bpy")
    scene = _pool_scene(bpy)
    exact_centre, exact_level = _pool(_render(bpy, scene, "CAMERA", tmp_path))
    mesh_centre, mesh_level = _pool(_render(bpy, scene, "GEOMETRY", tmp_path))
    preview_centre, preview_level = _pool(_render(bpy, scene, "GEOMETRY", tmp_path, "PREVIEW"))
    offset = np.linalg.norm(mesh_centre - exact_centre)
    preview_offset = np.linalg.norm(preview_centre - exact_centre)
    print(
        f"pool: exact camera {exact_centre} level {exact_level:.4g}; Apparent Geometry {mesh_centre} "
        f"(offset {offset:.2f} px, level ratio {mesh_level / exact_level:.4f}); boosted-mesh preview "
        f"{preview_centre} (offset {preview_offset:.1f} px, level ratio {preview_level / exact_level:.3f})"
    )
    assert offset < 2.0
    assert mesh_level / exact_level == pytest.approx(1.0, abs=0.10)
    assert preview_offset > 5.0 or abs(preview_level / exact_level - 1.0) > 0.2, (
        "the preview lights the meshes where they appear: it must differ"
    )


def test_final_render_restores_the_preview(relativity_addon, tmp_path):
    """After an F12 render the scene is back on the boosted-mesh preview: the camera is the user's
    perspective camera again, no compositor stage, the meshes boosted."""
    bpy = __import__("bpy")
    scene = _pool_scene(bpy)
    scene.relativity.method = "GEOMETRY"
    scene.relativity.beta = BETA
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    wall = scene.objects["Grid"]

    def positions():
        evaluated = wall.evaluated_get(bpy.context.evaluated_depsgraph_get())
        mesh = evaluated.to_mesh()
        points = np.array([tuple(evaluated.matrix_world @ v.co) for v in mesh.vertices])
        evaluated.to_mesh_clear()
        return points

    before = positions()
    compositor_before = ch.compat.compositor_tree(scene)
    dh.render(bpy, scene, tmp_path / "f12.exr")
    bpy.context.view_layer.update()
    assert scene.camera.data.type == "PERSP"
    assert ch.compat.compositor_tree(scene) == compositor_before
    after = positions()
    assert np.allclose(after, before, atol=1e-5), "the preview's boosted meshes are back"
    assert np.abs(after[:, 2] + 6.0).max() > 0.1, "the preview meshes are boosted, not at rest (z = -6)"


def test_panoramic_final_render_matches_the_exact_camera(relativity_addon, tmp_path):
    """With Blender's equirectangular camera the final render goes through the exact panorama too:
    it equals the exact camera's render of the same scene, the preview does not, and the camera is
    the user's panorama again afterwards."""
    bpy = __import__("bpy")
    scene = _pool_scene(bpy)
    scene.render.resolution_x, scene.render.resolution_y = 128, 64
    scene.camera.data.type = "PANO"
    scene.camera.data.panorama_type = "EQUIRECTANGULAR"
    exact = _render(bpy, scene, "CAMERA", tmp_path)
    mesh = _render(bpy, scene, "GEOMETRY", tmp_path)
    preview = _render(bpy, scene, "GEOMETRY", tmp_path, "PREVIEW")
    assert (scene.camera.data.type, scene.camera.data.panorama_type) == ("PANO", "EQUIRECTANGULAR")
    level = exact.mean()
    difference, preview_difference = np.abs(mesh - exact).mean() / level, np.abs(preview - exact).mean() / level
    print(
        f"equirectangular: mean |Apparent Geometry - exact| / mean {difference:.4f}, preview {preview_difference:.3f}"
    )
    assert level > 1e-3, "the pool must be in the panorama"
    assert difference < 0.02
    assert preview_difference > 0.2, "the preview lights the meshes where they appear: it must differ"
