"""Which light lit the scene, for the fast mode's reflected light (``physics/illuminant.py``).

The fast mode reads a reflected pixel as a reflectance under one illuminant. ``Lit By`` chooses
it (``Scene.relativity.fast_illuminant``); Automatic takes the scene's lamps: a blackbody at
``T`` when every lamp is a blackbody at that one temperature, else white (6504 K, the emitters'
white). Lamps are the scene's lights with power (``sources.light_blackbody``: their own
temperature or a Blackbody in their node tree; any other light is "not a blackbody"), meshes
whose emission colour is a blackbody (``sources.blackbody_source``, through node groups, or the
object's blackbody temperature) and a world whose background is one. Meshes that emit RGB colours
and an RGB world do not count: they are usually what is seen, not what lights (a grey world's
ambient fill, a glowing screen); Lit By: White or Blackbody overrides the choice.
"""

from . import grouped_colours, sources

OWN_PREFIX = "Relativity"  # the add-on's stand-in lamps, copies and lamp faces
STRENGTHS = {"ShaderNodeEmission": "Strength", "ShaderNodeBsdfPrincipled": "Emission Strength"}


def _blackbody_emission(tree):
    """Temperatures of the blackbody emission colours of a material or world tree with strength."""
    found = set()
    for node, socket, is_emission in grouped_colours.targets(tree):
        strength = node.inputs.get(STRENGTHS.get(node.bl_idname, ""))
        if not is_emission or (strength is not None and sources.constant_value(strength) == 0.0):
            continue
        blackbody = sources.blackbody_source(sources.rest_colour_input(socket))  # in front of the colour group
        if blackbody is not None and isinstance(blackbody.temperature, float):
            found.add(blackbody.temperature)
    return found


def scene_blackbody_temperature(scene):
    """Temperature (K) of the one blackbody that lights ``scene``, or None (white, mixed or none)."""
    temperatures, other = set(), False
    for obj in scene.objects:
        if obj.hide_render or obj.name.startswith(OWN_PREFIX):
            continue
        if obj.type == "LIGHT":
            if obj.data.energy > 0.0:
                temperature = sources.light_blackbody(obj.data)
                other |= temperature is None
                temperatures |= {temperature} - {None}
            continue
        for slot in obj.material_slots:
            material = slot.material
            if material is None or material.node_tree is None:
                continue
            emitted = _blackbody_emission(material.node_tree)
            if obj.relativity.temperature and any(is_emission for *_, is_emission in
                                                  grouped_colours.targets(material.node_tree)):
                emitted.add(float(obj.relativity.temperature))
            temperatures |= emitted
    world = scene.world
    if world is not None and world.node_tree is not None:
        backgrounds = [node for node in world.node_tree.nodes if node.bl_idname == "ShaderNodeBackground"]
        for background in backgrounds:
            blackbody = sources.blackbody_source(sources.rest_colour_input(background.inputs["Color"]))
            if blackbody is not None and isinstance(blackbody.temperature, float):
                temperatures.add(blackbody.temperature)
    return next(iter(temperatures)) if len(temperatures) == 1 and not other else None


def fast_illuminant(scene):
    """The fast mode's illuminant from the settings: a temperature (K), or 0.0 for white."""
    settings = scene.relativity
    if settings.fast_illuminant == "BLACKBODY":
        return float(settings.fast_illuminant_temperature)
    if settings.fast_illuminant == "AUTO":
        return float(scene_blackbody_temperature(scene) or 0.0)
    return 0.0
