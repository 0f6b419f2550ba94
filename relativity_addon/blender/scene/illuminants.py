"""Which lamps lit the scene, for the fast mode's reflected light (``physics/illuminants.py``).

The fast mode reads a pixel's colour as a spectrum and shifts that. Light that a blackbody lamp
at ``T`` sent onto surfaces is a reflectance times ``B(lambda, T)``; everything else (emitters
and the world seen directly, light of white or RGB lamps and of the world) is read as an RGB
colour in 6504 K white, the emitters' reading. So the lamps are sorted by temperature into light
groups (``light_groups.py``), whose passes the compositor reads through their own tables.

*Lit By* (``Scene.relativity.fast_illuminant``) chooses the lamps:

- **Automatic**: every blackbody lamp by its own temperature. Blackbody lamps are lights with
  power whose spectrum is a blackbody (``sources.light_blackbody``: their own temperature or a
  Blackbody in their node tree), meshes whose emission colours are one blackbody (a Blackbody node,
  also inside node groups, or the object's blackbody temperature) and a world whose background is
  one. At most ``len(names.LIT_GROUPS)`` temperatures get a group, the most frequent ones; the
  others' light is read in white.
- **White**: no groups: every pixel in white, as emitters (the reading before light groups).
- **Blackbody**: every light object (not emitting meshes nor the world) as a blackbody at the
  temperature given.

A light with its own velocity is hidden while applied and drawn by stand-in lamps whose shader
gives each surface point its own ``D T`` (``lights/stand_in_lamps.py``), so no table of one
temperature reads it. In the fast mode (not *White*) the stand-ins of a moving blackbody light go
into the light group ``names.OBSERVED_LIGHT_GROUP`` instead, and their shader also applies the
observer's shift (:func:`reads_observed`); the compositor adds only the reflectance's shift.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

from ..common import names
from . import grouped_colours, sources

if TYPE_CHECKING:
    from collections.abc import Collection

    from bpy.types import Scene

OWN_PREFIX = "Relativity"  # the add-on's stand-in lamps, copies and lamp faces
STRENGTHS = {"ShaderNodeEmission": "Strength", "ShaderNodeBsdfPrincipled": "Emission Strength"}
WORLD = ""  # the world's entry in a group's members


class LitGroup(NamedTuple):
    """Lamps of one blackbody temperature: their object names, and :data:`WORLD` for the world."""

    temperature: float
    members: tuple


def _emission(tree):
    """``(temperatures, emits)`` of a material's tree: the temperatures of its blackbody emission
    colours with strength, and whether it has an emission colour at all."""
    found, emits = set(), False
    for node, socket, is_emission in grouped_colours.targets(tree):
        emits |= is_emission
        strength = node.inputs.get(STRENGTHS.get(node.bl_idname, ""))
        if not is_emission or (strength is not None and sources.constant_value(strength) == 0.0):
            continue
        blackbody = sources.blackbody_source(sources.rest_colour_input(socket))  # in front of the colour group
        if blackbody is not None and isinstance(blackbody.temperature, float):
            found.add(blackbody.temperature)
    return found, emits


def _lamp_temperature(obj, seen):
    """The blackbody temperature of a lamp object (a light or an emitting mesh), or None;
    ``seen`` caches each material's :func:`_emission`."""
    if obj.type == "LIGHT":
        return sources.light_blackbody(obj.data) if obj.data.energy > 0.0 else None
    found = set()
    for slot in obj.material_slots:
        material = slot.material
        if material is None or material.node_tree is None:
            continue
        if material.name not in seen:
            seen[material.name] = _emission(material.node_tree)
        temperatures, emits = seen[material.name]
        found |= temperatures
        if obj.relativity.temperature and emits:
            found.add(float(obj.relativity.temperature))
    return found.pop() if len(found) == 1 else None


def _world_temperature(world):
    if world is None or world.node_tree is None:
        return None
    found = set()
    for background in [node for node in world.node_tree.nodes if node.bl_idname == "ShaderNodeBackground"]:
        blackbody = sources.blackbody_source(sources.rest_colour_input(background.inputs["Color"]))
        found.add(blackbody.temperature if blackbody is not None and isinstance(blackbody.temperature, float) else None)
    return found.pop() if len(found) == 1 else None


def _candidates(scene, moving):
    return [
        obj
        for obj in scene.objects
        if not obj.hide_render and not obj.name.startswith(OWN_PREFIX) and obj.name not in moving
    ]


def lit_groups(scene: Scene, moving: Collection[str] = ()) -> tuple[LitGroup, ...]:
    """The light groups of the fast mode's blackbody lamps, by *Lit By* (tuple of :class:`LitGroup`);
    ``moving``: the names of lights with their own velocity, drawn by stand-in lamps, left out."""
    settings = scene.relativity
    if settings.fast_illuminant == "WHITE":
        return ()
    if settings.fast_illuminant == "BLACKBODY":
        members = tuple(sorted(obj.name for obj in _candidates(scene, moving) if obj.type == "LIGHT"))
        return (LitGroup(float(settings.fast_illuminant_temperature), members),) if members else ()
    by_temperature, seen = {}, {}
    for obj in _candidates(scene, moving):
        if obj.type in ("LIGHT", "MESH", "CURVE", "SURFACE", "META", "FONT"):
            temperature = _lamp_temperature(obj, seen)
            if temperature is not None:
                by_temperature.setdefault(temperature, []).append(obj.name)
    world_temperature = _world_temperature(scene.world)
    if world_temperature is not None:
        by_temperature.setdefault(world_temperature, []).append(WORLD)
    ranked = sorted(by_temperature.items(), key=lambda item: (-len(item[1]), item[0]))[: len(names.LIT_GROUPS)]
    return tuple(LitGroup(temperature, tuple(sorted(members))) for temperature, members in ranked)


def user_light_groups(scene: Scene) -> list[str]:
    """Names of the light groups of ``scene``'s view layers that are not the add-on's."""
    own = {*names.LIT_GROUPS, names.OBSERVED_LIGHT_GROUP}
    return sorted({group.name for layer in scene.view_layers for group in layer.lightgroups} - own)


def reads_observed(scene: Scene) -> bool:
    """Whether the stand-in lamps of moving blackbody lights light the observed light group (not
    with *White*, nor where the scene has light groups of its own, whose lamps are read in white)."""
    return scene.relativity.fast_illuminant != "WHITE" and not user_light_groups(scene)
