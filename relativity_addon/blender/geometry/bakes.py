"""Motion and deformation bakes: Blender's own evaluation of an object sampled over a frame range.

Objects moved by constraints, drivers, NLA or non-object parents (``animation.
keyframe_motion_problem``) and deforming meshes cannot be evaluated at each vertex's retarded
time from keyframes. A bake steps the scene through sub-frames with ``frame_set`` (so it runs
outside handlers, with them held off, and shows Blender's progress indicator) and keeps the
samples on the object's cache mesh (``modifier.py``), so they are saved with the .blend and
removed with the effect.
"""

import math
from typing import TYPE_CHECKING

import bpy
import numpy as np

from ...errors import RelativityError
from ..common import busy, names
from ..scene import animation, snapshot
from . import apparent_meshes, modifier
from .motion import matrix_array, to_world

if TYPE_CHECKING:
    from bpy.stub_internal.rna_enums import OperatorReturnItems


def _bake_frames(scene, obj, frame_start, frame_end):
    """Sample frames for a bake of ``obj``: ``frame_start`` to ``frame_end`` (default: the scene's
    range, starting earlier by twice the current light-travel time to the farthest vertex) at
    ``relativity.samples_per_frame`` per frame."""
    fps = animation.frames_per_second(scene)
    first = scene.frame_start if frame_start is None else frame_start
    last = scene.frame_end if frame_end is None else frame_end
    if frame_start is None:
        # Light seen at the first frame left up to ~2 d / c earlier (d: camera to farthest vertex now).
        with busy.computing():
            depsgraph = bpy.context.evaluated_depsgraph_get()
            rest = modifier.evaluated_rest_positions(obj, depsgraph)
        snap = snapshot.read(scene, depsgraph, objects_for="GEOMETRY")
        x_o, c = snap.camera_position, snap.speed_of_light
        if rest is not None and len(rest):
            world = to_world(matrix_array(obj.evaluated_get(depsgraph).matrix_world), rest)
            first -= math.ceil(2.0 * float(np.max(np.linalg.norm(world - x_o, axis=1))) / c * fps) + 2
    per_frame = int(obj.relativity.samples_per_frame)
    frames = first + np.arange(int(round((last - first) * per_frame)) + 1) / per_frame
    if len(frames) < 2:
        raise RelativityError(f"Object {obj.name!r}: bake range needs at least two samples")
    return frames, per_frame


def _sample_frames(scene, frames, sample):
    """Call ``sample(depsgraph)`` at each of ``frames`` (scene.frame_set, sub-frames included),
    with the handlers held off and Blender's progress indicator showing; the scene's frame is
    restored."""
    saved_frame, saved_subframe = scene.frame_current, scene.frame_subframe
    window_manager = bpy.context.window_manager
    window_manager.progress_begin(0, len(frames))
    with busy.computing():
        try:
            for done, frame in enumerate(frames):
                whole = int(np.floor(frame))
                scene.frame_set(whole, subframe=float(frame - whole))
                sample(bpy.context.evaluated_depsgraph_get())
                window_manager.progress_update(done + 1)
        finally:
            scene.frame_set(saved_frame, subframe=saved_subframe)
            window_manager.progress_end()


def bake_deformation(
    scene: bpy.types.Scene, obj: bpy.types.Object, frame_start: float | None = None, frame_end: float | None = None
) -> int:
    """Sample the evaluated (tessellated, deformed) world positions of ``obj`` and its origin from
    ``frame_start`` to ``frame_end`` (default: the scene's range, starting earlier by twice the
    current light-travel time to the farthest vertex) at ``relativity.samples_per_frame``
    sub-frames, for per-vertex retarded times of a deforming mesh (the origin's path gives the
    velocity along which the baked shape is contracted, ``physics.rest_shape``). Steps the scene
    through the frames (frame_set), so it runs outside handlers; the scene's frame is restored.
    The samples live in a mesh datablock kept with the .blend (fake user) and are removed with the
    effect. Returns the number of samples.
    """
    _, cache = modifier.ensure_modifier(obj)
    fps = animation.frames_per_second(scene)
    frames, per_frame = _bake_frames(scene, obj, frame_start, frame_end)

    def sample(depsgraph: bpy.types.Depsgraph) -> None:
        rest = modifier.evaluated_rest_positions(obj, depsgraph)
        if rest is None or (samples and len(rest) != len(samples[0])):
            raise RelativityError(f"Object {obj.name!r}: vertex count changes during the bake range")
        matrix = matrix_array(obj.evaluated_get(depsgraph).matrix_world)
        samples.append(to_world(matrix, rest))
        origins.append(matrix[:3, 3])

    samples, origins = [], []
    _sample_frames(scene, frames, sample)
    mesh = modifier.bake_mesh(obj)
    if mesh is None:
        mesh = bpy.data.meshes.new(f"{names.BAKE_PREFIX} {obj.name}")
        mesh.use_fake_user = True
    mesh.clear_geometry()
    count = len(samples[0])
    mesh.vertices.add(count)
    for i, positions in enumerate(samples):
        attribute = mesh.attributes.new(f"sample_{i:05d}", "FLOAT_VECTOR", "POINT")
        attribute.data.foreach_set("vector", positions.astype(np.float32).ravel())
    cache.data[names.BAKE_KEY] = {
        "mesh": mesh.name,
        "start": float(frames[0] / fps),
        "step": 1.0 / (per_frame * fps),
        "samples": len(samples),
        "points": count,
        names.BAKE_ORIGINS_KEY: np.ravel(origins).tolist(),
    }
    apparent_meshes.update_after_bake(scene, obj)
    return len(samples)


def bake_motion(
    scene: bpy.types.Scene, obj: bpy.types.Object, frame_start: float | None = None, frame_end: float | None = None
) -> int:
    """Sample the world matrix of ``obj`` as Blender evaluates it (depsgraph: constraints, drivers,
    NLA, parents of any type, simulations) from ``frame_start`` to ``frame_end`` (default as
    :func:`bake_deformation`) at ``relativity.samples_per_frame`` sub-frames, for the rigid
    ANIMATION path. Steps the scene through the frames, so it runs outside handlers; the scene's
    frame is restored. The matrices (float64) are stored on the cache mesh, so they are saved with
    the .blend and removed with the effect. Returns the number of samples.
    """
    geometry_modifier, cache = modifier.ensure_modifier(obj)
    frames, per_frame = _bake_frames(scene, obj, frame_start, frame_end)
    # Only the transform is sampled: the modifier (tessellation, cache lookup) need not run.
    shown = geometry_modifier.show_viewport
    geometry_modifier.show_viewport = False
    matrices = []
    try:
        _sample_frames(
            scene, frames, lambda depsgraph: matrices.append(matrix_array(obj.evaluated_get(depsgraph).matrix_world))
        )
    finally:
        geometry_modifier.show_viewport = shown
    cache.data[names.MOTION_BAKE_KEY] = {
        "first_frame": float(frames[0]),
        "samples_per_frame": per_frame,
        "matrices": np.ravel(matrices).tolist(),
    }
    apparent_meshes.update_after_bake(scene, obj)
    return len(matrices)


def _poll_mesh(cls, context):
    obj = context.active_object
    if obj is None or obj.type != "MESH" or context.scene is None:
        cls.poll_message_set("Select a mesh object")
        return False
    return True


class _BakeOperator:
    """Shared execute of the bake operators: set the object's motion, bake, report."""

    bl_options = {"REGISTER", "UNDO"}
    use_deformation = False
    baked = "samples"

    def execute(self, context: bpy.types.Context) -> "set[OperatorReturnItems]":
        scene, obj = context.scene, context.active_object
        if self.use_deformation:
            obj.relativity.use_deformation = True
        obj.relativity.motion = "ANIMATION"
        try:
            count = self.bake(scene, obj)
        except RelativityError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Baked {count} {self.baked} of {obj.name!r}")
        return {"FINISHED"}


class RELATIVITY_OT_bake_deformation(_BakeOperator, bpy.types.Operator):
    """Sample the active object's deformed vertex positions over the scene's frame range, so each
    vertex can be shown at its own retarded time"""

    bl_idname = "relativity.bake_deformation"
    bl_label = "Bake Deformation"
    use_deformation = True
    bake = staticmethod(bake_deformation)

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return _poll_mesh(cls, context)


class RELATIVITY_OT_bake_motion(_BakeOperator, bpy.types.Operator):
    """Sample the active object's world transform over the scene's frame range as Blender evaluates
    it (constraints, drivers, NLA, parents), so its motion can be shown at each vertex's retarded
    time"""

    bl_idname = "relativity.bake_motion"
    bl_label = "Bake Motion"
    baked = "transforms"
    bake = staticmethod(bake_motion)

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if not _poll_mesh(cls, context):
            return False
        if context.active_object.relativity.use_deformation:
            cls.poll_message_set("A deforming object bakes its vertex positions: use Bake Deformation")
            return False
        return True


classes = (RELATIVITY_OT_bake_deformation, RELATIVITY_OT_bake_motion)
