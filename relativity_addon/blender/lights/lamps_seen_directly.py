"""Directly visible lamps on the exact camera's path: drawn by emitter meshes that get the Doppler colour.

A Cycles lamp seen by the camera (a point light with a radius, an area light, ``visible_camera``
on) writes no shader AOVs: its pixel carries the ``ln D`` of whatever lies behind it and is
shifted by the compositor as an RGB colour. A blackbody lamp then comes out on the RGB matrix
(Delta E 2000 of 26 against a blackbody emitter at ``D`` = 1.73, docs/moving-lights.md), and in
front of a blackbody emitter (which marks its pixels done) or nothing with an AOV it keeps its
rest colour. So while the exact camera renders, each such lamp at rest is hidden from camera
rays and an emitter mesh of its shape and radiance (its **face**), visible to camera rays only,
is drawn in its place with an ordinary material: the materials' Doppler colour (blackbodies
exactly, RGB through the compositor) and the spectral passes treat it like any emitter.

Radiance, measured against Cycles' own lamps (tests/blender/colour/test_visible_lamps.py):
an area light of power ``P`` and area ``A`` (Normalize on) shows ``P / (pi A)`` times its colour,
a point light of radius ``r`` a disc of ``P / (4 pi^2 r^2)``; ``2^exposure`` multiplies both.

A spot light is drawn as its point light's sphere times Cycles' cone mask toward the camera, taken
at the lamp's centre for the whole face. A sun with an angle ``theta`` is a disc of radiance
``E / (pi sin^2(theta / 2))`` in Cycles (measured); its face is a disc of that angular radius at
``SUN_DISTANCE`` of the camera's clip end, centred on the camera's rays' origin (the aperture centre
at the shutter time, where the exact camera's rays start). Not covered (the lamp keeps Cycles' own
drawing, warned): area lights with a spread below 180 degrees or Normalize off, portals, lamps
whose node tree's emission is textured, moving lights (their stand-ins draw nothing for the camera).
The face is opaque where Cycles' lamps are see-through, and an area light seen from behind gets no
face (it shows nothing there).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import bmesh
import bpy
from mathutils import Matrix, Vector

from ..colour import materials
from ..common import compat, names, visibility
from ..scene import snapshot, sources
from . import moving_lights

if TYPE_CHECKING:
    from bpy.types import Object, Scene

    from ..scene.snapshot import Snapshot

KINDS = ("POINT", "SPOT", "AREA", "SUN")
# A sun's face sits this far out, as a fraction of the camera's clip end: behind everything but
# what lies in the last 2 % before the clip end (the sun itself is behind everything).
SUN_DISTANCE = 0.98
DISC_SEGMENTS = 64


def _emission(light):
    """``(rgb, temperature or None, strength)`` of the face's Emission for ``light``, or None when
    the lamp's node tree makes a colour a constant face cannot carry."""
    colour = tuple(light.color)[:3]
    temperature = sources.light_blackbody(light)
    tree = compat.light_node_tree(light)
    node = None if tree is None else sources.light_emission_node(tree)
    if tree is not None and node is None:
        return None
    strength = 1.0
    if node is not None:
        if node.inputs["Strength"].is_linked:
            return None
        strength = float(node.inputs["Strength"].default_value)
        if temperature is not None and not light.use_temperature:  # the blackbody is in the node tree
            source = sources.blackbody_source(node.inputs["Color"])
            if source is None or source.scale is None:
                return None
            return colour, temperature, strength * source.scale
        if node.inputs["Color"].is_linked:
            return None
        colour = tuple(a * b for a, b in zip(colour, tuple(node.inputs["Color"].default_value)[:3], strict=True))
    if light.use_temperature and temperature is None:  # a tinted blackbody: an RGB colour
        colour = tuple(a * b for a, b in zip(colour, tuple(light.temperature_color)[:3], strict=True))
    return colour, temperature if light.use_temperature else None, strength


def _spot_mask(obj, camera):
    """Cycles' spot cone toward ``camera`` (its smoothstep blend; 0 outside the cone), taken at the
    lamp's centre for the whole face."""
    light = obj.data
    axis = (obj.matrix_world.to_3x3() @ Vector((0.0, 0.0, -1.0))).normalized()
    cos_axis = axis.dot((camera - obj.matrix_world.translation).normalized())
    cos_half, smooth = moving_lights.spot_cone(light.spot_size, light.spot_blend)
    if cos_axis <= cos_half:
        return 0.0
    if smooth == 0.0:
        return 1.0
    x = min((cos_axis - cos_half) * smooth, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _radiance_scale(obj, camera):
    """Radiance of the lamp per unit colour (W m^-2 sr^-1) seen from ``camera``, or None for a lamp
    without a face."""
    light = obj.data
    power = light.energy * 2.0 ** getattr(light, "exposure", 0.0)
    if light.type == "SUN":  # a disc of half-angle theta / 2 (none for a sun without an angle)
        return power / (math.pi * math.sin(0.5 * light.angle) ** 2) if light.angle > 1e-6 else None
    if light.type in ("POINT", "SPOT"):  # a spot is a point light masked by its cone
        radius = light.shadow_soft_size
        if radius <= 0.0:
            return None
        mask = _spot_mask(obj, camera) if light.type == "SPOT" else 1.0
        return power / (4.0 * math.pi**2 * radius**2) * mask if mask > 0.0 else None
    if light.type != "AREA" or light.cycles.is_portal or light.spread < math.pi - 1e-6 or not light.normalize:
        return None
    sx, sy, _sz = obj.matrix_world.to_scale()
    width = light.size
    height = light.size_y if light.shape in ("RECTANGLE", "ELLIPSE") else light.size
    area = width * height * abs(sx * sy) * (math.pi / 4.0 if light.shape in ("DISK", "ELLIPSE") else 1.0)
    return power / (math.pi * area) if area > 0.0 else None


def _candidates(scene, snap):
    """Lights at rest seen by camera rays, the kind a face can draw or not."""
    moving = {light.name for light in snap.moving_lights}
    for obj in scene.objects:
        if obj.type != "LIGHT" or obj.name in moving or snapshot.light_render_hidden(obj):
            continue
        if visibility.saved(obj, names.LAMP_FACE_SAVED_KEY, "visible_camera"):
            yield obj


def _facing_camera(obj, snap):
    """An area light is seen from the front (its local -Z side); a point light from everywhere."""
    if obj.data.type != "AREA":
        return True
    return (obj.matrix_world.inverted_safe() @ Vector(snap.camera_position)).z < 0.0


def _sun_distance(scene, snap):
    return SUN_DISTANCE * scene.objects[snap.camera].data.clip_end


def _mesh(name, light, sun_distance):
    mesh = bpy.data.meshes.new(name)
    mesh[names.LAMP_FACES_KEY] = _shape_key(light, sun_distance)
    if light.type in ("POINT", "SPOT"):
        builder = bmesh.new()
        bmesh.ops.create_uvsphere(
            builder, u_segments=DISC_SEGMENTS, v_segments=DISC_SEGMENTS // 2, radius=light.shadow_soft_size
        )
        builder.to_mesh(mesh)
        builder.free()
        return mesh
    if light.type == "SUN":  # toward the sun (local +Z), facing back along its light
        radius = sun_distance * math.tan(0.5 * light.angle)
        angles = [-2.0 * math.pi * i / DISC_SEGMENTS for i in range(DISC_SEGMENTS)]
        mesh.from_pydata(
            [(radius * math.cos(a), radius * math.sin(a), sun_distance) for a in angles],
            [],
            [tuple(range(DISC_SEGMENTS))],
        )
        return mesh
    width = light.size
    height = light.size_y if light.shape in ("RECTANGLE", "ELLIPSE") else light.size
    if light.shape in ("DISK", "ELLIPSE"):
        angles = [-2.0 * math.pi * i / DISC_SEGMENTS for i in range(DISC_SEGMENTS)]
        corners = [(0.5 * width * math.cos(a), 0.5 * height * math.sin(a), 0.0) for a in angles]
    else:
        corners = [
            (-0.5 * width, -0.5 * height, 0.0),
            (-0.5 * width, 0.5 * height, 0.0),
            (0.5 * width, 0.5 * height, 0.0),
            (0.5 * width, -0.5 * height, 0.0),
        ]
    mesh.from_pydata(corners, [], [tuple(range(len(corners)))])  # normal along local -Z, like the light
    return mesh


def _shape_key(light, sun_distance):
    if light.type == "SUN":
        return f"SUN {light.angle:.9g} {sun_distance:.9g}"
    if light.type == "AREA":
        return f"AREA {light.shape} {light.size:.9g} {light.size_y:.9g}"
    return f"{light.type} {light.shadow_soft_size:.9g}"


def _material(name, colour, temperature, strength):
    material = bpy.data.materials.new(name)
    tree = compat.material_node_tree(material)
    tree.nodes.clear()
    emission = tree.nodes.new("ShaderNodeEmission")
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    _write_material(material, colour, temperature, strength)
    return material


def _write_material(material, colour, temperature, strength):
    tree = material.node_tree
    emission = tree.nodes["Emission"]
    blackbody = tree.nodes.get("Blackbody")
    if temperature is not None:
        if blackbody is None:
            blackbody = tree.nodes.new("ShaderNodeBlackbody")
            tree.links.new(blackbody.outputs[0], emission.inputs["Color"])
        _set(blackbody.inputs["Temperature"], temperature)
        strength *= colour[0]  # grey: light_blackbody checked it
    elif blackbody is not None:
        tree.nodes.remove(blackbody)
    _set(emission.inputs["Color"], (*colour, 1.0))
    _set(emission.inputs["Strength"], strength)


def _set(socket, value):
    current = socket.default_value
    if isinstance(value, tuple):
        if all(math.isclose(a, b, rel_tol=1e-7, abs_tol=1e-12) for a, b in zip(current, value, strict=True)):
            return
    elif math.isclose(current, value, rel_tol=1e-7, abs_tol=1e-12):
        return
    socket.default_value = value


def _face(scene, obj, snap):
    """The face object of light object ``obj``, made (or remade for a new shape) as needed."""
    record = dict(scene.get(names.LAMP_FACES_KEY, {}))
    face = bpy.data.objects.get(record.get(obj.name, ""))
    sun_distance = _sun_distance(scene, snap)
    if face is not None and face.data.get(names.LAMP_FACES_KEY) != _shape_key(obj.data, sun_distance):
        _delete(face.name)
        face = None
    if face is None:
        name = f"{names.LAMP_FACE_PREFIX} {obj.name}"
        face = bpy.data.objects.new(name, _mesh(name, obj.data, sun_distance))
        scene.collection.objects.link(face)
        for ray in ("diffuse", "glossy", "transmission", "volume_scatter", "shadow"):
            setattr(face, f"visible_{ray}", False)
        face.hide_select = True
        record[obj.name] = face.name
        scene[names.LAMP_FACES_KEY] = record
    if obj.data.type == "SUN":  # at infinity: turned with the sun, centred where the rays start
        turn = obj.matrix_world.to_quaternion().to_matrix().to_4x4()
        matrix = Matrix.Translation(Vector(snap.mesh_observer[1])) @ turn
        if face.matrix_world != matrix:
            face.matrix_world = matrix
        return face
    if face.parent != obj:
        face.parent = obj
    # A point light's radius ignores the object's scale; an area light's size follows it.
    inverse = Matrix.Identity(4)
    if obj.data.type in ("POINT", "SPOT"):
        scale = obj.matrix_world.to_scale()
        inverse = Matrix.Diagonal((*(1.0 / s if s else 1.0 for s in scale), 1.0))
    if face.matrix_parent_inverse != inverse:
        face.matrix_parent_inverse = inverse
    return face


def _delete(face_name):
    face = bpy.data.objects.get(face_name)
    if face is None:
        return
    mesh = face.data
    used = [slot.material for slot in face.material_slots if slot.material is not None]
    bpy.data.objects.remove(face)
    if mesh is not None and mesh.users == 0:
        bpy.data.meshes.remove(mesh)
    for material in used:
        if material.users == 0:
            bpy.data.materials.remove(material)


def drawable(obj: Object, snap: Snapshot) -> tuple[tuple[float, ...], float | None, float] | None:
    """``(rgb, temperature, radiance)`` of the face that draws light object ``obj``, or None."""
    if obj.data.type not in KINDS or not _facing_camera(obj, snap):
        return None
    scale = _radiance_scale(obj, Vector(snap.camera_position))
    emission = _emission(obj.data)
    if scale is None or emission is None:
        return None
    colour, temperature, strength = emission
    return colour, temperature, scale * strength


def write(scene: Scene, snap: Snapshot) -> None:
    """Faces for the lamps seen directly while the exact camera renders (none otherwise). During a
    spectral pass the lamps' colours are spectral values: the faces keep the user's colours."""
    if materials.spectral_pass_wavelengths() is not None:
        return
    wanted = {}
    if snap.exact_camera:
        for obj in _candidates(scene, snap):
            face = drawable(obj, snap)
            if face is not None:
                wanted[obj.name] = face
    record = dict(scene.get(names.LAMP_FACES_KEY, {}))
    for light_name in [name for name in record if name not in wanted]:
        _delete(record.pop(light_name))
        scene[names.LAMP_FACES_KEY] = record
        obj = bpy.data.objects.get(light_name)
        if obj is not None:
            visibility.restore(obj, names.LAMP_FACE_SAVED_KEY)
    for light_name, (colour, temperature, strength) in wanted.items():
        obj = scene.objects[light_name]
        visibility.hide(obj, names.LAMP_FACE_SAVED_KEY, ("visible_camera",))
        face = _face(scene, obj, snap)
        if not face.material_slots or face.material_slots[0].material is None:
            face.data.materials.append(_material(face.name, colour, temperature, strength))
            materials.attach(face.material_slots[0].material)
        else:
            _write_material(face.material_slots[0].material, colour, temperature, strength)
    if not record and not wanted and names.LAMP_FACES_KEY in scene:
        del scene[names.LAMP_FACES_KEY]


def remove(scene: Scene) -> None:
    """Delete the faces and give the lamps back their camera visibility."""
    for face_name in dict(scene.get(names.LAMP_FACES_KEY, {})).values():
        _delete(face_name)
    if names.LAMP_FACES_KEY in scene:
        del scene[names.LAMP_FACES_KEY]
    for obj in bpy.data.objects:
        if obj.type == "LIGHT":
            visibility.restore(obj, names.LAMP_FACE_SAVED_KEY)


def _has_extent(light):
    """Whether Cycles draws the lamp for camera rays at all (a point, spot or sun without a size
    is a delta light, invisible)."""
    if light.type == "SUN":
        return light.angle > 1e-6
    return light.type == "AREA" or light.shadow_soft_size > 0.0


def warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """Lamps seen directly whose colour the exact camera shifts as the pixel behind them."""
    if not snap.exact_camera:
        return []
    record = scene.get(names.LAMP_FACES_KEY, {})
    return [
        f"Light {obj.name!r} is seen directly but not drawn as an emitter: its colour is shifted "
        "with what lies behind it (docs/moving-lights.md)"
        for obj in _candidates(scene, snap)
        if obj.name not in record
        and _has_extent(obj.data)
        and _facing_camera(obj, snap)
        and (obj.data.type != "SPOT" or _spot_mask(obj, Vector(snap.camera_position)) > 0.0)
    ]
