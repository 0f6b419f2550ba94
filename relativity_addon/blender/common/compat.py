"""Every call that differs between the supported Blender lines (4.5 LTS and 5.2 LTS), in one place.

Decided by feature detection (what the running Blender offers), not by version numbers, so a
later release that keeps the newer API needs no change here. Each function is tested on both
lines in ``tests/blender/test_compat.py`` (real ``bpy``).
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any

import bpy

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from bpy.types import (
        ActionChannelbag,
        AnimData,
        FCurve,
        Light,
        Material,
        Modifier,
        Node,
        NodeSocket,
        NodeTree,
        Scene,
        ShaderNodeTree,
        World,
        bpy_struct,
    )


def _modifier_inputs(modifier):
    """5.2+: a geometry-nodes modifier's inputs live in ``modifier.properties.inputs`` (RNA)."""
    properties = getattr(modifier, "properties", None)
    return getattr(properties, "inputs", None)


def modifier_input(modifier: Modifier, identifier: str) -> Any:
    """Value of a geometry-nodes modifier input (``identifier`` as in ``interface.items_tree``)."""
    inputs = _modifier_inputs(modifier)
    if inputs is not None:
        return getattr(inputs, identifier).value
    return modifier.get(identifier)  # 4.5: ID properties on the modifier


def set_modifier_input(modifier: Modifier, identifier: str, value: Any) -> None:
    set_modifier_inputs(modifier, {identifier: value})


def set_modifier_inputs(modifier: Modifier, values: dict[str, Any]) -> None:
    """Several inputs of one modifier (``identifier: value``): where they live is looked up once."""
    inputs = _modifier_inputs(modifier)
    if inputs is not None:
        for identifier, value in values.items():
            getattr(inputs, identifier).value = value
    else:
        for identifier, value in values.items():
            modifier[identifier] = value


def action_channelbag(animation_data: AnimData | None) -> ActionChannelbag | None:
    """The channelbag (F-curves, groups) of the action slot assigned to ``animation_data``, or None.

    4.5 lacks ``anim_utils.animdata_get_channelbag_for_assigned_slot``; the per-slot lookup
    exists in 4.5 and 5.x alike."""
    if animation_data is None or animation_data.action is None or animation_data.action_slot is None:
        return None
    from bpy_extras import anim_utils

    return anim_utils.action_get_channelbag_for_slot(animation_data.action, animation_data.action_slot)


def action_fcurves(animation_data: AnimData | None) -> Iterable[FCurve]:
    """The F-curves of the action slot assigned to ``animation_data`` (empty if none)."""
    channelbag = action_channelbag(animation_data)
    return () if channelbag is None else channelbag.fcurves


def _node_tree(owner):
    # 5.x: materials and worlds always have a node tree (use_nodes is deprecated, do not touch it);
    # 4.5: a new one has none until use_nodes is switched on.
    if owner.node_tree is None:
        owner.use_nodes = True
    return owner.node_tree


def world_node_tree(world: World) -> ShaderNodeTree:
    """The world's shader node tree, creating Blender's default one (Background) where needed."""
    return _node_tree(world)


def material_node_tree(material: Material) -> ShaderNodeTree:
    """The material's shader node tree, creating Blender's default one (Principled) where needed."""
    return _node_tree(material)


def rendered_node_tree(owner: Light | Material | World) -> ShaderNodeTree | None:
    """The node tree ``owner`` renders with, or None: 5.x always uses its tree (``use_nodes`` is
    deprecated and stays on), 4.5 only while ``use_nodes`` is on (else its plain colour)."""
    if owner.node_tree is None:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return owner.node_tree if getattr(owner, "use_nodes", True) else None


def empty_light_tree(light: Light) -> ShaderNodeTree:
    """``light``'s node tree, in use and emptied (5.x: ``use_nodes`` is deprecated and always on)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        light.use_nodes = True
    tree = light.node_tree
    tree.nodes.clear()
    return tree


def light_node_tree(light: Light) -> ShaderNodeTree | None:
    """The node tree a light renders with, or None. 5.x: lights always have one and always use
    it (``use_nodes`` is deprecated and stays on); 4.5: only while ``use_nodes`` is on."""
    return rendered_node_tree(light)


def eevee_engine() -> str:
    """Identifier of the EEVEE render engine ('BLENDER_EEVEE_NEXT' in 4.5, 'BLENDER_EEVEE' in 5.x)."""
    engines = {item.identifier for item in bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items}
    return "BLENDER_EEVEE" if "BLENDER_EEVEE" in engines else "BLENDER_EEVEE_NEXT"


def enum_name(data: Any, prop: str, value: str | None = None) -> str:
    """The name the user sees for ``value`` (default: the current value) of ``data``'s enum
    property ``prop``: "EEVEE" for the engine identifier 'BLENDER_EEVEE_NEXT' (4.5) or
    'BLENDER_EEVEE' (5.x)."""
    value = getattr(data, prop) if value is None else value
    for item in data.bl_rna.properties[prop].enum_items:
        if item.identifier == value:
            return item.name
    # the bpy module lists only EEVEE among the engines: the others as the Render Engine menu shows them
    return _ENGINE_NAMES.get(value, value.replace("_", " ").title())


_ENGINE_NAMES = {"CYCLES": "Cycles", "BLENDER_WORKBENCH": "Workbench"}


def engine_label(identifier: str) -> str:
    """The render engine's name as the Render Engine menu shows it ('EEVEE', not its identifier)."""
    return enum_name(bpy.types.RenderSettings, "engine", identifier)


def has_compositor_node_groups() -> bool:
    """5.x: the scene's compositor is a node group (``scene.compositing_node_group``) ending in a
    Group Output; 4.5 has the scene-owned ``scene.node_tree`` with a Composite node instead."""
    return "compositing_node_group" in bpy.types.Scene.bl_rna.properties


def compositor_tree(scene: Scene) -> NodeTree | None:
    """The scene's compositor node tree or None (4.5: only while ``scene.use_nodes`` is on)."""
    if has_compositor_node_groups():
        return scene.compositing_node_group
    return scene.node_tree if scene.use_nodes else None


def new_compositor_tree(scene: Scene, name: str) -> NodeTree:
    """Give a scene with no compositor tree one that passes Render Layers to the output; return it.

    5.x: a new node group ``name`` ending in a Group Output, assigned to the scene. 4.5: switches
    ``scene.use_nodes`` on, which makes Blender's default scene-owned tree (Render Layers ->
    Composite, and a Viewer) or re-enables the scene's existing one."""
    if not has_compositor_node_groups():
        scene.use_nodes = True
        return scene.node_tree
    tree = bpy.data.node_groups.new(name, "CompositorNodeTree")
    tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    layers = tree.nodes.new("CompositorNodeRLayers")
    output = tree.nodes.new("NodeGroupOutput")
    output.location = (400.0, 0.0)
    tree.links.new(layers.outputs["Image"], output.inputs[0])
    scene.compositing_node_group = tree
    return tree


def restore_compositor_tree(scene: Scene, name: str) -> None:
    """Undo :func:`new_compositor_tree`: the tree named ``name`` ("" for none) is the scene's again
    (4.5: the scene's own tree stays, ``use_nodes`` is restored)."""
    if not has_compositor_node_groups():
        scene.use_nodes = bool(name)
        return
    scene.compositing_node_group = bpy.data.node_groups.get(name) if name else None


def compositor_output(tree: NodeTree) -> Node | None:
    """The node whose first input is the compositor's result: the active Composite node (4.5) or
    the active Group Output (5.x)."""
    kind = "NodeGroupOutput" if has_compositor_node_groups() else "CompositorNodeComposite"
    outputs = [node for node in tree.nodes if node.bl_idname == kind]
    return next((node for node in outputs if getattr(node, "is_active_output", True)), outputs[0] if outputs else None)


def alpha_over_inputs(node: Node) -> tuple[NodeSocket, NodeSocket]:
    """``(background, foreground)`` of a compositor Alpha Over node: named sockets in 5.x, the
    two unnamed Image inputs after the factor in 4.5."""
    if "Background" in node.inputs:
        return node.inputs["Background"], node.inputs["Foreground"]
    return node.inputs[1], node.inputs[2]


def render_layers_diffuse_colour(layers: Node) -> NodeSocket | None:
    """The Diffuse Color pass's output of a compositor Render Layers node (the pass switched on
    and the node updated), or None: ``Diffuse Color`` in 5.x, ``DiffCol`` in 4.5."""
    for name in ("Diffuse Color", "DiffCol"):
        if name in layers.outputs:
            return layers.outputs[name]
    return None


def map_uv_nearest() -> tuple[dict[str, str], dict[str, str]]:
    """``(inputs, props)`` for a compositor Map UV node that reads the nearest texel.

    5.x: the Interpolation menu socket; 4.5: the ``filter_type`` property (which offers only
    nearest and anisotropic, no bilinear: callers interpolate themselves)."""
    if "filter_type" in bpy.types.CompositorNodeMapUV.bl_rna.properties:
        return {}, {"filter_type": "NEAREST"}
    return {"Interpolation": "Nearest"}, {}


def run_main(main: Callable[[], int | str | None]) -> None:
    """Run a script's ``main()`` and end the process with its exit status.

    Blender 4.5's ``bpy`` wheel can deadlock in ``exit()``: a static destructor waits on its
    delayed file-close thread (seen after rendering to a file, also after an error). There the
    process flushes its output and leaves with ``os._exit``; 5.x exits normally."""
    import os
    import sys

    try:
        status = main()
    except SystemExit as stop:  # argparse errors, explicit sys.exit
        status = stop.code
    if bpy.app.version >= (5, 0, 0):
        sys.exit(status)
    if not isinstance(status, int):
        if status is not None:
            print(status, file=sys.stderr)
        status = 0 if status is None else 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)


def custom_property_keys(owner: bpy_struct) -> list[str]:
    """Names of the user's custom (ID) properties on ``owner``.

    4.5 also lists there the storage of registered properties (``relativity``, ``cycles``, ...);
    5.x keeps those apart."""
    rna_properties = owner.bl_rna.properties
    return [key for key in owner.keys() if key not in rna_properties]


def custom_camera_aperture_scale(focal_length: float) -> float:
    """Factor from Cycles' custom-camera ``cam:aperture_position`` to scene units.

    5.x samples the aperture for a unit focal length (radius ``1 / (2 f-stop)``), 4.5 in scene
    units (radius ``focal length / (2 f-stop)``). No API tells the two apart: decided by version."""
    return focal_length if bpy.app.version >= (5, 0, 0) else 1.0


def volume_ray_marching(scene: Scene) -> bool | None:
    """Whether Cycles renders ``scene``'s volumes by ray marching: 5.x's ``volume_biased`` (its
    default is null scattering), None where Cycles has only ray marching (4.5)."""
    value = getattr(scene.cycles, "volume_biased", None)
    return None if value is None else bool(value)


def set_volume_ray_marching(scene: Scene, value: bool | None) -> None:
    """Set what :func:`volume_ray_marching` reads (nothing to set on 4.5, or for None)."""
    if value is not None and hasattr(scene.cycles, "volume_biased"):
        scene.cycles.volume_biased = value
