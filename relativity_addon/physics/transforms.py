"""Rotation and object matrices with Blender's conventions, vectorised over K samples in float64.

Blender's mathutils works in float32 and one matrix at a time; the apparent-geometry path needs
an object's matrix at many (sub-)frames, so these functions build them in numpy, with the same
conventions as Blender:

- Matrices act on column vectors (``x_world = M @ x_local``), right-handed axes.
- Euler order ``"XYZ"`` means X is applied first: ``R = Rz @ Ry @ Rx`` (``mathutils.Euler``).
- Quaternions are ``(w, x, y, z)`` and are normalised before use; a zero quaternion counts as
  ``(0, 1, 0, 0)`` (a half turn about X), as Blender's ``normalize_qt`` makes it.
- Axis-angle rows are ``(angle, axis x, y, z)``; a zero axis is no rotation.
- An object's local matrix composes as Blender's ``BKE_object_to_mat4``:
  ``M = T(location) @ R @ S(scale)`` (see :func:`compose_basis_matrices`).
"""

import numpy as np

from .arrays import ArrayLike, FloatArray
from .validation import finite_array

EULER_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")


def _rows(values: ArrayLike, width: int, name: str) -> FloatArray:
    """``values`` as finite float64 rows ``(K, width)``; a single row ``(width,)`` becomes ``(1, width)``."""
    array = finite_array(values, name)
    if array.ndim == 1:
        array = array[None, :]
    if array.ndim != 2 or array.shape[1] != width:
        raise ValueError(f"{name} must have shape (K, {width}) or ({width},), got {array.shape}")
    return array


def axis_rotation_matrices(axis: int, angles: ArrayLike) -> FloatArray:
    """Right-handed rotations by ``angles`` (radians, shape ``(K,)``) about coordinate axis
    ``axis`` (0 = X, 1 = Y, 2 = Z), shape ``(K, 3, 3)``: e.g. about Z,
    ``[[cos, -sin, 0], [sin, cos, 0], [0, 0, 1]]`` (a positive angle turns X towards Y)."""
    if axis not in (0, 1, 2):
        raise ValueError(f"axis must be 0, 1 or 2, got {axis!r}")
    angles = np.atleast_1d(finite_array(angles, "angles"))
    if angles.ndim != 1:
        raise ValueError(f"angles must have shape (K,), got {angles.shape}")
    c, s = np.cos(angles), np.sin(angles)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.zeros((len(angles), 3, 3))
    m[:, axis, axis] = 1.0
    m[:, i, i], m[:, i, j], m[:, j, i], m[:, j, j] = c, -s, s, c
    return m


def euler_matrices(angles: ArrayLike, order: str = "XYZ") -> FloatArray:
    """Rotation matrices ``(K, 3, 3)`` of Euler angles ``(K, 3)`` (radians about X, Y, Z, in that
    column order whatever ``order`` is) in Blender's rotation mode ``order``: the first letter is
    applied first, so ``"XYZ"`` gives ``R = Rz @ Ry @ Rx``."""
    if order not in EULER_ORDERS:
        raise ValueError(f"order must be one of {', '.join(EULER_ORDERS)}, got {order!r}")
    angles = _rows(angles, 3, "angles")
    rotation = np.broadcast_to(np.eye(3), (len(angles), 3, 3))
    for axis_name in order:
        axis = "XYZ".index(axis_name)
        rotation = axis_rotation_matrices(axis, angles[:, axis]) @ rotation
    return np.ascontiguousarray(rotation)


def quaternion_matrices(q: ArrayLike) -> FloatArray:
    """Rotation matrices ``(K, 3, 3)`` of quaternions ``(K, 4)`` as ``(w, x, y, z)``, normalised
    first as Blender does: a zero quaternion becomes ``(0, 1, 0, 0)``."""
    q = _rows(q, 4, "quaternions")
    length = np.linalg.norm(q, axis=1, keepdims=True)
    q = np.where(length > 0.0, q / np.where(length > 0.0, length, 1.0), [0.0, 1.0, 0.0, 0.0])
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


def axis_angle_matrices(values: ArrayLike) -> FloatArray:
    """Rotation matrices ``(K, 3, 3)`` of axis-angle rows ``(K, 4)`` = ``(angle, axis x, y, z)``
    (Blender's ``rotation_axis_angle``; the axis need not be normalised). A zero axis is no
    rotation, whatever the angle."""
    values = _rows(values, 4, "axis-angle values")
    axis_length = np.linalg.norm(values[:, 1:], axis=1, keepdims=True)
    axis = values[:, 1:] / np.where(axis_length > 0.0, axis_length, 1.0)
    half = 0.5 * np.where(axis_length[:, 0] > 0.0, values[:, 0], 0.0)[:, None]
    return quaternion_matrices(np.concatenate([np.cos(half), np.sin(half) * axis], axis=1))


def compose_basis_matrices(location: ArrayLike, rotation: ArrayLike, scale: ArrayLike) -> FloatArray:
    """Object matrices ``(K, 4, 4)`` float64 from ``location`` ``(K, 3)``, ``rotation`` matrices
    ``(K, 3, 3)`` and ``scale`` ``(K, 3)``: ``M = T(location) @ R @ diag(scale)`` (Blender's
    ``BKE_object_to_mat4``, the object's ``matrix_basis``).

    Delta transforms compose before this call, as Blender does: pass ``location + delta_location``,
    ``R_delta @ R`` (Euler deltas in the object's Euler order, quaternion deltas for quaternion
    mode; axis-angle has no delta) and ``scale * delta_scale``. Single samples (``(3,)``,
    ``(3, 3)``) are taken as ``K = 1``."""
    location = _rows(location, 3, "location")
    scale = _rows(scale, 3, "scale")
    rotation = finite_array(rotation, "rotation")
    if rotation.ndim == 2:
        rotation = rotation[None]
    if rotation.ndim != 3 or rotation.shape[1:] != (3, 3):
        raise ValueError(f"rotation must have shape (K, 3, 3) or (3, 3), got {rotation.shape}")
    count = max(len(location), len(rotation), len(scale))
    if any(len(array) not in (1, count) for array in (location, rotation, scale)):
        raise ValueError("location, rotation and scale must have the same number of samples (or one)")
    matrices = np.zeros((count, 4, 4))
    matrices[:, :3, :3] = rotation * scale[:, None, :]
    matrices[:, :3, 3] = location
    matrices[:, 3, 3] = 1.0
    return matrices
