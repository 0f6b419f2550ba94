"""Shape keys of a moving mesh at other times than the scene frame: its keyframed shape-key values
read at any (sub-)frame and blended as Blender does, so that ``world_lines`` can show each vertex
in the shape of its proper time at its retarded time.

Blender's relative blending (``BKE_key_evaluate_relative``): ``basis + sum value_k (key_k -
relative_key_k)`` over the unmuted keys, each value clamped to its slider range. Only the keys'
keyframes move (F-curves on ``key_blocks["..."].value``); a key without them keeps its value. The
blend works on the mesh's own vertices: the object's rest points must be exactly these (Tessellation
0, no modifier before the relativity one), which :meth:`ShapeKeyMotion.check` verifies against
what Blender evaluated at the scene frame, so a set-up it cannot reproduce raises RelativityError
instead of showing a wrong shape.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from ...errors import RelativityError
from ..common import compat
from . import modifier

if TYPE_CHECKING:
    import numpy.typing as npt
    from bpy.types import Object

    from ...physics.arrays import FloatArray

_VALUE_PATH = re.compile(r'^key_blocks\["(.+)"\]\.value$')
FRAME_SAMPLES_PER_FRAME = 16  # the values' table between the frames asked for (linear in between)


def _value_fcurves(key):
    """{key block name: F-curve} of the keyframed (unmuted, non-empty) values of a shape-key datablock."""
    animation_data = key.animation_data
    if animation_data is None or animation_data.action is None:
        return {}
    curves = {}
    for fcurve in compat.action_fcurves(animation_data):
        match = _VALUE_PATH.match(fcurve.data_path)
        if match and not fcurve.mute and (len(fcurve.keyframe_points) or len(fcurve.modifiers)):
            curves[match.group(1)] = fcurve
    return curves


def has_animated_shape_keys(obj: Object) -> bool:
    """Whether keyframes change the values of the mesh's shape keys (its own animation)."""
    key = getattr(obj.data, "shape_keys", None)
    return key is not None and bool(_value_fcurves(key))


def scene_time_reason(obj: Object) -> str | None:
    """Why ``obj``'s animated shape keys cannot be blended here at other times (one line), or None.
    The blend works on the mesh's own vertices with Blender's relative blending; otherwise the keys
    play at the scene's time (the shape Blender evaluated), which the object's warnings say."""
    if obj.relativity.tessellation > 0:
        return "Tessellation is above 0"
    modifiers = list(obj.modifiers)
    own = modifier.find_modifier(obj)
    before = [
        m
        for m in modifiers[: modifiers.index(own) if own is not None else len(modifiers)]
        if m.show_viewport or m.show_render
    ]
    if before:
        return f"modifier {before[0].name!r} comes before the relativity modifier"
    key = obj.data.shape_keys
    if not key.use_relative:
        return "its shape keys are absolute (Evaluation Time)"
    if key.animation_data is not None and any(
        _VALUE_PATH.match(driver.data_path) and not driver.mute for driver in key.animation_data.drivers
    ):
        return "drivers set its shape keys"
    for block in key.key_blocks:
        if block != key.reference_key and not block.mute and block.vertex_group:
            return f"shape key {block.name!r} has a vertex group"
    return None


def scene_time_warning(obj: Object) -> str | None:
    """The object's warning when its animated shape keys play at the scene's time although its own
    animation runs on its proper time, or None."""
    settings = obj.relativity
    if (
        not settings.use_proper_time
        or settings.motion == "STATIC"
        or settings.use_deformation
        or not has_animated_shape_keys(obj)
    ):
        return None
    reason = scene_time_reason(obj)
    if reason is None:
        return None
    return (
        f"Object {obj.name!r}: its shape keys play at the scene's time, not at its proper time ({reason}; "
        "Tessellation 0 with no modifier before the relativity one, or a deformation bake, plays them)"
    )


class ShapeKeyMotion:
    """The blended vertex positions of ``obj``'s mesh (object space, float64) at any frames."""

    def __init__(self, obj):
        key = obj.data.shape_keys
        self.name = obj.name
        if not key.use_relative:
            raise RelativityError(
                f"Object {obj.name!r}: absolute shape keys (Evaluation Time) are not played "
                "at proper time; use relative shape keys"
            )
        count = len(obj.data.vertices)

        def coordinates(block):
            values = np.empty(count * 3, dtype=np.float32)
            block.data.foreach_get("co", values)
            return values.reshape(count, 3).astype(np.float64)

        curves = _value_fcurves(key)
        if key.animation_data is not None and any(
            _VALUE_PATH.match(driver.data_path) and not driver.mute for driver in key.animation_data.drivers
        ):
            raise RelativityError(
                f"Object {obj.name!r}: drivers set its shape keys; driven shape keys are not "
                "played at proper time (turn Proper Time off, or bake the deformation)"
            )
        self.base = coordinates(key.reference_key)
        self.offsets, self.curves, self.limits, self.values = [], [], [], []
        for block in key.key_blocks:
            if block == key.reference_key or block.mute:
                continue
            if block.vertex_group:
                raise RelativityError(
                    f"Object {obj.name!r}: shape key {block.name!r} has a vertex group; "
                    "shape keys with vertex groups are not played at proper time"
                )
            self.offsets.append(coordinates(block) - coordinates(block.relative_key))
            self.curves.append(curves.get(block.name))
            self.limits.append((block.slider_min, block.slider_max))
            self.values.append(block.value)

    def values_at(self, frames: npt.ArrayLike) -> FloatArray:
        """Each key's value at ``frames`` (``(K,)``), shape ``(keys, K)``."""
        frames = np.atleast_1d(np.asarray(frames, dtype=np.float64))
        low, high = float(frames.min()), float(frames.max())
        table = np.linspace(low, high, int(min(100_000, max(2, np.ceil((high - low) * FRAME_SAMPLES_PER_FRAME) + 1))))
        rows = []
        for fcurve, (lowest, highest), value in zip(self.curves, self.limits, self.values, strict=True):
            if fcurve is None:
                rows.append(np.full(len(frames), value))
                continue
            if high == low:
                row = np.full(len(frames), fcurve.evaluate(low))
            else:
                row = np.interp(frames, table, np.fromiter((fcurve.evaluate(f) for f in table), np.float64, len(table)))
            rows.append(np.clip(row, lowest, highest))
        return np.array(rows).reshape(len(self.curves), len(frames))

    def positions(self, frames: npt.ArrayLike) -> FloatArray:
        """Blended positions ``(N, 3)``: vertex ``j`` at ``frames[j]`` (or all at one frame)."""
        frames = np.broadcast_to(np.asarray(frames, dtype=np.float64), (len(self.base),))
        values = self.values_at(frames)
        result = self.base.copy()
        for row, offset in zip(values, self.offsets, strict=True):
            result += row[:, None] * offset
        return result

    def check(self, rest: FloatArray, frame: float) -> None:
        """RelativityError unless ``rest`` (the rest points Blender evaluated at ``frame``) is this
        blend at ``frame``: the shape keys are then the only thing shaping the rest points."""
        if len(rest) != len(self.base):
            raise RelativityError(
                f"Object {self.name!r}: its animated shape keys are played at proper time only "
                "on the mesh's own vertices; set Tessellation to 0 and move modifiers after "
                "the relativity modifier, or bake the deformation (Animation, Deforming), "
                "or turn Proper Time off"
            )
        blend = self.positions(frame)
        scale = 1.0 + float(np.abs(blend).max(initial=0.0))
        if np.abs(blend - rest).max(initial=0.0) > 1e-5 * scale:
            raise RelativityError(
                f"Object {self.name!r}: something besides its shape keys (a modifier before the "
                "relativity modifier, a driver) shapes the mesh; its shape keys cannot be played at "
                "proper time (turn Proper Time off, or bake the deformation)"
            )
