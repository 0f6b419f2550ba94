"""The camera's lens as the add-on reads it once per snapshot: its own type, its projection (the
perspective view window or a panorama's parameters), stereo eyes, focal length and focus distance,
and the Detector Plane shutter's check that a real image forms (``physics/shutter.image_distance``).
The exact camera and the world's Doppler pixels take these from the snapshot, not from the camera."""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from ...errors import RelativityError
from ...physics.shutter import image_distance
from ..common import names

if TYPE_CHECKING:
    import numpy.typing as npt
    from bpy.types import Camera, Object, Scene
    from mathutils import Matrix

# The panoramas the exact camera renders, as its shader numbers them.
PANORAMA_PROJECTIONS = {"EQUIRECTANGULAR": 1, "FISHEYE_EQUIDISTANT": 2, "FISHEYE_EQUISOLID": 3, "MIRRORBALL": 4}


def lens_type(camera_data: Camera) -> str:
    """The camera's own type (PERSP, PANO, ...), also while the exact camera has made it CUSTOM."""
    saved = camera_data.get(names.CAMERA_SAVED_STATE_KEY)
    return str(saved["type"]) if saved is not None else str(camera_data.type)


def stereo_eyes(scene: Scene) -> bool:
    """Whether the scene renders Blender's stereo pair (each eye offset from the camera)."""
    render = scene.render
    return bool(render.use_multiview and render.views_format == "STEREO_3D")


def view_window(scene: Scene, camera: Object) -> tuple[float, float, float, float]:
    """The camera's image on the plane at unit distance: ``(left, right, bottom, top)`` in its
    local axes (Blender's own view frame: sensor fit, aspect and shift included)."""
    corners = camera.data.view_frame(scene=scene)
    xs = [corner.x / -corner.z for corner in corners]
    ys = [corner.y / -corner.z for corner in corners]
    return min(xs), max(xs), min(ys), max(ys)


def _fitted_sensor(scene: Scene, camera_data: Camera) -> tuple[float, float]:
    """Sensor width and height (mm) as Blender fits them to the image (fisheye equisolid)."""
    render = scene.render
    x_ratio = render.resolution_x * render.pixel_aspect_x
    y_ratio = render.resolution_y * render.pixel_aspect_y
    fit = camera_data.sensor_fit
    horizontal = x_ratio > y_ratio if fit == "AUTO" else fit == "HORIZONTAL"
    size = camera_data.sensor_height if fit == "VERTICAL" else camera_data.sensor_width
    if horizontal:
        return size, size * y_ratio / x_ratio
    return size * x_ratio / y_ratio, size


def projection_parameters(scene: Scene, camera_data: Camera) -> dict[str, float]:
    """A panorama's parameters as the exact camera's shader takes them (``projection`` 0: perspective)."""
    kind = lens_type(camera_data)
    projection = PANORAMA_PROJECTIONS.get(camera_data.panorama_type, 0) if kind == "PANO" else 0
    sensor_width, sensor_height = _fitted_sensor(scene, camera_data)
    return {
        "projection": projection,
        "longitude_min": camera_data.longitude_min,
        "longitude_max": camera_data.longitude_max,
        "latitude_min": camera_data.latitude_min,
        "latitude_max": camera_data.latitude_max,
        "fisheye_fov": camera_data.fisheye_fov,
        "fisheye_lens": camera_data.fisheye_lens,
        "sensor_width": sensor_width,
        "sensor_height": sensor_height,
    }


def projection(scene: Scene, camera: Object) -> tuple:
    """What the camera's image is, for the snapshot: ``("PERSP", left, right, bottom, top)`` (the
    view window), ``(panorama_type, (name, value), ...)`` (sorted parameters), or ``(type,)`` for a
    camera the exact camera does not take (orthographic, an unsupported panorama)."""
    data = cast("Camera", camera.data)
    kind = lens_type(data)
    if kind == "PERSP":
        return ("PERSP", *view_window(scene, camera))
    if kind == "PANO":
        parameters = projection_parameters(scene, data)
        parameters.update(shift_x=data.shift_x, shift_y=data.shift_y)
        return (data.panorama_type, *sorted((key, float(value)) for key, value in parameters.items()))
    return (kind,)


def focal_length(scene: Scene, camera: Object) -> float:
    """The camera's focal length in scene units."""
    return camera.data.lens * 1e-3 / (scene.unit_settings.scale_length or 1.0)


def focus_distance(camera: Object, matrix: Matrix | npt.ArrayLike | None = None) -> float | None:
    """The focus distance (scene units) of a camera with depth of field on, as Cycles takes it (a
    focus object's distance along the view axis); None with depth of field off."""
    dof = camera.data.dof
    if not dof.use_dof:
        return None
    if dof.focus_object is None:
        return float(dof.focus_distance)
    matrix = np.array(camera.matrix_world if matrix is None else matrix, dtype=np.float64)
    axis = -matrix[:3, 2] / max(np.linalg.norm(matrix[:3, 2]), 1e-30)
    return float(axis @ (np.array(dof.focus_object.matrix_world.translation, dtype=np.float64) - matrix[:3, 3]))


def check_detector_image(scene: Scene, camera: Object, matrix: Matrix | npt.ArrayLike | None = None) -> None:
    """RelativityError (one line) when the detector-plane shutter has no detector: depth of field on
    with the focus inside the focal length (the thin lens forms no real image). Depth of field off,
    the detector is Blender's sensor at the focal length (``shutter.image_distance``)."""
    if lens_type(cast("Camera", camera.data)) != "PERSP":
        return
    focus = focus_distance(camera, matrix)
    f = focal_length(scene, camera)
    try:
        image_distance(f, focus)
    except ValueError:
        scale = scene.unit_settings.scale_length or 1.0
        raise RelativityError(
            f"Camera {camera.name!r}: focus distance {focus * scale:.3g} m is inside the focal "
            f"length {f * scale:.3g} m: no image forms (Detector Plane shutter)"
        ) from None
