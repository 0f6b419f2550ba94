"""Light bounced from one moving surface onto another: what the static snapshot leaves out
(docs/lamp-doppler.md, "Light bounced between moving objects"; docs/physics.md, "Radiance" and
"Light-travel time").

Cycles renders one snapshot: every point where the camera sees it. A bounce ray from a receiving
point ``R`` meets the emitter's snapshot at ``x`` and carries the scene-frame radiance the
emitter's material sends along ``k_snap`` (``x -> R``). Physically ``R`` sees the emitter's point
(the same material point, rest normal ``n``) where it was when the light reaching ``R`` left it,
and receives the radiance in its own frame. Per bounce ray, the factor that turns the snapshot's
contribution into the physical one (a change of variables over the emitter's rest surface) is

    F = J * (D_s(k) / D_s(k_snap))^4 * D_p(k)^2 * c_p

- ``k``: the photon direction from the point where ``R`` sees it (its retarded position for the
  event of ``R``, uniform motion, :func:`emission_seen_from`) to ``R``;
- ``J``: the solid angle the rest-surface element subtends at ``R`` physically over the one its
  snapshot image subtends (:func:`solid_angle_ratio`);
- ``D_s = 1 / (gamma_s (1 - beta_s . k))``: the emitter's searchlight (eq. 14) along ``k``
  instead of ``k_snap``;
- ``D_p = gamma_p (1 - beta_p . k)``: the receiver's frame; radiance ``D_p^4`` times solid angle
  ``1 / D_p^2`` (Weiskopf et al. eqs. 13, 15);
- ``c_p``: the receiver's cosine with the photon direction aberrated into its frame, on its rest
  normal, over the snapshot's cosine (``k_snap`` on the same normal): 1 when the normal is not
  known (:func:`receiver_factor`).

Positions are in scene units in the frame where the observer is at rest; times are light-travel
path lengths, every snapshot point at ``|point - camera|`` before the camera event; velocities are
fractions of c. Not in ``F``: the emitter's own light at the other emission time (a lamp lights it
from elsewhere then), which one snapshot does not hold.
"""

import numpy as np

from .arrays import ArrayLike, FloatArray
from .lorentz import aberrate
from .retarded import light_travel_time_uniform
from .validation import unit_vectors, vector_array, velocity_array

MAX_SOLID_ANGLE_RATIO = 4.0  # a cap on J against fireflies (docs/lamp-doppler.md: the model's means do not feel it)
# A cap on c_p: where the receiver's normal is not its own (a curved receiver takes its box face's)
# the snapshot's cosine can be near 0 while the physical one is not; a 45-degree error made the
# model's mean 7e9x the physics approaching, capped 1.57x (docs/lamp-doppler.md, "Many moving objects").
MAX_COSINE_RATIO = 4.0


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.sum(a * b, axis=-1)


def _gamma(beta: FloatArray) -> FloatArray:
    return 1.0 / np.sqrt(1.0 - _dot(beta, beta))


def emission_seen_from(
    emitted_at: ArrayLike, emitter_beta: ArrayLike, received_at: ArrayLike, camera: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Where the receiving point sees the emitter's point whose snapshot position is ``emitted_at``.

    The point's world line is ``x(t) = emitted_at + beta_s (t - t_x)`` with ``t_x = -|emitted_at -
    camera|`` (path lengths, camera event at 0); the receiving event is ``(-|received_at -
    camera|, received_at)``. Returns the emission position and the path length ``tau`` to the
    receiving point (docs/physics.md's closed form for uniform motion).
    """
    x = vector_array(emitted_at, "emitted_at")
    beta = velocity_array(emitter_beta, "emitter_beta")
    r = vector_array(received_at, "received_at")
    eye = vector_array(camera, "camera")
    t_x = -np.linalg.norm(x - eye, axis=-1)
    t_r = -np.linalg.norm(r - eye, axis=-1)
    at_reception = x + (t_r - t_x)[..., None] * beta
    tau = light_travel_time_uniform(t_r, r, at_reception, beta, 1.0)
    return at_reception - tau[..., None] * beta, tau


def _stretch(v: FloatArray, beta: FloatArray) -> FloatArray:
    """``C^-1 v``: the scene-frame contraction along ``beta`` undone (``gamma`` along it)."""
    speed_squared = _dot(beta, beta)
    gamma = _gamma(beta)
    along = np.where(speed_squared > 0.0, _dot(beta, v) / np.where(speed_squared > 0.0, speed_squared, 1.0), 0.0)
    return v + ((gamma - 1.0) * along)[..., None] * beta


def solid_angle_ratio(
    emitted_at: ArrayLike,
    rest_normals: ArrayLike,
    emitter_beta: ArrayLike,
    received_at: ArrayLike,
    camera: ArrayLike,
) -> FloatArray:
    """``J``: solid angle at ``R`` of a rest-surface element physically over that of its snapshot image.

    Physically (in the emitter's frame the element subtends ``dA cos(theta') / r'^2``, ``theta'``
    between the rest normal and the photon direction there; to the scene frame ``dOmega / D_s^2``
    and ``r = D_s r'``): ``dA cos(theta') / tau^2``. The snapshot maps rest offsets by
    ``A = (I - beta chat^T / (1 + chat . beta)) C`` (``chat`` camera -> point: each point where
    the camera sees it), so its image subtends ``dA det(A) n . A^-1 k_snap / d^2`` with
    ``det A = 1 / (gamma (1 + chat . beta))`` and ``A^-1 k = C^-1 (k + beta (chat . k))``.
    Zero where the element faces away physically or its snapshot image would face away; at most
    :data:`MAX_SOLID_ANGLE_RATIO`: near the snapshot's outline the image is seen edge-on and the
    ratio diverges (integrable, but single rays there would be fireflies).
    """
    x = vector_array(emitted_at, "emitted_at")
    n = unit_vectors(rest_normals, "rest_normals")
    beta = velocity_array(emitter_beta, "emitter_beta")
    r = vector_array(received_at, "received_at")
    eye = vector_array(camera, "camera")
    source, tau = emission_seen_from(x, beta, r, eye)
    k = (r - source) / tau[..., None]
    cos_rest = np.maximum(_dot(n, aberrate(k, np.broadcast_to(beta, k.shape))), 0.0)
    to_r = r - x
    d = np.linalg.norm(to_r, axis=-1)
    k_snap = to_r / d[..., None]
    chat = unit_vectors(x - eye, "emitted_at - camera")
    det = 1.0 / (_gamma(beta) * (1.0 + _dot(chat, beta)))
    snapshot = det * _dot(_stretch(n, beta), k_snap + _dot(chat, k_snap)[..., None] * beta)
    ratio = cos_rest * d**2 / (tau**2 * np.where(snapshot > 0.0, snapshot, 1.0))
    result: FloatArray = np.where(snapshot > 0.0, np.minimum(ratio, MAX_SOLID_ANGLE_RATIO), 0.0)
    return result


def receiver_factor(
    k: ArrayLike, receiver_beta: ArrayLike, k_snapshot: ArrayLike, receiver_normals: ArrayLike | None = None
) -> FloatArray:
    """``D_p^2 c_p``: the receiver's frame. ``D_p = gamma_p (1 - beta_p . k)`` (radiance ``D_p^4``,
    solid angle ``1 / D_p^2``); ``c_p`` the cosine of ``k`` aberrated into the receiver's frame on
    its rest normal over the snapshot's cosine (``k_snapshot`` on the same normal), at most
    :data:`MAX_COSINE_RATIO`; 1 without normals."""
    k = unit_vectors(k, "k")
    beta = np.broadcast_to(velocity_array(receiver_beta, "receiver_beta"), k.shape)
    doppler: FloatArray = _gamma(beta) * (1.0 - _dot(beta, k))
    if receiver_normals is None:
        return doppler * doppler
    n = unit_vectors(receiver_normals, "receiver_normals")
    snapshot = -_dot(unit_vectors(k_snapshot, "k_snapshot"), n)
    physical = np.maximum(-_dot(aberrate(k, beta), n), 0.0)
    result: FloatArray = doppler**2 * np.minimum(physical / np.maximum(snapshot, 1e-12), MAX_COSINE_RATIO)
    return result


def bounce_correction(
    emitted_at: ArrayLike,
    rest_normals: ArrayLike,
    emitter_beta: ArrayLike,
    received_at: ArrayLike,
    receiver_beta: ArrayLike,
    camera: ArrayLike,
    receiver_normals: ArrayLike | None = None,
) -> FloatArray:
    """``F``, the factor on the radiance the snapshot point ``emitted_at`` sends to ``received_at``
    (module docstring); ``receiver_normals`` None takes ``c_p`` as 1."""
    x = vector_array(emitted_at, "emitted_at")
    beta_s = velocity_array(emitter_beta, "emitter_beta")
    r = vector_array(received_at, "received_at")
    source, tau = emission_seen_from(x, beta_s, r, camera)
    k = (r - source) / tau[..., None]
    k_snap = unit_vectors(r - x, "received_at - emitted_at")
    beta_s = np.broadcast_to(beta_s, k.shape)
    searchlight = ((1.0 - _dot(beta_s, k_snap)) / (1.0 - _dot(beta_s, k))) ** 4  # (D_s(k) / D_s(k_snap))^4
    geometry = solid_angle_ratio(x, rest_normals, beta_s, r, camera)
    result: FloatArray = geometry * searchlight * receiver_factor(k, receiver_beta, k_snap, receiver_normals)
    return result
