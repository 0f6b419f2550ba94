"""Lamps at rest lighting moving objects: Weiskopf et al. (1999) eq. 18 in the scene frame.

A lamp at rest in the scene frame lights an object moving with velocity ``beta`` (fraction of c,
scene frame). A photon from the lamp travelling along the unit direction ``k`` (scene frame) is
received by the object with Doppler factor (docs/physics.md, observer moving through the source's
frame)

    D = gamma (1 - beta . k)          (D > 1: the object runs into the light, blueshift)

Eq. 18 gives the object-frame spectral irradiance ``E'_lambda = D^5 cos(alpha') / r'^2 I_lambda(lambda D)``
(this project's ``D``; the paper writes its reciprocal) with ``alpha'`` and ``r'`` measured in the
object's frame. A renderer measures the distance in the scene (= the lamp's) frame: the emission
and absorption events are light-like separated, so ``r' = D r`` (eq. 25 in this convention), and

    E'_lambda = D^3 cos(alpha') / r^2 I_lambda(lambda D),    E' = D^2 cos(alpha') / r^2 I.

So at a given scene-frame distance a lamp straight ahead of an object at 0.5c (``D = sqrt(3)``)
delivers ``D^2 = 3`` times the irradiance of a lamp at rest relative to it, a lamp behind ``1/3``
(the often quoted ``D^4`` = 9 and 1/9 of eq. 19 hold at equal *object-frame* distance ``r'``; it is
the same relation). This is the plane-wave result: a wave's intensity transforms as ``D^2``.

Colour (Doppler colour on): the object-frame irradiance spectrum is the lamp's spectrum shifted
and scaled, ``D^-2 [D^5 I_lambda(lambda D)]``. The bracket is what the project's colour model
computes for an emitter seen with ``D``: ``M(D) rgb`` for an RGB lamp (up-sampled, lit by 6504 K
white, docs/spectral-model.md), and for a blackbody lamp at ``T`` a blackbody at ``D T`` with
luminance ``Y(D T) / Y(T)``. :func:`lamp_rgb_factor` gives the colour a copy of the lamp needs so
that Cycles' scene-frame irradiance ``cos(alpha) I / r^2`` becomes the object-frame one.

Per receiving point (point, spot and area lamps): a point ``x`` sees the lamp, in its own frame,
along ``-k'`` at the distance ``r' = D r``, i.e. at ``x - D r k'``, which lies on the line through
the lamp parallel to ``beta`` (:func:`apparent_lamp_offset`). Stand-in lamps on that line, the two
around that place weighted per receiving point (:func:`stand_in_weights`), give each point its own
``D`` and, exactly, its own aberrated direction (:func:`stand_in_irradiance` models what they
render). Suns (plane waves) and the former renderer's one ``D`` and one direction per lamp and
object (:func:`aberrated_lamp_matrix`) are measured against :func:`exact_irradiance` by
:func:`one_factor_irradiance` (docs/lamp-doppler.md).

numpy only (Blender's Python has no colour-science): the colour tables are those of
:mod:`.spectral_render`.
"""

import math

import numpy as np

from . import spectral_render
from .arrays import ArrayLike, FloatArray
from .validation import finite_array, positive_array, unit_vectors, velocity_array

IRRADIANCE_POWER = 2.0
"""``E'/E = D^2``: object-frame irradiance over scene-frame irradiance at the same event."""


def _gamma(beta: FloatArray) -> FloatArray:
    return 1.0 / np.sqrt(1.0 - np.sum(beta * beta, axis=-1))


def lamp_to_object_doppler(direction: ArrayLike, beta_object: ArrayLike) -> FloatArray:
    """``D = gamma (1 - beta . k)`` of light from a lamp at rest reaching an object moving with
    ``beta_object``; ``direction`` is the photon direction ``k`` (lamp -> object), scene frame."""
    k = unit_vectors(direction, "direction")
    beta = velocity_array(beta_object, "beta_object")
    return _gamma(beta) * (1.0 - np.sum(beta * k, axis=-1))


def irradiance_factor(doppler: ArrayLike) -> FloatArray:
    """``E'/E = D^2``: bolometric object-frame irradiance over the scene-frame irradiance Cycles
    computes at the same event (distance measured in the lamp's frame)."""
    return positive_array(doppler, "doppler") ** IRRADIANCE_POWER


def aberrated_direction(direction: ArrayLike, beta_object: ArrayLike) -> FloatArray:
    """The photon direction ``k'`` in the object's frame (docs/physics.md, aberration):
    ``k' = (k + (gamma - 1)(bhat.k) bhat - gamma beta) / (gamma (1 - beta.k))``."""
    k = unit_vectors(direction, "direction")
    beta = velocity_array(beta_object, "beta_object")
    gamma = _gamma(beta)[..., None]
    speed2 = np.sum(beta * beta, axis=-1, keepdims=True)
    bk = np.sum(beta * k, axis=-1, keepdims=True)
    along = np.where(speed2 > 0.0, (gamma - 1.0) * bk / np.where(speed2 > 0.0, speed2, 1.0), 0.0)
    return (k + along * beta - gamma * beta) / (gamma * (1.0 - bk))


def aberrated_disc_angle(direction: ArrayLike, beta_object: ArrayLike, angle: float) -> float:
    """The angular diameter (radians) in the object's frame of a disc of angular diameter
    ``angle`` (a sun) whose centre's light travels along ``direction`` (scene frame), for an
    object moving with ``beta_object``. Aberration maps circles on the sky to circles and is
    conformal (``dOmega' = dOmega / D^2``, docs/physics.md), so the disc stays a disc, ``angle / D``
    across when small; exactly, the angle between its two edges in the plane of ``k`` and ``beta``,
    each aberrated (:func:`aberrated_direction`)."""
    k = unit_vectors(direction, "direction")
    beta = velocity_array(beta_object, "beta_object")
    half = 0.5 * float(finite_array(angle, "angle"))
    axis = np.cross(k, beta)
    if np.linalg.norm(axis) < 1e-12:  # along the motion (or at rest): any axis across k
        axis = np.cross(k, np.eye(3)[int(np.argmin(np.abs(k)))])
    axis = axis / np.linalg.norm(axis)
    across = np.cross(axis, k)
    edges = [math.cos(half) * k + sign * math.sin(half) * across for sign in (1.0, -1.0)]
    first, second = (aberrated_direction(edge, beta) for edge in edges)
    return float(np.arccos(np.clip(first @ second / (np.linalg.norm(first) * np.linalg.norm(second)), -1.0, 1.0)))


def aberrated_lamp_matrix(
    lamp_matrix: ArrayLike, centre: ArrayLike, direction: ArrayLike, beta_object: ArrayLike
) -> FloatArray:
    """The lamp's 4x4 world matrix turned about ``centre`` so that its light arrives along the
    object-frame direction ``k'`` (:func:`aberrated_direction` of ``direction``, lamp -> centre)
    instead of ``k``: the rotation taking ``k`` to ``k'`` (smallest angle, about ``k x k'``) applied
    to the lamp's position about the centre and to its orientation. Cycles then lights the object
    from where it sees the lamp in its own frame (at the centre's direction)."""
    matrix = finite_array(lamp_matrix, "lamp_matrix").copy()
    k = unit_vectors(direction, "direction")
    k_object = aberrated_direction(k, beta_object)
    axis = np.cross(k, k_object)
    sine, cosine = float(np.linalg.norm(axis)), float(k @ k_object)
    if sine < 1e-12:
        return matrix  # on the axis of motion (or at rest): no aberration
    axis = axis / sine
    cross = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    rotation = np.eye(3) + sine * cross + (1.0 - cosine) * cross @ cross  # Rodrigues
    centre = finite_array(centre, "centre")
    matrix[:3, :3] = rotation @ matrix[:3, :3]
    matrix[:3, 3] = centre + rotation @ (matrix[:3, 3] - centre)
    return matrix


def lamp_rgb_factor(
    doppler: float,
    rgb: ArrayLike | None = None,
    temperature_k: float | None = None,
    use_doppler: bool = True,
    use_searchlight: bool = True,
) -> FloatArray:
    """Per-channel factor ``f`` (3,) so that a lamp of colour ``rgb`` (or a blackbody at
    ``temperature_k``, Blender's luminance-1 colour) with colour ``f * rgb`` lights the object
    as eq. 18 says, ``>= 0`` and finite.

    - Doppler and searchlight: ``D^-2 gamut(M(D) rgb) / rgb``; blackbody ``D^-2 Y(DT)/Y(T) rgb_unit(DT) / rgb_unit(T)``.
    - Doppler only (brightness kept): the same colours scaled to the lamp's own luminance.
    - searchlight only: ``D^2`` in every channel.
    - neither: 1.
    A channel the lamp does not emit (0) gets factor 0: its light cannot be made from nothing.
    """
    doppler = float(positive_array(doppler, "doppler"))
    if not use_doppler:
        return np.full(3, irradiance_factor(doppler) if use_searchlight else 1.0)
    if temperature_k is not None:
        rest = blackbody_unit_rgb(temperature_k)
        shifted = blackbody_unit_rgb(doppler * temperature_k)
        if use_searchlight:
            log_ratio = spectral_render.log_blackbody_luminance(
                doppler * temperature_k
            ) - spectral_render.log_blackbody_luminance(temperature_k)
            shifted = shifted * np.exp(min(float(log_ratio), 80.0)) / irradiance_factor(doppler)
    else:
        rest = finite_array(rgb if rgb is not None else (1.0, 1.0, 1.0), "rgb")
        shifted = spectral_render.gamut_map(spectral_render.doppler_rgb_matrix(doppler) @ rest)
        if use_searchlight:
            shifted = shifted / irradiance_factor(doppler)
        else:
            shifted = _same_luminance(shifted, rest)
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = np.where(rest > 1e-6, shifted / np.where(rest > 1e-6, rest, 1.0), 0.0)
    return np.clip(factor, 0.0, 1e30)


def blackbody_unit_rgb(temperature_k: float) -> FloatArray:
    """Linear Rec.709 colour of a blackbody at ``temperature_k``, gamut-mapped, luminance 1 (Blender's)."""
    rgb = spectral_render.xyz_to_linear_rec709(spectral_render.blackbody_xyz(temperature_k))
    mapped = spectral_render.gamut_map(rgb)
    y = float(spectral_render.luminance(mapped))
    return mapped / y if y > 0.0 and np.isfinite(y) else np.zeros(3)  # no visible light left (a few K)


def _same_luminance(rgb: FloatArray, reference: FloatArray) -> FloatArray:
    y, y0 = spectral_render.luminance(rgb), spectral_render.luminance(reference)
    return rgb * (y0 / y) if y > 0.0 else rgb * 0.0


# --- per receiving point: stand-in lamps on the line of apparent positions ---------------------


def apparent_lamp_offset(points: ArrayLike, lamp: ArrayLike, beta_object: ArrayLike) -> FloatArray:
    """Where a receiving point at ``points`` (scene frame) sees a lamp at rest at ``lamp`` in its
    own frame, as the offset ``u`` along ``bhat`` (the unit velocity): ``x - D r k' = lamp + u bhat``
    with ``u = r ((1 - gamma) (k . bhat) + gamma |beta|)``.

    The aberrated direction ``k'`` (:func:`aberrated_direction`) differs from ``k`` only along
    ``bhat`` and by the factor ``1 / D`` across it, so going back ``D r`` (the object-frame distance,
    eq. 25) along ``k'`` from ``x`` lands on the line through the lamp parallel to ``beta``: a light
    on that line at ``u`` is seen from ``x`` exactly along ``-k'``. 0 for an object at rest."""
    points = finite_array(points, "points")
    offset = points - finite_array(lamp, "lamp")
    r = np.linalg.norm(offset, axis=-1)
    k = offset / np.where(r > 0.0, r, 1.0)[..., None]
    beta = velocity_array(beta_object, "beta_object")
    speed = float(np.linalg.norm(beta))
    if speed == 0.0:
        return np.zeros_like(r)
    gamma = float(_gamma(beta))
    return r * ((1.0 - gamma) * (k @ (beta / speed)) + gamma * speed)


def stand_in_offsets(offsets: ArrayLike, distances: ArrayLike, max_angle: float, max_count: int) -> FloatArray:
    """Evenly spaced offsets (ascending) spanning the receiving points' ``offsets`` (from
    :func:`apparent_lamp_offset`), as many as keep neighbours within ``max_angle`` (radians) seen
    from the nearest point (object-frame ``distances`` ``D r``), at most ``max_count``."""
    offsets = finite_array(offsets, "offsets").ravel()
    low, high = float(offsets.min()), float(offsets.max())
    nearest = float(np.min(positive_array(distances, "distances")))
    count = 1 + math.ceil((high - low) / (max_angle * nearest)) if high > low else 1
    count = max(1, min(int(max_count), count))
    return np.array([0.5 * (low + high)]) if count == 1 else np.linspace(low, high, count)


def stand_in_weights(offsets: ArrayLike, stand_ins: ArrayLike) -> FloatArray:
    """Linear weights (..., n) of the stand-ins at ``stand_ins`` (ascending) for points whose lamp
    appears at ``offsets``: the two around it share 1; beyond the ends the end one takes all."""
    u = finite_array(offsets, "offsets")[..., None]
    at = finite_array(stand_ins, "stand_ins").ravel()
    before = np.concatenate([[-np.inf], at[:-1]])
    after = np.concatenate([at[1:], [np.inf]])
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        rising = np.where(np.isfinite(before), (u - before) / (at - before), 1.0)
        falling = np.where(np.isfinite(after), (after - u) / (after - at), 1.0)
    return np.clip(np.minimum(rising, falling), 0.0, 1.0)


def stand_in_irradiance(
    points: ArrayLike,
    rest_normals: ArrayLike,
    lamp: ArrayLike,
    beta_object: ArrayLike,
    stand_ins: ArrayLike,
    intensity: float = 1.0,
) -> FloatArray:
    """What the stand-ins render (bolometric): each at ``lamp + u_i bhat`` with strength
    ``w_i D^2 (t_i / r)^2 t_i / (D r)`` for the point (``t_i`` its distance to the stand-in, ``r``
    to the lamp, ``D r`` to where it sees the lamp), so Cycles' ``cos_i / t_i^2`` on the rest
    normal sums to ``D^2 cos(alpha') / r^2`` (:func:`exact_irradiance`) wherever both cosines are
    positive: the two stand-ins around the point and the apparent lamp ``P`` lie on one line, so
    with the linear weights ``P - x = sum_i w_i (P_i - x)``, i.e. ``-k' = sum_i w_i t_i / (D r) e_i``
    (``e_i`` toward stand-in ``i``), and the cosine is linear in that direction. Left: near the
    terminator one stand-in's cosine is clamped at 0 while the other's is not."""
    points = finite_array(points, "points")
    lamp = finite_array(lamp, "lamp")
    beta = velocity_array(beta_object, "beta_object")
    normals = unit_vectors(rest_normals, "rest_normals")
    speed = float(np.linalg.norm(beta))
    bhat = beta / speed if speed > 0.0 else np.zeros(3)
    offset = points - lamp
    r = np.linalg.norm(offset, axis=-1)
    doppler = lamp_to_object_doppler(offset, beta)
    weights = stand_in_weights(apparent_lamp_offset(points, lamp, beta), stand_ins)
    total = np.zeros_like(r)
    for index, u in enumerate(finite_array(stand_ins, "stand_ins").ravel()):
        towards = lamp + u * bhat - points
        t = np.linalg.norm(towards, axis=-1)
        cosine = np.maximum(np.sum(normals * towards, axis=-1) / t, 0.0)
        total += weights[..., index] * cosine * t / (doppler * r)
    return irradiance_factor(doppler) * total / r**2 * intensity


# --- what one factor per lamp and object leaves out --------------------------------------------


def exact_irradiance(
    points: ArrayLike, rest_normals: ArrayLike, lamp: ArrayLike, beta_object: ArrayLike, intensity: float = 1.0
) -> FloatArray:
    """Eq. 18 (bolometric) per point: ``E' = D^2 cos(alpha') / r^2 I``, with ``D`` from each
    point's own direction, ``alpha'`` between the object-frame (rest) normal and the object-frame
    photon direction, ``r`` the scene-frame distance from the lamp at rest. 0 where unlit."""
    points = finite_array(points, "points")
    offset = points - finite_array(lamp, "lamp")
    r = np.linalg.norm(offset, axis=-1)
    k = offset / r[..., None]
    doppler = lamp_to_object_doppler(k, beta_object)
    k_object = aberrated_direction(k, beta_object)
    cos_object = np.maximum(-np.sum(unit_vectors(rest_normals, "rest_normals") * k_object, axis=-1), 0.0)
    return irradiance_factor(doppler) * cos_object / r**2 * intensity


def one_factor_irradiance(
    points: ArrayLike,
    scene_normals: ArrayLike,
    lamp: ArrayLike,
    centre: ArrayLike,
    beta_object: ArrayLike,
    intensity: float = 1.0,
    aberrate: bool = True,
) -> FloatArray:
    """What the renderer computes: Cycles' scene-frame ``cos(alpha) / r^2 I`` on the scene-frame
    (contracted) surface from the lamp's copy (turned about ``centre`` to the aberrated direction
    with ``aberrate``), times ``D^2`` of the direction lamp -> ``centre``."""
    points = finite_array(points, "points")
    lamp = finite_array(lamp, "lamp")
    centre = finite_array(centre, "centre")
    doppler = lamp_to_object_doppler(centre - lamp, beta_object)
    if aberrate:
        placed = np.eye(4)
        placed[:3, 3] = lamp
        lamp = aberrated_lamp_matrix(placed, centre, centre - lamp, beta_object)[:3, 3]
    offset = points - lamp
    r = np.linalg.norm(offset, axis=-1)
    k = offset / r[..., None]
    cos_scene = np.maximum(-np.sum(unit_vectors(scene_normals, "scene_normals") * k, axis=-1), 0.0)
    return irradiance_factor(doppler) * cos_scene / r**2 * intensity


def contracted_sphere(
    radius: float, centre: ArrayLike, beta_object: ArrayLike, count: int = 4000
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Points, scene-frame normals and rest-frame normals of a sphere of rest radius ``radius``
    moving with ``beta_object``, Lorentz-contracted about ``centre`` at one scene time (a
    Fibonacci lattice of ``count`` points)."""
    beta = velocity_array(beta_object, "beta_object")
    index = np.arange(count) + 0.5
    z = 1.0 - 2.0 * index / count
    phi = np.pi * (1.0 + 5.0**0.5) * index
    rest_normals = np.stack([np.sqrt(1.0 - z * z) * np.cos(phi), np.sqrt(1.0 - z * z) * np.sin(phi), z], axis=-1)
    speed = float(np.linalg.norm(beta))
    bhat = beta / speed if speed > 0.0 else np.zeros(3)
    gamma = float(_gamma(beta))
    contraction = np.eye(3) - (1.0 - 1.0 / gamma) * np.outer(bhat, bhat)
    points = np.asarray(centre, dtype=np.float64) + radius * rest_normals @ contraction.T
    scene_normals = rest_normals @ np.linalg.inv(contraction)  # inverse transpose (symmetric)
    return points, scene_normals / np.linalg.norm(scene_normals, axis=-1, keepdims=True), rest_normals
