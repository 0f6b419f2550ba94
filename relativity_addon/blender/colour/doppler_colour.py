"""Searchlight and Doppler colour, as a whole: the colour module of the render paths.

Both paths attach the Doppler colour group to every material (``materials``), which reads
``D`` per shading point and scales and shifts the colour; the exact camera adds the world's
Doppler AOV and the compositor stage (``compositing``), which shifts ordinary colours per pixel
after the render. What the groups compute comes from a ``snapshot.Snapshot`` through one settings
group (materials) and the compositor group's flag inputs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ...errors import RelativityError
from ..common import names
from . import compositing, grouped_volumes, lut_images, materials, volumes, world_colour, world_sampling
from .compositing import is_applied as compositor_applied

if TYPE_CHECKING:
    from bpy.types import Scene

    from ..scene.snapshot import Snapshot


def apply(scene: Scene, snap: Snapshot) -> None:
    """Searchlight and Doppler colour for the snapshot's render path: the materials (and, for the
    exact camera, the world and the compositor stage). RelativityError (one line) after undoing
    any partial change."""
    try:
        _attach(scene, snap)
        if snap.colour.camera_path:
            compositing.apply_colour_stage(scene, snap)
        write(scene, snap)
    except (ImportError, ValueError, KeyError, RuntimeError) as error:
        remove(scene)
        message = str(error).strip().splitlines()
        raise RelativityError(
            f"Doppler colour could not be set up: {type(error).__name__}: {message[-1] if message else ''}"
        ) from error


def write(scene: Scene, snap: Snapshot, attach_new_materials: bool = False) -> None:
    """Write the snapshot's colour factors; before a render also attach materials added since."""
    if attach_new_materials:
        _attach(scene, snap)
    materials.write_settings(snap)
    _write_object_temperatures(scene)
    if snap.colour.camera_path:
        world_colour.write(scene.world)  # the world's colour groups only where they change the colour
    compositing.write_colour_stage(scene, snap)


def _attach(scene, snap):
    """The colour groups in every material (and on the exact camera's path the world and volumes)."""
    if snap.colour.camera_path and not materials.is_attached(scene.world):
        world_sampling.hold(scene.world)  # before the groups make the world look varying
    materials.attach_scene(scene, camera_path=snap.colour.camera_path)
    if snap.colour.camera_path:
        volumes.attach_scene(scene)
        grouped_volumes.attach_scene(scene)


def _write_object_temperatures(scene):
    """Each object's blackbody temperature as a custom property, which the colour groups inside
    shared node groups read (``grouped_colours.read_object_temperature``); written only where it
    changed (a write is a depsgraph update)."""
    for obj in scene.objects:
        if obj.library is not None:
            continue  # linked from another file: not editable here (its groups keep the RGB path)
        temperature = float(obj.relativity.temperature)
        if temperature > 0.0 and obj.get(names.OBJECT_TEMPERATURE_PROPERTY) != temperature:
            obj[names.OBJECT_TEMPERATURE_PROPERTY] = temperature
        elif temperature <= 0.0 and names.OBJECT_TEMPERATURE_PROPERTY in obj:
            del obj[names.OBJECT_TEMPERATURE_PROPERTY]


def remove_camera_stage(scene: Scene) -> None:
    """Undo what :func:`apply` adds for the exact camera only (the compositor stage and the world's
    Doppler AOV), after an Apparent Geometry final render; the materials stay attached."""
    compositing.remove_colour_stage(scene)
    materials.detach_world(scene.world)
    world_sampling.release(scene.world)


def remove(scene: Scene) -> None:
    """Undo :func:`apply`: the compositor stage, every material and world, and the add-on's node
    groups and lookup tables once no scene uses them."""
    compositing.remove_colour_stage(scene)
    materials.detach_all()
    for obj in scene.objects:
        if obj.library is None and names.OBJECT_TEMPERATURE_PROPERTY in obj:
            del obj[names.OBJECT_TEMPERATURE_PROPERTY]
    for world in bpy.data.worlds:
        world_sampling.release(world)
    if not any(compositor_applied(other) for other in bpy.data.scenes):
        remove_unused_data()


def remove_unused_data() -> bool:
    """Delete the add-on's node groups and LUT images once nothing uses the effect any more."""
    if any(materials.is_attached(material) for material in bpy.data.materials):
        return False
    group_names = (
        compositing.COMPOSITOR_GROUP,
        compositing.COMPOSITOR_GAMUT_MAP,
        volumes.GROUP,
        volumes.COLOUR_GROUP,
    ) + tuple(builder().name for builder in reversed(materials.GROUP_BUILDERS))
    for name in group_names:
        tree = bpy.data.node_groups.get(name)
        if tree is not None:
            bpy.data.node_groups.remove(tree)
    for name in (
        lut_images.DOPPLER_LUT_NAME,
        lut_images.BLACKBODY_LUT_NAME,
        names.WORLD_DOPPLER_IMAGE,
        *lut_images.ILLUMINANT_LUT_NAMES,
    ):
        image = bpy.data.images.get(name)
        if image is not None:
            bpy.data.images.remove(image)
    return True
