"""The panel's records of each scene's last sync: its snapshot and one-line warnings (``effect.sync``).

A full sync takes them all (:func:`record`): the scene's own (head), the meshes' (the records an
evaluation changes: their updates' errors and warnings, the Clip End their evaluated bounds need),
then the instancing check's, Static meshes moved by keys and every stage's (tail). A settled
update takes the meshes' part again (:func:`take_meshes`), a velocity dragged on a mesh the
stages' (:func:`take_stages`), the rest kept (``settled.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import RelativityError
from ..camera import exact_camera
from ..geometry import apparent_meshes, changes, clip_end, instancing
from ..scene import census, moving_objects, snapshot, traveller
from . import mesh_notes
from .stages import STAGES

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Scene

    from ..scene.snapshot import Snapshot

# Scene name -> (snapshot or None, warnings) of its last sync.
_scene_status: dict[str, tuple[Snapshot | None, list[str]]] = {}
# Scene name -> the warnings before and after the meshes' records of its last full record.
_record_parts: dict[str, tuple[list[str], list[str]]] = {}
_traveller_times: dict[str, float] = {}  # scene name -> the observer's proper time at the last synced frame


def forget(scene: Scene) -> None:
    _scene_status.pop(scene.name, None)
    _record_parts.pop(scene.name, None)


def refused(scene: Scene, error: RelativityError, said: bool) -> None:
    """The sync was refused: ``error`` is the record; printed once when ``said`` (a set-up scene)."""
    status = (None, [str(error)])
    repeated = _scene_status.get(scene.name) == status  # said at the last sync: once on the console
    if said and not repeated:
        print(f"Relativity: {error}")  # a scene never set up: the panel only
    _scene_status[scene.name] = status


def record(scene: Scene, snap: Snapshot, depsgraph: Depsgraph | None = None) -> None:
    """Every record of a sync of ``scene`` that gave ``snap``."""
    warnings = []
    if scene.render.engine == "CYCLES" and scene.cycles.device == "GPU":
        warnings.append("Cycles renders OSL cameras on the CPU (or OptiX) only: set Device to CPU")
    if snap.method == "CAMERA":
        camera_object = scene.objects.get(snap.camera)
        problem = camera_object and exact_camera.type_problem(camera_object.name, camera_object.data)
        if problem:
            warnings.append(problem[0].upper() + problem[1:])
    if snap.exact_camera:
        warnings += exact_camera.lens_warnings(scene.objects.get(snap.camera))
    if snap.method == "GEOMETRY":
        problem = exact_camera.final_render_problem(scene, snap)
        if snap.speed > 0.0 and problem is not None:
            warnings.append(f"Lamps, shadows and the world are not relativistic in this render: {problem}")
            if snap.exposure_mode == "COMPENSATED":
                warnings.append("Compensated exposure is applied by the exact camera only: not in this render")
    head = list(warnings)
    middle = _mesh_records(scene, snap, depsgraph)
    tail = _tail(scene, snap)
    _record_parts[scene.name] = (head, tail)
    _scene_status[scene.name] = (snap, head + middle + tail)
    try:
        _traveller_times[scene.name] = traveller.proper_time_at(scene, snap.frame)
    except (RelativityError, ValueError):
        _traveller_times.pop(scene.name, None)
    if snap.method == "GEOMETRY":
        mesh_notes.take(scene, snap)


def recorded_snapshot(scene: Scene) -> Snapshot | None:
    """The snapshot of the scene's last full record (None after a refusal or Remove)."""
    if scene.name not in _record_parts:
        return None
    return _scene_status.get(scene.name, (None, []))[0]


def take_meshes(scene: Scene, snap: Snapshot, depsgraph: Depsgraph | None) -> None:
    """The meshes' records taken again (an evaluation changed them), the others kept."""
    head, tail = _record_parts[scene.name]
    _scene_status[scene.name] = (snap, head + _mesh_records(scene, snap, depsgraph) + tail)


def take_stages(scene: Scene, snap: Snapshot) -> None:
    """The stages' records taken again with ``snap`` (the stages wrote it), the others kept."""
    head, tail = _record_parts[scene.name]
    warnings = _scene_status[scene.name][1]
    middle = warnings[len(head) : len(warnings) - len(tail)]
    tail = tail[: len(tail) - _stage_counts.get(scene.name, 0)]
    tail += _stage_warnings(scene, snap)
    _record_parts[scene.name] = (head, tail)
    _scene_status[scene.name] = (snap, head + middle + tail)


_stage_counts: dict[str, int] = {}  # scene name -> how many of its tail's records are the stages'


def _tail(scene, snap):
    """The records after the meshes': the instancing check's, Static meshes moved by keys, the stages'."""
    warnings = []
    if snap.method == "GEOMETRY":
        warnings += instancing.instancing_warnings(scene, snap)
        warnings += filter(
            None,
            (
                moving_objects.static_but_keyframed(entry.obj, scene)
                for entry in census.entries(scene)
                if entry.type == "MESH" and entry.motion == "STATIC"  # (what it looks at: read once)
            ),
        )
    return warnings + _stage_warnings(scene, snap)


def _stage_warnings(scene, snap):
    warnings = []
    for stage in STAGES:
        warnings += stage.warnings(scene, snap)
    _stage_counts[scene.name] = len(warnings)
    return warnings


def _mesh_records(scene, snap, depsgraph):
    """The records an evaluation of the meshes changes: their updates' errors and warnings, the
    Clip End their evaluated bounds need."""
    notes = changes.cache_notes(scene)  # (read once for both)
    found = apparent_meshes.scene_errors(scene, notes)
    if snap.method == "GEOMETRY":
        found += clip_end.clip_end_warnings(scene, snap, depsgraph)
        found += apparent_meshes.update_warnings(scene, notes)
    return found


def _status(scene):
    """(snapshot or None, warnings) of the scene's last sync; checked now if it has not synced
    since the file was opened."""
    if scene.name not in _scene_status:
        try:
            record(scene, snapshot.read(scene))
        except RelativityError as error:
            _scene_status[scene.name] = (None, [str(error)])
    return _scene_status[scene.name]


def last_snapshot(scene: Scene) -> Snapshot | None:
    """The snapshot of the scene's last sync, or None if that sync was refused."""
    return _status(scene)[0]


def traveller_time(scene: Scene) -> float | None:
    """The observer's proper time (seconds, 0 at frame 0) at the scene's last synced frame, or None."""
    _status(scene)
    return _traveller_times.get(scene.name)


def scene_warnings(scene: Scene) -> list[str]:
    """One-line problems that stop or falsify a relativistic render of ``scene`` (as of its last
    sync)."""
    return list(_status(scene)[1])
