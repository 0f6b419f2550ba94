"""Colours of surface shaders inside node groups: they get the Doppler colour group too.

``materials.attach`` puts the colour group in front of every emission and BSDF colour input
(``sources.COLOUR_INPUTS``) of a material. Such a node may sit inside a node group, at any
depth; without the colour group there its colour stays RGB in the spectral passes (and is not
shifted on the mesh path). A node group is shared by every material and group that uses it, so:

- a colour input inside a group gets its colour group **in the group's tree**, once, recorded on
  the tree like a material's insertions (``names.MATERIAL_ATTACHED_KEY``) and removed by
  :func:`detach_all`;
- a colour input that the group feeds straight from its own Group Input (through reroutes: a
  *pass-through*, e.g. a "Glow" group whose Color input goes to its Emission) gets none inside:
  its colour comes from outside, where each user of the group may feed something else, a
  Blackbody among them (``sources.blackbody_source`` cannot see out of a shared group). The
  colour group goes in front of the group node's input in the tree that uses the group instead
  (:func:`targets`), which may pass it on outward again. An input that feeds both an emission and
  a BSDF colour inside is no pass-through (one colour group cannot be both).

An object's blackbody temperature (``Object.relativity.temperature``) reaches the colours of its
materials' own nodes and their pass-throughs as a constant (``materials.attach``); an emission
colour inside a shared group reads it per object instead (:func:`read_object_temperature`: an
Object Attribute node on the custom property ``names.OBJECT_TEMPERATURE_PROPERTY``, which the colour
stage writes on the objects while it is applied, ``doppler_colour``; 0 where the object has none),
so every object using the group gets its own. A plain custom property, not the RNA path
``relativity.temperature``: the Attribute node reads that only where the add-on is registered, and
a file must render the same without it (measured: the RNA path gave the RGB path there, Delta E 26.8).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..common import names
from . import sources

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from bpy.types import Node, NodeSocket, NodeTree

KEY = names.MATERIAL_ATTACHED_KEY
OWN_PREFIX = "Relativity"  # the add-on's node groups and inserted nodes


def user_groups(tree: NodeTree) -> list[Node]:
    """The group nodes of ``tree`` that hold a user's node group (not the add-on's)."""
    return [
        node
        for node in tree.nodes
        if node.bl_idname == "ShaderNodeGroup"
        and node.node_tree is not None
        and not node.name.startswith(OWN_PREFIX)
        and not node.node_tree.name.startswith(OWN_PREFIX)
    ]


def group_input(socket: NodeSocket) -> str | None:
    """Identifier of the Group Input colour output feeding input ``socket`` through reroutes, or None."""
    for _step in range(256):
        link = sources.live_link(socket)
        if link is None:
            return None
        if link.from_node.bl_idname == "NodeGroupInput":
            return link.from_socket.identifier if link.from_socket.type == "RGBA" else None
        if link.from_node.bl_idname != "NodeReroute":
            return None
        socket = link.from_node.inputs[0]
    return None


def targets(tree: NodeTree, seen: tuple[str, ...] = ()) -> Iterator[tuple[Node, NodeSocket, bool]]:
    """``(node, socket, is_emission)`` for every colour input of ``tree`` that a colour group goes
    in front of: the colour nodes' own, and the inputs of group nodes that their group passes
    straight to a colour (:func:`pass_throughs`)."""
    for node in list(tree.nodes):
        for kind, socket_names in sources.COLOUR_INPUTS:
            if node.bl_idname == kind:
                for name in socket_names:
                    socket = node.inputs.get(name)
                    if socket is not None:
                        yield node, socket, kind == "ShaderNodeEmission" or name == "Emission Color"
    for node in user_groups(tree):
        for identifier, is_emission in pass_throughs(node.node_tree, seen).items():
            socket = sources.by_identifier(node.inputs, identifier)
            if socket is not None:
                yield node, socket, is_emission


def pass_throughs(group_tree: NodeTree, seen: tuple[str, ...] = ()) -> dict[str, bool]:
    """``{Group Input identifier: is_emission}``: the colour inputs of ``group_tree`` that feed a
    colour input of its own (or of a group inside it) straight, all of one kind."""
    if group_tree.name in seen:
        return {}
    kinds = {}
    for _node, socket, is_emission in targets(group_tree, (*seen, group_tree.name)):
        identifier = group_input(socket)
        if identifier is not None:
            kinds.setdefault(identifier, set()).add(is_emission)
    return {identifier: next(iter(found)) for identifier, found in kinds.items() if len(found) == 1}


def attach_groups(
    tree: NodeTree, insert: Callable[[NodeTree, Node, NodeSocket, bool], list], seen: tuple[str, ...] = ()
) -> None:
    """Colour groups into every user group used in ``tree`` (at any depth) not yet attached:
    ``insert(tree, node, socket, is_emission)`` puts one in and returns its records."""
    for node in user_groups(tree):
        group_tree = node.node_tree
        if group_tree.name in seen:
            continue
        if KEY not in group_tree:
            passed = pass_throughs(group_tree)
            records = [
                record
                for target, socket, is_emission in list(targets(group_tree))
                if passed.get(group_input(socket) or "") != is_emission
                for record in insert(group_tree, target, socket, is_emission)
            ]
            group_tree[KEY] = records
        attach_groups(group_tree, insert, (*seen, group_tree.name))


def read_object_temperature(tree: NodeTree, colour_node: Node) -> list[dict[str, str]]:
    """Feed colour group ``colour_node`` (inside a shared group's ``tree``) the rendered object's
    blackbody temperature: Is Blackbody where it is above 0, Temperature its value (at least
    100 K, so that the unused blackbody branch stays finite); nothing for a colour already
    recognised as a blackbody. Returns the records that remove the nodes it added."""
    if colour_node.inputs["Is Blackbody"].default_value or colour_node.inputs["Is Blackbody"].is_linked:
        return []
    attribute = tree.nodes.new("ShaderNodeAttribute")
    attribute.attribute_type = "OBJECT"
    attribute.attribute_name = names.OBJECT_TEMPERATURE_PROPERTY
    is_blackbody = tree.nodes.new("ShaderNodeMath")
    is_blackbody.operation = "GREATER_THAN"
    is_blackbody.inputs[1].default_value = 0.0
    temperature = tree.nodes.new("ShaderNodeMath")
    temperature.operation = "MAXIMUM"
    temperature.inputs[1].default_value = 100.0
    tree.links.new(attribute.outputs["Fac"], is_blackbody.inputs[0])
    tree.links.new(attribute.outputs["Fac"], temperature.inputs[0])
    tree.links.new(is_blackbody.outputs[0], colour_node.inputs["Is Blackbody"])
    tree.links.new(temperature.outputs[0], colour_node.inputs["Temperature"])
    records = []
    for role, node in (("Attribute", attribute), ("Is Blackbody", is_blackbody), ("Temperature", temperature)):
        node.name = node.label = f"{colour_node.name} Object Temperature {role}"
        node.location, node.hide = (colour_node.location.x - 200.0, colour_node.location.y - 40.0), True
        records.append({"group_node": node.name, "target": "", "socket": "", "source_node": "", "source_socket": ""})
    return records


def detach_all(detach_records: Callable[..., object]) -> None:
    """Remove the colour groups from every node group: ``detach_records(owner, tree)``."""
    for group_tree in bpy.data.node_groups:
        if KEY in group_tree:
            detach_records(group_tree, group_tree)
