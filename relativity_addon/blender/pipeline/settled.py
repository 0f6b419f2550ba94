"""Whether a depsgraph update reports only what the scene's last full sync already took.

A setting's update callback syncs the scene (a full sync: every stage, the panel's records) and
writes the changed mesh's modifier inputs; Blender then evaluates, and ``depsgraph_update_post``
reports that object and its mesh updated. Synced in full again, that update would pass over every
object and stage to find nothing new: on 1,000 meshes, half of a velocity change's time (issue 26).

:func:`remember` keeps, after a full sync, the frame and a fingerprint of each applied mesh whose
settings changed or whose cache an update wrote since the sync before (``changes.take_noted``);
:func:`holds` is true when the next depsgraph update reports those objects (and their meshes) only,
at the same frame, each with the same fingerprint (its transform, settings, data, parent,
modifiers, materials: what the stages and the snapshot read of it), and nothing was noted since.
Then only what the evaluation itself changes is taken again: the reported meshes' signatures
(the modifier's verdicts), their clip-end depths, their caches' notes (``effect.sync``). Not kept
where a stage reads the evaluated meshes (moving lights' stand-ins are placed by ray casts, the
cockpit's objects by their bounds) or during a final render. Any other sync forgets it; a settled
update keeps it (:func:`renew`: what it took is still so).

A Constant Velocity changed in the panel on a mesh the record holds (:func:`velocity_holds`; a
slider dragged: the second change on) needs no full sync either: nothing but that object's velocity
changed since the record (its other settings, transform, data, modifiers and materials are its
fingerprint's, and nothing else was noted), and the depsgraph update after it reports anything
else that changed. ``effect.velocity_changed`` then writes that mesh, the stages and their
warnings from the last snapshot with the new fastest speed.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import bpy

from ..geometry import modifier
from ..scene import animation, snapshot

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Object, Scene

    from ..scene.snapshot import Snapshot

# At most this many objects' fingerprints are taken after a full sync (about 20 us each).
MOST_NOTED = 64
# Scene name -> (frame, subframe, {object session_uid: fingerprint}, how many objects the scene
# holds, its applied meshes) as its last full sync left them.
_settled: dict[str, tuple[int, float, dict[int, tuple], int, tuple[Object, ...]]] = {}


def _fingerprint(obj: Object) -> tuple:
    """(what the stages read of the object but its velocity, its settings but the velocity, the velocity)."""
    data = obj.data
    return (
        (
            tuple(tuple(row) for row in obj.matrix_world),
            data.name if data is not None else None,
            len(data.vertices) if data is not None else 0,
            obj.parent.name if obj.parent is not None else None,
            tuple((mod.name, mod.type, mod.show_viewport, mod.show_render) for mod in obj.modifiers),
            tuple(slot.material.name if slot.material is not None else None for slot in obj.material_slots),
        ),
        animation.settings_key(obj.relativity, leave_out=("beta",)),
        obj.relativity.beta[:],
    )


def forget(scene: Scene) -> None:
    _settled.pop(scene.name, None)
    _held.pop(scene.name, None)


# Scene name -> the record :func:`holds` last took (put back by :func:`renew`).
_held: dict[str, tuple] = {}


def renew(scene: Scene) -> None:
    """After a settled update: the record :func:`holds` took holds still (nothing but what it knew
    was reported, unchanged)."""
    known = _held.pop(scene.name, None)
    if known is not None:
        _settled[scene.name] = known


def remember(scene: Scene, snap: Snapshot, noted: set[int]) -> None:
    """After a full sync of ``scene`` (Apparent Geometry): what it took of the objects in ``noted``
    (``changes.take_noted`` over the sync)."""
    forget(scene)
    if snap.moving_lights or snap.cockpit or snapshot.in_final_render(scene):
        return
    if len(noted) > MOST_NOTED:
        return  # an observer's change moves every mesh: its full sync is small beside their updates
    listed = tuple(modifier.applied_objects(scene))
    applied = {obj.session_uid: obj for obj in listed}
    if not noted <= applied.keys():
        return  # a light, a deleted or another kind of object changed: the next update syncs in full
    prints = {uid: _fingerprint(applied[uid]) for uid in noted}
    _settled[scene.name] = (scene.frame_current, scene.frame_subframe, prints, len(scene.objects), listed)


def holds(scene: Scene, depsgraph: Depsgraph, noted: set[int]) -> tuple[Object, ...] | None:
    """The scene's applied meshes if ``depsgraph`` (a handler's, as ``changes.reported`` hands it
    on) reports only the objects the scene's last full sync took, unchanged since, and nothing was
    ``noted`` (changed through a setting, ``changes.take_noted``) since (see the module); else None.
    Used once."""
    known = _settled.pop(scene.name, None)
    _held.pop(scene.name, None)
    if (
        known is None
        or noted
        or (scene.frame_current, scene.frame_subframe, len(scene.objects)) != known[:2] + known[3:4]
    ):
        return None
    prints = known[2]
    objects: dict[int, Object] = {}
    meshes = set()
    for update in depsgraph.updates:
        block = update.id.original or update.id
        if isinstance(block, bpy.types.Object) and block.session_uid in prints:
            objects[block.session_uid] = block
        elif isinstance(block, bpy.types.Mesh):
            meshes.add(block.name)
        else:
            return None  # the scene, another object, a material, a camera ...: a full sync
    if not objects or not meshes <= {obj.data.name for obj in objects.values() if obj.data is not None}:
        return None
    if not all(_fingerprint(obj) == prints[uid] for uid, obj in objects.items()):
        return None
    _held[scene.name] = known
    return known[4]


def velocity_holds(scene: Scene, obj: Object, noted: frozenset[int]) -> tuple[Object, ...] | None:
    """The scene's applied meshes when the change ``noted`` (``changes.noted``: this object alone)
    is a Constant Velocity changed on an applied mesh the scene's record holds, moving before and
    after, below c, nothing else of it changed (see the module); else None. On None the record is
    forgotten (a full sync follows); else it holds the new velocity."""
    known = _settled.get(scene.name)
    _held.pop(scene.name, None)
    uid = obj.session_uid
    if (
        known is None
        or noted != {uid}
        or uid not in known[2]
        or (scene.frame_current, scene.frame_subframe, len(scene.objects)) != known[:2] + known[3:4]
    ):
        forget(scene)
        return None
    settings = obj.relativity
    before = known[2][uid]
    now = _fingerprint(obj)
    speed = math.hypot(*now[2])
    if (
        now[:2] != before[:2]
        or not (settings.enabled and settings.motion == "CONSTANT" and not settings.lights_scene)
        or not (any(before[2]) and any(now[2]))  # (a mover before and after: the checks' movers are the same)
        or not (math.isfinite(speed) and speed < 1.0)
    ):
        forget(scene)
        return None
    known[2][uid] = now
    return known[4]
