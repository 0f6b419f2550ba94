"""A frame step of a mesh on straight keys, without its update (issue 26: 1,000 keyframed objects).

Where an object's keys draw one straight line over every retarded time its window reads, the
modifier computes the closed form of that line (``keyframed._uniform_over_window``); a frame step
then changes three of its inputs (the origin's offsets, ``uniform_motion.uniform_motion_inputs``, and the
edge check's ``Camera Offset``) and nothing else while the window stays on the line and the edges'
bound holds for the origin's new place. The full update (``apparent_meshes.update_object``: the
keys' line and window found again, the bound, some twenty inputs compared, the signature) cost
about a millisecond of Python per object and step; :func:`step` sets the three offsets and the
stored signature of every object whose record holds, from what the last update kept, with one
numpy pass over the objects (a pass per object cost about 90 us of small-array calls each, the
reads and writes 30 us); not while rendering: a render's update measures no edge, and sets other
inputs.

It steps only in a frame change's sync, and only while everything the update read is what it was:
the scene's inputs (``apparent_meshes.scene_key``: the observer, camera, speed of light, view, node
groups), the observer's time within the window's look-ahead (``keyframed._lines``), the origin on the
segment of the edges' swept bound (``edge_bounds.swept_bound``), the object's evaluated matrix on
the keys' line and its held rotation and scale (a script that moved it, a parent, a constraint or a
driver shows there), and its keys (``animation.keyframes_signature``, read once per sync and once for
a frame change's two syncs: a frame change reports every animated object and its Action, edited or
not, so Blender's report cannot tell an edit). Every full update forgets the object's record and
keeps a new one where it may.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

import bpy
import numpy as np

from ..common import busy, names
from ..scene import animation
from . import edge_bounds, keyframed, modifier, motion, tessellation, uniform_motion

if TYPE_CHECKING:
    from collections.abc import Iterable

    from bpy.types import Depsgraph, Object

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

# Float32 keys and matrices: the evaluated place may sit this far (relative) off the float64 line.
ROUNDING = 4e-6
# The three inputs a step writes, in this order (``uniform_motion.uniform_motion_inputs``' two offsets, the
# edge check's ``tessellation.camera_offset``).
OFFSETS = ("Scene Offset", "Local Offset", "Camera Offset")


class _Record(NamedTuple):
    """What a full update of an object on straight keys kept for its frame steps."""

    key: object  # the scene's inputs (``apparent_meshes.scene_key``)
    still: object  # the same but the observer's velocity (a turn keeps it)
    keys: int | None  # its keys (``animation.keyframes_hash``)
    start: FloatArray  # the keys' line: the origin at frame 0, world units
    per_frame: FloatArray  # its way per frame
    shape: FloatArray  # the 3x3 the keys hold (rotation and scale)
    fps: float
    t_low: float  # the observer's earliest and latest time (seconds) the window's look-ahead holds
    t_high: float
    tail: str  # the signature after its frame, matrix and the scene's parts
    held: FloatArray  # the evaluated 3x3 of the update
    inverse: FloatArray  # the offset maps N and N B (``uniform_motion.uniform_parts``)
    to_local: FloatArray
    w: FloatArray  # the keys' velocity, fraction of c
    scene: FloatArray  # the rest shape's 3x3 contracted along it (``Scene X/Y/Z``)
    # a closed-form object's (Static, Constant Velocity: ``remember_closed_form``) its settings read
    # (enabled, motion, velocity), else None; its line stands still (no way per frame: turns only)
    settings: tuple | None = None
    measured: bool = True  # whether its edges are checked (a turn then takes their bound again)


# Object session_uid -> its record.
_records: dict[int, _Record] = {}


def signature_head(frame: float | None, matrix: tuple) -> str:
    """The start of an object's signature (``apparent_meshes.object_signature`` writes its frame and
    evaluated world matrix first, with this): what a step writes anew."""
    return f"[{frame!r}, {matrix!r}, "


class Scene(NamedTuple):
    """What the records are compared with: the snapshot's ``apparent_meshes.scene_key``, the same
    without the observer's velocity, and the scene's parts of every signature (``_scene_parts``)."""

    key: object
    still: object
    seen_as: str


def remember(obj: Object, scene: Scene, snap: Snapshot, signature: str, matrix: tuple) -> None:
    """Keep what a full update of ``obj`` found (``signature`` stored with ``matrix``, its evaluated
    world matrix) if it took the closed form of straight keys with its edges proven short over the
    way to come (``keyframed.steppable_line``)."""
    line = keyframed.steppable_line(obj)
    head = signature_head(snap.frame, matrix) + scene.seen_as
    if line is None or not signature.startswith(head):
        return
    w = line[1] * line[3] / snap.speed_of_light  # the way per frame times fps, over c
    keys = animation.keyframes_hash(obj)
    _keep(obj, scene, snap, signature[len(head) :], np.array(matrix, dtype=np.float64), line, w, keys)


def remember_closed_form(
    obj: Object, scene: Scene, snap: Snapshot, signature: str, obj_eval: Object, measure: dict | None
) -> None:
    """Keep what a full update of a closed-form object (Static or Constant Velocity without an
    animation of its own: ``motion.closed_form``) found, for an observer's velocity change (its
    frame steps change none of its inputs): its origin stands where Blender draws it (``obj_eval``),
    with its velocity setting; kept where its edges are not checked (``measure`` None) or the bound
    proved them short, and not while rendering (its update sets other inputs)."""
    if busy.rendering() or (measure is not None and not measure["Edges Proven Short"]):
        return
    matrix = motion.matrix_array(obj_eval.matrix_world)
    head = signature_head(None, tuple(map(tuple, matrix.tolist()))) + scene.seen_as
    if obj.animation_data is not None or not signature.startswith(head):
        return
    settings = obj.relativity
    read = (settings.enabled, settings.motion, settings.beta[:])
    w = np.array(read[2] if read[1] == "CONSTANT" else (0.0, 0.0, 0.0), dtype=np.float64)
    line = (matrix[:3, 3].copy(), np.zeros(3), matrix[:3, :3].copy(), 1.0, -math.inf, math.inf)  # standing still
    _keep(obj, scene, snap, signature[len(head) :], matrix, line, w, None, read, measure is not None)


def _keep(obj, scene, snap, tail, matrix, line, w, keys, settings=None, measured=True):
    """Store ``obj``'s record: ``line`` (its start, way per frame, held 3x3, fps and the observer's
    times it holds for, as ``keyframed.steppable_line``), ``w`` its velocity, ``matrix`` its evaluated
    world matrix (4x4), ``tail`` its signature after the frame, matrix and scene's parts; the offset
    maps and the contracted shape as the full update's (``uniform_motion.uniform_parts``)."""
    start, per_frame, shape, fps, t_low, t_high = line
    inverse, to_local, fixed = uniform_motion.uniform_parts(shape, w, snap.mesh_observer[2], matrix)
    contracted = np.array([fixed["Scene X"], fixed["Scene Y"], fixed["Scene Z"]], dtype=np.float64).T
    held = matrix[:3, :3]
    _records[obj.session_uid] = _Record(
        scene.key,
        scene.still,
        keys,
        start,
        per_frame,
        shape,
        fps,
        t_low,
        t_high,
        tail,
        held,
        inverse,
        to_local,
        w,
        contracted,
        settings,
        measured,
    )


# Scene name -> its key (``apparent_meshes.scene_key``) at its last update.
_last_keys: dict[str, object] = {}


def turns(scene_name: str, key: object, stepping: bool) -> bool:
    """Whether an update outside a frame change (not ``stepping``) turns the records: the scene's key
    changed since its last update (every record of the last key was turned or gave way then)."""
    last, _last_keys[scene_name] = _last_keys.get(scene_name), key
    return not stepping and last != key


def forget(obj: Object) -> None:
    _records.pop(obj.session_uid, None)


def step(
    objects: Iterable[Object], scene: Scene, snap: Snapshot, depsgraph: Depsgraph, turning: bool = False
) -> set[int]:
    """Set the closed form's offsets of every object of ``objects`` whose record holds at the
    snapshot's frame, and its signature. Returns their session_uids (the others: a full update).

    ``turning`` (a sync that is not a frame change's): only the records of another observer's velocity
    are taken, their boost's inputs (``uniform_motion.OBSERVER_INPUTS``) set too and the edges' bound taken
    again over the way to come, for all of them at once (``edge_bounds.prove_over_ways``); a record
    of this velocity is current or needs its full update then."""
    if busy.rendering():  # (a render's update measures no edge)
        return set()
    t_o = snap.mesh_observer[0]
    found = []  # (object, record, evaluated world matrix, swept bound)
    for obj in objects:
        record = _records.get(obj.session_uid)
        if record is None or not record.t_low <= t_o <= record.t_high:
            continue
        if (record.key == scene.key) == turning or (turning and record.still != scene.still):
            continue
        if record.settings is not None:  # a closed-form object's: turns only, while its settings hold
            relativity = obj.relativity
            if not turning or obj.animation_data is not None:
                continue
            if (relativity.enabled, relativity.motion, relativity.beta[:]) != record.settings:
                continue
            swept = None
        else:
            swept = edge_bounds.swept_bound(obj)
            if swept is None or animation.keyframes_hash(obj) != record.keys:
                continue
        found.append((obj, record, tuple(tuple(row) for row in obj.evaluated_get(depsgraph).matrix_world), swept))
    if not found:
        return set()
    records, matrices = [item[1] for item in found], np.array([item[2] for item in found])
    turned = _turned(records, [item[0] for item in found], matrices, snap) if turning else None
    offsets = _offsets(records, matrices, [item[3] for item in found], snap, turned)
    stepped = set()
    for row, ((obj, record, matrix, _swept), values) in enumerate(zip(found, offsets, strict=True)):
        mod = modifier.find_modifier(obj) if values is not None else None
        data = modifier.cache_data(obj, mod) if mod is not None else None
        if mod is None or data is None or values is None:
            continue
        wanted = dict(zip(OFFSETS, values, strict=True))
        if turned is not None:
            wanted.update(zip(uniform_motion.OBSERVER_INPUTS, turned[1][row], strict=True))
            _records[obj.session_uid] = record._replace(key=scene.key, to_local=turned[0][row])
        modifier.write_inputs(mod, wanted)
        frame = snap.frame if record.settings is None else None  # (a closed form's depends on no frame)
        data[names.SIGNATURE_KEY] = signature_head(frame, matrix) + scene.seen_as + record.tail
        edge_bounds.announce(obj)  # the next evaluation is the add-on's: the rest box stays
        obj.update_tag(refresh={"DATA"})  # the modifier's inputs: its geometry alone (the frame moved the rest)
        stepped.add(obj.session_uid)
    return stepped


def _turned(records, objects, matrices, snap):
    """For an observer's velocity change: ``(N B per record, its OBSERVER_INPUTS as float32-rounded
    tuples per record (None where the edges' bound no longer clears its tolerance over the way to come)``,
    one numpy pass over the records (``uniform_motion.observer_parts``, ``edge_bounds.prove_over_ways``)."""
    beta_o = np.asarray(snap.mesh_observer[2], dtype=np.float64)
    inverse, w = np.array([r.inverse for r in records]), np.array([r.w for r in records])
    to_local, parts = uniform_motion.observer_parts(np.array([r.scene for r in records]), w, beta_o, inverse)
    # the bound at the origin's place now (the full update's _edge_bound: the matrix at the observer's time)
    at_t_o = matrices.copy()
    start, per_frame = np.array([r.start for r in records]), np.array([r.per_frame for r in records])
    fps = np.array([r.fps for r in records])
    at_t_o[:, :3, 3] = start + per_frame * (snap.mesh_observer[0] * fps)[:, None]
    scene = bpy.data.scenes.get(snap.scene)
    size = tessellation.render_size(scene) if scene is not None else (0.0, 0.0)
    measured = [row for row, r in enumerate(records) if r.measured]
    proven = np.ones(len(records), dtype=bool)  # (edges not checked: nothing to prove)
    proven[measured] = edge_bounds.prove_over_ways(
        [objects[row] for row in measured], at_t_o[measured], w[measured], per_frame[measured], snap, size
    )
    values = parts.transpose(1, 0, 2).astype(np.float32).astype(np.float64).tolist()
    return to_local, [tuple(map(tuple, rows)) if ok else None for rows, ok in zip(values, proven, strict=True)]


def _offsets(records, matrices, swept, snap, turned=None):
    """Per record: the three inputs (float32-rounded tuples, :data:`OFFSETS`) for the snapshot's
    frame, or None where its world matrix left the keys' line, its 3x3 the held one, or the origin
    the edges' swept bound (``turned``: the turn's, whose bound was taken at the origin now). One numpy
    pass over the objects, the full update's arithmetic."""
    t_o, x_o = snap.mesh_observer[0], np.asarray(snap.mesh_observer[1], dtype=np.float64)
    start, per_frame = np.array([r.start for r in records]), np.array([r.per_frame for r in records])
    shape, fps = np.array([r.shape for r in records]), np.array([r.fps for r in records])
    held, inverse = np.array([r.held for r in records]), np.array([r.inverse for r in records])
    to_local = np.array([r.to_local for r in records]) if turned is None else turned[0]
    translation = matrices[:, :3, 3]
    # where the keys' line puts the origin at this frame; the matrix on it, its 3x3 the held one
    place = start + per_frame * snap.frame
    scale = ROUNDING * (1.0 + np.abs(place).max(axis=1) + np.abs(shape).max(axis=(1, 2)))
    turn = matrices[:, :3, :3]
    ok = (np.abs(translation - place).max(axis=1) <= scale) & (np.abs(turn - shape).max(axis=(1, 2)) <= scale)
    ok &= (turn == held).all(axis=(1, 2))  # (the offset maps are the held matrix's)
    origin = start + per_frame * (t_o * fps)[:, None]  # as keyframed._uniform_over_window computes it
    if turned is None:
        ok &= edge_bounds.on_ways(origin, np.array([s[0] for s in swept]), np.array([s[1] for s in swept]))
    else:
        ok &= np.array([values is not None for values in turned[1]])
    offset = origin - x_o
    local = uniform_motion.uniform_local_offsets(offset, x_o, translation, inverse, to_local)
    camera = tessellation.camera_offsets(translation, snap)
    values = np.stack([offset, local, camera], axis=1).astype(np.float32).astype(np.float64).tolist()
    return [tuple(map(tuple, rows)) if good else None for rows, good in zip(values, ok.tolist(), strict=True)]
