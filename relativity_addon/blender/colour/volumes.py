"""Principled Volume blackbodies on the exact camera's path: seen as blackbodies at ``D T``.

Volume shaders write no AOVs in Cycles, so a volume's pixel used to carry the ``ln D`` and done
mask of what lies behind it, and the compositor shifted the volume's light by the RGB Doppler
matrix (Delta E 2000 of 27 from the blackbody at ``D T`` = 1.70 x 3000 K). Undoing the matrix
instead (emitting ``N(D)^-1`` of the wanted colour) is hopeless: ``M(D)`` is nearly rank one away
from ``D`` = 1 (condition number 1.3e9 at 1.7; docs/spectral-model.md). So, like a blackbody
emitter, the volume does the exact shift itself and marks its pixels done:

- **volume**: for camera rays, the group (``volume_nodes.py``) adds ``X - E`` to the Principled Volume's own
  blackbody emission ``E = tint sigma mix(1, T^4, intensity) B(T)`` (Cycles' formula,
  ``sigma = 5.670373e-14 / pi``, ``B`` the Blackbody node's colour; measured equal to Cycles' own
  to 2e-4), where ``X`` is what the materials' Doppler colour group makes of a blackbody colour
  ``E``: the blackbody at ``D T`` with ``E``'s luminance times ``Y(D T) / Y(T)``, divided by the
  camera's ``D^4``. ``X - E`` may be negative per channel; Cycles adds volume emission as it is.
  (With a temperature grid ``X`` follows the bolometric rule and replaces ``E``: see below.)
  Other rays (the volume lighting the scene) carry ``E``, the scene-frame light;
- **boundary**: a Transparent BSDF on the volume's surface (the material had none) writes the
  ``relativity_colour_done`` AOV where a camera ray enters the volume (front faces), so the
  compositor keeps those pixels; the material's ``ln D`` writer is muted.

Approximation (fast mode): the done mask keeps *everything* in the pixel as rendered, so what lies
behind the volume (seen through it) is not shifted: right against a black background or a
blackbody emitter, wrong in front of anything else. A camera inside the volume gets no mask (the
volume is then shifted again by the compositor). ``D`` is the observer's (a volume at rest in the
scene frame).

**Spectral mode** (``spectral_render``): the passes carry volumes like surfaces, so nothing above is
needed and what is seen through a volume is right too. In a pass the group's fast part and done
mask are 0, its ``Intensity`` output switches Cycles' RGB blackbody off, and its ``Color`` is
``E``'s spectral values (the blackbody at ``T`` with ``E``'s luminance; ``spectral_nodes``).
:func:`attach_colours` puts ``spectral_nodes.volume_colour_group`` in front of the volume colours
(:data:`VOLUME_COLOURS`: absorption and scatter colours up-sampled as reflectances, which Cycles'
per-channel formulas then apply per wavelength; emission colours as emitted colours;
docs/spectral-model.md). A Principled Volume blackbody inside a node group gets the group's
spectral part in the group's tree (:func:`attach_grouped`; ``grouped_volumes.py`` for the fast
part). What cannot be made spectral is refused in one line (:func:`spectral_problem`).

Recognised (``sources.volume_blackbody``): a Principled Volume feeding the active Material
Output's Volume input directly, the Surface input unlinked, a grey Blackbody Tint, a constant
Blackbody Intensity and a constant or linked Temperature (a node field is followed per point).

**Temperature grids** (a Volume object or fluid domain whose Temperature Attribute names a grid;
:func:`grid_materials`) follow the **bolometric rule** (docs/spectral-model.md, "Temperature
grids"): Cycles' own emission at ``D T`` (times ``D^(p - 4)``), finite where the gas fades to 0 K.
For camera rays the group feeds the Principled Volume's Temperature (times ``D``) and Blackbody Tint
(times the rule's gain), so Cycles reads the grid as at rest (docs/performance.md, "What is left":
5.2's Attribute node reads it 2.9 % dimmer, and 5.x's majorant grid evaluates no second read). The
boundary's AOV holds on Volume objects too (Cycles runs their surface AOV nodes). In a spectral
pass camera rays get ``E_bol(D T) B(mu, T) / Y_B(D T)``, other rays ``E`` up-sampled as RGB.
Not covered: a Principled Volume behind a Mix or Add shader or with a surface
shader (also refused by the spectral mode when it emits a blackbody; on an object with grids a
panel warning names it), and Apparent Geometry's boosted meshes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..common import names
from ..common.nodes import ensure_group
from ..scene import grouped_colours, sources
from . import materials, spectral_nodes
from .volume_nodes import volume_blackbody_group

if TYPE_CHECKING:
    from collections.abc import Iterator

    from bpy.types import Material, NodeTree, Scene

GROUP = names.VOLUME_BLACKBODY_GROUP
NODE_PREFIX = names.VOLUME_BLACKBODY_NODE_PREFIX
COLOUR_GROUP = names.VOLUME_COLOUR_GROUP
COLOUR_PREFIX = names.VOLUME_COLOUR_NODE_PREFIX
# (node type, input names) of volume colours made spectral in the passes (an Emission node in a
# volume already has the materials' colour group); True: an emitted colour, else a reflectance-like
# coefficient (scattering albedo, absorption colour), up-sampled as a reflectance.
VOLUME_COLOURS = (
    ("ShaderNodeVolumePrincipled", (("Color", False), ("Absorption Color", False), ("Emission Color", True))),
    ("ShaderNodeVolumeAbsorption", (("Color", False),)),
    ("ShaderNodeVolumeScatter", (("Color", False),)),
)
UNSUPPORTED_VOLUME_NODES = ("ShaderNodeVolumeCoefficients",)  # RGB coefficients: no spectrum to give them
VOLUME_KINDS = {kind for kind, _inputs in VOLUME_COLOURS} | set(UNSUPPORTED_VOLUME_NODES)


def volume_output(tree: NodeTree) -> tuple[bpy.types.Node | None, bpy.types.NodeSocket | None]:
    """``(active Material Output, what feeds its Volume input)``, or ``(None, None)``."""
    outputs = [node for node in tree.nodes if node.bl_idname == "ShaderNodeOutputMaterial"]
    output = next((node for node in outputs if node.is_active_output), outputs[0] if outputs else None)
    if output is None or not output.inputs["Volume"].is_linked:
        return None, None
    link = output.inputs["Volume"].links[0]
    return output, link.from_socket


def _correctable(material):
    """``(output, Principled Volume output socket, blackbody, intensity)`` where ``material``'s
    volume is a Principled Volume blackbody the correction handles, else None."""
    if material.node_tree is None:
        return None
    output, source = volume_output(material.node_tree)
    if output is None or source.node.bl_idname != "ShaderNodeVolumePrincipled" or output.inputs["Surface"].is_linked:
        return None
    blackbody = sources.volume_blackbody(source.node)
    intensity = sources.constant_value(source.node.inputs["Blackbody Intensity"])
    if blackbody is None or intensity is None:
        return None
    return output, source, blackbody, intensity


def _blackbody_group(tree, node, blackbody, intensity):
    """The correction's group node in ``tree`` for the Principled Volume ``node`` (its blackbody's
    temperature linked or set, its constant intensity and tint)."""
    ensure_group(volume_blackbody_group(), names.GROUP_VERSION_KEY, names.SHADER_GROUPS_VERSION)
    group = tree.nodes.new("ShaderNodeGroup")
    group.node_tree = bpy.data.node_groups[GROUP]
    group.name = group.label = f"{NODE_PREFIX} {node.name}"
    if isinstance(blackbody.temperature, float):
        group.inputs["Temperature"].default_value = blackbody.temperature
    else:
        tree.links.new(blackbody.temperature, group.inputs["Temperature"])
    group.inputs["Intensity"].default_value = intensity
    group.inputs["Tint"].default_value = tuple(node.inputs["Blackbody Tint"].default_value)[0]
    return group


def attach(material: Material, grids: bool = False) -> bool:
    """Add the camera-ray correction to a material whose volume is a Principled Volume blackbody
    (after ``materials.attach``, whose records restore it on detach). Returns whether it did.

    ``grids``: the material is on an object that may carry a temperature grid (:func:`grid_materials`);
    where its Temperature Attribute names one, an Attribute node reads it, so that the group
    follows Cycles' ``T`` = Temperature x max(grid, 0), and the group shifts by the bolometric rule
    (Cycles' own emission at ``D T``: finite where the grid fades to 0 K, docs/spectral-model.md)."""
    if not materials.is_attached(material):
        return False
    records = [record.to_dict() for record in material[materials.ATTACHED_KEY]]
    if any(record["group_node"].startswith(NODE_PREFIX) for record in records):
        _upgrade(material, material.node_tree, records)
        return False
    found = _correctable(material)
    if found is None:
        return False
    tree = material.node_tree
    output, source, blackbody, intensity = found
    node = source.node
    group = _blackbody_group(tree, node, blackbody, intensity)
    created = [group]
    grid_name = node.inputs["Temperature Attribute"].default_value if grids else ""
    if grid_name:
        attribute = tree.nodes.new("ShaderNodeAttribute")
        attribute.name = attribute.label = f"{NODE_PREFIX} Grid {node.name}"
        attribute.attribute_type = "GEOMETRY"
        attribute.attribute_name = grid_name
        tree.links.new(attribute.outputs["Fac"], group.inputs["Grid"])
        tree.links.new(attribute.outputs["Alpha"], group.inputs["Grid Alpha"])
        group.inputs["Bolometric"].default_value = 1.0
        created.append(attribute)
    temperature_source = _link_emission_inputs(tree, node, group)
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.name = emission.label = f"{NODE_PREFIX} Emission {node.name}"
    tree.links.new(group.outputs["Color"], emission.inputs["Color"])
    add = tree.nodes.new("ShaderNodeAddShader")
    add.name = add.label = f"{NODE_PREFIX} Add {node.name}"
    tree.links.new(source, add.inputs[0])
    tree.links.new(emission.outputs[0], add.inputs[1])
    tree.links.new(add.outputs[0], output.inputs["Volume"])
    # the boundary: see-through, marks the pixels entered as already shifted; the material's own
    # ln D writer is muted (the pixel's D is that of what lies behind, the same direction)
    boundary = tree.nodes.new("ShaderNodeBsdfTransparent")
    boundary.name = boundary.label = f"{NODE_PREFIX} Boundary {node.name}"
    tree.links.new(boundary.outputs[0], output.inputs["Surface"])
    done = tree.nodes.new("ShaderNodeOutputAOV")
    done.name = done.label = f"{NODE_PREFIX} Done {node.name}"
    done.aov_name = materials.DONE_AOV
    tree.links.new(group.outputs["Done"], done.inputs["Value"])
    log_doppler = tree.nodes.get(f"{materials.NODE_PREFIX} AOV")
    if log_doppler is not None:
        log_doppler.mute = True
    created += [emission, add, boundary, done]
    for new_node in created:
        new_node.location = (output.location.x - 200.0, output.location.y - 300.0)
        new_node.hide = True
    blank = {
        "target": "",
        "socket": "",
        "source_node": "",
        "source_socket": "",
        "object_temperature": records[0]["object_temperature"] if records else 0.0,
    }
    records += [{**blank, "group_node": new_node.name} for new_node in created if new_node is not add]
    records += [{**blank, **temperature_source, "group_node": group.name}]
    records += [
        {
            **blank,
            "group_node": add.name,
            "target": output.name,
            "socket": output.inputs["Volume"].identifier,
            "source_node": node.name,
            "source_socket": source.identifier,
        },
    ]
    material[materials.ATTACHED_KEY] = records
    return True


def _bolometric(group):
    """Whether the volume blackbody ``group`` node may shift by the bolometric rule (a grid read)."""
    bolometric = group.inputs["Bolometric"]
    return bolometric.is_linked or bolometric.default_value > 0.0


def _link_emission_inputs(tree, node, group):
    """Feed the Principled Volume ``node``'s Blackbody Intensity from the volume blackbody ``group``,
    and where the group may take the bolometric rule (:func:`_bolometric`) its Temperature and
    Blackbody Tint too (the rule shifts Cycles' own emission through them; the visible rule leaves
    them as they were). Returns the record fields that give the Temperature input its own link back
    on detach (``materials.resolve_record``; none where it was a constant, which stays in the socket)."""
    tree.links.new(group.outputs["Intensity"], node.inputs["Blackbody Intensity"])  # 0 in spectral passes
    temperature = node.inputs["Temperature"]
    if not _bolometric(group):
        return {}
    source = temperature.links[0].from_socket if temperature.is_linked else None
    tree.links.new(group.outputs["Temperature"], temperature)
    tree.links.new(group.outputs["Tint"], node.inputs["Blackbody Tint"])
    if source is None:
        return {}
    return {
        "target": node.name,
        "socket": temperature.identifier,
        "source_node": source.node.name,
        "source_socket": source.identifier,
    }


def _upgrade(owner, tree, records):
    """A correction put in before the group fed the Principled Volume's Temperature and Tint (group
    version 10; a file set up with an earlier add-on): link them, so that the bolometric rule, which
    the group no longer emits itself, reaches the gas; recorded on ``owner`` (material or group)."""
    for record in list(records):
        group = tree.nodes.get(record["group_node"])
        if group is None or group.bl_idname != "ShaderNodeGroup" or "Tint" not in group.outputs:
            continue
        node = tree.nodes.get(group.name.removeprefix(f"{NODE_PREFIX} "))
        if node is None or node.bl_idname != "ShaderNodeVolumePrincipled":
            continue
        temperature = node.inputs["Temperature"]
        if not _bolometric(group) or (temperature.is_linked and temperature.links[0].from_node == group):
            continue
        blank = {"target": "", "socket": "", "source_node": "", "source_socket": ""}
        records.append({**blank, **record, **_link_emission_inputs(tree, node, group), "group_node": group.name})
        owner[materials.ATTACHED_KEY] = records


def _reads_grids(obj):
    """Whether Cycles may multiply ``obj``'s volume Temperature by a temperature grid: a Volume
    object (OpenVDB grids) or a fluid domain (smoke and fire)."""
    return obj.type == "VOLUME" or any(
        modifier.type == "FLUID" and modifier.fluid_type == "DOMAIN" for modifier in obj.modifiers
    )


def grid_materials(scene: Scene) -> dict[Material, str]:
    """``{material: object name}`` of the materials on objects that may carry temperature grids:
    their emission is ``Temperature x grid``, which :func:`attach` reads with an Attribute node and
    shifts by the bolometric rule (a grid fades to 0 K at its edges, where ``Y(D T) / Y(T)`` of
    Cycles' ``sigma T^4`` glow explodes: docs/spectral-model.md)."""
    found = {}
    for obj in scene.objects:
        if _reads_grids(obj):
            for slot in obj.material_slots:
                if slot.material is not None:
                    found.setdefault(slot.material, obj.name)
    return found


def blackbody_materials(scene: Scene) -> list[str]:
    """Names of the materials of ``scene`` with a volume blackbody the correction handles
    (:func:`attach`, :func:`attach_grouped`)."""
    return [
        material.name
        for material, _temperature in materials.scene_materials(scene)
        if material.node_tree is not None
        and any(
            node.name.startswith(f"{NODE_PREFIX} Add ")
            for tree in (
                material.node_tree,
                *(inner for _group, inner, _node in grouped_volume_nodes(material.node_tree)),
            )
            for node in tree.nodes
        )
    ]


def attach_grouped(material: Material, grids: bool = False) -> bool:
    """The spectral part of the correction for Principled Volume blackbodies inside the node groups
    of an attached ``material``, in the group's tree (once for every material sharing it, recorded
    on the tree like the grouped colours, which ``grouped_colours.detach_all`` undoes): in a pass
    Cycles' RGB blackbody is off and the group emits its Planck spectrum, as in the material's own
    tree; outside the passes it adds nothing until ``grouped_volumes.attach_scene`` switches its
    ``Fast Part`` on (the done mask and boundary belong to each material using the group). Returns
    whether it did."""
    if not materials.is_attached(material) or material.node_tree is None:
        return False
    did = False
    for _group, inner, node in list(grouped_volume_nodes(material.node_tree)):
        existing = inner.nodes.get(f"{NODE_PREFIX} {node.name}")
        if inner.nodes.get(f"{NODE_PREFIX} Add {node.name}") is not None:
            if existing is not None:  # put in for another material, which may not carry grids
                reader = [
                    {"group_node": new.name, "target": "", "socket": "", "source_node": "", "source_socket": ""}
                    for new in _grid_reader(inner, node, existing, grids)
                ]
                inner[materials.ATTACHED_KEY] = [r.to_dict() for r in inner[materials.ATTACHED_KEY]] + reader
                did = did or bool(reader)
            # the reader's rule reaches the Principled Volume (also a group set up by an earlier version)
            _upgrade(inner, inner, [record.to_dict() for record in inner.get(materials.ATTACHED_KEY, [])])
            continue
        blackbody = sources.volume_blackbody(node)
        if blackbody is None:
            continue
        intensity = sources.constant_value(node.inputs["Blackbody Intensity"])
        if intensity is None or not node.outputs[0].is_linked:
            continue
        group = _blackbody_group(inner, node, blackbody, intensity)
        group.inputs["Fast Part"].default_value = 0.0  # on where every user takes the boundary (grouped_volumes)
        created = [group, *_grid_reader(inner, node, group, grids)]
        emission = inner.nodes.new("ShaderNodeEmission")
        emission.name = emission.label = f"{NODE_PREFIX} Emission {node.name}"
        add = inner.nodes.new("ShaderNodeAddShader")
        add.name = add.label = f"{NODE_PREFIX} Add {node.name}"
        targets = [link.to_socket for link in node.outputs[0].links]
        temperature_source = _link_emission_inputs(inner, node, group)
        inner.links.new(group.outputs["Color"], emission.inputs["Color"])
        inner.links.new(node.outputs[0], add.inputs[0])
        inner.links.new(emission.outputs[0], add.inputs[1])
        blank = {"target": "", "socket": "", "source_node": "", "source_socket": ""}
        records = [{**blank, "group_node": new.name} for new in (*created, emission)]
        records.append({**blank, **temperature_source, "group_node": group.name})
        for target in targets:
            inner.links.new(add.outputs[0], target)
            relink = {"target": target.node.name, "socket": target.identifier, "source_node": node.name}
            records.append({**relink, "group_node": add.name, "source_socket": node.outputs[0].identifier})
        for new in (*created, emission, add):
            new.location, new.hide = (node.location.x + 200.0, node.location.y - 200.0), True
        inner[materials.ATTACHED_KEY] = [record.to_dict() for record in inner.get(materials.ATTACHED_KEY, [])] + records
        did = True
    return did


def _grid_reader(inner, node, group, grids):
    """An Attribute node reading the temperature grid ``node`` names, feeding ``group`` (in a shared
    group's tree ``inner``), where a user of the group may carry grids and none is there yet:
    Cycles' ``T`` per point as in :func:`attach`, and the bolometric rule where the grid is (its
    Alpha: a shared group follows the shading point, not its users' objects). Returns the nodes added."""
    grid_name = node.inputs["Temperature Attribute"].default_value if grids else ""
    name = f"{NODE_PREFIX} Grid {node.name}"
    if not grid_name or inner.nodes.get(name) is not None:
        return []
    attribute = inner.nodes.new("ShaderNodeAttribute")
    attribute.name = attribute.label = name
    attribute.attribute_type = "GEOMETRY"
    attribute.attribute_name = grid_name
    inner.links.new(attribute.outputs["Fac"], group.inputs["Grid"])
    inner.links.new(attribute.outputs["Alpha"], group.inputs["Grid Alpha"])
    inner.links.new(attribute.outputs["Alpha"], group.inputs["Bolometric"])
    attribute.location, attribute.hide = (node.location.x + 200.0, node.location.y - 250.0), True
    return [attribute]


def attach_colours(material: Material) -> bool:
    """Put the volume colour group (``spectral_nodes.volume_colour_group``: unchanged outside the
    spectral passes) in front of every volume colour input of an attached ``material``
    (:data:`VOLUME_COLOURS`), recorded like ``materials.attach``'s groups. Returns whether it did."""
    if not materials.is_attached(material):
        return False
    records = [record.to_dict() for record in material[materials.ATTACHED_KEY]]
    if any(record["group_node"].startswith(COLOUR_PREFIX) for record in records):
        return False
    tree = material.node_tree
    targets = _volume_colour_inputs(tree.nodes)
    grouped = [(inner, _volume_colour_inputs([node])) for _group, inner, node in grouped_volume_nodes(tree)]
    if not targets and not grouped:
        return False
    group_tree = ensure_group(
        spectral_nodes.volume_colour_group(), names.GROUP_VERSION_KEY, names.SHADER_GROUPS_VERSION
    )
    for target, socket, emitted in targets:
        _node, record = materials.insert_colour_group(tree, group_tree, COLOUR_PREFIX, target, socket, emitted)
        record["object_temperature"] = records[0]["object_temperature"] if records else 0.0
        records.append(record)
    material[materials.ATTACHED_KEY] = records
    # inside node groups: once in the group's tree (shared by every material using it), recorded
    # on the tree like the surfaces' grouped colours (grouped_colours.py), which detach_all undoes
    for inner, inner_targets in grouped:
        inner_records = [record.to_dict() for record in inner.get(materials.ATTACHED_KEY, [])]
        for target, socket, emitted in inner_targets:
            if socket.is_linked and socket.links[0].from_node.name.startswith(COLOUR_PREFIX):
                continue  # put in for another material already
            inner_records.append(
                materials.insert_colour_group(inner, group_tree, COLOUR_PREFIX, target, socket, emitted)[1]
            )
        inner[materials.ATTACHED_KEY] = inner_records
    return True


def _volume_colour_inputs(nodes):
    """``(node, input, is_emitted)`` of every volume colour (:data:`VOLUME_COLOURS`) of ``nodes``."""
    return [
        (node, node.inputs[name], emitted)
        for node in list(nodes)
        for kind, inputs in VOLUME_COLOURS
        if node.bl_idname == kind
        for name, emitted in inputs
    ]


def grouped_volume_nodes(
    tree: NodeTree, seen: tuple[str, ...] = ()
) -> Iterator[tuple[bpy.types.Node, NodeTree, bpy.types.Node]]:
    """``(group node, its tree, volume node)`` for every volume node (:data:`VOLUME_KINDS`) inside
    the user's node groups used in ``tree``, at any depth."""
    for group in grouped_colours.user_groups(tree):
        inner = group.node_tree
        if inner.name in seen:
            continue
        for node in list(inner.nodes):
            if node.bl_idname in VOLUME_KINDS:
                yield group, inner, node
        yield from grouped_volume_nodes(inner, (*seen, inner.name))


def attach_scene(scene: Scene) -> None:
    """The correction for every attached material of ``scene`` with a Principled Volume blackbody,
    except those on objects with temperature grids (:func:`grid_materials`); every volume colour
    made spectral for the spectral passes (:func:`attach_colours`), and blackbodies inside node
    groups too (:func:`attach_grouped`)."""
    grids = grid_materials(scene)
    for material, _temperature in materials.scene_materials(scene):
        attach(material, grids=material in grids)
        attach_colours(material)
        attach_grouped(material, grids=material in grids)


def _grouped_problem(material, on_grids):
    """Why the passes cannot carry a volume node inside one of ``material``'s node groups, or None:
    a Volume Coefficients node, a Principled Volume blackbody without its correction in the group's
    tree (or reading a temperature grid without the group's reader), a colour grid, an emission
    colour fed from outside the group (which may be a blackbody the group cannot see)."""
    for group, inner, node in grouped_volume_nodes(material.node_tree):
        where = f"{node.name!r} inside the node group {inner.name!r} ({group.name!r}) in material {material.name!r}"
        if node.bl_idname in UNSUPPORTED_VOLUME_NODES:
            return f"Spectral colour cannot make the volume node {where} spectral (RGB coefficients)"
        if node.bl_idname != "ShaderNodeVolumePrincipled":
            continue
        reads_grid = emits_blackbody(node) and on_grids and node.inputs["Temperature Attribute"].default_value
        if reads_grid and inner.nodes.get(f"{NODE_PREFIX} Grid {node.name}") is None:
            return f"Spectral colour cannot follow temperature grids inside node groups: {where} reads one"
        if emits_blackbody(node) and inner.nodes.get(f"{NODE_PREFIX} Add {node.name}") is None:
            return (
                f"Spectral colour cannot make the blackbody of {where} spectral: it needs a grey tint and a "
                "constant intensity (added after Set Up: set up again)"
            )
        if on_grids and node.inputs["Color Attribute"].default_value:
            return f"Spectral colour cannot follow colour grids: {where} reads the Color Attribute grid"
        strength = sources.constant_value(node.inputs["Emission Strength"])
        if grouped_colours.group_input(node.inputs["Emission Color"]) is not None and strength != 0.0:
            return (
                f"Spectral colour cannot make the emission of {where} spectral: its colour comes from outside the group"
            )
    return None


def emits_blackbody(node: bpy.types.Node) -> bool:
    """Whether a Principled Volume may add its blackbody emission (intensity linked or above the cutoff)."""
    intensity = sources.constant_value(node.inputs["Blackbody Intensity"])
    return intensity is None or intensity > sources.BLACKBODY_INTENSITY_CUTOFF


def spectral_problem(scene: Scene) -> str | None:
    """Why the spectral passes cannot carry ``scene``'s volumes (one line), or None: a colour grid
    (Color Attribute), a blackbody the correction does not handle (it would stay RGB), a Volume
    Coefficients node, what :func:`_grouped_problem` names inside node groups, or a world volume."""
    grids = grid_materials(scene)
    for material, _temperature in materials.scene_materials(scene):
        if material.node_tree is None:
            continue
        grouped = _grouped_problem(material, material in grids)
        if grouped is not None:
            return grouped
        correctable = _correctable(material)
        corrected = correctable[1].node if correctable is not None else None
        for node in material.node_tree.nodes:
            where = f"{node.name!r} in material {material.name!r}"
            if node.bl_idname in UNSUPPORTED_VOLUME_NODES:
                return f"Spectral colour cannot make the volume node {where} spectral (RGB coefficients)"
            if node.bl_idname != "ShaderNodeVolumePrincipled" or not node.outputs[0].is_linked:
                continue
            if material in grids and node.inputs["Color Attribute"].default_value:
                return f"Spectral colour cannot follow colour grids: {where} reads the Color Attribute grid"
            attached = material.node_tree.nodes.get(f"{NODE_PREFIX} Add {node.name}") is not None
            if emits_blackbody(node) and node != corrected and not attached:
                return (
                    f"Spectral colour cannot make the blackbody of {where} spectral: it needs a grey tint, a "
                    "constant intensity and the Principled Volume alone on the Volume output"
                )
    world = scene.world
    tree = world.node_tree if world is not None else None
    if tree is not None and any(
        node.bl_idname == "ShaderNodeOutputWorld" and node.inputs["Volume"].is_linked for node in tree.nodes
    ):
        return f"Spectral colour does not cover world volumes (world {world.name!r})"
    return None


def warnings(scene: Scene) -> list[str]:
    """One line per Principled Volume blackbody the correction cannot handle (it keeps the RGB
    matrix's colour shift): on an object with temperature grids, or inside a node group whose
    users cannot all take the boundary (``grouped_volumes.attach_scene``)."""
    lines = []
    for material, name in grid_materials(scene).items():
        if material.node_tree is None or _correctable(material) is not None:
            continue
        for node in material.node_tree.nodes:
            if (
                node.bl_idname == "ShaderNodeVolumePrincipled"
                and node.outputs[0].is_linked
                and emits_blackbody(node)
                and material.node_tree.nodes.get(f"{NODE_PREFIX} Add {node.name}") is None
            ):
                lines.append(
                    f"Volume {name!r} ({material.name!r}): its blackbody keeps the RGB colour shift (the "
                    "correction needs a grey tint, a constant intensity and the Principled Volume alone on "
                    "the Volume output)"
                )
                break
    for material, _temperature in materials.scene_materials(scene):
        tree = material.node_tree
        if tree is None or tree.nodes.get(names.VOLUME_GROUPED_BOUNDARY_NODE) is not None:
            continue  # with that boundary the fast mode shifts it (grouped_volumes.py)
        grouped = next(
            (
                (inner, node)
                for _group, inner, node in grouped_volume_nodes(tree)
                if node.bl_idname == "ShaderNodeVolumePrincipled" and emits_blackbody(node)
            ),
            None,
        )
        if grouped is not None:
            lines.append(
                f"Material {material.name!r}: the blackbody of {grouped[1].name!r} inside the node group "
                f"{grouped[0].name!r} keeps the RGB colour shift in F12 (it needs a grey tint, a constant "
                "intensity, and every material using the group without a surface shader, the group feeding "
                "its Volume output; Render Spectral shifts it to D T)"
            )
    return lines
