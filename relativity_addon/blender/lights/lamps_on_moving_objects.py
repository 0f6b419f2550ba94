"""Lamps at rest lighting moving objects (Weiskopf et al. eq. 18), by Cycles light linking.

For every lamp at rest (point, spot, area, sun) and every moving object of the Apparent Geometry
path (CONSTANT or rigid ANIMATION motion), the lamp's light on that object is received with
``D = gamma (1 - beta . k)`` (``beta`` the object's scene-frame velocity, ``k`` the photon
direction lamp -> receiving point): the object-frame irradiance is ``D^2`` times what Cycles
computes in the scene frame, its spectrum shifted by ``D``, and it arrives from the aberrated
direction ``k'`` (``physics/lamp_doppler.py``). The stage excludes the moving objects from the
lamp's own light linking and adds, per lamp and object, copies light-linked to that object alone:

- point, spot and area lamps: a few **stand-ins** (point lamps for point and spot lamps, the panel
  for area lamps) on the line through the lamp parallel to ``beta``, where the receiving points
  see the lamp in their own frame; their light trees (``lamp_stand_ins.py``) give each receiving
  point its own ``D``, colour and aberrated direction (eq. 18 per point);
- suns: one copy with the colour of ``D`` turned to ``k'``: a plane wave has one ``k``, so one
  ``D`` and one ``k'`` for the whole object (exact for an object that does not turn).

The objects lit this way are shaded with their rest-frame normals (``rest_normals.py``: eq. 18's
cosine). The observer's Doppler factor (eq. 14) stays the materials' job. docs/lamp-doppler.md
measures what is left.

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
from ..camera import exact_camera
from ..common import busy, names, nodes
from ..geometry import apparent_meshes, modifier
from ..geometry import motion as world_lines
from ..scene import snapshot, sources
from . import lamp_stand_ins, lamp_trees, moving_lights, moving_pairs, rest_normals, stand_in_lamps, unshifted_light

if TYPE_CHECKING:
    from bpy.types import Light, Object, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

KEY = names.LAMP_DOPPLER_KEY
COPY_KEY = names.LAMP_DOPPLER_COPY_KEY
PREFIX = names.LAMP_DOPPLER_PREFIX
KINDS = ("POINT", "SPOT", "AREA", "SUN")
PER_POINT = ("POINT", "SPOT", "AREA")  # stand-ins on the line of apparent positions; a sun: one copy
MAX_ANGLE = 0.2  # radians between neighbouring stand-ins seen from the nearest receiving point
MAX_STAND_INS = 3  # per lamp and object: two light a point; more add noise (benchmarks/lamp_doppler_cost.py)
MAX_AREA_STAND_INS = 6  # an area lamp's extent widens the span (a 1 m panel 1 m away: 6.6 % off with 3)
# Light data settings the copy does not take over from its lamp (the colour carries the factor).
_OWN = {"name", "color", "use_temperature", "temperature", "rna_type", "type", "use_nodes"}


# --- what to light ------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class Mover:
    name: str
    centre: tuple  # world, scene frame: the centre's retarded position for the camera event
    beta: tuple  # scene-frame velocity there, fraction of c
    corners: tuple = ()  # the bounding box's corners, edge midpoints and face centres, retarded like the centre


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
        and not moving_pairs.is_ours(scene, obj)  # a moving light's lamps: moving_pairs.py
    ]


def _local_box(obj):
    """The centre, then the corners, edge midpoints and face centres of the mesh's bounding box
    (object space): where the receiving points' apparent lamp offsets reach their extremes closely
    enough (the offset is not monotonic over a face). From the mesh's float32 positions."""
    mesh = obj.data
    count = len(mesh.vertices)
    if count == 0:
        return np.zeros((27, 3))
    co = np.empty(count * 3, dtype=np.float32)
    mesh.attributes["position"].data.foreach_get("vector", co)
    co = co.reshape(-1, 3)
    low, high = co.min(axis=0).astype(np.float64), co.max(axis=0).astype(np.float64)
    steps = np.array(list(np.ndindex(3, 3, 3))) - 1
    grid = (low + high) / 2.0 + steps * (high - low) / 2.0
    return grid[np.argsort(np.abs(steps).sum(axis=1), kind="stable")]  # the centre first


# Object name -> (key, box): the points of :func:`_local_box` while the object's geometry key
# (``apparent_meshes.geometry_key``: Blender has not evaluated it again) stays the same.
_boxes = {}


def _box(obj):
    """:func:`_local_box`, read again only when the object's geometry may have changed."""
    key = apparent_meshes.geometry_key(obj)
    known = _boxes.get(obj.name)
    if key is not None and known is not None and known[0] == key:
        return known[1]
    box = _local_box(obj)
    _boxes[obj.name] = (key, box)
    return box


def rest_box(obj: Object) -> tuple[FloatArray, FloatArray]:
    """The low and high corners of the mesh's bounding box (object space, rest shape)."""
    box = _box(obj)
    return box.min(axis=0), box.max(axis=0)


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
            world, beta = world_lines.apparent_world_positions(
                scene, obj, obj, _box(obj), at_rest_observer, shape_keys_too=False
            )
        except ValueError as error:
            raise RelativityError(f"Object {obj.name!r}: {error}") from None
        beta = tuple(float(b) for b in np.asarray(beta)[0])
        if math.hypot(*beta) > 0.0:
            corners = tuple(tuple(float(x) for x in point) for point in world[1:])
            found.append(Mover(obj.name, tuple(float(x) for x in world[0]), beta, corners))
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


def lamp_points(matrix: FloatArray, light: Light) -> FloatArray:
    """World points of the lamp that span its light: its position; an area lamp's corners too."""
    if light.type != "AREA":
        return matrix[None, :3, 3]
    half_x = 0.5 * float(light.size)
    half_y = 0.5 * float(light.size_y if light.shape in ("RECTANGLE", "ELLIPSE") else light.size)
    local = [
        (0.0, 0.0, 0.0),
        (-half_x, -half_y, 0.0),
        (half_x, -half_y, 0.0),
        (-half_x, half_y, 0.0),
        (half_x, half_y, 0.0),
    ]
    return np.array([matrix[:3, :3] @ point + matrix[:3, 3] for point in local])


def stand_in_placement(matrix: FloatArray, light: Light, mover: Mover) -> tuple[FloatArray, tuple[float, float, float]]:
    """``(offsets, (D low, D centre, D high))``: the stand-ins' offsets along ``bhat`` from the
    lamp (``lamp_doppler.stand_in_offsets`` over the object's box and the lamp's extent) and the
    range of ``D`` over the object (its centre's from the lamp's position)."""
    receivers = np.array([mover.centre, *mover.corners])
    elements = lamp_points(matrix, light)
    separation = receivers[None, :, :] - elements[:, None, :]
    distance = np.linalg.norm(separation, axis=-1)
    usable = distance > 1e-6
    if not usable.any():
        return np.zeros(1), (1.0, 1.0, 1.0)
    beta = np.array(mover.beta)
    offsets = lamp_doppler.apparent_lamp_offset(receivers[None, :, :], elements[:, None, :], beta)[usable]
    dopplers = lamp_doppler.lamp_to_object_doppler(separation[usable], beta)
    most = MAX_AREA_STAND_INS if light.type == "AREA" else MAX_STAND_INS
    stand_ins = lamp_doppler.stand_in_offsets(offsets, dopplers * distance[usable], MAX_ANGLE, most)
    centre = float(lamp_doppler.lamp_to_object_doppler(incidence(matrix, light.type, mover), beta))
    spread = (min(float(dopplers.min()), centre * math.exp(-0.01)), max(float(dopplers.max()), centre * math.exp(0.01)))
    return stand_ins, (spread[0], centre, spread[1])


def copy_colour(lamp: Object, doppler_factor: float, snap: Snapshot) -> tuple[float, ...]:
    """The copy's colour: the lamp's colour with eq. 18's factor (its temperature folded in)."""
    light = lamp.data
    temperature = sources.light_blackbody(light)
    factor = lamp_doppler.lamp_rgb_factor(
        doppler_factor,
        rgb=lamp_trees.doppler_rgb(light),
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


def _build(scene, layout, mover_names):
    """``layout``: (lamp, mover's name, number of copies) for every pair."""
    record = {"copies": [], "lights": [], "collections": [], "lamps": {}}
    scene[KEY] = record  # recorded first: a failure half-way is still removed
    excluded = [scene.objects[name] for name in mover_names]
    for lamp in {lamp.name: lamp for lamp, _, _ in layout}.values():
        exclude = _collection(f"{PREFIX} not {lamp.name}", excluded, "EXCLUDE")
        record["collections"].append(exclude.name)
        record["lamps"][lamp.name] = ""
        lamp[KEY] = True
        lamp.light_linking.receiver_collection = exclude
    for lamp, mover_name, count in layout:
        obj = scene.objects[mover_name]
        receive = _collection(f"{PREFIX} {lamp.name} on {obj.name}", [obj], "INCLUDE")
        record["collections"].append(receive.name)
        for index in range(count):
            data = lamp.data.copy()
            if lamp.data.type in PER_POINT:
                if data.type == "SPOT":
                    data.type = "POINT"  # the cone is the tree's, of the true direction
                lamp_stand_ins.make_tree(data)
            copy = bpy.data.objects.new(f"{PREFIX} {lamp.name} on {obj.name} {index}", data)
            copy[COPY_KEY] = [lamp.name, obj.name, str(index)]  # ID property arrays: one type
            scene.collection.objects.link(copy)
            for key in ("visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume_scatter"):
                setattr(copy, key, getattr(lamp, key))
            copy.visible_camera = False  # the lamp itself is seen once
            copy.hide_select = True
            copy.light_linking.receiver_collection = receive
            copy.light_linking.blocker_collection = lamp.light_linking.blocker_collection
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


def _follow(copy_data, light, own=frozenset()):
    """Take over the lamp's settings (size, energy, spot cone, ...) except its colour (and ``own``)."""
    for prop in light.bl_rna.properties:
        key = prop.identifier
        if (
            key in _OWN
            or key in own
            or prop.is_readonly
            or prop.type not in {"BOOLEAN", "INT", "FLOAT", "ENUM"}
            or key not in copy_data.bl_rna.properties  # a spot's cone on its point-lamp stand-ins
        ):
            continue
        value = getattr(light, key)
        _set(copy_data, key, tuple(value) if getattr(prop, "is_array", False) else value)


def write(scene: Scene, snap: Snapshot) -> int:
    """Bring the copies up to date with the snapshot (rebuilt when the lamps or moving objects
    changed, else only their colours and settings written). Nothing without moving objects or
    off the Apparent Geometry path. With Doppler colour and searchlight both off the copies stay,
    with no factor of ``D``: the aberrated direction (and the rest normals) are geometry."""
    pairs, moving_lit = [], []
    if snap.method == "GEOMETRY":
        lit_by = lamps(scene)
        moving = moving_lights.uses_lamps(snap) and bool(stand_in_lamps.stand_in_names(scene))
        found = movers(scene, snap) if lit_by or moving else []  # no lamps: nothing to place
        pairs = [(lamp, mover) for lamp in lit_by for mover in found]
        moving_lit = moving_pairs.write(scene, snap, found)  # moving lights on moving objects
    else:
        moving_pairs.remove(scene)
    record = _record(scene)
    placed = []
    for lamp, mover in pairs:
        matrix = lamp_matrix(scene, lamp, snap)
        stand_ins = stand_in_placement(matrix, lamp.data, mover) if lamp.data.type in PER_POINT else None
        placed.append((lamp, mover, matrix, stand_ins))
    layout = sorted(
        [lamp.name, mover.name, str(index)]
        for lamp, mover, _, stand_ins in placed
        for index in range(1 if stand_ins is None else len(stand_ins[0]))
    )
    kept = sorted(_copy_pairs(record)) if record is not None else []
    if busy.keeps_stand_ins() and pairs and all(len(e) == 3 and scene.objects.get(e[0]) for e in kept):
        # a bake steps frames: every copy made stays under its name, those this frame does not use hidden
        layout = sorted(map(list, {tuple(entry) for entry in kept} | {tuple(entry) for entry in layout}))
    if record is not None and kept != layout:
        _remove_copies(scene)
        record = None
    lit = sorted({mover.name for _, mover in pairs} | set(moving_lit))
    if lit:
        rest_normals.write(scene, [scene.objects[name] for name in lit], snap)
    elif rest_normals.written(scene):
        rest_normals.remove(scene)
    if not pairs:
        return 0
    if record is None:
        counts: dict[tuple[str, str], int] = {}
        for lamp_name, mover_name, index in layout:
            counts[lamp_name, mover_name] = max(counts.get((lamp_name, mover_name), 0), int(index) + 1)
        mover_names = sorted({mover for _, mover in counts})
        _build(scene, [(scene.objects[lamp], mover, n) for (lamp, mover), n in counts.items()], mover_names)
    copies = {tuple(bpy.data.objects[name][COPY_KEY]): bpy.data.objects[name] for name in _record(scene)["copies"]}
    used = {(lamp.name, mover.name): 1 if s is None else len(s[0]) for lamp, mover, _, s in placed}
    for (lamp_name, mover_name, index), copy in copies.items():  # only a bake's kept copies are ever hidden
        _set(copy, "hide_render", int(index) >= used.get((lamp_name, mover_name), 0))
    for lamp, mover, matrix, stand_ins in placed:
        if stand_ins is None:
            copy = copies[(lamp.name, mover.name, "0")]
            doppler_factor, turned = placement(matrix, lamp.data.type, mover)
            k = incidence(matrix, lamp.data.type, mover)
            angle = lamp_doppler.aberrated_disc_angle(k, mover.beta, float(lamp.data.angle))
            write_copy(copy, lamp, copy_colour(lamp, doppler_factor, snap), turned, angle=angle)
            continue
        offsets, dopplers = stand_ins
        _write_stand_ins(
            lamp,
            mover,
            matrix,
            offsets,
            dopplers,
            snap,
            [copies[(lamp.name, mover.name, str(i))] for i in range(len(offsets))],
        )
    return len(layout)


def write_copy(
    copy: Object,
    lamp: Object,
    colour: tuple[float, ...],
    matrix: FloatArray,
    power_factor: float | None = None,
    angle: float | None = None,
) -> None:
    """The copy of ``lamp`` with its settings, ``colour`` and world ``matrix`` (``power_factor``: its
    energy; ``angle``: a sun's disc as the object sees it, ``lamp_doppler.aberrated_disc_angle``)."""
    own = {"energy"} if power_factor is not None else set()
    _follow(copy.data, lamp.data, frozenset(own | ({"angle"} if angle is not None else set())))
    if angle is not None:
        _set(copy.data, "angle", min(angle, math.pi))  # Blender's largest sun
    if power_factor is not None:
        _set(copy.data, "energy", float(lamp.data.energy) * power_factor)
    _set(copy.data, "use_temperature", False)
    _set(copy.data, "color", colour)
    if not np.allclose(np.array(copy.matrix_world), matrix, rtol=1e-6, atol=1e-9):
        copy.matrix_world = mathutils.Matrix(matrix.tolist())


def _write_stand_ins(lamp, mover, matrix, offsets, dopplers, snap, copies):
    """The stand-ins of ``lamp`` for ``mover``: moved along ``bhat`` to their offsets, the colour of
    the centre's ``D`` and the inputs of their trees (``lamp_stand_ins.py``)."""
    beta = np.array(mover.beta)
    speed = float(np.linalg.norm(beta))
    colours = [np.array(copy_colour(lamp, doppler, snap)) for doppler in dopplers]
    slope, curvature = lamp_stand_ins.colour_fit(dopplers, colours)
    base = tuple(float(v) for v in colours[1] * lamp_trees.tree_colour(lamp.data))
    axis = -matrix[:3, 2] / max(float(np.linalg.norm(matrix[:3, 2])), 1e-12)
    cone, blend = -2.0, 1e-6
    if lamp.data.type == "SPOT":
        cone, smooth = moving_lights.spot_cone(lamp.data.spot_size, lamp.data.spot_blend)
        blend = 1.0 / smooth if smooth > 0.0 else 1e-6
    far = lamp_stand_ins.FAR
    centre = np.array(mover.centre)
    lamp_distance = max(float(np.linalg.norm(centre - matrix[:3, 3])), 1e-9)
    for index, copy in enumerate(copies):
        moved = matrix.copy()
        moved[:3, 3] += offsets[index] * beta / speed
        # without the tree (EEVEE) the copies share the lamp's light at the centre: (t / r)^2 / n each
        share = (max(float(np.linalg.norm(centre - moved[:3, 3])), 1e-9) / lamp_distance) ** 2 / len(copies)
        write_copy(copy, lamp, base, moved, share)
        values = {
            "Offset": float(offsets[index]),
            "Previous": float(offsets[index - 1]) if index > 0 else float(offsets[index]) - far,
            "Next": float(offsets[index + 1]) if index + 1 < len(offsets) else float(offsets[index]) + far,
            "Direction": tuple(float(v) for v in beta / speed),
            "Speed": speed,
            "Gamma": 1.0 / math.sqrt(1.0 - speed * speed),
            "Log Doppler": math.log(dopplers[1]),
            "Slope": slope,
            "Curvature": curvature,
            "Axis": tuple(float(v) for v in axis),
            "Cone": float(cone),
            "Blend": float(blend),
            "Lambert": 1.0 if lamp.data.type == "AREA" else 0.0,
            "Scale": 1.0 / share,
        }
        sockets = lamp_stand_ins.inputs(copy.data)
        for name, value in values.items():
            _set(sockets[name], "default_value", value)


def _copy_pairs(record):
    found = []
    for name in record["copies"]:
        obj = bpy.data.objects.get(name)
        found.append(list(obj[COPY_KEY]) if obj is not None and COPY_KEY in obj else ["", name])
    return found


def apply(scene: Scene, snap: Snapshot) -> int:
    return write(scene, snap)


def remove(scene: Scene) -> int:
    """Delete the copies, their light data and the collections, and the moving lights' lamps on
    moving objects; give the lamps back their own (empty) light linking. Returns the number of
    copies removed."""
    rest_normals.remove(scene)
    return moving_pairs.remove(scene) + _remove_copies(scene)


def _remove_copies(scene):
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
    nodes.remove_unused_groups([names.LAMP_STAND_IN_GROUP])
    return len(copies)


def warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """What this stage does not render right, one line each."""
    if snap.method != "GEOMETRY" or not modifier.any_applied(scene):
        return []
    found = [
        f"Light {obj.name!r} uses light linking: its light on moving objects is not Doppler shifted (eq. 18)"
        for obj in scene.objects
        if obj.type == "LIGHT" and _skipped_lamp(obj) and not is_copy(obj) and not moving_pairs.is_ours(scene, obj)
    ]
    found += [
        f"Object {obj.name!r} deforms: lamps light it as if it were at rest (eq. 18 not applied)"
        for obj in modifier.applied_objects(scene)
        if obj.relativity.motion == "ANIMATION" and obj.relativity.use_deformation
    ]
    preview_renders = snap.speed == 0.0 or exact_camera.final_render_problem(scene, snap) is not None
    if moving_lights.supported(snap) and not moving_lights.uses_lamps(snap) and preview_renders and movers(scene, snap):
        found.append(
            "Moving lights on moving objects: the render's material shader lights them as if at rest "
            "(docs/moving-lights.md); only the exact camera's final render (a moving observer) includes their motion"
        )
    record = _record(scene)
    found += (
        lamp_trees.warnings(scene.objects[name] for name in record["lamps"] if name in scene.objects) if record else []
    )
    moving = modifier.moving_objects(scene)
    unshifted = unshifted_light.sources(scene, moving) if moving else None
    if unshifted:
        found.append(
            f"Light {unshifted} reaches moving objects unshifted (eq. 18 not applied: 0.86x of it across "
            "the motion at 0.5c, far more off along it; docs/lamp-doppler.md)"
        )
    used = light_linking_collections(scene) if KEY in scene else 0  # (a pass over the objects)
    if used > MAX_LIGHT_LINKING:
        found.append(
            f"Lamps on moving objects need {used} light-linking collections, over Cycles' {MAX_LIGHT_LINKING}: "
            "some moving objects are lit wrongly; use fewer lamps or fewer moving objects"
        )
    return found


# Cycles renders at most this many light-linking collections (receivers and blockers) in a scene;
# beyond it the others are ignored ("Maximum number of light linking collections (64) exceeded").
MAX_LIGHT_LINKING = 64


def light_linking_collections(scene: Scene) -> int:
    """How many distinct collections the scene's objects use for light or shadow linking."""
    used = set()
    for obj in scene.objects:
        linking = getattr(obj, "light_linking", None)
        if linking is None:
            continue
        for collection in (linking.receiver_collection, linking.blocker_collection):
            if collection is not None:
                used.add(collection.name)
    return len(used)
