"""Apply, sync and remove the relativistic effect: the only module that knows both render paths.

One data path from a setting to the render::

    scene.relativity, Object.relativity, the camera    (settings: ui/props.py, ui/objects.py)
          |  snapshot.read (every check, once)
          v
    Snapshot  ->  the render path of the Method:
                    exact_camera.write      OSL parameters of the exact camera   (Exact Camera)
                    apparent_meshes.update  cache meshes of apparent geometry    (Apparent Geometry)
              ->  every stage of stages.STAGES, in order: apply at Set Up, write at every sync,
                  remove in reverse, warnings for the panel

:func:`sync` runs that path; every handler (``handlers.py``) and every property update callback
calls it, so a setting changed in the panel reaches the next render on either path. The two render
paths and the stages import nothing from each other's subpackages upwards
(``tests/static/test_architecture.py``). :func:`sync` never raises: what stops a correct render is
kept as the scene's warnings (shown in the panel), and the exact camera is marked invalid (it
renders black, never a wrong image).
"""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING

import bpy

from ...errors import RelativityError
from ..camera import exact_camera
from ..colour import doppler_colour
from ..common import busy, collector, compat, names
from ..geometry import apparent_meshes, changes, edge_bounds, instancing, modifier
from ..scene import animation, moving_objects, snapshot
from . import bake, mesh_notes, records, render_notice, settled
from .stages import STAGES, Sync

if TYPE_CHECKING:
    from collections.abc import Iterable

    from bpy.types import Depsgraph, Object, Scene

    from ..scene.snapshot import Snapshot

_final_render_valid = {}  # scene name -> whether its last exact final render's camera was valid
_setup_notices = {}  # scene name -> why switching the Method did not set the scene up again


def applied_method(scene: Scene) -> str | None:
    """``'CAMERA'`` or ``'GEOMETRY'``: the render path applied to ``scene``, or None (the exact
    camera of an Apparent Geometry final render does not count: it is there for the render)."""
    camera_object = scene.camera
    if (
        camera_object is not None
        and camera_object.type == "CAMERA"
        and exact_camera.is_applied(camera_object.data)
        and not exact_camera.is_render_only(camera_object.data)
    ):
        return "CAMERA"
    if modifier.any_applied(scene):
        return "GEOMETRY"
    return None


def is_applied(scene: Scene) -> bool:
    """Whether anything of the add-on is in the file (Remove is available): an applied render path,
    a camera datablock holding the OSL camera (its object may be deleted), a cache object, or any
    datablock or scene record a stage left (its ``relativity_`` ID properties, its node groups,
    texts and images), also when the camera or a moving object was deleted after Set Up. Pieces
    outside the scene while another scene is set up are that scene's."""
    if applied_method(scene) is not None or _stored_by_add_on(scene):
        return True
    if any(applied_method(other) is not None for other in bpy.data.scenes if other != scene):
        return False  # the pieces are another set-up scene's: its own Remove takes them
    if exact_camera.applied_camera_data() or modifier.orphan_caches():
        return True
    return any(_stored_by_add_on(block) for block in _local_blocks()) or _named_by_add_on()


def _local_blocks():
    data = bpy.data
    for collection in (data.cameras, data.materials, data.worlds, data.lights, data.objects, data.meshes):
        yield from (block for block in collection if block.library is None)


def _stored_by_add_on(block):
    """An ID property of the add-on's (``relativity_...``; ``relativity`` itself holds the settings)."""
    return any(key.startswith("relativity_") for key in block.keys())


def _named_by_add_on():
    data = bpy.data
    return any(
        block.library is None
        and block.name.startswith(("Relativity ", "relativistic_"))
        and block.name != names.SPECTRAL_IMAGE  # the spectral render's picture is the user's
        for collection in (data.node_groups, data.texts, data.images)
        for block in collection
    )


@collector.paused()
def apply(
    scene: Scene, frame_range: tuple[int, int] | None = None, objects: Iterable[Object] | None = None
) -> Object | list[Object]:
    """Apply the scene's method: check the observer (and the camera's speed over ``frame_range``,
    first and last frame, default the scene's range, when the velocity comes from its animation),
    then the render path and the colour stage. Returns the camera object (exact camera) or the
    list of objects (apparent geometry); ``objects`` limits the apparent geometry to those.
    Raises RelativityError (one line) and leaves the scene as it was."""
    snap = snapshot.read(scene)
    if snap.velocity_source == "CAMERA_ANIMATION":
        snapshot.check_animation_speed(scene, *(frame_range or (None, None)))
    if applied_method(scene) not in (None, snap.method):
        remove(scene)
    if snap.method == "CAMERA":
        result = exact_camera.apply(scene, snap)
        undo = lambda: exact_camera.remove(result)  # noqa: E731
    else:
        result = apparent_meshes.apply(scene, snap, objects)
        undo = lambda: apparent_meshes.remove(scene, result)  # noqa: E731
    try:
        if snap.method == "GEOMETRY":
            instancing.check_instancing(scene, preview=_preview(scene, snap))
        for stage in STAGES:
            stage.apply(scene, snap)
    except RelativityError:
        _remove_stages(scene)
        undo()
        raise
    _setup_notices.pop(scene.name, None)
    settled.forget(scene)
    records.record(scene, snap)
    return result


def _remove_stages(scene):
    """Every stage removed, in reverse order of :data:`STAGES` (the last applied goes first)."""
    for stage in reversed(STAGES):
        stage.remove(scene)


def remove(scene: Scene) -> int:
    """Remove everything the add-on added (every relativistic camera, the apparent geometry, the
    colour stage, a bake for rendering anywhere); the settings stay, they are the user's. Returns
    the number of things removed."""
    removed = bool(bake.unbake(scene)) + len(apparent_meshes.remove(scene))
    for camera_data in exact_camera.applied_camera_data():
        removed += bool(exact_camera.remove_data(camera_data))
    _remove_stages(scene)
    snapshot.end_final_render(scene)
    settled.forget(scene)
    records.forget(scene)
    _setup_notices.pop(scene.name, None)
    return removed


def bake_for_render_anywhere(scene: Scene, first: int, last: int) -> dict[str, int]:
    """Bake frames ``first`` .. ``last`` of the set-up scene into keyframes, image sequences and
    (Apparent Geometry) meshes played back by frame, in the final render's configuration, so that
    they render without the add-on (``bake.py``). RelativityError (one line) where that cannot be
    done: nothing set up, no OSL in this Blender for what needs it, a frame refused."""
    method = applied_method(scene)
    if method is None:
        raise RelativityError("Nothing to bake: press Set Up Relativistic Render first")
    bake.unbake(scene)  # a bake's own camera and meshes first out: every frame is computed again
    snap = snapshot.read(scene)
    exact = method == "GEOMETRY" and final_render_problem(scene, snap) is None
    problem = bake.refusal(scene, method, exact)
    if problem is not None:
        raise RelativityError(problem)
    if snap.velocity_source == "CAMERA_ANIMATION":
        snapshot.check_animation_speed(scene, first, last)
    if method == "CAMERA":
        counts = bake.bake(scene, first, last, lambda: sync(scene, before_render=True))
    else:
        counts = _bake_geometry(scene, first, last, exact)
    records.record(scene, snapshot.read(scene))
    return counts


def _bake_geometry(scene, first, last, exact):
    """Apparent Geometry baked as its final render makes it: with ``exact``, behind the exact camera
    (:func:`begin_final_render`; the meshes at their scene-frame retarded positions), which stays
    for the bake; else the boosted meshes. Every applied mesh is captured at each frame."""

    def frame_sync():
        if exact:  # as F12 at this frame: the preview decides the tessellation the final render keeps
            end_final_render(scene)
            sync(scene)
            begin_final_render(scene)
        return sync(scene, before_render=True)

    # Each frame is changed to from the preview, as between two renders (render_complete ends the
    # final render first): a frame change behind the exact camera placed the stand-in lamps again
    # from the frame-change handler's depsgraph (one point lamp), deleting the kept lines, which the
    # next final render made anew after the lamps' copies on the moving meshes. Cycles' light order
    # follows the objects' order in the scene, so the baked file then sampled its lights in another
    # order than the add-on's render: the same image, other noise (0.006-0.016 mean at 16 samples).
    leave_frame = (lambda: end_final_render(scene)) if exact else None
    try:
        counts = bake.bake(scene, first, last, frame_sync, modifier.applied_objects(scene), exact, leave_frame)
    except BaseException:
        if exact:
            end_final_render(scene)
        raise
    snapshot.end_final_render(scene)  # the mark only: the camera and its colour stage are the bake's now
    return counts


# --- the Apparent Geometry final render -------------------------------------------------------


def final_render_problem(scene: Scene, snap: Snapshot) -> str | None:
    """Why an Apparent Geometry final render of ``snap`` is not made with the exact camera (one
    line), or None when it is (``exact_camera.final_render_problem``)."""
    return exact_camera.final_render_problem(scene, snap)


def _preview(scene, snap):
    """Where the boosted-mesh preview of a moving observer is seen: None (the meshes are not boosted),
    "RENDER" (the final render is the preview too) or "VIEWPORT"."""
    if not instancing.boosted(snap):
        return None
    return "RENDER" if final_render_problem(scene, snap) is not None else "VIEWPORT"


def begin_final_render(scene: Scene) -> bool:
    """Before a final render (``render_init``) of an Apparent Geometry scene with a moving observer:
    the exact camera photographs the scene, whose moving objects hold their retarded positions in
    the scene frame, so lamps, shadows and the world light them where they are
    (``snapshot.begin_final_render``). :func:`end_final_render` goes back to the boosted-mesh
    preview. Returns whether the exact camera is used; RelativityError (one line) after undoing."""
    if bake.holds_geometry(scene):
        return False  # baked: the bake's exact camera (if any) is in place, the meshes are played back
    if applied_method(scene) != "GEOMETRY" or snapshot.in_final_render(scene):
        return snapshot.in_final_render(scene)
    problem = final_render_problem(scene, snapshot.read(scene))
    if problem is not None:
        if problem.startswith(("Camera", "the exact camera", "this Blender build")):
            print(f"Relativity: Apparent Geometry renders the boosted-mesh preview: {problem}")
            render_notice.tell(
                "Relativity: the final render is the boosted-mesh preview", problem[0].upper() + problem[1:]
            )
        return False
    snapshot.begin_final_render(scene)
    try:
        snap = snapshot.read(scene)
        exact_camera.apply(scene, snap, render_only=True)
        doppler_colour.apply(scene, snap)
    except RelativityError:
        end_final_render(scene)
        raise
    sync(scene)
    return True


def end_final_render(scene: Scene) -> None:
    """After the render (``render_complete``, ``render_cancel``): back to the boosted-mesh preview;
    the meshes follow at the next depsgraph update or frame change (a handler of the render thread
    must not evaluate the depsgraph)."""
    if bake.holds_geometry(scene):
        return
    was_exact = snapshot.in_final_render(scene)
    snapshot.end_final_render(scene)
    camera_object = scene.camera
    if was_exact and camera_object is not None and exact_camera.is_render_only(camera_object.data):
        _final_render_valid[scene.name] = bool(camera_object.data.cycles_custom.get("settings_valid", False))
    _remove_render_only_camera(scene)
    if was_exact:
        doppler_colour.remove_camera_stage(scene)
        sync(scene, update_geometry=False)
        for obj in modifier.applied_objects(scene):
            obj.update_tag()


def final_render_was_valid(scene: Scene) -> bool:
    """False if the exact camera of the scene's last Apparent Geometry final render was invalid
    (it rendered black: the scene's warnings say why)."""
    return _final_render_valid.pop(scene.name, True)


def _remove_render_only_camera(scene):
    camera_object = scene.camera
    if camera_object is not None and camera_object.type == "CAMERA" and exact_camera.is_render_only(camera_object.data):
        exact_camera.remove(camera_object)


@collector.paused()
def sync(
    scene: Scene,
    depsgraph: Depsgraph | None = None,
    *,
    update_geometry: bool = True,
    attach_new_materials: bool = False,
    before_render: bool = False,
    in_frame_change: bool = False,
    record: bool = True,
) -> Snapshot | None:
    """Bring the applied render path up to date with the scene at its current frame.

    ``update_geometry=False`` skips the apparent geometry (it needs the frame's evaluated meshes,
    which exist only after a frame change); only objects whose inputs changed (the frame among
    them) are recomputed; ``attach_new_materials`` attaches the Doppler colour to materials added
    since Set Up; ``before_render`` (``render_pre``) also writes what only a render reads (the
    world's direction image); ``in_frame_change`` (``frame_change_post``): the depsgraph is not
    evaluated again (``apparent_meshes.update_object``); ``record=False`` (``frame_change_pre``) takes
    no warnings for the panel: the frame change's ``frame_change_post`` takes them, with the new
    frame's meshes (a pass over every mesh: issue 26's 1,000 objects).
    Never raises."""
    reported = None
    if depsgraph is not None:
        # also while computing: what Blender evaluated again (a render's fresh depsgraph: only
        # the meshes whose inputs differ from the viewport's; no shading-only update: changes.reported)
        reported = changes.reported(depsgraph)
        apparent_meshes.note_updates(reported)
    if busy.is_computing():
        return None
    noted = changes.take_noted()  # (settled.py)
    if bake.holds_geometry(scene):  # played back as baked, with its camera: nothing to write until Remove
        return last_snapshot(scene)
    full = update_geometry and record and not (before_render or in_frame_change)
    # the meshes listed, their keys and settings read, once a sync
    with modifier.listed_once(), animation.signed_once(), moving_objects.checked_once():
        applied = settled.holds(scene, reported, noted) if full and reported is not None else None
        if applied is not None:
            modifier.listed_as(scene, applied)
            snap = _settled_sync(scene, depsgraph)
            if snap is not None:
                return snap
        modifier.unlink_caches()  # brought into a collection by Append
        method = applied_method(scene)
        if not snapshot.in_final_render(scene):
            _remove_render_only_camera(scene)  # left by a render that did not end (a file saved then)
        try:
            snap = snapshot.read(scene, depsgraph)
            if method is not None and method != snap.method:
                # applied with the other method (the setting changed where no callback ran)
                raise RelativityError(f"Set up again: the scene is set up for {_method_name(scene, method)}")
            if method == "CAMERA" or (method == "GEOMETRY" and snap.exact_camera):
                exact_camera.write(scene, snap)
            if method == "GEOMETRY":
                instancing.check_instancing(scene, depsgraph, evaluate=update_geometry, preview=_preview(scene, snap))
            if method == "GEOMETRY" and update_geometry:
                apparent_meshes.update(scene, snap, depsgraph, only_changed=True, in_frame_change=in_frame_change)
            if method is not None:
                update = Sync(depsgraph, attach_new_materials, before_render)
                for stage in STAGES:
                    stage.write(scene, snap, update)
        except RelativityError as error:
            if method == "CAMERA" or snapshot.in_final_render(scene):
                exact_camera.invalidate(scene.camera)
            _refused(scene, error)
            settled.forget(scene)
            return None
        if record:
            records.record(scene, snap, depsgraph)
        if full and method == "GEOMETRY":
            settled.remember(scene, snap, noted | changes.take_noted())
        else:
            settled.forget(scene)
        return snap


def _settled_sync(scene, depsgraph):
    """A depsgraph update of what the last full sync took (``settled.py``): the reported meshes'
    signatures (an update if the modifier's verdict differs: then a full sync follows), their
    clip-end depths and caches' notes; the rest of the panel's records kept. None: sync in full."""
    snap = records.recorded_snapshot(scene)
    if snap is None:  # (settled: set up for Apparent Geometry at the last full sync)
        return None
    if apparent_meshes.update(scene, snap, depsgraph, only_changed=True):
        return None
    records.take_meshes(scene, snap, depsgraph)
    settled.renew(scene)
    return snap


@collector.paused()
def velocity_changed(scene: Scene, obj: Object) -> None:
    """Update callback of an object's Constant Velocity: :func:`object_changed`, but where the
    velocity changes again on a mesh the scene's record holds (``settled.velocity_holds``: a slider
    dragged), that mesh's update, the stages and their warnings only, from the last snapshot with
    the new fastest speed (the depsgraph update after it takes the mesh's records). Never raises."""
    changes.note_changed(obj.session_uid)
    edge_bounds.announce(obj)  # (as object_changed)
    snap = records.recorded_snapshot(scene)
    applied = None
    usable = snap is not None and snap.method == "GEOMETRY" and not snap.exact_camera
    if usable and not busy.is_computing() and not bake.holds_geometry(scene):  # (baked: played back as it is)
        applied = settled.velocity_holds(scene, obj, changes.noted())
    if applied is None or snap is None:
        object_changed(scene, obj)
        return
    changes.take_noted()
    with modifier.listed_once(), animation.signed_once(), moving_objects.checked_once():
        modifier.listed_as(scene, applied)
        fastest = moving_objects.fastest_speed_with(scene, obj, math.hypot(*obj.relativity.beta))
        snap = dataclasses.replace(snap, fastest_object=fastest)
        try:
            apparent_meshes.update(scene, snap, only_changed=True)
            for stage in STAGES:
                stage.write(scene, snap, Sync())
        except RelativityError as error:
            _refused(scene, error)
            settled.forget(scene)
            return
        except ReferenceError:  # a kept mesh removed since (an undo that kept the object count)
            snap = None
        else:
            records.take_stages(scene, snap)  # (Static meshes and instancing: as they were)
            mesh_notes.take_for(scene, obj, snap)  # (its spin's line reads the velocity)
    if snap is None:  # the full way, with the scene's meshes listed again
        settled.forget(scene)
        object_changed(scene, obj)
    elif changes.take_noted() - {obj.session_uid}:  # (the update notes the mesh whose cache it wrote)
        settled.forget(scene)


def setting_changed(scene: Scene) -> None:
    """Update callback of every scene setting: switch the render path if the method changed
    (re-applying it), else sync. Never raises."""
    method = applied_method(scene)
    if method is not None and method != scene.relativity.method:
        try:
            apply(scene)
        except RelativityError as error:
            _refused(scene, error)
            _setup_refused(scene, error)
        return
    if method is not None:  # the Method is the applied one again: a refused switch is no longer news
        _setup_notices.pop(scene.name, None)
    sync(scene)


def object_changed(scene: Scene, obj: Object) -> None:
    """Update callback of every object setting: a mesh switched on after Set Up gets the apparent
    geometry, a changed blackbody temperature re-attaches its materials, then sync. Never raises."""
    changes.note_changed(obj.session_uid)  # Blender tags the object after this callback
    if (
        obj.type == "MESH"
        and obj.relativity.enabled
        and not obj.relativity.moves_with_camera
        and modifier.find_modifier(obj) is None
        and applied_method(scene) == "GEOMETRY"  # (last: it lists the scene's meshes)
    ):
        try:
            apparent_meshes.apply(scene, snapshot.read(scene), [obj])
        except RelativityError as error:
            _refused(scene, error)
            return
    edge_bounds.announce(obj)  # the setting's update tags the object: not an edit of its rest shape
    sync(scene, attach_new_materials=True)


# --- warnings, computed when the effect syncs -------------------------------------------------


def _setup_refused(scene, error):
    """Switching the Method could not set the scene up again: one line for the panel (until the
    next Set Up or Remove) and, when Blender has a window, a popup (an update callback has no
    operator to report with)."""
    if applied_method(scene) is None:
        notice = f"The relativistic effect was removed: {error}"
    else:
        notice = f"Still set up for {_method_name(scene, applied_method(scene))}: {error}"
    _setup_notices[scene.name] = notice
    render_notice.tell("Relativity: the Method was not switched", notice)


def _method_name(scene, method):
    return compat.enum_name(scene.relativity, "method", method)


def setup_notice(scene: Scene) -> str | None:
    """Why the last switch of the Method failed (one line), or None."""
    return _setup_notices.get(scene.name)


def _refused(scene, error):
    records.refused(scene, error, applied_method(scene) is not None or snapshot.in_final_render(scene))


last_snapshot = records.last_snapshot
traveller_time = records.traveller_time
scene_warnings = records.scene_warnings
