"""Moving emissive meshes that light the scene (``Object.relativity.lights_scene``).

A mesh emitter with Constant Velocity lights other surfaces from where it was when it sent each
of them its light, beamed by eq. 19 (Weiskopf et al. 1999), like a moving light. The moving-light
stage draws it as a **point light at the object's origin** with the emitter's mean radiant
intensity, ``I = L A / 4`` per channel (``L`` the emission's radiance, strength times colour;
``A`` the mesh's surface area in world units): the mean projected area of a convex body is a
quarter of its surface (Cauchy), so a sphere is exact in every direction, and any convex emitter
is exact on average over directions. Its own emission then reaches camera rays only (its diffuse,
glossy, transmission and volume ray visibility are switched off while applied, which also keeps
Cycles from sampling it as a light), so the camera still sees it where the apparent geometry puts
it. Approximations (docs/moving-lights.md): one point at the origin (the emitter's size and shape
shape neither the light's direction dependence nor its shadows), a constant emission colour and
strength (the first Emission shader, or Principled BSDF emission, of its materials; textures are
not followed), and the object's velocity for every part of it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..common import compat, names, visibility
from . import sources

if TYPE_CHECKING:
    import numpy.typing as npt
    from bpy.types import Material, Object
    from mathutils import Matrix

RAYS = ("visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume_scatter")


def _emissions(tree):
    """``(colour, strength)`` input sockets of the tree's Emission and Principled BSDF nodes in use."""
    for node in tree.nodes:
        if node.bl_idname == "ShaderNodeEmission":
            sockets = node.inputs["Color"], node.inputs["Strength"]
        elif node.bl_idname == "ShaderNodeBsdfPrincipled":
            sockets = node.inputs["Emission Color"], node.inputs["Emission Strength"]
        else:
            continue
        if not node.mute and node.outputs[0].is_linked:
            yield sockets


def emission_radiance(obj: Object) -> tuple[float, ...] | None:
    """``(r, g, b)`` radiance of the emitter's first constant emission, or None."""
    for slot in obj.material_slots:
        material = slot.material
        if material is None or material.node_tree is None:
            continue
        for colour, strength in _emissions(material.node_tree):
            colour = _rest_colour(colour)
            if colour is None or strength.is_linked:
                continue
            radiance = tuple(float(strength.default_value) * float(v) for v in tuple(colour.default_value)[:3])
            if max(radiance) > 0.0:
                return radiance
    return None


def emits(material: Material) -> bool:
    """Whether ``material`` emits light at all (an Emission or Principled emission in use, its
    strength and colour not zero where unlinked)."""
    tree = compat.rendered_node_tree(material)
    return tree is not None and any(
        (strength.is_linked or strength.default_value > 0.0)
        and (colour.is_linked or max(colour.default_value[:3]) > 0.0)
        for colour, strength in _emissions(tree)
    )


def _rest_colour(socket):
    """The unlinked socket holding the colour, looking through the Doppler colour stage's group,
    or None for a linked colour."""
    socket = sources.rest_colour_input(socket)
    return None if socket is None or socket.is_linked else socket


def surface_area(obj: Object, matrix: Matrix | npt.ArrayLike) -> float:
    """The mesh's surface area in world units (its rest shape under the world matrix ``matrix``)."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    count = len(mesh.loop_triangles)
    if count == 0:
        return 0.0
    corners = np.empty(3 * count, dtype=np.int64)
    mesh.loop_triangles.foreach_get("vertices", corners)
    local = np.empty(3 * len(mesh.vertices), dtype=np.float64)
    mesh.vertices.foreach_get("co", local)
    world = local.reshape(-1, 3) @ np.asarray(matrix)[:3, :3].T
    a, b, c = (world[corners.reshape(-1, 3)[:, i]] for i in range(3))
    return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=-1).sum())


def intensity(obj: Object, matrix: Matrix | npt.ArrayLike) -> tuple[float, ...] | None:
    """Mean radiant intensity ``L A / 4`` (W/sr per channel) of the emitter, or None."""
    radiance = emission_radiance(obj)
    if radiance is None:
        return None
    area = surface_area(obj, matrix)
    return tuple(v * area / 4.0 for v in radiance) if area > 0.0 else None


def is_emitter_light(obj: Object) -> bool:
    return obj.type == "MESH" and obj.relativity.motion == "CONSTANT" and obj.relativity.lights_scene


def hide_from_light_rays(obj: Object) -> None:
    """Camera rays only: the stand-in light carries the emitter's light (the user's values saved)."""
    visibility.hide(obj, names.EMITTER_SAVED_KEY, RAYS)


def restore(obj: Object) -> bool:
    return visibility.restore(obj, names.EMITTER_SAVED_KEY)
