"""Lamps at rest lighting moving objects (Weiskopf et al. eq. 18), by Cycles light linking.

For every lamp at rest (point, spot, area, sun) and every moving object of the Apparent Geometry
path (CONSTANT or rigid ANIMATION motion), the lamp's light on that object is received with
``D = gamma (1 - beta . k)`` (``beta`` the object's scene-frame velocity, ``k`` the direction lamp
-> object centre): the object-frame irradiance is ``D^2`` times what Cycles computes in the scene
frame, its spectrum shifted by ``D``, and it arrives from the aberrated direction ``k'``
(``physics/lamp_doppler.py``). Cycles cannot vary a lamp per receiver, so the stage adds, per lamp
and object, a **copy of the lamp** whose colour carries that factor, turned about the object's
centre from ``k`` to ``k'``, light-linked to receive only that object, and excludes the moving
objects from the lamp's own light linking; the objects lit this way are shaded with their
rest-frame normals (``rest_normals.py``: eq. 18's cosine). The observer's Doppler factor (eq. 14)
stays the materials' job.

One ``D`` per lamp and object (at the object's centre, its retarded position for the camera
event in the scene frame): docs/lamp-doppler.md measures what that leaves out.

Everything added is recorded on the scene (``names.LAMP_DOPPLER_KEY``): the copies, their light
data, the collections, and each lamp's own receiver collection; :func:`remove` deletes and
restores exactly that. Lamps that already use light linking (a receiver collection) are left as
they are, with a warning.
"""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING

import bpy
import mathutils
import numpy as np

from ...errors import RelativityError
from ...physics import lamp_doppler
from ..common import names
from ..geometry import apparent_meshes, modifier
from ..geometry import motion as world_lines
from ..scene import snapshot, sources
from . import rest_normals

if TYPE_CHECKING:
    from bpy.types import Object, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

KEY = names.LAMP_DOPPLER_KEY
COPY_KEY = names.LAMP_DOPPLER_COPY_KEY
PREFIX = names.LAMP_DOPPLER_PREFIX
KINDS = ("POINT", "SPOT", "AREA", "SUN")
# Light data settings the copy does not take over from its lamp (the colour carries the factor).
_OWN = {"name", "color", "use_temperature", "temperature", "rna_type", "type", "use_nodes"}


# --- what to light ------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class Mover:
    name: str
    centre: tuple  # world, scene frame: the centre's retarded position for the camera event
    beta: tuple  # scene-frame velocity there, fraction of c


def is_copy(obj: Object) -> bool:
    return COPY_KEY in obj


def _skipped_lamp(obj):
    return obj.light_linking.receiver_collection is not None and KEY not in obj


def lamps(scene: Scene) -> list[Object]:
    """Lamps at rest that render and that the stage can split (no light linking of their own)."""
    return [
        obj
        for obj in scene.objects
        if obj.type == "LIGHT"
        and not is_copy(obj)
        and obj.data.type in KINDS
        and obj.relativity.motion == "STATIC"
        and not snapshot.light_render_hidden(obj)
        and not _skipped_lamp(obj)
    ]


# Object name -> (key, centre): the centre of its mesh while its geometry key
# (``apparent_meshes.geometry_key``: Blender has not evaluated it again) stays the same.
_centres = {}


def _local_centre(obj):
    """The centre of the mesh's bounding box (object space), from its float32 positions."""
    mesh = obj.data
    count = len(mesh.vertices)
    if count == 0:
        return np.zeros(3)
    co = np.empty(count * 3, dtype=np.float32)
    mesh.attributes["position"].data.foreach_get("vector", co)
    co = co.reshape(-1, 3)
    return (co.min(axis=0).astype(np.float64) + co.max(axis=0).astype(np.float64)) / 2.0


def _centre(obj):
    """:func:`_local_centre`, read again only when the object's geometry may have changed."""
    key = apparent_meshes.geometry_key(obj)
    known = _centres.get(obj.name)
    if key is not None and known is not None and known[0] == key:
        return known[1]
    centre = _local_centre(obj)
    _centres[obj.name] = (key, centre)
    return centre


def movers(scene: Scene, snap: Snapshot) -> list[Mover]:
    """The moving objects of the Apparent Geometry path: centre and scene-frame velocity, with
    light-travel time from the camera event and no boost (the scene frame)."""
    # the scene frame: the exact camera's meshes are there already (seen from the aperture at the
    # shutter time); the boosted-mesh preview's observer is taken at rest for this
    at_rest_observer = snap if snap.exact_camera else dataclasses.replace(snap, beta=(0.0, 0.0, 0.0))
    found = []
    for obj in modifier.applied_objects(scene):
        motion = obj.relativity.motion
        if motion not in ("CONSTANT", "ANIMATION") or (motion == "ANIMATION" and obj.relativity.use_deformation):
            continue
        try:
            centre = _centre(obj)[None]
            world, beta = world_lines.apparent_world_positions(
                scene, obj, obj, centre, at_rest_observer, shape_keys_too=False
            )
        except ValueError as error:
            raise RelativityError(f"Object {obj.name!r}: {error}") from None
        beta = tuple(float(b) for b in np.asarray(beta)[0])
        if math.hypot(*beta) > 0.0:
            found.append(Mover(obj.name, tuple(float(x) for x in world[0]), beta))
    return found


def lamp_matrix(scene: Scene, lamp: Object, snap: Snapshot) -> FloatArray:
    """The lamp's world matrix at the snapshot's frame (its keyframes evaluated there)."""
    return np.asarray(snapshot.camera_matrix(scene, lamp, snap.frame), dtype=np.float64)


def incidence(matrix: FloatArray, kind: str, mover: Mover) -> FloatArray:
    """The photon direction ``k`` (scene frame) from a lamp with world ``matrix`` to ``mover``'s centre."""
    if kind == "SUN":
        return -matrix[:3, 2]
    direction = np.array(mover.centre) - matrix[:3, 3]
    if np.linalg.norm(direction) < 1e-9:
        return -np.array(mover.beta)  # lamp at the centre: take it as straight ahead
    return direction


def placement(matrix: FloatArray, kind: str, mover: Mover) -> tuple[float, FloatArray]:
    """``(D, copy's world matrix)``: eq. 18's factor for the lamp's light on ``mover`` and the lamp
    turned about the centre to the direction the object sees it from in its own frame."""
    k = incidence(matrix, kind, mover)
    doppler_factor = float(lamp_doppler.lamp_to_object_doppler(k, mover.beta))
    return doppler_factor, lamp_doppler.aberrated_lamp_matrix(matrix, mover.centre, k, mover.beta)


def copy_colour(lamp: Object, doppler_factor: float, snap: Snapshot) -> tuple[float, ...]:
    """The copy's colour: the lamp's colour with eq. 18's factor (its temperature folded in)."""
    light = lamp.data
    temperature = sources.light_blackbody(light)
    factor = lamp_doppler.lamp_rgb_factor(
        doppler_factor,
        rgb=tuple(light.color),
        temperature_k=temperature,
        use_doppler=snap.use_doppler,
        use_searchlight=snap.use_searchlight,
    )
    colour = np.array(light.color, dtype=np.float64)
    if light.use_temperature:
        colour = colour * np.array(light.temperature_color, dtype=np.float64)
    return tuple(float(v) for v in colour * factor)


# --- writing --------------------------------------------------------------------------------


def _record(scene):
    return scene[KEY].to_dict() if KEY in scene else None


def _collection(name, objects, state):
    collection = bpy.data.collections.new(name)
    for obj in objects:
        collection.objects.link(obj)
    for entry in collection.collection_objects:
        entry.light_linking.link_state = state
    return collection


def _build(scene, pairs, mover_names):
    record = {"copies": [], "lights": [], "collections": [], "lamps": {}}
    scene[KEY] = record  # recorded first: a failure half-way is still removed
    excluded = [scene.objects[name] for name in mover_names]
    for lamp in {lamp.name: lamp for lamp, _ in pairs}.values():
        exclude = _collection(f"{PREFIX} not {lamp.name}", excluded, "EXCLUDE")
        record["collections"].append(exclude.name)
        record["lamps"][lamp.name] = ""
        lamp[KEY] = True
        lamp.light_linking.receiver_collection = exclude
    for lamp, mover in pairs:
        obj = scene.objects[mover.name]
        receive = _collection(f"{PREFIX} {lamp.name} on {obj.name}", [obj], "INCLUDE")
        data = lamp.data.copy()
        copy = bpy.data.objects.new(f"{PREFIX} {lamp.name} on {obj.name}", data)
        copy[COPY_KEY] = [lamp.name, obj.name]
        scene.collection.objects.link(copy)
        for key in ("visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume_scatter"):
            setattr(copy, key, getattr(lamp, key))
        copy.visible_camera = False  # the lamp itself is seen once
        copy.hide_select = True
        copy.light_linking.receiver_collection = receive
        copy.light_linking.blocker_collection = lamp.light_linking.blocker_collection
        record["collections"].append(receive.name)
        record["copies"].append(copy.name)
        record["lights"].append(data.name)
    scene[KEY] = record


def _set(owner, attribute, value):
    """Write only a changed value (a write triggers a depsgraph update, whose handler syncs again)."""
    current = getattr(owner, attribute)
    if hasattr(current, "__len__") and not isinstance(current, str):
        if all(math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-12) for a, b in zip(current, value, strict=True)):
            return
    elif current == value or (isinstance(value, float) and math.isclose(current, value, rel_tol=1e-6)):
        return
    setattr(owner, attribute, value)


def _follow(copy_data, light):
    """Take over the lamp's settings (size, energy, spot cone, ...) except its colour."""
    for prop in light.bl_rna.properties:
        key = prop.identifier
        if key in _OWN or prop.is_readonly or prop.type not in {"BOOLEAN", "INT", "FLOAT", "ENUM"}:
            continue
        value = getattr(light, key)
        _set(copy_data, key, tuple(value) if getattr(prop, "is_array", False) else value)


def write(scene: Scene, snap: Snapshot) -> int:
    """Bring the copies up to date with the snapshot (rebuilt when the lamps or moving objects
    changed, else only their colours and settings written). Nothing without moving objects or
    off the Apparent Geometry path."""
    pairs = []
    if snap.method == "GEOMETRY" and (snap.use_doppler or snap.use_searchlight):
        lit_by = lamps(scene)
        found = movers(scene, snap) if lit_by else []  # no lamps: nothing to place
        pairs = [(lamp, mover) for lamp in lit_by for mover in found]
    record = _record(scene)
    layout = sorted([lamp.name, mover.name] for lamp, mover in pairs)
    if record is not None and sorted(_copy_pairs(record)) != layout:
        remove(scene)
        record = None
    if not pairs:
        rest_normals.remove(scene)
        return 0
    rest_normals.write(scene, [scene.objects[name] for name in sorted({mover.name for _, mover in pairs})])
    if record is None:
        _build(scene, pairs, sorted({mover.name for _, mover in pairs}))
    copies = {tuple(bpy.data.objects[name][COPY_KEY]): bpy.data.objects[name] for name in _record(scene)["copies"]}
    for lamp, mover in pairs:
        copy = copies[(lamp.name, mover.name)]
        doppler_factor, matrix = placement(lamp_matrix(scene, lamp, snap), lamp.data.type, mover)
        _follow(copy.data, lamp.data)
        _set(copy.data, "use_temperature", False)
        _set(copy.data, "color", copy_colour(lamp, doppler_factor, snap))
        if not np.allclose(np.array(copy.matrix_world), matrix, rtol=1e-6, atol=1e-9):
            copy.matrix_world = mathutils.Matrix(matrix.tolist())
    return len(pairs)


def _copy_pairs(record):
    found = []
    for name in record["copies"]:
        obj = bpy.data.objects.get(name)
        found.append(list(obj[COPY_KEY]) if obj is not None and COPY_KEY in obj else ["", name])
    return found


def apply(scene: Scene, snap: Snapshot) -> int:
    return write(scene, snap)


def remove(scene: Scene) -> int:
    """Delete the copies, their light data and the collections; give the lamps back their own
    (empty) light linking. Returns the number of copies removed."""
    rest_normals.remove(scene)
    record = _record(scene)
    if record is None:
        return 0
    ours = set(record["collections"])
    mine = [
        obj
        for obj in bpy.data.objects
        if scene.objects.get(obj.name) is obj or obj.name in record["lamps"] or obj.name in record["copies"]
    ]
    for lamp in mine:  # by the mark, not only the name: a lamp renamed while applied too
        if lamp.type == "LIGHT" and KEY in lamp:
            receiver = lamp.light_linking.receiver_collection
            if receiver is None or receiver.name in ours:
                saved = record["lamps"].get(lamp.name, "")
                lamp.light_linking.receiver_collection = bpy.data.collections.get(saved) if saved else None
            del lamp[KEY]
    copies = [obj for obj in mine if COPY_KEY in obj]
    lights = {obj.data for obj in copies} | {bpy.data.lights.get(name) for name in record["lights"]}
    for obj in copies:
        bpy.data.objects.remove(obj)
    for light in lights - {None}:
        if light.users == 0:
            bpy.data.lights.remove(light)
    for name in record["collections"]:
        collection = bpy.data.collections.get(name)
        if collection is not None:
            bpy.data.collections.remove(collection)
    del scene[KEY]
    return len(copies)


def warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """What this stage does not render right, one line each."""
    if snap.method != "GEOMETRY" or not modifier.applied_objects(scene):
        return []
    found = [
        f"Light {obj.name!r} uses light linking: its light on moving objects is not Doppler shifted (eq. 18)"
        for obj in scene.objects
        if obj.type == "LIGHT" and _skipped_lamp(obj) and not is_copy(obj)
    ]
    found += [
        f"Object {obj.name!r} deforms: lamps light it as if it were at rest (eq. 18 not applied)"
        for obj in modifier.applied_objects(scene)
        if obj.relativity.motion == "ANIMATION" and obj.relativity.use_deformation
    ]
    return found
