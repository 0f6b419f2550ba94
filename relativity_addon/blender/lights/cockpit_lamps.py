"""The scene's lamps on the cockpit: lamps at rest in the scene lighting the objects that move with
the camera (``camera/cockpit.py``), as Weiskopf et al.'s eq. 18 says a lamp at rest lights a moving
object (``lamps_on_moving_objects.py``, docs/lamp-doppler.md; rests on ``physics/lamp_doppler.py``).

The cockpit moves with the camera's velocity ``beta``. Light from a lamp reaches it along the
scene-frame direction ``k`` (lamp -> the cockpit's centre) with ``D = gamma (1 - beta . k)``; in the
cockpit's frame it arrives along the aberrated ``k'`` with ``D^2`` the scene-frame irradiance at the
same distance (with the searchlight; the shifted colour with the Doppler colour). Each lamp gets one
copy in the cockpit scene, turned about the cockpit's centre so that its light arrives along ``k'``,
with the colour and strength of ``lamps_on_moving_objects.copy_colour`` (one ``D`` and one direction
for the whole cockpit, exact at its centre: the cockpit is small beside the distance to the lamps).
A sun: its direction aberrated, ``D^2``, its disc as the cockpit sees it
(``lamp_doppler.aberrated_disc_angle``). The copies are not seen by the camera (the film shows the
relativistic render there); the scene's objects cast no shadow on the cockpit (they are not in
its scene). Lamps with their own velocity (moving lights) and the add-on's own lamps are left out
(docs/cockpit.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy
import numpy as np

from ...physics import lamp_doppler
from ..camera import cockpit
from ..common import names
from ..scene import cockpit as cockpit_reader
from . import lamps_on_moving_objects as eq18
from . import stand_in_lights

if TYPE_CHECKING:
    from bpy.types import Object, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

KEY = names.COCKPIT_LAMPS_KEY
PREFIX = names.COCKPIT_LAMP_PREFIX


def lamps(scene: Scene, snap: Snapshot) -> list[Object]:
    """The scene's lamps at rest that render, not moving with the camera and not the add-on's own."""
    moving = {light.name for light in snap.moving_lights}
    return [
        obj
        for obj in eq18.lamps(scene)
        if obj.name not in moving
        and not cockpit_reader.moves_with_camera(obj)
        and not obj.name.startswith("Relativity")  # stand-ins, copies, lamp faces
    ]


def centre(scene: Scene, snap: Snapshot) -> FloatArray:
    """The cockpit's centre (world): the middle of its meshes' bounding boxes, else the camera."""
    points = []
    for name in snap.cockpit:
        obj = scene.objects.get(name)
        if obj is not None and obj.type == "MESH":
            corners = np.array([tuple(corner) for corner in obj.bound_box], dtype=np.float64)
            matrix = np.array(obj.matrix_world, dtype=np.float64)
            points.append((matrix[:3, :3] @ corners.mean(axis=0)) + matrix[:3, 3])
    return np.mean(points, axis=0) if points else snap.camera_position


def write(scene: Scene, snap: Snapshot, structural: bool = True) -> None:
    """Copies of the scene's lamps in the cockpit scene, placed and coloured for the frame (made and
    deleted only when ``structural``)."""
    rest_scene = cockpit.cockpit_scene(scene)
    if rest_scene is None:
        if structural:
            remove(scene)
        return
    record = scene[KEY].to_dict() if KEY in scene else {}
    wanted = {lamp.name: lamp for lamp in lamps(scene, snap)}
    if structural:
        for name in list(record):
            copy = bpy.data.objects.get(record[name])
            if name not in wanted or copy is None or copy.type != "LIGHT" or copy.data.type != wanted[name].data.type:
                stand_in_lights.delete_lamp(record.pop(name))
        for name, lamp in wanted.items():
            if name not in record:
                copy = bpy.data.objects.new(f"{PREFIX} {name}", lamp.data.copy())
                copy.data.name = copy.name
                copy.visible_camera = False  # the film shows the relativistic render there
                rest_scene.collection.objects.link(copy)
                record[name] = copy.name
        scene[KEY] = record
    mover = eq18.Mover("cockpit", tuple(float(v) for v in centre(scene, snap)), tuple(float(b) for b in snap.beta))
    for name, copy_name in record.items():
        original, copied = wanted.get(name), bpy.data.objects.get(copy_name)
        if original is None or copied is None or copied.type != "LIGHT" or copied.data.type != original.data.type:
            continue
        matrix = eq18.lamp_matrix(scene, original, snap)
        doppler, turned = eq18.placement(matrix, original.data.type, mover)
        angle = None
        if original.data.type == "SUN":  # the disc as the cockpit sees it (docs/physics.md)
            k = eq18.incidence(matrix, "SUN", mover)
            angle = lamp_doppler.aberrated_disc_angle(k, mover.beta, float(original.data.angle))
        eq18.write_copy(copied, original, eq18.copy_colour(original, doppler, snap), turned, angle=angle)


def apply(scene: Scene, snap: Snapshot) -> None:
    write(scene, snap)


def remove(scene: Scene) -> None:
    """Delete the copies; safe when nothing was applied."""
    if KEY not in scene:
        return
    for copy_name in scene[KEY].to_dict().values():
        stand_in_lights.delete_lamp(copy_name)
    del scene[KEY]
