"""Motion from keyframes: world matrices of any object at many (sub-)frames, and the observer
velocity from the camera's animation.

:func:`world_matrices` evaluates the keyframes of an object and its object-parent chain (F-curves
at fractional frames, deltas included) in float64, never with ``frame_set``, so the result depends
on the frame alone: a frame rendered by itself in a fresh process gets the same motion as in a
sequence (farm-safe). Constraints, drivers, NLA and simulations are not evaluated:
:func:`keyframe_motion_problem` says when keyframes alone are not the motion (such objects need a
motion bake, and such a camera cannot give the velocity).

The observer velocity from the camera's animation (``snapshot.camera_beta_at``) differentiates
these matrices.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from mathutils import Matrix

from ...errors import RelativityError
from ...physics import transforms
from ..common import compat, once

if TYPE_CHECKING:
    from collections.abc import Iterable
    from contextlib import AbstractContextManager

    import numpy.typing as npt
    from bpy.types import FCurve, Object, Scene


def frames_per_second(scene: Scene) -> float:
    return scene.render.fps / scene.render.fps_base


# Properties of an object whose animation moves it (what the keyframe evaluation reads).
TRANSFORM_PATHS = frozenset(
    (
        "location",
        "rotation_euler",
        "rotation_quaternion",
        "rotation_axis_angle",
        "scale",
        "delta_location",
        "delta_rotation_euler",
        "delta_rotation_quaternion",
        "delta_scale",
    )
)
_SORTED_TRANSFORM_PATHS = tuple(sorted(TRANSFORM_PATHS))
# The channels that are an object's world line; the others (rotation, scale) are its own animation,
# which plays at its proper time (``world_lines``).
LOCATION_PATHS = frozenset(("location", "delta_location"))


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
        if fcurve.data_path in TRANSFORM_PATHS
        and not fcurve.mute
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


def basis_matrices(
    obj: Object, frames: npt.ArrayLike, own_frames: npt.ArrayLike | None = None
) -> npt.NDArray[np.float64]:
    """The object's ``matrix_basis`` at each of ``frames`` (float, sub-frames allowed) from its
    keyframes, deltas included, as float64 ``(K, 4, 4)`` (mathutils is float32). With
    ``own_frames`` (same shape), the rotation and scale channels (the object's own animation) are
    read there and the location channels (its world line) at ``frames``.

    Blender's composition (``BKE_object_to_mat4``): location + delta location, then
    R = R_delta @ R (Euler deltas in the object's Euler order, quaternion deltas for quaternions;
    axis-angle has no delta in the UI), then scale * delta scale."""
    frames = np.atleast_1d(np.asarray(frames, dtype=np.float64))
    own_frames = frames if own_frames is None else np.atleast_1d(np.asarray(own_frames, dtype=np.float64))
    curves = _transform_fcurves(obj)

    def channels(path, size):
        return _channels(obj, curves, path, size, frames if path in LOCATION_PATHS else own_frames)

    mode = obj.rotation_mode
    if mode == "QUATERNION":
        rotation = transforms.quaternion_matrices(
            channels("delta_rotation_quaternion", 4)
        ) @ transforms.quaternion_matrices(channels("rotation_quaternion", 4))
    elif mode == "AXIS_ANGLE":
        rotation = transforms.axis_angle_matrices(channels("rotation_axis_angle", 4))
    else:
        rotation = transforms.euler_matrices(channels("delta_rotation_euler", 3), mode) @ transforms.euler_matrices(
            channels("rotation_euler", 3), mode
        )
    return transforms.compose_basis_matrices(
        channels("location", 3) + channels("delta_location", 3),
        rotation,
        channels("scale", 3) * channels("delta_scale", 3),
    )


def world_matrices(
    obj: Object, frames: npt.ArrayLike, own_frames: npt.ArrayLike | None = None
) -> npt.NDArray[np.float64]:
    """``matrix_world`` at each of ``frames`` from keyframes alone, float64 ``(K, 4, 4)``: the
    object's basis under its object-parent chain evaluated at the same frames,
    ``parent_world @ matrix_parent_inverse @ basis`` (rotation and scale channels of every link at
    ``own_frames`` if given, see :func:`basis_matrices`). Constraints, drivers, NLA and simulations
    are not evaluated (see :func:`keyframe_motion_problem`); a bone, vertex or other non-object
    parent raises RelativityError."""
    matrices = basis_matrices(obj, frames, own_frames)
    parent = obj.parent
    if parent is None:
        return matrices
    if obj.parent_type != "OBJECT":
        raise RelativityError(
            f"{obj.name!r} has a {obj.parent_type.lower().replace('_', ' ')} parent; "
            "its motion from keyframes follows object parents only"
        )
    parent_inverse = np.array(obj.matrix_parent_inverse, dtype=np.float64)
    return world_matrices(parent, frames, own_frames) @ parent_inverse @ matrices


_signed = once.Once()  # object session_uid -> its keys' signature, ("hash", uid) -> its hash, inside signed_once()


def signed_once(kept: dict[object, object] | None = None) -> AbstractContextManager[None]:
    """Inside: :func:`keyframes_signature` reads each object's keys once (a sync edits no key; its
    stages asked up to three times per object: issue 26's 1,000 keyframed objects), into ``kept``
    when given (a frame change's two syncs share one: no script runs between them)."""
    return _signed.kept(kept)


def keyframes_signature(obj: Object) -> tuple[object, ...]:
    """Everything of the object's (and its parents') keyframes and transform that moves it, as a
    cache key: the F-curves' keys and their modifiers' settings (:func:`settings_key`). A channel
    an F-curve animates enters by its keys alone, not by its current value: that value changes at
    every frame step, which changes no key (the evaluation reads the keys, :func:`basis_matrices`)."""
    signatures = _signed.values()
    if signatures is None:
        return _keyframes_signature(obj)
    uid = obj.session_uid
    if uid not in signatures:
        signatures[uid] = _keyframes_signature(obj)
    return signatures[uid]


def keyframes_hash(obj: Object) -> int:
    """``hash(keyframes_signature(obj))``, taken once per object inside :func:`signed_once` (a deep
    tuple's hash is not kept by Python: the syncs' signatures and caches compare it for 1,000 objects)."""
    signatures = _signed.values()
    if signatures is None:
        return hash(_keyframes_signature(obj))
    key = ("hash", obj.session_uid)
    if key not in signatures:
        signatures[key] = hash(keyframes_signature(obj))
    return signatures[key]


def _keyframes_signature(obj):
    parts = []
    while obj is not None:
        animated = set()  # the live transform channels (_transform_fcurves), from the same pass
        animation_data = obj.animation_data
        if animation_data is not None and animation_data.action is not None:
            for fcurve in compat.action_fcurves(animation_data):
                path, index, mute = fcurve.data_path, fcurve.array_index, fcurve.mute
                modifiers = tuple(settings_key(modifier) for modifier in fcurve.modifiers)
                if path in TRANSFORM_PATHS and not mute and (len(fcurve.keyframe_points) or modifiers):
                    animated.add((path, index))
                parts.append(
                    (
                        path,
                        index,
                        mute,
                        fcurve.extrapolation,
                        modifiers,
                        tuple(
                            (
                                tuple(p.co),
                                tuple(p.handle_left),
                                tuple(p.handle_right),
                                p.interpolation,
                                p.easing,
                                p.back,
                                p.amplitude,
                                p.period,
                            )
                            for p in fcurve.keyframe_points
                        ),
                    )
                )
        paths = {path for path, _index in animated}
        parts.append(
            (
                tuple(map(tuple, obj.matrix_parent_inverse)),
                obj.rotation_mode,
                obj.parent_type,
                *(
                    tuple(None if (path, i) in animated else value for i, value in enumerate(getattr(obj, path)))
                    if path in paths
                    else tuple(getattr(obj, path))
                    for path in _SORTED_TRANSFORM_PATHS
                ),
            )
        )
        obj = obj.parent
    return tuple(parts)


def settings_key(struct: Any, leave_out: tuple[str, ...] = ()) -> tuple[object, ...]:
    """Every value of an RNA struct (an F-curve modifier, an object's relativity settings; the items
    of its collections, an envelope's control points, likewise; no pointers, nor the panel's state),
    arrays as tuples: what it holds, as a key (a curve with modifiers used to give no keys' signature,
    and the camera's proper time, kept under it, held its value when a modifier's settings were edited).
    ``leave_out``: settings of ``struct`` itself not in the key."""
    identifier = struct.bl_rna.identifier
    values: list[object] = [identifier]
    for name, kind in _key_fields(struct, identifier):
        if name in leave_out:
            continue
        value = getattr(struct, name)
        if kind == "COLLECTION":
            values.append(tuple(settings_key(item) for item in value))
        elif kind == "ARRAY":
            values.append(tuple(value))
        else:
            values.append(value)
    return tuple(values)


# RNA struct identifier -> (property name, "COLLECTION" / "ARRAY" / "VALUE") of what settings_key
# reads (walking ``bl_rna.properties`` took most of a key: 20 us for the relativity settings).
_fields: dict[tuple[str, int], tuple[tuple[str, str], ...]] = {}


def _key_fields(struct, identifier):
    properties = struct.bl_rna.properties
    key = (identifier, len(properties))  # (a struct registered again with other settings: read again)
    known = _fields.get(key)
    if known is None:
        known = _fields[key] = tuple(
            (
                prop.identifier,
                "COLLECTION" if prop.type == "COLLECTION" else "ARRAY" if getattr(prop, "is_array", False) else "VALUE",
            )
            for prop in properties
            if prop.identifier not in ("rna_type", "show_expanded", "active") and prop.type != "POINTER"
        )
    return known


def off_keys(obj: Object, frame: float) -> bool:
    """Whether a transform channel that a live F-curve of the object's action animates holds another
    value than that F-curve at ``frame``: changed in the panel or the viewport without a key
    (Blender keeps such a value until the frame changes; a render evaluates the keys again). False
    for an object with NLA tracks or drivers on its transform (its values are not its action's)."""
    animation_data = obj.animation_data
    if animation_data is None or len(animation_data.nla_tracks):
        return False
    if any(driver.data_path in TRANSFORM_PATHS and not driver.mute for driver in animation_data.drivers):
        return False
    for (path, index), fcurve in _transform_fcurves(obj).items():
        keyed = fcurve.evaluate(frame)
        if abs(getattr(obj, path)[index] - keyed) > 1e-5 * (1.0 + abs(keyed)):  # float32 values
            return True
    return False


def has_transform_keys(obj: Object) -> bool:
    """Whether live keyframes of the object's own action move, turn or scale it."""
    return bool(_transform_fcurves(obj))


def held_before_frame(obj: Object) -> float | None:
    """The frame before which the keyframes of the object and its object parents hold it still
    (the earliest first key of the transform curves that move, all extrapolated as constant), or
    None when a curve moves it before its first key (linear extrapolation, F-curve modifiers) or
    nothing moves it."""
    first = None
    while obj is not None:
        for fcurve in _transform_fcurves(obj).values():
            if len(fcurve.modifiers) or fcurve.extrapolation != "CONSTANT":
                return None
            values = {round(point.co[1], 12) for point in fcurve.keyframe_points}
            if len(values) > 1:
                start = min(point.co[0] for point in fcurve.keyframe_points)
                first = start if first is None else min(first, start)
        obj = obj.parent
    return first


def has_own_animation(obj: Object, scene: Scene | None = None) -> bool:
    """Whether keyframes turn or scale the object (or an object parent): its own animation, which a
    CONSTANT object plays at its proper time (``world_lines``). Objects whose keyframes are not
    their motion (:func:`keyframe_motion_problem`) are left as Blender shows them."""
    if keyframe_motion_problem(obj, scene) is not None:
        return False
    while obj is not None:
        if any(path not in LOCATION_PATHS for path, _ in _transform_fcurves(obj)):
            return True
        obj = obj.parent
    return False


EULER_PATHS = frozenset(("rotation_euler", "delta_rotation_euler"))
ROTATION_PREFIXES = ("rotation", "delta_rotation")  # the rotation channels of every mode


def fastest_key_rates(obj: Object) -> tuple[float, float] | None:
    """``(location speed, turn rate)`` per frame at most, that the object's own location and Euler
    rotation keys draw (scene units and radians per frame; each channel's steepest slope, its Bezier
    segments bounded by their control polygons, summed over the channels), or None where another
    channel turns it (quaternion, axis-angle) or an F-curve has modifiers: no bound read off the keys."""
    location, turn = np.zeros(3), 0.0
    for (path, index), fcurve in _transform_fcurves(obj).items():
        steepest = None if len(fcurve.modifiers) else _steepest(fcurve)
        if path in LOCATION_PATHS | EULER_PATHS and steepest is None:
            return None
        if path in LOCATION_PATHS:
            location[index] += steepest
        elif path in EULER_PATHS:
            turn += steepest
        elif path.startswith(ROTATION_PREFIXES):
            return None
    return float(np.linalg.norm(location)), turn


def keys_vary(obj: Object, prefixes: Iterable[str]) -> bool:
    """Whether a live channel of the object's own action whose path starts with one of ``prefixes``
    (:data:`ROTATION_PREFIXES`: any rotation mode; :data:`LOCATION_PATHS`) holds differing key values
    or handles, or has modifiers (its parents' keys are not read)."""
    prefixes = tuple(prefixes)
    for (path, _index), fcurve in _transform_fcurves(obj).items():
        if not path.startswith(prefixes):
            continue
        if len(fcurve.modifiers):
            return True
        points = fcurve.keyframe_points
        values = {float(v) for point in points for v in (point.co[1], point.handle_left[1], point.handle_right[1])}
        if len(values) > 1:
            return True
    return False


def _steepest(fcurve: FCurve) -> float | None:
    """The largest slope (value per frame) of an F-curve between its keys: a Bezier segment's
    derivative lies within its control polygon's slopes (the hodograph's convex hull); None where a
    segment eases otherwise (Sine, Elastic...: no bound kept here)."""
    points = sorted(fcurve.keyframe_points, key=lambda point: point.co[0])
    steepest = 0.0
    for left, right in zip(points, points[1:], strict=False):
        polygon = [left.co, right.co]
        if left.interpolation == "BEZIER":
            polygon = [left.co, left.handle_right, right.handle_left, right.co]
        elif left.interpolation == "CONSTANT":
            continue
        elif left.interpolation != "LINEAR":
            return None
        for a, b in zip(polygon, polygon[1:], strict=False):
            if b[0] - a[0] > 1e-9:
                steepest = max(steepest, abs(float(b[1]) - float(a[1])) / (float(b[0]) - float(a[0])))
    return steepest


def world_matrix_at(obj: Object, frame: float) -> Matrix:
    """``matrix_world`` at ``frame`` from keyframes alone (object parents; no constraints)."""
    return Matrix(world_matrices(obj, [frame])[0].tolist())


def keyframe_motion_problem(obj: Object, scene: Scene | None = None) -> str | None:
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


def check_supported(obj: Object, scene: Scene | None = None) -> None:
    """Refuse set-ups whose motion the keyframe evaluation would get wrong."""
    problem = keyframe_motion_problem(obj, scene)
    if problem is not None:
        raise RelativityError(
            f"Velocity from animation reads keyframes only, and {problem}; "
            "bake the camera motion to keyframes or set the velocity manually"
        )


def _straight_channel(fcurve: FCurve, low: float, high: float) -> tuple[float, float] | None:
    """``(value at frame 0, change per frame)`` of an F-curve that is a straight line from frame
    ``low`` to ``high`` (one value at every key and handle; one linear segment between two keys;
    before its first key or after its last with constant extrapolation), else None."""
    points = sorted(fcurve.keyframe_points, key=lambda point: point.co[0])
    if len(fcurve.modifiers) or not points:
        return None
    values = {value for point in points for value in (point.co[1], point.handle_left[1], point.handle_right[1])}
    if len(values) == 1:
        return float(points[0].co[1]), 0.0
    if fcurve.extrapolation == "CONSTANT" and (high <= points[0].co[0] or low >= points[-1].co[0]):
        return float((points[0] if high <= points[0].co[0] else points[-1]).co[1]), 0.0
    for left, right in zip(points, points[1:], strict=False):
        if left.co[0] <= low and high <= right.co[0]:
            if left.interpolation != "LINEAR":
                return None
            slope = (float(right.co[1]) - float(left.co[1])) / (float(right.co[0]) - float(left.co[0]))
            return float(left.co[1]) - slope * float(left.co[0]), slope
    return None


def _keyed_line(obj, channel):
    """``(translation at frame 0, its change per frame, the channels' lines)`` summed from what
    ``channel(fcurve)`` gives each transform F-curve (a tuple starting ``(value at frame 0, change per
    frame)``, or None), the channels no F-curve animates taken at the object's own values; None when
    the object has a parent, a channel gives None, or a channel other than a location changes."""
    if obj.parent is not None:
        return None
    curves = _transform_fcurves(obj)
    start, rate, lines = np.zeros(3), np.zeros(3), []
    for (path, index), fcurve in curves.items():
        line = channel(fcurve)
        if line is None or (path not in LOCATION_PATHS and line[1] != 0.0):
            return None
        lines.append(line)
        if path in LOCATION_PATHS:
            start[index] += line[0]
            rate[index] += line[1]
    for path in LOCATION_PATHS:  # the channels no F-curve animates: the object's own values
        for index in range(3):
            if (path, index) not in curves:
                start[index] += float(getattr(obj, path)[index])
    return start, rate, lines


def straight_keys(
    obj: Object, low: float, high: float
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]] | None:
    """``(translation at frame 0, its change per frame)`` of the object's world matrix when, from
    frame ``low`` to ``high``, its keyframes move it along a straight line at a constant rate and
    neither turn nor scale it (every location and delta location channel straight there, every
    other transform channel one value, no parent), else None. In float64 from the keys themselves:
    the line the keys draw, without the float32 rounding of Blender's evaluation
    (:func:`world_matrices`)."""
    found = _keyed_line(obj, lambda fcurve: _straight_channel(fcurve, low, high))
    return None if found is None else found[:2]


def _channel_span(fcurve: FCurve, frame: float) -> tuple[float, float, float, float] | None:
    """``(value at frame 0, change per frame, low, high)``: the line :func:`_straight_channel` gives
    for every range of positive length inside ``[low, high]`` (the frames around ``frame`` where the
    F-curve is that line), else None."""
    points = sorted(fcurve.keyframe_points, key=lambda point: point.co[0])
    if len(fcurve.modifiers) or not points:
        return None
    values = {value for point in points for value in (point.co[1], point.handle_left[1], point.handle_right[1])}
    if len(values) == 1:
        return float(points[0].co[1]), 0.0, -math.inf, math.inf
    if fcurve.extrapolation == "CONSTANT" and frame < points[0].co[0]:
        return float(points[0].co[1]), 0.0, -math.inf, float(points[0].co[0])
    if fcurve.extrapolation == "CONSTANT" and frame > points[-1].co[0]:
        return float(points[-1].co[1]), 0.0, float(points[-1].co[0]), math.inf
    for left, right in zip(points, points[1:], strict=False):
        if left.co[0] <= frame <= right.co[0] and left.co[0] < right.co[0]:
            if left.interpolation != "LINEAR":
                return None
            slope = (float(right.co[1]) - float(left.co[1])) / (float(right.co[0]) - float(left.co[0]))
            return float(left.co[1]) - slope * float(left.co[0]), slope, float(left.co[0]), float(right.co[0])
    return None


def straight_span(
    obj: Object, frame: float
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], float, float] | None:
    """``(translation at frame 0, its change per frame, low, high)``: what :func:`straight_keys` gives
    for every range of frames of positive length inside ``[low, high]`` (the frames around ``frame``
    over which the keys draw that one line), or None where it gives None around ``frame``. Read once,
    it answers :func:`straight_keys` for any window inside the span without reading a key (issue 26:
    a frame step of 1,000 keyframed objects)."""
    found = _keyed_line(obj, lambda fcurve: _channel_span(fcurve, frame))
    if found is None:
        return None
    start, rate, lines = found
    low = max((line[2] for line in lines), default=-math.inf)
    high = min((line[3] for line in lines), default=math.inf)
    return start, rate, low, high


def translates_only(obj: Object) -> bool:
    """Whether the object's keyframes only move it: no parent, no F-curve modifiers, every rotation
    and scale channel one value at every key and handle (the conditions of :func:`straight_keys`
    but the location channels' interpolation)."""
    if obj.parent is not None:
        return False
    for (path, _index), fcurve in _transform_fcurves(obj).items():
        if len(fcurve.modifiers):
            return False
        if path not in LOCATION_PATHS:
            points = fcurve.keyframe_points
            if len({value for p in points for value in (p.co[1], p.handle_left[1], p.handle_right[1])}) > 1:
                return False
    return True
