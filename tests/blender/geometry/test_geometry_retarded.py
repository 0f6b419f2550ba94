"""Retarded positions on the evaluated mesh (depsgraph), not on the add-on's Python arrays.

For every vertex of the evaluated mesh at apparent position x_a, seen by a camera at rest at
(t_o, x_o): t_e = t_o - |x_o - x_a| / c, and the vertex's true world line evaluated at t_e
(analytically for the wheel, by Blender's own animation evaluation for the keyframed path, the
mesh being the rest shape contracted along its origin's velocity) must be x_a:
|x_o - x_e(t_e)| = c (t_o - t_e) to 1e-6 relative.
"""

import math

import numpy as np
import pytest

import geometry_helpers as gh

C = 10.0
FPS = 24


def _scene(bpy):
    return gh.slow_light_scene(bpy, C, FPS)


def _keyframe(obj, path, index, points, interpolation):
    for frame, value in points:
        obj.keyframe_insert(path, index=index, frame=frame)
        fcurve = _fcurve(obj, path, index)
        fcurve.keyframe_points[-1].co = (frame, value)
    fcurve = _fcurve(obj, path, index)
    for point in fcurve.keyframe_points:
        point.interpolation = interpolation
    fcurve.extrapolation = "LINEAR"
    fcurve.update()
    return fcurve


def _fcurve(obj, path, index):
    from bpy_extras import anim_utils

    animation = obj.animation_data
    bag = anim_utils.action_get_channelbag_for_slot(animation.action, animation.action_slot)
    return next(f for f in bag.fcurves if f.data_path == path and f.array_index == index)


def test_rotating_wheel_rim_at_0_9c(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera_object = _scene(bpy)
    radius = 1.0
    omega = 0.9 * C / radius
    mesh = bpy.data.meshes.new("Wheel")
    angles = np.linspace(0.0, 2.0 * math.pi, 96, endpoint=False)
    rim = [(radius * math.cos(a), radius * math.sin(a), 0.0) for a in angles]
    mesh.from_pydata(rim + [(0.0, 0.0, 0.0)], [], [(i, (i + 1) % 96, 96) for i in range(96)])
    wheel = bpy.data.objects.new("Wheel", mesh)
    wheel.location = (0.5, 0.0, -4.0)
    wheel.rotation_mode = "ZXY"  # spin about the axle (local Z) first, then tilt
    wheel.rotation_euler = (0.3, 0.0, 0.0)  # tilted towards the camera
    scene.collection.objects.link(wheel)
    # Angle omega * t: linear keys, linear extrapolation; the frame range covers every t_e.
    _keyframe(wheel, "rotation_euler", 2, [(0.0, 0.0), (FPS, omega)], "LINEAR")
    wheel.relativity.motion = "ANIMATION"
    wheel.relativity.tessellation = 0
    wheel.relativity.samples_per_frame = 32
    scene.frame_set(30)
    gh.apply_geometry(scene)
    x_a, beta_seen = gh.evaluated_points(bpy, wheel, "relativity_beta")
    rest = gh.evaluated_attribute(bpy, wheel, "relativity_rest")

    x_o = np.array(camera_object.matrix_world.translation)
    t_o = 30 / FPS
    tau = np.linalg.norm(x_a - x_o, axis=1) / C
    t_e = t_o - tau
    tilt = np.array([[1, 0, 0], [0, math.cos(0.3), -math.sin(0.3)], [0, math.sin(0.3), math.cos(0.3)]])
    a = omega * t_e
    spun = np.stack(
        [np.cos(a) * rest[:, 0] - np.sin(a) * rest[:, 1], np.sin(a) * rest[:, 0] + np.cos(a) * rest[:, 1], rest[:, 2]],
        axis=1,
    )
    x_e = spun @ tilt.T + np.array(wheel.location)
    residual = np.abs(np.linalg.norm(x_o - x_e, axis=1) - C * tau) / (C * tau)
    mismatch = np.linalg.norm(x_a - x_e, axis=1) / (C * tau)
    print(f"max light-cone residual {residual.max():.2e}, max position mismatch {mismatch.max():.2e}")
    assert residual.max() < 1e-6
    assert mismatch.max() < 1e-6
    # The evaluated rim really spans different retarded times (a rigid render would not).
    assert np.ptp(t_e[:96]) > 0.05
    # relativity_beta: omega x r at t_e, over c.
    omega_vector = tilt @ np.array([0.0, 0.0, omega])
    expected_beta = np.cross(omega_vector, x_e - np.array(wheel.location)) / C
    assert np.max(np.abs(beta_seen - expected_beta)) < 1e-3
    assert abs(np.linalg.norm(beta_seen[:96], axis=1).mean() - 0.9) < 1e-3


def test_accelerated_keyframed_path(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera_object = _scene(bpy)
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(0.0, 0.0, -3.0))
    box = bpy.context.object
    # Eased (Bezier) path along x: accelerates from rest, peak speed below c.
    _keyframe(box, "location", 0, [(0.0, -6.0), (48.0, 6.0)], "BEZIER")
    box.relativity.motion = "ANIMATION"
    box.relativity.tessellation = 1
    box.relativity.samples_per_frame = 16
    frame = 36
    scene.frame_set(frame)
    gh.apply_geometry(scene)
    x_a, _ = gh.evaluated_points(bpy, box)
    rest = gh.evaluated_attribute(bpy, box, "relativity_rest")
    x_o = np.array(camera_object.matrix_world.translation)
    tau = np.linalg.norm(x_a - x_o, axis=1) / C
    t_e = frame / FPS - tau
    fcurve = _fcurve(box, "location", 0)
    speeds = [abs(fcurve.evaluate(f + 0.01) - fcurve.evaluate(f - 0.01)) / (0.02 / FPS) for f in np.arange(0, 48, 0.5)]
    assert 0.5 * C < max(speeds) < C
    # Blender's own evaluation of the object at each vertex's retarded (sub-)frame, the mesh as the
    # rest shape contracted along the velocity the keys give there.
    x_e = gh.world_lines_by_frame_set(bpy, scene, box, rest, t_e, FPS, c=C)
    mismatch = np.linalg.norm(x_a - x_e, axis=1) / (C * tau)
    residual = np.abs(np.linalg.norm(x_o - x_e, axis=1) - C * tau) / (C * tau)
    print(
        f"max light-cone residual {residual.max():.2e}, max position mismatch {mismatch.max():.2e}, "
        f"retarded frames {t_e.min() * FPS:.2f}..{t_e.max() * FPS:.2f}"
    )
    assert residual.max() < 1e-6
    assert mismatch.max() < 1e-6
    assert np.ptp(t_e) * FPS > 0.5


def test_deforming_mesh_from_baked_evaluated_positions(relativity_addon, factory_blender):
    """Shape-key deformation (eased keys): each vertex is seen where Blender's own evaluation of the
    deformed mesh puts it at that vertex's retarded time."""
    bpy = factory_blender
    scene, camera_object = _scene(bpy)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.3, 0.2, -3.0))
    blob = bpy.context.object
    blob.shape_key_add(name="Basis")
    stretched = blob.shape_key_add(name="Stretch")
    for i, point in enumerate(stretched.data):
        point.co = point.co * 2.5
        point.co.x += i % 2
    stretched.value = 0.0
    stretched.keyframe_insert("value", frame=0)
    stretched.value = 1.0
    stretched.keyframe_insert("value", frame=24)
    blob.relativity.motion = "ANIMATION"
    blob.relativity.use_deformation = True
    blob.relativity.tessellation = 0
    blob.relativity.samples_per_frame = 16
    frame = 20
    scene.frame_set(frame)
    with pytest.raises(gh.geometry_module().RelativityError, match="not baked"):
        gh.apply_geometry(scene)
    assert gh.addon_module("geometry.modifier").find_modifier(blob) is None  # nothing applied
    blob.relativity.use_deformation = False
    gh.apply_geometry(scene)
    blob.relativity.use_deformation = True
    assert gh.addon_module("geometry.bakes").bake_deformation(scene, blob, 0, 24) == 24 * 16 + 1
    assert scene.frame_current == frame
    x_a, _ = gh.evaluated_points(bpy, blob)
    x_o = np.array(camera_object.matrix_world.translation)
    tau = np.linalg.norm(x_a - x_o, axis=1) / C
    t_e = frame / FPS - tau
    # Blender's own evaluation of the deformed mesh at each vertex's retarded (sub-)frame.
    x_e = np.empty_like(x_a)
    for i, t in enumerate(t_e):
        whole = math.floor(t * FPS)
        scene.frame_set(whole, subframe=t * FPS - whole)
        x_e[i] = gh.evaluated_attribute(bpy, blob, "relativity_rest")[i] + np.array(blob.location)
    mismatch = np.linalg.norm(x_a - x_e, axis=1) / (C * tau)
    print(
        f"deforming: max position mismatch {mismatch.max():.2e}, retarded frames "
        f"{t_e.min() * FPS:.2f}..{t_e.max() * FPS:.2f}"
    )
    assert mismatch.max() < 1e-6
    speeds = np.linalg.norm(x_e - _ev_points_at(bpy, scene, blob, t_e - 1e-3), axis=1) / 1e-3
    assert speeds.max() > 0.1 * C  # the deformation is fast enough to matter
    gh.remove_effect(scene)
    assert not any(mesh.name.startswith("RelativityBake") for mesh in bpy.data.meshes)


def _ev_points_at(bpy, scene, obj, times):
    out = np.empty((len(times), 3))
    for i, t in enumerate(times):
        whole = math.floor(t * FPS)
        scene.frame_set(whole, subframe=t * FPS - whole)
        out[i] = gh.evaluated_attribute(bpy, obj, "relativity_rest")[i] + np.array(obj.location)
    return out
