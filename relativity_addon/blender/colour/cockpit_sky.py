"""The sky on the cockpit: the scene's world as the moving camera sees it, the world of the
cockpit's rest render (``camera/cockpit.py``; docs/cockpit.md).

An object moving with the camera is lit, in the camera frame, by the scene's light as the moving
camera receives it. For the world (the sky), light arriving along the camera-frame photon direction
``k'`` left the sky in the scene-frame direction ``k`` (Gray eq. 2 with ``-beta``) and arrives with
``D = 1 / (gamma (1 + beta . k'))`` and radiance ``D^4 L`` (docs/physics.md, "Radiance"): brighter
ahead, the searchlight. The cockpit scene gets a copy of the scene's world in which

- every texture reads the scene-frame direction: the ``Relativity Cockpit Sky`` group turns Cycles'
  direction of the world's ray (``Incoming`` = ``k'``) into ``-k`` (``Direction``), linked into the
  textures' unlinked Vector inputs and in place of Texture Coordinate's Generated, Object and
  Normal and Geometry's Incoming outputs;
- every Background colour goes through ``Relativity Cockpit Sky Colour``: the colour as the exact
  camera's materials shift a colour seen by the camera (``materials.doppler_matrix_group`` when the
  Doppler colour is on, and ``exp(a Spectral Searchlight + p ln D)``: ``D^4`` with the searchlight
  alone, Chang's ``D``, the exact visible factor with Doppler and searchlight).

Left out (docs/cockpit.md): the scene's lamps and the light its objects scatter; a world whose
node tree changes after Set Up (new nodes or links) is copied again at the next Set Up; Time of
flight (no aberration here). Remove deletes the copy and the groups.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..camera import cockpit
from ..common import names
from ..common.nodes import Group, Node, ensure_group, fmath, group_node, remove_unused_groups, vmath
from . import materials, world_sampling

if TYPE_CHECKING:
    from bpy.types import NodeTree, Scene, World

    from ..scene.snapshot import Snapshot

KEY = names.COCKPIT_SKY_KEY
SKY_GROUP = names.COCKPIT_SKY_GROUP
COLOUR_GROUP = names.COCKPIT_SKY_COLOUR_GROUP
SKY_NODE = f"{names.COCKPIT_SKY_PREFIX} Direction"
COLOUR_NODE = f"{names.COCKPIT_SKY_PREFIX} Colour"
# The sky's light-sampling map when the world's is Automatic (1024 x 512 evaluations of the world
# before each render): 256 resolves the searchlight's cone (1.4 degrees a texel) and took the cost
# of the sky and a sun on a cockpit from 2.17x to 1.02x the cockpit lit by its own lamp alone (CPU,
# benchmarks/cockpit_light_cost.py), the measured radiances unchanged (test_cockpit_sky.py)
MAP_RESOLUTION = 256
# outputs of the world's coordinate nodes that are the ray's direction in a world shader
DIRECTION_OUTPUTS = {"ShaderNodeTexCoord": ("Generated", "Object", "Normal"), "ShaderNodeNewGeometry": ("Incoming",)}


def sky_group() -> Group:
    """``Direction``: the scene-frame direction ``-k`` the sky is read in; ``Log Doppler``: ``ln D``.

    ``k = (k' + ((gamma - 1) / b^2 (beta . k') + gamma) beta) / (gamma (1 + beta . k'))`` (the photon
    direction from the camera frame to the scene frame, eq. 2), normalised; ``Aberration`` 0 keeps
    ``k'``. ``ln D = -ln gamma - ln(1 + beta . k')``."""
    nodes = {
        "geometry": Node("ShaderNodeNewGeometry"),
        "bk": vmath("DOT_PRODUCT", "group.Beta", "geometry.Incoming"),
        "bb": vmath("DOT_PRODUCT", "group.Beta", "group.Beta"),
        "safe_bb": fmath("MAXIMUM", "bb.Value", 1e-12),
        "gamma_1": fmath("SUBTRACT", "group.Gamma", 1.0),
        "ratio": fmath("DIVIDE", "gamma_1", "safe_bb"),
        "along": fmath("MULTIPLY_ADD", "ratio", "bk.Value", "group.Gamma"),
        "aberrated": fmath("MULTIPLY", "along", "group.Aberration"),
        "shift": vmath("SCALE", "group.Beta", scale="aberrated"),
        "k": vmath("ADD", "geometry.Incoming", "shift"),
        "incoming": vmath("NORMALIZE", "k"),
        "direction": vmath("SCALE", "incoming", scale=-1.0),
        "one_bk": fmath("ADD", 1.0, "bk.Value"),
        "safe_one_bk": fmath("MAXIMUM", "one_bk", 1e-12),
        "ln_one_bk": fmath("LOGARITHM", "safe_one_bk", materials.E),
        "ln_gamma": fmath("LOGARITHM", "group.Gamma", materials.E),
        "sum": fmath("ADD", "ln_gamma", "ln_one_bk"),
        "ln_d": fmath("MULTIPLY", "sum", -1.0),
    }
    return Group(
        SKY_GROUP,
        "ShaderNodeTree",
        (
            ("Beta", "NodeSocketVector", (0.0, 0.0, 0.0)),
            ("Gamma", "NodeSocketFloat", 1.0),
            ("Aberration", "NodeSocketFloat", 1.0),
        ),
        (
            ("Direction", "NodeSocketVector", "direction"),
            ("Incoming", "NodeSocketVector", "incoming"),
            ("Log Doppler", "NodeSocketFloat", "ln_d"),
        ),
        nodes,
    )


def colour_group(with_matrix: bool) -> Group:
    """``Color`` as the moving camera sees it: the Doppler-shifted colour (``Use Doppler``, the
    materials' Doppler matrix group) times ``exp(a Spectral Searchlight + p ln D)``."""
    nodes = {
        "power_term": fmath("MULTIPLY", "group.Power of D", "group.Log Doppler"),
        "log_safe": fmath("MINIMUM", "log", materials.EXP_LIMIT),
        "gain": fmath("EXPONENT", "log_safe"),
        "out": vmath("SCALE", "base", scale="gain"),
    }
    if with_matrix:
        nodes.update(
            matrix=group_node(materials.DOPPLER_MATRIX, {"Color": "group.Color", "Log Doppler": "group.Log Doppler"}),
            mix=Node(
                "ShaderNodeMix",
                {"Factor": "group.Use Doppler", 4: "group.Color", 5: "matrix.Color"},
                {"data_type": "VECTOR"},
            ),
            base=vmath("ADD", "mix.Result"),
            log=fmath("MULTIPLY_ADD", "matrix.Log White Luminance", "group.Spectral Searchlight", "power_term"),
        )
    else:
        nodes.update(base=vmath("ADD", "group.Color"), log=fmath("ADD", "power_term", 0.0))
    return Group(
        COLOUR_GROUP,
        "ShaderNodeTree",
        (
            ("Color", "NodeSocketColor", (1.0, 1.0, 1.0, 1.0)),
            ("Log Doppler", "NodeSocketFloat", 0.0),
            ("Use Doppler", "NodeSocketFloat", 0.0),
            ("Spectral Searchlight", "NodeSocketFloat", 0.0),
            ("Power of D", "NodeSocketFloat", 4.0),
        ),
        (("Color", "NodeSocketColor", "out"),),
        nodes,
    )


def _ensure_groups(snap):
    with_matrix = bool(snap.colour.use_doppler)
    if with_matrix:
        materials.ensure_node_groups()
    ensure_group(sky_group(), names.GROUP_VERSION_KEY, names.COCKPIT_SKY_GROUPS_VERSION)
    version = 2 * names.COCKPIT_SKY_GROUPS_VERSION + int(with_matrix)
    ensure_group(colour_group(with_matrix), names.GROUP_VERSION_KEY, version)


def sky_world(scene: Scene) -> World | None:
    """The cockpit's sky of ``scene``, or None."""
    record = scene.get(KEY)
    return bpy.data.worlds.get(record["world"]) if record is not None else None


def _copy(scene, source):
    """A copy of ``source`` with the add-on's own nodes taken out and the sky's put in."""
    sky = source.copy()
    sky.name = f"{names.COCKPIT_SKY_PREFIX} {scene.name}"
    materials.detach_world(sky)  # the exact camera's AOV writer and colour groups, copied along
    world_sampling.release(sky)  # the copy varies with the direction: a light-sampling map it needs
    if sky.cycles.sampling_method == "AUTOMATIC":
        sky.cycles.sampling_method = "MANUAL"
        sky.cycles.sample_map_resolution = MAP_RESOLUTION
    tree = sky.node_tree
    if tree is None:
        return sky
    direction = tree.nodes.new("ShaderNodeGroup")
    direction.node_tree = bpy.data.node_groups[SKY_GROUP]
    direction.name = direction.label = SKY_NODE
    for link in list(tree.links):
        if link.from_socket.name in DIRECTION_OUTPUTS.get(link.from_node.bl_idname, ()):
            output = "Incoming" if link.from_socket.name == "Incoming" else "Direction"
            tree.links.new(direction.outputs[output], link.to_socket)
    for node in list(tree.nodes):
        vector = node.inputs.get("Vector") if node.bl_idname.startswith("ShaderNodeTex") else None
        if vector is not None and not vector.is_linked:
            tree.links.new(direction.outputs["Direction"], vector)
        if node.bl_idname != "ShaderNodeBackground":
            continue
        colour = tree.nodes.new("ShaderNodeGroup")
        colour.node_tree = bpy.data.node_groups[COLOUR_GROUP]
        colour.name = colour.label = f"{COLOUR_NODE} {node.name}"
        socket = node.inputs["Color"]
        if socket.is_linked:
            tree.links.new(socket.links[0].from_socket, colour.inputs["Color"])
        tree.links.new(direction.outputs["Log Doppler"], colour.inputs["Log Doppler"])
        tree.links.new(colour.outputs["Color"], socket)
    return sky


def _set(socket, value):
    current = socket.default_value
    if (tuple(current) if hasattr(current, "__len__") else current) != value:
        socket.default_value = value


def _write_values(scene, snap, sky):
    """The velocity and colour settings, and the user's unlinked values (colour, strength) again."""
    source = scene.world
    tree = sky.node_tree
    if tree is None:
        return
    direction = tree.nodes.get(SKY_NODE)
    if direction is not None:
        aberration = snap.use_geometry and not snap.use_time_of_flight
        _set(direction.inputs["Beta"], tuple(float(b) for b in snap.beta))
        _set(direction.inputs["Gamma"], float(snap.gamma))
        _set(direction.inputs["Aberration"], 1.0 if aberration else 0.0)
    factors = snap.colour
    for node in tree.nodes:
        if node.bl_idname == "ShaderNodeGroup" and node.name.startswith(COLOUR_NODE):
            _set(node.inputs["Use Doppler"], 1.0 if factors.use_doppler else 0.0)
            _set(node.inputs["Spectral Searchlight"], 1.0 if factors.spectral_searchlight else 0.0)
            _set(node.inputs["Power of D"], float(factors.power_of_d))
    if source is None or source.node_tree is None:
        return
    for node in source.node_tree.nodes:
        copy = tree.nodes.get(node.name)
        if copy is None or copy.bl_idname != node.bl_idname:
            continue
        for socket, target in zip(node.inputs, copy.inputs, strict=False):  # a copy: the same sockets
            if target.identifier != socket.identifier or not hasattr(socket, "default_value"):
                continue
            value = socket.default_value
            value = tuple(value) if hasattr(value, "__len__") and not isinstance(value, str) else value
            grouped = node.bl_idname == "ShaderNodeBackground" and socket.name == "Color" and target.is_linked
            if grouped and not socket.is_linked:  # the colour goes through the sky's colour group
                group = target.links[0].from_node
                if group.name.startswith(COLOUR_NODE):
                    _set(group.inputs["Color"], value)
            elif not target.is_linked:
                _set(target, value)


def write(scene: Scene, snap: Snapshot, structural: bool = True) -> None:
    """The cockpit scene's world: the scene's world as the moving camera sees it (made when the
    cockpit exists and ``structural``; values only otherwise)."""
    rest_scene = cockpit.cockpit_scene(scene)
    if rest_scene is None:
        if structural:
            remove(scene)
        return
    source = scene.world
    record = scene.get(KEY)
    sky = sky_world(scene)
    if structural and (sky is None or record["source"] != (source.name if source is not None else "")):
        remove(scene)
        sky = None
        if source is not None:
            _ensure_groups(snap)
            sky = _copy(scene, source)
        scene[KEY] = {"world": sky.name if sky is not None else "", "source": source.name if source else ""}
    if rest_scene.world != sky:
        rest_scene.world = sky
    if sky is not None:
        _write_values(scene, snap, sky)


def apply(scene: Scene, snap: Snapshot) -> None:
    write(scene, snap)


def remove(scene: Scene) -> None:
    """Delete the sky and its groups; safe when nothing was applied."""
    record = scene.get(KEY)
    if record is None:
        return
    sky = bpy.data.worlds.get(record["world"]) if record["world"] else None
    rest_scene = cockpit.cockpit_scene(scene)
    if rest_scene is not None and rest_scene.world is not None and rest_scene.world == sky:
        rest_scene.world = None
    if sky is not None:
        bpy.data.worlds.remove(sky)
    del scene[KEY]
    remove_unused_groups((COLOUR_GROUP, SKY_GROUP))


def groups() -> tuple[NodeTree | None, ...]:
    """The sky's groups, for tests."""
    return bpy.data.node_groups.get(SKY_GROUP), bpy.data.node_groups.get(COLOUR_GROUP)
