"""Light bounced between moving objects (docs/lamp-doppler.md, "Light bounced between moving objects").

Cycles renders one static snapshot, so light one moving object sends another reaches it with the
wrong geometry and no Doppler factor between the two frames (measured 1.12x the physics at 0.5c
apart, 0.95x approaching). This stage puts the per-ray factor of ``physics/bounce.py`` between each
moving object's surface shader and its material output; on non-camera rays it scales the closure.
Two forms, by the scene's shading system:

- Open Shading Language on (and available): a script node (``shaders/relativistic_bounce.osl``);
  the receiver's velocity from the moving objects' apparent bounding boxes written into the shader's
  text per scene (rewritten and recompiled when they change, every sync), its rest normal traced;
- SVM, Cycles' default, and builds without OSL: a node group per scene (``bounce_nodes.py``), the
  receiver's velocity and rest normal from each moving object's rest box, the values node inputs
  the sync writes.

A receiving point in no moving object's box is taken at rest (``beta_p = 0``). With a moving
observer only in Apparent Geometry's final render through the exact camera, whose meshes are the
scene frame's seen from a camera at rest at ``Snapshot.mesh_observer`` (the node form there:
``trace()`` crashes behind Cycles' OSL camera; not on the boosted-mesh preview). The node form for
at most :data:`MAX_NODE_MOVERS` moving objects (its cost grows with them on every shading point),
beyond which the panel says the bounce is uncorrected; where it corrects the light a moving object
with curved faces receives (its normal from its box), the panel says so. Everything is
recorded (the inserted node and the old link on each material; the text datablock or node group
on the scene) and :func:`remove` deletes exactly that.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING, Any, cast

import bpy
import numpy as np

from ..camera import exact_camera
from ..common import names, osl
from ..common.nodes import build_group, detach_inserted, ensure_group, linked_surface, remove_unused_groups
from ..geometry import modifier
from . import bounce_nodes, lamps_on_moving_objects, unshifted_light

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from bpy.types import Material, Mesh, NodeTree, Object, Scene, Text

    from ..scene.snapshot import Snapshot
    from .lamps_on_moving_objects import Mover

SHADER_PATH = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "shaders", names.BOUNCE_SHADER_TEXT)
MATERIAL_KEY = names.BOUNCE_MATERIAL_KEY
NODE_NAME = names.BOUNCE_NODE_NAME
MARKER = "//@GENERATED@"
MARGIN = 0.05  # the boxes grown by this share of their size on each side: the corners' images bound the image loosely
MEASURED_ERROR = "12 %"  # docs/lamp-doppler.md: the snapshot's bounce 1.121x the physics at 0.5c apart
# The node form runs every moving object's box on every shading point of every moving object's
# material: beyond this many moving objects it is not built (docs/lamp-doppler.md, "Cost", measured
# by benchmarks/bounce_cost.py --movers) and the panel says the bounce is uncorrected.
MAX_NODE_MOVERS = 8
NODE_COST_AT_MAX = "3x"  # the node form's render time over the uncorrected one at MAX_NODE_MOVERS
# docs/lamp-doppler.md, "Receivers at rest": a sphere alone at 0.5c lighting a panel at rest, the
# snapshot's bounce 0.55x receding and 3.58x approaching (the stage is built for two or more movers)
AT_REST_ERROR = "3.6x"
# the node form takes a receiver's rest normal from its box: faces further off its local axes than
# this are curved; docs/lamp-doppler.md, "The receiver's normal off": the bounce 0.69-1.57x of the
# physics in the model where the normal is 45 degrees off
CURVED_DEGREES = 5.0
CURVED_ERROR = "0.69-1.57x"


def _moving_count(scene: Scene) -> int:
    return len(modifier.moving_objects(scene))


def off_axis_faces(mesh: Mesh) -> bool:
    """Whether some face of ``mesh`` (object space) is more than :data:`CURVED_DEGREES` off every
    local axis: the node form's receiver normal, its rest box's nearest face, is not its own there."""
    count = len(mesh.polygons)
    if count == 0:
        return False
    normals = np.empty(count * 3, dtype=np.float32)
    mesh.polygon_normals.foreach_get("vector", normals)
    largest = np.abs(normals.reshape(-1, 3)).max(axis=1)
    return bool(np.any(largest < math.cos(math.radians(CURVED_DEGREES))))


def _with_material(scene: Scene) -> bool:
    """Whether any set-up mesh has a material (the factor goes on materials: none, nothing to build)."""
    return any(slot.material is not None for obj in modifier.applied_objects(scene) for slot in obj.material_slots)


def _lit_at_rest(scene: Scene, moving: Sequence[Object]) -> bool:
    """Whether the scene renders anything at rest (not in ``moving``) that a moving object could light."""
    return any(True for _ in unshifted_light.objects_at_rest(scene, moving))


def _cheap_reason(scene: Scene, snap: Snapshot) -> str | None:
    """The reasons that need no object's position (checked first: a sync pays nothing for them)."""
    if snap.method != "GEOMETRY" or scene.render.engine != "CYCLES":
        return "off the Apparent Geometry path"
    if _moving_count(scene) < 2:
        return "fewer than two moving objects"
    if not _with_material(scene):
        return "no moving object has a material"
    if snap.speed > 0.0 and not snap.exact_camera:
        return "the observer moves"  # the boosted-mesh preview (its meshes are the observer frame's)
    if not _osl_form(scene, snap) and (count := _moving_count(scene)) > MAX_NODE_MOVERS:
        return _over_limit(count, snap.exact_camera)
    return None


def _over_limit(count: int, exact: bool) -> str:
    return (
        f"{count} moving objects, over the node form's {MAX_NODE_MOVERS} (it would render more than "
        f"{NODE_COST_AT_MAX} slower; "
        + ("a moving observer's final render takes the node form)" if exact else "OSL shading corrects it)")
    )


def uses_osl(scene: Scene) -> bool:
    """Whether the scene takes the OSL form (OSL shading on and available) or the node form."""
    return bool(scene.cycles.shading_system) and osl.unavailable_reason() is None


def _osl_form(scene: Scene, snap: Snapshot) -> bool:
    """The OSL form, except behind the exact camera (its ``trace()`` crashes Blender there)."""
    return uses_osl(scene) and not snap.exact_camera


def _camera(snap: Snapshot) -> tuple[float, ...]:
    """Where the snapshot's meshes are seen from, at rest in the scene frame: the camera, or behind
    the exact camera its aperture centre at the shutter time (``Snapshot.mesh_observer``)."""
    return tuple(float(x) for x in snap.mesh_observer[1])


def _reason(scene: Scene, snap: Snapshot, movers: Sequence[Mover] | None = None) -> str | None:
    """Why the bounce between moving objects is left uncorrected (one line), or None."""
    cheap = _cheap_reason(scene, snap)
    if cheap is not None:
        return cheap
    found = lamps_on_moving_objects.movers(scene, snap) if movers is None else movers
    if len(found) < 2:
        return "fewer than two moving objects"
    return None


def _vector(values: Sequence[float]) -> str:
    return ", ".join(f"{float(v):.7g}" for v in values)


def generated(camera: Sequence[float], movers: Sequence[Mover]) -> str:
    """The shader's scene part: the camera's position and one box test per moving object."""
    lines = [f"#define CAMERA point({_vector(camera)})", "", "int receiver_velocity(point R, output vector beta)", "{"]
    lines.append("  float best = 1e30;")
    for mover in movers:
        points = np.array((mover.centre, *mover.corners), dtype=np.float64)
        low, high = points.min(axis=0), points.max(axis=0)
        grow = MARGIN * (high - low).max() + 1e-4
        low, high = low - grow, high + grow
        volume = float(np.prod(high - low))
        lines.append(
            f"  if (inside(R, point({_vector(low)}), point({_vector(high)})) && {volume:.7g} < best) "
            f"{{ best = {volume:.7g}; beta = vector({_vector(mover.beta)}); }}  /* {mover.name} */"
        )
    lines += ["  return best < 1e30;", "}"]
    return "\n".join(lines)


def shader_source(camera: Sequence[float], movers: Sequence[Mover]) -> str:
    with open(SHADER_PATH, encoding="utf-8") as handle:
        return handle.read().replace(MARKER, generated(camera, movers))


def _scene_text(scene: Scene) -> Text | None:
    """The scene's own text datablock (each set-up scene has one: its camera and movers)."""
    name = scene.get(names.BOUNCE_TEXT_KEY)
    return bpy.data.texts.get(name) if isinstance(name, str) else None


def _carries(material: Material, text_name: str, kind: str = "text") -> bool:
    """Whether the material carries the factor of the scene whose text (or, ``kind`` "group",
    node group) is ``text_name``."""
    return MATERIAL_KEY in material and material[MATERIAL_KEY].get(kind) == text_name


def _text(scene: Scene, source: str) -> tuple[Text, bool]:
    """The scene's text datablock holding ``source``, and whether it changed."""
    text = _scene_text(scene)
    if text is None:
        text = bpy.data.texts.new(names.BOUNCE_SHADER_TEXT)
        scene[names.BOUNCE_TEXT_KEY] = text.name
    if text.as_string().rstrip("\n") == source.rstrip("\n"):
        return text, False
    text.clear()
    text.write(source)
    return text, True


def attach(material: Material | None, text: Text) -> bool:
    """Insert the script node between the material's surface shader and its output."""
    if material is None or (found := linked_surface(material, MATERIAL_KEY)) is None:
        return False
    tree, output = found
    source = output.inputs["Surface"].links[0].from_socket
    node = tree.nodes.new("ShaderNodeScript")
    node.name = node.label = NODE_NAME
    node.mode = "INTERNAL"
    with osl.compiling():
        node.script = text  # compiles (oslquery importable: osl.unavailable_reason) and creates the sockets
    node.location = (output.location.x - 150.0, output.location.y - 250.0)
    node.hide = True
    material[MATERIAL_KEY] = {
        "node": node.name,
        "output": output.name,
        "source_node": source.node.name,
        "source_socket": source.identifier,
        "text": text.name,
    }
    if "Out" not in node.outputs or "Surface" not in node.inputs:
        detach(material)
        return False
    beta = tree.nodes.new("ShaderNodeAttribute")
    beta.name = beta.label = f"{NODE_NAME} Velocity"
    beta.attribute_type = "GEOMETRY"
    beta.attribute_name = names.BETA_ATTRIBUTE
    beta.location = (node.location.x - 200.0, node.location.y - 50.0)
    beta.hide = True
    material[MATERIAL_KEY] = {**material[MATERIAL_KEY].to_dict(), "velocity": beta.name}
    tree.links.new(source, node.inputs["Surface"])
    tree.links.new(beta.outputs["Vector"], node.inputs["BetaS"])
    tree.links.new(node.outputs["Out"], output.inputs["Surface"])
    return True


def detach(material: Material | None) -> bool:
    """Remove the inserted nodes and link the old surface shader to the output again."""
    return detach_inserted(material, MATERIAL_KEY, ("node", "velocity"))


def _recompile(materials: Sequence[Material]) -> None:
    from cycles import osl as cycles_osl  # Cycles' own add-on, present where OSL is

    def report(kind: object, message: object) -> None:
        pass  # a failed compile leaves the node's old bytecode; attach checks the sockets

    for material in materials:
        node = material.node_tree.nodes.get(material[MATERIAL_KEY]["node"])
        if node is not None:
            with osl.compiling():
                cycles_osl.update_script_node(node, report)


def _materials(scene: Scene, found: Sequence[Mover]) -> dict[str, Material]:
    materials = {}
    for mover in found:
        for slot in scene.objects[mover.name].material_slots:
            if slot.material is not None:
                materials[slot.material.name] = slot.material
    return materials


def _write_osl(scene: Scene, snap: Snapshot, found: Sequence[Mover]) -> int:
    _remove_group(scene)
    text, changed = _text(scene, shader_source(_camera(snap), found))
    materials = _materials(scene, found)
    for material in bpy.data.materials:  # no longer on one of this scene's moving objects
        if _carries(material, text.name) and material.name not in materials:
            detach(material)
    # (a material another set-up scene's movers carry keeps that scene's lookup)
    attached = [m for m in materials.values() if attach(m, text) or MATERIAL_KEY in m]
    if changed:
        _recompile([m for m in attached if _carries(m, text.name)])
    return len(attached)


def _scene_group(scene: Scene, camera: Sequence[float], found: Sequence[Mover]) -> NodeTree:
    """The scene's node group with one receiver box per moving object, its values written (the
    nodes rebuilt only when the number of moving objects changed)."""
    for spec in (bounce_nodes.receiver_group(), bounce_nodes.factor_group()):
        ensure_group(spec, names.GROUP_VERSION_KEY, names.BOUNCE_GROUPS_VERSION)
    name = scene.get(names.BOUNCE_GROUP_KEY)
    tree = bpy.data.node_groups.get(name) if isinstance(name, str) else None
    if tree is None:
        name = f"{names.BOUNCE_SCENE_GROUP} {scene.name}"
        tree = build_group(bounce_nodes.scene_group_spec(name, len(found)))
        scene[names.BOUNCE_GROUP_KEY] = tree.name
    elif bounce_nodes.receiver_node_name(len(found) - 1) not in tree.nodes or (
        bounce_nodes.receiver_node_name(len(found)) in tree.nodes
    ):
        tree = build_group(bounce_nodes.scene_group_spec(tree.name, len(found)), keep_interface=True)
    eye = tuple(float(x) for x in camera)
    _set_inputs(tree.nodes["factor"], {"Camera": eye})
    _set_inputs(tree.nodes["to_camera"], {1: eye})
    for index, mover in enumerate(found):
        obj = scene.objects[mover.name]
        low, high = lamps_on_moving_objects.rest_box(obj)
        values = bounce_nodes.receiver_values(
            camera, mover.centre, mover.beta, np.array(obj.matrix_world)[:3, :3], low, high, MARGIN
        )
        _set_inputs(tree.nodes[bounce_nodes.receiver_node_name(index)], values)
    return tree


def _set_inputs(node: Any, values: Mapping[Any, float | tuple[float, ...]]) -> None:
    """Write the inputs that changed beyond float32 rounding (a write is a depsgraph update: no loops)."""
    for key, value in values.items():
        socket = node.inputs[key]
        if not np.allclose(np.asarray(socket.default_value, dtype=np.float64), value, rtol=1e-6, atol=1e-9):
            socket.default_value = value


def attach_group(material: Material | None, group: NodeTree) -> bool:
    """Insert the scene's bounce group between the material's surface shader and its output."""
    if material is None or (found := linked_surface(material, MATERIAL_KEY)) is None:
        return False
    tree, output = found
    source = output.inputs["Surface"].links[0].from_socket
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    node.name = node.label = NODE_NAME
    node.location = (output.location.x - 150.0, output.location.y - 250.0)
    node.hide = True
    material[MATERIAL_KEY] = {
        "node": node.name,
        "output": output.name,
        "source_node": source.node.name,
        "source_socket": source.identifier,
        "group": group.name,
    }
    tree.links.new(source, node.inputs["Surface"])
    tree.links.new(node.outputs["Surface"], output.inputs["Surface"])
    return True


def _write_nodes(scene: Scene, snap: Snapshot, found: Sequence[Mover]) -> int:
    _remove_text(scene)
    group = _scene_group(scene, _camera(snap), found)
    materials = _materials(scene, found)
    for material in bpy.data.materials:
        if _carries(material, group.name, "group") and material.name not in materials:
            detach(material)
    return len([m for m in materials.values() if attach_group(m, group) or MATERIAL_KEY in m])


def write(scene: Scene, snap: Snapshot) -> int:
    """Bring the factor up to date: the lookup (camera, boxes, velocities), the moving objects'
    materials, in the form the scene's shading takes (:func:`uses_osl`). Everything removed when
    it does not apply (:func:`_reason`). Returns the number of materials carrying the factor."""
    cheap = _cheap_reason(scene, snap)
    found = lamps_on_moving_objects.movers(scene, snap) if cheap is None else []
    if cheap is not None or _reason(scene, snap, found) is not None:
        remove(scene)
        return 0
    return _write_osl(scene, snap, found) if _osl_form(scene, snap) else _write_nodes(scene, snap, found)


def apply(scene: Scene, snap: Snapshot) -> int:
    return write(scene, snap)


def _remove_text(scene: Scene) -> None:
    text = _scene_text(scene)
    if text is not None:
        for material in bpy.data.materials:
            if _carries(material, text.name):
                detach(material)
        bpy.data.texts.remove(text)
    if names.BOUNCE_TEXT_KEY in scene:
        del scene[names.BOUNCE_TEXT_KEY]


def _remove_group(scene: Scene) -> None:
    name = scene.get(names.BOUNCE_GROUP_KEY)
    if isinstance(name, str):
        for material in bpy.data.materials:
            if _carries(material, name, "group"):
                detach(material)
        tree = bpy.data.node_groups.get(name)
        if tree is not None and tree.users == 0:
            bpy.data.node_groups.remove(tree)
        remove_unused_groups((names.BOUNCE_RECEIVER_GROUP, names.BOUNCE_FACTOR_GROUP))
    if names.BOUNCE_GROUP_KEY in scene:
        del scene[names.BOUNCE_GROUP_KEY]


def remove(scene: Scene) -> None:
    """Detach the node from the materials that carry this scene's factor and delete its text or
    node group; another set-up scene's are left alone."""
    _remove_text(scene)
    _remove_group(scene)


def warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """One line when two moving objects light each other uncorrected for a reason the user can change,
    or when one moving object lights objects at rest uncorrected; where the node form corrects it,
    one line naming the moving meshes with curved faces (their normal is their box's)."""
    if snap.method != "GEOMETRY":
        return []
    reason = _cheap_reason(scene, snap)  # (no positions: the panel is drawn often)
    moving = modifier.moving_objects(scene) if reason == "fewer than two moving objects" else []
    if len(moving) == 1 and _lit_at_rest(scene, moving):
        return [
            f"Light the moving object sends onto objects at rest is not corrected, up to {AT_REST_ERROR} off "
            "at 0.5c (docs/lamp-doppler.md): the correction is built for two or more moving objects"
        ]
    # the final render (through the exact camera) corrects it with the node form; the preview is a preview
    in_final = reason == "the observer moves" and exact_camera.final_render_problem(scene, snap) is None
    if in_final and (count := _moving_count(scene)) > MAX_NODE_MOVERS:
        reason, in_final = _over_limit(count, exact=True), False  # the final render's reason, said now
    if reason is None or in_final:
        return [] if _osl_form(scene, snap) and not in_final else _curved_lines(scene, snap, in_final)
    if reason in ("off the Apparent Geometry path", "fewer than two moving objects", "no moving object has a material"):
        return []
    return [
        f"Light bounced between moving objects is not corrected, up to {MEASURED_ERROR} off at 0.5c "
        f"(docs/lamp-doppler.md): {reason}"
    ]


def _curved_lines(scene: Scene, snap: Snapshot, in_final: bool) -> list[str]:
    """One line naming the moving objects with curved faces, where the node form corrects the light
    they receive from other moving objects with their box's face normals."""
    curved = [
        obj.name
        for obj in modifier.moving_objects(scene)
        if obj.type == "MESH" and off_axis_faces(cast("Mesh", obj.data))
    ]
    if not curved:
        return []
    where = "in the final render" if (in_final or snap.exact_camera) else "on SVM shading (OSL shading traces it)"
    return [
        f"Light other moving objects reflect onto {', '.join(repr(n) for n in sorted(curved))} is approximate "
        f"{where}: faces more than {CURVED_DEGREES:g} degrees off the object's axes take its box's normal, "
        f"{CURVED_ERROR} of the physics where 45 degrees off (docs/lamp-doppler.md)"
    ]
