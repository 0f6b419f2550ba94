"""Light that no lamp carries reaching moving objects: the world, emitting meshes, and light
bounced off objects at rest.

Lamps at rest reach moving objects through light-linked copies with eq. 18's Doppler factor
(``lamps_on_moving_objects.py``); the world's light, that of emitting meshes (at rest, or moving
without Lights Scene) and the light surfaces at rest reflect (Cycles renders one snapshot in the
scene frame) reach them as Cycles computes it there, unshifted. What that leaves
(docs/lamp-doppler.md, "Approximate cases": 0.86x of eq. 18 on a face across the motion at 0.5c,
0.27x and 5.1x toward and away from it) is said in one panel line; this module finds whether a
scene has such light.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..colour import world_sampling
from ..common import compat
from ..geometry import modifier
from ..scene import emitting_meshes

if TYPE_CHECKING:
    from collections.abc import Iterator, Sequence

    from bpy.types import Material, NodeTree, Object, Scene, World

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "FONT", "META", "CURVES", "POINTCLOUD", "VOLUME"}


def sources(scene: Scene, moving: Sequence[Object]) -> str | None:
    """What lights the ``moving`` objects besides the lamps, with no Doppler factor, to follow
    "Light": "from the world", "from emitting meshes" (at rest, or moving without Lights Scene; a
    moving object's own emission does not count for itself), "from the world and emitting meshes",
    "bounced off objects at rest" (:func:`bounces_at_rest`), "from ... or bounced off objects at
    rest", or None."""
    world = scene.world is not None and world_lights(scene.world)
    emitting = {material for material in bpy.data.materials if emitting_meshes.emits(material)}
    receivers = {obj.name for obj in moving}
    meshes = bool(emitting) and any(
        any(slot.material in emitting for slot in obj.material_slots)
        for obj in scene.objects
        if receivers - {obj.name} and not obj.hide_render and not emitting_meshes.is_emitter_light(obj)
    )
    parts = [part for part, used in (("the world", world), ("emitting meshes", meshes)) if used]
    said = [f"from {' and '.join(parts)}"] if parts else []
    said += ["bounced off objects at rest"] if bounces_at_rest(scene, moving) else []
    return " or ".join(said) or None


def objects_at_rest(scene: Scene, moving: Sequence[Object]) -> Iterator[Object]:
    """The objects the scene renders at rest (not in ``moving``): geometry, not the add-on's caches."""
    moving_names = {obj.name for obj in moving}
    return (
        obj
        for obj in scene.objects
        if obj.type in GEOMETRY_TYPES
        and obj.name not in moving_names
        and not obj.hide_render
        and not modifier.is_cache(obj)
    )


def bounces_at_rest(scene: Scene, moving: Sequence[Object]) -> bool:
    """Whether light bounced off objects at rest reaches the ``moving`` objects: Cycles bounces light
    (Max Bounces and diffuse, glossy or transmission bounces above 0) and some object at rest
    renders a surface that reflects (no material, or one with a BSDF; not emission alone)."""
    cycles = scene.cycles
    bounces = max(cycles.diffuse_bounces, cycles.glossy_bounces, cycles.transmission_bounces)
    if cycles.max_bounces <= 0 or bounces <= 0:
        return False
    return any(
        not obj.material_slots or any(_reflects(slot.material) for slot in obj.material_slots)
        for obj in objects_at_rest(scene, moving)
    )


def _reflects(material: Material | None) -> bool:
    """Whether ``material`` reflects light: none (Cycles' grey), no node tree (its colour) or a BSDF in use."""
    tree = None if material is None else compat.rendered_node_tree(material)
    return tree is None or _has_bsdf(tree)


def _has_bsdf(tree: NodeTree, depth: int = 0) -> bool:
    """Whether ``tree`` (or a group in it, a few levels deep) has a BSDF in use."""
    for node in tree.nodes:
        if node.mute or not any(output.is_linked for output in node.outputs):
            continue
        if node.bl_idname.startswith("ShaderNodeBsdf") or node.bl_idname == "ShaderNodeSubsurfaceScattering":
            return True
        group = getattr(node, "node_tree", None)
        if group is not None and depth < 4 and _has_bsdf(group, depth + 1):
            return True
    return False


def world_lights(world: World) -> bool:
    """Whether ``world`` sends light: anything but a black (or zero-strength) constant background."""
    if compat.rendered_node_tree(world) is None:
        return any(value > 0.0 for value in world.color)
    background = world_sampling.constant_background(world)
    if background is None:
        return True
    colour, strength = background.inputs["Color"].default_value, background.inputs["Strength"].default_value
    return strength > 0.0 and any(value > 0.0 for value in tuple(colour)[:3])
