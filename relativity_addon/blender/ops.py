"""Operators: set the scene up for a relativistic render, remove everything again, check motion.

``apply_effect(scene)`` and ``remove_effect(scene)`` are the single entry points used by the
operators and by the batch script. They raise ``RelativityError`` (one line) instead of leaving a
half-applied scene.
"""

import importlib
import importlib.util
import math

import bpy
from bpy.types import Operator

from . import animation, camera
from .camera import RelativityError

# Module names the apparent-geometry path may live under (built by another part of the project).
_GEOMETRY_MODULES = ("geometry", "apparent_geometry")


def geometry_module():
    """The apparent-geometry glue module if it exists in this version of the add-on, else None."""
    for name in _GEOMETRY_MODULES:
        if importlib.util.find_spec(f"{__package__}.{name}") is not None:
            return importlib.import_module(f".{name}", __package__)
    return None


def gamma_of_speed(speed):
    return math.inf if speed >= 1.0 else 1.0 / math.sqrt(1.0 - speed * speed)


def apply_effect(scene, frame_range=None):
    """Sync the velocity (if it comes from the camera animation), check it over ``frame_range``
    (first, last; default the scene's range), and apply the chosen method. Returns the camera."""
    settings = scene.relativity
    if settings.velocity_source == "CAMERA_ANIMATION":
        animation.check_animation_speed(scene, *(frame_range or (None, None)))
        animation.sync_velocity_from_animation(scene)
    if settings.method == "GEOMETRY":
        module = geometry_module()
        apply_geometry = getattr(module, "apply_apparent_geometry", None)
        if apply_geometry is not None:
            return apply_geometry(scene)
    # Without the geometry path, the camera's validation refuses method GEOMETRY in one line.
    return camera.apply_relativistic_camera(scene)


def applied_cameras():
    return [
        obj for obj in bpy.data.objects
        if obj.type == "CAMERA" and camera.is_applied(obj.data)
    ]


def is_effect_applied(scene):
    if applied_cameras():
        return True
    module = geometry_module()
    applied_objects = getattr(module, "applied_objects", None)
    return bool(applied_objects and applied_objects(scene))


def remove_effect(scene):
    """Remove everything the add-on added (every relativistic camera, the apparent geometry).
    The scene settings stay: they are the user's. Returns the number of things removed."""
    removed = 0
    module = geometry_module()
    remove_geometry = getattr(module, "remove_apparent_geometry", None)
    if remove_geometry is not None:
        removed += len(remove_geometry(scene) or ())
    for obj in applied_cameras():
        removed += bool(camera.remove_relativistic_camera(scene, obj))
    return removed


def _poll_scene(cls, context):
    scene = context.scene
    if scene is None or not hasattr(scene, "relativity"):
        cls.poll_message_set("No scene with relativity settings")
        return False
    return True


class RELATIVITY_OT_setup_scene(Operator):
    """Render this scene as photographed by the moving camera (applies the chosen method)"""

    bl_idname = "relativity.setup_scene"
    bl_label = "Set Up Relativistic Render"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        if not _poll_scene(cls, context):
            return False
        scene = context.scene
        if scene.camera is None or scene.camera.type != "CAMERA":
            cls.poll_message_set("The scene has no active camera")
            return False
        if scene.render.engine != "CYCLES":
            cls.poll_message_set("Switch the render engine to Cycles: the relativistic camera is an OSL camera")
            return False
        return True

    def execute(self, context):
        scene = context.scene
        try:
            apply_effect(scene)
        except RelativityError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        speed = scene.relativity.speed
        self.report({"INFO"}, f"Relativistic render set up: {speed:.4g} c, gamma {gamma_of_speed(speed):.4g}")
        return {"FINISHED"}


class RELATIVITY_OT_remove_all(Operator):
    """Remove everything the add-on added to the file, restoring cameras and objects exactly"""

    bl_idname = "relativity.remove_all"
    bl_label = "Remove Relativistic Effect"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        if not _poll_scene(cls, context):
            return False
        if not is_effect_applied(context.scene):
            cls.poll_message_set("Nothing to remove: the relativistic render is not set up")
            return False
        return True

    def execute(self, context):
        removed = remove_effect(context.scene)
        self.report({"INFO"}, f"Removed the relativistic effect ({removed} item{'s' if removed != 1 else ''})")
        return {"FINISHED"}


class RELATIVITY_OT_check_animation(Operator):
    """Check that the camera's animation stays below the speed of light over the frame range"""

    bl_idname = "relativity.check_animation"
    bl_label = "Check Camera Speed"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        if not _poll_scene(cls, context):
            return False
        if context.scene.camera is None:
            cls.poll_message_set("The scene has no active camera")
            return False
        return True

    def execute(self, context):
        scene = context.scene
        try:
            highest = animation.check_animation_speed(scene)
        except RelativityError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report(
            {"INFO"},
            f"Camera speed peaks at {highest:.4g} c (below c) over frames {scene.frame_start}-{scene.frame_end}",
        )
        return {"FINISHED"}


classes = (RELATIVITY_OT_setup_scene, RELATIVITY_OT_remove_all, RELATIVITY_OT_check_animation)
