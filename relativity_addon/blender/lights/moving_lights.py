"""Moving lights: lights with a velocity light each surface from their
retarded position, with eq. 19's ``D^4`` beaming and shadows (docs/moving-lights.md).

Cycles' own lights cannot move during the light's flight, so a moving light is drawn by the
surfaces instead: every material of the scene gets the group ``Relativity Moving Lights``
(one OSL script node per moving light, ``shaders/relativistic_moving_light.osl``) added to its
surface shader, which computes the retarded light position in closed form, traces a shadow ray
toward it and emits the surface's diffuse reflection of that light. The Blender light itself is
hidden from renders while the effect is applied. Every change is recorded (the user's
``hide_render`` on the light, the scene's Open Shading Language setting, each material's old
surface link) and :func:`remove` restores it exactly.

This is the Apparent Geometry path's renderer and the stage's entry point. Behind the exact camera
(an OSL camera) a material's ``trace()`` crashes Cycles (measured on 4.5 and 5.2: the camera shader
clears the thread's trace data), so there :func:`write` hands the lights to ``moving_lamps.py``
(stand-in lamps whose shadows Cycles traces; :func:`uses_lamps`). What is covered:
docs/moving-lights.md. Here: point and spot lights with CONSTANT motion, surfaces at rest in the
scene frame, diffuse reflection (the albedo is the Base Color / Color of the first Principled or
Diffuse BSDF feeding the output), one shadow ray to a point source.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING, Any

import bpy
import numpy as np

from ...errors import RelativityError
from ...physics import spectral_render
from ..camera import exact_camera
from ..colour import materials
from ..common import busy, names, osl
from ..common.nodes import detach_inserted, linked_surface
from ..scene import emitting_meshes, sources
from . import lamp_trees, stand_in_lamps

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt
    from bpy.types import Depsgraph, Material, NodeTree, Scene

    from ..scene.snapshot import MovingLight, Snapshot

SHADER_PATH = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "shaders", names.MOVING_LIGHT_SHADER_TEXT)
GROUP = names.MOVING_LIGHTS_GROUP
MATERIAL_KEY = names.MOVING_LIGHTS_MATERIAL_KEY
NODE_PREFIX = names.MOVING_LIGHT_NODE_PREFIX
SUPPORTED_KINDS = {"POINT": 0, "SPOT": 1}  # by the material shader
LAMP_KINDS = {"POINT", "SPOT", "SUN", "AREA"}  # by stand-in lamps (moving_lamps.py)
ALBEDO_INPUTS = {"ShaderNodeBsdfPrincipled": "Base Color", "ShaderNodeBsdfDiffuse": "Color"}


def supported(snap: Snapshot) -> list[MovingLight]:
    """The snapshot's moving lights this stage renders: point and spot lights with constant
    velocity, and every kind, constant or keyframed (ANIMATION), where stand-in lamps draw them
    (:func:`uses_lamps`; a keyframed sun moves with its keyframes' velocity at the frame). None
    in a Blender build without OSL: both ways are OSL shaders."""
    if osl.unavailable_reason() is not None:
        return []
    if uses_lamps(snap):
        return [light for light in snap.moving_lights if light.kind in LAMP_KINDS]
    return [light for light in snap.moving_lights if light.kind in SUPPORTED_KINDS and light.motion == "CONSTANT"]


def is_applied(scene: Scene) -> bool:
    return names.SHADING_SYSTEM_SAVED_KEY in scene


# --- the shader and its group ---------------------------------------------------------------


def _shader_text():
    with open(SHADER_PATH, encoding="utf-8") as handle:
        source = handle.read()
    text = bpy.data.texts.get(names.MOVING_LIGHT_SHADER_TEXT)
    if text is None:
        text = bpy.data.texts.new(names.MOVING_LIGHT_SHADER_TEXT)
    if text.as_string().rstrip("\n") != source.rstrip("\n"):
        text.clear()
        text.write(source)
    return text


def _new_group():
    group = bpy.data.node_groups.new(GROUP, "ShaderNodeTree")
    group.interface.new_socket("Albedo", in_out="INPUT", socket_type="NodeSocketColor").default_value = (
        0.8,
        0.8,
        0.8,
        1.0,
    )
    group.interface.new_socket("Emission", in_out="OUTPUT", socket_type="NodeSocketShader")
    return group


def ensure_group(light_names: Sequence[str]) -> NodeTree:
    """The group with one compiled script node per light (rebuilt inside when the lights change;
    its interface never changes, so the materials' links survive)."""
    group = bpy.data.node_groups.get(GROUP) or _new_group()
    if list(group.get(names.MOVING_LIGHTS_LIGHTS_KEY, [])) == list(light_names) and len(group.nodes):
        return group
    group.nodes.clear()
    inputs = group.nodes.new("NodeGroupInput")
    output = group.nodes.new("NodeGroupOutput")
    text = _shader_text()
    previous = None
    for index, name in enumerate(light_names):
        node = group.nodes.new("ShaderNodeScript")
        node.name = node.label = f"light {name}"
        node.mode = "INTERNAL"
        with osl.compiling():
            node.script = text  # compiles (oslquery must be importable) and creates the sockets
        node.location = (200.0, -200.0 * index)
        if "Emission" not in node.outputs or "light_position" not in node.inputs:
            raise RelativityError("The moving-light OSL shader did not compile (no sockets on its script node)")
        group.links.new(inputs.outputs["Albedo"], node.inputs["Albedo"])
        if previous is None:
            previous = node.outputs["Emission"]
        else:
            add = group.nodes.new("ShaderNodeAddShader")
            add.location = (400.0, -200.0 * index)
            group.links.new(previous, add.inputs[0])
            group.links.new(node.outputs["Emission"], add.inputs[1])
            previous = add.outputs[0]
    if previous is not None:
        group.links.new(previous, output.inputs["Emission"])
    group[names.MOVING_LIGHTS_LIGHTS_KEY] = list(light_names)
    return group


def reception_event(snap: Snapshot) -> tuple[float, tuple[float, ...]]:
    """``(c (t - t_o), x)``, the event where the camera receives the light, in the scene frame
    (``Snapshot.mesh_observer``: the exact camera's aperture centre at its shutter time; the
    boosted-mesh preview's ``(t_o, x_cam)``)."""
    t, x, _ = snap.mesh_observer
    return snap.speed_of_light * (t - snap.time), tuple(float(v) for v in x)


def spot_cone(spot_size: float, spot_blend: float) -> tuple[float, float]:
    """Cycles' spot cone: ``(cos of the half angle, 1 / width of the blend in cos)``; the mask is
    ``smoothstep(0, 1, (cos - cos_half) * smooth)`` (no blend: smooth 0, a hard edge)."""
    cos_half = math.cos(min(spot_size, math.pi) * 0.5)
    smooth = 1.0 / ((1.0 - cos_half) * spot_blend) if spot_blend > 0.0 and cos_half < 1.0 else 0.0
    return cos_half, smooth


def shader_parameters(light: MovingLight, snap: Snapshot) -> dict[str, Any]:
    """The script node's inputs for one light (world axes; intensity in W/sr per channel): the
    light's position at the reception event's time and that event's position."""
    cos_half, smooth = spot_cone(light.spot_size, light.spot_blend)
    ct, camera_position = reception_event(snap)
    intensity = tuple(4.0 * v for v in light.intensity) if light.kind == "AREA" else light.intensity
    return {
        **blackbody_parameters(light.temperature, float(spectral_render.luminance(intensity))),
        **rgb_spectral_parameters(light.temperature, intensity),
        "light_position": tuple(p + b * ct for p, b in zip(light.position, light.beta, strict=True)),
        "light_beta": light.beta,
        "camera_position": camera_position,
        # an area light's centre: a Lambertian emitter of power P has I = P / pi along its axis
        "intensity": intensity,
        "lambert": light.kind == "AREA",
        "light_type": SUPPORTED_KINDS.get(light.kind, 0),
        "spot_axis": light.axis,
        "spot_cos_half_angle": cos_half if light.kind == "SPOT" else -1.0,
        "spot_smooth": smooth,
        "use_shadows": not snap.exact_camera,
    }


def blackbody_parameters(temperature: float, luminance: float) -> dict[str, Any]:
    """The stand-in lamp shader's blackbody inputs (eq. 18's spectrum, docs/moving-lights.md): the
    light's temperature and luminance, and in a spectral pass its wavelengths and the scale of
    ``planck_shape``: ``luminance B(mu, T') / Y_B(T)`` per nm with ``B = C1 / pi (500 nm)^-5
    planck_shape``, as ``physics.spectral_render.blackbody_samples`` normalises lamps at rest."""
    wavelengths = materials.spectral_pass_wavelengths()
    scale = 0.0
    if temperature > 0.0:
        constant = spectral_render.PLANCK_C1 / math.pi * (500e-9) ** -5 * 1e-9  # per nm
        scale = luminance * constant * math.exp(-float(spectral_render.log_blackbody_luminance(temperature)))
    return {
        "temperature": float(temperature),
        "light_luminance": float(luminance),  # not "luminance": OSL has a luminance()
        "spectral": wavelengths is not None and temperature > 0.0,
        **{
            f"wavelength_{index}": float(value)
            for index, value in enumerate(wavelengths if wavelengths is not None else (500.0, 550.0, 600.0))
        },
        "spectral_scale": scale,
    }


def rgb_spectral_parameters(temperature: float, intensity: npt.ArrayLike) -> dict[str, Any]:
    """An RGB light's stand-in lamp inputs (eq. 18, docs/moving-lights.md): the basis weights of
    its intensity, ``A(1)^-1 I``, whose up-sampled spectrum the shader shifts by each receiving
    point's ``D`` (the passes give lamps at rest ``emission_matrix(mu) @ I``), and ``spectral`` in
    a spectral pass; in the fast mode the shader takes the shifted spectrum's CIE integral."""
    if temperature > 0.0:
        return {"basis_weights": (0.0, 0.0, 0.0)}
    weights = spectral_render.tables()["inverse_rest_matrix"] @ np.asarray(intensity, dtype=np.float64)
    parameters = {"basis_weights": tuple(float(v) for v in weights)}
    if materials.spectral_pass_wavelengths() is not None:
        parameters["spectral"] = True
    return parameters


def _same(a, b):
    return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-30)  # sockets hold float32


def _set_input(socket, value):
    """Write a socket's default value only when it changed (a write triggers a depsgraph update,
    whose handler syncs again)."""
    current = socket.default_value
    if isinstance(value, tuple):
        value = value + tuple(current)[len(value) :]  # colour sockets carry alpha
        if all(_same(a, b) for a, b in zip(current, value, strict=True)):
            return False
    elif _same(current, value):
        return False
    socket.default_value = value
    return True


def _silence_group(snap):
    """Light nothing and trace nothing from the materials (behind the OSL camera the stand-in lamps
    light the scene, and trace() would crash Cycles)."""
    group = bpy.data.node_groups.get(GROUP)
    if group is None:
        return
    for light in supported(snap):
        node = group.nodes.get(f"light {light.name}")
        if node is not None:
            for key, value in (("intensity", (0.0, 0.0, 0.0)), ("use_shadows", False)):
                if key in node.inputs:
                    _set_input(node.inputs[key], value)


def _write_parameters(group, snap):
    for light in supported(snap):
        node = group.nodes[f"light {light.name}"]
        for key, value in shader_parameters(light, snap).items():
            if key in node.inputs:  # "lambert" is the stand-in lamps' (area lights)
                _set_input(node.inputs[key], value)


# --- materials ------------------------------------------------------------------------------


def _albedo_socket(tree, surface):
    """The colour input of the first Principled or Diffuse BSDF upstream of the surface socket."""
    seen, queue = set(), [surface]
    while queue:
        socket = queue.pop(0)
        for link in socket.links:
            node = link.from_node
            if node.name in seen:
                continue
            seen.add(node.name)
            if node.bl_idname in ALBEDO_INPUTS:
                return node.inputs[ALBEDO_INPUTS[node.bl_idname]]
            queue.extend(node.inputs)
    return None


def _albedo_source(socket):
    """The socket feeding the albedo, looking through the Doppler colour stage's group (the
    rest-frame colour is what the light reflects from), or None for the socket's own value."""
    socket = sources.rest_colour_input(socket)
    return socket.links[0].from_socket if socket is not None and socket.is_linked else None


def attach(material: Material | None, group: NodeTree) -> bool:
    """Add the group's emission to the material's surface: ``surface + moving lights``."""
    if material is None or (found := linked_surface(material, MATERIAL_KEY)) is None:
        return False
    tree, output = found
    albedo = _albedo_socket(tree, output.inputs["Surface"])
    if albedo is None:
        return False
    source = output.inputs["Surface"].links[0].from_socket
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    node.name = node.label = f"{NODE_PREFIX}"
    node.location = (output.location.x - 200.0, output.location.y - 200.0)
    node.hide = True
    add = tree.nodes.new("ShaderNodeAddShader")
    add.name = add.label = f"{NODE_PREFIX} Add"
    add.location = (output.location.x - 100.0, output.location.y - 150.0)
    add.hide = True
    albedo_source = _albedo_source(albedo)
    if albedo_source is not None:
        tree.links.new(albedo_source, node.inputs["Albedo"])
    elif albedo.is_linked:  # through the Doppler group, from its own colour value
        node.inputs["Albedo"].default_value = albedo.links[0].from_node.inputs["Color"].default_value
    else:
        node.inputs["Albedo"].default_value = albedo.default_value
    tree.links.new(source, add.inputs[0])
    tree.links.new(node.outputs["Emission"], add.inputs[1])
    tree.links.new(add.outputs[0], output.inputs["Surface"])
    material[MATERIAL_KEY] = {
        "group_node": node.name,
        "add_node": add.name,
        "output": output.name,
        "source_node": source.node.name,
        "source_socket": source.identifier,
    }
    return True


def detach(material: Material | None) -> bool:
    """Remove the inserted nodes and link the old surface shader to the output again."""
    return detach_inserted(material, MATERIAL_KEY, ("group_node", "add_node"))


def _scene_materials(scene):
    found = {}
    for obj in scene.objects:
        for slot in getattr(obj, "material_slots", ()):
            if slot.material is not None:
                found[slot.material.name] = slot.material
    return list(found.values())


# --- lights and the scene -------------------------------------------------------------------


def _hide_light(obj):
    if obj.type == "MESH":  # an emitter lighting the scene: its own light reaches the camera only
        emitting_meshes.hide_from_light_rays(obj)
        return
    if names.LIGHT_SAVED_KEY not in obj:
        obj[names.LIGHT_SAVED_KEY] = {"hide_render": bool(obj.hide_render)}
    if not obj.hide_render:
        obj.hide_render = True


def _restore_light(obj):
    if emitting_meshes.restore(obj):
        return True
    saved = obj.get(names.LIGHT_SAVED_KEY)
    if saved is None:
        return False
    hide = bool(saved["hide_render"])
    del obj[names.LIGHT_SAVED_KEY]
    if obj.hide_render != hide:
        obj.hide_render = hide
    return True


def _enable_osl(scene):
    if names.SHADING_SYSTEM_SAVED_KEY not in scene:
        scene[names.SHADING_SYSTEM_SAVED_KEY] = bool(scene.cycles.shading_system)
    if not scene.cycles.shading_system:
        scene.cycles.shading_system = True


def uses_lamps(snap: Snapshot) -> bool:
    """Whether the moving lights are drawn by stand-in lamps (``moving_lamps.py``, with shadows
    behind Cycles' OSL camera) rather than by the material shader (with traced shadows)."""
    return snap.exact_camera


def write(
    scene: Scene, snap: Snapshot, attach_new_materials: bool = False, depsgraph: Depsgraph | None = None
) -> NodeTree | None:
    """Bring the moving lights up to date with the snapshot: hide the moving lights (and show
    again those no longer moving), rebuild the group when the lights changed, write every light's
    parameters and attach materials (all on the first write, then new ones on request). With no
    moving light left, everything is removed. RelativityError (one line) if OSL is unavailable."""
    lights = supported(snap)
    if not lights:
        if is_applied(scene):
            remove(scene)
        return None
    first = not is_applied(scene) or bpy.data.node_groups.get(GROUP) is None
    try:
        osl.ensure_oslquery_importable()
    except osl.OSLUnavailableError as error:
        raise RelativityError(f"{error}: moving lights need it") from error
    light_names = [light.name for light in lights]
    for obj in scene.objects:
        saved = names.LIGHT_SAVED_KEY in obj or names.EMITTER_SAVED_KEY in obj
        if obj.type in ("LIGHT", "MESH") and saved and obj.name not in light_names:
            _restore_light(obj)
    for name in light_names:
        _hide_light(scene.objects[name])
    _enable_osl(scene)
    if uses_lamps(snap):
        _silence_group(snap)  # the preview's material nodes, during an Apparent Geometry final render
        stand_in_lamps.write(
            scene, snap, lights, lambda light: shader_parameters(light, snap), reception_event(snap)[0], depsgraph
        )
        return None
    # after an Apparent Geometry final render; between a bake's frames they stay for the next one
    (stand_in_lamps.hide if busy.keeps_stand_ins() else stand_in_lamps.remove)(scene)
    group = ensure_group(light_names)
    _write_parameters(group, snap)
    if first or attach_new_materials:
        for material in _scene_materials(scene):
            attach(material, group)
    return group


def apply(scene: Scene, snap: Snapshot) -> NodeTree | None:
    return write(scene, snap, attach_new_materials=True)


def remove(scene: Scene) -> None:
    """Restore everything :func:`write` changed: materials, lights, the scene's shading system;
    delete the group, the stand-in lamps and the shader texts."""
    stand_in_lamps.remove(scene)
    for material in bpy.data.materials:
        detach(material)
    for obj in bpy.data.objects:
        if obj.type in ("LIGHT", "MESH"):
            _restore_light(obj)
    if names.SHADING_SYSTEM_SAVED_KEY in scene:
        saved = bool(scene[names.SHADING_SYSTEM_SAVED_KEY])
        del scene[names.SHADING_SYSTEM_SAVED_KEY]
        if scene.cycles.shading_system != saved:
            scene.cycles.shading_system = saved
    group = bpy.data.node_groups.get(GROUP)
    if group is not None and not any(is_applied(other) for other in bpy.data.scenes):
        bpy.data.node_groups.remove(group)
        text = bpy.data.texts.get(names.MOVING_LIGHT_SHADER_TEXT)
        if text is not None:
            bpy.data.texts.remove(text)


def warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """What the moving-light stage does not render right, one line each."""
    drawn = {light.name for light in supported(snap)}
    no_osl = osl.unavailable_reason()
    why = (
        f"{no_osl[0].lower()}{no_osl[1:]}" if no_osl else "moving {kind} lights with this motion need the exact camera"
    )
    found = [
        f"Light {light.name!r} ({light.kind.lower()}): rendered at rest here ({why.format(kind=light.kind.lower())})"
        for light in snap.moving_lights
        if light.name not in drawn
    ]
    if supported(snap) and snap.method == "GEOMETRY" and snap.speed > 0.0:
        problem = exact_camera.final_render_problem(scene, snap)
        found.append(
            "Moving lights with a moving observer: the viewport preview lights the surfaces where they appear; "
            + ("the final render is exact" if problem is None else f"so does the final render ({problem})")
        )
    if supported(snap) and uses_lamps(snap):
        found.append(
            "Moving lights with the exact camera: stand-in lamps on the light's path, shadows blended "
            "between neighbouring lamps (docs/moving-lights.md)"
        )
    for light in supported(snap):  # rendered without its tree: what of the tree is carried
        obj = scene.objects.get(light.name)
        reason = lamp_trees.problem(obj.data) if obj is not None and obj.type == "LIGHT" else None
        if reason is not None:
            found.append(
                f"Light {light.name!r}: its node tree ({reason}) is left out of the moving light "
                "(it carries the Color, Emission Strength and a Blackbody only)"
            )
    if supported(snap) and scene.render.engine != "CYCLES":
        found.append("Moving lights need Cycles (OSL)")
    return found
