"""Attach, update, validate and remove the relativistic OSL camera.

The shader (``relativity_addon/shaders/relativistic_camera.osl``) is stored in the .blend as a
text datablock and compiled by Cycles into the camera's bytecode; every parameter it needs is
written to ``camera.data.cycles_custom``. A render therefore needs nothing outside the file.
What ``apply_relativistic_camera`` changes on the camera is recorded in ID properties of the
camera data, so ``remove_relativistic_camera`` restores it exactly (and undo covers both).

Coordinate conventions: Cycles' camera shaders use +Z forward, +Y up, +X right. Blender's
camera object looks down its local -Z with +Y up and +X right, so a vector in the camera's
local axes maps to shader coordinates as (x, y, -z).
"""

import math
import os

import bpy
from bpy.app.handlers import persistent

from . import compat, osl

SHADER_TEXT_NAME = "relativistic_camera.osl"
SHADER_PATH = os.path.join(os.path.dirname(os.path.dirname(__file__)), "shaders", SHADER_TEXT_NAME)

# ID property on the camera data: present while the relativistic camera is applied; holds what
# was there before.
SAVED_STATE_KEY = "relativity_saved_state"

# Shader parameters that must exist after compilation; their absence means an empty shader.
REQUIRED_PARAMETERS = (
    "frame_left",
    "frame_right",
    "frame_bottom",
    "frame_top",
    "lens_focal_length",
    "aperture_scale",
    "beta",
    "speed_of_light",
    "shutter_model",
    "shutter_time",
    "shutter_plane_point",
    "shutter_plane_normal",
    "use_lorentz_window",
    "use_geometry",
    "use_searchlight",
    "settings_valid",
)


class RelativityError(Exception):
    """A user-facing problem that prevents a physically correct render (one-line message)."""


def shader_source():
    with open(SHADER_PATH, encoding="utf-8") as handle:
        return handle.read()


def ensure_shader_text():
    """The text datablock holding the camera shader, created or refreshed from the package."""
    source = shader_source()
    text = bpy.data.texts.get(SHADER_TEXT_NAME)
    if text is None:
        text = bpy.data.texts.new(SHADER_TEXT_NAME)
    if text.as_string().rstrip("\n") != source.rstrip("\n"):
        text.clear()
        text.write(source)
    return text


def is_applied(camera_data):
    return camera_data is not None and SAVED_STATE_KEY in camera_data


def _finite(values):
    return all(math.isfinite(value) for value in values)


def validate_scene(scene, require_perspective=True):
    """Raise RelativityError unless the scene can be rendered with correct physics."""
    settings = scene.relativity
    beta = tuple(settings.beta)
    if not _finite(beta):
        raise RelativityError("observer velocity beta is not a finite vector")
    speed = math.sqrt(sum(b * b for b in beta))
    if speed >= 1.0:
        raise RelativityError(f"observer speed |beta| = {speed:.6g} must be below 1 (the speed of light)")
    c = settings.speed_of_light
    if not (math.isfinite(c) and c > 0.0):
        raise RelativityError("speed of light must be a positive finite number")
    if not math.isfinite(settings.shutter_time):
        raise RelativityError("shutter time must be finite")
    if settings.method != "CAMERA":
        raise RelativityError(f"render method {settings.method!r} is not implemented yet; use 'CAMERA'")
    if scene.render.engine != "CYCLES":
        raise RelativityError(
            f"the relativistic camera needs the Cycles render engine, not {scene.render.engine}"
        )
    camera_object = scene.camera
    if camera_object is None or camera_object.type != "CAMERA":
        raise RelativityError(f"scene {scene.name!r} has no active camera")
    if settings.shutter_model == "ARBITRARY_PLANE":
        normal = tuple(settings.shutter_plane_normal)
        if not _finite(normal) or sum(n * n for n in normal) == 0.0:
            raise RelativityError("arbitrary shutter plane needs a non-zero normal")
    if require_perspective and not is_applied(camera_object.data):
        if camera_object.data.type != "PERSP":
            raise RelativityError(
                f"camera {camera_object.name!r} is {camera_object.data.type}, "
                "the relativistic camera replaces a perspective camera only"
            )
    return camera_object


def camera_world_matrix(scene, camera_object):
    """The camera's world matrix at the scene's current (sub-)frame.

    During Blender's own animation render the original camera object is not re-evaluated, so
    its ``matrix_world`` is that of the frame the file was saved at; a farm worker would then
    render a turning camera wrongly. Keyframed transforms (with object parents) are therefore
    evaluated from the F-curves at the frame itself; only a camera moved by constraints, drivers
    or NLA falls back to ``matrix_world``.
    """
    from . import animation

    try:
        animation.check_supported(camera_object)
        return animation.world_matrix_at(camera_object, scene.frame_current + scene.frame_subframe)
    except RelativityError:
        return camera_object.matrix_world


def _world_to_camera_rotation(scene, camera_object):
    """Rotation taking world vectors to the camera's local axes (scale and shear removed)."""
    return camera_world_matrix(scene, camera_object).to_quaternion().to_matrix().transposed()


def _local_to_shader(vector):
    return (vector[0], vector[1], -vector[2])


def camera_frame_window(scene, camera_data):
    """Image window of lens-centre rays on the plane at unit distance: left, right, bottom, top.

    Taken from Blender's own view frame, so sensor fit, aspect and lens shift match the
    built-in perspective camera. Cycles already adds a lens shift to the raster position it
    hands a custom camera, but scaled by the image's own width and height where Blender's
    perspective camera scales both by the sensor-fit dimension (measured with Blender 5.0);
    the window is offset so that the sum is the perspective camera's shift.
    """
    corners = camera_data.view_frame(scene=scene)
    xs = [corner.x / -corner.z for corner in corners]
    ys = [corner.y / -corner.z for corner in corners]
    width = max(xs) - min(xs)
    height = max(ys) - min(ys)
    offset_x = (max(xs) + min(xs)) / 2.0 - camera_data.shift_x * width
    offset_y = (max(ys) + min(ys)) / 2.0 - camera_data.shift_y * height
    return (
        offset_x - width / 2.0,
        offset_x + width / 2.0,
        offset_y - height / 2.0,
        offset_y + height / 2.0,
    )


def shader_parameters(scene, camera_object):
    """Values for ``cycles_custom``, from the scene settings and the camera's world rotation."""
    from mathutils import Vector

    settings = scene.relativity
    camera_data = camera_object.data
    rotation = _world_to_camera_rotation(scene, camera_object)
    beta_local = rotation @ Vector(settings.beta)
    left, right, bottom, top = camera_frame_window(scene, camera_data)
    unit_scale = scene.unit_settings.scale_length or 1.0
    return {
        "frame_left": left,
        "frame_right": right,
        "frame_bottom": bottom,
        "frame_top": top,
        "lens_focal_length": camera_data.lens * 1e-3 / unit_scale,
        "aperture_scale": compat.custom_camera_aperture_scale(camera_data.lens * 1e-3 / unit_scale),
        "beta": _local_to_shader(beta_local),
        "speed_of_light": settings.speed_of_light,
        "shutter_model": list(_shutter_models()).index(settings.shutter_model),
        "shutter_time": settings.shutter_time,
        "shutter_plane_point": _local_to_shader(settings.shutter_plane_point),
        "shutter_plane_normal": _local_to_shader(settings.shutter_plane_normal),
        "use_lorentz_window": bool(settings.use_lorentz_window),
        "use_geometry": bool(settings.use_geometry),
        "use_searchlight": bool(settings.use_searchlight),
        "settings_valid": True,
    }


def _shutter_models():
    from .props import SHUTTER_MODELS

    return SHUTTER_MODELS


def _write_parameters(camera_data, values):
    custom = camera_data.cycles_custom
    for name, value in values.items():
        current = custom.get(name)
        if isinstance(value, tuple):
            value = tuple(float(v) for v in value)
        elif isinstance(value, bool):
            value = bool(value) if isinstance(current, bool) else int(value)
        elif isinstance(current, int) and not isinstance(current, bool):
            value = int(value)
        elif isinstance(value, (int, float)) and isinstance(current, float):
            value = float(value)
        custom[name] = value
    camera_data.update_tag()


def _missing_parameters(camera_data):
    custom = camera_data.cycles_custom
    return [name for name in REQUIRED_PARAMETERS if name not in custom]


def compile_shader(camera_data):
    """Compile the camera's shader; raise RelativityError on any failure or empty result."""
    try:
        errors = osl.compile_custom_camera(camera_data)
    except osl.OSLUnavailableError as error:
        raise RelativityError(f"OSL unavailable: {error}") from error
    if errors:
        raise RelativityError(f"relativistic camera shader failed to compile: {errors[0]}")
    missing = _missing_parameters(camera_data)
    if missing or not camera_data.custom_bytecode:
        raise RelativityError(
            "relativistic camera shader compiled to an empty shader "
            f"(missing parameters: {', '.join(missing) or 'bytecode'})"
        )


def _save_state(camera_data):
    custom = camera_data.cycles_custom
    camera_data[SAVED_STATE_KEY] = {
        "type": camera_data.type,
        "custom_mode": camera_data.custom_mode,
        "custom_shader": camera_data.custom_shader.name if camera_data.custom_shader else "",
        "custom_filepath": camera_data.custom_filepath,
        "custom_bytecode": camera_data.custom_bytecode,
        "custom_bytecode_hash": camera_data.custom_bytecode_hash,
        "cycles_custom": {key: custom[key] for key in custom.keys()},
    }


def apply_relativistic_camera(scene):
    """Turn the scene camera into the relativistic OSL camera and sync it. Returns the camera.

    Raises RelativityError (one-line message) if the scene cannot be rendered correctly.
    """
    camera_object = validate_scene(scene)
    camera_data = camera_object.data
    if not is_applied(camera_data):
        try:
            osl.ensure_oslquery_importable()
        except osl.OSLUnavailableError as error:
            raise RelativityError(f"OSL unavailable: {error}") from error
        _save_state(camera_data)
        text = ensure_shader_text()
        camera_data.type = "CUSTOM"
        camera_data.custom_mode = "INTERNAL"
        camera_data.custom_shader = text
    try:
        if _missing_parameters(camera_data) or not camera_data.custom_bytecode:
            compile_shader(camera_data)
        _write_parameters(camera_data, shader_parameters(scene, camera_object))
    except RelativityError:
        if SAVED_STATE_KEY in camera_data:
            remove_relativistic_camera(scene)
        raise
    from . import compositing  # Doppler colour stage (materials + compositor), undone on remove

    try:
        compositing.apply_camera_colour(scene)
    except RelativityError:
        remove_relativistic_camera(scene)
        raise
    return camera_object


def sync_relativistic_camera(scene):
    """Re-write the shader parameters from the scene state; mark the shader invalid on error."""
    camera_object = scene.camera
    if camera_object is None or camera_object.type != "CAMERA" or not is_applied(camera_object.data):
        return False
    camera_data = camera_object.data
    try:
        validate_scene(scene)
        if camera_data.type != "CUSTOM":
            raise RelativityError(f"camera {camera_object.name!r} is no longer a custom camera")
        if _missing_parameters(camera_data) or not camera_data.custom_bytecode:
            ensure_shader_text()
            compile_shader(camera_data)
        _write_parameters(camera_data, shader_parameters(scene, camera_object))
    except RelativityError:
        if "settings_valid" in camera_data.cycles_custom:
            _write_parameters(camera_data, {"settings_valid": False})
        raise
    return True


def sync_if_applied(scene):
    """Property-update entry point: never raises; an invalid state renders black, not wrong."""
    try:
        sync_relativistic_camera(scene)
    except RelativityError as error:
        print(f"Relativity: {error}")


def remove_relativistic_camera(scene, camera_object=None):
    """Restore the camera exactly as it was before ``apply_relativistic_camera``."""
    camera_object = camera_object or scene.camera
    if camera_object is None or camera_object.type != "CAMERA":
        return False
    camera_data = camera_object.data
    if not is_applied(camera_data):
        return False
    from . import compositing

    compositing.remove_camera_colour(scene)
    saved = camera_data[SAVED_STATE_KEY].to_dict()
    custom = camera_data.cycles_custom
    for key in list(custom.keys()):
        del custom[key]
    for key, value in saved.get("cycles_custom", {}).items():
        custom[key] = value
    camera_data.custom_mode = saved["custom_mode"]
    camera_data.custom_shader = bpy.data.texts.get(saved["custom_shader"]) if saved["custom_shader"] else None
    camera_data.custom_filepath = saved["custom_filepath"]
    camera_data.custom_bytecode = saved["custom_bytecode"]
    camera_data.custom_bytecode_hash = saved["custom_bytecode_hash"]
    camera_data.type = saved["type"]
    del camera_data[SAVED_STATE_KEY]
    text = bpy.data.texts.get(SHADER_TEXT_NAME)
    if text is not None and not any(cam.custom_shader == text for cam in bpy.data.cameras):
        bpy.data.texts.remove(text)
    camera_data.update_tag()
    return True


@persistent
def _render_pre(scene, _depsgraph=None):
    """Re-sync before every render from the scene state alone (frame order does not matter)."""
    try:
        sync_relativistic_camera(scene)
    except RelativityError as error:
        print(f"Relativity: not rendering relativistic physics: {error}")


def register():
    if _render_pre not in bpy.app.handlers.render_pre:
        bpy.app.handlers.render_pre.append(_render_pre)


def unregister():
    if _render_pre in bpy.app.handlers.render_pre:
        bpy.app.handlers.render_pre.remove(_render_pre)
