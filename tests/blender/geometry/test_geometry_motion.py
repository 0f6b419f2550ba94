"""Rigid ANIMATION objects seen at their retarded times when more than their own keyframes move
them: keyframed parents (with a parent inverse), delta transforms, and, through a motion bake,
constraints and other parent types.

Every check is on the evaluated mesh (depsgraph). For each vertex at apparent position x_a, seen by
a camera at rest at (t_o, x_o): t_e = t_o - |x_o - x_a| / c, and Blender's own evaluation of the
object at t_e (scene.frame_set at that sub-frame, matrix_world; independent of the add-on), with
the mesh as the rest shape contracted along the origin's velocity (docs/physics.md), must put the
vertex at x_a: |x_o - x_e(t_e)| = c (t_o - t_e) to 1e-6 relative.
"""

import importlib
import math

import numpy as np
import pytest

import geometry_helpers as gh
from relativity_addon.blender.common import compat

C = 10.0
FPS = 24
FRAME = 30


def _scene(bpy):
    return gh.slow_light_scene(bpy, C, FPS)


def _empty(bpy, scene, name):
    empty = bpy.data.objects.new(name, None)
    scene.collection.objects.link(empty)
    return empty


def _wheel(bpy, scene, radius=1.0, spokes=96):
    mesh = bpy.data.meshes.new("Wheel")
    angles = np.linspace(0.0, 2.0 * math.pi, spokes, endpoint=False)
    rim = [(radius * math.cos(a), radius * math.sin(a), 0.0) for a in angles]
    mesh.from_pydata(rim + [(0.0, 0.0, 0.0)], [], [(i, (i + 1) % spokes, spokes) for i in range(spokes)])
    wheel = bpy.data.objects.new("Wheel", mesh)
    scene.collection.objects.link(wheel)
    return wheel


def _box(bpy, location=(0.0, 0.0, -4.0), size=0.6):
    bpy.ops.mesh.primitive_cube_add(size=size, location=location)
    box = bpy.context.object
    box.name = "Box"
    return box


def _measure(bpy, scene, camera_object, obj, with_beta=False, remove=True):
    """(residual, mismatch, t_e, x_e[, beta seen, beta expected]) of the evaluated mesh at FRAME.
    With ``remove`` the effect is removed once the mesh is read, so the reference frame_set calls
    do not also recompute the apparent geometry at every sub-frame."""
    x_a, beta_seen = gh.evaluated_points(bpy, obj, "relativity_beta")
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    if remove:
        gh.remove_effect(scene)
    x_o = np.array(camera_object.matrix_world.translation)
    t_o = FRAME / FPS
    t_e = t_o - np.linalg.norm(x_a - x_o, axis=1) / C
    x_e = gh.world_lines_by_frame_set(bpy, scene, obj, rest, t_e, FPS, c=C)
    residual, mismatch = gh.retarded_residuals(x_a, x_e, x_o)
    print(
        f"{obj.name}: max light-cone residual {residual.max():.2e}, max position mismatch {mismatch.max():.2e}, "
        f"retarded frames {t_e.min() * FPS:.3f}..{t_e.max() * FPS:.3f}"
    )
    if not with_beta:
        return residual, mismatch, t_e, x_e
    dt = 2e-3
    velocity = (
        gh.world_lines_by_frame_set(bpy, scene, obj, rest, t_e + dt, FPS, c=C)
        - gh.world_lines_by_frame_set(bpy, scene, obj, rest, t_e - dt, FPS, c=C)
    ) / (2 * dt)
    return residual, mismatch, t_e, x_e, beta_seen, velocity / C


def test_spinning_wheel_on_a_moving_turning_car(relativity_addon, factory_blender):
    """The parent chain is evaluated at each vertex's retarded time, parent inverse included."""
    bpy = factory_blender
    scene, camera_object = _scene(bpy)
    car = _empty(bpy, scene, "Car")
    car.location = (-3.0, 0.0, -5.0)
    gh.keyframe_linear(car, "location", 0, [(0, -3.0), (FPS, -1.0)])  # 2 units/s = 0.2 c
    gh.keyframe_linear(car, "rotation_euler", 2, [(0, 0.0), (FPS, 0.4)])  # yaw 0.4 rad/s
    wheel = _wheel(bpy, scene)
    scene.frame_set(10)
    wheel.parent = car
    wheel.matrix_parent_inverse = car.matrix_world.inverted()  # what Ctrl+P does
    wheel.location = (-1.5, -0.6, -4.8)  # world position at frame 10, 0.9 from the car origin
    wheel.rotation_mode = "ZXY"  # spin about the axle (local Z) first, then tilt
    wheel.rotation_euler = (0.4, 0.0, 0.0)
    omega = 6.5  # rad/s: rim at 0.65 c about the hub; up to ~0.9 c in the world
    gh.keyframe_linear(wheel, "rotation_euler", 2, [(0, 0.0), (FPS, omega)])
    wheel.relativity.motion = "ANIMATION"
    wheel.relativity.use_proper_time = False  # Blender's own matrix_world at t_e (the clock: test_proper_time_*)
    wheel.relativity.tessellation = 0
    wheel.relativity.samples_per_frame = 32
    scene.frame_set(FRAME)
    gh.apply_geometry(scene)

    residual, mismatch, t_e, x_e, beta_seen, beta_true = _measure(bpy, scene, camera_object, wheel, with_beta=True)
    assert residual.max() < 1e-6
    assert mismatch.max() < 1e-6
    assert np.ptp(t_e[:96]) > 0.05  # the rim really spans different retarded times
    assert FRAME / FPS - t_e.max() > 0.3  # the car moved 0.6 units since the light left: the parent counts
    speeds = np.linalg.norm(beta_true[:96], axis=1)
    print(f"rim speeds {speeds.min():.3f}..{speeds.max():.3f} c, beta error {np.abs(beta_seen - beta_true).max():.1e}")
    assert 0.85 < speeds.max() < 0.95
    assert np.abs(beta_seen - beta_true).max() < 2e-3


def test_delta_transforms_count(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera_object = _scene(bpy)
    box = _box(bpy)
    box.rotation_mode = "YXZ"
    gh.keyframe_linear(box, "location", 0, [(0, -3.0), (48, 3.0)])  # 0.3 c along x
    gh.keyframe_linear(box, "delta_location", 1, [(0, -2.0), (48, 2.0)])  # keyed delta: 0.2 c along y
    gh.keyframe_linear(box, "delta_rotation_euler", 2, [(0, 0.0), (48, 6.0)])  # keyed delta spin 3 rad/s
    box.delta_rotation_euler[0] = 0.5
    box.delta_scale = (1.5, 1.0, 0.7)
    box.relativity.motion = "ANIMATION"
    box.relativity.use_proper_time = False  # Blender's own matrix_world at t_e
    box.relativity.tessellation = 1
    box.relativity.samples_per_frame = 16
    scene.frame_set(FRAME)
    gh.apply_geometry(scene)
    residual, mismatch, t_e, x_e = _measure(bpy, scene, camera_object, box)
    assert residual.max() < 1e-6
    assert mismatch.max() < 1e-6
    # The keyed delta alone moved the box ~0.8 units along y since the light left: deltas matter.
    assert (box.delta_location.y - (-2.0 + 4.0 * t_e * FPS / 48)).min() > 0.5


def test_keyframe_matrices_match_blender(relativity_addon, factory_blender):
    """animation.world_matrices (one vectorised call for many sub-frames) equals Blender's
    matrix_world: every rotation mode, keyed deltas, a three-level parent chain with a parent
    inverse, muted curves skipped (and, as in Blender 5.0, curves of a muted group still count)."""
    bpy = factory_blender
    animation = importlib.import_module(f"{relativity_addon}.blender.scene.animation")
    scene, _ = _scene(bpy)
    rng = np.random.default_rng(7)
    modes = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX", "QUATERNION", "AXIS_ANGLE")
    frames = np.array([0.5, 1.0, 3.25, 7.125, 12.5, 16.75, 18.0])
    worst = 0.0
    for start in range(0, len(modes), 3):
        chain = []
        for level in range(3):
            obj = _empty(bpy, scene, f"Level{start}{level}")
            obj.rotation_mode = modes[(start + level) % len(modes)]
            if chain:
                obj.parent = chain[-1]
                obj.matrix_parent_inverse = chain[-1].matrix_world.inverted()
            obj.delta_rotation_euler = rng.normal(size=3) * 0.3
            obj.delta_rotation_quaternion = rng.normal(size=4)
            obj.delta_scale = rng.uniform(0.5, 1.5, 3)
            rotation = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}.get(
                obj.rotation_mode, "rotation_euler"
            )
            for frame in (1, 7, 15):
                obj.location, obj.scale = rng.normal(size=3), rng.uniform(0.5, 2.0, 3)
                obj.delta_location = rng.normal(size=3)
                setattr(obj, rotation, rng.normal(size=len(getattr(obj, rotation))))
                for path in ("location", "scale", "delta_location", rotation):
                    obj.keyframe_insert(path, frame=frame, group="Moves" if path == "scale" else "")
            bag = compat.action_channelbag(obj.animation_data)
            bag.fcurves[1].mute = True  # location y: Blender ignores it, so must we
            bag.groups["Moves"].mute = level == 1
            chain.append(obj)
            bpy.context.view_layer.update()
        computed = animation.world_matrices(chain[-1], frames)
        for matrix, frame in zip(computed, frames, strict=True):
            scene.frame_set(math.floor(frame), subframe=frame - math.floor(frame))
            expected = np.array(chain[-1].matrix_world)
            worst = max(worst, np.abs(matrix - expected).max() / np.abs(expected).max())
    print(f"worst relative difference to matrix_world {worst:.1e}")
    assert worst < 1e-5  # float32 matrices in Blender


def test_constraint_needs_a_bake_then_matches_blender(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, camera_object = _scene(bpy)
    target = _empty(bpy, scene, "Target")
    target.location = (-4.0, 0.5, -4.0)
    gh.keyframe_linear(target, "location", 0, [(0, -4.0), (48, 4.0)])  # 4 units/s = 0.4 c
    box = _box(bpy)
    gh.keyframe_linear(box, "rotation_euler", 2, [(0, 0.0), (FPS, 2.0)])  # its own keyed spin
    box.relativity.motion = "ANIMATION"
    box.relativity.samples_per_frame = 16
    scene.relativity.method = "GEOMETRY"
    scene.frame_set(FRAME)
    gh.apply_geometry(scene)
    assert gh.geometry_module().scene_errors(scene) == []

    # The constraint arrives: the handler's update refuses it and the error reporting names the fix.
    constraint = box.constraints.new("COPY_LOCATION")
    constraint.target = target
    bpy.context.view_layer.update()
    errors = gh.geometry_module().scene_errors(scene)
    assert len(errors) == 1 and "'Box'" in errors[0] and "constraints" in errors[0] and "Bake Motion" in errors[0]
    log = gh.draw_object_panel(bpy, scene, box)
    assert ("operator", "relativity.bake_motion") in log and hasattr(bpy.ops.relativity, "bake_motion")
    assert any(entry[0] == "label" and entry[2] == "ERROR" and "Bake Motion" in entry[1] for entry in log)
    gh.remove_effect(scene)
    with pytest.raises(gh.geometry_module().RelativityError, match=r"'Box'.*constraints.*Bake Motion"):
        gh.apply_geometry(scene)
    assert gh.addon_module("geometry.modifier").find_modifier(box) is None

    # The operator bakes the scene's range, started earlier by the light-travel time.
    scene.frame_start, scene.frame_end = 20, FRAME
    bpy.context.view_layer.objects.active = box
    assert bpy.ops.relativity.bake_motion() == {"FINISHED"}
    assert (scene.frame_current, scene.frame_subframe) == (FRAME, 0.0)
    first, per_frame, matrices = gh.addon_module("geometry.modifier").motion_bake(box)
    assert per_frame == 16 and first < 20 - 2 * 4.0 / C * FPS and first + (len(matrices) - 1) / 16 == FRAME
    gh.apply_geometry(scene)
    assert gh.geometry_module().scene_errors(scene) == []
    log = gh.draw_object_panel(bpy, scene, box)
    assert any(entry[0] == "label" and entry[1].startswith("Motion baked") for entry in log)
    assert not any(entry[0] == "label" and entry[2] == "ERROR" for entry in log)

    residual, mismatch, t_e, x_e = _measure(bpy, scene, camera_object, box, remove=False)
    assert residual.max() < 1e-6
    assert mismatch.max() < 1e-6
    # Seen where the constraint had it ~10 frames ago, 1.6 units behind where it is now.
    assert box.matrix_world.translation.x - x_e[:, 0].mean() > 1.0

    # Edited motion after the bake is not rendered from the stale bake.
    gh.keyframe_linear(target, "location", 0, [(48, 8.0)])
    scene.frame_set(FRAME)
    errors = gh.geometry_module().scene_errors(scene)
    assert len(errors) == 1 and "motion bake" in errors[0] and "bake its motion again" in errors[0]


def test_non_object_parent_needs_a_bake(relativity_addon, factory_blender):
    bpy = factory_blender
    animation = importlib.import_module(f"{relativity_addon}.blender.scene.animation")
    scene, _ = _scene(bpy)
    anchor = _box(bpy, location=(0.0, 0.0, -6.0), size=2.0)
    anchor.name = "Anchor"
    gh.keyframe_linear(anchor, "location", 0, [(0, -1.0), (48, 1.0)])
    box = _box(bpy)
    box.parent = anchor
    box.parent_type = "VERTEX"
    box.parent_vertices[0] = 0
    box.relativity.motion = "ANIMATION"
    box.relativity.samples_per_frame = 4
    scene.frame_set(FRAME)
    with pytest.raises(animation.RelativityError, match="vertex parent"):
        animation.world_matrices(box, [FRAME])
    with pytest.raises(gh.geometry_module().RelativityError, match=r"'Box' has a vertex parent.*Bake Motion"):
        gh.apply_geometry(scene, [box])
    assert gh.addon_module("geometry.bakes").bake_motion(scene, box, 0, FRAME) == FRAME * 4 + 1
    gh.apply_geometry(scene, [box])
    assert gh.geometry_module().scene_errors(scene) == []


def test_what_keyframes_miss_is_named(relativity_addon, factory_blender):
    bpy = factory_blender
    animation = importlib.import_module(f"{relativity_addon}.blender.scene.animation")
    scene, _ = _scene(bpy)
    rig = _empty(bpy, scene, "Rig")
    box = _box(bpy)
    box.parent = rig
    gh.keyframe_linear(box, "location", 0, [(0, 0.0), (10, 1.0)])
    box["speed"] = 1.0
    box.driver_add('["speed"]')  # a driver that does not move the object
    assert animation.keyframe_motion_problem(box) is None
    driver = box.driver_add("scale", 1)
    assert animation.keyframe_motion_problem(box) == "'Box' has drivers on its transform"
    driver.mute = True
    assert animation.keyframe_motion_problem(box) is None
    rig.constraints.new("FOLLOW_PATH")
    assert animation.keyframe_motion_problem(box) == "'Rig' has constraints"
    rig.constraints[0].enabled = False
    rig.animation_data_create().nla_tracks.new()
    assert animation.keyframe_motion_problem(box) == "'Rig' has NLA tracks"
    scene.render.frame_map_new = 200  # keyframes no longer sit at the scene's frames
    assert animation.keyframe_motion_problem(box, scene) == f"scene {scene.name!r} remaps time (Time Stretching)"


def test_remove_takes_the_motion_bake_and_restores_the_file(relativity_addon, factory_blender, tmp_path):
    """The bake is saved with the .blend (a farm worker renders from the file alone) and leaves
    with the effect: the file is as before, bit for bit in what the effect may touch."""
    bpy = factory_blender
    scene, _ = _scene(bpy)
    target = _empty(bpy, scene, "Target")
    gh.keyframe_linear(target, "location", 0, [(0, -4.0), (48, 4.0)])
    box = _box(bpy)
    box.constraints.new("COPY_LOCATION").target = target
    box.relativity.motion = "ANIMATION"
    box.relativity.samples_per_frame = 4
    box.modifiers.new("Bevel", "BEVEL")
    scene.frame_set(FRAME)
    before = gh.file_fingerprint(bpy)

    gh.addon_module("geometry.bakes").bake_motion(scene, box, 0, FRAME)
    gh.apply_geometry(scene)
    assert gh.file_fingerprint(bpy) != before
    points, _ = gh.evaluated_points(bpy, box)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "baked.blend"))
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "baked.blend"))
    scene, box = bpy.context.scene, bpy.data.objects["Box"]
    assert gh.addon_module("geometry.modifier").motion_bake(box) is not None
    scene.frame_set(FRAME)
    reloaded, _ = gh.evaluated_points(bpy, box)
    assert np.allclose(reloaded, points, atol=1e-6)
    assert gh.geometry_module().scene_errors(scene) == []

    assert gh.remove_effect(scene) == 1
    assert gh.file_fingerprint(bpy) == before
    assert not any(gh.addon_module("common.names").MOTION_BAKE_KEY in mesh for mesh in bpy.data.meshes)
    assert not any(o.name.startswith("RelativityCache") for o in bpy.data.objects)
