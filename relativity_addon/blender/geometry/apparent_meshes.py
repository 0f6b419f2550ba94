"""Apparent geometry of moving objects: each mesh deformed to where the observer sees it.

For every mesh carrying the modifier (``modifier.py``), :func:`update_object` reads the
tessellated rest positions from the *evaluated* mesh (stored before the modifier sets positions,
so its output never feeds back), computes the apparent positions for the snapshot's observer
event with numpy (``world_lines.py``, ``physics/apparent.py``) and writes them, with each point's
velocity relative to the observer, into the cache mesh. ``effect.sync`` calls :func:`update` at
every frame change and whenever an input changed (observer velocity, c, camera or object
transform, object settings, the evaluated rest shape): the result depends only on the scene state
at the frame. Instancers of moving meshes are refused (:func:`check_instancing`).

Frames: the scene frame is the observer's frame only when the observer velocity is zero. The mesh
path renders in the camera's frame (axes parallel to world): an object at rest in the scene
appears moving with ``-beta``.

Errors are ``RelativityError`` with a one-line message; during handler updates they are kept on
the object's cache (:func:`scene_errors`) and the viewport keeps the last valid state.
"""

from __future__ import annotations

import zlib
from typing import TYPE_CHECKING

import bpy
import numpy as np

from ...errors import RelativityError
from ..common import busy, names
from ..scene import animation, snapshot
from . import changes, clip_end, edge_bounds, instancing, keyframed, modifier, motion, straight_steps, tessellation
from .modifier import applied_objects
from .uniform_motion import closed_form_inputs

if TYPE_CHECKING:
    from collections.abc import Iterable

    from bpy.types import Depsgraph, Object, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

# Points of a closed-form motion computed at a time: bounds the float64 temporaries, which for
# every point at once are several times the float32 positions the cache holds.
CHUNK_POINTS = 1 << 20


def rest_fingerprint(obj_eval: Object, values: FloatArray | None = None) -> tuple[int, int] | None:
    """``(point count, CRC-32)`` of the tessellated rest positions on the evaluated mesh, or None:
    an edit of the mesh or of a modifier (an Array's count or offset) changes it, which nothing
    else in the signature sees. One read of the attribute, no mesh copy; none with ``values``
    (the attribute's float32 values, read already)."""
    if values is None:
        attribute = obj_eval.data.attributes.get(names.REST_ATTRIBUTE) if obj_eval.type == "MESH" else None
        if attribute is None:
            return None
        values = np.empty(len(attribute.data) * 3, dtype=np.float32)
        attribute.data.foreach_get("vector", values)
    return len(values) // 3, zlib.crc32(np.ascontiguousarray(values, dtype=np.float32).data)


# Object name -> (evaluated mesh key, fingerprint, read number) of its rest positions as read
# since the depsgraph last evaluated its geometry (:func:`note_updates` forgets it then): an
# object Blender did not evaluate again has the same rest shape, and is not read again at every
# sync. The read number tells others (the lamp stage) that the geometry may have changed.
_known_rest = {}
_reads = [0]


def note_updates(depsgraph: Depsgraph) -> None:
    """Forget the rest fingerprints of the objects whose geometry ``depsgraph`` evaluated again
    (called by every sync that gets a handler's depsgraph, also while the add-on computes), and
    every object it reports updated is no longer current (``changes.py``)."""
    changes.note_updates(depsgraph)
    edge_bounds.note_updates(depsgraph)
    if not _known_rest:
        return
    for update in depsgraph.updates:
        if update.is_updated_geometry and isinstance(update.id, bpy.types.Object):
            _known_rest.pop(update.id.name, None)


def _evaluated_key(obj_eval):
    """The evaluated mesh's address and point count: a known fingerprint of another mesh (another
    file's object of the same name) is not taken."""
    return (obj_eval.data.as_pointer(), len(obj_eval.data.vertices)) if obj_eval.type == "MESH" else None


def _remember(obj_eval, fingerprint):
    _reads[0] += 1
    _known_rest[obj_eval.name] = (_evaluated_key(obj_eval), fingerprint, _reads[0])


def _note_unread(obj_eval):
    """Note an object whose rest shape the update does not read (a new read number, no fingerprint)
    unless it is noted already since Blender last evaluated its geometry."""
    known = _known_rest.get(obj_eval.name)
    if known is None or known[0] != _evaluated_key(obj_eval):
        _remember(obj_eval, None)


def _rest_fingerprint(obj_eval):
    """The object's rest fingerprint, read only when its geometry was evaluated since the last read."""
    known = _known_rest.get(obj_eval.name)
    if known is not None and known[0] == _evaluated_key(obj_eval):
        return known[1]
    fingerprint = rest_fingerprint(obj_eval)
    _remember(obj_eval, fingerprint)
    return fingerprint


def geometry_key(obj: Object) -> tuple | None:
    """A key that stays the same while Blender has not evaluated the geometry of ``obj`` again
    since the add-on last read it (its mesh, that read), or None (unknown: it may have changed).
    Reads nothing: what the lamp stage computes from the mesh is kept under it."""
    known = _known_rest.get(obj.name)
    if known is None or obj.type != "MESH":
        return None
    return obj.data.name, obj.data.as_pointer(), len(obj.data.vertices), known[2]


def object_signature(
    snap: Snapshot,
    obj: Object,
    depsgraph: Depsgraph | None = None,
    fingerprint: tuple[int, int] | None = None,
    expected: tuple[bool | None, bool | None] = (None, None),
) -> str:
    """Everything the object's apparent positions depend on, as a string stored with its cache
    (the evaluated rest shape too, given the update's ``depsgraph``, or its ``fingerprint``).
    ``expected``: the verdicts (edges short, window found) the update expects, in place of those of
    an evaluation that made none (None: the evaluation's); an evaluation confirming them changes nothing."""
    relativity = obj.relativity
    evaluated = obj.evaluated_get(depsgraph) if depsgraph is not None else obj
    verdict: object = None
    closed = False
    if depsgraph is not None:
        scene = bpy.data.scenes.get(snap.scene)
        closed = scene is not None and motion.closed_form(obj, scene)
        mod = modifier.find_modifier(obj)
        # keyframed motion in the modifier (or, uniform over its window, the closed form: keyframed.py)
        keyframed_on = not closed and mod is not None and modifier.closed_form_on(mod)
        measured = bool(relativity.use_adaptive_tessellation and relativity.tessellation > 0)
        short = tessellation.edges_short(evaluated) if (closed or keyframed_on) and measured else None
        short = expected[0] if expected[0] is not None and measured else short
        # and, for keyframed motion, whether every retarded time lay inside the modifier's intervals
        window = keyframed.window_found(evaluated) if expected[1] is None else expected[1]
        verdict = (short, window) if keyframed_on else short
        if fingerprint is None and (closed or keyframed_on) and (not measured or short):
            # the modifier computes the positions from the rest shape, and no decision reads it:
            # only noted, so that geometry_key stays while Blender does not evaluate it again
            _note_unread(evaluated)
        elif fingerprint is None:
            fingerprint = _rest_fingerprint(evaluated)
    frame = None if closed else snap.frame  # the closed form depends on the observer's event, not on the time
    parts = [  # after the frame, the matrix (straight_steps.step writes them anew) and the scene's parts
        relativity.enabled,
        relativity.motion,
        tuple(relativity.beta),
        relativity.tessellation,
        (relativity.use_adaptive_tessellation, relativity.tessellation_tolerance, snap.projection)
        if relativity.use_adaptive_tessellation
        else None,
        _render_size(snap) if relativity.use_adaptive_tessellation else None,
        relativity.samples_per_frame,
        # the keys: an edit leaving the current frame's place changes the past the window reads (also the
        # own rotation keys of a Constant Velocity mesh: its spin at the retarded times)
        animation.keyframes_hash(obj) if obj.animation_data is not None else None,
        snap.fps,
        relativity.use_deformation,
        relativity.use_proper_time,
        len(obj.data.vertices),
        fingerprint,
        verdict,
    ]
    head = straight_steps.signature_head(frame, tuple(map(tuple, evaluated.matrix_world)))
    return f"{head}{_scene_parts(snap)}, {repr(parts)[1:]}"


def _render_size(snap: Snapshot) -> tuple[float, float] | None:
    scene = bpy.data.scenes.get(snap.scene)
    return tessellation.render_size(scene) if scene is not None else None


# Objects whose new subdivision's positions wait for a sync outside ``frame_change_post``.
_deferred: set[str] = set()


def deferred() -> bool:
    """Whether some object's update waits for a sync outside a frame change (:func:`update_object`)."""
    return bool(_deferred)


def update_object(
    scene: Scene,
    obj: Object,
    snap: Snapshot,
    depsgraph: Depsgraph | None = None,
    in_frame_change: bool = False,
    check_first: bool = False,
) -> int:
    """Recompute the cache of one object for the snapshot's frame. Raises RelativityError.

    ``in_frame_change`` (``frame_change_post``): Blender 4.5 crashed evaluating the depsgraph
    again there after the tessellation changed (a segmentation fault at frame 10 of the street
    fly-through), so then a closed-form object keeps the handler's depsgraph (its inputs do not
    read the new subdivision; the next sync finds the check's new verdict) and another object's
    positions wait for the next sync (:func:`deferred`): the handlers and the batch script sync
    again outside the frame change."""
    _deferred.discard(obj.name)
    straight_steps.forget(obj)
    changes.note_changed(obj.session_uid)  # its cache is written: read again until a sync finds it current
    mod, cache = modifier.ensure_modifier(obj)
    checked = keyframed.verdicts_made(mod)  # none yet at Set Up: the update then expects its own
    if depsgraph is None:
        depsgraph = bpy.context.evaluated_depsgraph_get()
    obj_eval = obj.evaluated_get(depsgraph)
    closed = motion.closed_form(obj, scene)
    in_modifier = closed or keyframed.can_show(obj, scene)
    measure = tessellation.edge_measure_inputs(scene, obj, obj_eval, snap) if in_modifier else None
    try:
        unchecked = check_first and not checked[0]  # Set Up: the modifier's check first (apply)
        if measure is not None and (measure["Edges Proven Short"] or tessellation.edges_short(obj_eval) or unchecked):
            # the bound shows every edge's image short, or the modifier found them so at its last
            # evaluation and left the mesh whole; it checks again at the next (a longer edge shows
            # in the signature: decided then)
            decision: tessellation.Decision | None = tessellation.Decision(0, warning="")
        else:
            decision = tessellation.decide(scene, obj, obj_eval, snap)
        if decision is not None and tessellation.apply(obj, mod, cache, decision):
            if in_frame_change and not in_modifier:
                _deferred.add(obj.name)
                cache.data[names.SIGNATURE_KEY] = ""  # computed at the next sync
                return 0
            if not in_frame_change and not closed:  # a closed-form object reads no rest position
                depsgraph = bpy.context.evaluated_depsgraph_get()  # (4.5 crashed: docs/performance.md)
    except ValueError as error:  # the physics core's checks (superluminal motion, NaN)
        raise RelativityError(f"Object {obj.name!r}: {error}") from None
    codes = tessellation.face_codes(cache, mod) if decision is None else decision.codes
    agrees = decision is not None and decision.level == 0 and decision.codes is None  # the check's verdict then
    short = None if checked[0] or measure is None or decision is None else agrees
    if closed:
        return _update_closed_form(scene, obj, snap, depsgraph, mod, cache, codes, measure, short)
    obj_eval = obj.evaluated_get(depsgraph)
    if in_modifier and keyframed.update(obj, depsgraph, snap, scene, mod, cache, codes, measure):
        expected = (short, None if checked[1] or not keyframed.is_on(mod) else True)  # the window holds its bound
        signature = cache.data[names.SIGNATURE_KEY] = object_signature(snap, obj, depsgraph, expected=expected)
        straight_steps.remember(obj, steps_scene(snap), snap, signature, tuple(map(tuple, obj_eval.matrix_world)))
        for key in (names.ERROR_KEY, names.WARNING_KEY):
            if key in cache.data:
                del cache.data[key]
        obj.update_tag()
        return len(obj_eval.data.vertices)
    if measure is not None and unchecked:  # on the Python path: no check, decided after an evaluation
        _deferred.add(obj.name)
        cache.data[names.SIGNATURE_KEY] = ""
        return 0
    changed = modifier.set_closed_form(mod, None)
    changed |= modifier.set_inputs(mod, {"Measure Edges": False, "Keyframed": False})
    if changed:  # the rest positions are stored before the closed form: they are current
        obj.update_tag()
    rest32 = modifier.evaluated_rest_positions(obj, depsgraph, dtype=np.float32)
    if rest32 is None:
        raise RelativityError(f"Object {obj.name!r}: evaluated mesh has no {names.REST_ATTRIBUTE!r} attribute")
    obj_eval = obj.evaluated_get(depsgraph)
    fingerprint = rest_fingerprint(obj_eval, rest32.reshape(-1))
    keyframed.note_rest(cache.data, rest32)
    _remember(obj_eval, fingerprint)
    measured = decision.vertices if decision is not None and decision.codes is None else None
    computed = measured[1:] if measured is not None and np.array_equal(measured[0], rest32) else None
    local, beta_seen, delay, depth = _apparent_local(scene, obj, obj_eval, rest32, snap, computed)
    warning = motion.keyframes_start_warning(obj, scene, snap.mesh_observer[0] - delay)
    modifier.write_cache(cache.data, local, beta_seen, codes)
    cache.data[names.DEPTH_KEY] = depth
    clip_end.note_depth(obj, snap, depth)
    cache.data[names.SIGNATURE_KEY] = object_signature(snap, obj, depsgraph, fingerprint)
    if names.ERROR_KEY in cache.data:
        del cache.data[names.ERROR_KEY]
    if warning is not None:
        cache.data[names.WARNING_KEY] = warning
    elif names.WARNING_KEY in cache.data:
        del cache.data[names.WARNING_KEY]
    obj.update_tag()
    return len(local)


def _update_closed_form(scene, obj, snap, depsgraph, mod, cache, codes, measure, short):
    """:func:`update_object` of a closed-form object (``motion.closed_form``): the modifier
    computes the positions and the velocity attribute; this sets its inputs (a few vectors), and
    reads and writes no vertex. The farthest seen depth comes from the evaluated bounds
    (:func:`clip_end_warnings`)."""
    obj_eval = obj.evaluated_get(depsgraph)
    try:
        inputs = closed_form_inputs(obj, obj_eval, snap)
    except ValueError as error:  # the physics core's checks
        raise RelativityError(f"Object {obj.name!r}: {error}") from None
    changed = modifier.set_closed_form(mod, inputs)
    changed |= modifier.set_inputs(mod, {"Keyframed": False, "Measure Edges": measure is not None, **(measure or {})})
    points = 0 if codes is None else len(codes)
    if len(cache.data.vertices) != points:  # positions of an update on the cache's path
        modifier.write_cache(cache.data, np.zeros((0, 3)), np.zeros((1, 3)), codes)
        changed = True
    signature = cache.data[names.SIGNATURE_KEY] = object_signature(snap, obj, depsgraph, expected=(short, None))
    straight_steps.remember_closed_form(obj, steps_scene(snap), snap, signature, obj_eval, measure)
    for key in (names.ERROR_KEY, names.WARNING_KEY):
        if key in cache.data:
            del cache.data[key]
    if changed:
        edge_bounds.announce(obj)
        obj.update_tag()
    return len(obj_eval.data.vertices)


def _apparent_local(scene, obj, obj_eval, rest32, snap, computed=None):
    """``(object-space apparent positions (N, 3) float32, velocities seen, the largest light
    delay, the farthest seen depth)`` of the rest positions ``rest32``; ``computed``: the
    ``(world positions, delays, velocities)`` the tessellation measure already found for these
    points. The closed form (``motion.closed_form``) goes CHUNK_POINTS at a time: each point
    depends on its own rest position only, and a part's float64 temporaries are what the peak
    memory holds."""
    inverse = motion.affine_inverse(motion.matrix_array(obj_eval.matrix_world))
    whole = computed is not None or not motion.closed_form(obj, scene)
    step = max(len(rest32), 1) if whole else CHUNK_POINTS
    local = np.empty(rest32.shape, dtype=np.float32)
    delay, depth, beta_seen = 0.0, 0.0, []
    for start in range(0, max(len(rest32), 1), step):
        if computed is not None:
            world, delays, beta = computed
        else:
            rest = rest32[start : start + step].astype(np.float64)
            try:
                world, delays, beta = motion.apparent_world_positions(scene, obj, obj_eval, rest, snap, with_delay=True)
            except ValueError as error:  # the physics core's checks (superluminal motion, NaN)
                raise RelativityError(f"Object {obj.name!r}: {error}") from None
        delay = max(delay, float(np.max(delays, initial=0.0)))
        depth = max(depth, clip_end.farthest_seen_depth(scene, snap, world))
        # On coordinate rows (3, n): numpy multiplies the transposed views without copying them.
        local[start : start + step] = (inverse[:3, :3] @ world.T + inverse[:3, 3:]).T
        beta_seen.append(beta)
    shared = all(len(beta) == 1 for beta in beta_seen)  # one velocity for every point
    return local, beta_seen[0] if shared else np.concatenate(beta_seen), delay, depth


def update(
    scene: Scene,
    snap: Snapshot,
    depsgraph: Depsgraph | None = None,
    only_changed: bool = False,
    in_frame_change: bool = False,
) -> int:
    """Recompute every object carrying the modifier (only those whose inputs changed, with
    ``only_changed``: the signatures of the objects not current, ``changes.py``; ``in_frame_change``:
    see :func:`update_object`). A failure is recorded on the object's cache and printed, never
    raised: the viewport keeps the last valid state. Returns the number of objects updated."""
    updated = 0
    with busy.computing():
        objects = applied_objects(scene)
        evaluated = None
        current: dict[int, bool] = {}
        key = scene_key(snap)
        stepping = in_frame_change and depsgraph is not None  # a frame change: its depsgraph reports what moved
        if only_changed and objects:
            # The signatures hold the evaluated rest shapes: without the handler's depsgraph, the
            # scene's, evaluated now, which also reports Blender's pending updates (note_updates)
            # before the current objects are taken (update_object evaluates again after its edits).
            evaluated = _evaluated(depsgraph)
            current = changes.current_objects(scene.name, key, snap.frame, stepping)
        # straight keys' offsets set at a frame step; an observer's velocity change turns the records
        turning = straight_steps.turns(scene.name, key, stepping)
        if only_changed and objects and (stepping or turning):
            waiting = [o for o in objects if o.session_uid not in current]
            stepped = straight_steps.step(waiting, steps_scene(snap, key), snap, evaluated, turning)
            current.update(dict.fromkeys(stepped, False))
            updated += len(stepped)
        seen_as = _scene_parts(snap)
        for obj in objects:
            uid = obj.session_uid
            if uid in current:
                continue
            data = modifier.cache_data(obj)
            stored = data.get(names.SIGNATURE_KEY) if only_changed and data is not None else None
            # (a signature made for another observer, camera or c cannot be this one: not built again)
            if stored is not None and seen_as in stored and stored == object_signature(snap, obj, evaluated):
                current[uid] = motion.closed_form(obj, scene)
                continue
            if evaluated is None:
                evaluated = _evaluated(depsgraph)
            try:
                # one evaluation for every object: an update tags its own object only, so the others'
                # evaluated meshes stay what this depsgraph holds (one per object would evaluate the
                # objects updated before it again, and pass over the scene each time)
                update_object(scene, obj, snap, evaluated, in_frame_change)
                updated += 1
            except RelativityError as error:
                print(f"Relativity: {error}")
                data = modifier.cache_data(obj)
                if data is not None:
                    data[names.ERROR_KEY] = str(error)
                    data[names.SIGNATURE_KEY] = object_signature(snap, obj, _evaluated(depsgraph))
    return updated


def _seen_from(snap: Snapshot) -> list:
    """The observer's part of every signature and of the scene key: c, its velocity, the camera."""
    return [
        snap.speed_of_light,
        snap.beta,
        snap.camera,
        snap.camera_matrix,
        snap.exact_camera,
        snap.shutter_time if snap.exact_camera else 0.0,
    ]


def _scene_parts(snap: Snapshot) -> str:
    """The text every signature made for this snapshot holds (:func:`object_signature`'s first parts
    after the frame and matrix, comma-separated as ``repr`` writes them)."""
    return repr(_seen_from(snap))[1:-1]


def scene_key(snap: Snapshot) -> tuple:
    """What every object's signature takes from the snapshot and the scene but the frame: while it
    stays, an object Blender did not update keeps its signature (``changes.py``). Its third part is
    the observer's velocity (``steps_scene``)."""
    return (
        snap.scene,
        *_seen_from(snap),
        snap.projection,
        _render_size(snap),
        snap.fps,
        modifier.group_generation(),
    )


def steps_scene(snap: Snapshot, key: tuple | None = None) -> straight_steps.Scene:
    """The scene's key of the snapshot (``key`` when given), the same without the observer's velocity
    and the scene's parts of its signatures: what ``straight_steps`` compares its records with."""
    key = scene_key(snap) if key is None else key
    return straight_steps.Scene(key, (*key[:2], None, *key[3:]), _scene_parts(snap))


def _evaluated(depsgraph: Depsgraph | None) -> Depsgraph:
    return depsgraph if depsgraph is not None else bpy.context.evaluated_depsgraph_get()


def update_after_bake(scene: Scene, obj: Object) -> None:
    """Recompute ``obj`` right after a bake (raises, so the bake operator reports the problem)."""
    with busy.computing():
        depsgraph = bpy.context.evaluated_depsgraph_get()
        update_object(scene, obj, snapshot.read(scene, depsgraph, objects_for="GEOMETRY"), depsgraph)


# Scene name -> names of meshes Set Up left out because their evaluated mesh has no vertices.
_skipped_empty = {}


def scene_errors(scene: Scene, notes: list | None = None) -> list[str]:
    """One-line errors of the last update of each object (empty when every cache is current), and
    the meshes left out for having nothing to draw; ``notes``: ``changes.cache_notes``' when read."""
    errors = [
        error for _obj, error, _warning in (changes.cache_notes(scene) if notes is None else notes) if error is not None
    ]
    for name in _skipped_empty.get(scene.name, ()):
        obj = scene.objects.get(name)
        if obj is not None and obj.type == "MESH" and modifier.find_modifier(obj) is None:
            errors.append(f"Mesh {name!r} has no vertices: nothing to draw, left out of the apparent geometry")
    return errors


def update_warnings(scene: Scene, notes: list | None = None) -> list[str]:
    """One-line warnings of the last update of each object that did not fail (what it drew that is
    not the motion the user likely means: keys starting too late); they stop no render."""
    return [
        warning
        for _obj, error, warning in (changes.cache_notes(scene) if notes is None else notes)
        if warning and error is None
    ]


def apply(scene: Scene, snap: Snapshot, objects: Iterable[Object] | None = None) -> list[Object]:
    """Add the modifier to ``objects`` (default: every mesh of the scene whose
    ``relativity.enabled`` is on) and compute the snapshot's frame. Returns the objects.
    Meshes whose evaluated mesh has no vertices are left out (a warning: nothing to draw).

    Raises RelativityError (one line) if an object's settings are invalid, or a moving mesh draws
    instances the modifier cannot move; nothing is changed in that case.
    """
    if objects is None:
        objects = [
            obj
            for obj in scene.objects
            if obj.type == "MESH"
            and obj.relativity.enabled
            and not obj.relativity.moves_with_camera  # at rest with the camera: camera/cockpit.py
            and not modifier.is_cache(obj)
        ]
    linked = next((obj for obj in objects if obj.library is not None), None)
    if linked is not None:
        raise RelativityError(
            f"Mesh {linked.name!r} is linked from {bpy.path.basename(linked.library.filepath)!r}: its apparent "
            "geometry cannot be written in this file; make it local (Object > Relations > Make Local)"
        )
    for obj in objects:
        if obj.relativity.motion == "CONSTANT":
            snapshot.check_velocity(obj.relativity.beta, f"object {obj.name!r} velocity")
    depsgraph = bpy.context.evaluated_depsgraph_get()
    problem = instancing.instancing_problem(depsgraph, [*objects, *applied_objects(scene)], scene.objects)
    if problem is not None:
        raise RelativityError(problem)
    instancing.forget(scene.name)
    empty = [obj for obj in objects if len(obj.evaluated_get(depsgraph).data.vertices) == 0]
    objects = [obj for obj in objects if obj not in empty]
    _skipped_empty[scene.name] = sorted({*_skipped_empty.get(scene.name, ()), *(obj.name for obj in empty)})
    try:
        with busy.computing():
            for obj in objects:
                modifier.ensure_modifier(obj)
            depsgraph = bpy.context.evaluated_depsgraph_get()
            # as in a frame change: no evaluation per object (each costs a pass over the scene); the
            # modifiers check the edges first: after one evaluation, the meshes whose verdicts are not
            # what their update expected are computed again, those needing a new subdivision after one more
            for obj in objects:
                update_object(scene, obj, snap, depsgraph, in_frame_change=True, check_first=True)
            depsgraph = bpy.context.evaluated_depsgraph_get()
            for obj in [obj for obj in objects if obj.name not in _deferred]:
                if modifier.cache_data(obj).get(names.SIGNATURE_KEY) != object_signature(snap, obj, depsgraph):
                    update_object(scene, obj, snap, depsgraph, in_frame_change=True)
            waiting = [obj for obj in objects if obj.name in _deferred]
            if waiting:
                depsgraph = bpy.context.evaluated_depsgraph_get()
                for obj in waiting:
                    update_object(scene, obj, snap, depsgraph)
    except RelativityError:
        for obj in objects:
            modifier.remove_object_effect(obj)
        modifier.remove_unused_group()
        raise
    return list(objects)


def remove(scene: Scene, objects: Iterable[Object] | None = None) -> list[Object]:
    """Remove the modifier, the caches and (if unused) the node group. Returns objects restored.
    Without ``objects``, also the caches of objects deleted while set up and the effect of meshes
    unlinked from every scene while set up."""
    orphans = []
    if objects is None:
        _skipped_empty.pop(scene.name, None)
        orphans = modifier.orphan_caches()
        instancing.forget(scene.name)
    objects = [*applied_objects(scene), *modifier.unlinked_objects()] if objects is None else objects
    later: list = []
    restored = [obj for obj in objects if modifier.remove_object_effect(obj, later)]
    modifier.remove_later(later)
    for cache in orphans:
        modifier.remove_cache(cache)
    modifier.remove_unused_group()
    return restored
