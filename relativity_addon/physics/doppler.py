"""Doppler factor and apparent distance (docs/physics.md, "Aberration and Doppler factor").

``D = nu_received / nu_emitted``: ``D > 1`` is a blueshift. ``k`` is always the photon's
propagation direction (from the source toward the observer), a unit vector; it is normalised here.
"""

import numpy as np

from .arrays import ArrayLike, FloatArray
from .validation import finite_array, unit_vectors, velocity_array


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.sum(a * b, axis=-1)


def _gamma(beta: FloatArray) -> FloatArray:
    return 1.0 / np.sqrt(1.0 - _dot(beta, beta))


def doppler_factor_moving_observer(k: ArrayLike, beta_observer: ArrayLike) -> FloatArray:
    """D = gamma (1 - beta·k) for an observer moving with ``beta_observer`` through the frame in
    which the source is at rest; ``k`` is the photon direction in that (source) frame."""
    k = unit_vectors(k, "k")
    beta = velocity_array(beta_observer, "beta_observer")
    return _gamma(beta) * (1.0 - _dot(beta, k))


def doppler_factor_from_observed_direction(k_observed: ArrayLike, beta_observer: ArrayLike) -> FloatArray:
    """D = 1 / (gamma (1 + beta·k')) with ``k_observed`` the photon direction in the observer's
    own frame: the same D as :func:`doppler_factor_moving_observer`, from the other side."""
    k = unit_vectors(k_observed, "k_observed")
    beta = velocity_array(beta_observer, "beta_observer")
    return 1.0 / (_gamma(beta) * (1.0 + _dot(beta, k)))


def doppler_factor_moving_source(k: ArrayLike, beta_source: ArrayLike) -> FloatArray:
    """D = 1 / (gamma_s (1 - beta_s·k)) for a source moving with ``beta_source`` in the
    observer's frame; ``k`` is the photon direction in the observer's frame."""
    k = unit_vectors(k, "k")
    beta = velocity_array(beta_source, "beta_source")
    return 1.0 / (_gamma(beta) * (1.0 - _dot(beta, k)))


def doppler_factor(k: ArrayLike, beta_observer: ArrayLike, beta_source: ArrayLike) -> FloatArray:
    """D = gamma_o (1 - beta_o·k) / (gamma_s (1 - beta_s·k)) with source and observer velocities
    and the photon direction ``k`` all given in the scene frame."""
    k = unit_vectors(k, "k")
    beta_o = velocity_array(beta_observer, "beta_observer")
    beta_s = velocity_array(beta_source, "beta_source")
    return (_gamma(beta_o) * (1.0 - _dot(beta_o, k))) / (_gamma(beta_s) * (1.0 - _dot(beta_s, k)))


def apparent_distance(distance_source_frame: ArrayLike, doppler: ArrayLike) -> FloatArray:
    """r' = D r: the distance of a source as it appears in the observer's frame, for a distance
    ``r`` measured in the source frame at emission (Weiskopf et al. eq. 25, in this D convention)."""
    r = finite_array(distance_source_frame, "distance_source_frame")
    d = finite_array(doppler, "doppler")
    if np.any(d <= 0.0):
        raise ValueError("doppler must be positive")
    return d * r
