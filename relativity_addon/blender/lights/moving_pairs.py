"""A moving light lighting a moving object: the stand-in lamps' light with the receiver's motion
(Weiskopf et al. eqs. 18 and 19 with the relative Doppler factor; docs/moving-lights.md).

The moving light's stand-in lamps (``stand_in_lamps.py``) compute eq. 19 for surfaces at rest. A
moving object receives the photon in its own frame with ``D = D_L D_R`` (``D_R = gamma_R (1 -
beta_R . n)``), from the aberrated direction ``-k'`` and the distance ``r' = D_R r``. So per moving
light and moving object this module adds ``COUNT`` point lamps with the same shader, light-linked
to that object alone and given its velocity (``receiver_beta``); the stand-ins' own light linking
excludes the moving objects. The lamps are placed on the light's path over the times where the
object's bounding box sees the light in its own frame: ``x - D_R r k' = x_L(t_e) + u bhat_R``
(``lamp_doppler.apparent_lamp_offset`` with the emission point for the lamp), which lies on the path
when the two motions are parallel (exact there; otherwise its place along the path). The shader's
linear weights between them then sum Cycles' ``cos / t^2`` to eq. 18's ``cos(alpha') / r'^2``. Each
lamp is a sphere far too small to show (:func:`lamp_radius`), for Cycles' light tree. Unlike the
stand-ins, each lamp keeps its own light datablock (one OSL shader each at a render): its power is
its share of the light, which Cycles' light tree samples by, and a light's power is the
datablock's (an object's scale does not change a point light's).

A fixed number of lamps per pair, so an animation render or a bake keeps the same datablocks from
frame to frame. Everything made is recorded on the scene (``names.MOVING_PAIR_KEY``) and deleted by
:func:`remove`, which also gives the stand-ins back their empty light linking.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import bpy
import numpy as np

from ...physics import lamp_doppler
from ...physics.moving_lights import retarded_times, retarded_times_on_path
from ..common import busy, names
from ..geometry import motion as world_lines
from . import moving_lights, stand_in_lamps, stand_in_lights, stand_in_paths

if TYPE_CHECKING:
    from collections.abc import Sequence

    from bpy.types import Object, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import MovingLight, Snapshot

KEY = names.MOVING_PAIR_KEY
COPY_KEY = names.MOVING_PAIR_COPY_KEY
PREFIX = names.MOVING_PAIR_PREFIX
COUNT = 6  # lamps per light and object (the most; the unused ones hidden): two light a point
MAX_ANGLE = 0.1  # radians between neighbouring lamps seen from the nearest point (the terminator's error)
PADDING = 0.05  # the span widened by this fraction on each side
# the stand-in shader's inputs that place one lamp on the path (the rest are the light's, copied)
_OWN = {
    *("strip", "lamp_time", "previous_time", "previous_position", "next_time", "next_position"),
    *("receiver_beta", "scale"),
}
SHARE_FLOOR = 0.05  # the least power share of a lamp (of the largest), so Cycles still samples it
# a lamp's radius over its distance to the object: not a point (see lamp_radius), far too small to show
RADIUS = 1e-5


def is_ours(scene: Scene, obj: Object) -> bool:
    """Whether ``obj`` is a moving light's stand-in (point or strip) or one of this module's lamps:
    a lamp at rest for nothing (the lamps-at-rest stage leaves it alone)."""
    if COPY_KEY in obj:
        return True
    if obj.type != "LIGHT" or obj.data.type == "SUN":  # a stand-in sun is a plane wave in the scene frame
        return False
    return any(obj.name in found for found in stand_in_lamps.stand_in_names(scene).values())


def _record(scene):
    return scene[KEY].to_dict() if KEY in scene else None


def _path_times(scene, snap, light, values, reception_time, points):
    """``(c (t_e - t_reception), emission positions, path velocity there)`` for ``points``."""
    camera = np.asarray(values["camera_position"], float)
    if light.motion != "ANIMATION":
        origin, beta = np.array(values["light_position"], float), np.array(light.beta, float)
        times, _ = retarded_times(points, camera, origin, beta)
        return times, origin + times[:, None] * beta, np.broadcast_to(beta, points.shape)

    def where(at):
        return stand_in_paths.path_positions(scene, snap, light, values, reception_time, np.asarray(at, float))

    here = where([0.0])[0]
    reach = float(np.max(np.linalg.norm(points - camera, axis=-1) + np.linalg.norm(points - here, axis=-1)))
    knots = np.linspace(-4.0 * reach, 0.0, 257)
    speed = float(np.max(np.linalg.norm(np.diff(where(knots), axis=0), axis=-1)) / (knots[1] - knots[0]))
    knots = np.linspace(-reach * 2.0 / (1.0 - min(speed, 0.999)), 0.0, 513)
    times, _ = retarded_times_on_path(points, camera, knots, where(knots))
    step = 1e-3 * (knots[1] - knots[0])
    return times, where(times), (where(times + step) - where(times - step)) / (2.0 * step)


SURFACE_SAMPLES = 512  # the mesh's vertices (at most this many) that place a pair's lamps


def surface_samples(scene: Scene, snap: Snapshot, name: str) -> tuple[FloatArray, FloatArray]:
    """World points (where the camera sees them, scene frame) and rest-frame normals (world axes)
    of up to ``SURFACE_SAMPLES`` of object ``name``'s vertices: the points the pair's lamps light."""
    obj = scene.objects[name]
    count = len(obj.data.vertices)
    if count == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    co, normal = np.empty(count * 3, np.float32), np.empty(count * 3, np.float32)
    obj.data.vertices.foreach_get("co", co)
    obj.data.vertices.foreach_get("normal", normal)
    step = max(1, -(-count // SURFACE_SAMPLES))
    local = co.reshape(-1, 3)[::step].astype(np.float64)
    world, _ = world_lines.apparent_world_positions(scene, obj, obj, local, snap, shape_keys_too=False)
    normals = normal.reshape(-1, 3)[::step].astype(np.float64) @ np.linalg.inv(np.array(obj.matrix_world)[:3, :3])
    return np.asarray(world, float), normals / np.maximum(np.linalg.norm(normals, axis=-1, keepdims=True), 1e-30)


def pair_times(
    scene: Scene,
    snap: Snapshot,
    light: MovingLight,
    points: FloatArray,
    normals: FloatArray,
    mover_beta: Sequence[float],
) -> tuple[FloatArray, FloatArray]:
    """The lamp times (ascending, ``c (t - t_reception)``; 2 to ``COUNT``, ``MAX_ANGLE`` apart seen
    from the nearest point) spanning where the object's ``points`` that face the light see it in
    their own frame, projected on the path (``x_L(t_e) + u bhat_R``), and the lamps' power shares
    (the largest 1): their mean weights over those points that face the camera too (Cycles' light
    tree samples lamps by power, and only two of them light a point)."""
    values = moving_lights.shader_parameters(light, snap)
    reception_time = moving_lights.reception_event(snap)[0]
    times, sources, velocity = _path_times(scene, snap, light, values, reception_time, points)
    beta_r = np.asarray(mover_beta, float)
    bhat = beta_r / np.linalg.norm(beta_r)
    u = lamp_doppler.apparent_lamp_offset(points, sources, beta_r)
    speed2 = np.sum(velocity * velocity, axis=-1)
    seen = times + np.where(speed2 > 0.0, u * (velocity @ bhat) / np.where(speed2 > 0.0, speed2, 1.0), 0.0)
    apparent = sources + u[:, None] * bhat  # where each point sees the light in its own frame
    usable = np.isfinite(seen)
    facing = usable & (np.sum(normals * (apparent - points), axis=-1) > 0.0)
    usable = facing if facing.any() else usable
    if not usable.any():
        return np.linspace(-1.0, 0.0, 2), np.ones(2)
    low, high = float(seen[usable].min()), float(seen[usable].max())
    pad = max(PADDING * (high - low), 1e-3 * max(1.0, abs(low)))
    along = float(np.sqrt(np.max(speed2[usable])))
    distance = np.linalg.norm(apparent - points, axis=-1)[usable]  # the object-frame D_R r
    spread = lamp_doppler.stand_in_offsets([along * (low - pad), along * (high + pad)], distance, MAX_ANGLE, COUNT)
    times = np.linspace(low - pad, high + pad, max(len(spread), 2))
    camera = np.asarray(values["camera_position"], float)
    seen_by_camera = usable & (np.sum(normals * (camera - points), axis=-1) > 0.0)  # the light the camera sees
    shares = lamp_doppler.stand_in_weights(seen[seen_by_camera if seen_by_camera.any() else usable], times).mean(axis=0)
    return times, np.maximum(shares / max(float(shares.max()), 1e-12), SHARE_FLOOR)


def lamp_radius(points: FloatArray, positions: FloatArray) -> float:
    """The pair lamps' radius: RADIUS of the nearest lamp-to-point distance (1e-5 m without points).

    Cycles builds one light tree over every lamp and cuts a light set's tree out of it. Its cost
    of a cluster is its power times its box's area, or the box's length when the area is zero: a
    cluster of point lamps on a line (the pair lamps alone) costs a length, one holding a moving
    light's strips (thin area lights along the same line) an area, so the tree mixes the two kinds
    differently from how either alone would, and the object's cut-out tree sampled its lamps badly
    (docs/moving-lights.md: 10.6 % per pixel against 1.6 % with point stand-ins). A radius gives every
    cluster an area; the light and the shadows change by about ``radius / distance``."""
    if len(points) == 0 or len(positions) == 0:
        return RADIUS
    nearest = float(np.min(np.linalg.norm(points[:, None, :] - positions[None, :, :], axis=-1)))
    return RADIUS * max(nearest, 1e-3)


def _value(value):
    return tuple(float(v) for v in value) if hasattr(value, "__len__") and not isinstance(value, str) else value


def _collection(name, objects, state):
    collection = bpy.data.collections.new(name)
    for obj in objects:
        collection.objects.link(obj)
    for entry in collection.collection_objects:
        entry.light_linking.link_state = state
    return collection


def _build(scene, light_names, mover_names):
    record: dict[str, Any] = {"copies": [], "lights": [], "collections": [], "exclude": ""}
    scene[KEY] = record  # recorded first: a failure half-way is still removed
    movers = [scene.objects[name] for name in mover_names]
    exclude = _collection(f"{PREFIX} not moving", movers, "EXCLUDE")
    record["exclude"] = exclude.name
    record["collections"].append(exclude.name)
    for light_name in light_names:
        for obj in movers:
            receive = _collection(f"{PREFIX} {light_name} on {obj.name}", [obj], "INCLUDE")
            record["collections"].append(receive.name)
            for index in range(COUNT):
                copy = stand_in_lamps.new_point_lamp(scene, f"{PREFIX} {light_name} on {obj.name} {index}")
                copy[COPY_KEY] = [light_name, obj.name, str(index)]
                copy.hide_select = True
                copy.light_linking.receiver_collection = receive
                record["copies"].append(copy.name)
                record["lights"].append(copy.data.name)
    scene[KEY] = record


def write(scene: Scene, snap: Snapshot, movers: Sequence[Any]) -> list[str]:
    """Light ``movers`` (``lamps_on_moving_objects.Mover``) by the moving lights' stand-ins with their
    motion included. Returns the names of the objects lit so (they need rest normals)."""
    stand_ins = stand_in_lamps.stand_in_names(scene)
    lights = [
        light
        for light in (moving_lights.supported(snap) if moving_lights.uses_lamps(snap) and movers else [])
        if light.kind != "SUN" and light.name in stand_ins
    ]
    if not lights:
        if busy.keeps_stand_ins() and KEY in scene:  # a bake's frames: kept under their names, hidden
            for name in _record(scene)["copies"]:
                obj = bpy.data.objects.get(name)
                if obj is not None and not obj.hide_render:
                    obj.hide_render = True
        else:
            remove(scene)
        return []
    light_names, mover_names = sorted(light.name for light in lights), sorted(mover.name for mover in movers)
    layout = sorted([lamp, mover, str(i)] for lamp in light_names for mover in mover_names for i in range(COUNT))
    record = _record(scene)
    kept = (
        sorted(list(bpy.data.objects[n][COPY_KEY]) for n in record["copies"] if n in bpy.data.objects) if record else []
    )
    if record is not None and kept != layout:
        remove(scene)
        record = None
    if record is None:
        _build(scene, light_names, mover_names)
        record = _record(scene)
    exclude = bpy.data.collections[record["exclude"]]
    copies = {tuple(bpy.data.objects[name][COPY_KEY]): bpy.data.objects[name] for name in record["copies"]}
    surfaces = {mover.name: surface_samples(scene, snap, mover.name) for mover in movers}
    for light in lights:
        first = None
        for name in stand_ins[light.name]:
            obj = bpy.data.objects.get(name)
            if obj is None:
                continue
            first = first or obj
            if obj.light_linking.receiver_collection != exclude:
                obj.light_linking.receiver_collection = exclude
        if first is None:  # its stand-ins are gone (the stage makes them again at the next sync)
            continue
        shared = {
            socket.name: socket.default_value
            for socket in first.data.node_tree.nodes[names.MOVING_LAMP_PREFIX].inputs
            if socket.name not in _OWN and not socket.is_linked  # linked: the stand-in's own (PER_LAMP)
        }
        values = moving_lights.shader_parameters(light, snap)
        reception_time = moving_lights.reception_event(snap)[0]
        for mover in movers:
            points, normals = surfaces[mover.name]
            times, shares = pair_times(scene, snap, light, points, normals, mover.beta)
            positions = stand_in_paths.path_positions(scene, snap, light, values, reception_time, times)
            radius = lamp_radius(points, positions)
            for index in range(len(times), COUNT):
                copy = copies[(light.name, mover.name, str(index))]
                if not copy.hide_render:
                    copy.hide_render = True
            for index in range(len(times)):
                copy = copies[(light.name, mover.name, str(index))]
                before, after = max(index - 1, 0), min(index + 1, len(times) - 1)
                inputs = dict(
                    shared,
                    strip=0,
                    lamp_time=float(times[index]),
                    previous_time=float(times[before]),
                    previous_position=tuple(float(v) for v in positions[before]),
                    next_time=float(times[after]),
                    next_position=tuple(float(v) for v in positions[after]),
                    receiver_beta=tuple(float(v) for v in mover.beta),
                    scale=1.0 / float(shares[index]),
                )
                energy = 4.0 * math.pi * float(shares[index])
                if not math.isclose(copy.data.energy, energy, rel_tol=1e-6):
                    copy.data.energy = energy
                if not math.isclose(copy.data.shadow_soft_size, radius, rel_tol=1e-4):
                    copy.data.shadow_soft_size = radius
                stand_in_lights.write_inputs(copy, {k: _value(v) for k, v in inputs.items()})
                location = tuple(float(v) for v in positions[index])
                if not np.allclose(tuple(copy.location), location, rtol=1e-7, atol=1e-9):
                    copy.location = location
                for key in ("visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume_scatter"):
                    if getattr(copy, key) != getattr(first, key):
                        setattr(copy, key, getattr(first, key))
                if copy.lightgroup != first.lightgroup:
                    copy.lightgroup = first.lightgroup
                if copy.hide_render:
                    copy.hide_render = False
    return mover_names


def remove(scene: Scene) -> int:
    """Delete the lamps, their light data and collections; the stand-ins' light linking back to
    none. Returns the number of lamps removed."""
    record = _record(scene)
    if record is None:
        return 0
    for found in stand_in_lamps.stand_in_names(scene).values():
        for name in found:
            obj = bpy.data.objects.get(name)
            receiver = obj.light_linking.receiver_collection if obj is not None else None
            if receiver is not None and receiver.name in record["collections"]:
                obj.light_linking.receiver_collection = None
    copies = [bpy.data.objects.get(name) for name in record["copies"]]
    for obj in copies:
        if obj is not None:
            stand_in_lights.delete_lamp(obj.name)
    for name in record["lights"]:
        light = bpy.data.lights.get(name)
        if light is not None and light.users == 0:
            bpy.data.lights.remove(light)
    for name in record["collections"]:
        collection = bpy.data.collections.get(name)
        if collection is not None:
            bpy.data.collections.remove(collection)
    del scene[KEY]
    return sum(obj is not None for obj in copies)
