"""The panel's records of each scene's last sync: its snapshot and one-line warnings (``effect.sync``).

A full sync takes them all (:func:`record`): the scene's own (head), the meshes' (the records an
evaluation changes: their updates' errors and warnings, the Clip End their evaluated bounds need),
the instancing check's and Static meshes moved by keys, then every stage's. A settled
update takes the meshes' part again (:func:`take_meshes`), a velocity dragged on a mesh the
stages' (:func:`take_stages`), the rest kept (``settled.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

from ...errors import RelativityError
from ..camera import exact_camera
from ..geometry import apparent_meshes, changes, clip_end, instancing
from ..scene import census, moving_objects, snapshot, traveller
from . import mesh_notes
from .stages import STAGES

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Scene

    from ..scene.snapshot import Snapshot


class _Record(NamedTuple):
    """A scene's last sync: its snapshot (None: refused) and its warnings in the panel's order."""

    snap: Snapshot | None
    head: list[str]  # the scene's own
    meshes: list[str]  # what an evaluation of the meshes changes
    objects: list[str]  # the instancing check's, Static meshes moved by keys
    stages: list[str]  # every stage's

    @property
    def warnings(self) -> list[str]:
        return self.head + self.meshes + self.objects + self.stages


_records: dict[str, _Record] = {}  # scene name -> its last sync's record
_traveller_times: dict[str, float] = {}  # scene name -> the observer's proper time at the last synced frame


def forget(scene: Scene) -> None:
    _records.pop(scene.name, None)


def refused(scene: Scene, error: RelativityError, said: bool) -> None:
    """The sync was refused: ``error`` is the record; printed once when ``said`` (a set-up scene)."""
    record = _Record(None, [str(error)], [], [], [])
    if said and _records.get(scene.name) != record:  # said at the last sync: once on the console
        print(f"Relativity: {error}")  # a scene never set up: the panel only
    _records[scene.name] = record


def record(scene: Scene, snap: Snapshot, depsgraph: Depsgraph | None = None) -> None:
    """Every record of a sync of ``scene`` that gave ``snap`` (the objects' settings read once:
    ``census``)."""
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
    with census.taken():
        objects = _object_warnings(scene, snap)
        _records[scene.name] = _Record(
            snap, warnings, _mesh_records(scene, snap, depsgraph), objects, _stage_warnings(scene, snap)
        )
        try:
            _traveller_times[scene.name] = traveller.proper_time_at(scene, snap.frame)
        except (RelativityError, ValueError):
            _traveller_times.pop(scene.name, None)
        if snap.method == "GEOMETRY":
            mesh_notes.take(scene, snap)


def recorded_snapshot(scene: Scene) -> Snapshot | None:
    """The snapshot of the scene's last full record (None after a refusal or Remove)."""
    known = _records.get(scene.name)
    return known.snap if known is not None else None


def take_meshes(scene: Scene, snap: Snapshot, depsgraph: Depsgraph | None) -> None:
    """The meshes' records taken again (an evaluation changed them), the others kept."""
    _records[scene.name] = _records[scene.name]._replace(snap=snap, meshes=_mesh_records(scene, snap, depsgraph))


def take_stages(scene: Scene, snap: Snapshot) -> None:
    """The stages' records taken again with ``snap`` (the stages wrote it), the others kept."""
    _records[scene.name] = _records[scene.name]._replace(snap=snap, stages=_stage_warnings(scene, snap))


def _object_warnings(scene, snap):
    """The instancing check's records and Static meshes moved by keys."""
    if snap.method != "GEOMETRY":
        return []
    warnings = instancing.instancing_warnings(scene, snap)
    warnings += filter(
        None,
        (
            moving_objects.static_but_keyframed(entry.obj, scene)
            for entry in census.entries(scene)
            if entry.type == "MESH" and entry.motion == "STATIC"  # (what it looks at: read once)
        ),
    )
    return warnings


def _stage_warnings(scene, snap):
    warnings = []
    for stage in STAGES:
        warnings += stage.warnings(scene, snap)
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
    """The scene's last record; checked now if it has not synced since the file was opened."""
    if scene.name not in _records:
        try:
            record(scene, snapshot.read(scene))
        except RelativityError as error:
            _records[scene.name] = _Record(None, [str(error)], [], [], [])
    return _records[scene.name]


def last_snapshot(scene: Scene) -> Snapshot | None:
    """The snapshot of the scene's last sync, or None if that sync was refused."""
    return _status(scene).snap


def traveller_time(scene: Scene) -> float | None:
    """The observer's proper time (seconds, 0 at frame 0) at the scene's last synced frame, or None."""
    _status(scene)
    return _traveller_times.get(scene.name)


def scene_warnings(scene: Scene) -> list[str]:
    """One-line problems that stop or falsify a relativistic render of ``scene`` (as of its last
    sync)."""
    return _status(scene).warnings
