"""The camera's lens as the exact camera takes it: its own type, focal length and focus distance, and
the Detector Plane shutter's check that a real image forms (``physics/shutter.image_distance``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...errors import RelativityError
from ...physics.shutter import image_distance
from ..common import names

if TYPE_CHECKING:
    import numpy.typing as npt
    from bpy.types import Object, Scene
    from mathutils import Matrix


def camera_lens_type(camera: Object) -> str:
    """The camera's own type (PERSP, PANO, ...), also while the exact camera has made it CUSTOM."""
    saved = camera.data.get(names.CAMERA_SAVED_STATE_KEY)
    return saved["type"] if saved is not None else camera.data.type


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
    if camera_lens_type(camera) != "PERSP":
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
