"""The fast mode's light groups: blackbody lamps sorted by temperature (``illuminants.py``).

Cycles renders, per view-layer light group, the light its lamps (lights, emitting objects, the
world) contribute to each pixel, by any number of bounces. The exact camera's compositor stage
reads each group's pass through the table of its lamps' blackbody (``physics/illuminant.py``) and
the rest of the pixel through the emitters' table (``compositing.py``).

Everything set is recorded on the scene (``names.LIGHT_GROUPS_KEY``) and given back by
:func:`release`: the light groups added to the view layers, and each object's and the world's
light group, which is only ever set where it was empty. A view layer that already has light
groups of the user's is left alone: its lamps are read in white (:func:`user_groups`).
"""

import bpy

from . import illuminants, names

KEY = names.LIGHT_GROUPS_KEY
SLOTS = names.LIT_GROUPS


def user_groups(scene):
    """Names of the light groups of ``scene``'s view layers that are not the add-on's."""
    return sorted({group.name for layer in scene.view_layers for group in layer.lightgroups} - set(SLOTS))


def warnings(scene, snap):
    """One line when blackbody lamps are read in white because the scene has its own light groups."""
    if snap.lit_groups and user_groups(scene):
        return [f"Fast colour reads the lamps in white light: the scene has its own light groups "
                f"({', '.join(user_groups(scene))}); Render Spectral is exact"]
    return []


def hold(scene):
    """Add the slots' light groups to every view layer (before the compositor stage links their passes)."""
    if KEY in scene or user_groups(scene):
        return False
    for layer in scene.view_layers:
        for name in SLOTS:
            layer.lightgroups.add(name=name)
    scene[KEY] = {"objects": {}, "world": {}}
    return True


def assign(scene, groups):
    """Put the lamps of ``groups`` (``illuminants.LitGroup``, one per slot) into the slots' light
    groups and take every other lamp the add-on put there out again. Returns the temperature of
    each slot (0: empty)."""
    if KEY not in scene:
        return (0.0,) * len(SLOTS)
    record = scene[KEY]
    wanted = {member: SLOTS[index] for index, group in enumerate(groups) for member in group.members}
    held_objects, held_worlds = dict(record["objects"]), dict(record["world"])
    for name in list(held_objects):
        obj = bpy.data.objects.get(name)
        if obj is not None and name not in wanted:
            obj.lightgroup = held_objects.pop(name)
    for member, slot in wanted.items():
        if member == illuminants.WORLD:
            continue
        obj = bpy.data.objects.get(member)
        if obj is None or (member not in held_objects and obj.lightgroup):
            continue  # the user's own light group
        held_objects.setdefault(member, obj.lightgroup)
        if obj.lightgroup != slot:
            obj.lightgroup = slot
    world = scene.world
    world_slot = wanted.get(illuminants.WORLD)
    if world is not None and world_slot is not None and (world.name in held_worlds or not world.lightgroup):
        held_worlds.setdefault(world.name, world.lightgroup)
        if world.lightgroup != world_slot:
            world.lightgroup = world_slot
    for name in list(held_worlds):
        held = bpy.data.worlds.get(name)
        if held is not None and (held != world or world_slot is None):
            held.lightgroup = held_worlds.pop(name)
    if dict(record["objects"]) != held_objects or dict(record["world"]) != held_worlds:
        scene[KEY] = {"objects": held_objects, "world": held_worlds}
    temperatures = [group.temperature for group in groups] + [0.0] * len(SLOTS)
    return tuple(temperatures[:len(SLOTS)])


def release(scene):
    """Give back every light group set and remove the slots' light groups."""
    if KEY not in scene:
        return False
    record = scene[KEY].to_dict()
    for name, group in record["objects"].items():
        obj = bpy.data.objects.get(name)
        if obj is not None:
            obj.lightgroup = group
    for name, group in record["world"].items():
        world = bpy.data.worlds.get(name)
        if world is not None:
            world.lightgroup = group
    for layer in scene.view_layers:
        for name in SLOTS:
            group = layer.lightgroups.get(name)
            if group is not None:
                layer.lightgroups.remove(group)
    del scene[KEY]
    return True
