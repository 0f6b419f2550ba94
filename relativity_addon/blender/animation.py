"""Motion from keyframes: the observer velocity from the camera's animation, and world matrices of any
object at many (sub-)frames.

With ``scene.relativity.velocity_source == 'CAMERA_ANIMATION'`` the observer velocity is the time
derivative of the camera's world position, in scene time ``t = frame / fps`` (PHYSICS.md, units),
divided by the scene's speed of light:

    beta(f) = (x(f + h) - x(f - h)) / (2 h / fps) / c        (central difference, h = STEP_FRAMES)

The position is evaluated from the keyframes of the camera and its parents directly (F-curves at
fractional frames), never with ``frame_set``, so the result depends on the frame alone: a frame
rendered by itself in a fresh process gets the same velocity as in a sequence (farm-safe).
Constraints and drivers are not evaluated; a camera that depends on them is refused with a clear
message rather than given a wrong velocity.

:func:`world_matrices` is that evaluation, vectorised over many (sub-)frames in float64: the
apparent-geometry path samples keyframed objects with it at their retarded times, and
:func:`keyframe_motion_problem` says when keyframes alone are not the motion (constraints,
transform drivers, NLA, simulation, non-object parents: those objects need a baked motion).

Persistent ``frame_change_pre`` and ``render_pre`` handlers write the velocity into
``scene.relativity.beta`` (which re-syncs the relativistic camera through its update callback).
``check_animation_speed`` is run by the operator and the batch script before rendering: it reports
the first frame where the camera would move at or above c.
"""

import math

import bpy
import numpy as np
from bpy.app.handlers import persistent
from mathutils import Matrix

from . import compat
from .camera import RelativityError

# Half-width of the central difference, in frames. Small enough to be the instantaneous velocity
# of smooth keyframe curves, large enough for float32 key values.
STEP_FRAMES = 1.0 / 64.0
# Sub-frame samples per frame used by ``check_animation_speed``.
CHECK_SAMPLES_PER_FRAME = 4


def frames_per_second(scene):
    return scene.render.fps / scene.render.fps_base


# Properties of an object whose animation moves it (what the keyframe evaluation reads).
TRANSFORM_PATHS = frozenset((
    "location", "rotation_euler", "rotation_quaternion", "rotation_axis_angle", "scale",
    "delta_location", "delta_rotation_euler", "delta_rotation_quaternion", "delta_scale",
))


def _transform_fcurves(obj):
    """{(data_path, index): F-curve} of the live transform channels of the object's active action.

    Skipped like Blender's animation system skips them: muted curves and empty curves (no keys, no
    modifiers). Muting a channel group does not mute its curves' evaluation (Blender 5.0)."""
    animation_data = obj.animation_data
    if animation_data is None or animation_data.action is None:
        return {}
    return {
        (fcurve.data_path, fcurve.array_index): fcurve
        for fcurve in compat.action_fcurves(animation_data)
        if fcurve.data_path in TRANSFORM_PATHS and not fcurve.mute
        and (len(fcurve.keyframe_points) or len(fcurve.modifiers))
    }


def _channels(obj, curves, path, size, frames):
    """Values of ``obj.<path>`` at ``frames``, shape ``(K, size)``: F-curve or the static value."""
    current = getattr(obj, path)
    columns = []
    for index in range(size):
        fcurve = curves.get((path, index))
        if fcurve is None:
            columns.append(np.full(len(frames), float(current[index])))
        else:
            columns.append(np.fromiter((fcurve.evaluate(frame) for frame in frames), np.float64, len(frames)))
    return np.stack(columns, axis=1)


def _axis_rotations(axis, angles):
    c, s = np.cos(angles), np.sin(angles)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.zeros((len(angles), 3, 3))
    m[:, axis, axis] = 1.0
    m[:, i, i], m[:, i, j], m[:, j, i], m[:, j, j] = c, -s, s, c
    return m


def _euler_matrices(angles, mode):
    """Rotation matrices ``(K, 3, 3)`` of Euler angles in Blender's order ``mode`` ("XYZ": X
    applied first, R = Rz Ry Rx)."""
    rotation = np.broadcast_to(np.eye(3), (len(angles), 3, 3))
    for axis_name in mode:
        axis = "XYZ".index(axis_name)
        rotation = _axis_rotations(axis, angles[:, axis]) @ rotation
    return rotation


def _quaternion_matrices(q):
    """Rotation matrices of quaternions ``(K, 4)`` (w, x, y, z), normalised as Blender does: a
    zero quaternion becomes (0, 1, 0, 0)."""
    length = np.linalg.norm(q, axis=1, keepdims=True)
    q = np.where(length > 0.0, q / np.where(length > 0.0, length, 1.0), [0.0, 1.0, 0.0, 0.0])
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)


def _axis_angle_matrices(values):
    """Rotation matrices of (angle, axis x, y, z) rows; a zero axis is no rotation."""
    axis_length = np.linalg.norm(values[:, 1:], axis=1, keepdims=True)
    axis = values[:, 1:] / np.where(axis_length > 0.0, axis_length, 1.0)
    half = 0.5 * np.where(axis_length[:, 0] > 0.0, values[:, 0], 0.0)[:, None]
    return _quaternion_matrices(np.concatenate([np.cos(half), np.sin(half) * axis], axis=1))


def basis_matrices(obj, frames):
    """The object's ``matrix_basis`` at each of ``frames`` (float, sub-frames allowed) from its
    keyframes, deltas included, as float64 ``(K, 4, 4)`` (mathutils is float32).

    Blender's composition (``BKE_object_to_mat4``): location + delta location, then
    R = R_delta @ R (Euler deltas in the object's Euler order, quaternion deltas for quaternions;
    axis-angle has no delta in the UI), then scale * delta scale."""
    frames = np.atleast_1d(np.asarray(frames, dtype=np.float64))
    curves = _transform_fcurves(obj)

    def channels(path, size):
        return _channels(obj, curves, path, size, frames)

    mode = obj.rotation_mode
    if mode == "QUATERNION":
        rotation = _quaternion_matrices(channels("delta_rotation_quaternion", 4)) @ \
            _quaternion_matrices(channels("rotation_quaternion", 4))
    elif mode == "AXIS_ANGLE":
        rotation = _axis_angle_matrices(channels("rotation_axis_angle", 4))
    else:
        rotation = _euler_matrices(channels("delta_rotation_euler", 3), mode) @ \
            _euler_matrices(channels("rotation_euler", 3), mode)
    scale = channels("scale", 3) * channels("delta_scale", 3)
    matrices = np.zeros((len(frames), 4, 4))
    matrices[:, :3, :3] = rotation * scale[:, None, :]
    matrices[:, :3, 3] = channels("location", 3) + channels("delta_location", 3)
    matrices[:, 3, 3] = 1.0
    return matrices


def world_matrices(obj, frames):
    """``matrix_world`` at each of ``frames`` from keyframes alone, float64 ``(K, 4, 4)``: the
    object's basis under its object-parent chain evaluated at the same frames,
    ``parent_world @ matrix_parent_inverse @ basis``. Constraints, drivers, NLA and simulations
    are not evaluated (see :func:`keyframe_motion_problem`); a bone, vertex or other non-object
    parent raises RelativityError."""
    matrices = basis_matrices(obj, frames)
    parent = obj.parent
    if parent is None:
        return matrices
    if obj.parent_type != "OBJECT":
        raise RelativityError(
            f"{obj.name!r} has a {obj.parent_type.lower().replace('_', ' ')} parent; "
            "its motion from keyframes follows object parents only"
        )
    parent_inverse = np.array(obj.matrix_parent_inverse, dtype=np.float64)
    return world_matrices(parent, frames) @ parent_inverse @ matrices


def basis_matrix_at(obj, frame):
    """The object's ``matrix_basis`` at ``frame`` from its keyframes (deltas included)."""
    return Matrix(basis_matrices(obj, [frame])[0].tolist())


def world_matrix_at(obj, frame):
    """``matrix_world`` at ``frame`` from keyframes alone (object parents; no constraints)."""
    return Matrix(world_matrices(obj, [frame])[0].tolist())


def keyframe_motion_problem(obj, scene=None):
    """Why keyframes alone do not give the object's world matrix at other frames of ``scene`` (one
    line, naming the object or ancestor at fault), or None when :func:`world_matrices` is exact."""
    if scene is not None and scene.render.frame_map_old != scene.render.frame_map_new:
        return f"scene {scene.name!r} remaps time (Time Stretching)"
    while obj is not None:
        if any(constraint.enabled for constraint in obj.constraints):
            return f"{obj.name!r} has constraints"
        animation_data = obj.animation_data
        if animation_data is not None:
            if len(animation_data.nla_tracks):
                return f"{obj.name!r} has NLA tracks"
            if any(driver.data_path in TRANSFORM_PATHS and not driver.mute for driver in animation_data.drivers):
                return f"{obj.name!r} has drivers on its transform"
        if obj.rigid_body is not None:
            return f"{obj.name!r} is a rigid body (simulated)"
        parent = obj.parent
        if parent is not None:
            if obj.parent_type != "OBJECT":
                return f"{obj.name!r} has a {obj.parent_type.lower().replace('_', ' ')} parent"
            if parent.type == "CURVE" and getattr(parent.data, "use_path", False):
                return f"{obj.name!r} follows the path of curve {parent.name!r}"
        obj = parent
    return None


def check_supported(obj, scene=None):
    """Refuse set-ups whose motion the keyframe evaluation would get wrong."""
    problem = keyframe_motion_problem(obj, scene)
    if problem is not None:
        raise RelativityError(
            f"velocity from animation reads keyframes only, and {problem}; "
            "bake the camera motion to keyframes or set the velocity manually"
        )


def _animated_camera(scene):
    camera_object = scene.camera
    if camera_object is None:
        raise RelativityError(f"scene {scene.name!r} has no active camera")
    check_supported(camera_object, scene)
    return camera_object


def camera_beta_at(scene, frame, camera_object=None):
    """Observer velocity (world axes, fraction of c) of the camera at ``frame`` (float allowed)."""
    camera_object = camera_object or _animated_camera(scene)
    c = scene.relativity.speed_of_light
    if not (math.isfinite(c) and c > 0.0):
        raise RelativityError("speed of light must be a positive finite number")
    before = world_matrix_at(camera_object, frame - STEP_FRAMES).translation
    after = world_matrix_at(camera_object, frame + STEP_FRAMES).translation
    dt = 2.0 * STEP_FRAMES / frames_per_second(scene)
    return tuple((a - b) / dt / c for a, b in zip(after, before))


def current_frame(scene):
    return scene.frame_current + scene.frame_subframe


def check_animation_speed(scene, frame_start=None, frame_end=None):
    """Raise RelativityError naming the first frame where the camera moves at or above c.

    Samples every frame of [frame_start, frame_end] (default: the scene's frame range) and
    CHECK_SAMPLES_PER_FRAME - 1 sub-frames between frames. Returns the highest speed found.
    """
    camera_object = _animated_camera(scene)
    frame_start = scene.frame_start if frame_start is None else frame_start
    frame_end = scene.frame_end if frame_end is None else frame_end
    highest = 0.0
    steps = max(int(round((frame_end - frame_start) * CHECK_SAMPLES_PER_FRAME)), 0)
    for step in range(steps + 1):
        frame = frame_start + step / CHECK_SAMPLES_PER_FRAME
        beta = camera_beta_at(scene, frame, camera_object)
        speed = math.sqrt(sum(b * b for b in beta))
        if not math.isfinite(speed) or speed >= 1.0:
            where = f"frame {int(frame)}" if frame == int(frame) else f"frame {math.floor(frame)} (sub-frame {frame:g})"
            raise RelativityError(
                f"camera {camera_object.name!r} moves at {speed:.4g} c at {where}: "
                "its animation must stay below the speed of light (slow it down or raise c)"
            )
        highest = max(highest, speed)
    return highest


def sync_velocity_from_animation(scene):
    """Write the camera's velocity at the current frame into ``scene.relativity.beta``."""
    settings = scene.relativity
    if settings.velocity_source != "CAMERA_ANIMATION":
        return False
    beta = camera_beta_at(scene, current_frame(scene))
    if tuple(settings.beta) != tuple(float(b) for b in beta):
        settings.beta = beta
    return True


def sync_velocity_if_animated(scene):
    """Update-callback and handler entry point: never raises."""
    try:
        return sync_velocity_from_animation(scene)
    except RelativityError as error:
        print(f"Relativity: {error}")
        return False


@persistent
def _frame_change_pre(scene, _depsgraph=None):
    sync_velocity_if_animated(scene)


@persistent
def _render_pre(scene, _depsgraph=None):
    sync_velocity_if_animated(scene)


_HANDLERS = (("frame_change_pre", _frame_change_pre), ("render_pre", _render_pre))


def register():
    for name, handler in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler not in handlers:
            # Before the camera's render_pre re-sync, so the camera sees this frame's velocity.
            handlers.insert(0, handler)


def unregister():
    for name, handler in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
