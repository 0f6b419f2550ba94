"""The fast mode's light groups: blackbody lamps sorted by temperature (``illuminants.py``).

Cycles renders, per view-layer light group, the light its lamps (lights, emitting objects, the
world) contribute to each pixel, by any number of bounces. The exact camera's compositor stage
reads each group's pass through the table of its lamps' blackbody (``physics/illuminants.py``) and
the rest of the pixel through the emitters' table (``compositing.py``).

Everything set is recorded on the scene (``names.LIGHT_GROUPS_KEY``) and given back by
:func:`release`: the light groups added to the view layers, and each object's and the world's
light group, which is only ever set where it was empty. A view layer that already has light
groups of the user's is left alone: its lamps are read in white (:func:`user_groups`).

The stand-in lamps of moving blackbody lights (``Snapshot.observed_lights``) go into one more
light group, :data:`OBSERVED`: their shader already gives the illuminant the observer sees (each
surface point's own ``D T`` shifted by the observer's ``D``), and the compositor adds only the
reflectance's own shift to that pass (``compositing.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..common import compat, names
from ..scene import illuminants

if TYPE_CHECKING:
    from collections.abc import Sequence

    from bpy.types import Node, NodeTree, Scene

    from ..scene.illuminants import LitGroup
    from ..scene.snapshot import Snapshot

KEY = names.LIGHT_GROUPS_KEY
SLOTS = names.LIT_GROUPS
OBSERVED = names.OBSERVED_LIGHT_GROUP
GROUPS = (*SLOTS, OBSERVED)  # every light group the add-on adds, in the compositor's order


def user_groups(scene: Scene) -> list[str]:
    """Names of the light groups of ``scene``'s view layers that are not the add-on's."""
    return illuminants.user_light_groups(scene)


def stand_ins(scene: Scene, lights: Sequence[str]) -> list[str]:
    """The stand-in lamps of the moving lights named ``lights`` (``lights/stand_in_lamps.py``'s record)."""
    record = scene.get(names.MOVING_LAMPS_KEY)
    if record is None:
        return []
    return [name for light in lights for name in record.get(light, ())]


def warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """One line when blackbody lamps are read in white because the scene has its own light groups."""
    if snap.lit_groups and user_groups(scene):
        return [
            f"Fast colour reads the lamps in white light: the scene has its own light groups "
            f"({', '.join(user_groups(scene))}); Render Spectral is exact"
        ]
    return []


def hold(scene: Scene) -> bool:
    """Add the slots' light groups to every view layer (before the compositor stage links their passes)."""
    if KEY in scene or user_groups(scene):
        return False
    for layer in scene.view_layers:
        for name in GROUPS:
            layer.lightgroups.add(name=name)
    scene[KEY] = {"objects": {}, "world": {}}
    return True


def _datablock(kind, name):
    """The object or world ``name`` (``kind``: a key of the record), or None."""
    return (bpy.data.objects if kind == "objects" else bpy.data.worlds).get(name)


def observed_held(scene: Scene) -> bool:
    """Whether the view layers hold the observed light group (not in a file set up before it)."""
    return KEY in scene and all(layer.lightgroups.get(OBSERVED) is not None for layer in scene.view_layers)


def assign(scene: Scene, groups: Sequence[LitGroup], observed: Sequence[str] = ()) -> tuple[float, ...]:
    """Put the lamps of ``groups`` (``illuminants.LitGroup``, one per slot) into the slots' light
    groups and the objects named ``observed`` into :data:`OBSERVED`, and take every other lamp the
    add-on put there out again. Returns the temperature of each slot (0: empty)."""
    if KEY not in scene:
        return (0.0,) * len(SLOTS)
    record = scene[KEY]
    wanted = {("objects", name): OBSERVED for name in observed} if observed_held(scene) else {}
    for index, group in enumerate(groups):
        for member in group.members:
            if member != illuminants.WORLD:
                wanted["objects", member] = SLOTS[index]
            elif scene.world is not None:
                wanted["world", scene.world.name] = SLOTS[index]
    held = {kind: dict(record[kind]) for kind in ("objects", "world")}
    for kind, names_held in held.items():
        for name in list(names_held):
            block = _datablock(kind, name)
            if block is not None and (kind, name) not in wanted:
                block.lightgroup = names_held.pop(name)
    for (kind, name), slot in wanted.items():
        block = _datablock(kind, name)
        if block is None or (name not in held[kind] and block.lightgroup):
            continue  # the user's own light group
        held[kind].setdefault(name, block.lightgroup)
        if block.lightgroup != slot:
            block.lightgroup = slot
    if any(dict(record[kind]) != held[kind] for kind in held):
        scene[KEY] = held
    temperatures = [group.temperature for group in groups] + [0.0] * len(SLOTS)
    return tuple(temperatures[: len(SLOTS)])


def release(scene: Scene) -> bool:
    """Give back every light group set and remove the slots' light groups."""
    if KEY not in scene:
        return False
    record = scene[KEY].to_dict()
    for kind, names_held in record.items():
        for name, group in names_held.items():
            block = _datablock(kind, name)
            if block is not None:
                block.lightgroup = group
    for layer in scene.view_layers:
        for name in GROUPS:
            group = layer.lightgroups.get(name)
            if group is not None:
                layer.lightgroups.remove(group)
    del scene[KEY]
    return True


def mute_observed_branch(nodes: Sequence[Node]) -> None:
    """Mute the observed group's reflectance shift in the compositor stage's group of ``nodes``
    unless a lamp of the file is in an observed group: the group then passes that pass through
    and the compositor evaluates none of the branch (benchmarks/observed_group_cost.py)."""
    in_use = any(obj.lightgroup == OBSERVED for obj in bpy.data.objects)
    for group in {node.node_tree for node in nodes if node.node_tree is not None}:
        branch = group.nodes.get("observed_seen")
        if branch is not None and branch.mute == in_use:
            branch.mute = not in_use


def link_diffuse_colour(tree: NodeTree, layers: Node, node: Node) -> None:
    """Link the Diffuse Color pass of ``layers`` (a Render Layers node of ``tree``, which shows the
    pass once updated) into the compositor stage's group ``node`` (the observed group's reflectance shift)."""
    socket = node.inputs.get("Diffuse Color")
    if socket is None or socket.is_linked:
        return
    layers.update()
    output = compat.render_layers_diffuse_colour(layers)
    if output is not None:
        tree.links.new(output, socket)
