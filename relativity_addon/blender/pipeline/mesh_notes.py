"""The panel's notes on one mesh of the Apparent Geometry path: taken at each sync for the meshes
whose inputs changed (:func:`take`: too coarse to curve, spinning while it moves), read by the panel
and the batch script with the mesh's last update error and the bake it needs
(:func:`object_warnings`, :func:`bake_status`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..geometry import changes, modifier, shape_keys, tessellation
from ..lights import turning_receivers
from ..scene import animation

if TYPE_CHECKING:
    from bpy.types import Object, Scene

    from ..scene.snapshot import Snapshot

# Mesh name -> (the inputs its notes were taken for, the notes).
_object_warnings: dict[str, tuple[tuple, list[str]]] = {}


def take(scene: Scene, snap: Snapshot) -> None:
    """The notes of every mesh on the path whose inputs changed since they were taken (at a sync)."""
    eye = tuple(snap.camera_position)
    for obj in scene.objects:
        if obj.type == "MESH" and obj.relativity.enabled:
            known = _object_warnings.get(obj.name)
            if known is not None and known[0][0] == eye and changes.is_current(scene.name, obj.session_uid):
                continue  # an applied mesh Blender did not update since its warnings were made
            _object_warnings[obj.name] = mesh_warnings(scene, obj, snap)


def take_for(scene: Scene, obj: Object, snap: Snapshot) -> None:
    """The notes of one mesh whose settings changed (a dragged velocity: ``effect.velocity_changed``)."""
    _object_warnings[obj.name] = mesh_warnings(scene, obj, snap)


def mesh_warnings(scene: Scene, obj: Object, snap: Snapshot) -> tuple[tuple, list[str]]:
    """(inputs, warnings) of a mesh; the edges are measured again only when the inputs change (the
    spin's line reads the keys, c and fps: a key edited away from the current frame, or c changed,
    left it stale before)."""
    inputs = (
        tuple(snap.camera_position),
        snap.speed_of_light,
        snap.fps,
        animation.keyframes_hash(obj) if obj.animation_data is not None else None,  # (the spin's keys)
        obj.relativity.motion,
        tuple(obj.relativity.beta),
        tuple(tuple(row) for row in obj.matrix_world),
        obj.data.name,
        len(obj.data.edges),
        obj.relativity.tessellation,
        obj.relativity.use_adaptive_tessellation and tessellation.warning(obj),
        modifier.find_modifier(obj) is not None,
    )
    known = _object_warnings.get(obj.name)
    if known is not None and known[0] == inputs:
        return known
    coarse = tessellation.coarse_mesh_warning(obj, snap.camera_position)
    spin = turning_receivers.spin_warning(obj, scene, snap.speed_of_light)
    return inputs, [line for line in (coarse, spin) if line]


def _shape_key_warnings(obj):
    warning = shape_keys.scene_time_warning(obj)
    return [warning] if warning else []


def object_warnings(scene: Scene, obj: Object | None) -> list[str]:
    """Warnings for the active object on the apparent-geometry path: its last update error, a bake
    it needs, a mesh too coarse to curve (as of the last sync), shape keys left at scene time."""
    if obj is None or obj.type != "MESH" or scene.relativity.method != "GEOMETRY":
        return []
    warnings = list(_object_warnings.get(obj.name, ((), []))[1])
    error = modifier.object_error(obj)
    status = bake_status(scene, obj)
    if error is not None:  # the last update failed: the viewport shows an older state
        warnings.append(error)
    elif status is not None and status[1] is None and status[2] is not None:
        warnings.append(status[2])
    return warnings + _shape_key_warnings(obj)


def bake_status(scene: Scene, obj: Object) -> tuple[str, str | None, str | None] | None:
    """For an ANIMATION mesh: (bake operator, what is baked or None, why a bake is needed or None);
    None for other objects."""
    settings = obj.relativity
    if obj.type != "MESH" or settings.motion != "ANIMATION":
        return None
    if settings.use_deformation:
        baked = "Deformation baked" if modifier.bake_mesh(obj) is not None else None
        return "relativity.bake_deformation", baked, "Deforming mesh: press Bake Deformation"
    frames = modifier.motion_bake_range(obj)
    if frames is not None:
        return "relativity.bake_motion", f"Motion baked: frames {frames[0]:g} to {frames[1]:g}", None
    problem = animation.keyframe_motion_problem(obj, scene)
    needed = f"{problem}: keyframes are not its motion, press Bake Motion" if problem else None
    return "relativity.bake_motion", None, needed
