"""Photo-ray timing of Gray et al. (2020), "Relativistic photography with a wide aperture".

All positions are in the camera frame, with the aperture centre at the origin; ``beta`` is the
camera's velocity in the scene frame expressed in camera coordinates. A photo ray ends at detector
point ``D``, passes lens point ``L`` coming from the object point ``P`` conjugate to ``D``; its
forward (propagation) direction is ``d = (L - P) / |L - P|``. The shutter model fixes the camera
time ``t_L`` at which the ray passes ``L`` (docs/physics.md, "Relativistic camera"); Gray eqs. (1)
and (2) then carry the ray into the scene frame, where the scene is at rest and timing no longer
matters.
"""

import enum

import numpy as np

from .arrays import ArrayLike, FloatArray
from .lorentz import _aberrate, _boost
from .validation import finite_array, speed_of_light, unit_vectors, vector_array, velocity_array


class ShutterModel(enum.IntEnum):
    """Where the camera's instantaneous shutter sits (Gray et al. section 3, appendix B).

    The integer values are the codes of the OSL camera's ``shutter_model`` parameter
    (``SHUTTER_*`` in ``shaders/relativistic_camera.osl``) and the order of the add-on's
    ``shutter_model`` enum property; the names are that property's identifiers.
    ``ShutterModel("PINHOLE")`` (by name) works as well as ``ShutterModel(0)``.
    """

    PINHOLE = 0  # every ray passes the aperture centre at t_S
    APERTURE_PLANE = 1  # every ray passes its lens point at t_S
    DETECTOR_PLANE = 2  # every ray reaches the detector at t_S
    FOCUS_SURFACE = 3  # every ray passes the focus surface at t_S
    FIXED_POINT_SURFACE = 4  # each focus point P at its fixed-point time (eq. 4)
    ARBITRARY_PLANE = 5  # every ray crosses a given plane at t_S (appendix B)

    @classmethod
    def _missing_(cls, value: object) -> "ShutterModel | None":
        if isinstance(value, str) and value in cls.__members__:
            return cls.__members__[value]
        return None


# The models' names in code order: the identifiers of the add-on's shutter_model property.
SHUTTER_MODEL_NAMES: tuple[str, ...] = tuple(model.name for model in ShutterModel)


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.sum(a * b, axis=-1)


def fixed_point_time(position: ArrayLike, beta: ArrayLike, c: float) -> FloatArray:
    """Gray et al. eq. (4): the camera time at which ``position`` is a spatial fixed point of
    eq. (1), i.e. maps to itself in the scene frame.

    t = (1 - gamma)(beta·x) / (c gamma beta^2) = -gamma (beta·x) / ((gamma + 1) c),
    the second form being finite at beta = 0 (where every point is fixed at t = 0).
    """
    c = speed_of_light(c)
    x = vector_array(position, "position")
    beta = velocity_array(beta)
    gamma = 1.0 / np.sqrt(1.0 - _dot(beta, beta))
    return -gamma * _dot(beta, x) / ((gamma + 1.0) * c)


def fixed_point_plane(shutter_time: float, beta: ArrayLike, c: float) -> tuple[FloatArray, FloatArray]:
    """Gray et al. eq. (6): the plane of spatial fixed points of eq. (1) at camera time ``t_S``,

        -beta·x = ((gamma + 1) / gamma) c t_S,

    returned as ``(point, unit_normal)`` with the normal along beta. The place for a Lorentz
    window. At beta = 0 there is no such plane (every point is fixed at t_S = 0, none otherwise):
    ``ValueError``.
    """
    c = speed_of_light(c)
    t_s = float(finite_array(shutter_time, "shutter_time"))
    beta = velocity_array(beta)
    if beta.ndim != 1:
        raise ValueError("fixed_point_plane takes a single velocity")
    speed_squared = float(_dot(beta, beta))
    if speed_squared == 0.0:
        raise ValueError("a camera at rest has no plane of fixed points: beta must be non-zero")
    gamma = 1.0 / np.sqrt(1.0 - speed_squared)
    point = -((gamma + 1.0) / gamma) * c * t_s * beta / speed_squared
    return point, beta / np.sqrt(speed_squared)


def image_distance(focal_length: float, focus_distance: float | None = None) -> float:
    """Thin-lens distance from the lens to the detector, ``1/s = 1/f - 1/u``, for a lens of focal
    length ``f`` focused at distance ``u`` (both in one length unit).

    ``focus_distance=None`` (or infinite) is the lens focused at infinity, the detector at the
    focal length: Blender's perspective camera with depth of field off, a pinhole whose sensor
    sits ``f`` behind it. The detector-plane shutter's rays then reach that sensor at ``t_S``.
    ``u <= f`` forms no real image (the rays from the focus point diverge behind the lens):
    ``ValueError``.
    """
    f = float(focal_length)
    if not (np.isfinite(f) and f > 0.0):
        raise ValueError("the focal length must be positive and finite")
    if focus_distance is None or np.isposinf(focus_distance):
        return f
    u = float(focus_distance)
    if not u > f:
        raise ValueError(f"a lens of focal length {f:g} focused at {u:g} forms no real image")
    return 1.0 / (1.0 / f - 1.0 / u)


def lens_time(
    model: ShutterModel | int | str,
    lens_point: ArrayLike,
    object_point: ArrayLike,
    *,
    c: float,
    shutter_time: ArrayLike = 0.0,
    detector_point: ArrayLike | None = None,
    beta: ArrayLike | None = None,
    plane_point: ArrayLike | None = None,
    plane_normal: ArrayLike | None = None,
    ideal_lens: bool = True,
) -> FloatArray:
    """Camera time ``t_L`` at which a photo ray passes its lens point, for a shutter model.

    | model               | t_L                                                   |
    |---------------------|-------------------------------------------------------|
    | PINHOLE             | t_S (``lens_point`` is the aperture centre)           |
    | APERTURE_PLANE      | t_S                                                   |
    | DETECTOR_PLANE      | t_S - |D - L| / c - delay(L) (needs ``detector_point``)|
    | FOCUS_SURFACE       | t_S + |L - P| / c                                     |
    | FIXED_POINT_SURFACE | t_P + |L - P| / c, t_P from eq. (4)   (needs ``beta``)|
    | ARBITRARY_PLANE     | t_S + ((L - P0)·n) / (c d·n)  (needs plane P0, n)     |

    ``t_L`` is the time the ray enters the (thin) lens from the object side. An ideal lens obeys
    the principle of equal optical path: every ray from ``P`` to ``D`` takes the same time, that
    of the chief ray through the aperture centre, so the lens delays the ray through ``L`` by
    ``delay(L) = (|P| + |D| - |P - L| - |L - D|) / c`` (zero for the chief ray). This is what
    makes the detector-plane shutter stigmatic (Gray et al. section 3B). ``ideal_lens=False``
    models a phase hologram of a lens (no delays; Gray et al. Fig. 6b), which blurs. The other
    models fix the ray's time on the object side of the lens, where the delay plays no part.

    For the arbitrary plane, the ray crosses the plane at ``S = L - a d`` with
    ``(S - P0)·n = 0``, so ``a = (L - P0)·n / (d·n)`` and ``t_L = t_S + a / c``. Gray et al.'s
    eq. (B5) (and docs/physics.md's table) print ``(P0 - L)·n``, which is the same expression when
    ``d`` is the backward (tracing) direction; with the forward ``d`` used here the sign of the
    numerator is ``L - P0`` (a shutter plane in front of the lens is crossed *before* ``L``).
    """
    model = ShutterModel(model)
    c = speed_of_light(c)
    t_s = finite_array(shutter_time, "shutter_time")
    lens = vector_array(lens_point, "lens_point")
    obj = vector_array(object_point, "object_point")
    if model in (ShutterModel.PINHOLE, ShutterModel.APERTURE_PLANE):
        return np.broadcast_to(t_s, np.broadcast_shapes(t_s.shape, lens.shape[:-1], obj.shape[:-1])).copy()
    if model is ShutterModel.DETECTOR_PLANE:
        if detector_point is None:
            raise ValueError("the detector-plane shutter needs detector_point")
        detector = vector_array(detector_point, "detector_point")
        lens_to_detector = np.linalg.norm(detector - lens, axis=-1) / c
        if not ideal_lens:
            return t_s - lens_to_detector
        chief_ray = (np.linalg.norm(obj, axis=-1) + np.linalg.norm(detector, axis=-1)) / c
        return t_s - chief_ray + np.linalg.norm(lens - obj, axis=-1) / c
    if model is ShutterModel.FOCUS_SURFACE:
        return t_s + np.linalg.norm(lens - obj, axis=-1) / c
    if model is ShutterModel.FIXED_POINT_SURFACE:
        if beta is None:
            raise ValueError("the fixed-point-surface shutter needs beta")
        return fixed_point_time(obj, beta, c) + np.linalg.norm(lens - obj, axis=-1) / c
    if plane_point is None or plane_normal is None:
        raise ValueError("the arbitrary-plane shutter needs plane_point and plane_normal")
    d = unit_vectors(lens - obj, "lens_point - object_point")
    normal = unit_vectors(plane_normal, "plane_normal")
    d_n = _dot(d, normal)
    if np.any(np.abs(d_n) < 1e-12):
        raise ValueError("a photo ray runs parallel to the shutter plane and never crosses it")
    a = _dot(lens - vector_array(plane_point, "plane_point"), normal) / d_n
    return t_s + a / c


def photo_ray_in_scene(
    lens_point: ArrayLike, object_point: ArrayLike, lens_time: ArrayLike, beta: ArrayLike, c: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """A camera-frame photo ray carried into the scene frame (Gray et al. eqs. 1 and 2).

    The event of the ray at ``L`` at camera time ``t_L`` maps by eq. (1); the forward direction
    ``d = (L - P)/|L - P|`` by eq. (2). Returns ``(scene_time, scene_origin, scene_direction)``
    with ``scene_direction`` the unit forward direction; a backward ray tracer starts at
    ``scene_origin`` and traces along ``-scene_direction``.
    """
    c = speed_of_light(c)
    lens = vector_array(lens_point, "lens_point")
    d = unit_vectors(lens - vector_array(object_point, "object_point"), "lens_point - object_point")
    beta = velocity_array(beta)
    scene_time, scene_origin = _boost(finite_array(lens_time, "lens_time"), lens, -beta, c)
    return scene_time, scene_origin, _aberrate(d, -beta)


def lorentz_window_ray(
    lens_point: ArrayLike,
    object_point: ArrayLike,
    lens_time: ArrayLike,
    beta: ArrayLike,
    c: float,
    window_point: ArrayLike,
    window_normal: ArrayLike,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """A photo ray through a Lorentz-transformation window, carried into the scene frame.

    The window (Gray et al. section 4) changes a ray's direction exactly as the change of frame
    does, so it cancels eq. (2): beyond the window the scene-frame ray keeps its camera-frame
    direction ``d``. It starts from the scene-frame event of the ray crossing the window plane
    (point ``W``, camera time ``t_W = t_L - |L - W| / c``). With the window in the plane of fixed
    points for ``t_S`` (:func:`fixed_point_plane`) and rays crossing it at ``t_S``, that event is
    ``W`` itself, so the photo equals the photo at rest. Returns as :func:`photo_ray_in_scene`.
    """
    c = speed_of_light(c)
    lens = vector_array(lens_point, "lens_point")
    d = unit_vectors(lens - vector_array(object_point, "object_point"), "lens_point - object_point")
    normal = unit_vectors(window_normal, "window_normal")
    d_n = _dot(d, normal)
    if np.any(np.abs(d_n) < 1e-12):
        raise ValueError("a photo ray runs parallel to the Lorentz window and never crosses it")
    a = _dot(lens - vector_array(window_point, "window_point"), normal) / d_n
    window_crossing = lens - a[..., None] * d
    window_time = finite_array(lens_time, "lens_time") - a / c
    scene_time, scene_origin = _boost(window_time, window_crossing, -velocity_array(beta), c)
    return scene_time, scene_origin, d
