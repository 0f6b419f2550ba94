"""The whole state of a .blend as a comparable structure, for "Remove gives the file back" tests.

:func:`dump` reads every datablock collection the add-on can touch: objects (transforms, every
RNA setting, modifiers and their inputs, constraints, material slots, ID properties), meshes
(counts, attributes with domain, type and a hash of their data, materials, ID properties),
materials, worlds, lights and node groups (every node with its settings and input default
values, every link, the group interface), cameras (every setting, Cycles' custom camera and its
parameters), scenes (render, Cycles, colour management, view layers with their passes, light
groups and AOVs, the compositor tree), texts (a hash of the content), images (size, source, a
hash of the pixels), collections. :func:`differences` lists where two dumps differ, one line each.

Left out, with the reason:

- ``session_uid``, ``users``, ``tag``, ``is_evaluated``, ``original``, ``is_runtime_data``:
  runtime bookkeeping of Blender (counts of references and session ids), not saved state; an
  extra user left behind shows up as an extra datablock or reference anyway.
- Node ``dimensions``, ``select``, and sockets' ``is_linked``-like derived flags: drawing state of
  the node editor, computed when it draws (or follows from the links, which are compared).
- ``Scene.tool_settings``, ``Scene.sequence_editor``: editing tools and the video sequencer, no
  part of a render the add-on touches; large and noisy.
- Object ``mode``-dependent and ``bound_box``: derived from the mesh, which is compared.
- ID properties behind registered groups (``mesh["cycles"]``, ``scene["relativity"]``): Blender
  stores a value there once anything writes or reads the group, even the default; the groups are
  compared through RNA instead (a default written back is the default).
- A camera's ``["cycles"]`` ID property: Blender 4.5 writes this legacy group (the panorama
  settings) on every camera of a file it opens, with or without the add-on.
- Images of type Render Result and Viewer Node: Blender makes them for any render and compositor
  output; they hold no user data.
- 4.5's scene-owned compositor tree while Use Nodes is off and it is Blender's default tree (Render
  Layers -> Composite, a Reroute to a Viewer): 4.5's Python cannot delete it, the render does not use it, and
  ticking Use Nodes makes the same tree.
- Workspaces, screens, window managers, brushes, palettes: the UI, not the scene.
"""

from __future__ import annotations

import hashlib

RUNTIME_PROPERTIES = frozenset(
    {
        "rna_type",
        "session_uid",
        "users",
        "tag",
        "is_evaluated",
        "original",
        "is_runtime_data",
        "is_missing",
        "is_library_indirect",
        "is_embedded_data",
        "library_weak_reference",
        "preview",
        "dimensions",
        "select",
        "bound_box",
        "is_editmode",
        "tool_settings",
        "sequence_editor",
        "is_dirty",
        "is_linked",
        "is_multi_input",
        "is_unavailable",
        "is_icon_visible",
        "is_inactive",
        "link_limit",
        "internal_links",
    }
)
_SIMPLE = {"BOOLEAN", "INT", "FLOAT", "STRING", "ENUM"}


def _plain(value):
    if isinstance(value, str | bool | int | float) or value is None:
        return value
    if isinstance(value, set | frozenset):
        return tuple(sorted(value))
    try:
        return tuple(_plain(v) for v in value)
    except TypeError:
        return repr(value)


def _id_ref(bpy, value):
    return ("ID", type(value).__name__, value.name, value.library.filepath if value.library else "")


def key(block):
    """A datablock's key in the dump: its name, and for linked data the library's file name too
    (a linked and a local datablock may share a name)."""
    return block.name if block.library is None else f"{block.name} [{block.library.filepath}]"


def idprops(owner):
    """ID properties (custom properties, the add-on's stored records) as plain values."""
    try:
        keys = list(owner.keys())
    except (TypeError, AttributeError):
        return {}
    registered = owner.bl_rna.properties if hasattr(owner, "bl_rna") else {}
    out = {}
    for key in keys:
        if key in registered:
            continue  # a registered group (cycles, relativity): compared through RNA, default or not
        value = owner[key]
        if hasattr(value, "to_dict"):
            value = value.to_dict()
        elif hasattr(value, "to_list"):
            value = value.to_list()
        elif type(value).__name__ == "bpy_prop_array":
            value = list(value)
        out[key] = repr(value)
    return out


def rna(bpy, struct, depth=1, skip=()):
    """Every readable RNA setting of ``struct``: simple values as they are, references to
    datablocks by name, nested structs to ``depth`` levels; collections are left to the caller."""
    out = {}
    for prop in struct.bl_rna.properties:
        key = prop.identifier
        if key in RUNTIME_PROPERTIES or key in skip:
            continue
        try:
            value = getattr(struct, key)
        except (AttributeError, RuntimeError, TypeError, ValueError):
            continue
        if prop.type in _SIMPLE:
            out[key] = _plain(value)
        elif prop.type == "POINTER":
            if value is None:
                out[key] = None
            elif isinstance(value, bpy.types.ID):
                out[key] = _id_ref(bpy, value)
            elif depth > 0:
                out[key] = rna(bpy, value, depth - 1)
    return out


_ATTRIBUTE_FIELDS = {
    "FLOAT_VECTOR": "vector",
    "FLOAT2": "vector",
    "FLOAT_COLOR": "color",
    "BYTE_COLOR": "color",
}


def _attribute_hash(attribute):
    field = _ATTRIBUTE_FIELDS.get(attribute.data_type, "value")
    digest = hashlib.sha1()
    for item in attribute.data:
        value = getattr(item, field, None)
        digest.update(repr(_plain(value)).encode())
    return digest.hexdigest()


def mesh_dump(bpy, mesh):
    return {
        "counts": (len(mesh.vertices), len(mesh.edges), len(mesh.polygons), len(mesh.loops)),
        "attributes": sorted(
            (a.name, a.domain, a.data_type, _attribute_hash(a)) for a in mesh.attributes if not a.name.startswith(".")
        ),
        "internal_attributes": sorted(a.name for a in mesh.attributes if a.name.startswith(".")),
        "materials": [m.name if m else None for m in mesh.materials],
        "shape_keys": _id_ref(bpy, mesh.shape_keys) if mesh.shape_keys else None,
        "idprops": idprops(mesh),
        "rna": rna(bpy, mesh, depth=1),
    }


def _socket(bpy, socket):
    value = getattr(socket, "default_value", None)
    if value is not None and not isinstance(value, str | bool | int | float):
        value = _id_ref(bpy, value) if isinstance(value, bpy.types.ID) else _plain(value)
    return (socket.identifier, socket.name, socket.bl_idname, value, socket.hide, socket.enabled)


def node_tree_dump(bpy, tree):
    if tree is None:
        return None
    nodes = {}
    for node in tree.nodes:
        nodes[node.name] = {
            "type": node.bl_idname,
            "rna": rna(bpy, node, depth=0, skip=("location_absolute",)),
            "inputs": [_socket(bpy, s) for s in node.inputs],
            "outputs": [(s.identifier, s.name, s.hide, s.enabled) for s in node.outputs],
            "idprops": idprops(node),
        }
    links = sorted(
        (
            link.from_node.name,
            link.from_socket.identifier,
            link.to_node.name,
            link.to_socket.identifier,
            link.is_muted,
            link.is_valid,
        )
        for link in tree.links
    )
    interface = None
    if getattr(tree, "interface", None) is not None:
        interface = [
            (item.item_type, item.name, getattr(item, "in_out", None), getattr(item, "socket_type", None))
            for item in tree.interface.items_tree
        ]
    return {"name": tree.name, "nodes": nodes, "links": links, "interface": interface, "idprops": idprops(tree)}


def _modifier(bpy, modifier):
    out = {"rna": rna(bpy, modifier, depth=0), "idprops": idprops(modifier)}
    inputs = getattr(getattr(modifier, "properties", None), "inputs", None)
    if inputs is not None:
        out["inputs"] = rna(bpy, inputs, depth=1)
    return out


def object_dump(bpy, obj):
    return {
        "rna": rna(bpy, obj, depth=1),
        "matrix_world": _plain(obj.matrix_world),
        "data": _id_ref(bpy, obj.data) if obj.data else None,
        "modifiers": [(m.name, m.type, _modifier(bpy, m)) for m in obj.modifiers],
        "constraints": [(c.name, c.type, rna(bpy, c, depth=0)) for c in obj.constraints],
        "material_slots": [(s.link, s.material.name if s.material else None) for s in obj.material_slots],
        "collections": sorted(c.name for c in obj.users_collection),
        "idprops": idprops(obj),
    }


def camera_dump(bpy, camera):
    custom = getattr(camera, "cycles_custom", None)
    return {
        "rna": rna(bpy, camera, depth=1),
        "cycles_custom": idprops(custom) if custom is not None else None,
        # 4.5's Cycles versioning writes a legacy "cycles" group on every camera of a file it loads
        "idprops": {k: v for k, v in idprops(camera).items() if k != "cycles"},
    }


_DEFAULT_COMPOSITOR = {"CompositorNodeComposite", "CompositorNodeRLayers", "CompositorNodeViewer", "NodeReroute"}


def compositor_tree(scene):
    if "compositing_node_group" in scene.bl_rna.properties:
        return scene.compositing_node_group
    tree = scene.node_tree
    if tree is not None and not scene.use_nodes and {n.bl_idname for n in tree.nodes} <= _DEFAULT_COMPOSITOR:
        return None
    return tree


def scene_dump(bpy, scene):
    layers = {}
    for layer in scene.view_layers:
        layers[layer.name] = {
            "rna": rna(bpy, layer, depth=1),
            "aovs": [(a.name, a.type) for a in layer.aovs],
            "lightgroups": [g.name for g in getattr(layer, "lightgroups", ())],
        }
    tree = compositor_tree(scene)
    return {
        "rna": rna(bpy, scene, depth=0, skip=("node_tree",)),
        "render": rna(bpy, scene.render, depth=1),
        "cycles": rna(bpy, scene.cycles, depth=0),
        "view_settings": rna(bpy, scene.view_settings, depth=1),
        "display_settings": rna(bpy, scene.display_settings, depth=0),
        "view_layers": layers,
        "compositor": node_tree_dump(bpy, tree) if tree is not None and tree.name not in bpy.data.node_groups else None,
        "compositor_name": tree.name if tree is not None else None,
        "objects": sorted(o.name for o in scene.objects),
        "relativity": rna(bpy, scene.relativity, depth=0) if hasattr(scene, "relativity") else None,
        "idprops": idprops(scene),
    }


def _text_hash(text):
    return hashlib.sha1(text.as_string().encode()).hexdigest()


def _image(bpy, image):
    count = len(image.pixels)  # reading loads a packed or generated image's buffer: the same each time
    pixels = hashlib.sha1(repr(tuple(image.pixels[:])).encode()).hexdigest() if count < 4_000_000 else count
    return {"size": tuple(image.size), "source": image.source, "pixels": pixels, "idprops": idprops(image)}


def dump(bpy):
    """The file's state: {collection: {datablock name: what it holds}}."""
    data = bpy.data
    return {
        "objects": {key(o): object_dump(bpy, o) for o in data.objects},
        "meshes": {key(m): mesh_dump(bpy, m) for m in data.meshes},
        "materials": {
            key(m): {
                "rna": rna(bpy, m, depth=1),
                "tree": node_tree_dump(bpy, m.node_tree),
                "idprops": idprops(m),
            }
            for m in data.materials
        },
        "node_groups": {key(g): node_tree_dump(bpy, g) for g in data.node_groups},
        "cameras": {key(c): camera_dump(bpy, c) for c in data.cameras},
        "lights": {
            key(light): {
                "rna": rna(bpy, light, depth=1),
                "tree": node_tree_dump(bpy, light.node_tree),
                "idprops": idprops(light),
            }
            for light in data.lights
        },
        "worlds": {
            key(w): {"rna": rna(bpy, w, depth=1), "tree": node_tree_dump(bpy, w.node_tree), "idprops": idprops(w)}
            for w in data.worlds
        },
        "scenes": {key(s): scene_dump(bpy, s) for s in data.scenes},
        "collections": {
            key(c): (sorted(o.name for o in c.objects), sorted(k.name for k in c.children), idprops(c))
            for c in data.collections
        },
        "texts": {key(t): _text_hash(t) for t in data.texts},
        "images": {key(i): _image(bpy, i) for i in data.images if i.type not in ("RENDER_RESULT", "COMPOSITING")},
        "actions": sorted(a.name for a in data.actions),
        "libraries": sorted(lib.filepath for lib in data.libraries),
    }


def differences(before, after, path=""):
    """Where two dumps differ, one line each (``path: before -> after``)."""
    if isinstance(before, dict) and isinstance(after, dict):
        lines = []
        for key in sorted(set(before) | set(after), key=str):
            where = f"{path}/{key}"
            if key not in after:
                lines.append(f"{where}: removed")
            elif key not in before:
                lines.append(f"{where}: added")
            else:
                lines += differences(before[key], after[key], where)
        return lines
    if before != after:
        return [f"{path}: {str(before)[:200]} -> {str(after)[:200]}"]
    return []


def renamed(state, collection, old, new):
    """``state`` with one datablock's key renamed (an operation's own intended change)."""
    state = dict(state)
    state[collection] = {new if k == old else k: v for k, v in state[collection].items()}
    return state
