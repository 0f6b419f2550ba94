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

from .arrays import BoolArray, FloatArray
from .validation import velocity_array


def pixel_directions(window: ArrayLike, size: tuple[int, int]) -> FloatArray:
    """Unit camera-frame directions ``(height, width, 3)`` through the pixel centres, rows bottom
    first (as Blender stores images); ``window`` is the image's ``(left, right, bottom, top)`` on
    the plane at unit distance in front of the camera."""
    left, right, bottom, top = (float(v) for v in np.asarray(window, dtype=np.float64).ravel())
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


def compensation(
    beta_camera: ArrayLike,
    window: ArrayLike,
    aberration: bool = True,
    power: float = 4.0,
    size: tuple[int, int] = (48, 36),
) -> float:
    """The compensated exposure ``k = exp(-power <ln D>)`` over the image (a ``size`` grid of pixel
    directions is plenty: ``ln D`` is smooth)."""
    mean = float(np.mean(log_doppler(pixel_directions(window, size), beta_camera, aberration)))
    return float(np.exp(-power * mean))


# Blender's panorama types (camera.data.panorama_type) this module maps, as the exact camera does.
PANORAMAS = ("EQUIRECTANGULAR", "FISHEYE_EQUIDISTANT", "FISHEYE_EQUISOLID", "MIRRORBALL")


def panorama_directions(
    kind: str,
    size: tuple[int, int],
    longitude: tuple[float, float] = (-np.pi, np.pi),
    latitude: tuple[float, float] = (-np.pi / 2, np.pi / 2),
    fov: float = np.pi,
    lens: float = 10.5,
    sensor: tuple[float, float] = (36.0, 24.0),
) -> tuple[FloatArray, BoolArray]:
    """Unit camera-frame directions ``(height, width, 3)`` through the pixel centres of one of
    Blender's panoramas (rows bottom first, camera looking down -Z), as Cycles maps them and the
    exact camera's shader writes them out; and the mask of pixels inside the image (a fisheye's or
    mirror ball's circle; the others get the forward direction). ``sensor`` is the fitted sensor
    size in millimetres (equisolid), ``lens`` its focal length, ``fov`` the fisheye's field of view."""
    width, height = size
    u, v = np.meshgrid((np.arange(width) + 0.5) / width, (np.arange(height) + 0.5) / height)
    inside = np.ones(u.shape, dtype=bool)
    if kind == "EQUIRECTANGULAR":
        lon = longitude[0] + u * (longitude[1] - longitude[0])
        lat = latitude[0] + v * (latitude[1] - latitude[0])
        forward = np.stack([np.cos(lat) * np.sin(lon), np.sin(lat), np.cos(lat) * np.cos(lon)], axis=-1)
    elif kind == "MIRRORBALL":  # the forward unit vector reflected at the ball's normal
        nx, ny = 2.0 * u - 1.0, 2.0 * v - 1.0
        r2 = nx * nx + ny * ny
        inside = r2 <= 1.0
        normal = np.stack([nx, ny, np.sqrt(np.maximum(1.0 - r2, 0.0))], axis=-1)
        forward = 2.0 * normal[..., 2:3] * normal - np.array([0.0, 0.0, 1.0])
    elif kind in ("FISHEYE_EQUIDISTANT", "FISHEYE_EQUISOLID"):
        if kind == "FISHEYE_EQUIDISTANT":  # the image circle fills the frame
            x, y = 2.0 * u - 1.0, 2.0 * v - 1.0
            r = np.hypot(x, y)
            inside = r <= 1.0
            theta = r * 0.5 * fov
        else:  # equisolid: image radius 2 f sin(theta / 2) on the sensor
            x, y = (u - 0.5) * sensor[0], (v - 0.5) * sensor[1]
            r = np.hypot(x, y)
            inside = r <= 2.0 * lens * np.sin(0.25 * fov)
            theta = 2.0 * np.arcsin(np.minimum(r / (2.0 * lens), 1.0))
        s = np.divide(np.sin(theta), r, out=np.zeros_like(r), where=r > 0.0)
        forward = np.stack([x * s, y * s, np.cos(theta)], axis=-1)
    else:
        raise ValueError(f"unknown panorama type {kind!r}")
    directions = forward * np.array([1.0, 1.0, -1.0])  # +Z forward -> the camera's -Z
    directions[~inside] = (0.0, 0.0, -1.0)
    return directions / np.linalg.norm(directions, axis=-1, keepdims=True), inside
