"""A frame step of a mesh on straight keys, without its update (issue 26: 1,000 keyframed objects).

Where an object's keys draw one straight line over every retarded time its window reads, the
modifier computes the closed form of that line (``keyframed._uniform_over_window``); a frame step
then changes three of its inputs (the origin's offsets, ``motion.uniform_motion_inputs``, and the
edge check's ``Camera Offset``) and nothing else while the window stays on the line and the edges'
bound holds for the origin's new place. The full update (``apparent_meshes.update_object``: the
keys' line and window found again, the bound, some twenty inputs compared, the signature) cost
about a millisecond of Python per object and step; :func:`step` sets the three offsets and the
stored signature from what the last update kept (not while rendering: a render's update measures
no edge, and sets other inputs).

It steps only in a frame change's sync, and only while everything the update read is what it was:
the scene's inputs (``apparent_meshes.scene_key``: the observer, camera, speed of light, view, node
groups), the observer's time within the window's look-ahead (``keyframed._lines``), the origin on the
segment of the edges' swept bound (``tessellation.swept_bound``), the object's evaluated matrix on
the keys' line and its held rotation and scale (a script that moved it, a parent, a constraint or a
driver shows there), and its keys (``animation.keyframes_signature``, read once per sync and once for
a frame change's two syncs: a frame change reports every animated object and its Action, edited or
not, so Blender's report cannot tell an edit). Every full update forgets the object's record and
keeps a new one where it may.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..common import busy, names
from ..scene import animation
from . import keyframed, modifier, motion, tessellation

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Object

    from ..scene.snapshot import Snapshot

# Float32 keys and matrices: the evaluated place may sit this far (relative) off the float64 line.
ROUNDING = 4e-6

# Object session_uid -> (scene key, keys, line start, way per frame, held 3x3, fps, the observer's earliest
# and latest time, the signature after its frame and matrix).
_records: dict[int, tuple] = {}


def signature_head(frame: float | None, matrix: tuple) -> str:
    """The start of an object's signature (``apparent_meshes.object_signature`` writes its frame and
    evaluated world matrix first, with this): what a step writes anew."""
    return f"[{frame!r}, {matrix!r}, "


def remember(obj: Object, key: object, snap: Snapshot, signature: str, matrix: tuple) -> None:
    """Keep what a full update of ``obj`` found (``signature`` stored with ``matrix``, its evaluated
    world matrix) if it took the closed form of straight keys with its edges proven short over the
    way to come (``keyframed.steppable_line``)."""
    line = keyframed.steppable_line(obj)
    head = signature_head(snap.frame, matrix)
    keys = animation.keyframes_signature(obj)  # (None: keys with F-curve modifiers, not compared)
    if line is None or keys is None or not signature.startswith(head):
        return
    start, per_frame, shape, fps, t_low, t_high = line
    _records[obj.session_uid] = (key, keys, start, per_frame, shape, fps, t_low, t_high, signature[len(head) :])


def forget(obj: Object) -> None:
    _records.pop(obj.session_uid, None)


def step(obj: Object, key: object, snap: Snapshot, depsgraph: Depsgraph) -> bool:
    """Set the closed form's offsets of ``obj`` for the snapshot's frame from its record, and its
    signature; False (nothing written) where the record does not hold: the full update then."""
    record = _records.get(obj.session_uid)
    if record is None or record[0] != key or busy.rendering():  # (a render's update measures no edge)
        return False
    _key, keys, start, per_frame, shape, fps, t_low, t_high, tail = record
    t_o, x_o, beta_o = snap.mesh_observer
    if not t_low <= t_o <= t_high or animation.keyframes_signature(obj) != keys:
        return False
    obj_eval = obj.evaluated_get(depsgraph)
    matrix = motion.matrix_array(obj_eval.matrix_world)
    place = start + per_frame * snap.frame  # where the keys' line puts the origin at this frame
    scale = ROUNDING * (1.0 + float(np.abs(place).max()) + float(np.abs(shape).max()))
    if np.abs(matrix[:3, 3] - place).max() > scale or np.abs(matrix[:3, :3] - shape).max() > scale:
        return False
    origin = start + per_frame * (t_o * fps)  # as keyframed._uniform_over_window computes it
    swept = tessellation.swept_bound(obj)
    if swept is None or not tessellation.on_way(origin, *swept):
        return False
    c = snap.speed_of_light
    inputs = motion.uniform_motion_inputs(shape, origin, per_frame * fps / c, matrix, np.asarray(x_o), beta_o)
    data = modifier.cache_data(obj)
    mod = modifier.find_modifier(obj)
    if data is None or mod is None:
        return False
    offsets = {name: inputs[name] for name in ("Scene Offset", "Local Offset")}
    modifier.write_inputs(mod, {**offsets, "Camera Offset": tessellation.camera_offset(matrix, snap)})
    data[names.SIGNATURE_KEY] = signature_head(snap.frame, tuple(tuple(row) for row in obj_eval.matrix_world)) + tail
    tessellation.announce(obj)  # the next evaluation is the add-on's: the rest box stays
    obj.update_tag(refresh={"DATA"})  # the modifier's inputs: its geometry alone (the frame moved the rest)
    return True
