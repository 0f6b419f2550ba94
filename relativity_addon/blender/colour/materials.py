"""Doppler colour and searchlight in materials: shader node groups and attaching them.

Where the Doppler factor is computed in the shader: the group ``Relativity Doppler Factor``
(:data:`DOPPLER_FACTOR`), from the geometry's Incoming vector ``k`` (the direction the photon
propagates, toward the viewer) and two velocities in fractions of c:

    D = gamma_o (1 - beta_o . k) / (gamma_s (1 - beta_s . k))          (docs/physics.md)

``beta_s`` is the point attribute ``relativity_beta`` (the apparent-geometry modifier writes the
emitter's velocity relative to the observer; 0 where absent), ``beta_o`` the observer velocity
(the scene's ``beta`` on the exact-camera path, 0 on the mesh path, whose meshes already live in
the observer frame).

Colour (``docs/spectral-model.md``): ordinary colours go through the packed Doppler matrix table,
``rgb_obs = exp(a(D)) gamut_map(N(D) rgb)``; colours that come from Blender's Blackbody node are
seen as a blackbody at ``D T`` with luminance ratio ``Y(D T) / Y(T)`` from the packed blackbody
table. Every group is declared once as data (``nodes.Group``) and built by ``nodes.build_group``.

Settings reach the shaders through one shared group, ``Relativity Settings``, whose constant
nodes :func:`write_settings` rewrites from the snapshot at every sync (``effect.sync``), so
materials never need to be touched again after :func:`attach`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import bpy

from ..common import names
from ..common.nodes import Group, Node, ensure_group, fmath, group_node, vmath
from ..scene import grouped_colours, sources
from . import lut_images, spectral_nodes

if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping

    from bpy.types import Material, NodeSocket, NodeTree, Scene, World

    from ..common.nodes import TreeType
    from ..scene.snapshot import Snapshot

BETA_ATTRIBUTE = names.BETA_ATTRIBUTE
DONE_AOV = names.COLOUR_DONE_AOV
ATTACHED_KEY = names.MATERIAL_ATTACHED_KEY
NODE_PREFIX = names.MATERIAL_NODE_PREFIX
EXP_LIMIT = 80.0  # float32 exp overflows past ~88: clamp the log brightness before exp


# --- the groups -----------------------------------------------------------------------------

SETTINGS = names.SETTINGS_GROUP
DOPPLER_FACTOR = names.DOPPLER_FACTOR_GROUP
GAMUT_MAP = names.GAMUT_MAP_GROUP
DOPPLER_MATRIX = names.DOPPLER_MATRIX_GROUP
BLACKBODY_SHIFT = names.BLACKBODY_SHIFT_GROUP
DOPPLER_EMISSION = names.DOPPLER_COLOUR_GROUP
DOPPLER_AOV = names.DOPPLER_AOV_GROUP
LOG_DOPPLER_AOV = names.LOG_DOPPLER_AOV
COVERAGE_AOV = names.COVERAGE_AOV

LN10 = math.log(10.0)
E = math.e
# Rec.709 luminance weights (row Y of RGB -> XYZ); see physics/spectral.py.
LUMINANCE_WEIGHTS = (0.2126729, 0.7151522, 0.0721750)


def settings_group() -> Group:
    """Constants written by :func:`write_settings` (one place for every material)."""
    values = ("Use Doppler", "Spectral Searchlight", "Power of D", "Camera Power", "Camera Path")
    nodes = {name: Node("ShaderNodeValue") for name in values}
    nodes["Observer Beta"] = Node("ShaderNodeCombineXYZ", {0: 0.0, 1: 0.0, 2: 0.0})
    outputs = tuple((name, "NodeSocketFloat", name) for name in values)
    outputs += (("Observer Beta", "NodeSocketVector", "Observer Beta"),)
    spectral, spectral_outputs = spectral_nodes.settings_nodes()
    nodes.update(spectral)
    return Group(SETTINGS, "ShaderNodeTree", (), outputs + spectral_outputs, nodes)


def doppler_factor_group() -> Group:
    """``ln D`` for the photon reaching the camera from this shading point."""
    nodes = {
        "geometry": Node("ShaderNodeNewGeometry"),
        "beta_s": Node("ShaderNodeAttribute", props={"attribute_name": BETA_ATTRIBUTE, "attribute_type": "GEOMETRY"}),
        "bo_k": vmath("DOT_PRODUCT", "group.Observer Beta", "geometry.Incoming"),
        "bo_bo": vmath("DOT_PRODUCT", "group.Observer Beta", "group.Observer Beta"),
        "bs_k": vmath("DOT_PRODUCT", "beta_s.Vector", "geometry.Incoming"),
        "bs_bs": vmath("DOT_PRODUCT", "beta_s.Vector", "beta_s.Vector"),
        # ln D = ln(1 - bo.k) - ln(1 - bs.k) + ln gamma_o - ln gamma_s, ln gamma = -ln(1 - b^2) / 2
        "one_bo_k": fmath("MAXIMUM", "ns_bo_k", 1e-12),
        "ns_bo_k": fmath("SUBTRACT", 1.0, "bo_k.Value"),
        "one_bs_k": fmath("MAXIMUM", "ns_bs_k", 1e-12),
        "ns_bs_k": fmath("SUBTRACT", 1.0, "bs_k.Value"),
        "one_bo2": fmath("MAXIMUM", "ns_bo2", 1e-12),
        "ns_bo2": fmath("SUBTRACT", 1.0, "bo_bo.Value"),
        "one_bs2": fmath("MAXIMUM", "ns_bs2", 1e-12),
        "ns_bs2": fmath("SUBTRACT", 1.0, "bs_bs.Value"),
        "ln_num": fmath("LOGARITHM", "one_bo_k", E),
        "ln_den": fmath("LOGARITHM", "one_bs_k", E),
        "ln_go2": fmath("LOGARITHM", "one_bo2", E),  # = -2 ln gamma_o
        "ln_gs2": fmath("LOGARITHM", "one_bs2", E),
        "half_diff": fmath("SUBTRACT", "ln_gs2", "ln_go2"),
        "kinematic": fmath("SUBTRACT", "ln_num", "ln_den"),
        "ln_d": fmath("MULTIPLY_ADD", "half_diff", 0.5, "kinematic"),
        # the emitter's own part, ln D_s = -ln(gamma_s (1 - bs.k)): D = D_o D_s
        "ln_gs": fmath("MULTIPLY", "ln_gs2", 0.5),
        "ln_ds": fmath("SUBTRACT", "ln_gs", "ln_den"),
    }
    return Group(
        DOPPLER_FACTOR,
        "ShaderNodeTree",
        (("Observer Beta", "NodeSocketVector", None),),
        (("Log Doppler", "NodeSocketFloat", "ln_d"), ("Log Emitter Doppler", "NodeSocketFloat", "ln_ds")),
        nodes,
    )


def gamut_map_group(name: str | None = None, tree_type: TreeType = "ShaderNodeTree") -> Group:
    """``rgb' = max(Y + (rgb - Y) clamp(Y / (Y - min rgb)), 0)`` (spectral.gamut_map_linear_rec709)."""
    nodes = {
        "luminance": vmath("DOT_PRODUCT", "group.Color", LUMINANCE_WEIGHTS),
        "split": Node("ShaderNodeSeparateXYZ", {0: "group.Color"}),
        "min_rg": fmath("MINIMUM", "split.X", "split.Y"),
        "smallest": fmath("MINIMUM", "min_rg", "split.Z"),
        "spread": fmath("SUBTRACT", "luminance.Value", "smallest"),
        "safe_spread": fmath("MAXIMUM", "spread", 1e-30),
        "saturation": fmath("DIVIDE", "luminance.Value", "safe_spread", clamp=True),
        "grey": Node("ShaderNodeCombineXYZ", {0: "luminance.Value", 1: "luminance.Value", 2: "luminance.Value"}),
        "chroma": vmath("SUBTRACT", "group.Color", "grey"),
        "scaled": vmath("SCALE", "chroma", scale="saturation"),
        "mapped": vmath("ADD", "scaled", "grey"),
        "clipped": vmath("MAXIMUM", "mapped", (0.0, 0.0, 0.0)),
    }
    return Group(
        name or GAMUT_MAP,
        tree_type,
        (("Color", "NodeSocketColor", (1.0, 1.0, 1.0, 1.0)),),
        (("Color", "NodeSocketColor", "clipped"),),
        nodes,
    )


def _lut_texture(image_name, u_reference, v):
    return {
        "uv": Node("ShaderNodeCombineXYZ", {0: u_reference, 1: v, 2: 0.0}),
        "texture": Node(
            "ShaderNodeTexImage",
            props={"image": image_name, "interpolation": "Linear", "extension": "EXTEND"},
        ),
    }


def doppler_matrix_group() -> Group:
    """``gamut_map(N(D) rgb)`` and ``a(D)``: ``M(D) rgb`` mapped is ``exp(a)`` times the colour."""
    scale, offset = lut_images.texture_u_scale_offset(lut_images.DOPPLER_LOG10_RANGE)
    nodes = {"u": fmath("MULTIPLY_ADD", "group.Log Doppler", scale / LN10, offset)}
    for row in range(3):
        lookup = _lut_texture(lut_images.DOPPLER_LUT_NAME, "u", (row + 0.5) / 3.0)
        nodes[f"uv{row}"] = lookup["uv"]
        nodes[f"row{row}"] = lookup["texture"]
        nodes[f"row{row}"].inputs = {"Vector": f"uv{row}"}
        nodes[f"dot{row}"] = vmath("DOT_PRODUCT", f"row{row}.Color", "group.Color")
    nodes["product"] = Node("ShaderNodeCombineXYZ", {0: "dot0.Value", 1: "dot1.Value", 2: "dot2.Value"})
    nodes["mapped"] = group_node(GAMUT_MAP, {0: "product"})
    return Group(
        DOPPLER_MATRIX,
        "ShaderNodeTree",
        (("Color", "NodeSocketColor", (1.0, 1.0, 1.0, 1.0)), ("Log Doppler", "NodeSocketFloat", 0.0)),
        (("Color", "NodeSocketColor", "mapped"), ("Log White Luminance", "NodeSocketFloat", "row0.Alpha")),
        nodes,
    )


def blackbody_shift_group() -> Group:
    """Unit-luminance colour of the blackbody at ``D T`` and ``ln(Y(D T) / Y(T))``."""
    scale, offset = lut_images.texture_u_scale_offset(lut_images.BLACKBODY_LOG10_RANGE)
    nodes = {
        "ln_t": fmath("LOGARITHM", "safe_t", E),
        "safe_t": fmath("MAXIMUM", "group.Temperature", 1.0),
        "ln_dt": fmath("ADD", "ln_t", "group.Log Doppler"),
        "u_t": fmath("MULTIPLY_ADD", "ln_t", scale / LN10, offset),
        "u_dt": fmath("MULTIPLY_ADD", "ln_dt", scale / LN10, offset),
    }
    for key in ("t", "dt"):
        lookup = _lut_texture(lut_images.BLACKBODY_LUT_NAME, f"u_{key}", 0.5)
        nodes[f"uv_{key}"] = lookup["uv"]
        nodes[f"lut_{key}"] = lookup["texture"]
        nodes[f"lut_{key}"].inputs = {"Vector": f"uv_{key}"}
    nodes["log_ratio"] = fmath("SUBTRACT", "lut_dt.Alpha", "lut_t.Alpha")
    return Group(
        BLACKBODY_SHIFT,
        "ShaderNodeTree",
        (("Temperature", "NodeSocketFloat", 5762.0), ("Log Doppler", "NodeSocketFloat", 0.0)),
        (("Color", "NodeSocketColor", "lut_dt.Color"), ("Log Luminance Ratio", "NodeSocketFloat", "log_ratio")),
        nodes,
    )


def doppler_colour_group() -> Group:
    """Observed colour of a surface colour ``Color`` (or a blackbody at ``Temperature``).

    ``out = base exp(E)``, with ``base`` the Doppler-shifted colour (unshifted when Doppler is
    off) and ``E`` the log brightness: the exact visible factor (``a``, or ``ln Y(DT)/Y(T)``)
    when Doppler and the searchlight are both on, else ``p ln D`` with ``p`` = 4 (searchlight
    without colour) or 1 (Chang et al.'s comparison), minus the ``D^4`` the exact camera applies.
    On the exact-camera path the scene is at rest, so only camera rays are shifted: ordinary
    colours pass unchanged (the compositor shifts the pixel), blackbodies seen directly are shifted
    here and write the ``relativity_colour_done`` AOV so the compositor leaves them alone, and the
    light every other ray carries (a lamp lighting the floor) stays the scene-frame light: a moving
    emitter there (Apparent Geometry's final render) gets its ``D_s^4`` toward every ray, its colour
    left unshifted on the rays that reach the camera through another surface.
    In a spectral pass (``spectral_nodes``) every colour becomes its spectral values instead.
    """
    nodes = {
        "settings": group_node(SETTINGS),
        "doppler": group_node(DOPPLER_FACTOR, {"Observer Beta": "settings.Observer Beta"}),
        "matrix": group_node(DOPPLER_MATRIX, {"Color": "group.Color", "Log Doppler": "doppler"}),
        "blackbody": group_node(BLACKBODY_SHIFT, {"Temperature": "group.Temperature", "Log Doppler": "doppler"}),
        # brightness exponent shared by both branches: (p - camera p) ln D
        "power": fmath("SUBTRACT", "settings.Power of D", "settings.Camera Power"),
        "power_term": fmath("MULTIPLY", "power", "doppler"),
        # ordinary colour
        "rgb_base": Node(
            "ShaderNodeMix",
            {"Factor": "settings.Use Doppler", 4: "group.Color", 5: "matrix.Color"},
            {"data_type": "VECTOR"},
        ),
        "rgb_log": fmath("MULTIPLY_ADD", "matrix.Log White Luminance", "settings.Spectral Searchlight", "power_term"),
        "rgb_log_safe": fmath("MINIMUM", "rgb_log", EXP_LIMIT),
        "rgb_gain": fmath("EXPONENT", "rgb_log_safe"),
        "rgb_shifted": vmath("SCALE", "rgb_base.Result", scale="rgb_gain"),
        "rgb_out": Node(
            "ShaderNodeMix",
            {"Factor": "settings.Camera Path", 4: "rgb_shifted", 5: "group.Color"},
            {"data_type": "VECTOR"},
        ),
        # blackbody: the LUT colour has unit luminance; keep the input colour's luminance
        "bb_luminance": vmath("DOT_PRODUCT", "group.Color", LUMINANCE_WEIGHTS),
        "bb_shifted_colour": vmath("SCALE", "blackbody.Color", scale="bb_luminance.Value"),
        "bb_base": Node(
            "ShaderNodeMix",
            {"Factor": "settings.Use Doppler", 4: "group.Color", 5: "bb_shifted_colour"},
            {"data_type": "VECTOR"},
        ),
        "bb_log": fmath("MULTIPLY_ADD", "blackbody.Log Luminance Ratio", "settings.Spectral Searchlight", "power_term"),
        "bb_log_safe": fmath("MINIMUM", "bb_log", EXP_LIMIT),
        "bb_gain": fmath("EXPONENT", "bb_log_safe"),
        "bb_out": vmath("SCALE", "bb_base.Result", scale="bb_gain"),
        # exact camera: the blackbody shift only for camera rays (1 - path (1 - camera ray))
        "light_path": Node("ShaderNodeLightPath"),
        "other_ray": fmath("SUBTRACT", 1.0, "light_path.Is Camera Ray"),
        "unshifted": fmath("MULTIPLY", "settings.Camera Path", "other_ray"),
        "shifted_ray": fmath("SUBTRACT", 1.0, "unshifted"),
        "bb_select": fmath("MULTIPLY", "group.Is Blackbody", "shifted_ray"),
        "fast": Node(
            "ShaderNodeMix", {"Factor": "bb_select", 4: "rgb_out.Result", 5: "bb_out"}, {"data_type": "VECTOR"}
        ),
        "spectral": group_node(spectral_nodes.SPECTRAL_COLOUR, spectral_nodes.COLOUR_LINKS),
        # A moving emitter behind the exact camera (Apparent Geometry's final render): the camera
        # applies the observer's D_o^4 only, the compositor divides by the whole D^4; the rest, D_s^4,
        # on every ray (toward the ray's direction): the scene-frame light it sends other surfaces too
        "emitter_log": fmath("MULTIPLY", "settings.Camera Power", "doppler.Log Emitter Doppler"),
        "emitter_log_safe": fmath("MINIMUM", "emitter_log", EXP_LIMIT),
        "emitter_gain": fmath("EXPONENT", "emitter_log_safe"),
        "fast_gained": vmath("SCALE", "fast.Result", scale="emitter_gain"),
        "out": Node(
            "ShaderNodeMix",
            {"Factor": "settings.Spectral Pass", 4: "fast_gained", 5: "spectral"},
            {"data_type": "VECTOR"},
        ),
        "done_path": fmath("MULTIPLY", "group.Is Blackbody", "settings.Camera Path"),
        "done": fmath("MULTIPLY", "done_path", "light_path.Is Camera Ray"),
        "aov": Node("ShaderNodeOutputAOV", {"Value": "done"}, {"aov_name": DONE_AOV}),
    }
    return Group(
        DOPPLER_EMISSION,
        "ShaderNodeTree",
        spectral_nodes.COLOUR_INPUTS,
        (("Color", "NodeSocketColor", "out.Result"),),
        nodes,
    )


def doppler_aov_group() -> Group:
    """Writes ``ln D`` of the first camera hit to the ``relativity_log_doppler`` AOV, and 1 to the
    ``relativity_coverage`` AOV: samples that write neither (a camera ray scattered in a volume)
    would otherwise dilute the pixel's mean ``ln D``; the compositor divides by the coverage.

    The exact camera's compositor stage reads ``D`` from it: computed by Cycles per sample from
    the scene-frame photon direction, so it is right for every shutter model, depth of field and
    the Lorentz window, and it follows per-frame velocity changes in animation renders.
    """
    nodes = {
        "settings": group_node(SETTINGS),
        "doppler": group_node(DOPPLER_FACTOR, {"Observer Beta": "settings.Observer Beta"}),
        "aov": Node("ShaderNodeOutputAOV", {"Value": "doppler"}, {"aov_name": LOG_DOPPLER_AOV}),
        "coverage": Node("ShaderNodeOutputAOV", {"Value": 1.0}, {"aov_name": COVERAGE_AOV}),
    }
    return Group(DOPPLER_AOV, "ShaderNodeTree", (), (), nodes)


GROUP_BUILDERS = (
    settings_group,
    doppler_factor_group,
    gamut_map_group,
    doppler_matrix_group,
    blackbody_shift_group,
    spectral_nodes.spectral_colour_group,
    doppler_colour_group,
    doppler_aov_group,
)


def ensure_node_groups() -> NodeTree:
    """Pack the LUTs and build any missing or outdated group, dependencies first.

    Existing up-to-date groups are left alone: rebuilding a group's interface would drop the
    links of every material node that uses it. Returns the top group.
    """
    lut_images.ensure_doppler_matrix_lut()
    lut_images.ensure_blackbody_lut()
    if not _specs:  # built once per session: constants, and each object setting's change attaches
        _specs.extend(builder() for builder in GROUP_BUILDERS)
    for spec in _specs:
        ensure_group(spec, names.GROUP_VERSION_KEY, names.SHADER_GROUPS_VERSION)
    return bpy.data.node_groups[DOPPLER_EMISSION]


_specs: list[Group] = []  # GROUP_BUILDERS' groups


# --- settings -------------------------------------------------------------------------------


# Wavelengths (nm) of the spectral pass being rendered (spectral_render), None between passes.
_spectral_pass = {"wavelengths": None}


def set_spectral_pass(wavelengths_nm: Iterable[float] | None) -> None:
    """Render the next passes at these three rest-frame wavelengths (None: the fast mode again);
    takes effect at the next :func:`write_settings`."""
    _spectral_pass["wavelengths"] = None if wavelengths_nm is None else tuple(float(w) for w in wavelengths_nm)


def spectral_pass_wavelengths() -> tuple[float, ...] | None:
    """The three wavelengths (nm) of the spectral pass being rendered, or None."""
    return _spectral_pass["wavelengths"]


def settings_values(snap: Snapshot) -> dict[str, Any]:
    """Constants for ``Relativity Settings`` from a ``snapshot.Snapshot`` (and the spectral pass)."""
    colour = snap.colour
    return {
        **spectral_nodes.pass_values(_spectral_pass["wavelengths"]),
        "Use Doppler": 1.0 if colour.use_doppler else 0.0,
        "Spectral Searchlight": 1.0 if colour.spectral_searchlight else 0.0,
        "Power of D": colour.power_of_d,
        "Camera Power": colour.camera_power,
        "Camera Path": 1.0 if colour.camera_path else 0.0,
        # the mesh path's meshes already live in the observer frame
        "Observer Beta": tuple(snap.beta) if colour.camera_path else (0.0, 0.0, 0.0),
    }


def write_settings(snap: Snapshot) -> bool:
    """Write the settings (Cycles reads shader values written in render_pre for every frame)."""
    tree = bpy.data.node_groups.get(SETTINGS)
    if tree is None:
        return False
    for name, value in settings_values(snap).items():
        node = tree.nodes[name]
        vector = isinstance(value, tuple)
        sockets = node.inputs[:3] if vector else node.outputs[:1]
        components = value if vector else (value,)
        for socket, component in zip(sockets, components, strict=True):
            if socket.default_value != component:  # also runs on depsgraph updates: no loops
                socket.default_value = component
    return True


# --- attaching to materials -----------------------------------------------------------------


def is_attached(material: Material | None) -> bool:
    return material is not None and ATTACHED_KEY in material


def attach(material: Material | None, temperature: float | None = None) -> bool:
    """Insert the Doppler colour group in front of every colour input of ``material``.

    A colour fed by a Blackbody node is shifted as a blackbody at that node's temperature. With
    ``temperature`` (an object marked as a blackbody emitter, ``Object.relativity.temperature``)
    every emission colour is a blackbody at that temperature, with the material's luminance.
    """
    if material is None or material.node_tree is None or is_attached(material):
        return False
    group = bpy.data.node_groups.get(DOPPLER_EMISSION) or ensure_node_groups()
    tree = material.node_tree
    records = []
    for target_node, socket, is_emission in list(grouped_colours.targets(tree)):
        node, record = insert_colour_group(tree, group, NODE_PREFIX, target_node, socket, is_emission)
        if temperature and is_emission and not node.inputs["Is Blackbody"].default_value:
            node.inputs["Is Blackbody"].default_value = 1.0
            node.inputs["Temperature"].default_value = temperature
        records.append(record)
    object_temperature = float(temperature or 0.0)
    records.append(_insert_aov_writer(tree))
    for record in records:
        record["object_temperature"] = object_temperature  # what attach_scene compares to re-attach
    material[ATTACHED_KEY] = records

    def insert(inner, target, socket, is_emission):  # inside a shared group: the object's own temperature
        node, record = insert_colour_group(inner, group, NODE_PREFIX, target, socket, is_emission)
        return [record, *(grouped_colours.read_object_temperature(inner, node) if is_emission else ())]

    grouped_colours.attach_groups(tree, insert)
    return True


def insert_colour_group(
    tree: NodeTree,
    group_tree: NodeTree,
    prefix: str,
    target_node: bpy.types.Node,
    socket: NodeSocket,
    is_emission: bool,
) -> tuple[bpy.types.Node, dict[str, Any]]:
    """Put colour group ``group_tree`` (inputs ``spectral_nodes.COLOUR_INPUTS``) in front of
    ``socket`` of ``target_node``, a colour fed by a Blackbody (through reroutes, mixes, groups)
    marked as one; returns the group node and the record :func:`detach` undoes it by."""
    source = socket.links[0].from_socket if socket.is_linked else None
    blackbody = sources.blackbody_source(socket)
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group_tree
    node.name = node.label = f"{prefix} {target_node.name} {socket.identifier}"
    node.location, node.hide = (target_node.location.x - 220.0, target_node.location.y), True
    if source is not None:
        tree.links.new(source, node.inputs["Color"])
    else:
        node.inputs["Color"].default_value = socket.default_value
    if blackbody is not None:
        sources.mark_blackbody(tree, node, blackbody)
    node.inputs["Is Emission"].default_value = 1.0 if is_emission else 0.0
    tree.links.new(node.outputs["Color"], socket)
    return node, {
        "group_node": node.name,
        "target": target_node.name,
        "socket": socket.identifier,
        "source_node": source.node.name if source is not None else "",
        "source_socket": source.identifier if source is not None else "",
    }


def _insert_aov_writer(tree):
    """The Doppler AOV group in ``tree`` (it writes the pixel's ``ln D``); its record."""
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = bpy.data.node_groups[DOPPLER_AOV]
    node.name = node.label = f"{NODE_PREFIX} AOV"
    node.hide = True
    return {"group_node": node.name, "target": "", "socket": "", "source_node": "", "source_socket": ""}


def detach(material: Material | World) -> bool:
    """Remove the inserted groups and restore the original links exactly."""
    if not is_attached(material):
        return False
    return _detach_records(material, material.node_tree)


def resolve_record(
    tree: NodeTree, record: Mapping[str, Any]
) -> tuple[bpy.types.Node | None, NodeSocket | None, NodeSocket | None]:
    """``(group node, target input socket, source output socket)`` of an insertion record
    (:func:`insert_colour_group`) in ``tree``, each None where it is gone (or was never there)."""
    node = tree.nodes.get(record["group_node"])
    target = tree.nodes.get(record["target"]) if record["target"] else None
    source_node = tree.nodes.get(record["source_node"]) if record["source_node"] else None
    socket = sources.by_identifier(target.inputs, record["socket"]) if target is not None else None
    source = sources.by_identifier(source_node.outputs, record["source_socket"]) if source_node is not None else None
    return node, socket, source


def _detach_records(owner, tree):
    """Undo the insertions recorded on ``owner`` (a material, world or node group) in ``tree``."""
    for record in list(owner[ATTACHED_KEY]):
        node, socket, source = resolve_record(tree, record.to_dict())
        if node is not None:
            tree.nodes.remove(node)
        if socket is not None and source is not None:
            tree.links.new(source, socket)
    del owner[ATTACHED_KEY]
    return True


def scene_materials(scene: Scene) -> list[tuple[Material, float | None]]:
    """``(material, blackbody temperature or None)`` for every material used in ``scene``."""
    found = {}
    for obj in scene.objects:
        temperature = obj.relativity.temperature or None
        for slot in obj.material_slots:
            if slot.material is not None:
                found[slot.material] = found.get(slot.material) or temperature
    return list(found.items())


def attached_temperature(material: Material) -> float:
    """The object blackbody temperature ``material`` was attached with (0: none)."""
    records = material[ATTACHED_KEY]
    return float(records[0].get("object_temperature", 0.0)) if len(records) else 0.0


def attach_scene(scene: Scene, camera_path: bool) -> None:
    """Attach the Doppler colour group to every material of ``scene`` (no-op for attached ones);
    on the exact camera's path the world writes the Doppler AOV too."""
    ensure_node_groups()
    for material, temperature in scene_materials(scene):
        if is_attached(material) and attached_temperature(material) != float(temperature or 0.0):
            detach(material)  # its object's blackbody temperature changed since
        attach(material, temperature)
    if camera_path:
        attach_world(scene.world)


def attach_world(world: World | None) -> bool:
    """The world's Doppler AOV writer (muted where ``world_doppler`` gives the compositor the
    world's D) and a colour group in front of every Background colour (``world_colour`` links it
    where it changes the colour: blackbodies, spectral passes)."""
    if world is None or world.node_tree is None or ATTACHED_KEY in world:
        return False
    tree = world.node_tree
    records = [_insert_aov_writer(tree)]
    for background in [n for n in tree.nodes if n.bl_idname == "ShaderNodeBackground"]:
        # every background colour: the fast mode shifts only blackbodies here (the compositor the
        # rest), a spectral pass needs all of them as emitted spectra
        group = bpy.data.node_groups[DOPPLER_EMISSION]
        records.append(insert_colour_group(tree, group, NODE_PREFIX, background, background.inputs["Color"], True)[1])
    world[ATTACHED_KEY] = records
    return True


def detach_world(world: World | None) -> bool:
    if world is None or ATTACHED_KEY not in world:
        return False
    if not isinstance(world[ATTACHED_KEY], str):
        return detach(world)  # the same records as a material's
    node = world.node_tree.nodes.get(world[ATTACHED_KEY]) if world.node_tree else None  # older files: the AOV's name
    if node is not None:
        world.node_tree.nodes.remove(node)
    del world[ATTACHED_KEY]
    return True


def detach_all() -> None:
    """Detach from every material and world (the groups and LUTs stay in the file, unused)."""
    for material in bpy.data.materials:
        detach(material)
    for world in bpy.data.worlds:
        detach_world(world)
    grouped_colours.detach_all(_detach_records)
