"""The stand-in lamps' lights (``stand_in_lamps.py``): one light datablock per moving light and
kind, its lamps' own shader inputs on their objects.

Cycles compiles (JIT) one OSL shader per light datablock at every render, so all the lamps of one
moving light share one light and one script node (``shaders/relativistic_moving_lamp.osl``); what
differs between them (:data:`PER_LAMP`: a lamp's time and position, its neighbours', a strip's normal
and length) is each lamp object's custom properties, read by Attribute nodes of type Object
(docs/moving-lights.md, "One light datablock for a light's stand-ins"; docs/performance.md).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Literal

import bpy

from ...errors import RelativityError
from ..common import compat, names, osl

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from bpy.types import Light, Object, Scene, Text


LightKind = Literal["POINT", "SUN", "SPOT", "AREA"]
STRIP_WIDTH = 1e-3  # a strip's width over its length


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


def new_light(name: str, text: Text, kind: LightKind = "POINT", per_lamp: Sequence[str] = ()) -> Light:
    """A light with the moving-lamp shader; its inputs ``per_lamp`` linked from Attribute nodes
    reading the lamp object's custom properties (:func:`lamp_key`)."""
    light = bpy.data.lights.new(name, kind)
    if kind == "SUN":  # direction, strength and angle are written by stand_in_lamps._write_sun; no shader
        return light
    light.energy = 4.0 * math.pi  # 1 W/sr: the shader's Emission carries the intensity
    light.color = (1.0, 1.0, 1.0)
    if kind == "AREA":  # a strip along a piece of the path: the object's scale gives its length (_place_strip)
        light.shape = "RECTANGLE"
        light.size, light.size_y = 1.0, STRIP_WIDTH
    else:
        light.shadow_soft_size = 0.0
    tree = compat.empty_light_tree(light)
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


def new_object(scene: Scene, name: str, light: Light) -> Object:
    obj = bpy.data.objects.new(name, light)
    obj.rotation_mode = "QUATERNION"
    if light.type != "SUN":
        obj.visible_camera = False  # a strip is no surface the camera sees
    scene.collection.objects.link(obj)
    return obj


def is_shared(light: Light) -> bool:
    """Whether ``light`` is a stand-in light that reads its lamps' own inputs from the objects."""
    if light.type == "SUN":
        return True
    tree = light.node_tree
    node = tree.nodes.get(names.MOVING_LAMP_PREFIX) if tree is not None else None
    return node is not None and all(node.inputs[key].is_linked for key in PER_LAMP)


def delete_lamp(name: str) -> None:
    """Delete the lamp object ``name`` (if any) and its light data once nothing else uses it."""
    obj = bpy.data.objects.get(name)
    if obj is None:
        return
    light = obj.data
    bpy.data.objects.remove(obj)
    if light is not None and light.users == 0:
        bpy.data.lights.remove(light)


def same(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-9)


def set_changed(owner: Any, key: str, value: Any) -> None:
    """Write only a changed value (a write triggers a depsgraph update, whose handler syncs)."""
    current = getattr(owner, key)
    if isinstance(value, tuple):
        value = value + tuple(current)[len(value) :]
        if all(same(a, b) for a, b in zip(current, value, strict=True)):
            return
    elif same(current, value):
        return
    setattr(owner, key, value)


def _set_own(obj, key, value):
    """Write the custom property ``key`` of ``obj`` if it changed; whether it did."""
    current = obj.get(key)
    if isinstance(value, tuple):
        if hasattr(current, "__len__") and len(current) == len(value) and all(map(same, current, value)):
            return False
        obj[key] = list(value)
    elif current is not None and not hasattr(current, "__len__") and same(current, value):
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
            set_changed(socket, "default_value", value)
    if changed:  # an ID property written from Python tags nothing: the viewport's render would not see it
        obj.update_tag()
