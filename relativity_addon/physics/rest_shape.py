"""The modelled mesh is an object's rest shape (docs/architecture.md, "Motion sources and the rest
shape"; the contraction is the Lorentz boost of docs/physics.md read at equal scene times).

At scene time ``t`` an object is, in the scene frame, its rest shape contracted along the velocity
``beta(t)`` of its origin, about the origin:

    x(t) = T(t) + C(beta(t)) L(t) x_rest,    C(beta) = I - (1 - 1/gamma) bhat bhat^T

(``T``: the origin, ``L``: rotation and scale of the object's world matrix,
``C``: :func:`apparent.lorentz_contraction_matrix`). CONSTANT motion folds ``C`` into the object
matrix once. A sampled motion (keyframes, motion bake, deformation bake) contracts each sample with
the origin's velocity there: the Catmull-Rom slope at the knot, ``(T[k+1] - T[k-1]) / 2h`` (one-sided
at the ends, as the linear end padding makes it), which is the velocity the interpolated motion has
at that knot. The contracted samples are interpolated like the others, so each vertex is contracted
with ``beta`` at its own retarded time, to the accuracy of the sampling, and exactly for uniform
motion (the contracted samples are then linear in time as well).
"""

import numpy as np

from .apparent import (
    SampledPointMotion,
    SampledRigidMotion,
    _uniform_grid,
    apparent_positions,
    apparent_positions_sampled,
)
from .arrays import ArrayLike, BoolArray, FloatArray
from .validation import finite_array, positive_array, speed_of_light, vector_array


def origin_velocities(origins: ArrayLike, step: float) -> FloatArray:
    """Velocities (units per second, ``(K, 3)``) of an origin sampled every ``step`` seconds at
    positions ``origins`` (``(K, 3)``, K >= 2): the Catmull-Rom knot slopes of
    :class:`apparent.SampledRigidMotion`, central differences with one-sided ones at the ends."""
    origins = vector_array(origins, "origins")
    step = float(positive_array(step, "step"))
    if origins.ndim != 2 or len(origins) < 2:
        raise ValueError(f"need at least 2 origin samples of shape (K, 3), got shape {origins.shape}")
    padded = np.concatenate([2.0 * origins[:1] - origins[1:2], origins, 2.0 * origins[-1:] - origins[-2:-1]])
    return (padded[2:] - padded[:-2]) / (2.0 * step)


def contraction_matrices(beta: ArrayLike) -> tuple[FloatArray, BoolArray]:
    """``C(beta)`` of :func:`apparent.lorentz_contraction_matrix` for each row of ``beta``
    (``(K, 3)``, fractions of c), shape ``(K, 3, 3)``, and the mask of rows with ``|beta| >= 1``
    (not slower than light: their matrix is the identity, and they must not be used)."""
    beta = finite_array(beta, "beta").reshape(-1, 3)
    speed_squared = np.einsum("ki,ki->k", beta, beta)
    superluminal = speed_squared >= 1.0
    moving = (speed_squared > 0.0) & ~superluminal
    result = np.broadcast_to(np.eye(3), (len(beta), 3, 3)).copy()
    if np.any(moving):
        s2 = speed_squared[moving]
        shrink = 1.0 - np.sqrt(1.0 - s2)  # 1 - 1/gamma
        bhat = beta[moving] / np.sqrt(s2)[:, None]
        result[moving] -= shrink[:, None, None] * bhat[:, :, None] * bhat[:, None, :]
    return result, superluminal


def contracted_rigid_samples(matrices: ArrayLike, step: float, c: float) -> tuple[FloatArray, BoolArray]:
    """Object-to-world matrices ``(K, 4, 4)`` sampled every ``step`` seconds with the rest-shape
    contraction applied: the 3x3 part ``L`` becomes ``C(beta_k) L`` with ``beta_k`` the origin's
    knot velocity over ``c``; the translation (the origin) is kept. Returns the matrices and the
    mask of samples whose origin is not slower than light (left uncontracted)."""
    c = speed_of_light(c)
    matrices = finite_array(matrices, "matrices")
    if matrices.ndim != 3 or matrices.shape[1:] != (4, 4):
        raise ValueError(f"matrices must have shape (K, 4, 4), got {matrices.shape}")
    contraction, superluminal = contraction_matrices(origin_velocities(matrices[:, :3, 3], step) / c)
    contracted = matrices.copy()
    contracted[:, :3, :3] = contraction @ matrices[:, :3, :3]
    return contracted, superluminal


def contracted_point_samples(
    positions: ArrayLike, origins: ArrayLike, step: float, c: float
) -> tuple[FloatArray, BoolArray]:
    """World positions ``(K, N, 3)`` of a deforming mesh sampled every ``step`` seconds, with the
    object's origin at ``origins`` (``(K, 3)``), contracted about the origin along its knot
    velocity (the same convention as rigid motion: the baked shape is taken as the rest shape
    carried along by the origin). Returns the positions and the superluminal mask."""
    c = speed_of_light(c)
    positions = vector_array(positions, "positions")
    origins = vector_array(origins, "origins")
    if positions.ndim != 3 or origins.shape != (positions.shape[0], 3):
        raise ValueError(f"positions (K, N, 3) and origins (K, 3) do not match: {positions.shape}, {origins.shape}")
    contraction, superluminal = contraction_matrices(origin_velocities(origins, step) / c)
    relative = positions - origins[:, None, :]
    return np.einsum("kij,knj->kni", contraction, relative) + origins[:, None, :], superluminal


def check_samples_used(t_e: ArrayLike, start: float, step: float, superluminal: BoolArray) -> None:
    """``ValueError`` if a retarded time ``t_e`` is interpolated from a sample whose origin is not
    slower than light (samples ``start + k step``; an interval uses its two ends and one sample on
    each side, the end intervals also the linear extrapolation beyond the grid)."""
    if not np.any(superluminal) or np.size(t_e) == 0:
        return
    count = len(superluminal)
    intervals = np.arange(count - 1)
    running = np.concatenate([[0], np.cumsum(superluminal)])
    touched = running[np.minimum(intervals + 3, count)] - running[np.maximum(intervals - 1, 0)] > 0
    interval = np.clip(np.floor((np.asarray(t_e) - start) / step), 0, count - 2).astype(np.int64)
    if np.any(touched[interval]):
        first = start + step * int(np.flatnonzero(superluminal)[0])
        raise ValueError(f"the sampled motion is not slower than light: its origin reaches c near t = {first:.6g} s")


def apparent_positions_rigid_rest_shape(
    times: ArrayLike,
    matrices: ArrayLike,
    rest_local: ArrayLike,
    observer_time: float,
    observer_position: ArrayLike,
    c: float,
    observer_beta: ArrayLike = (0.0, 0.0, 0.0),
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Apparent positions of the rest-shape points ``rest_local`` (``(N, 3)``, object space) of a
    body whose object-to-world matrices at the uniformly spaced ``times`` are ``matrices``
    (``(K, 4, 4)``): contracted (:func:`contracted_rigid_samples`), then solved per point by
    :func:`apparent.apparent_positions_sampled`. Returns ``(apparent, tau, beta_seen)``."""
    times = finite_array(times, "times")
    if times.ndim != 1 or times.size < 2:
        raise ValueError("need at least 2 sample times")
    start, step, _ = _uniform_grid(times)
    contracted, superluminal = contracted_rigid_samples(matrices, step, c)
    result = apparent_positions_sampled(
        SampledRigidMotion(times, contracted, rest_local), observer_time, observer_position, c, observer_beta
    )
    check_samples_used(observer_time - result[1], start, step, superluminal)
    return result


def apparent_positions_deforming_rest_shape(
    times: ArrayLike,
    positions: ArrayLike,
    origins: ArrayLike,
    observer_time: float,
    observer_position: ArrayLike,
    c: float,
    observer_beta: ArrayLike = (0.0, 0.0, 0.0),
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Apparent positions of a deforming mesh sampled at the uniformly spaced ``times``
    (``positions`` ``(K, N, 3)``, origin ``origins`` ``(K, 3)``), contracted by
    :func:`contracted_point_samples`, each point at its own retarded time
    (:func:`apparent.apparent_positions`). Returns ``(apparent, tau, beta_seen)``."""
    times = finite_array(times, "times")
    if times.ndim != 1 or times.size < 2:
        raise ValueError("need at least 2 sample times")
    start, step, _ = _uniform_grid(times)
    contracted, superluminal = contracted_point_samples(positions, origins, step, c)
    motion = SampledPointMotion(times, contracted)
    result = apparent_positions(
        motion.positions,
        observer_time,
        observer_position,
        c,
        contracted.shape[1],
        observer_beta,
        velocity=motion.velocities,
    )
    check_samples_used(observer_time - result[1], start, step, superluminal)
    return result
