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

A render's depsgraph is built from scratch and reports every object updated (F12 on 1,000 meshes
took every signature, clip-end depth and mesh note again); :func:`reported` leaves out of its
updates the applied meshes whose evaluated inputs there are the original's (the viewport's): see
:func:`_same_in_render`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, cast

import bpy

from ..common import names
from ..scene import animation
from . import modifier

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Object, Scene

# Scene name -> (scene key, frame, {object session_uid: whether its signature holds no frame}).
_current: dict[str, tuple[object, float, dict[int, bool]]] = {}
# Objects (session_uid) Blender evaluated again since the clip-end depth was last taken from them.
_moved: set[int] = set()
# Objects (session_uid) whose settings changed or whose cache an update wrote since a sync last
# took them (:func:`take_noted`: ``pipeline/settled.py``).
_noted: set[int] = set()


class _Updates:
    """A depsgraph's updates with some objects left out (what :func:`reported` hands on)."""

    def __init__(self, updates: list) -> None:
        self.updates = updates


def reported(depsgraph: Depsgraph) -> Depsgraph:
    """``depsgraph`` as a sync's note_updates should take it: without the applied meshes that
    :func:`_same_in_render` finds unchanged in a render's depsgraph, nor those a viewport's reports
    with neither their transform nor their geometry updated (shading alone: Blender tags every
    rendered object so after a render; none of the meshes' per-object work reads shading, and a
    setting's change is noted by its update callback, :func:`note_changed`)."""
    if depsgraph.mode == "RENDER":
        kept = [update for update in depsgraph.updates if not _same_in_render(update.id)]
    else:
        kept = [update for update in depsgraph.updates if not _shading_only(update)]
        if len(kept) == len(depsgraph.updates):
            return depsgraph
    return cast("Depsgraph", _Updates(kept))


def _shading_only(update: Any) -> bool:
    if update.is_updated_transform or update.is_updated_geometry:
        return False
    obj = update.id
    return isinstance(obj, bpy.types.Object) and modifier.find_modifier(obj.original or obj) is not None


def _same_in_render(evaluated: Any) -> bool:
    """Whether an object a render's fresh depsgraph reports has the inputs its original holds.

    Blender evaluates the viewport's depsgraph before a render starts (an edit made just before
    F12 is reported there), and the original holds that evaluation's results; the render's
    depsgraph then evaluates its frame's animation and drivers again, which may differ from the
    original (a keyed property changed since the last frame change, without a key): so the world
    matrix and every relativity setting are compared, evaluated against original. Only a mesh
    whose modifier stack is the add-on's modifier alone and whose mesh has no shape keys (nothing
    else the render evaluates differently from the viewport: render levels, shape key values)."""
    if not isinstance(evaluated, bpy.types.Object) or evaluated.type != "MESH":
        return False
    obj = evaluated.original
    if obj is None or obj is evaluated or len(obj.modifiers) != 1 or modifier.find_modifier(obj) is None:
        return False
    mesh = obj.data
    if mesh is None or mesh.shape_keys is not None:
        return False
    if [tuple(row) for row in evaluated.matrix_world] != [tuple(row) for row in obj.matrix_world]:
        return False
    return animation.settings_key(evaluated.relativity) == animation.settings_key(obj.relativity)


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
    _noted.add(uid)
    for _key, _frame, current in _current.values():
        current.pop(uid, None)


def noted() -> frozenset[int]:
    """The objects :func:`note_changed` named since :func:`take_noted` last took them (kept)."""
    return frozenset(_noted)


def take_noted() -> set[int]:
    """The objects (session_uid) :func:`note_changed` named since the last call; the set starts again."""
    taken = set(_noted)
    _noted.clear()
    return taken


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
