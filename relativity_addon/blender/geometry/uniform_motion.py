"""The closed form's inputs (issue 26): uniform motion's relations (docs/physics.md, "Light-travel
time" and "Lorentz boost of an event") folded, in float64, into the few vectors the modifier reads
(``node_group.CLOSED_FORM_INPUTS``): for a Static or Constant Velocity mesh, keyframed motion uniform
over its window (``keyframed.py``), a frame step on straight keys and an observer's velocity change
on many meshes at once (``straight_steps``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...physics import apparent
from ..scene.snapshot import check_velocity
from .motion import affine_inverse, check_parent_motion, matrix_array

if TYPE_CHECKING:
    from bpy.types import Object

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot


def closed_form_inputs(obj: Object, obj_eval: Object, snap: Snapshot) -> dict[str, tuple[float, ...] | float]:
    """The modifier's closed-form inputs (``node_group.CLOSED_FORM_INPUTS``) for a closed-form object:
    the relations of :func:`apparent_world_positions` (uniform motion through where Blender draws the
    object at the observer's time, the rest shape contracted along ``beta``; the retarded emission
    event boosted into the observer's frame, docs/physics.md) folded into affine maps of the rest
    position and the light-travel distance ``s = c tau``, in float64. Seen in units of c, the closed
    form needs no c. Raises RelativityError for a velocity not below c."""
    _t_o, x_o, beta_o = snap.mesh_observer  # behind the exact camera: the scene frame
    check_parent_motion(obj)
    matrix = matrix_array(obj_eval.matrix_world)
    w = np.zeros(3)
    if obj.relativity.motion == "CONSTANT":
        w = np.array(check_velocity(obj.relativity.beta, f"object {obj.name!r} velocity"), dtype=np.float64)
    return uniform_motion_inputs(matrix[:3, :3], matrix[:3, 3], w, matrix, x_o, beta_o)


# The closed form's towards form (root - r.w) / (1 - w.w) on every point (``Folded``) where it rounds at
# most this many times worse than float32 on the receding points (1 / (1 - |w|): |w| <= 0.9); faster,
# each point takes the form that avoids cancellation (docs/physics.md, "Light-travel time").
FOLD_LIMIT = 10.0


def uniform_motion_inputs(
    shape: FloatArray, origin: FloatArray, w: FloatArray, matrix: FloatArray, x_o: FloatArray, beta_o: FloatArray
) -> dict[str, tuple[float, ...] | float]:
    """The closed-form inputs of uniform motion (also keyframed motion uniform over the window of its
    retarded times, ``keyframed.py``): at the observer's time the origin is at ``origin`` (scene) and
    the rest shape's 3x3 is ``shape``, contracted along ``w`` (the velocity, fraction of c); seen from
    the observer at ``x_o`` moving with ``beta_o``, in the object space of the world ``matrix``."""
    x_o = np.asarray(x_o, dtype=np.float64)
    matrix = np.asarray(matrix, dtype=np.float64)
    inverse, to_local, fixed = uniform_parts(shape, w, beta_o, matrix)
    offset = np.asarray(origin, dtype=np.float64) - x_o
    local = uniform_local_offsets(offset[None], x_o, matrix[None, :3, 3], inverse[None], to_local[None])[0]
    return {**fixed, "Scene Offset": _vector(offset), "Local Offset": _vector(local)}


def uniform_local_offsets(
    offsets: FloatArray, x_o: FloatArray, translations: FloatArray, inverses: FloatArray, to_locals: FloatArray
) -> FloatArray:
    """``Local Offset`` of :func:`uniform_motion_inputs` for each row (N, 3): ``N B (origin - x_o) + N (x_o -
    the matrix's translation)``, ``offsets`` the origins less ``x_o``, ``inverses`` N and ``to_locals`` N B
    (N, 3, 3; :func:`uniform_parts`). A frame step of many meshes takes them in one pass."""
    return np.einsum("nij,nj->ni", to_locals, offsets) + np.einsum("nij,nj->ni", inverses, x_o - translations)


def uniform_parts(
    shape: FloatArray, w: FloatArray, beta_o: FloatArray, matrix: FloatArray
) -> tuple[FloatArray, FloatArray, dict[str, tuple[float, ...] | float]]:
    """``(N, N B, the inputs that depend on neither the origin nor the observer's place)`` of
    :func:`uniform_motion_inputs` (N the inverse of the object's 3x3, B the boost), kept per inputs."""
    beta_o = np.asarray(beta_o, dtype=np.float64)
    shape, w = np.asarray(shape, dtype=np.float64), np.asarray(w, dtype=np.float64)
    key = b"".join(np.ascontiguousarray(a).tobytes() for a in (shape, w, beta_o, matrix[:3, :3]))
    known = _uniform_parts.get(key)
    if known is None:
        known = _uniform_parts[key] = _uniform_motion_parts(shape, w, beta_o, matrix)
        if len(_uniform_parts) > 4096:  # more objects, or velocities, than a sync passes over
            _uniform_parts.clear()
    return known


def _vector(values):
    return tuple(float(v) for v in values)


# (shape, w, beta_o, the object's 3x3) -> what uniform_motion_inputs computes from them alone: a frame
# step of keyframed motion on straight keys (issue 26: 1,000 objects) changes the two offsets only.
_uniform_parts: dict[bytes, tuple[FloatArray, FloatArray, dict[str, tuple[float, ...] | float]]] = {}


def _uniform_motion_parts(shape, w, beta_o, matrix):
    """``(the inverse of the object's 3x3, its product with the boost, the inputs that do not
    depend on the origin or the observer's place)`` of :func:`uniform_motion_inputs`."""
    # r = A x_rest + k: the point at the observer's time, relative to the observer
    scene = apparent.lorentz_contraction_matrix(w) @ shape
    # object space: N (x_o + e' - t), N the inverse of the object's 3x3
    inverse = affine_inverse(matrix)[:3, :3]
    to_local, seen_parts = observer_parts(scene[None], w[None], beta_o, inverse[None])
    fixed = {
        "Scene X": _vector(scene[:, 0]),
        "Scene Y": _vector(scene[:, 1]),
        "Scene Z": _vector(scene[:, 2]),
        "Velocity": _vector(w),
        "Inverse Gamma Squared": 1.0 - float(w @ w),
        # one form for every point: no per-point choice (4 of the closed form's 19 nodes per point)
        "Folded": 1.0 / (1.0 - float(np.sqrt(w @ w))) <= FOLD_LIMIT,
        **{name: _vector(values[0]) for name, values in zip(OBSERVER_INPUTS, seen_parts, strict=True)},
    }
    return inverse, to_local[0], fixed


# The closed form's inputs that depend on the observer's velocity (and on the object), besides ``Local
# Offset``: what an observer's velocity change sets (``straight_steps``), in :func:`observer_parts`' order.
OBSERVER_INPUTS = ("Local X", "Local Y", "Local Z", "Delay Direction", "Seen Velocity")


def observer_parts(
    scene: FloatArray, w: FloatArray, beta_o: FloatArray, inverse: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """For N objects (``scene``: each rest shape's 3x3 contracted, ``A``; ``w`` its velocity;
    ``inverse``, N: the inverse of its world 3x3) seen by an observer moving with ``beta_o``:
    ``N B`` (N, 3, 3; B the boost) and the values of :data:`OBSERVER_INPUTS` (5, N, 3). The emission
    event (-s, e = r - s w) boosted: e' = B e + gamma s beta_o (Lorentz boost), in object space
    N (x_o + e' - t)."""
    beta_o = np.asarray(beta_o, dtype=np.float64)
    gamma = 1.0 / np.sqrt(1.0 - float(beta_o @ beta_o))
    boost = np.eye(3) + (gamma * gamma / (gamma + 1.0)) * np.outer(beta_o, beta_o)
    to_local = inverse @ boost
    local = to_local @ scene
    delay = gamma * (inverse @ beta_o) - np.einsum("nij,nj->ni", to_local, w)
    seen = apparent.velocity_seen_by_observer(w, beta_o).reshape(-1, 3)
    return to_local, np.stack((local[:, :, 0], local[:, :, 1], local[:, :, 2], delay, seen))
