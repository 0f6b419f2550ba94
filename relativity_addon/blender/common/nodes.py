"""One declarative builder for every node group the add-on makes: geometry nodes, shader nodes
and compositor nodes alike.

A group is data (:class:`Group`): its interface and a dict of :class:`Node` by name, each with
its input values, where a string is a link. :func:`build_group` creates or rebuilds the tree;
:func:`ensure_group` rebuilds it only when its version stamp is outdated (rebuilding an
interface drops the links of every node that uses the group).

Building is slow for large groups: every node, link and value set from Python makes Blender
update the whole tree, so a build costs the square of its size (the Apparent Geometry group, 410
nodes and 946 links: 1.9-3 s of every Set Up). :func:`ensure_group` therefore keeps each built
group that refers to no other datablock in a small ``.blend`` in the extension's user folder
(``bpy.utils.extension_path_user``; run from the source tree, Blender's user data folder),
named by a fingerprint of the spec, the version stamp, this builder's source and the Blender
build, and appends it from there the next time (15 ms).
"""

from __future__ import annotations

import hashlib
import os
import typing
from dataclasses import dataclass, field, fields, is_dataclass
from typing import TYPE_CHECKING

import bpy

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    from bpy.types import Material, NodeTree


class Literal(str):
    """A string input value (an attribute name, a menu item), not a reference to a socket."""


Menu = Literal


class Links(tuple):
    """Several references into one multi-input socket (Join Geometry), linked in order."""


TreeType = typing.Literal["GeometryNodeTree", "CompositorNodeTree", "ShaderNodeTree"]


@dataclass
class Node:
    """One node: ``inputs`` maps socket (name or index) to a constant or a reference.

    A reference is ``"node"`` (first output), ``"node.Output Name"``, ``"node.2"`` (output index)
    or ``"group.Input Name"`` (the group's own input). ``props`` are node attributes; the values
    of ``node_tree`` and ``image`` name a node group and an image; ``capture_items`` lists a
    Capture Attribute's values as ``(socket type, name)``.
    """

    kind: str
    inputs: dict = field(default_factory=dict)
    props: dict = field(default_factory=dict)


@dataclass
class Group:
    """``inputs``: (name, socket type, default or None, or a dict of socket attributes);
    ``outputs``: (name, socket type, reference or None)."""

    name: str
    tree_type: TreeType
    inputs: tuple
    outputs: tuple
    nodes: dict


def fmath(operation: str, a: object, b: object = 0.0, c: object = 0.0, clamp: bool = False) -> Node:
    return Node("ShaderNodeMath", {0: a, 1: b, 2: c}, {"operation": operation, "use_clamp": clamp})


def vmath(operation: str, a: object, b: object = (0.0, 0.0, 0.0), scale: object = None) -> Node:
    inputs = {0: a, 1: b}
    if scale is not None:
        inputs["Scale"] = scale
    return Node("ShaderNodeVectorMath", inputs, {"operation": operation})


def group_node(group_name: str, inputs: dict | None = None, kind: str = "ShaderNodeGroup") -> Node:
    return Node(kind, inputs or {}, {"node_tree": group_name})


def _socket(sockets, key):
    if isinstance(key, int):
        return sockets[key]
    if key.isdigit():
        return sockets[int(key)]
    for socket in sockets:  # the available socket of that name first (Math/Mix have hidden twins)
        if socket.name == key and socket.enabled and not getattr(socket, "is_unavailable", False):
            return socket
    return sockets[key]


def _new_interface_socket(tree, name, in_out, socket_type, default):
    socket = tree.interface.new_socket(name, in_out=in_out, socket_type=socket_type)
    attributes = default if isinstance(default, dict) else {"default_value": default}
    for attribute, value in attributes.items():
        if value is not None:
            setattr(socket, attribute, value)


def build_group(spec: Group, keep_interface: bool = False) -> NodeTree:
    """Create or rebuild the node group described by ``spec`` (a :class:`Group`); with
    ``keep_interface`` an existing group keeps its sockets (the links of the nodes using it stay)."""
    tree = bpy.data.node_groups.get(spec.name)
    if tree is None or tree.bl_idname != spec.tree_type:
        tree = bpy.data.node_groups.new(spec.name, spec.tree_type)
        keep_interface = False
    tree.nodes.clear()
    if not keep_interface:
        tree.interface.clear()
        for name, socket_type, default in spec.inputs:
            _new_interface_socket(tree, name, "INPUT", socket_type, default)
        for name, socket_type, _reference in spec.outputs:
            _new_interface_socket(tree, name, "OUTPUT", socket_type, None)
    group_in = tree.nodes.new("NodeGroupInput")
    group_out = tree.nodes.new("NodeGroupOutput")
    built = {}
    for index, (name, node_spec) in enumerate(spec.nodes.items()):
        node = tree.nodes.new(node_spec.kind)
        node.name = node.label = name
        node.location = (200.0 * (index % 8), -200.0 * (index // 8))
        for prop, value in node_spec.props.items():
            if prop == "node_tree":
                value = bpy.data.node_groups[value]
            elif prop == "image":
                value = bpy.data.images[value]
            elif prop == "capture_items":  # Capture Attribute's values: (socket type, name)
                for socket_type, item in value:
                    node.capture_items.new(socket_type, item)
                continue
            setattr(node, prop, value)
        built[name] = node

    def resolve(reference):
        node_name, _, socket_key = reference.partition(".")
        if node_name == "group":
            return _socket(group_in.outputs, socket_key)
        return _socket(built[node_name].outputs, socket_key or 0)

    for name, node_spec in spec.nodes.items():
        for key, value in node_spec.inputs.items():
            target = _socket(built[name].inputs, key)
            if isinstance(value, Links):
                for reference in value:
                    tree.links.new(resolve(reference), target)
            elif isinstance(value, str) and not isinstance(value, Literal):
                tree.links.new(resolve(value), target)
            else:
                target.default_value = value
    for name, _socket_type, reference in spec.outputs:
        if isinstance(reference, str):
            tree.links.new(resolve(reference), _socket(group_out.inputs, name))
    return tree


def ensure_group(spec: Group, version_key: str, version: int) -> NodeTree:
    """The group of ``spec``, built (or appended from the cache of built groups) if missing or
    stamped with another version."""
    tree = bpy.data.node_groups.get(spec.name)
    if tree is None or tree.get(version_key) != version:
        path = _cache_path(spec, version_key, version)
        cached = _append(path, spec.name, tree) if path is not None else None
        if cached is not None:
            return cached
        tree = build_group(spec)
        tree[version_key] = version
        if path is not None:
            _write(path, tree)
    return tree


def _builder_fingerprint() -> str:
    """This module's source: a change to how groups are built (not only to a spec) is not served
    from groups kept by the old builder."""
    try:
        with open(__file__, "rb") as source:
            return hashlib.sha256(source.read()).hexdigest()
    except OSError:
        return ""


_BUILDER = _builder_fingerprint()


def _canonical(value: object) -> object:
    """``value`` as nested tuples that tell apart what the builder tells apart (a
    :class:`Literal` from a reference, :class:`Links` from a tuple)."""
    if is_dataclass(value) and not isinstance(value, type):
        return (type(value).__name__, *(_canonical(getattr(value, f.name)) for f in fields(value)))
    if isinstance(value, dict):
        return ("dict", *((repr(key), _canonical(item)) for key, item in value.items()))
    if isinstance(value, (list, tuple)):
        return (type(value).__name__, *(_canonical(item) for item in value))
    return (type(value).__name__, repr(value))


def _cache_path(spec: Group, version_key: str, version: int) -> str | None:
    """Where the built group of ``spec`` is kept, or None: a group naming other datablocks (a
    nested group, an image) is not kept, nor anything when the user folder cannot be written."""
    if any(prop in ("node_tree", "image") for node in spec.nodes.values() for prop in node.props):
        return None
    package = (__package__ or "").rsplit(".blender", 1)[0]
    try:
        if package.startswith("bl_ext."):
            folder = bpy.utils.extension_path_user(package, path="node_groups", create=True)
        else:  # run from the source tree (examples/render.py, benchmarks): Blender's user data folder
            folder = bpy.utils.user_resource("DATAFILES", path=os.path.join(package, "node_groups"), create=True)
    except (ValueError, OSError):  # a read-only user folder
        return None
    if not folder:
        return None
    key = repr((_canonical(spec), version_key, version, _BUILDER, bpy.app.version_string, bpy.app.build_hash))
    return os.path.join(folder, f"{hashlib.sha256(key.encode()).hexdigest()[:24]}.blend")


def _append(path: str, name: str, stale: NodeTree | None) -> NodeTree | None:
    """The group ``name`` appended from ``path`` (replacing ``stale`` for everything that uses
    it), or None if the file is missing or unreadable."""
    if not os.path.isfile(path):
        return None
    try:
        with bpy.data.libraries.load(path, link=False) as (source, target):  # type: ignore[func-returns-value]  # the stubs miss its context manager
            target.node_groups = [name] if name in source.node_groups else []
    except (OSError, RuntimeError):
        return None
    for library in list(bpy.data.libraries):  # appending leaves the file's library entry behind
        if os.path.normpath(bpy.path.abspath(library.filepath)) == os.path.normpath(path):
            bpy.data.libraries.remove(library)
    if not target.node_groups or target.node_groups[0] is None:
        return None
    tree = target.node_groups[0]
    if stale is not None:
        stale.user_remap(tree)
        bpy.data.node_groups.remove(stale)
    tree.name = name
    tree.use_fake_user = False
    return tree


def _write(path: str, tree: NodeTree) -> None:
    """Keep ``tree`` in ``path`` (written beside it, then moved in: parallel processes never read
    half a file); a failure only means building again next time."""
    partial = f"{path}.{os.getpid()}.blend"
    try:
        bpy.data.libraries.write(partial, {tree}, fake_user=False, compress=False)
        os.replace(partial, path)
    except (OSError, RuntimeError):
        if os.path.exists(partial):
            os.remove(partial)


def interface_identifier(group: NodeTree, name: str, in_out: str = "INPUT") -> str:
    """The identifier (``Socket_N``) of the group's interface socket ``name``."""
    for item in group.interface.items_tree:
        if item.item_type == "SOCKET" and item.in_out == in_out and item.name == name:
            return item.identifier
    raise KeyError(name)


def remove_unused_groups(names: Iterable[str]) -> None:
    """Delete the named node groups that nothing uses any more."""
    for name in names:
        tree = bpy.data.node_groups.get(name)
        if tree is not None and tree.users == 0:
            bpy.data.node_groups.remove(tree)


def detach_inserted(material: Material | None, key: str, node_keys: Sequence[str]) -> bool:
    """Undo a node insertion recorded on ``material[key]`` (``output``, ``source_node``,
    ``source_socket`` and the inserted nodes' names under ``node_keys``): the inserted nodes
    removed, the old surface shader linked to the output again, the record deleted."""
    if material is None or key not in material:
        return False
    record = material[key].to_dict()
    tree = material.node_tree
    if tree is not None:
        for node_key in node_keys:
            node = tree.nodes.get(record.get(node_key, ""))
            if node is not None:
                tree.nodes.remove(node)
        output = tree.nodes.get(record["output"])
        source_node = tree.nodes.get(record["source_node"])
        source = (
            None
            if source_node is None
            else next((s for s in source_node.outputs if s.identifier == record["source_socket"]), None)
        )
        if output is not None and source is not None:
            tree.links.new(source, output.inputs["Surface"])
    del material[key]
    return True


def cycles_material_output(tree: NodeTree) -> typing.Any:
    """The material output node Cycles renders (the active one among those for Cycles or all), or None."""
    outputs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial" and n.target in ("ALL", "CYCLES")]
    active = [n for n in outputs if n.is_active_output]
    return next(iter(active or outputs), None)


def linked_surface(material: typing.Any, key: str) -> typing.Any:
    """``(tree, output)``: where a stage can insert nodes on ``material``'s surface (its node tree and
    the output Cycles renders, whose Surface is linked), or None where the material has no tree,
    already carries the stage's record ``key`` or renders no linked surface."""
    if material.node_tree is None or key in material:
        return None
    output = cycles_material_output(material.node_tree)
    if output is None or not output.inputs["Surface"].is_linked:
        return None
    return material.node_tree, output
