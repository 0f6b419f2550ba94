"""Apparent Geometry after Set Up (issue 25): edits that change what a moving mesh draws, motions
the settings do not describe, and instancers of moving meshes. Each is either moved right
(measured against the retarded-position relation of docs/physics.md, with the observer at rest at
the origin: a point of a body moving with velocity u is seen at x_e = p - u tau, with
tau = ((D.u) + sqrt((D.u)^2 + (c^2 - u.u) D.D)) / (c^2 - u.u), D = x_o - p) or named in one line:
in Set Up's refusal, or at sync (the panel's warnings, the last render's refusal)."""

import numpy as np
from test_object_type_sweep import _cube_mesh, _link

import geometry_helpers as gh

C = 4.0  # scene units per second: slow light, large delays
FPS = 24
BETA = np.array([0.3, 0.0, 0.0])


def _scene(bpy, resolution=(64, 48), samples=4):
    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.cycles.samples = samples
    scene.frame_set(12)
    return scene, camera


def _mover(bpy, scene, name="Mover", size=0.5, location=(0.0, 1.0, -6.0)):
    obj = _link(bpy, scene, name, _cube_mesh(bpy, name, size))
    obj.location = location
    obj.relativity.enabled = True
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = tuple(BETA)
    obj.relativity.tessellation = 0
    return obj


def _uniform_retarded(p, u, x_o):
    """Where a point at ``p`` now (observer time), moving with velocity ``u``, is seen from ``x_o``."""
    delta = x_o - p
    du, uu = delta @ u, u @ u
    tau = (du + np.sqrt(du * du + (C * C - uu) * (delta @ delta))) / (C * C - uu)
    return p - u * tau


def _warnings(scene):
    return gh.addon_module("pipeline.effect").scene_warnings(scene)


def _synced(bpy, scene):
    """What a depsgraph update after an edit does (the handler), then the scene's state."""
    bpy.context.view_layer.update()
    return gh.addon_module("pipeline.effect").sync(scene, bpy.context.evaluated_depsgraph_get())


# --- 1. a modifier edited after Set Up ------------------------------------------------------


def test_array_count_edited_after_setup_is_followed_and_rendered_where_seen(
    relativity_addon, factory_blender, tmp_path
):
    """Array count 2 -> 3 after Set Up: the cache follows (it used to keep 2 copies' points, so the
    modifier's count check left the mesh at rest, in the viewport and in F12, with no warning). Each
    small emissive cube is rendered at the retarded position of its centre (pixel centroids)."""
    bpy = factory_blender
    scene, camera = _scene(bpy, resolution=(96, 72))
    obj = _mover(bpy, scene, "Row", size=0.08, location=(1.2, -0.8, -6.0))
    obj.data.materials.append(gh.ch.emission_material(bpy, "Glow", 20.0))
    array = obj.modifiers.new("Array", "ARRAY")
    array.count, array.use_relative_offset, array.use_constant_offset = 2, False, True
    array.constant_offset_displace = (0.0, 0.8, 0.0)
    scene.relativity.method = "GEOMETRY"
    assert bpy.ops.relativity.setup_scene() == {"FINISHED"}
    array.count = 3  # the edit, after Set Up
    bpy.context.view_layer.update()  # the depsgraph handler syncs
    x_o = np.array(camera.matrix_world.translation)
    u = BETA * C
    centres = [np.array([1.2, -0.8 + 0.8 * i, -6.0]) for i in range(3)]
    expected_world = [_uniform_retarded(p, u, x_o) for p in centres]
    # the viewport: each cube's evaluated vertices centred on its retarded centre (contracted sides)
    x_a, _ = gh.evaluated_points(bpy, obj)
    assert len(x_a) == 24, len(x_a)
    for i, expected in enumerate(expected_world):
        centre = x_a[8 * i : 8 * i + 8].mean(axis=0)
        print(f"cube {i}: evaluated centre {centre.round(4)}, retarded {expected.round(4)}")
        assert np.linalg.norm(centre - expected) < 2e-3
    # F12: the render of the same state
    image = gh.ch.render_exr(bpy, scene, tmp_path / "array.exr")
    intensity = gh.ch.luminance(image)
    pinhole = gh.ch.pinhole_model(bpy, scene, camera)
    for i, expected in enumerate(expected_world):
        pixel = pinhole.project_direction(expected - x_o)
        rest_pixel = pinhole.project_direction(centres[i] - x_o)
        measured, total = gh.ch.centroid(intensity, pixel, 4)
        print(f"cube {i}: measured {measured}, expected {pixel.round(2)}, at rest {rest_pixel.round(2)}")
        assert total > 0.0 and np.linalg.norm(measured - pixel) < 0.6
        assert np.linalg.norm(rest_pixel - pixel) > 10.0  # the check tells the two apart
    assert not any("'Row'" in warning for warning in _warnings(scene)), _warnings(scene)
