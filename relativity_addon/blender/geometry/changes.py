"""Which applied meshes may have changed since a sync last found them up to date, so that a sync
builds the signature (``apparent_meshes.object_signature``) of those only, not of every mesh.

An object is *current* in a scene once a sync found its stored signature up to date, under the
scene's inputs of that sync (:func:`scene_key`'s value: the observer, the camera, the view, the
node group's generation; not the frame). It stays current until its settings change (the
update callback: :func:`note_changed`) or Blender reports an update of the object in any handler's
depsgraph (its transform, geometry or settings; a parent moved; at a frame
change, its keyframes or drivers: :func:`note_updates`), the scene key changes, or the frame
changes for an object whose positions depend on the frame itself (not the closed form). Objects
are known by ``session_uid`` (kept across renames, new for a file loaded again).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..common import names
from . import modifier

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Object, Scene

# Scene name -> (scene key, frame, {object session_uid: whether its signature holds no frame}).
_current: dict[str, tuple[object, float, dict[int, bool]]] = {}
# Objects (session_uid) Blender evaluated again since the clip-end depth was last taken from them.
_moved: set[int] = set()


def note_updates(depsgraph: Depsgraph) -> None:
    """Forget every object ``depsgraph`` reports updated (called by every sync that gets a
    handler's depsgraph, also while the add-on computes)."""
    # the updates hold evaluated copies, whose session_uid is 0: the original's
    updated = {
        (update.id.original or update.id).session_uid
        for update in depsgraph.updates
        if isinstance(update.id, bpy.types.Object)
    }
    if not updated:
        return
    _moved.update(updated)
    for _key, _frame, current in _current.values():
        for uid in updated:
            current.pop(uid, None)


def note_changed(uid: int) -> None:
    """An object's settings changed (its update callback runs before Blender tags the object)."""
    _moved.add(uid)
    for _key, _frame, current in _current.values():
        current.pop(uid, None)


def current_objects(scene_name: str, key: object, frame: float, frame_reported: bool) -> dict[int, bool]:
    """The objects (session_uid -> closed form) still current in the scene for ``key`` at ``frame``;
    the caller adds those it finds up to date. Another key: none. Another frame: the closed-form
    ones when ``frame_reported`` (``frame_change_post``, whose depsgraph reports what the frame
    moved), else none."""
    known = _current.get(scene_name)
    if known is None or known[0] != key:
        known = (key, frame, {})
    elif known[1] != frame:
        kept: dict[int, bool] = {uid: True for uid, closed in known[2].items() if closed} if frame_reported else {}
        known = (key, frame, kept)
    _current[scene_name] = known
    return known[2]


def is_current(scene_name: str, uid: int) -> bool:
    """Whether the object (session_uid) is current in the scene (:func:`current_objects`)."""
    known = _current.get(scene_name)
    return known is not None and uid in known[2]


def moved() -> set[int]:
    """The objects (session_uid) Blender evaluated again since the set was last cleared (the caller
    clears it once it has taken what it needs from every applied object)."""
    return _moved


# Object session_uid -> (error, warning) its cache held when last read (kept while it is current:
# only an update writes them, and an updated object is not current until its next sync).
_notes: dict[int, tuple[str | None, str | None]] = {}


def cache_notes(scene: Scene) -> list[tuple[Object, str | None, str | None]]:
    """(object, error or None, warning or None) of every applied object, read from the caches of
    those not current (``changes.is_current``)."""
    found = []
    for obj in modifier.applied_objects(scene):
        uid = obj.session_uid
        notes = _notes.get(uid)
        if notes is None or not is_current(scene.name, uid):
            data = modifier.cache_data(obj)
            notes = (None, None) if data is None else (data.get(names.ERROR_KEY) or None, data.get(names.WARNING_KEY))
            _notes[uid] = notes
        found.append((obj, *notes))
    return found
