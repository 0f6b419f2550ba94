"""Operators: set the scene up for a relativistic render, remove everything again, check motion.

They call ``effect.apply`` and ``effect.remove``, the entry points the batch script uses too,
and report a ``RelativityError`` in one line instead of leaving a half-applied scene.
"""

from typing import TYPE_CHECKING

from bpy.props import IntProperty
from bpy.types import Context, Operator

from ...errors import RelativityError
from ..common import osl
from ..pipeline import effect, spectral_render
from ..scene import snapshot

if TYPE_CHECKING:
    from bpy.stub_internal.rna_enums import OperatorReturnItems


def _poll_scene(cls, context):
    scene = context.scene
    if scene is None:
        cls.poll_message_set("No active scene")
        return False
    return True


class RELATIVITY_OT_setup_scene(Operator):
    """Render this scene as photographed by the moving camera (applies the chosen method)"""

    bl_idname = "relativity.setup_scene"
    bl_label = "Set Up Relativistic Render"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context: Context) -> bool:
        if not _poll_scene(cls, context):
            return False
        scene = context.scene
        if scene.camera is None or scene.camera.type != "CAMERA":
            cls.poll_message_set("The scene has no active camera")
            return False
        if scene.relativity.method == "CAMERA" and scene.render.engine != "CYCLES":
            cls.poll_message_set("Switch the render engine to Cycles: the relativistic camera is an OSL camera")
            return False
        return True

    def execute(self, context: Context) -> "set[OperatorReturnItems]":
        scene = context.scene
        try:
            effect.apply(scene)
        except RelativityError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        snap = effect.last_snapshot(scene)
        no_osl = osl.unavailable_reason()
        if no_osl is not None and snap.method == "GEOMETRY":
            at_rest = ", moving lights at rest" if snap.moving_lights else ""
            self.report({"WARNING"}, f"{no_osl}: the final render is the boosted-mesh preview{at_rest}")
        done = f"Relativistic render set up: {snap.speed:.4g} c, gamma {snap.gamma:.4g}"
        warnings = effect.scene_warnings(scene)
        if warnings:  # set up, but not everything renders right: say so now, not only in the panel
            more = f" (and {len(warnings) - 1} more in the panel)" if len(warnings) > 1 else ""
            self.report({"WARNING"}, f"{done}; {warnings[0]}{more}")
        else:
            self.report({"INFO"}, done)
        return {"FINISHED"}


class RELATIVITY_OT_remove_all(Operator):
    """Remove everything the add-on added to the file, restoring cameras and objects exactly"""

    bl_idname = "relativity.remove_all"
    bl_label = "Remove Relativistic Effect"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context: Context) -> bool:
        if not _poll_scene(cls, context):
            return False
        if not effect.is_applied(context.scene):
            cls.poll_message_set("Nothing to remove: the relativistic render is not set up")
            return False
        return True

    def execute(self, context: Context) -> "set[OperatorReturnItems]":
        removed = effect.remove(context.scene)
        self.report({"INFO"}, f"Removed the relativistic effect ({removed} item{'s' if removed != 1 else ''})")
        return {"FINISHED"}


class RELATIVITY_OT_check_animation(Operator):
    """Check that the camera's animation stays below the speed of light over the frame range"""

    bl_idname = "relativity.check_animation"
    bl_label = "Check Camera Speed"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context: Context) -> bool:
        if not _poll_scene(cls, context):
            return False
        if context.scene.camera is None:
            cls.poll_message_set("The scene has no active camera")
            return False
        return True

    def execute(self, context: Context) -> "set[OperatorReturnItems]":
        scene = context.scene
        try:
            highest = snapshot.check_animation_speed(scene)
        except RelativityError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report(
            {"INFO"},
            f"Camera speed peaks at {highest:.4g} c (below c) over frames {scene.frame_start}-{scene.frame_end}",
        )
        return {"FINISHED"}


class RELATIVITY_OT_render_spectral(Operator):
    """Render the current frame with spectral colour: exact for lamps, sun and sky at rest (the chosen
    number of passes of three wavelengths each); the picture opens as an image"""

    bl_idname = "relativity.render_spectral"
    bl_label = "Render Spectral"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context: Context) -> bool:
        if not _poll_scene(cls, context):
            return False
        try:
            spectral_render.ready(context.scene)  # the rest of the check: when pressed (execute)
        except RelativityError as error:
            cls.poll_message_set(str(error))
            return False
        return True

    def execute(self, context: Context) -> "set[OperatorReturnItems]":
        scene = context.scene
        window_manager = context.window_manager
        passes = scene.relativity.spectral_passes
        window_manager.progress_begin(0, passes)
        try:
            pixels, info = spectral_render.render(
                scene, passes, progress=lambda done, _total: window_manager.progress_update(done)
            )
        except RelativityError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            window_manager.progress_end()
        image = spectral_render.store_image(pixels)
        for area in context.screen.areas if context.screen else ():
            if area.type == "IMAGE_EDITOR":
                area.spaces.active.image = image
                break
        low, high = info["doppler_range"]
        self.report(
            {"INFO"},
            f"Spectral render in image {image.name!r}: D {low:.3g} to {high:.3g}, "
            f"{passes} passes, {info['seconds']:.1f} s",
        )
        return {"FINISHED"}


class RELATIVITY_OT_bake_render_anywhere(Operator):
    """Write what the add-on computes per frame into keyframes, image sequences and (Apparent
    Geometry) meshes played back by frame, so that the file renders these frames without the
    add-on (plain Blender, scripts disabled)"""

    bl_idname = "relativity.bake_render_anywhere"
    bl_label = "Bake for Render Anywhere"
    bl_options = {"REGISTER", "UNDO"}

    frame_start: IntProperty(  # type: ignore[valid-type]
        name="First Frame", default=-1, description="-1: the scene's first frame"
    )
    frame_end: IntProperty(  # type: ignore[valid-type]
        name="Last Frame", default=-1, description="-1: the scene's last frame"
    )

    @classmethod
    def poll(cls, context: Context) -> bool:
        if not _poll_scene(cls, context):
            return False
        if effect.applied_method(context.scene) is None:
            cls.poll_message_set("Set up the relativistic render first")
            return False
        return True

    def execute(self, context: Context) -> "set[OperatorReturnItems]":
        scene = context.scene
        first = scene.frame_start if self.frame_start < 0 else self.frame_start
        last = scene.frame_end if self.frame_end < 0 else self.frame_end
        try:
            counts = effect.bake_for_render_anywhere(scene, first, last)
        except RelativityError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        images = f", {counts['sequences']} image sequence(s) beside the file" if counts["sequences"] else ""
        meshes = f", {counts['meshes']} meshes played back by frame" if counts.get("meshes") else ""
        where = " in a Blender with OSL (Cycles on the CPU: OSL shaders)" if counts.get("needs_osl", 1) else ""
        self.report(
            {"INFO"},
            f"Baked frames {first}-{last}: {counts['fcurves']} animated values{images}{meshes}; the file renders "
            f"them without the add-on{where}",
        )
        return {"FINISHED"}


classes = (
    RELATIVITY_OT_setup_scene,
    RELATIVITY_OT_remove_all,
    RELATIVITY_OT_bake_render_anywhere,
    RELATIVITY_OT_check_animation,
    RELATIVITY_OT_render_spectral,
)
