"""Apparent Geometry baked for rendering anywhere: each frame's evaluated mesh, played back by frame.

The apparent geometry comes from Python at every frame (``apparent_meshes.update`` writes a cache
mesh that the modifier samples): opened without the add-on, or with scripts disabled, a file draws
the one frame its caches hold at every frame. :func:`capture` copies an object's evaluated mesh at a
frame (the whole modifier stack's output with every attribute: the apparent positions,
``relativity_beta`` for the Doppler shaders, UVs, materials) into a mesh datablock; :func:`install`
puts an object's frames, in frame order, in a collection of objects linked to no scene and adds a
geometry-nodes modifier (``names.PLAYBACK_GROUP``) at the end of its stack that replaces the
geometry by the frame's mesh: Scene Time's frame, rounded, minus the first frame picks the
instance of the collection (Collection Info sorts its children by name, and the frame index is
zero-padded in the name), held at the first and last frame outside the range. The add-on's own
modifier is switched off meanwhile (its result would be replaced). :func:`remove` undoes it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import bpy

from ..common import compat, names
from ..common.nodes import Group, Node, ensure_group, interface_identifier, remove_unused_groups
from . import modifier

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Mesh, NodeTree, Object


def node_group_spec() -> Group:
    """Geometry: the instance ``clamp(round(frame) - First Frame, 0, Frame Count - 1)`` of the
    collection ``Frames`` (its children in name order, at their own origin), realized."""
    integer = "FunctionNodeIntegerMath"
    nodes = {
        "time": Node("GeometryNodeInputSceneTime"),
        "frame": Node("FunctionNodeFloatToInt", {"Float": "time.Frame"}, {"rounding_mode": "ROUND"}),
        "offset": Node(integer, {0: "frame.Integer", 1: "group.First Frame"}, {"operation": "SUBTRACT"}),
        "last": Node(integer, {0: "group.Frame Count", 1: 1}, {"operation": "SUBTRACT"}),
        "at_least_first": Node(integer, {0: "offset.Value", 1: 0}, {"operation": "MAXIMUM"}),
        "wanted": Node(integer, {0: "at_least_first.Value", 1: "last.Value"}, {"operation": "MINIMUM"}),
        "frames": Node(
            "GeometryNodeCollectionInfo",
            {"Collection": "group.Frames", "Separate Children": True, "Reset Children": True},
            {"transform_space": "ORIGINAL"},
        ),
        "index": Node("GeometryNodeInputIndex"),
        "is_frame": Node(
            "FunctionNodeCompare", {"A": "index.Index", "B": "wanted.Value"}, {"data_type": "INT", "operation": "EQUAL"}
        ),
        "pick": Node(
            "GeometryNodeSeparateGeometry",
            {"Geometry": "frames", "Selection": "is_frame.Result"},
            {"domain": "INSTANCE"},
        ),
        "realize": Node("GeometryNodeRealizeInstances", {"Geometry": "pick.Selection"}),
    }
    return Group(
        names.PLAYBACK_GROUP,
        "GeometryNodeTree",
        (
            ("Geometry", "NodeSocketGeometry", None),
            ("Frames", "NodeSocketCollection", None),
            ("First Frame", "NodeSocketInt", {"default_value": 1}),
            ("Frame Count", "NodeSocketInt", {"min_value": 1, "default_value": 1}),
        ),
        (("Geometry", "NodeSocketGeometry", "realize.Geometry"),),
        nodes,
    )


def ensure_node_group() -> NodeTree:
    return ensure_group(node_group_spec(), names.PLAYBACK_GROUP_VERSION_KEY, names.PLAYBACK_GROUP_VERSION)


def _frame_name(obj_name: str, index: int) -> str:
    return f"{names.PLAYBACK_PREFIX} {index:06d} {obj_name}"


def capture(obj: Object, depsgraph: Depsgraph, index: int, previous: Mesh | None = None) -> Mesh:
    """The evaluated mesh of ``obj`` in ``depsgraph`` as a new mesh datablock (every attribute and
    material kept), named for frame ``index`` of the bake; ``previous`` (the last frame's) instead
    when it is the same in every value and material (a mesh at rest behind the exact camera): the
    frames then share it."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = bpy.data.meshes.new_from_object(evaluated, preserve_all_data_layers=True, depsgraph=depsgraph)
    if (
        previous is not None
        and list(mesh.materials) == list(previous.materials)
        and mesh.unit_test_compare(mesh=previous, threshold=0.0) == "Same"  # Blender's own comparison
    ):
        bpy.data.meshes.remove(mesh)
        return previous
    mesh.name = _frame_name(obj.name, index)
    return mesh


def install(obj: Object, meshes: list[Mesh], first_frame: int) -> dict[str, Any]:
    """Play ``meshes`` (one per frame from ``first_frame``, a mesh repeated where frames share it)
    on ``obj``; returns the record :func:`remove` takes."""
    collection = bpy.data.collections.new(f"{names.PLAYBACK_PREFIX} {obj.name}")
    frames = []
    for index, mesh in enumerate(meshes):
        holder = bpy.data.objects.new(_frame_name(obj.name, index), mesh)
        collection.objects.link(holder)
        frames.append(holder.name)
    group = ensure_node_group()
    playback = obj.modifiers.new(names.PLAYBACK_MODIFIER, "NODES")
    playback.node_group = group
    for name, value in (("Frames", collection), ("First Frame", first_frame), ("Frame Count", len(meshes))):
        compat.set_modifier_input(playback, interface_identifier(group, name), value)
    apparent = modifier.find_modifier(obj)
    shown = None
    if apparent is not None:
        shown = [apparent.show_viewport, apparent.show_render]
        apparent.show_viewport = apparent.show_render = False
    obj.update_tag()
    return {
        "object": obj.name,
        "modifier": playback.name,
        "collection": collection.name,
        "frames": frames,
        "meshes": list(dict.fromkeys(mesh.name for mesh in meshes)),
        "shown": shown,
    }


def remove(record: dict[str, Any]) -> None:
    """Take out what :func:`install` added (and the captured meshes); the add-on's modifier shown
    again as it was."""
    obj = bpy.data.objects.get(record["object"])
    if obj is not None:
        playback = obj.modifiers.get(record["modifier"])
        if playback is not None:
            obj.modifiers.remove(playback)
        apparent = modifier.find_modifier(obj)
        if apparent is not None and record.get("shown") is not None:
            apparent.show_viewport, apparent.show_render = record["shown"]
        obj.update_tag()
    for name in record["frames"]:
        holder = bpy.data.objects.get(name)
        if holder is not None:
            bpy.data.objects.remove(holder)
    discard_meshes(record["meshes"])
    collection = bpy.data.collections.get(record["collection"])
    if collection is not None:
        bpy.data.collections.remove(collection)
    remove_unused_groups((names.PLAYBACK_GROUP,))


def discard_meshes(mesh_names: list[str]) -> None:
    """Delete captured meshes nothing uses (a bake that stopped half-way)."""
    for name in mesh_names:
        mesh = bpy.data.meshes.get(name)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
