"""Observer velocity from the active camera's animation.

With ``scene.relativity.velocity_source == 'CAMERA_ANIMATION'`` the observer velocity is the time
derivative of the camera's world position, in scene time ``t = frame / fps`` (PHYSICS.md, units),
divided by the scene's speed of light:

    beta(f) = (x(f + h) - x(f - h)) / (2 h / fps) / c        (central difference, h = STEP_FRAMES)

The position is evaluated from the keyframes of the camera and its parents directly (F-curves at
fractional frames), never with ``frame_set``, so the result depends on the frame alone: a frame
rendered by itself in a fresh process gets the same velocity as in a sequence (farm-safe).
Constraints and drivers are not evaluated; a camera that depends on them is refused with a clear
message rather than given a wrong velocity.

Persistent ``frame_change_pre`` and ``render_pre`` handlers write the velocity into
``scene.relativity.beta`` (which re-syncs the relativistic camera through its update callback).
``check_animation_speed`` is run by the operator and the batch script before rendering: it reports
the first frame where the camera would move at or above c.
"""

import math

import bpy
from bpy.app.handlers import persistent
from mathutils import Euler, Matrix, Quaternion, Vector

from .camera import RelativityError

# Half-width of the central difference, in frames. Small enough to be the instantaneous velocity
# of smooth keyframe curves, large enough for float32 key values.
STEP_FRAMES = 1.0 / 64.0
# Sub-frame samples per frame used by ``check_animation_speed``.
CHECK_SAMPLES_PER_FRAME = 4


def frames_per_second(scene):
    return scene.render.fps / scene.render.fps_base


def _animated_values(obj, frame):
    """{(data_path, index): value} of the object's active-action F-curves at ``frame``."""
    animation_data = obj.animation_data
    if animation_data is None or animation_data.action is None:
        return {}
    from bpy_extras import anim_utils

    channelbag = anim_utils.animdata_get_channelbag_for_assigned_slot(animation_data)
    if channelbag is None:
        return {}
    return {
        (fcurve.data_path, fcurve.array_index): fcurve.evaluate(frame)
        for fcurve in channelbag.fcurves
        if not fcurve.mute
    }


def _vector(obj, values, path, size):
    current = getattr(obj, path)
    return [values.get((path, i), current[i]) for i in range(size)]


def _rotation_matrix(obj, values, prefix=""):
    mode = obj.rotation_mode
    if mode == "QUATERNION" or prefix:
        if prefix and mode not in ("QUATERNION", "AXIS_ANGLE"):
            euler = _vector(obj, values, prefix + "rotation_euler", 3)
            return Euler(euler, mode).to_matrix().to_4x4()
        quaternion = Quaternion(_vector(obj, values, prefix + "rotation_quaternion", 4))
        return quaternion.normalized().to_matrix().to_4x4()
    if mode == "AXIS_ANGLE":
        angle, x, y, z = _vector(obj, values, "rotation_axis_angle", 4)
        axis = Vector((x, y, z))
        if axis.length == 0.0:
            return Matrix.Identity(4)
        return Matrix.Rotation(angle, 4, axis.normalized())
    return Euler(_vector(obj, values, "rotation_euler", 3), mode).to_matrix().to_4x4()


def basis_matrix_at(obj, frame):
    """The object's ``matrix_basis`` at ``frame`` from its keyframes (deltas included)."""
    values = _animated_values(obj, frame)
    location = Vector(_vector(obj, values, "location", 3)) + Vector(_vector(obj, values, "delta_location", 3))
    scale = [a * b for a, b in zip(_vector(obj, values, "scale", 3), _vector(obj, values, "delta_scale", 3))]
    rotation = _rotation_matrix(obj, values, prefix="delta_") @ _rotation_matrix(obj, values)
    scale_matrix = Matrix.Diagonal((*scale, 1.0))
    return Matrix.Translation(location) @ rotation @ scale_matrix


def world_matrix_at(obj, frame):
    """``matrix_world`` at ``frame`` from keyframes alone (object parents; no constraints)."""
    matrix = basis_matrix_at(obj, frame)
    if obj.parent is not None:
        if obj.parent_type != "OBJECT":
            raise RelativityError(
                f"velocity from animation: {obj.name!r} has a {obj.parent_type.lower()} parent; "
                "only object parenting is supported"
            )
        matrix = world_matrix_at(obj.parent, frame) @ obj.matrix_parent_inverse @ matrix
    return matrix


def check_supported(obj):
    """Refuse set-ups whose motion the keyframe evaluation would get wrong."""
    while obj is not None:
        if any(constraint.enabled for constraint in obj.constraints):
            raise RelativityError(
                f"velocity from animation reads keyframes only, and {obj.name!r} has constraints; "
                "bake the camera motion to keyframes or set the velocity manually"
            )
        animation_data = obj.animation_data
        if animation_data is not None and (len(animation_data.drivers) or len(animation_data.nla_tracks)):
            raise RelativityError(
                f"velocity from animation reads the active action only, and {obj.name!r} has drivers "
                "or NLA tracks; bake the camera motion to keyframes"
            )
        obj = obj.parent


def _animated_camera(scene):
    camera_object = scene.camera
    if camera_object is None:
        raise RelativityError(f"scene {scene.name!r} has no active camera")
    check_supported(camera_object)
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
