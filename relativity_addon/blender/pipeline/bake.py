"""Bake for Render Anywhere: what the handlers write per frame, as data Blender plays back by itself.

A set-up file renders its relativistic frames only while the add-on's handlers run (``handlers.py``:
every frame change syncs the camera's shader parameters, the stand-in lamps of moving lights, the
colour factors and, before each render, the world's ``ln D`` image). :func:`bake` steps through a
frame range, lets the sync write each frame as it does before a render, records every animatable
number the add-on's writes reach (ID properties such as the OSL camera's ``cycles_custom``, RNA
properties of objects, cameras, lamps, worlds, materials and scenes, the nodes and node-socket
values of every node tree) and keyframes those that change (LINEAR for floats, CONSTANT for integers and booleans,
one key per frame: exact at every frame). An image whose pixels change (the world's ``ln D``) is
written per frame as OpenEXR files beside the .blend and read back as an image sequence. Then plain
``blender -b baked.blend -a`` renders the same frames with no add-on and with scripts disabled.

Apparent Geometry is baked in its final-render configuration (``effect.bake_for_render_anywhere``
puts it in place first: the exact camera behind it for a moving observer, else the boosted meshes):
at each frame every moving mesh's evaluated geometry is captured, and ``geometry/playback.py``
plays the captured meshes back by frame; the exact camera's parameters are keyframed as above.
Stand-in lamps (of moving lights behind that camera, and lamps' copies on moving meshes) are kept
under their names while the frames are stepped (``busy.keeping_stand_ins``), those a frame does not
use hidden by a keyed ``hide_render``: every frame holds the same datablocks.

What was added is recorded on the scene (``names.BAKE_RECORD_KEY``); :func:`unbake` (from Remove)
takes it out again: the F-curves, the actions it created, the sequence images and their files,
the played-back meshes and the final render's exact camera.
"""

from __future__ import annotations

import contextlib
import functools
import json
import math
import os
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import bpy
import numpy as np

from ...errors import RelativityError
from ..camera import exact_camera
from ..colour import doppler_colour
from ..common import busy, compat, names, osl
from ..geometry import playback

if TYPE_CHECKING:
    from collections.abc import Sequence

    from bpy.types import Object, Scene

COLLECTIONS = ("objects", "cameras", "lights", "materials", "worlds", "node_groups", "scenes")
_EMBEDDED = ("node_tree",)  # a material's, world's or light's tree (and 4.5's scene compositor)
_NUMERIC = {"FLOAT", "INT", "BOOLEAN"}
Key = tuple[str, str, str, str, int]  # (collection, ID name, embedded tree or "", data path, index)


def refusal(scene: Scene, method: str, exact_final_render: bool = True) -> str | None:
    """Why ``scene`` (set up with ``method``; on Apparent Geometry, ``exact_final_render``: its final
    render is the exact camera) cannot be baked here (one line), or None. What is baked must render
    where it is baked: an OSL camera or OSL material nodes (moving lights on Apparent Geometry) need
    a Blender with OSL."""
    if scene.camera is None:
        return "Cannot bake: the scene has no active camera"
    reason = osl.unavailable_reason()
    if reason is None:
        return None
    reason = f"{reason[0].lower()}{reason[1:]}"
    if method == "CAMERA" or exact_final_render:
        return f"Cannot bake the exact camera: it is an OSL shader and {reason}"
    if scene.cycles.shading_system:
        return f"Cannot bake: the moving lights are OSL script nodes in the materials and {reason}"
    return None


# --- recording ----------------------------------------------------------------------------------


def _owners():
    """(collection, ID name, embedded attribute or "", the datablock that holds the F-curves)."""
    data = bpy.data
    for collection in COLLECTIONS:
        for block in getattr(data, collection):
            if block.library is not None:
                continue
            yield collection, block.name, "", block
            for attribute in _EMBEDDED:
                tree = getattr(block, attribute, None) if collection != "node_groups" else None
                if tree is not None:
                    yield collection, block.name, attribute, tree
            if collection == "scenes":
                tree = compat.compositor_tree(block)
                if tree is not None and tree.is_embedded_data:
                    yield collection, block.name, "node_tree", tree


def _value(value):
    if isinstance(value, (bool, int, float)):
        return value
    try:
        return tuple(float(v) for v in value)
    except (TypeError, ValueError):
        return None


def _id_properties(owner, prefix, out):
    try:
        keys = compat.custom_property_keys(owner) if prefix == "" else list(owner.keys())
    except TypeError:
        return
    for key in keys:
        value = owner[key]
        path = f'{prefix}["{key}"]'
        if hasattr(value, "keys"):
            _id_properties(value, path, out)
            continue
        if hasattr(value, "to_list"):
            value = value.to_list()
        value = _value(value)
        if value is not None:
            out[path] = value


def _rna_properties(struct, prefix, out):
    for prop in struct.bl_rna.properties:
        if prop.type not in _NUMERIC or prop.is_readonly or not prop.is_animatable:
            continue
        value = _value(getattr(struct, prop.identifier))
        if value is not None:
            out[prefix + prop.identifier] = value


def _sockets(tree, out):
    for node in tree.nodes:
        _rna_properties(node, f'nodes["{node.name}"].', out)  # a node muted per frame, say
        for kind, sockets in (("inputs", node.inputs), ("outputs", node.outputs)):
            for index, socket in enumerate(sockets):
                if socket.bl_rna.properties.get("default_value") is None:
                    continue
                value = _value(socket.default_value)
                if value is not None:
                    out[f'nodes["{node.name}"].{kind}[{index}].default_value'] = value


def _state(block, embedded):
    out = {}
    _rna_properties(block, "", out)
    _id_properties(block, "", out)
    if embedded or isinstance(block, bpy.types.NodeTree):
        _sockets(block, out)
    if isinstance(block, bpy.types.Scene):
        _rna_properties(block.cycles, "cycles.", out)
    if isinstance(block, bpy.types.Camera):
        _id_properties(block.cycles_custom, "cycles_custom", out)  # the OSL camera's parameters
    for name in ("frame_current", "frame_float", "frame_subframe"):
        out.pop(name, None)
    return out


def record_frame() -> dict[Key, Any]:
    """Every animatable number of the file's local datablocks, by (owner, data path, index)."""
    values = {}
    for collection, name, embedded, block in _owners():
        with warnings.catch_warnings():  # 5.x: reading use_nodes and the like warns (deprecated)
            warnings.simplefilter("ignore", DeprecationWarning)
            state = _state(block, embedded)
        for path, value in state.items():
            if isinstance(value, tuple):
                for index, item in enumerate(value):
                    values[collection, name, embedded, path, index] = item
            else:
                values[collection, name, embedded, path, -1] = value
    return values


def _image_pixels(image):
    if image.source not in ("GENERATED", "FILE") or (image.source == "FILE" and not image.packed_file):
        return None
    pixels = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(pixels)
    return pixels


def _add_on_images():
    return [image for image in bpy.data.images if image.name.startswith("Relativity ") and image.library is None]


# --- writing ---------------------------------------------------------------------------------


def _owner(collection, name, embedded):
    block = getattr(bpy.data, collection).get(name)
    if block is None or not embedded:
        return block
    if collection == "scenes":
        return compat.compositor_tree(block)
    return getattr(block, embedded, None)


def _animated_paths(block):
    animation = block.animation_data
    if animation is None:
        return set()
    paths = {(f.data_path, f.array_index) for f in compat.action_fcurves(animation)}
    return paths | {(f.data_path, f.array_index) for f in animation.drivers}


def _keyframe(block, path, index, frames, values, created):
    animation = block.animation_data or block.animation_data_create()
    if animation.action is None:
        action = bpy.data.actions.new(f"{names.BAKE_ACTION_PREFIX} {block.name}")
        animation.action = action
        created.append(action.name)
    fcurve = animation.action.fcurve_ensure_for_datablock(block, path, index=max(index, 0))
    fcurve.keyframe_points.clear()
    fcurve.keyframe_points.add(len(frames))
    co = np.column_stack([np.asarray(frames, np.float32), np.asarray(values, np.float32)])
    fcurve.keyframe_points.foreach_set("co", co.ravel())
    step = not isinstance(values[0], float)
    for point in fcurve.keyframe_points:
        point.interpolation = "CONSTANT" if step else "LINEAR"
    fcurve.update()


def _changed(values):
    first = values[0]
    if isinstance(first, float):
        return any(not math.isclose(v, first, rel_tol=1e-7, abs_tol=1e-9) for v in values[1:])
    return any(v != first for v in values[1:])


def _sequence_folder(scene):
    if not bpy.data.filepath:
        raise RelativityError(
            "Save the file first: the bake writes the per-frame world image beside it (an image sequence)"
        )
    stem = os.path.splitext(os.path.basename(bpy.data.filepath))[0]
    return f"//{stem}{names.BAKE_FOLDER_SUFFIX}"


def _write_sequence(scene, image, frames, pixels):
    """The per-frame pixels of ``image`` as OpenEXR files and an image sequence reading them;
    every Image node that read ``image`` reads the sequence."""
    folder = _sequence_folder(scene)
    absolute = bpy.path.abspath(folder)
    os.makedirs(absolute, exist_ok=True)
    stem = bpy.path.clean_name(image.name)
    width, height = image.size
    scratch = bpy.data.images.new(names.BAKE_SCRATCH_IMAGE, width, height, alpha=True, float_buffer=True)
    scratch.colorspace_settings.is_data = True  # written as computed
    settings = scene.render.image_settings
    media = ("media_type",) if hasattr(settings, "media_type") else ()  # 5.x: image, multilayer or video
    kept = (*media, "file_format", "color_depth", "color_mode")
    saved = [getattr(settings, name) for name in kept]
    files = []
    try:
        # save_render in 32-bit OpenEXR: Image.save writes 8 bits (values clamped to 1) in 5.2
        for name, value in zip(kept, ("IMAGE",) * len(media) + ("OPEN_EXR", "32", "RGBA"), strict=True):
            setattr(settings, name, value)
        for frame, frame_pixels in zip(frames, pixels, strict=True):
            path = os.path.join(absolute, f"{stem}_{frame:04d}.exr")
            scratch.pixels.foreach_set(frame_pixels)
            scratch.save_render(path, scene=scene)
            files.append(path)
    finally:
        for name, value in zip(kept, saved, strict=True):
            setattr(settings, name, value)
        bpy.data.images.remove(scratch)
    sequence = bpy.data.images.load(files[0])
    sequence.name = f"{image.name}{names.BAKE_IMAGE_SUFFIX}"
    sequence.source = "SEQUENCE"
    sequence.filepath = f"{folder}/{stem}_{frames[0]:04d}.exr"
    sequence.colorspace_settings.is_data = image.colorspace_settings.is_data
    fake_user = image.use_fake_user
    image.use_fake_user = True  # no node reads it while baked: kept for Remove and the add-on's own renders
    users = []
    for tree in _all_trees():
        for node in tree.nodes:
            if getattr(node, "image", None) == image:
                node.image = sequence
                user = getattr(node, "image_user", node)
                user.frame_duration = len(frames)
                user.frame_start = frames[0]
                user.frame_offset = frames[0] - 1
                if hasattr(user, "use_auto_refresh"):
                    user.use_auto_refresh = True
                users.append([tree.name, node.name])
    return {"image": image.name, "sequence": sequence.name, "files": files, "nodes": users, "fake_user": fake_user}


def _all_trees():
    yield from bpy.data.node_groups
    for block in (*bpy.data.materials, *bpy.data.worlds, *bpy.data.lights):
        if getattr(block, "node_tree", None) is not None:
            yield block.node_tree
    for scene in bpy.data.scenes:
        tree = compat.compositor_tree(scene)
        if tree is not None and tree.is_embedded_data:
            yield tree


def _step(scene, frames, sync_for_render, meshes, leave_frame):
    """The frames' recorded states and the add-on's images' pixels; the evaluated mesh of every
    object of ``meshes`` (object -> list, filled) captured at each frame; ``leave_frame`` (or None)
    runs before each frame change."""
    states, images = [], {}
    for index, frame in enumerate(frames):
        if leave_frame is not None:
            leave_frame()
        scene.frame_set(frame)
        if sync_for_render() is None:
            raise RelativityError(f"Cannot bake frame {frame}: the relativistic render is refused there")
        states.append(record_frame())
        for image in _add_on_images():
            pixels = _image_pixels(image)
            if pixels is not None:
                images.setdefault(image.name, []).append(pixels)
        if meshes:
            # the meshes the sync wrote, evaluated; the handlers this evaluation fires write nothing
            # more (a render reads the state its render_pre sync left)
            with busy.computing():
                depsgraph = bpy.context.evaluated_depsgraph_get()
                for obj, captured in meshes.items():
                    captured.append(playback.capture(obj, depsgraph, index, captured[-1] if captured else None))
    return states, images


def _differ(states):
    """Whether the frames' recorded datablocks and properties differ (added or removed)."""
    return any(set(state) != set(states[0]) for state in states[1:])


def _discard(meshes):
    """Delete the captured meshes and empty the lists (a bake refused, or stepped again)."""
    playback.discard_meshes(list({mesh.name for captured in meshes.values() for mesh in captured}))
    for captured in meshes.values():
        captured.clear()


def bake(
    scene: Scene,
    first: int,
    last: int,
    sync_for_render: Callable[[], object],
    geometry: Sequence[Object] = (),
    exact_final_render: bool = False,
    leave_frame: Callable[[], object] | None = None,
) -> dict[str, int]:
    """Step frames ``first`` .. ``last``, calling ``sync_for_render`` at each (the sync a render
    runs), and keyframe what changes; capture the evaluated meshes of ``geometry`` (Apparent
    Geometry's moving meshes) at each frame and play them back (``geometry/playback.py``);
    ``exact_final_render``: the scene's camera holds the final render's exact camera, which the
    bake keeps (and :func:`unbake` removes); ``leave_frame``: called before each frame change (what a
    render's ``render_complete`` undoes before the next frame's). Returns counts: frames, F-curves, image sequences,
    meshes, and ``needs_osl`` (1 where what was baked renders only in a Blender with OSL).
    RelativityError (one line) if the frames differ in what they hold (stand-in lamps added or
    removed; with ``geometry`` they are kept, and the range stepped again if a later frame added
    some) or a frame's sync is refused."""
    if last < first:
        raise RelativityError(f"Bake: last frame {last} before first frame {first}")
    unbake(scene)
    frames = list(range(first, last + 1))
    start = scene.frame_current
    meshes: dict[Object, list] = {obj: [] for obj in geometry}
    try:
        # played-back geometry: the handlers leave the scene as baked, so stand-in lamps can stay
        with busy.keeping_stand_ins() if geometry else contextlib.nullcontext():
            states, images = _step(scene, frames, sync_for_render, meshes, leave_frame)
            if geometry and _differ(states):  # stand-ins first needed at a later frame: all there now
                _discard(meshes)
                states, images = _step(scene, frames, sync_for_render, meshes, leave_frame)
    except RelativityError:
        _discard(meshes)
        scene.frame_set(start)
        raise
    keys = set(states[0])
    problem = None
    if _differ(states):
        differ = sorted({key[1] for state in states[1:] for key in keys ^ set(state)})
        problem = (
            f"Cannot bake frames {first}-{last}: the add-on's datablocks change within them "
            f"({', '.join(differ[:3])}); bake shorter ranges"
        )
    changing_images = [
        name
        for name, per_frame in images.items()
        if len(per_frame) == len(frames) and any(not np.array_equal(per_frame[0], p) for p in per_frame[1:])
    ]
    if problem is None and changing_images and not bpy.data.filepath:
        try:
            _sequence_folder(scene)
        except RelativityError as error:
            problem = str(error)
    if problem is not None:  # refused before anything is added
        _discard(meshes)
        scene.frame_set(start)
        raise RelativityError(problem)
    record: dict[str, Any] = {
        "frames": [first, last],
        "fcurves": [],
        "actions": [],
        "sequences": [],
        "geometry": [],
        "exact_camera": exact_final_render,
    }
    grouped: dict[tuple[str, str, str], list[tuple[str, int]]] = {}
    for key in sorted(keys):
        values = [state[key] for state in states]
        if _changed(values):
            grouped.setdefault(key[:3], []).append((key[3], key[4]))
    try:  # whatever was added is recorded, also when a step fails: Remove takes it out
        for owner_key, paths in grouped.items():
            block = _owner(*owner_key)
            if block is None:
                raise RelativityError(
                    f"Cannot bake frames {first}-{last}: {owner_key[1]!r} was removed while baking; bake shorter ranges"
                )
            animated = _animated_paths(block)
            for path, index in paths:
                if (path, max(index, 0)) in animated:
                    continue  # the user's own animation plays back by itself
                values = [state[(*owner_key, path, index)] for state in states]
                _keyframe(block, path, index, frames, values, record["actions"])
                record["fcurves"].append([*owner_key, path, index])
        for name in changing_images:
            record["sequences"].append(_write_sequence(scene, bpy.data.images[name], frames, images[name]))
        for obj, captured in meshes.items():
            record["geometry"].append(playback.install(obj, captured, first))
    finally:
        scene[names.BAKE_RECORD_KEY] = json.dumps(record)
    scene.frame_set(start)
    return {
        "frames": len(frames),
        "fcurves": len(record["fcurves"]),
        "sequences": len(record["sequences"]),
        "meshes": sum(len(set(captured)) for captured in meshes.values()),
        # what it renders with: the exact camera (OSL), OSL script nodes of moving lights
        "needs_osl": int(exact_final_render or not geometry or bool(scene.cycles.shading_system)),
    }


def holds_geometry(scene: Scene) -> bool:
    """Whether the scene's bake plays Apparent Geometry back (the add-on then leaves the file as
    baked: the handlers write nothing until Remove or the next bake)."""
    stored = scene.get(names.BAKE_RECORD_KEY)
    return isinstance(stored, str) and _plays_geometry(stored)


@functools.lru_cache(maxsize=16)
def _plays_geometry(stored: str) -> bool:
    """Parsed once per record, not at every sync (every handler asks)."""
    return bool(json.loads(stored).get("geometry"))


def baked_frames(scene: Scene) -> tuple[int, int] | None:
    """The frame range of the scene's bake, or None if it is not baked."""
    stored = scene.get(names.BAKE_RECORD_KEY)
    if not isinstance(stored, str):
        return None
    first, last = json.loads(stored)["frames"]
    return int(first), int(last)


def unbake(scene: Scene) -> int:
    """Take out what :func:`bake` added (F-curves, the actions it made, image sequences and their
    files, the Image nodes back on their images). Returns the number of F-curves removed."""
    stored = scene.get(names.BAKE_RECORD_KEY)
    if stored is None:
        return 0
    record = json.loads(stored) if isinstance(stored, str) else {}
    removed = 0
    for collection, name, embedded, path, index in record.get("fcurves", []):
        block = _owner(collection, name, embedded)
        bag = None if block is None else compat.action_channelbag(block.animation_data)
        fcurve = None if bag is None else bag.fcurves.find(path, index=max(int(index), 0))
        if fcurve is not None:
            bag.fcurves.remove(fcurve)
            removed += 1
    for action_name in record.get("actions", []):
        action = bpy.data.actions.get(action_name)
        if action is None:
            continue
        for block in _users_of(action):
            block.animation_data.action = None
            if not block.animation_data.drivers:
                block.animation_data_clear()
        bpy.data.actions.remove(action)
    for sequence_record in record.get("sequences", []):
        image = bpy.data.images.get(sequence_record["image"])
        if image is not None:
            image.use_fake_user = sequence_record["fake_user"]
        for tree_name, node_name in sequence_record["nodes"]:
            tree = next((t for t in _all_trees() if t.name == tree_name), None)
            node = None if tree is None else tree.nodes.get(node_name)
            if node is not None and image is not None:
                node.image = image
        sequence = bpy.data.images.get(sequence_record["sequence"])
        if sequence is not None:
            bpy.data.images.remove(sequence)
        files = sequence_record["files"]
        for path in files:
            if os.path.isfile(path):
                os.remove(path)
        folders = {os.path.dirname(path) for path in files}
        for folder in folders:
            if os.path.isdir(folder) and not os.listdir(folder):
                os.rmdir(folder)
    for geometry_record in record.get("geometry", []):
        playback.remove(geometry_record)
    if record.get("exact_camera"):  # the Apparent Geometry final render's camera, kept for the bake
        camera_data = scene.camera.data if scene.camera is not None else None
        if isinstance(camera_data, bpy.types.Camera) and exact_camera.is_render_only(camera_data):
            exact_camera.remove_data(camera_data)
        doppler_colour.remove_camera_stage(scene)
    del scene[names.BAKE_RECORD_KEY]
    return removed


def _users_of(action):
    for _collection, _name, _embedded, block in _owners():
        animation = getattr(block, "animation_data", None)
        if animation is not None and animation.action == action:
            yield block
