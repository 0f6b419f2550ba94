"""The exact camera: attach, write, invalidate and remove the relativistic OSL camera.

The shader (``relativity_addon/shaders/relativistic_camera.osl``) is stored in the .blend as a
text datablock and compiled by Cycles into the camera's bytecode; every parameter it needs is
written to ``camera.data.cycles_custom`` from a ``snapshot.Snapshot``. A render therefore needs
nothing outside the file. What :func:`apply` changes on the camera is recorded in ID properties
of the camera data, so :func:`remove` restores it exactly (and undo covers both).

Coordinate conventions: Cycles' camera shaders use +Z forward, +Y up, +X right. Blender's
camera object looks down its local -Z with +Y up and +X right, so a vector in the camera's
local axes maps to shader coordinates as (x, y, -z).

Blender's panoramic cameras (equirectangular, fisheye equidistant and equisolid, mirror ball) go
through the same shader: it maps the raster position to the camera-frame direction as Blender's
own panorama does, then Lorentz-transforms the ray like the perspective camera's. A panorama is a
pinhole: the shutter models that need a thin lens (detector plane, focus surface, fixed-point
surface) are refused, depth of field is not rendered (a warning). The panorama settings stay on
the camera data (the same properties in 4.5 and 5.x), and :func:`remove` gives back the camera
type, so a panoramic camera comes back panoramic.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING, Any

import bpy

from ...errors import RelativityError
from ..common import compat, names, osl
from ..scene import lens, snapshot
from ..scene.lens import PANORAMA_PROJECTIONS, lens_type, projection_parameters, stereo_eyes

if TYPE_CHECKING:
    from bpy.types import Camera, Object, Scene, Text

    from ..scene.snapshot import Snapshot

SHADER_PATH = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "shaders", names.SHADER_TEXT)

# Shader parameters that must exist after compilation; their absence means an empty shader.
REQUIRED_PARAMETERS = (
    "frame_left",
    "frame_right",
    "frame_bottom",
    "frame_top",
    "projection",
    "longitude_min",
    "longitude_max",
    "latitude_min",
    "latitude_max",
    "fisheye_fov",
    "fisheye_lens",
    "sensor_width",
    "sensor_height",
    "lens_focal_length",
    "use_dof",
    "aperture_scale",
    "beta",
    "speed_of_light",
    "shutter_model",
    "shutter_time",
    "shutter_plane_point",
    "shutter_plane_normal",
    "use_lorentz_window",
    "phase_hologram",
    "window_with_shutter_model",
    "window_time",
    "use_geometry",
    "use_time_of_flight",
    "use_searchlight",
    "settings_valid",
    "use_eye_offset",
    "camera_origin",
)


# Blender's panorama types the shader renders -> its PROJECTION_* code (0 is the perspective camera).
# Shutter models defined by a thin lens's geometry (detector, focus distance): perspective only.
LENS_SHUTTERS = ("DETECTOR_PLANE", "FOCUS_SURFACE", "FIXED_POINT_SURFACE")


def shader_source() -> str:
    with open(SHADER_PATH, encoding="utf-8") as handle:
        return handle.read()


def ensure_shader_text() -> Text:
    """The text datablock holding the camera shader, created or refreshed from the package."""
    source = shader_source()
    text = bpy.data.texts.get(names.SHADER_TEXT)
    if text is None:
        text = bpy.data.texts.new(names.SHADER_TEXT)
    if text.as_string().rstrip("\n") != source.rstrip("\n"):
        text.clear()
        text.write(source)
    return text


def is_applied(camera_data: Camera | None) -> bool:
    return camera_data is not None and names.CAMERA_SAVED_STATE_KEY in camera_data


def is_render_only(camera_data: Camera) -> bool:
    """Applied for the time of an Apparent Geometry final render (``effect.begin_final_render``)."""
    return is_applied(camera_data) and bool(camera_data[names.CAMERA_SAVED_STATE_KEY].get("render_only", False))


def type_problem(camera_name: str, camera_data: Camera) -> str | None:
    """Why the exact camera cannot replace this camera (one line), or None."""
    kind = lens_type(camera_data)
    if kind == "PERSP":
        return None
    if kind == "PANO":
        if camera_data.panorama_type in PANORAMA_PROJECTIONS:
            return None
        projection = compat.enum_name(camera_data, "panorama_type")
        return (
            f"Camera {camera_name!r} has panorama type {projection}: the relativistic camera "
            "renders perspective, equirectangular, fisheye equidistant/equisolid and mirror ball cameras"
        )
    kind = compat.enum_name(camera_data, "type")
    return f"Camera {camera_name!r} is {kind}: the relativistic camera replaces a perspective or panoramic camera only"


def final_render_problem(scene: Scene, snap: Snapshot) -> str | None:
    """Why an Apparent Geometry final render of ``snap`` is not made with the exact camera (one
    line, lower-case: it follows a colon), or None when it is. Without a moving observer nothing
    needs it (the boosted meshes are then scene-frame meshes)."""
    if snap.method != "GEOMETRY" or snap.geometry_final_render != "EXACT":
        return "Final Render is set to Boosted Meshes" if snap.method == "GEOMETRY" else "not Apparent Geometry"
    if snap.speed == 0.0 and snap.velocity_source != "CAMERA_ANIMATION":
        return "the observer is at rest"
    if snap.engine != "CYCLES":
        return f"the exact camera needs Cycles, not {compat.enum_name(scene.render, 'engine', snap.engine)}"
    no_osl = osl.unavailable_reason()
    if no_osl is not None:
        return no_osl[0].lower() + no_osl[1:]
    if snap.cockpit and snap.moving_lights:
        # placing the stand-in lamps in render_init evaluates a depsgraph, which crashed Blender 5.2
        # with the cockpit's Render Layers node in the changed compositor (docs/cockpit.md)
        return "objects moving with the camera and moving lights do not render together through it yet"
    return type_problem(snap.camera, scene.objects[snap.camera].data)


def type_changed(camera_object: Object) -> str:
    """The one line for a camera whose Type the user changed after Set Up (the OSL camera is Custom)."""
    kind = compat.enum_name(camera_object.data, "type")
    return (
        f"Camera {camera_object.name!r}: Type was changed to {kind} after Set Up: "
        "set it back to Custom, or press Remove and Set Up again"
    )


def lens_warnings(camera_object: Object | None) -> list[str]:
    """One-line notes on what the exact camera does not render for this camera (the shutter model
    read from the scene whose active camera it is)."""
    if camera_object is None or camera_object.type != "CAMERA" or not camera_object.data.dof.use_dof:
        return []
    name = camera_object.name
    if lens_type(camera_object.data) == "PANO":
        return [f"Camera {name!r}: the relativistic panorama is a pinhole, depth of field is not rendered"]
    scene = next((s for s in camera_object.users_scene if s.camera == camera_object), None)
    if scene is None or lens_type(camera_object.data) != "PERSP":
        return []
    settings = scene.relativity
    if settings.shutter_model == "PINHOLE":
        return [f"Camera {name!r}: Pinhole shutter ignores depth of field: choose Aperture Plane for a blurred image"]
    if settings.shutter_model == "FOCUS_SURFACE":
        warning = _focus_surface_warning(scene, camera_object)
        return [warning] if warning else []
    return []


def _focus_surface_warning(scene, camera_object):
    """The focus-surface shutter times each ray where it crosses the focus surface, so the ray
    passes the lens ``|L - P|/c`` after the shutter time; by then the camera has moved on, and
    what lies nearer than that surface at the shutter time is not photographed (a black frame when
    nothing is beyond it). One line when the axial ray's lens event is displaced noticeably."""
    settings = scene.relativity
    try:
        beta = snapshot.observer_velocity(scene, camera_object, snapshot.current_frame(scene))
    except RelativityError:
        return None
    speed = math.sqrt(sum(b * b for b in beta))
    focus = lens.focus_distance(camera_object)
    c = settings.speed_of_light
    if speed == 0.0 or focus is None or not (c > 0.0):
        return None
    lens_time = settings.shutter_time + focus / c  # the axial ray at the lens centre
    moved = speed / math.sqrt(1.0 - speed * speed) * c * lens_time  # eq. (1): gamma beta c t_L
    if moved <= 0.01 * focus:
        return None
    scale = scene.unit_settings.scale_length or 1.0
    return (
        f"Camera {camera_object.name!r}: the Focus Surface shutter times rays at the focus surface "
        f"{focus * scale:.3g} m ahead, so they reach the lens {lens_time:.3g} s after the shutter time, "
        f"{moved * scale:.3g} m further on: nearer objects are not photographed "
        f"(shutter time {-focus / c:.3g} s times them at the lens)"
    )


def _local_to_shader(vector):
    return (vector[0], vector[1], -vector[2])


def camera_frame_window(scene: Scene, camera_data: Camera) -> tuple[float, float, float, float]:
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


def shader_parameters(scene: Scene, camera_data: Camera, snap: Snapshot) -> dict[str, Any]:
    """Values for ``cycles_custom`` from the snapshot and the camera's lens and sensor."""
    left, right, bottom, top = camera_frame_window(scene, camera_data)
    unit_scale = scene.unit_settings.scale_length or 1.0
    return {
        "frame_left": left,
        "frame_right": right,
        "frame_bottom": bottom,
        "frame_top": top,
        "lens_focal_length": camera_data.lens * 1e-3 / unit_scale,
        "use_dof": lens_type(camera_data) == "PERSP" and camera_data.dof.use_dof,
        "aperture_scale": compat.custom_camera_aperture_scale(camera_data.lens * 1e-3 / unit_scale),
        "beta": _local_to_shader(snap.beta_camera),
        "speed_of_light": snap.speed_of_light,
        "shutter_model": snap.shutter_code,
        "shutter_time": snap.shutter_time,
        "shutter_plane_point": _local_to_shader(snap.shutter_plane_point),
        "shutter_plane_normal": _local_to_shader(snap.shutter_plane_normal),
        "use_lorentz_window": snap.use_lorentz_window,
        "phase_hologram": snap.imaging_element == "PHASE_HOLOGRAM",
        "window_with_shutter_model": snap.lorentz_window_shutter == "SHUTTER_MODEL",
        "window_time": snap.lorentz_window_time,
        "use_geometry": snap.use_geometry,
        "use_time_of_flight": snap.use_time_of_flight,
        "use_searchlight": snap.use_searchlight,
        "exposure": snap.exposure,
        "settings_valid": True,
        "use_eye_offset": stereo_eyes(scene),
        "camera_origin": tuple(float(row[3]) for row in snap.camera_matrix[:3]),
        **projection_parameters(scene, camera_data),
    }


def _same(current, value):
    if hasattr(current, "__len__") and hasattr(value, "__len__"):
        return len(current) == len(value) and all(a == b for a, b in zip(current, value, strict=True))
    return current == value


def _write_parameters(camera_data, values):
    """Write shader parameters, only those that changed (a write tags the camera for a depsgraph
    update, whose handler syncs again)."""
    custom = camera_data.cycles_custom
    changed = False
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
        if current is not None and _same(current, value):
            continue
        custom[name] = value
        changed = True
    if changed:
        camera_data.update_tag()


def _missing_parameters(camera_data):
    custom = camera_data.cycles_custom
    return [name for name in REQUIRED_PARAMETERS if name not in custom]


def compile_shader(camera_data: Camera) -> None:
    """Compile the camera's shader; raise RelativityError on any failure or empty result."""
    try:
        errors = osl.compile_custom_camera(camera_data)
    except osl.OSLUnavailableError as error:
        raise RelativityError(f"{error}: the relativistic camera needs it") from error
    if errors:
        raise RelativityError(f"Relativistic camera shader failed to compile: {errors[0]}")
    missing = _missing_parameters(camera_data)
    if missing or not camera_data.custom_bytecode:
        raise RelativityError(
            "Relativistic camera shader compiled to an empty shader "
            f"(missing parameters: {', '.join(missing) or 'bytecode'})"
        )


def _save_state(camera_data, render_only):
    custom = camera_data.cycles_custom
    camera_data[names.CAMERA_SAVED_STATE_KEY] = {
        "render_only": render_only,
        "type": camera_data.type,
        "custom_mode": camera_data.custom_mode,
        "custom_shader": camera_data.custom_shader.name if camera_data.custom_shader else "",
        "custom_filepath": camera_data.custom_filepath,
        "custom_bytecode": camera_data.custom_bytecode,
        "custom_bytecode_hash": camera_data.custom_bytecode_hash,
        "cycles_custom": {key: custom[key] for key in custom.keys()},
    }


def apply(scene: Scene, snap: Snapshot, render_only: bool = False) -> Object:
    """Turn the snapshot's camera into the relativistic OSL camera and write its parameters
    (``render_only``: for the time of a final render). Returns the camera object;
    RelativityError (one line), with the camera restored, on failure."""
    camera_object = scene.objects[snap.camera]
    camera_data = camera_object.data
    if not is_applied(camera_data):
        problem = type_problem(camera_object.name, camera_data)
        if problem is not None:
            raise RelativityError(problem)
        try:
            osl.ensure_oslquery_importable()
        except osl.OSLUnavailableError as error:
            raise RelativityError(f"{error}: the relativistic camera needs it") from error
        _save_state(camera_data, render_only)
        text = ensure_shader_text()
        with osl.compiling():
            camera_data.type = "CUSTOM"
            camera_data.custom_mode = "INTERNAL"
            camera_data.custom_shader = text
    elif camera_data.type != "CUSTOM":
        raise RelativityError(type_changed(camera_object))  # the user's change stays until Remove
    try:
        write(scene, snap)
    except RelativityError:
        remove(camera_object)
        raise
    return camera_object


def write(scene: Scene, snap: Snapshot) -> None:
    """Write the snapshot into the applied camera (compiling the shader if it is missing)."""
    camera_object = scene.objects[snap.camera]
    camera_data = camera_object.data
    if not is_applied(camera_data):
        raise RelativityError(f"Camera {camera_object.name!r} is not the relativistic camera")
    if camera_data.type != "CUSTOM":
        raise RelativityError(type_changed(camera_object))
    if lens_type(camera_data) == "PANO" and snap.shutter_model in LENS_SHUTTERS:
        name = snap.shutter_model.replace("_", " ").lower()
        raise RelativityError(
            f"The {name} shutter needs a perspective camera's lens: camera "
            f"{camera_object.name!r} is a panorama (use pinhole, aperture plane or arbitrary plane)"
        )
    if stereo_eyes(scene) and lens_type(camera_data) == "PANO":
        raise RelativityError(
            f"Camera {camera_object.name!r}: stereo panoramas (Blender's spherical stereo) "
            "are not rendered by the relativistic camera; switch Stereoscopy off"
        )
    if stereo_eyes(scene) and camera_data.stereo.convergence_mode == "TOE":
        raise RelativityError(
            f"Camera {camera_object.name!r}: toe-in stereo turns the eyes apart, so they cannot "
            "share one shutter plane; use off-axis or parallel convergence"
        )
    if _missing_parameters(camera_data) or not camera_data.custom_bytecode:
        ensure_shader_text()
        compile_shader(camera_data)
    _write_parameters(camera_data, shader_parameters(scene, camera_data, snap))


def invalidate(camera_object: Object | None) -> None:
    """Mark the camera's parameters invalid: the shader renders black, never a wrong image."""
    if camera_object is None or camera_object.type != "CAMERA" or not is_applied(camera_object.data):
        return
    if camera_object.data.cycles_custom.get("settings_valid", False):
        _write_parameters(camera_object.data, {"settings_valid": False})


def applied_cameras() -> list[Object]:
    return [obj for obj in bpy.data.objects if obj.type == "CAMERA" and is_applied(obj.data)]


def applied_camera_data() -> list[Camera]:
    """Every camera datablock holding the OSL camera, also one whose object was deleted (an
    orphan keeps the relativistic settings until it is restored)."""
    return [data for data in bpy.data.cameras if data.library is None and is_applied(data)]


def remove(camera_object: Object | None) -> bool:
    """Restore the camera exactly as it was before :func:`apply`; a Type the user chose after Set
    Up (no longer the OSL camera's Custom) stays."""
    if camera_object is None or camera_object.type != "CAMERA":
        return False
    return remove_data(camera_object.data)


def remove_data(camera_data: Camera) -> bool:
    """Restore camera data exactly as it was before :func:`apply` (its object may be gone)."""
    if not is_applied(camera_data):
        return False
    try:  # restoring the shader runs Cycles' update, which compiles it (in a freshly opened file too)
        osl.ensure_oslquery_importable()
    except osl.OSLUnavailableError:
        pass  # Cycles cannot compile then either: it reports that itself
    saved = camera_data[names.CAMERA_SAVED_STATE_KEY].to_dict()
    custom = camera_data.cycles_custom
    for key in list(custom.keys()):
        del custom[key]
    for key, value in saved.get("cycles_custom", {}).items():
        custom[key] = value
    with osl.compiling():
        _restore_shader(camera_data, saved)
    camera_data.update_tag()
    return True


def _restore_shader(camera_data: Camera, saved: dict) -> None:
    camera_data.custom_mode = saved["custom_mode"]
    shader = bpy.data.texts.get(saved["custom_shader"]) if saved["custom_shader"] else None
    ours = bpy.data.texts.get(names.SHADER_TEXT)
    last = ours is not None and not any(cam.custom_shader == ours for cam in bpy.data.cameras if cam != camera_data)
    if last and shader is None and camera_data.custom_shader == ours:
        # Deleting the text clears the pointer: Blender 4.5 counts this pointer of a file it opened
        # one user short, and clearing it by hand prints "ID user decrement error".
        bpy.data.texts.remove(ours)
    elif camera_data.custom_shader != shader:
        camera_data.custom_shader = shader
    camera_data.custom_filepath = saved["custom_filepath"]
    camera_data.custom_bytecode = saved["custom_bytecode"]
    camera_data.custom_bytecode_hash = saved["custom_bytecode_hash"]
    if camera_data.type == "CUSTOM":
        camera_data.type = saved["type"]
    del camera_data[names.CAMERA_SAVED_STATE_KEY]
    text = bpy.data.texts.get(names.SHADER_TEXT)
    if text is not None and not any(cam.custom_shader == text for cam in bpy.data.cameras):
        bpy.data.texts.remove(text)
