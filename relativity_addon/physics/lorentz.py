"""Lorentz boosts of events, photon directions and velocities (docs/physics.md, "Lorentz boost").

Convention throughout: frame S' moves with velocity ``beta * c`` relative to frame S, axes
parallel. Arrays broadcast: times have shape ``(...)``, positions, directions and velocities
``(..., 3)``. The factor ``(gamma - 1) / beta^2`` is written ``gamma^2 / (gamma + 1)``, which is
the same number but stays finite at ``beta = 0``.
"""

import numpy as np

from .arrays import ArrayLike, FloatArray
from .validation import finite_array, speed_of_light, unit_vectors, vector_array, velocity_array


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.sum(a * b, axis=-1)


def lorentz_factor(beta: ArrayLike) -> FloatArray:
    """gamma = 1 / sqrt(1 - beta·beta) for velocities ``beta`` (fractions of c), shape ``(...)``."""
    beta = velocity_array(beta)
    return 1.0 / np.sqrt(1.0 - _dot(beta, beta))


def _boost(t: FloatArray, x: FloatArray, beta: FloatArray, c: float) -> tuple[FloatArray, FloatArray]:
    gamma = 1.0 / np.sqrt(1.0 - _dot(beta, beta))
    beta_x = _dot(beta, x)
    ct = c * t
    x_boosted = x + ((gamma * gamma / (gamma + 1.0)) * beta_x - gamma * ct)[..., None] * beta
    t_boosted = gamma * (ct - beta_x) / c
    return t_boosted, x_boosted


def boost_event(t: ArrayLike, x: ArrayLike, beta: ArrayLike, c: float) -> tuple[FloatArray, FloatArray]:
    """Event ``(t, x)`` in S seen in S' (S' moves with ``beta`` in S).

    x' = x + (gamma - 1)(bhat·x) bhat - gamma beta c t,   c t' = gamma (c t - beta·x).

    Returns ``(t', x')``; ``t`` in seconds, ``x`` in scene units, ``c`` in scene units per second.
    """
    c = speed_of_light(c)
    return _boost(finite_array(t, "t"), vector_array(x, "x"), velocity_array(beta), c)


def inverse_boost_event(
    t_prime: ArrayLike, x_prime: ArrayLike, beta: ArrayLike, c: float
) -> tuple[FloatArray, FloatArray]:
    """Event ``(t', x')`` in S' seen in S: the boost with ``-beta``.

    This is Gray et al. eq. (1) when S' is the camera frame and ``beta`` the camera's velocity in
    the scene frame S: x = x' + (gamma - 1)(bhat·x') bhat + gamma beta c t'.
    """
    c = speed_of_light(c)
    return _boost(finite_array(t_prime, "t'"), vector_array(x_prime, "x'"), -velocity_array(beta), c)


camera_to_scene_event = inverse_boost_event
camera_to_scene_event.__doc__ = inverse_boost_event.__doc__


def aberrate(k: ArrayLike, beta: ArrayLike) -> FloatArray:
    """Unit photon propagation direction ``k`` in S seen in S' (S' moves with ``beta`` in S).

    k' = (k + (gamma - 1)(bhat·k) bhat - gamma beta) / (gamma (1 - beta·k)).

    The result is a unit vector (the transform preserves the null norm of the photon's
    4-momentum); it is renormalised to remove rounding.
    """
    k = unit_vectors(k, "k")
    beta = velocity_array(beta)
    return _aberrate(k, beta)


def _aberrate(k: FloatArray, beta: FloatArray) -> FloatArray:
    gamma = 1.0 / np.sqrt(1.0 - _dot(beta, beta))
    beta_k = _dot(beta, k)
    numerator = k + ((gamma * gamma / (gamma + 1.0)) * beta_k - gamma)[..., None] * beta
    k_prime = numerator / (gamma * (1.0 - beta_k))[..., None]
    return k_prime / np.linalg.norm(k_prime, axis=-1, keepdims=True)


def camera_to_scene_direction(d: ArrayLike, beta: ArrayLike) -> FloatArray:
    """Gray et al. eq. (2): a photon's propagation direction ``d`` in the camera frame seen
    in the scene frame, for a camera moving with ``beta`` (in camera coordinates) through the scene.

    d_scene ∝ d + (gamma - 1)(bhat·d) bhat + gamma beta, returned normalised. This is
    :func:`aberrate` with ``-beta``. A viewing direction ``v`` (out of the camera) is the reverse
    of the photon's: its scene-frame direction is ``-camera_to_scene_direction(-v, beta)``.
    """
    return _aberrate(unit_vectors(d, "d"), -velocity_array(beta))


def compose_velocities(beta_frame: ArrayLike, beta_in_frame: ArrayLike) -> FloatArray:
    """Velocity in S of a body moving with ``beta_in_frame`` in S', where S' moves with
    ``beta_frame`` in S (relativistic velocity addition, the inverse boost of the body's 4-velocity).

    u = [u'/gamma_v + v + (gamma_v / (gamma_v + 1)) (v·u') v] / (1 + v·u').
    """
    v = velocity_array(beta_frame, "beta_frame")
    u = velocity_array(beta_in_frame, "beta_in_frame")
    gamma = 1.0 / np.sqrt(1.0 - _dot(v, v))
    v_u = _dot(v, u)
    numerator = u / gamma[..., None] + v + ((gamma / (gamma + 1.0)) * v_u)[..., None] * v
    return numerator / (1.0 + v_u)[..., None]
