"""Principled Volume blackbodies inside shared node groups, fast mode: seen at ``D T`` too.

The correction of ``volumes.py`` has two halves. The emission half (``X - E`` for camera rays, the
volume blackbody group) depends on the shading point and the ray only: the observer's ``D`` from
the ray's direction (a volume is at rest) and the Principled Volume's own ``T``, so it can sit in
the shared group's tree, where ``volumes.attach_grouped`` already puts it for the spectral passes.
The boundary half (a Transparent BSDF writing the done AOV where a camera ray enters the gas) is
per material, and every material using the group has its own tree and Surface output: it goes
there, as a second volume blackbody group node whose ``Done`` alone is used.

So the group's ``Fast Part`` is switched on (:func:`attach_scene`) where every material of the
scene using the group can take the boundary: its active Material Output's Surface unlinked and its
Volume fed by a node group. A temperature grid is read inside the group (``volumes.attach_grouped``
puts an Attribute node there when a user may carry grids) and the bolometric rule follows the
grid's Alpha per point, where the ungrouped correction chooses it per material. A material taking the
boundary must have every grouped blackbody it uses switched on, since its done mask keeps all of
its pixels as rendered; the sets are narrowed until they agree. The same approximations as
ungrouped gas hold (what is seen through the gas keeps its rest colour; a camera inside the gas
gets no mask), and a material outside the scene that uses the group gets the shifted emission
without the mask (it is rendered by another scene).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..common import names
from . import materials, volumes

if TYPE_CHECKING:
    from bpy.types import Material, Node, Scene

PRINCIPLED = "ShaderNodeVolumePrincipled"
BOUNDARY = names.VOLUME_GROUPED_BOUNDARY_NODE
MASK = f"{names.VOLUME_BLACKBODY_NODE_PREFIX} Grouped Mask"
DONE = f"{names.VOLUME_BLACKBODY_NODE_PREFIX} Grouped Done"


def _correctors(material):
    """``(group tree, volume blackbody group node)`` of every corrected grouped blackbody of ``material``."""
    found = []
    for _group, inner, node in volumes.grouped_volume_nodes(material.node_tree):
        corrector = inner.nodes.get(f"{volumes.NODE_PREFIX} {node.name}")
        if node.bl_idname == PRINCIPLED and corrector is not None and corrector.bl_idname == "ShaderNodeGroup":
            found.append((inner, corrector))
    return found


def _can_take_boundary(material, on_grids):
    """Whether ``material``'s own tree can mark its volume's pixels done (Surface free, Volume from
    a node group), and every temperature grid its grouped blackbodies read has its reader."""
    tree = material.node_tree
    output, source = volumes.volume_output(tree)
    if output is None or source.node.bl_idname != "ShaderNodeGroup":
        return False
    surface = output.inputs["Surface"]
    if surface.is_linked and surface.links[0].from_node.name != BOUNDARY:
        return False
    for _group, inner, node in volumes.grouped_volume_nodes(tree):
        if node.bl_idname != PRINCIPLED or not volumes.emits_blackbody(node):
            continue
        reads_grid = on_grids and node.inputs["Temperature Attribute"].default_value
        if reads_grid and inner.nodes.get(f"{volumes.NODE_PREFIX} Grid {node.name}") is None:
            return False
    return True


def handled(material: Material) -> bool:
    """Whether ``material``'s grouped blackbodies are shifted in the fast mode (it has the boundary)."""
    return material.node_tree is not None and material.node_tree.nodes.get(BOUNDARY) is not None


def attach_scene(scene: Scene) -> None:
    """Switch the fast part on in every shared group whose users in ``scene`` all take the boundary,
    put the boundary into those users' trees, and take it out of the others (after
    ``volumes.attach_scene``)."""
    grids = volumes.grid_materials(scene)
    users: dict[str, list[Material]] = {}
    correctors: dict[str, list[Node]] = {}
    candidates = set()
    for material, _temperature in materials.scene_materials(scene):
        if material.node_tree is None or not materials.is_attached(material):
            continue
        found = _correctors(material)
        for inner, corrector in found:
            users.setdefault(inner.name, []).append(material)
            correctors.setdefault(inner.name, []).append(corrector)
        if found and _can_take_boundary(material, material in grids):
            candidates.add(material.name)
    while True:  # a group is on where all its users take the boundary; a user takes it where all its groups are on
        on = {name for name, using in users.items() if all(m.name in candidates for m in using)}
        dropped = {m.name for name, using in users.items() if name not in on for m in using} & candidates
        if not dropped:
            break
        candidates -= dropped
    for name, group_nodes in correctors.items():
        for corrector in group_nodes:
            corrector.inputs["Fast Part"].default_value = 1.0 if name in on else 0.0
    for using in users.values():
        for material in using:
            if material.name in candidates:
                _add_boundary(material)
            else:
                _remove_boundary(material)


def _add_boundary(material):
    """The boundary of the ungrouped correction in ``material``'s own tree, recorded like its nodes
    (``materials.detach`` removes them, and with them the link to the Surface input)."""
    tree = material.node_tree
    if tree.nodes.get(BOUNDARY) is not None:
        return
    output, _source = volumes.volume_output(tree)
    mask = tree.nodes.new("ShaderNodeGroup")
    mask.node_tree = bpy.data.node_groups[volumes.GROUP]
    boundary = tree.nodes.new("ShaderNodeBsdfTransparent")
    done = tree.nodes.new("ShaderNodeOutputAOV")
    done.aov_name = materials.DONE_AOV
    tree.links.new(boundary.outputs[0], output.inputs["Surface"])
    tree.links.new(mask.outputs["Done"], done.inputs["Value"])
    records = [record.to_dict() for record in material[materials.ATTACHED_KEY]]
    temperature = records[0]["object_temperature"] if records else 0.0
    for node, name in ((mask, MASK), (boundary, BOUNDARY), (done, DONE)):
        node.name = node.label = name
        node.location, node.hide = (output.location.x - 200.0, output.location.y - 300.0), True
        records.append(
            {
                "group_node": name,
                "target": "",
                "socket": "",
                "source_node": "",
                "source_socket": "",
                "object_temperature": temperature,
            }
        )
    material[materials.ATTACHED_KEY] = records
    # the pixel's ln D is that of what lies behind, the same direction: the material's writer off
    log_doppler = tree.nodes.get(f"{materials.NODE_PREFIX} AOV")
    if log_doppler is not None:
        log_doppler.mute = True


def _remove_boundary(material):
    tree = material.node_tree
    if tree.nodes.get(BOUNDARY) is None:
        return
    for name in (MASK, BOUNDARY, DONE):
        node = tree.nodes.get(name)
        if node is not None:
            tree.nodes.remove(node)
    records = [record.to_dict() for record in material[materials.ATTACHED_KEY]]
    material[materials.ATTACHED_KEY] = [r for r in records if r["group_node"] not in (MASK, BOUNDARY, DONE)]
    log_doppler = tree.nodes.get(f"{materials.NODE_PREFIX} AOV")
    if log_doppler is not None:
        log_doppler.mute = False
