"""Rest-frame shading normals for moving objects lit by lamps at rest (eq. 18's ``cos(alpha')``).

Eq. 18's cosine is between the object's rest-frame normal and the photon direction in the object's
frame. Cycles takes it on the mesh it renders, the apparent (retarded, Lorentz-contracted)
surface, whose normals differ (Penrose-Terrell): measured 43 % too bright and 19 % too dark on two
faces of a cube at 0.5c (docs/lamp-doppler.md). The lamp copies of ``lamp_doppler`` already
arrive from the object-frame direction; this stage gives the BSDFs the rest-frame normal:

- each moving object's mesh gets a corner attribute ``names.REST_NORMAL_ATTRIBUTE``: its own
  corner normals (object space) before the apparent-geometry modifier moves the vertices (the
  modifier's subdivision interpolates it);
- every material of those objects gets the group ``names.REST_NORMAL_GROUP`` (attribute -> world
  normal, or the geometry's own normal where the attribute is absent, e.g. a static object
  sharing the material: the transform then gets a unit stand-in, as the absent attribute's
  ``(0, 0, 0)`` normalised to NaN, and the static mesh rendered black) linked into the Normal
  input of each BSDF whose Normal is not linked.

Everything is recorded (the mesh names on the scene and a mark on each mesh, which follows a
rename; the inserted node on each material) and :func:`remove` deletes exactly that.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import bpy
import numpy as np

from ..common import names, nodes
from ..geometry import apparent_meshes, motion

if TYPE_CHECKING:
    from collections.abc import Sequence

    from bpy.types import Material, Mesh, NodeTree, Object, Scene

    from ..scene.snapshot import Snapshot

KEY = names.REST_NORMAL_KEY
ATTRIBUTE = names.REST_NORMAL_ATTRIBUTE
MATERIAL_KEY = names.REST_NORMAL_MATERIAL_KEY
MESH_KEY = names.REST_NORMAL_MESH_KEY
NODE_NAME = names.REST_NORMAL_GROUP


def _group_spec():
    return nodes.Group(
        name=names.REST_NORMAL_GROUP,
        tree_type="ShaderNodeTree",
        inputs=(),
        outputs=(("Normal", "NodeSocketVector", "normal.Result"),),
        nodes={
            "rest": nodes.Node(
                "ShaderNodeAttribute", props={"attribute_name": ATTRIBUTE, "attribute_type": "GEOMETRY"}
            ),
            "length": nodes.vmath("LENGTH", "rest.Vector"),
            "present": nodes.fmath("GREATER_THAN", "length.Value", 0.5),
            # where the attribute is absent its (0, 0, 0) would normalise to NaN in the transform,
            # and the mix's 0 x NaN is NaN: a mesh at rest sharing the material rendered black
            "safe": nodes.Node(
                "ShaderNodeMix", {"Factor": "present", 4: (0.0, 0.0, 1.0), 5: "rest.Vector"}, {"data_type": "VECTOR"}
            ),
            "world": nodes.Node(
                "ShaderNodeVectorTransform",
                {0: "safe.Result"},
                {"vector_type": "NORMAL", "convert_from": "OBJECT", "convert_to": "WORLD"},
            ),
            "geometry": nodes.Node("ShaderNodeNewGeometry"),
            "normal": nodes.Node(
                "ShaderNodeMix", {"Factor": "present", 4: "geometry.Normal", 5: "world"}, {"data_type": "VECTOR"}
            ),
        },
    )


def _group():
    return nodes.ensure_group(_group_spec(), names.GROUP_VERSION_KEY, names.REST_NORMAL_GROUP_VERSION)


def _corner_normals(mesh):
    values = np.empty(len(mesh.loops) * 3, dtype=np.float32)
    mesh.corner_normals.foreach_get("vector", values)
    return values


def _turned_normals(scene, obj, snap, normals):
    """The corner normals (object space, flat) turned to the object's orientation at the retarded
    time of their vertex and written back in the object space of its current matrix (which the
    group's transform applies): ``L_now^T L_e^-T n``, normalised. The mesh's own normals where the
    object does not turn. Taking them untouched, a sphere spinning once a second at 0.5c rendered
    97-100 % black where the lamp lit it (its normals turned by the spin during the light's travel)."""
    mesh = obj.data  # the rest shape (the evaluated one is the apparent mesh)
    rest = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
    mesh.vertices.foreach_get("co", rest)
    # the original's matrix, as the lamp stage's centres: evaluating the depsgraph here would run
    # the handlers' sync inside this one
    orientations = motion.retarded_orientations(scene, obj, obj, rest.reshape(-1, 3), snap)
    corners = np.empty(len(mesh.loops), dtype=np.int64)
    mesh.loops.foreach_get("vertex_index", corners)
    now = np.array(obj.matrix_world, dtype=np.float64)[:3, :3]
    turned = np.linalg.solve(np.transpose(orientations, (0, 2, 1))[corners], normals.reshape(-1, 3, 1))[..., 0]
    local = turned @ now  # L_now^T n_world, per row
    length = np.linalg.norm(local, axis=1, keepdims=True)
    return (local / np.maximum(length, 1e-12)).astype(np.float32).ravel()


# Mesh name -> the geometry key (``apparent_meshes.geometry_key``, and the observer's event for an
# object that turns) its rest normals were written at.
_written = {}


def _write_attribute(mesh, normals):
    """(Re)write the mesh's rest normals where they changed; False if the name is taken by a
    user's attribute of another kind."""
    attribute = mesh.attributes.get(ATTRIBUTE)
    if attribute is not None and (attribute.domain != "CORNER" or attribute.data_type != "FLOAT_VECTOR"):
        return False
    if attribute is None:
        attribute = mesh.attributes.new(ATTRIBUTE, "FLOAT_VECTOR", "CORNER")
    else:
        current = np.empty(len(normals), dtype=np.float32)
        attribute.data.foreach_get("vector", current)
        if np.array_equal(current, normals):
            return True
    attribute.data.foreach_set("vector", normals)
    mesh.update()
    return True


def _normal_inputs(tree):
    """Unlinked Normal inputs of the BSDFs (and subsurface nodes) in a material's tree."""
    return [
        node.inputs["Normal"]
        for node in tree.nodes
        if (node.bl_idname.startswith("ShaderNodeBsdf") or node.bl_idname == "ShaderNodeSubsurfaceScattering")
        and "Normal" in node.inputs
        and not node.inputs["Normal"].is_linked
    ]


def attach(material: Material | None, group: NodeTree) -> bool:
    if material is None or material.node_tree is None or MATERIAL_KEY in material:
        return False
    tree = material.node_tree
    targets = _normal_inputs(tree)
    if not targets:
        return False
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    node.name = node.label = NODE_NAME
    node.hide = True
    for socket in targets:
        tree.links.new(node.outputs["Normal"], socket)
    material[MATERIAL_KEY] = node.name
    return True


def detach(material: Material | None) -> bool:
    if material is None or MATERIAL_KEY not in material:
        return False
    tree = material.node_tree
    node = tree.nodes.get(material[MATERIAL_KEY]) if tree is not None else None
    if node is not None:
        tree.nodes.remove(node)  # its links go with it: the Normal inputs are unlinked again
    del material[MATERIAL_KEY]
    return True


def write(scene: Scene, objects: Sequence[Object], snap: Snapshot) -> None:
    """Rest normals for ``objects`` (the moving meshes lit by lamp copies), an object that turns
    (its own rotation keys) at each vertex's retarded time; everything removed when there are none."""
    if not objects:
        remove(scene)
        return
    record = scene[KEY].to_dict() if KEY in scene else {"meshes": []}
    group = _group()
    for obj in objects:
        mesh = cast("Mesh", obj.data)
        if mesh.name not in record["meshes"]:
            if ATTRIBUTE in mesh.attributes and MESH_KEY not in mesh:
                continue  # the user's own attribute of that name: left alone
            mesh[MESH_KEY] = True
            record["meshes"].append(mesh.name)
            scene[KEY] = record
        key = apparent_meshes.geometry_key(obj)
        turns = motion.turns(obj, scene)
        if key is not None and turns:
            t_o, x_o, beta_o = snap.mesh_observer
            key = (*key, t_o, tuple(x_o), tuple(beta_o), snap.speed_of_light)
        if key is None or _written.get(mesh.name) != key:  # else the normals written are current
            normals = _corner_normals(mesh)
            if turns:
                normals = _turned_normals(scene, obj, snap, normals)
            _write_attribute(mesh, normals)
            _written[mesh.name] = key
        for slot in obj.material_slots:
            attach(slot.material, group)


def written(scene: Scene) -> bool:
    """Whether anything of this stage may be in the file: its record on the scene or its shader
    group (what :func:`write` makes first); a sync with nothing lit skips :func:`remove`'s pass over
    every material and mesh otherwise (issue 26: 2 ms a sync on 1,000 meshes)."""
    return KEY in scene or names.REST_NORMAL_GROUP in bpy.data.node_groups or bool(_written)


def remove(scene: Scene) -> None:
    """Detach the group from every material, delete the attributes the stage added and the group."""
    _written.clear()
    for material in bpy.data.materials:
        detach(material)
    added: list[Mesh | None] = [mesh for mesh in bpy.data.meshes if MESH_KEY in mesh and mesh.library is None]
    if KEY in scene:  # also a file set up before meshes were marked
        added += [bpy.data.meshes.get(name) for name in scene[KEY].to_dict()["meshes"]]
        del scene[KEY]
    for mesh in added:
        attribute = mesh.attributes.get(ATTRIBUTE) if mesh is not None else None
        if attribute is not None:
            mesh.attributes.remove(attribute)
        if mesh is not None and MESH_KEY in mesh:
            del mesh[MESH_KEY]
    nodes.remove_unused_groups([names.REST_NORMAL_GROUP])
