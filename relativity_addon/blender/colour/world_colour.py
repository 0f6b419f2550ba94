"""The world's Doppler colour groups: in the Background colours only where they change something.

``materials.attach_world`` puts the Doppler colour group in front of every Background colour of
the world on the exact camera's path. In the fast (non-spectral) mode a colour that is not a
blackbody passes through the group unchanged (the compositor shifts the pixel), yet Cycles runs
the group for every sample that meets the world: 0.07 us a sample, measured on a world-only
panorama. So the group's output is linked to the Background only where it is needed:

- in the spectral passes (``materials.set_spectral_pass``): every colour becomes its spectral values;
- for a Background colour fed by a blackbody (``Is Blackbody``): shifted to ``D T`` here.

Elsewhere the Background gets its own colour back (the source's link, or its unlinked value) and
the group stays in the tree, unlinked, which Cycles leaves out of the compiled shader. (Muting
the group node instead does not work in Blender 4.5: a muted group's unlinked Color input
reaches the Background as black.) :func:`write` runs at every sync, so each spectral pass and
the fast mode after it find the links they need; ``materials.detach`` undoes either state.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..common import names
from . import materials

if TYPE_CHECKING:
    from bpy.types import Node, World


def _colour_records(world):
    """``(group node, Background Color socket, source socket or None)`` of each Background colour."""
    if (
        world is None
        or world.node_tree is None
        or names.MATERIAL_ATTACHED_KEY not in world
        or isinstance(world[names.MATERIAL_ATTACHED_KEY], str)
    ):
        return []
    found = []
    for record in world[names.MATERIAL_ATTACHED_KEY]:
        group, socket, source = materials.resolve_record(world.node_tree, record)
        if (
            group is not None
            and socket is not None
            and group.node_tree is not None
            and group.node_tree.name == materials.DOPPLER_EMISSION
        ):
            found.append((group, socket, source))
    return found


def is_active(group: Node) -> bool:
    """Whether the group must colour the Background now: a spectral pass, or a blackbody."""
    return materials.spectral_pass_wavelengths() is not None or group.inputs["Is Blackbody"].default_value > 0.0


def write(world: World | None) -> None:
    """Link each world colour group into its Background where :func:`is_active`, else give the
    Background its own colour; only links that differ are changed (this runs at every sync)."""
    tree = world.node_tree if world is not None else None
    for group, socket, source in _colour_records(world):
        feeding = socket.links[0].from_socket if socket.is_linked else None
        if is_active(group):
            if feeding is not None and feeding.node == group:
                continue
            if source is None:  # the user may have changed the unlinked colour meanwhile
                group.inputs["Color"].default_value = socket.default_value
            tree.links.new(group.outputs["Color"], socket)
        elif source is not None:
            if feeding != source:
                tree.links.new(source, socket)
        elif feeding is not None and feeding.node == group:
            tree.links.remove(socket.links[0])


def linked_groups(world: World) -> list[Node]:
    """The world's colour groups that feed their Background now (for tests and the docs)."""
    return [
        group
        for group, socket, _source in _colour_records(world)
        if socket.is_linked and socket.links[0].from_node == group
    ]
