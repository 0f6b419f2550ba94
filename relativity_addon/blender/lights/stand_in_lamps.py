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
wider, from its reception event): the hit points that get at least 1 % of the brightest one's
irradiance set the span of retarded times (``stand_in_paths.py``, ``physics.moving_lights.lamp_times``).
A light's lamps share one light datablock (Cycles compiles one OSL shader per datablock at every
render): what differs between them (``stand_in_lights.PER_LAMP``) is on each lamp object, read by
Attribute nodes (``stand_in_lights.py``). Everything made here (objects,
the light, the shader text) is named ``names.MOVING_LAMP_PREFIX``, listed on the scene and deleted
by :func:`remove`; the user's light is hidden by ``moving_lights.py``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import bpy
import numpy as np
from mathutils import Matrix, Vector

from ...physics import spectral_render
from ...physics.moving_lights import (
    end_on_share,
    retarded_times_on_path,
    sun_in_scene_frame,
)
from ..camera import cockpit
from ..colour import light_groups, materials
from ..common import busy, names
from . import lamp_shader, lamp_trees, stand_in_lights, stand_in_paths
from .stand_in_lights import delete_lamp, lamp_key, write_inputs
from .stand_in_paths import MAX_LAMPS

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence

    from bpy.types import Depsgraph, Light, Object, Scene

    from ..scene.snapshot import MovingLight, Snapshot

KERNEL = 0.5  # the box of path each point is lit from (continuous shadows), in lamp spacings
STRIP_SIDES = 3  # one-sided strips per lamp (lines) or piece of the path (Continuous), facing 120 degrees apart
LINE_SIDES = 3  # strips per line, facing 120 degrees apart (two facing opposite ways: a plane seen edge on)
LINE = 1.25  # Blended Lamps: each lamp a line (strips) this many lamp spacings long along the path (0: points)
END_ON = 0.2  # point lamps instead of lines when this share of the lit points' light comes along the path


# --- the stand-in lamps ---------------------------------------------------------------------


def new_point_lamp(scene: Scene, name: str) -> Object:
    """A point lamp (radius 0, power 4 pi) with its own light and moving-lamp shader, its inputs
    unset (:func:`write_inputs`)."""
    return stand_in_lights.new_object(scene, name, stand_in_lights.new_light(name, lamp_shader.shader_text()))


def stand_in_names(scene: Scene) -> dict[str, list[str]]:
    """``{light name: [its stand-in lamps' object names]}`` (``names.MOVING_LAMPS_KEY``)."""
    return _record(scene)


def _record(scene):
    stored = scene.get(names.MOVING_LAMPS_KEY)
    return {} if stored is None else {key: list(value) for key, value in stored.to_dict().items()}


def _shader_lamps(lamp_names):
    """The stand-in objects named when all are there and are shader lamps (point or area), else []."""
    objects = [bpy.data.objects.get(name) for name in lamp_names]
    if any(obj is None or obj.data.type not in {"POINT", "AREA"} for obj in objects):
        return []
    return objects


def _new_lamps(scene, light_name, light, start, stop):
    """Names of new stand-in objects ``start`` .. ``stop - 1`` of the light, sharing ``light``."""
    return [
        stand_in_lights.new_object(scene, f"{names.MOVING_LAMP_PREFIX} {light_name} {index}", light).name
        for index in range(start, stop)
    ]


def _lamps_for(scene, light_name, count, text, kind="POINT", keep=False):
    """The light's first ``count`` lamps, sharing one light datablock; while a bake steps frames
    (``busy.keeps_stand_ins``) or ``keep`` (a render runs: :func:`reserve`) the others are kept,
    hidden from renders, and more are added under the next names when needed."""
    record = _record(scene)
    existing = [name for name in record.get(light_name, []) if bpy.data.objects.get(name) is not None]
    lights = {bpy.data.objects[name].data for name in existing}
    same_kind = len(lights) <= 1 and all(light.type == kind and stand_in_lights.is_shared(light) for light in lights)
    kept = (busy.keeps_stand_ins() or keep) and same_kind
    if len(existing) < count or (not kept and (len(existing) != count or not same_kind)):
        if not kept:
            for name in existing:
                delete_lamp(name)
            existing = []
        if existing:
            light = bpy.data.objects[existing[0]].data
        else:
            light = stand_in_lights.new_light(
                f"{names.MOVING_LAMP_PREFIX} {light_name}", text, kind, stand_in_lights.PER_LAMP
            )
        existing += _new_lamps(scene, light_name, light, len(existing), count)
        record[light_name] = existing
        scene[names.MOVING_LAMPS_KEY] = record
    lamps = [bpy.data.objects[name] for name in existing]
    for index, obj in enumerate(lamps):
        stand_in_lights.set_changed(obj, "hide_render", index >= count)
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
        objects = _shader_lamps(existing)
        if not objects or len({obj.data for obj in objects}) != 1 or not stand_in_lights.is_shared(objects[0].data):
            continue
        lamps, sides = _capacity(objects[0])
        added = _new_lamps(scene, light_name, objects[0].data, len(existing), lamps * sides)
        for name in added:
            bpy.data.objects[name].hide_render = True
        record[light_name] = existing + added
    if record:
        scene[names.MOVING_LAMPS_KEY] = record


def _held(scene, light_name):
    """How many lamps (times) the light's stand-ins, hidden ones included, hold (0: none)."""
    objects = _shader_lamps(_record(scene).get(light_name, []))
    if not objects:
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
                stand_in_lights.set_changed(obj, "hide_render", True)


def _stored_times(scene, light_name):
    """The stand-ins' times of the last placement (their own inputs), or None."""
    objects = _shader_lamps(_record(scene).get(light_name, []))
    if not objects:
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
                points = stand_in_paths.visible_points(scene, snap, depsgraph, values["camera_position"])
            times, positions = stand_in_paths.lamp_path(scene, snap, light, values, reception_time, points)
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
                positions = stand_in_paths.path_positions(scene, snap, light, values, reception_time, times)
        else:  # no depsgraph (frame_change_pre, render_pre): the times of the last placement, moved on
            positions = stand_in_paths.path_positions(scene, snap, light, values, reception_time, times)
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
    stand_in_lights.set_changed(obj, "location", tuple(float(v) for v in centre))
    stand_in_lights.set_changed(obj, "rotation_quaternion", tuple(Matrix(rotation.tolist()).to_quaternion()))
    # the light (1 x STRIP_WIDTH) is shared by the light's strips: the scale sets the length and width
    stand_in_lights.set_changed(obj, "scale", (max(length, 1e-6), max(length, 1e-6), 1.0))
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
            stand_in_lights.set_changed(obj, "location", tuple(float(v) for v in positions[index]))
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
    stand_in_lights.set_changed(stand_in, "angle", min(float(user.angle) / doppler, math.pi))
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
        stand_in_lights.set_changed(stand_in, "energy", float(user.energy) * strength)
        stand_in_lights.set_changed(stand_in, "color", colour)
        if stand_in.use_temperature != (temperature is not None):
            stand_in.use_temperature = temperature is not None
        if temperature is not None:
            stand_in_lights.set_changed(stand_in, "temperature", float(temperature))
    else:
        stand_in_lights.set_changed(stand_in, "energy", float(user.energy) * doppler * doppler)
    if stand_in.use_shadow != user.use_shadow:
        stand_in.use_shadow = user.use_shadow
    rotation = Vector(tuple(float(v) for v in direction)).to_track_quat("-Z", "Y")
    stand_in_lights.set_changed(obj, "rotation_quaternion", tuple(rotation))


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
