"""Each pixel's Doppler factor for a moving camera, and the one exposure that keeps a frame watchable.

The searchlight scales radiance by ``D^4`` (docs/physics.md, "Radiance"): at 0.9c the view ahead is
hundreds of times brighter and the view behind as much darker, so most frames of a fly-through
are burnt out or black. *Compensated* exposure multiplies a whole frame by one number,

    k = exp(-power <ln D>),

the inverse of the log-average (geometric mean) of ``D^power`` over the image's pixel directions:
a frame whose brightness change is the searchlight alone is brought back to its brightness at
rest on average, and its contrast stays the physical one. ``k`` depends only on the camera's
velocity and field of view, never on the picture, so the physics is recoverable from it (it goes
into the output's metadata).

Pixel directions are camera-frame directions (the camera looks down its local -Z). With
aberration, a photon arriving from camera-frame direction ``d'`` has ``D = 1 / (gamma (1 - beta.d'))``;
without it (and behind the Lorentz window) the ray is taken as the scene-frame direction ``d``,
``D = gamma (1 + beta.d)`` (Gray et al. 2020; the OSL camera computes the same).
"""

import numpy as np
from numpy.typing import ArrayLike

from .arrays import FloatArray
from .validation import velocity_array


def pixel_directions(window: ArrayLike, size: tuple[int, int]) -> FloatArray:
    """Unit camera-frame directions ``(height, width, 3)`` through the pixel centres, rows bottom
    first (as Blender stores images); ``window`` is the image's ``(left, right, bottom, top)`` on
    the plane at unit distance in front of the camera."""
    left, right, bottom, top = (float(v) for v in window)
    width, height = size
    x = left + (np.arange(width) + 0.5) / width * (right - left)
    y = bottom + (np.arange(height) + 0.5) / height * (top - bottom)
    directions = np.stack(np.broadcast_arrays(x[None, :], y[:, None], -1.0), axis=-1)
    return directions / np.linalg.norm(directions, axis=-1, keepdims=True)


def log_doppler(directions: ArrayLike, beta_camera: ArrayLike, aberration: bool = True) -> FloatArray:
    """``ln D`` for camera-frame ray directions and the camera velocity in camera axes."""
    beta = velocity_array(beta_camera, "beta_camera")
    gamma = 1.0 / np.sqrt(1.0 - beta @ beta)
    bd = np.asarray(directions, dtype=np.float64) @ beta
    if aberration:
        return -np.log(gamma * (1.0 - bd))
    return np.log(gamma * (1.0 + bd))


def compensation(beta_camera: ArrayLike, window: ArrayLike, aberration: bool = True, power: float = 4.0,
                 size: tuple[int, int] = (48, 36)) -> float:
    """The compensated exposure ``k = exp(-power <ln D>)`` over the image (a ``size`` grid of pixel
    directions is plenty: ``ln D`` is smooth)."""
    mean = float(np.mean(log_doppler(pixel_directions(window, size), beta_camera, aberration)))
    return float(np.exp(-power * mean))
