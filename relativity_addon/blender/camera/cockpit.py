"""Objects moving with the camera (Gray et al. 2020, appendix A): a cockpit, a window frame, a
visor, a HUD, rendered as at rest in front of a camera at rest and laid over the relativistic render.

Gray et al. trace a ray through the camera-frame objects first and Lorentz-transform it only when
it leaves them. A Cycles camera shader makes one ray and cannot trace, and Cycles has no ray
visibility for "camera rays not yet transformed", so the two parts are rendered apart in one F12:

- the scene ``"Relativity Cockpit <scene>"`` holds a copy of each object moving with the camera
  (sharing its mesh, light and materials, parented as the original, so it follows the camera's
  animation) and a camera at rest on the user's camera (a child of it, a copy of its lens with the
  type it had before the OSL camera), with a transparent film and no world: Blender's render of
  the camera-frame scene at rest;
- the originals are hidden from the relativistic render (``hide_render``; a light among them is
  drawn there by the moving-light stage with the camera's velocity, ``snapshot.moving_lights``);
- the compositor lays the cockpit's render (its Render Layers node, which makes Blender render that
  scene as part of the frame) over the relativistic one with Alpha Over, after every other node:
  the cockpit occludes exactly where it does at rest, and the scene is seen through its open or
  transparent parts unchanged.

What is approximated (docs/cockpit.md): the cockpit is lit by the lights moving with the camera,
its own emission, the sky as the moving camera sees it (``colour/cockpit_sky.py`` gives this scene
its world) and the scene's lamps at rest (``lights/cockpit_lamps.py``, one ``D`` per lamp); moving
lamps and the light bounced off the scene do not reach it, it casts no shadow on the scene and the
two do not see each other in reflections. Remove deletes the scene,
the copies and the nodes and gives back the user's ``hide_render`` and compositor exactly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..common import compat, names
from ..scene import snapshot as snapshot_reader
from . import exact_camera

if TYPE_CHECKING:
    from bpy.types import Object, Scene

    from ..scene.snapshot import Snapshot

KEY = names.COCKPIT_KEY
HIDDEN_KEY = names.COCKPIT_HIDDEN_KEY
COPY_KEY = names.COCKPIT_COPY_KEY
LAYERS_NODE = f"{names.COCKPIT_PREFIX} Render Layers"
OVER_NODE = f"{names.COCKPIT_PREFIX} Alpha Over"
# the scene's render settings the cockpit's render shares (Cycles' are all copied but these)
RENDER_SETTINGS = (
    "resolution_x",
    "resolution_y",
    "resolution_percentage",
    "pixel_aspect_x",
    "pixel_aspect_y",
    "use_border",
    "border_min_x",
    "border_max_x",
    "border_min_y",
    "border_max_y",
    "fps",
    "fps_base",
    "use_multiview",  # a stereo pair: the cockpit is rendered for each eye, and each view composited
    "views_format",
)
# the OSL camera's settings stay the user's (the exact camera's text must not gain a user here)
CAMERA_SKIPPED = ("name", "type", "custom_mode", "custom_shader", "custom_filepath", "custom_bytecode")
CYCLES_SKIPPED = ("shading_system", "sample_clamp_direct", "sample_clamp_indirect", "film_transparent_glass")
# ID properties the add-on keeps on objects and camera data (not to be carried onto a copy)
ADDON_KEYS = (
    HIDDEN_KEY,
    names.LIGHT_SAVED_KEY,
    names.EMITTER_SAVED_KEY,
    names.LAMP_FACE_SAVED_KEY,
    names.CAMERA_SAVED_STATE_KEY,
)


def is_applied(scene: Scene) -> bool:
    return KEY in scene


def cockpit_scene(scene: Scene) -> Scene | None:
    """The scene that renders ``scene``'s camera-frame objects at rest, or None."""
    return bpy.data.scenes.get(scene[KEY]["scene"]) if is_applied(scene) else None


def _copy_values(source, target, names_, skip=()):
    """Set ``target``'s simple properties ``names_`` (all of them when None) to ``source``'s, only
    where they differ."""
    for prop in source.bl_rna.properties:
        key = prop.identifier
        if prop.is_readonly or key in skip or (names_ is not None and key not in names_):
            continue
        if prop.type not in ("BOOLEAN", "INT", "FLOAT", "ENUM", "STRING", "POINTER") or key == "rna_type":
            continue
        value = getattr(source, key)
        if prop.type in ("BOOLEAN", "INT", "FLOAT") and getattr(prop, "is_array", False):
            same = tuple(getattr(target, key)) == tuple(value)
        else:
            same = getattr(target, key) == value
        if not same:
            try:
                setattr(target, key, value)
            except (AttributeError, TypeError, ValueError):
                pass  # a value this Blender refuses here (a read-only or context-bound setting)


def _rest_type(camera_data):
    """The camera's type before the exact camera made it a custom (OSL) camera."""
    if exact_camera.is_applied(camera_data):
        return camera_data[names.CAMERA_SAVED_STATE_KEY]["type"]
    return camera_data.type


def _write_camera(rest_camera, camera):
    data = rest_camera.data
    _copy_values(camera.data, data, None, skip=CAMERA_SKIPPED)
    _copy_values(camera.data.dof, data.dof, None)
    _copy_values(camera.data.stereo, data.stereo, None)  # the eyes (Blender's stereo pair)
    rest_type = _rest_type(camera.data)
    if data.type != rest_type:
        data.type = rest_type
    if rest_camera.parent != camera:
        rest_camera.parent = camera
    identity = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    for matrix in ("matrix_parent_inverse", "matrix_basis"):
        if tuple(map(tuple, getattr(rest_camera, matrix))) != identity:
            setattr(rest_camera, matrix, identity)


def _write_render(scene, cockpit):
    _copy_values(scene.render, cockpit.render, RENDER_SETTINGS)
    _copy_values(scene.cycles, cockpit.cycles, None, skip=CYCLES_SKIPPED)
    for view in scene.render.views:  # Stereo 3D's left and right (every scene has them)
        rest_view = cockpit.render.views.get(view.name)
        if rest_view is not None and rest_view.use != view.use:
            rest_view.use = view.use
    clamps = scene.get(names.CLAMP_SAVED_KEY)  # the user's clamps, not the searchlight's (clamping.py)
    for name in ("sample_clamp_direct", "sample_clamp_indirect"):
        value = clamps[name] if clamps is not None and name in clamps else getattr(scene.cycles, name)
        if getattr(cockpit.cycles, name) != value:
            setattr(cockpit.cycles, name, value)
    for name, value in (("engine", "CYCLES"), ("film_transparent", True), ("use_compositing", False)):
        if getattr(cockpit.render, name) != value:
            setattr(cockpit.render, name, value)
    for name in ("frame_current", "frame_subframe"):  # no frame_set: a handler must not evaluate
        if getattr(cockpit, name) != getattr(scene, name):
            setattr(cockpit, name, getattr(scene, name))


def _user_hidden(obj):
    """The user's ``hide_render`` (kept by this stage or the moving-light stage while they hide it)."""
    saved = obj.get(HIDDEN_KEY)
    if saved is not None:
        return bool(saved)
    return snapshot_reader.light_render_hidden(obj)


def _new_copy(original, cockpit):
    copy = original.copy()
    for key in ADDON_KEYS:
        if key in copy:
            del copy[key]
    copy[COPY_KEY] = original.name
    for modifier in [m for m in getattr(copy, "modifiers", ()) if m.name == names.GEOMETRY_MODIFIER]:
        copy.modifiers.remove(modifier)
    cockpit.collection.objects.link(copy)
    return copy


def _write_copy(copy, original):
    if copy.data != original.data:
        copy.data = original.data
    for name in ("parent", "parent_type", "parent_bone"):
        if getattr(copy, name) != getattr(original, name):
            setattr(copy, name, getattr(original, name))
    for name in ("matrix_parent_inverse", "matrix_basis"):
        if getattr(copy, name) != getattr(original, name):
            setattr(copy, name, getattr(original, name).copy())
    hidden = _user_hidden(original)
    if copy.hide_render != hidden:
        copy.hide_render = hidden


def _hide(obj):
    if HIDDEN_KEY not in obj:
        obj[HIDDEN_KEY] = bool(obj.hide_render)
    if not obj.hide_render:
        obj.hide_render = True


def _restore(obj):
    saved = obj.get(HIDDEN_KEY)
    if saved is None:
        return
    del obj[HIDDEN_KEY]
    if obj.hide_render != bool(saved):
        obj.hide_render = bool(saved)


def _write_objects(scene, cockpit, snap):
    wanted = {name: scene.objects[name] for name in snap.cockpit if name in scene.objects}
    copies = {obj[COPY_KEY]: obj for obj in list(cockpit.collection.objects) if COPY_KEY in obj}
    for name, copy in copies.items():
        if name not in wanted or copy.type != wanted[name].type:
            bpy.data.objects.remove(copy)
    for name, original in wanted.items():
        if name not in copies or copies[name].type != original.type:
            _new_copy(original, cockpit)
        if original.type != "LIGHT":  # a light: drawn by the moving-light stage (or at rest, Blender's)
            _hide(original)
    for obj in scene.objects:
        if HIDDEN_KEY in obj and obj.name not in wanted:
            _restore(obj)


def _compose(scene, cockpit):
    """Alpha Over the cockpit's render onto whatever feeds the compositor's output (again after a
    stage that rewired it)."""
    record = scene[KEY]
    tree = compat.compositor_tree(scene)
    if tree is None:
        tree = compat.new_compositor_tree(scene, names.COMPOSITOR_SCENE_TREE)
        record["created_tree"] = tree.name
    output = compat.compositor_output(tree)
    if output is None:
        return
    layers, over = tree.nodes.get(LAYERS_NODE), tree.nodes.get(OVER_NODE)
    if layers is None:
        layers = tree.nodes.new("CompositorNodeRLayers")
        layers.name = layers.label = LAYERS_NODE
        layers.location = (output.location.x - 400.0, output.location.y - 300.0)
    if layers.scene != cockpit:
        layers.scene = cockpit
    if layers.layer != cockpit.view_layers[0].name:
        layers.layer = cockpit.view_layers[0].name
    if over is None:
        over = tree.nodes.new("CompositorNodeAlphaOver")
        over.name = over.label = OVER_NODE
        over.location = (output.location.x - 200.0, output.location.y)
    background, foreground = compat.alpha_over_inputs(over)
    if not foreground.is_linked:
        tree.links.new(layers.outputs["Image"], foreground)
    result = output.inputs[0]
    if result.is_linked and result.links[0].from_node == over:
        return
    if result.is_linked:
        tree.links.new(result.links[0].from_socket, background)
    tree.links.new(over.outputs[0], result)


def write(scene: Scene, snap: Snapshot, structural: bool = True) -> None:
    """Bring the cockpit scene, the copies, the hidden originals and the compositor up to date with
    the snapshot; with no object moving with the camera, remove everything. ``structural=False``
    (a depsgraph handler's sync) adds and removes nothing: a scene made while Blender evaluates
    one crashes the evaluation's caller (a ``ray_cast`` on it, measured on 5.2)."""
    if not structural:
        if cockpit_scene(scene) is not None and snap.cockpit:
            _write_values(scene, snap)
        return
    if not snap.cockpit:
        remove(scene)
        return
    if not is_applied(scene):
        scene[KEY] = {
            "scene": "",
            "created_tree": "",
            "use_compositing": bool(scene.render.use_compositing),
            "first": names.COMPOSITOR_SAVED_KEY not in scene,  # before the colour stage's compositor
        }
    cockpit = cockpit_scene(scene)
    camera = bpy.data.objects.get(snap.camera)
    if cockpit is None:
        cockpit = bpy.data.scenes.new(f"{names.COCKPIT_PREFIX} {scene.name}")
        cockpit.world = None
        data = camera.data.copy()
        for key in ADDON_KEYS:
            if key in data:
                del data[key]
        if data.custom_shader is not None and data.custom_shader.name == names.SHADER_TEXT:
            data.custom_shader = None
        rest_camera = bpy.data.objects.new(f"{names.COCKPIT_PREFIX} Camera {scene.name}", data)
        cockpit.collection.objects.link(rest_camera)
        cockpit.camera = rest_camera
        scene[KEY]["scene"] = cockpit.name
    _write_objects(scene, cockpit, snap)
    _compose(scene, cockpit)
    if not scene.render.use_compositing:
        scene.render.use_compositing = True
    _write_values(scene, snap)


def _write_values(scene, snap):
    """The settings of what exists: the camera at rest, the render settings, the copies."""
    cockpit = cockpit_scene(scene)
    camera = bpy.data.objects.get(snap.camera)
    if camera is not None and camera.type == "CAMERA":
        _write_camera(cockpit.camera, camera)
    _write_render(scene, cockpit)
    for copy in copies(scene):
        original = scene.objects.get(copy[COPY_KEY])
        if original is not None and original.type == copy.type:
            _write_copy(copy, original)


def apply(scene: Scene, snap: Snapshot) -> None:
    write(scene, snap)


def _uncompose(scene, record):
    tree = compat.compositor_tree(scene)
    if tree is not None:
        over = tree.nodes.get(OVER_NODE)
        output = compat.compositor_output(tree)
        if over is not None:
            background = compat.alpha_over_inputs(over)[0]
            source = background.links[0].from_socket if background.is_linked else None
            fed = output is not None and output.inputs[0].is_linked and output.inputs[0].links[0].from_node == over
            tree.nodes.remove(over)
            if fed and source is not None:
                tree.links.new(source, output.inputs[0])
        layers = tree.nodes.get(LAYERS_NODE)
        if layers is not None:
            tree.nodes.remove(layers)
    colour = scene.get(names.COMPOSITOR_SAVED_KEY)
    if record.get("first") and colour is not None:
        # the colour stage came after this one (a sync before it) and took this compositor for the
        # user's: it gives back what this stage found when it goes
        if record.get("created_tree"):
            colour["tree"], colour["created_tree"] = "", record["created_tree"]
        colour["use_compositing"] = bool(record["use_compositing"])
        return
    if record.get("created_tree"):
        compat.restore_compositor_tree(scene, "")
        created = bpy.data.node_groups.get(record["created_tree"])
        if created is not None and created.users == 0:
            bpy.data.node_groups.remove(created)
    if scene.render.use_compositing != bool(record["use_compositing"]):
        scene.render.use_compositing = bool(record["use_compositing"])


def remove(scene: Scene) -> None:
    """Give back everything :func:`write` added or changed; safe when nothing was applied."""
    for obj in bpy.data.objects:
        if HIDDEN_KEY in obj:
            _restore(obj)
    if not is_applied(scene):
        return
    record = scene[KEY].to_dict()
    _uncompose(scene, record)
    cockpit = bpy.data.scenes.get(record["scene"]) if record["scene"] else None
    if cockpit is not None:
        rest_camera = cockpit.camera
        for obj in list(cockpit.collection.objects):
            if COPY_KEY in obj:
                bpy.data.objects.remove(obj)
        if rest_camera is not None:
            data = rest_camera.data
            bpy.data.objects.remove(rest_camera)
            if data.users == 0:
                bpy.data.cameras.remove(data)
        bpy.data.scenes.remove(cockpit)
    del scene[KEY]


def copies(scene: Scene) -> list[Object]:
    cockpit = cockpit_scene(scene)
    return [obj for obj in cockpit.collection.objects if COPY_KEY in obj] if cockpit is not None else []


def warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """What the cockpit leaves out, one line each."""
    if not snap.cockpit:
        return []
    found = [
        f"Objects moving with the camera ({len(snap.cockpit)}): lit by the sky and the lamps at rest (one D per "
        "lamp); moving lamps, light and shadows from the scene's objects and reflections are left out (docs/cockpit.md)"
    ]
    if snap.stereo and scene.render.views_format != "STEREO_3D":
        found.append("Objects moving with the camera: a Multi-View render's own views are not rendered at rest")
    return found
