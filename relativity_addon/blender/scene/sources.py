"""Blackbody sources: which colours in a node tree carry a blackbody spectrum.

A blackbody at ``T`` seen with Doppler factor ``D`` is a blackbody at ``D T`` with luminance
ratio ``Y(D T) / Y(T)`` (docs/spectral-model.md); any other colour goes through the RGB Doppler
matrix. So the colour code needs to know, for a colour input, whether what feeds it is "a
blackbody at ``T`` times a non-negative scalar". :func:`blackbody_source` answers that by
tracing the links backwards, with a few rules, and says None (the RGB path) for anything else:

- **Blackbody node**: a blackbody at its Temperature, scale 1.
- **Reroute**, and a **muted node**: whatever feeds it (a muted node passes its internal link).
- **Group node**: into the group, to the active Group Output's matching input; a **Group Input**
  there leads back out to the group node's matching input.
- **Mix** (``ShaderNodeMix``, data type RGBA) and the legacy **MixRGB**, never with the result
  clamped (clamping changes a bright blackbody's chromaticity). The factor ``f`` must be known to
  lie in [0, 1]: a constant there, or any input with Clamp Factor on.

  - ``MIX`` (``(1 - f) A + f B``): a constant ``f`` of 0 or 1 picks that side; otherwise both
    sides must be blackbodies at the same temperature (the same value, or the same socket).
  - ``MULTIPLY`` (``A (1 - f + f B)``, Blender's blend): ``A`` a blackbody and ``B`` an unlinked
    grey (r = g = b >= 0) for any ``f``; ``B`` a blackbody and ``A`` an unlinked grey only for a
    constant ``f`` = 1 (else the result is grey plus blackbody).
- **Vector Math** ``SCALE`` by an unlinked (or Value node) non-negative constant.

The temperature is a float when it is a constant (unlinked, or a Value node, also across group
boundaries), else the output socket that feeds it, which the caller links into its own group;
a non-constant temperature computed inside a group cannot be linked from the material's tree,
so that case is None too. Unlinked colours are constants, never blackbodies.

Lights: :func:`light_blackbody` gives the temperature of a light whose spectrum is a blackbody
(its own temperature setting, or an Emission fed by a Blackbody in its node tree; lamps seen
directly are drawn by emitter faces, ``lamp_faces.py``), and :func:`volume_blackbody` the
Principled Volume's own blackbody emission (shifted for camera rays by ``volumes.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

from ..common import compat, names

if TYPE_CHECKING:
    from collections.abc import Container, Iterable

    from bpy.types import Light, Node, NodeLink, NodeSocket, NodeTree, Scene

MIX_NODES = ("ShaderNodeMix", "ShaderNodeMixRGB")
BLACKBODY_INTENSITY_CUTOFF = 1e-3  # below this Blender's Principled Volume emits no blackbody


class Blackbody(NamedTuple):
    """A blackbody colour: ``temperature`` (K, float) or the output socket feeding the Blackbody
    node's Temperature; ``scale`` the non-negative factor it is multiplied by (None: varies per
    shading point, e.g. a clamped Mix factor fed by a texture)."""

    temperature: float | NodeSocket
    scale: float | None


# --- following links ------------------------------------------------------------------------


def live_link(socket: NodeSocket) -> NodeLink | None:
    """The link feeding input ``socket`` as Cycles sees it (muted and invalid links do not count)."""
    for link in socket.links:
        if link.is_valid and not link.is_muted:
            return link
    return None


def _group_output_input(group_node, identifier):
    tree = group_node.node_tree
    if tree is None:
        return None
    outputs = [node for node in tree.nodes if node.bl_idname == "NodeGroupOutput"]
    output = next((node for node in outputs if node.is_active_output), outputs[0] if outputs else None)
    if output is None:
        return None
    return next((socket for socket in output.inputs if socket.identifier == identifier), None)


def by_identifier(sockets: Iterable[NodeSocket], identifier: str) -> NodeSocket | None:
    return next((socket for socket in sockets if socket.identifier == identifier), None)


def _upstream(socket, groups):
    """Skip reroutes, muted nodes and group boundaries from output ``socket``: the output socket
    that really produces the value, with its stack of enclosing group nodes; (None, groups) for
    an unlinked input (a constant) reached on the way; None where the path ends (missing socket,
    a Group Input outside any group)."""
    while True:
        node = socket.node
        if node.bl_idname == "NodeReroute" or node.mute:
            if node.bl_idname == "NodeReroute":
                inner = node.inputs[0]
            else:
                inner = next((link.from_socket for link in node.internal_links if link.to_socket == socket), None)
                if inner is None:
                    return None
            link = live_link(inner)
            if link is None:
                return None, groups, inner
            socket = link.from_socket
        elif node.bl_idname == "ShaderNodeGroup":
            inner = _group_output_input(node, socket.identifier)
            if inner is None:
                return None
            groups = (*groups, node)
            link = live_link(inner)
            if link is None:
                return None, groups, inner
            socket = link.from_socket
        elif node.bl_idname == "NodeGroupInput":
            if not groups:
                return None
            outer = by_identifier(groups[-1].inputs, socket.identifier)
            groups = groups[:-1]
            if outer is None:
                return None
            link = live_link(outer)
            if link is None:
                return None, groups, outer
            socket = link.from_socket
        else:
            return socket, groups, None


def _feed(input_socket, groups):
    """``(output socket or None, groups, unlinked input or None)`` for what feeds ``input_socket``."""
    link = live_link(input_socket)
    if link is None:
        return None, groups, input_socket
    return _upstream(link.from_socket, groups)


def _float_feed(input_socket, groups):
    """A float input: its constant value (unlinked, or a Value node) or ``(socket, groups)``."""
    found = _feed(input_socket, groups)
    if found is None:
        return None
    socket, groups, constant = found
    if constant is not None:
        return float(constant.default_value)
    if socket.node.bl_idname == "ShaderNodeValue":
        return float(socket.default_value)
    return socket, groups


def constant_value(input_socket: NodeSocket) -> float | None:
    """The constant value an input holds (unlinked, or a Value node, also through groups), or None."""
    return _constant(input_socket, ())


def _constant(input_socket, groups):
    value = _float_feed(input_socket, groups)
    return value if isinstance(value, float) else None


def _temperature(input_socket, groups):
    value = _float_feed(input_socket, groups)
    if value is None or isinstance(value, float):
        return value
    socket, inner_groups = value
    return socket if not inner_groups else None  # only sockets of the top-level tree can be linked


def _grey_constant(input_socket, groups):
    """Grey level of an input fed by nothing (r = g = b >= 0), else None."""
    found = _feed(input_socket, groups)
    if found is None or found[2] is None:
        return None
    r, g, b = tuple(found[2].default_value)[:3]
    return float(r) if r == g == b and r >= 0.0 else None


# --- the rules ------------------------------------------------------------------------------


def blackbody_source(socket: NodeSocket | None) -> Blackbody | None:
    """What feeds input ``socket``, as a :class:`Blackbody`, or None (not recognised as one)."""
    return _trace(socket, ())


def _trace(input_socket, groups):
    found = _feed(input_socket, groups)
    if found is None or found[0] is None:
        return None
    socket, groups, _ = found
    node = socket.node
    if node.bl_idname == "ShaderNodeBlackbody":
        temperature = _temperature(node.inputs["Temperature"], groups)
        return None if temperature is None else Blackbody(temperature, 1.0)
    if node.bl_idname in MIX_NODES:
        return _mix(node, groups)
    if node.bl_idname == "ShaderNodeVectorMath" and node.operation == "SCALE":
        scale = _constant(by_identifier(node.inputs, "Scale"), groups)
        inner = _trace(by_identifier(node.inputs, "Vector"), groups)
        if inner is None or scale is None or scale < 0.0:
            return None
        return Blackbody(inner.temperature, _times(inner.scale, scale))
    return None


def _times(*factors):
    product = 1.0
    for factor in factors:
        if factor is None:
            return None
        product *= factor
    return product


def _mix_sockets(node):
    """``(factor, A, B, clamp factor)`` of a colour mix node, None if it clamps its result."""
    if node.bl_idname == "ShaderNodeMixRGB":
        if node.use_clamp:
            return None
        return node.inputs["Fac"], node.inputs["Color1"], node.inputs["Color2"], False
    if node.data_type != "RGBA" or node.clamp_result:
        return None
    inputs = {socket.identifier: socket for socket in node.inputs}
    return inputs["Factor_Float"], inputs["A_Color"], inputs["B_Color"], node.clamp_factor


def _mix(node, groups):
    sockets = _mix_sockets(node)
    if sockets is None or node.blend_type not in ("MIX", "MULTIPLY"):
        return None
    factor_socket, a, b, clamp_factor = sockets
    factor = _constant(factor_socket, groups)
    if factor is None and not clamp_factor:
        return None  # varies and may leave [0, 1]
    if factor is not None:
        if clamp_factor:
            factor = min(max(factor, 0.0), 1.0)
        elif not 0.0 <= factor <= 1.0:
            return None
    if node.blend_type == "MIX":
        if factor in (0.0, 1.0):
            return _trace(b if factor else a, groups)
        first, second = _trace(a, groups), _trace(b, groups)
        if first is None or second is None or not _same_temperature(first.temperature, second.temperature):
            return None
        if factor is None or first.scale is None or second.scale is None:
            return Blackbody(first.temperature, None)
        return Blackbody(first.temperature, (1.0 - factor) * first.scale + factor * second.scale)
    first = _trace(a, groups)
    grey = _grey_constant(b, groups)
    if first is not None and grey is not None:
        keep = None if factor is None else 1.0 - factor + factor * grey
        return Blackbody(first.temperature, _times(first.scale, keep))
    second = _trace(b, groups)
    grey = _grey_constant(a, groups)
    if second is not None and grey is not None and factor == 1.0:
        return Blackbody(second.temperature, _times(second.scale, grey))
    return None


def _same_temperature(first, second):
    if isinstance(first, float) or isinstance(second, float):
        return isinstance(first, float) and isinstance(second, float) and first == second
    return first == second  # the same output socket


# --- lights ---------------------------------------------------------------------------------


def _grey(colour):
    r, g, b = tuple(colour)[:3]
    return r == g == b


def light_emission_node(tree: NodeTree) -> Node | None:
    """The Emission node that a light's active Light Output shows, or None."""
    outputs = [node for node in tree.nodes if node.bl_idname == "ShaderNodeOutputLight"]
    output = next((node for node in outputs if node.is_active_output), outputs[0] if outputs else None)
    if output is None:
        return None
    found = _feed(output.inputs["Surface"], ())
    if found is None or found[0] is None or found[0].node.bl_idname != "ShaderNodeEmission":
        return None
    return found[0].node


def light_tree_emission(light: Light) -> Node | None:
    """The Emission node of the tree ``light`` renders with (:func:`light_emission_node`), or None
    (no tree in use, or none shown)."""
    tree = compat.light_node_tree(light)
    return light_emission_node(tree) if tree is not None else None


def _light_emission_colour(tree):
    """The Color input of the Emission node that a light's active Light Output shows, or None."""
    node = light_emission_node(tree)
    return None if node is None else node.inputs["Color"]


def light_blackbody(light: Light) -> float | None:
    """Temperature (K) of a light (``bpy.types.Light``) whose emitted spectrum is a blackbody's
    times a constant, or None.

    Blackbody when the light's colour is grey and exactly one blackbody is in play: its own
    temperature (``use_temperature``) with a node tree that emits a grey constant (or no node
    tree), or a node tree whose Emission colour is a blackbody (:func:`blackbody_source`) at a
    constant temperature, with ``use_temperature`` off. Two blackbodies multiplied are not one.
    """
    if not _grey(light.color):
        return None
    own = float(light.temperature) if light.use_temperature else None
    tree = compat.light_node_tree(light)
    if tree is None:
        return own
    colour = _light_emission_colour(tree)
    if colour is None:
        return None
    source = blackbody_source(colour)
    if source is None:
        return own if _grey_constant(colour, ()) is not None else None
    if own is not None or not isinstance(source.temperature, float):
        return None
    return source.temperature


def light_tree_blackbody(light: Light) -> Blackbody | None:
    """The Blackbody on the Emission Color of the light's tree that is its blackbody
    (:func:`light_blackbody`, its own temperature off), or None."""
    node = light_tree_emission(light)
    if node is None or not node.inputs["Color"].is_linked or light.use_temperature or light_blackbody(light) is None:
        return None
    return blackbody_source(node.inputs["Color"])


def light_tree_factor(light: Light) -> tuple[float, float, float]:
    """What the light's node tree multiplies its Color by (linear RGB), a Blackbody in it left out
    (that is :func:`light_blackbody`'s): its Emission's Strength times its unlinked Color, or times
    the Blackbody's constant; ones without a tree, the Strength alone for any other Color."""
    node = light_tree_emission(light)
    if node is None:
        return (1.0, 1.0, 1.0)
    strength = node.inputs["Strength"]
    scale = float(strength.default_value) if not strength.is_linked else 1.0
    colour = node.inputs["Color"]
    if not colour.is_linked:
        r, g, b = (scale * float(v) for v in colour.default_value[:3])
        return (r, g, b)
    blackbody = light_tree_blackbody(light)
    if blackbody is not None and isinstance(blackbody.scale, float):
        scale *= blackbody.scale
    return (scale, scale, scale)


def scene_blackbody_lights(scene: Scene) -> dict[str, float]:
    """``{light object name: temperature}`` for every light of ``scene`` that is a blackbody."""
    found = {}
    for obj in scene.objects:
        if obj.type == "LIGHT":
            temperature = light_blackbody(obj.data)
            if temperature is not None:
                found[obj.name] = temperature
    return found


# --- Principled Volume ----------------------------------------------------------------------


def volume_blackbody(node: Node) -> Blackbody | None:
    """The Principled Volume's own blackbody emission, or None.

    Blender (Cycles and EEVEE alike) adds ``tint sigma mix(1, T^4, intensity) blackbody(T)``
    with ``T`` the Temperature input (times the temperature grid where the volume has one) when
    Blackbody Intensity exceeds 1e-3: a blackbody at ``T`` when the tint is grey. Returned with
    scale None (it varies with the grid and Stefan-Boltzmann's ``T^4``). Volume shaders write no
    AOVs: ``volumes.py`` shifts it for camera rays and marks the pixels on the volume's boundary."""
    if node.bl_idname != "ShaderNodeVolumePrincipled":
        return None
    intensity = _constant(node.inputs["Blackbody Intensity"], ())
    if intensity is not None and intensity <= BLACKBODY_INTENSITY_CUTOFF:
        return None
    if _grey_constant(node.inputs["Blackbody Tint"], ()) is None:
        return None
    temperature = _temperature(node.inputs["Temperature"], ())
    return None if temperature is None else Blackbody(temperature, None)


# (node type, input names) whose colour is an emitted or reflected rest-frame colour.
COLOUR_INPUTS = (
    ("ShaderNodeEmission", ("Color",)),
    ("ShaderNodeBsdfPrincipled", ("Base Color", "Emission Color")),
    ("ShaderNodeBsdfDiffuse", ("Color",)),
)


def grouped_node(tree: NodeTree | None, kinds: Container[str], seen: tuple[str, ...] = ()) -> tuple[Node, Node] | None:
    """``(group node, inner node)``: the first node whose type is in ``kinds`` inside a node
    group of ``tree`` (at any depth; the add-on's own groups aside), or None."""
    if tree is None or tree.name in seen:
        return None
    for node in tree.nodes:
        if (
            node.bl_idname != "ShaderNodeGroup"
            or node.node_tree is None
            or node.name.startswith(names.MATERIAL_NODE_PREFIX)
        ):
            continue
        inner = next((n for n in node.node_tree.nodes if n.bl_idname in kinds), None)
        if inner is None:
            found = grouped_node(node.node_tree, kinds, (*seen, tree.name))
            inner = found[1] if found is not None else None
        if inner is not None:
            return node, inner
    return None


def mark_blackbody(tree: NodeTree, node: Node, blackbody: Blackbody) -> None:
    """Colour group ``node`` shifts its colour as a blackbody (``sources.Blackbody``)."""
    node.inputs["Is Blackbody"].default_value = 1.0
    if isinstance(blackbody.temperature, float):
        node.inputs["Temperature"].default_value = blackbody.temperature
    else:
        tree.links.new(blackbody.temperature, node.inputs["Temperature"])


def rest_colour_input(socket: NodeSocket) -> NodeSocket | None:
    """The input socket holding the user's rest-frame colour of a colour input: the socket itself,
    or, where the Doppler colour stage's group (``materials.py``) feeds it, that group's Color
    input; None for a group without one."""
    if socket.is_linked:
        node = socket.links[0].from_node
        if node.bl_idname == "ShaderNodeGroup" and node.name.startswith(names.MATERIAL_NODE_PREFIX):
            return node.inputs.get("Color")
    return socket
