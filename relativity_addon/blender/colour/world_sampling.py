"""The world's light-sampling map while the exact camera's Doppler groups are in a constant world.

Before every render Cycles builds an importance map of a world whose colour may vary with the
direction, by evaluating its shader over the map (1024 x 512 under the default Automatic
sampling); a constant world (a Background of constant colour and strength) needs none. Once the
exact camera's Doppler AOV and colour groups are in its node tree Cycles can no longer tell that
it is constant and builds the map: 1.9 s of every render, measured on a world-only 192 x 96
panorama at 1 sample (2.1 s against 0.08 s without the map). The groups change the colour for
camera rays only, so the map of the world's light is uniform anyway: while they are in a
constant world its Sampling is Manual at resolution ``MAP_RESOLUTION`` (a uniform map, cheap), and
the user's settings come back when they go. Worlds that vary (textures, sky) keep theirs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..common import names

if TYPE_CHECKING:
    from bpy.types import Node, World

MAP_RESOLUTION = 16
SAVED = names.WORLD_SAMPLING_SAVED_KEY


def constant_background(world: World) -> Node | None:
    """The world's one Background of unlinked colour and strength that its surface is, or None."""
    tree = world.node_tree
    if tree is None:
        return None
    outputs = [node for node in tree.nodes if node.bl_idname == "ShaderNodeOutputWorld" and node.is_active_output]
    links = outputs[0].inputs["Surface"].links if len(outputs) == 1 else None
    if not links or outputs[0].inputs["Volume"].is_linked:
        return None
    background = links[0].from_node
    if background.bl_idname != "ShaderNodeBackground" or any(socket.is_linked for socket in background.inputs):
        return None
    return background


def hold(world: World | None) -> None:
    """Before the Doppler groups go into ``world``: a uniform map if the world is constant."""
    if world is None or SAVED in world or constant_background(world) is None:
        return
    settings = world.cycles
    world[SAVED] = {
        "sampling_method": settings.sampling_method,
        "sample_map_resolution": settings.sample_map_resolution,
    }
    settings.sampling_method = "MANUAL"
    settings.sample_map_resolution = MAP_RESOLUTION


def release(world: World | None) -> None:
    """Give the world back its sampling settings."""
    if world is None or SAVED not in world:
        return
    saved = world[SAVED].to_dict()
    world.cycles.sampling_method = saved["sampling_method"]
    world.cycles.sample_map_resolution = saved["sample_map_resolution"]
    del world[SAVED]
