"""Input checks shared by the physics core.

Bad input is a user error: every check raises ``ValueError`` with a message that names the
argument, so no function of the core ever returns NaN or inf for NaN, inf or superluminal input.
"""

import numpy as np

from .arrays import ArrayLike, FloatArray


def finite_array(value: ArrayLike, name: str) -> FloatArray:
    """``value`` as a float64 array, or ``ValueError`` if any element is NaN or inf."""
    array = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got NaN or inf")
    return array


def vector_array(value: ArrayLike, name: str) -> FloatArray:
    """``value`` as a finite float64 array of 3-vectors (last axis of length 3)."""
    array = finite_array(value, name)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f"{name} must have 3 components on its last axis, got shape {array.shape}")
    return array


def unit_vectors(value: ArrayLike, name: str) -> FloatArray:
    """Normalised 3-vectors; ``ValueError`` for zero-length (or denormal) vectors."""
    array = vector_array(value, name)
    norm = np.linalg.norm(array, axis=-1, keepdims=True)
    if np.any(norm < 1e-300):
        raise ValueError(f"{name} must not contain zero-length directions")
    return array / norm


def velocity_array(beta: ArrayLike, name: str = "beta") -> FloatArray:
    """Velocities as fractions of c: finite 3-vectors with ``|beta| < 1``."""
    array = vector_array(beta, name)
    speed_squared = np.sum(array * array, axis=-1)
    if np.any(speed_squared >= 1.0):
        speed = float(np.sqrt(np.max(speed_squared)))
        raise ValueError(f"|{name}| must be below 1 (slower than light), got {speed:.6g}")
    return array


def positive_array(value: ArrayLike, name: str) -> FloatArray:
    """A finite array whose elements are all strictly positive."""
    array = finite_array(value, name)
    if np.any(array <= 0.0):
        raise ValueError(f"{name} must be positive")
    return array


def speed_of_light(c: ArrayLike) -> float:
    """The speed of light in scene units per second: a positive finite scalar."""
    array = positive_array(c, "c")
    if array.ndim != 0:
        raise ValueError("c must be a scalar")
    return float(array)
