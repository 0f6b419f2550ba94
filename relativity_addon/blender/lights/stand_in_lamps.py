"""Moving lights behind Cycles' OSL camera, with shadows: stand-in point lamps on the light's path.

A material's OSL ``trace()`` crashes Cycles behind an OSL camera (docs/moving-lights.md), so the
material shader of ``moving_lights.py`` cannot cast shadows there. Here Cycles' own lamps do:
each moving light gets a few point lamps (radius 0) on its straight path, spread over the
retarded positions that the surfaces near the camera see, and Cycles traces their shadow rays.
Each lamp's light shader (``shaders/relativistic_moving_lamp.osl``) computes, for the receiving
point, the light's exact retarded position and gives the two lamps around it linear weights and
the strength ``w D^4 (t / r)^3``: a diffuse surface then gets eq. 19's ``D^4 I cos / r^2`` exactly,
and its shadow is the weighted blend of the two lamps' shadows. Two sharp shadows one lamp spacing
apart blend into a stepped edge, so each lamp is drawn out into a line along the path (LINE lamp
spacings long: LINE_SIDES thin one-sided area lights, the shader spreading the lamp's light over
them): its shadow is soft along the path only, and the neighbours' soft shadows, weighted, put the
half-shadow where each point's own retarded position does (docs/moving-lights.md).

The lamps are placed from ``scene.ray_cast`` over the camera's view (a grid of its rays, 5 %
wider, from its reception event): the hit points that get at least 1 % of the brightest one's irradiance set the
span of retarded times (``physics.moving_lights.lamp_times``). A light's lamps share one light
datablock (Cycles compiles one OSL shader per datablock at every render): what differs between them
(:data:`PER_LAMP`) is on each lamp object, read by Attribute nodes. Everything made here (objects,
the light, the shader text) is named ``names.MOVING_LAMP_PREFIX``, listed on the scene and deleted
by :func:`remove`; the user's light is hidden by ``moving_lights.py``.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING, Any

import bpy
import numpy as np
from mathutils import Matrix, Vector

from ...errors import RelativityError
from ...physics import spectral_render
from ...physics.lorentz import camera_to_scene_direction
from ...physics.moving_lights import (
    end_on_share,
    lamp_times,
    retarded_times,
    retarded_times_on_path,
    sun_in_scene_frame,
)
from ..camera import cockpit
from ..colour import light_groups, materials
from ..common import busy, names, osl
from ..scene import animation, lens
from . import lamp_shader, lamp_trees

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence

    import numpy.typing as npt
    from bpy.types import Depsgraph, Light, Object, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import MovingLight, Snapshot

MAX_LAMPS = 16  # per moving light: each costs Cycles light samples (only two light a point); more: sharper shadows
KERNEL = 0.5  # the box of path each point is lit from (continuous shadows), in lamp spacings
STRIP_SIDES = 3  # one-sided strips per lamp (lines) or piece of the path (Continuous), facing 120 degrees apart
STRIP_WIDTH = 1e-3  # a strip's width over its length
LINE_SIDES = 3  # strips per line, facing 120 degrees apart (two facing opposite ways: a plane seen edge on)
LINE = 1.25  # Blended Lamps: each lamp a line (strips) this many lamp spacings long along the path (0: points)
END_ON = 0.2  # point lamps instead of lines when this share of the lit points' light comes along the path
SPACING = 0.1  # wanted distance between neighbouring lamps, as a fraction of the median light distance


def view_directions(
    scene: Scene, snap: Snapshot, columns: int = 32, rows: int = 24, margin: float = 0.05
) -> FloatArray:
    """Scene-frame directions of a grid over the camera's view, widened by ``margin`` (the exact
    camera's rays: the pinhole direction in the camera frame, aberrated into the scene frame unless
    a Lorentz window keeps it, Gray eq. 6)."""
    left, right, bottom, top = lens.view_window(scene, scene.objects[snap.camera])
    widen_x, widen_y = margin * (right - left), margin * (top - bottom)
    x = np.linspace(left - widen_x, right + widen_x, columns)
    y = np.linspace(bottom - widen_y, top + widen_y, rows)
    local = np.stack(np.broadcast_arrays(x[None, :], y[:, None], -1.0), axis=-1).reshape(-1, 3)
    world = local @ np.array(snap.camera_matrix)[:3, :3].T
    world /= np.linalg.norm(world, axis=-1, keepdims=True)
    if snap.exact_camera and snap.use_geometry and not snap.use_lorentz_window and any(snap.beta):
        # Gray eq. (2) carries photon directions: the photon arriving along a view direction
        # travels the other way (as the camera shader's scene_ray_direction does)
        world = -camera_to_scene_direction(-world, snap.beta)
    return world


def visible_points(
    scene: Scene, snap: Snapshot, depsgraph: Depsgraph | None, origin: npt.ArrayLike
) -> npt.NDArray[Any]:
    """Surface points the camera sees (the first hit of each ray of :func:`view_directions`)."""
    if depsgraph is None:
        try:
            depsgraph = bpy.context.evaluated_depsgraph_get()
        except (AttributeError, RuntimeError):
            return np.zeros((0, 3))
    points = []
    for direction in view_directions(scene, snap):
        hit, location, *_rest = scene.ray_cast(depsgraph, origin, tuple(float(v) for v in direction))
        if hit:
            points.append(tuple(location))
    return np.array(points, float).reshape(-1, 3)


def _spacing(times, irradiance, speed):
    """Wanted ``c t`` between lamps: SPACING of the median distance of the lit points, over the speed."""
    lit = np.isfinite(irradiance) & (irradiance >= 0.01 * np.nanmax(irradiance))
    distance = float(np.median(1.0 / np.sqrt(irradiance[lit])))  # ~ r (D^4 ~ 1 for a typical point)
    return SPACING * distance / max(speed, 1e-9)


def _keyframe_path(obj, snap, reception_time, times):
    """The animated light's world positions at the times ``c (t - t_reception)`` (keyframes)."""
    frames = snap.frame + (reception_time + np.asarray(times, float)) / snap.speed_of_light * snap.fps
    return animation.world_matrices(obj, frames)[:, :3, 3]


def lamp_path(
    scene: Scene,
    snap: Snapshot,
    light: MovingLight,
    values: Mapping[str, Any],
    reception_time: float,
    points: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Where the stand-in lamps go: their times ``c (t - t_reception)`` on the light's path (ascending)
    and positions, for these surface points (the lit ones' retarded times; at least one lamp)."""
    camera_position = values["camera_position"]
    if light.motion != "ANIMATION":
        origin, beta = np.array(values["light_position"], float), np.array(light.beta, float)
        speed = float(np.linalg.norm(beta))
        if len(points) == 0 or speed == 0.0:
            return np.zeros(1), origin[None, :]
        times, irradiance = retarded_times(points, camera_position, origin, beta)
        times = lamp_times(times, irradiance, _spacing(times, irradiance, speed), MAX_LAMPS)
        return times, origin + times[:, None] * beta
    obj = scene.objects[light.name]  # its keyframes were checked by snapshot.moving_lights
    here = _keyframe_path(obj, snap, reception_time, [0.0])[0]
    if len(points) == 0:
        return np.zeros(1), here[None, :]
    reach = float(np.max(np.linalg.norm(points - camera_position, axis=-1) + np.linalg.norm(points - here, axis=-1)))
    knots = np.linspace(-4.0 * reach, 0.0, 257)
    path = _keyframe_path(obj, snap, reception_time, knots)
    speed = float(np.max(np.linalg.norm(np.diff(path, axis=0), axis=-1)) / (knots[1] - knots[0]))
    if speed >= 1.0:
        raise RelativityError(f"Light {light.name!r} moves at {speed:.3f}c on its keyframes (must be below c)")
    if speed == 0.0:
        return np.zeros(1), here[None, :]
    knots = np.linspace(-reach * 2.0 / (1.0 - speed), 0.0, 513)
    times, irradiance = retarded_times_on_path(
        points, camera_position, knots, _keyframe_path(obj, snap, reception_time, knots)
    )
    times = lamp_times(times, irradiance, _spacing(times, irradiance, speed), MAX_LAMPS)
    return times, _keyframe_path(obj, snap, reception_time, times)


# --- the stand-in lamps ---------------------------------------------------------------------


# the shader's inputs that differ between the lamps of one light: each lamp object's own custom
# properties (names.MOVING_LAMP_INPUT_KEY + input), read by Attribute nodes in the light's one node
# tree; the rest are the script node's values. Cycles compiles (JIT) one OSL shader per light
# datablock at every render, so one datablock for all of a light's lamps (docs/performance.md).
PER_LAMP = (
    *("lamp_time", "lamp_position", "previous_time", "previous_position", "next_time", "next_position"),
    *("after_time", "after_position", "strip_normal", "strip_length"),
)


def lamp_key(name: str) -> str:
    """The custom property of a stand-in object holding its shader input ``name`` (PER_LAMP)."""
    return names.MOVING_LAMP_INPUT_KEY + name


def _new_light(name, text, kind="POINT", per_lamp=()):
    """A light with the moving-lamp shader; its inputs ``per_lamp`` linked from Attribute nodes
    reading the lamp object's custom properties (:func:`lamp_key`)."""
    light = bpy.data.lights.new(name, kind)
    if kind == "SUN":  # direction, strength and angle are written by _write_sun; no shader
        return light
    light.energy = 4.0 * math.pi  # 1 W/sr: the shader's Emission carries the intensity
    light.color = (1.0, 1.0, 1.0)
    if kind == "AREA":  # a strip along a piece of the path: the object's scale gives its length (_place_strip)
        light.shape = "RECTANGLE"
        light.size, light.size_y = 1.0, STRIP_WIDTH
    else:
        light.shadow_soft_size = 0.0
    with warnings.catch_warnings():  # 5.x: use_nodes is deprecated (always on)
        warnings.simplefilter("ignore", DeprecationWarning)
        light.use_nodes = True
    tree = light.node_tree
    tree.nodes.clear()
    node = tree.nodes.new("ShaderNodeScript")
    node.name = node.label = names.MOVING_LAMP_PREFIX
    node.mode = "INTERNAL"
    with osl.compiling():
        node.script = text
    if "Emission" not in node.outputs or "lamp_time" not in node.inputs:
        bpy.data.lights.remove(light)
        raise RelativityError("The moving-lamp OSL shader did not compile (no sockets on its script node)")
    for index, key in enumerate(per_lamp):
        attribute = tree.nodes.new("ShaderNodeAttribute")
        attribute.name = attribute.label = key
        attribute.attribute_type = "OBJECT"
        attribute.attribute_name = lamp_key(key)
        attribute.location = (-300.0, -60.0 * index)
        socket = node.inputs[key]
        tree.links.new(attribute.outputs["Fac" if socket.type == "VALUE" else "Vector"], socket)
    output = tree.nodes.new("ShaderNodeOutputLight")
    output.location = (300.0, 0.0)
    tree.links.new(node.outputs["Emission"], output.inputs["Surface"])
    return light


def _new_object(scene, name, light):
    obj = bpy.data.objects.new(name, light)
    obj.rotation_mode = "QUATERNION"
    if light.type != "SUN":
        obj.visible_camera = False  # a strip is no surface the camera sees
    scene.collection.objects.link(obj)
    return obj


def _is_shared(light):
    """Whether ``light`` is a stand-in light that reads its lamps' own inputs from the objects."""
    if light.type == "SUN":
        return True
    tree = light.node_tree
    node = tree.nodes.get(names.MOVING_LAMP_PREFIX) if tree is not None else None
    return node is not None and all(node.inputs[key].is_linked for key in PER_LAMP)


def new_point_lamp(scene: Scene, name: str) -> Object:
    """A point lamp (radius 0, power 4 pi) with its own light and moving-lamp shader, its inputs
    unset (:func:`write_inputs`)."""
    return _new_object(scene, name, _new_light(name, lamp_shader.shader_text()))


def stand_in_names(scene: Scene) -> dict[str, list[str]]:
    """``{light name: [its stand-in lamps' object names]}`` (``names.MOVING_LAMPS_KEY``)."""
    return _record(scene)


def delete_lamp(name: str) -> None:
    """Delete the lamp object ``name`` (if any) and its light data once nothing else uses it."""
    obj = bpy.data.objects.get(name)
    if obj is None:
        return
    light = obj.data
    bpy.data.objects.remove(obj)
    if light is not None and light.users == 0:
        bpy.data.lights.remove(light)


def _same(a, b):
    return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-9)


def _set(owner, key, value):
    """Write only a changed value (a write triggers a depsgraph update, whose handler syncs)."""
    current = getattr(owner, key)
    if isinstance(value, tuple):
        value = value + tuple(current)[len(value) :]
        if all(_same(a, b) for a, b in zip(current, value, strict=True)):
            return
    elif _same(current, value):
        return
    setattr(owner, key, value)


def _record(scene):
    stored = scene.get(names.MOVING_LAMPS_KEY)
    return {} if stored is None else {key: list(value) for key, value in stored.to_dict().items()}


def _lamps_for(scene, light_name, count, text, kind="POINT", keep=False):
    """The light's first ``count`` lamps, sharing one light datablock; while a bake steps frames
    (``busy.keeps_stand_ins``) or ``keep`` (a render runs: :func:`reserve`) the others are kept,
    hidden from renders, and more are added under the next names when needed."""
    record = _record(scene)
    existing = [name for name in record.get(light_name, []) if bpy.data.objects.get(name) is not None]
    lights = {bpy.data.objects[name].data for name in existing}
    same_kind = len(lights) <= 1 and all(light.type == kind and _is_shared(light) for light in lights)
    kept = (busy.keeps_stand_ins() or keep) and same_kind
    if len(existing) < count or (not kept and (len(existing) != count or not same_kind)):
        if not kept:
            for name in existing:
                delete_lamp(name)
            existing = []
        if existing:
            light = bpy.data.objects[existing[0]].data
        else:
            light = _new_light(f"{names.MOVING_LAMP_PREFIX} {light_name}", text, kind, PER_LAMP)
        existing += [
            _new_object(scene, f"{names.MOVING_LAMP_PREFIX} {light_name} {index}", light).name
            for index in range(len(existing), count)
        ]
        record[light_name] = existing
        scene[names.MOVING_LAMPS_KEY] = record
    lamps = [bpy.data.objects[name] for name in existing]
    for index, obj in enumerate(lamps):
        _set(obj, "hide_render", index >= count)
    return lamps[:count]


def _capacity(obj):
    """``(lamps the stand-ins of this kind can hold at most, strips or lamps per lamp)`` for a
    light's stand-in ``obj``: MAX_LAMPS points or lines, or MAX_LAMPS - 1 pieces of strips."""
    if obj.data.type == "POINT":
        return MAX_LAMPS, 1
    if obj.data.node_tree.nodes[names.MOVING_LAMP_PREFIX].inputs["strip"].default_value == 1:
        return MAX_LAMPS - 1, STRIP_SIDES
    return MAX_LAMPS, LINE_SIDES


def reserve(scene: Scene) -> None:
    """Before a render (``render_init``): give every moving light as many stand-ins as it can use,
    those not in use hidden from renders. Between Render Animation's frames none are made or deleted
    (Blender 5.2 crashed, :func:`write`), so a frame that needs more lamps than the first (a keyframed
    light at rest before the first frame has one) takes them from these instead of making do with
    the first frame's count. Not for the cockpit: made in its render (its Render Layers node), they
    crashed Blender 5.2 (``test_cockpit_lamp.py``)."""
    if cockpit.is_applied(scene):
        return
    record = _record(scene)
    for light_name, existing in record.items():
        objects = [bpy.data.objects.get(name) for name in existing]
        if not objects or any(obj is None for obj in objects) or objects[0].data.type == "SUN":
            continue
        lights = {obj.data for obj in objects}
        if len(lights) != 1 or not _is_shared(objects[0].data):
            continue
        lamps, sides = _capacity(objects[0])
        for index in range(len(existing), lamps * sides):
            obj = _new_object(scene, f"{names.MOVING_LAMP_PREFIX} {light_name} {index}", objects[0].data)
            obj.hide_render = True
            existing.append(obj.name)
        record[light_name] = existing
    if record:
        scene[names.MOVING_LAMPS_KEY] = record


def _held(scene, light_name):
    """How many lamps (times) the light's stand-ins, hidden ones included, hold (0: none)."""
    objects = [bpy.data.objects.get(name) for name in _record(scene).get(light_name, [])]
    if not objects or any(obj is None or obj.data.type not in {"POINT", "AREA"} for obj in objects):
        return 0
    lamps, sides = _capacity(objects[0])
    return len(objects) // sides + (lamps == MAX_LAMPS - 1)  # Continuous: pieces, one time more


def hide(scene: Scene) -> None:
    """Hide every stand-in lamp from renders, keeping it: the preview's sync between the frames a
    bake steps (``busy.keeps_stand_ins``), where the next frame's final render uses them again."""
    for names_of_light in _record(scene).values():
        for name in names_of_light:
            obj = bpy.data.objects.get(name)
            if obj is not None:
                _set(obj, "hide_render", True)


def _stored_times(scene, light_name):
    """The stand-ins' times of the last placement (their own inputs), or None."""
    objects = [bpy.data.objects.get(name) for name in _record(scene).get(light_name, [])]
    if not objects or any(obj is None or obj.data.type not in {"POINT", "AREA"} for obj in objects):
        return None
    objects = [obj for obj in objects if not obj.hide_render]  # a bake's unused lamps are hidden
    if not objects or any(lamp_key("lamp_time") not in obj for obj in objects):
        return None
    times = [float(obj[lamp_key("lamp_time")]) for obj in objects]
    if objects[0].data.type == "AREA":  # LINE_SIDES strips per lamp (lines) or STRIP_SIDES per piece
        inputs = objects[0].data.node_tree.nodes[names.MOVING_LAMP_PREFIX].inputs
        if inputs["strip"].default_value == 1:  # the pieces' starts and the last end
            times = times[::STRIP_SIDES] + [float(objects[-1].get(lamp_key("next_time"), times[-1]))]
        else:
            times = times[:: inputs["strip_sides"].default_value]
    return np.array(times, float)


def _use_lines(points, camera_position, times, positions):
    """Whether the lamps at ``times`` (``positions``) are drawn out into lines: unless the surface
    points see the path nearly end on (within 6 degrees of it for END_ON of their light), where a
    strip along it would be seen edge on and light them through a sliver (or not at all)."""
    if LINE <= 0.0 or len(times) < 2:
        return False
    if len(points) == 0:
        return True
    point_times, irradiance = retarded_times_on_path(points, camera_position, times, positions)
    return end_on_share(point_times, irradiance, points, times, positions, sin_limit=0.1) <= END_ON


def _stored_lines(scene, light_name):
    """Whether the last placement drew the lamps of ``light_name`` as lines."""
    objects = [bpy.data.objects.get(name) for name in _record(scene).get(light_name, [])]
    if not objects or objects[0] is None or objects[0].data.type != "AREA":
        return False
    return objects[0].data.node_tree.nodes[names.MOVING_LAMP_PREFIX].inputs["strip"].default_value == 2


def path_positions(
    scene: Scene, snap: Snapshot, light: MovingLight, values: Mapping[str, Any], reception_time: float, times: Any
) -> FloatArray:
    """The light's positions at the times ``c (t - t_reception)``."""
    if light.motion == "ANIMATION":
        return np.asarray(_keyframe_path(scene.objects[light.name], snap, reception_time, times), dtype=np.float64)
    path = np.array(values["light_position"], float) + np.outer(times, np.array(light.beta, float))
    return np.asarray(path, dtype=np.float64)


def write(
    scene: Scene,
    snap: Snapshot,
    lights: Sequence[MovingLight],
    parameters: Callable[[MovingLight], Mapping[str, Any]],
    reception_time: float,
    depsgraph: Depsgraph | None = None,
) -> None:
    """Place and set the stand-in lamps of ``lights`` (``parameters(light)``: the material
    shader's inputs, ``moving_lights.shader_parameters``; ``reception_time`` ``c (t_reception -
    t_o)``); delete those of lights no longer moving. They are placed (ray casts) when a depsgraph
    is given or none exist yet; without one, the last placement's times are kept and the lamps move
    along the path to them."""
    text = lamp_shader.shader_text()
    record = _record(scene)
    for stale in set(record) - {light.name for light in lights}:
        for name in record.pop(stale):
            delete_lamp(name)
        scene[names.MOVING_LAMPS_KEY] = record
    points = None
    observed = light_groups.observed_held(scene)
    colour = snap.colour
    for light in lights:
        if light.kind == "SUN":
            _write_sun(scene, light, _lamps_for(scene, light.name, 1, text, "SUN")[0])
            continue
        values = parameters(light)
        camera_position = np.asarray(values["camera_position"], float)
        stored = _stored_times(scene, light.name)
        times = None if depsgraph is not None else stored
        lines = _stored_lines(scene, light.name)
        keep = busy.rendering() or cockpit.is_applied(scene)
        if times is None:  # place them (the camera's view is ray-cast)
            if points is None:
                points = visible_points(scene, snap, depsgraph, values["camera_position"])
            times, positions = lamp_path(scene, snap, light, values, reception_time, points)
            if not (keep and stored is not None):  # while rendering the lamps stay what they are (below)
                lines = _use_lines(points, camera_position, times, positions)
            held = max(_held(scene, light.name), len(stored)) if stored is not None else 0
            if keep and stored is not None and len(times) > held:
                # no more than there are (hidden ones too, :func:`reserve`): stand-ins made and
                # deleted between Render Animation's frames (frame_change_post) crashed Blender
                # 5.2's render of the next frame, and at a frame change with the cockpit's Render
                # Layers node (docs/cockpit.md)
                ends = np.linspace(0.0, 1.0, len(times))
                times = np.interp(np.linspace(0.0, 1.0, held), ends, times)
                positions = path_positions(scene, snap, light, values, reception_time, times)
        else:  # no depsgraph (frame_change_pre, render_pre): the times of the last placement, moved on
            positions = path_positions(scene, snap, light, values, reception_time, times)
        shared = {
            key: values[key]
            for key in (
                "camera_position",
                "light_beta",
                "spot_axis",
                "spot_cos_half_angle",
                "spot_smooth",
                "temperature",
                "light_luminance",
                "wavelength_0",
                "wavelength_1",
                "wavelength_2",
                "spectral_scale",
                "basis_weights",
            )
        }
        if light.motion == "ANIMATION" and len(times) < 2:
            # one lamp: its keyframed path where the surfaces see it is at rest (lamp_path), where
            # the shader would carry it on at the frame's velocity (a light starting to move there)
            shared["light_beta"] = (0.0, 0.0, 0.0)
        shared["spectral"] = int(values["spectral"])
        shared["lambert"] = int(values["lambert"])
        # the fast mode's observed light group (light_groups.OBSERVED): the observer's shift too
        shared.update(
            observer_shift=int(observed and light.name in snap.observed_lights),
            observer_beta=tuple(float(v) for v in snap.beta),
            use_doppler=int(colour.use_doppler),
            spectral_searchlight=int(colour.spectral_searchlight),
            power_of_d=float(colour.power_of_d),
            camera_power=float(colour.camera_power),
        )
        if len(times) < 2 or snap.moving_light_shadows != "CONTINUOUS":
            _write_points(scene, light, text, shared, times, positions, camera_position, lines, keep)
        else:
            _write_strips(scene, light, text, shared, times, positions, camera_position, keep)


def _set_own(obj, key, value):
    """Write the custom property ``key`` of ``obj`` if it changed; whether it did."""
    current = obj.get(key)
    if isinstance(value, tuple):
        if hasattr(current, "__len__") and len(current) == len(value) and all(map(_same, current, value)):
            return False
        obj[key] = list(value)
    elif current is not None and not hasattr(current, "__len__") and _same(current, value):
        return False
    else:
        obj[key] = value
    return True


def write_inputs(obj: Object, inputs: Mapping[str, Any]) -> None:
    """Set the moving-lamp shader's inputs of lamp ``obj`` (only changed values): those its light
    reads from the object (Attribute nodes, :data:`PER_LAMP`) as the object's custom properties, the
    others on the script node (shared by the lamps of one light)."""
    node = obj.data.node_tree.nodes[names.MOVING_LAMP_PREFIX]
    changed = False
    for key, value in inputs.items():
        value = tuple(map(float, value)) if isinstance(value, tuple) else value
        socket = node.inputs[key]
        if socket.is_linked:
            changed = _set_own(obj, lamp_key(key), value) or changed
        else:
            _set(socket, "default_value", value)
    if changed:  # an ID property written from Python tags nothing: the viewport's render would not see it
        obj.update_tag()


def _place_strip(obj, centre, axis, length, side, camera_position, sides=STRIP_SIDES):
    """Set strip ``obj`` (an area light, 1 by STRIP_WIDTH) ``length`` long along ``axis`` at
    ``centre``, side ``side`` of ``sides`` facing 360 / ``sides`` degrees apart about the axis (the
    first toward the camera); returns its normal (it emits along it)."""
    first = camera_position - centre
    first = first - (first @ axis) * axis
    if not np.linalg.norm(first) > 1e-9 * max(length, 1.0):
        first = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    first /= np.linalg.norm(first)
    angle = 2.0 * math.pi * side / sides  # Rodrigues: the first normal turned about the axis
    normal = first * math.cos(angle) + np.cross(axis, first) * math.sin(angle)
    rotation = np.column_stack([axis, np.cross(-normal, axis), -normal])  # emits along its local -Z
    _set(obj, "location", tuple(float(v) for v in centre))
    _set(obj, "rotation_quaternion", tuple(Matrix(rotation.tolist()).to_quaternion()))
    # the light (1 x STRIP_WIDTH) is shared by the light's strips: the scale sets the length and width
    _set(obj, "scale", (max(length, 1e-6), max(length, 1e-6), 1.0))
    return normal


def _write_points(scene, light, text, shared, times, positions, camera_position, lines, keep=False):
    """A lamp at each time, lighting the points whose retarded times lie next to it: a point lamp,
    or (``lines``, two lamps or more) LINE_SIDES strips LINE lamp spacings long along the path."""
    last = len(times) - 1
    lines = lines and last > 0
    sides = LINE_SIDES if lines else 1
    lamps = _lamps_for(scene, light.name, sides * len(times), text, "AREA" if lines else "POINT", keep)
    for number, obj in enumerate(lamps):
        index, side = divmod(number, sides)
        before, after = max(index - 1, 0), min(index + 1, last)
        inputs = dict(
            shared,
            strip=2 if lines else 0,
            lamp_position=tuple(positions[index]),
            lamp_time=float(times[index]),
            previous_time=float(times[before]),
            previous_position=tuple(positions[before]),
            next_time=float(times[after]),
            next_position=tuple(positions[after]),
        )
        if lines:
            along = positions[after] - positions[before]
            gap = float(np.linalg.norm(along)) / (after - before)  # the lamp spacing here
            axis = along / max(float(np.linalg.norm(along)), 1e-30)
            normal = _place_strip(obj, positions[index], axis, LINE * gap, side, camera_position, sides)
            inputs.update(strip_normal=tuple(normal), strip_sides=sides)
        else:
            _set(obj, "location", tuple(float(v) for v in positions[index]))
        write_inputs(obj, inputs)


def _write_strips(scene, light, text, shared, times, positions, camera_position, keep=False):
    """STRIP_SIDES one-sided strips (thin area lights facing 120 degrees apart about the path) along
    each piece between the times: each point gets its light, and its shadow rays, from the path
    within KERNEL / 2 of the piece's duration around its own retarded time (the shader's box)."""
    pieces = len(times) - 1
    width = KERNEL  # in units of the piece's duration
    for index, obj in enumerate(_lamps_for(scene, light.name, STRIP_SIDES * pieces, text, "AREA", keep)):
        piece, side = divmod(index, STRIP_SIDES)
        start, end = positions[piece], positions[piece + 1]
        along = end - start
        length = float(np.linalg.norm(along))
        axis = along / max(length, 1e-30)
        normal = _place_strip(obj, 0.5 * (start + end), axis, length, side, camera_position)
        after = min(piece + 2, pieces)
        inputs = dict(
            shared,
            strip=1,
            lamp_position=tuple(start),
            lamp_time=float(times[piece]),
            previous_time=float(times[max(piece - 1, 0)]),
            previous_position=tuple(positions[max(piece - 1, 0)]),
            next_time=float(times[piece + 1]),
            next_position=tuple(end),
            after_time=float(times[after]),
            after_position=tuple(positions[after]),
            path_start=float(times[0]),
            path_end=float(times[-1]),
            kernel_width=width,
            strip_normal=tuple(normal),
            strip_length=length,
        )
        write_inputs(obj, inputs)


def fast_sun(user: Light, doppler: float) -> tuple[tuple[float, ...], float | None, float]:
    """``(colour, temperature or None, strength factor)`` of the stand-in for sun ``user`` seen at
    ``D`` in the fast mode (eq. 18 for a plane wave: irradiance ``D^3 S(lambda D)``): a blackbody
    sun is the blackbody at ``D T`` with ``D^-2 Y(D T)/Y(T)`` its strength (the spectral passes'
    brightness); an RGB sun keeps the ``D^2`` of its total with the colour of its shifted spectrum
    (``M(D) c`` at ``c``'s luminance), as moving RGB lamps keep eq. 19's ``D^4``."""
    colour, temperature = lamp_trees.rest_emission(user)  # its tree's Blackbody or Strength too
    if temperature is not None:
        log_ratio = spectral_render.log_blackbody_luminance(
            doppler * temperature
        ) - spectral_render.log_blackbody_luminance(temperature)
        return tuple(float(v) for v in colour), doppler * temperature, float(np.exp(log_ratio)) / doppler**2
    if user.use_temperature:  # a tinted blackbody: an RGB colour
        colour = colour * np.array(user.temperature_color[:3])
    shifted = spectral_render.gamut_map(spectral_render.doppler_rgb_matrix(doppler) @ colour)
    y, y_shifted = float(spectral_render.luminance(colour)), float(spectral_render.luminance(shifted))
    if y_shifted > 0.0:
        colour = shifted * (y / y_shifted)
    return tuple(float(v) for v in colour), None, doppler**2


def _write_sun(scene, light, obj):
    """The stand-in sun: the user's sun aberrated, ``1 / D`` its angle, its ``D`` stored for the
    spectral passes (which set its colour to ``D S(mu D)`` at strength ``D^2``); outside them the
    colour and strength of :func:`fast_sun`."""
    user = scene.objects[light.name].data
    direction, doppler = sun_in_scene_frame(light.axis, light.beta)
    stand_in = obj.data
    if stand_in.get(names.SUN_DOPPLER_KEY) != float(doppler):  # for the spectral passes' shift
        stand_in[names.SUN_DOPPLER_KEY] = float(doppler)
    _set(stand_in, "angle", min(float(user.angle) / doppler, math.pi))
    if materials.spectral_pass_wavelengths() is None:  # in a pass (the user's sun spectral too): they stay
        rest_colour, rest_temperature = lamp_trees.rest_emission(user)
        rest = {
            "color": [float(v) for v in rest_colour],
            "use_temperature": rest_temperature is not None or bool(user.use_temperature),
            "temperature": float(user.temperature if rest_temperature is None else rest_temperature),
        }
        saved = stand_in.get(names.SUN_REST_KEY)
        if saved is None or saved.to_dict() != rest:  # the spectrum the passes shift
            stand_in[names.SUN_REST_KEY] = rest
        colour, temperature, strength = fast_sun(user, doppler)
        _set(stand_in, "energy", float(user.energy) * strength)
        _set(stand_in, "color", colour)
        if stand_in.use_temperature != (temperature is not None):
            stand_in.use_temperature = temperature is not None
        if temperature is not None:
            _set(stand_in, "temperature", float(temperature))
    else:
        _set(stand_in, "energy", float(user.energy) * doppler * doppler)
    if stand_in.use_shadow != user.use_shadow:
        stand_in.use_shadow = user.use_shadow
    rotation = Vector(tuple(float(v) for v in direction)).to_track_quat("-Z", "Y")
    _set(obj, "rotation_quaternion", tuple(rotation))


def remove(scene: Scene) -> None:
    """Delete every stand-in lamp and the shader text."""
    for names_of_light in _record(scene).values():
        for name in names_of_light:
            delete_lamp(name)
    if names.MOVING_LAMPS_KEY in scene:
        del scene[names.MOVING_LAMPS_KEY]
    if not any(names.MOVING_LAMPS_KEY in other for other in bpy.data.scenes):
        text = bpy.data.texts.get(names.MOVING_LAMP_SHADER_TEXT)
        if text is not None:
            bpy.data.texts.remove(text)
