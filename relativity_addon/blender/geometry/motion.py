"""Where each vertex of a moving object is seen: its apparent world position and velocity for
the observer event of a snapshot, by the object's motion source (``Object.relativity.motion``).
Behind the exact camera (``Snapshot.exact_camera``) the positions are retarded positions in the
scene frame and the velocities scene-frame ones (``Snapshot.mesh_observer``); on the boosted-mesh
preview they are carried into the observer frame.

- STATIC and CONSTANT: the mesh is the object's rest-frame shape; with a constant velocity it is
  Lorentz-contracted along ``beta`` about the object origin, and the retarded times have a closed
  form (``physics.apparent.apparent_positions_uniform``).
- ANIMATION, rigid: world matrices on a sub-frame grid around the retarded times, from the
  object's keyframes under its object-parent chain (``animation.world_matrices``, float64, no
  ``frame_set``) or from its motion bake (``bakes.bake_motion``) when constraints, drivers or NLA
  move it; per-vertex retarded times by the core's sampled solver. The mesh is the rest shape
  here too: each sample is contracted along the velocity of the object's origin there
  (``physics.rest_shape``), so a constant keyframed velocity gives the CONSTANT result.
- ANIMATION with ``use_deformation``: per-vertex positions from the deformation bake, contracted
  the same way about the object's origin along the origin's velocity (baked with them).

Proper time (``Object.relativity.use_proper_time``, docs/proper-time.md): an object's own animation
(rotation and scale keys, shape keys; with a deformation bake everything about the origin's path,
armatures included) plays at its proper time along its world line.

Every function raises RelativityError (one line) for a motion it cannot show correctly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...errors import RelativityError
from ...physics import apparent, proper_time, rest_shape, sampling
from ..common import names
from ..scene import animation
from ..scene.snapshot import check_velocity
from . import modifier, shape_keys

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    import numpy.typing as npt
    from bpy.types import Object, Scene
    from mathutils import Matrix

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

    Positions = tuple[FloatArray, FloatArray, FloatArray]

# Most samples of a keyframed object's clock table (its path from scene time 0 to the retarded times).
CLOCK_SAMPLES = 200_000
# Solves with each vertex in the shape of its own retarded time, after the first with the scene frame's.
SHAPE_PASSES = 2
_clock_tables = {}  # object name -> the clock table of its last update (see _path_clock)


def matrix_array(matrix: Matrix | Iterable[Iterable[float]]) -> FloatArray:
    return np.array([list(row) for row in matrix], dtype=np.float64)


def affine_inverse(matrix: FloatArray) -> FloatArray:
    """The inverse of an affine 4x4 ``matrix`` (last row 0 0 0 1) by the adjugate of its 3x3 part,
    in float64 scalars: no LAPACK call (whose threads cost milliseconds per call on a loaded
    machine) and no small-array numpy calls (``np.cross`` was as slow), once per object update."""
    (a, b, c, x), (d, e, f, y), (g, h, i, z) = matrix[:3].tolist()
    rows = (
        (e * i - f * h, c * h - b * i, b * f - c * e),
        (f * g - d * i, a * i - c * g, c * d - a * f),
        (d * h - e * g, b * g - a * h, a * e - b * d),
    )
    scale = 1.0 / (a * rows[0][0] + b * rows[1][0] + c * rows[2][0])
    inverse = [[value * scale for value in row] for row in rows]
    for row in inverse:
        row.append(-(row[0] * x + row[1] * y + row[2] * z))
    return np.array([*inverse, [0.0, 0.0, 0.0, 1.0]])


def to_world(matrix: FloatArray, points: FloatArray) -> FloatArray:
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def apparent_world_positions(
    scene: Scene,
    obj: Object,
    obj_eval: Object,
    rest: FloatArray,
    snap: Snapshot,
    shape_keys_too: bool = True,
    with_delay: bool = False,
) -> tuple[FloatArray, ...]:
    """Apparent world positions ``(N, 3)`` of the rest points (object space) of ``obj`` and the
    points' velocities relative to the observer (``(N, 3)``, or ``(1, 3)`` shared by all); with
    ``with_delay`` between them each point's light delay ``t_o - t_e`` (scene frame, seconds).
    ``shape_keys_too=False``: ``rest`` are not the mesh's points (its centre, say): rigid motion only."""
    t_o, x_o, beta_o = snap.mesh_observer  # behind the exact camera: the scene frame
    c = snap.speed_of_light
    matrix_now = matrix_array(obj_eval.matrix_world)
    check_parent_motion(obj)
    motion = obj.relativity.motion
    if motion == "ANIMATION" and obj.relativity.use_deformation:
        world, delay, beta_seen = deformed_apparent_positions(obj, len(rest), t_o, x_o, beta_o, c)
    elif motion == "ANIMATION":
        world, delay, beta_seen = animated_apparent_positions(
            obj, scene, rest, t_o, x_o, beta_o, c, obj_eval=obj_eval, shape_keys_too=shape_keys_too
        )
    elif not closed_form(obj, scene):  # CONSTANT, playing its own animation
        beta_u = np.array(check_velocity(obj.relativity.beta, f"object {obj.name!r} velocity"))
        world, delay, beta_seen = proper_time_apparent_positions(
            obj, scene, rest, t_o, x_o, beta_o, c, beta_u=beta_u, matrix_now=matrix_now, shape_keys_too=shape_keys_too
        )
    else:
        beta_u = np.zeros(3)
        if motion == "CONSTANT":
            beta_u = np.array(check_velocity(obj.relativity.beta, f"object {obj.name!r} velocity"))
        # The mesh is the object's rest-frame shape: in the scene it is contracted along its motion
        # about the object's origin (folded into the object matrix: one affine map per vertex).
        contracted = apparent.lorentz_contraction_matrix(beta_u) @ matrix_now[:3, :3]
        # Built as coordinate rows (3, N), the layout the closed form works on: no copy there.
        world_now = (contracted @ rest.T + matrix_now[:3, 3:]).T
        world, delay, beta_seen = apparent.apparent_positions_uniform(t_o, x_o, world_now, beta_u, c, beta_o)
        beta_seen = beta_seen[:1]  # one velocity for every vertex
    return (world, delay, beta_seen) if with_delay else (world, beta_seen)


def turns(obj: Object, scene: Scene) -> bool:
    """Whether the rigid object's orientation (rotation, scale) changes along its apparent
    positions: rotation or scale keys (its own or an object parent's), or a motion bake; not a
    deforming object (its normals are its own)."""
    motion = obj.relativity.motion
    if motion == "STATIC" or (motion == "ANIMATION" and obj.relativity.use_deformation):
        return False
    if motion == "ANIMATION" and modifier.motion_bake_range(obj) is not None:
        return True
    return animation.has_own_animation(obj, scene)


def retarded_orientations(scene: Scene, obj: Object, obj_eval: Object, rest: FloatArray, snap: Snapshot) -> FloatArray:
    """The linear part (rotation and scale, ``(N, 3, 3)``) of the object's world matrix at the
    retarded time of each rest point (object space), on the clock its apparent positions use: what
    turns its rest-frame normals there. The current matrix for every point when the object does not
    turn (the closed form). A rigid object only (no deformation)."""
    now = matrix_array(obj_eval.matrix_world)[:3, :3]
    if not turns(obj, scene) or not len(rest):
        return np.broadcast_to(now, (len(rest), 3, 3))
    t_o, c = snap.mesh_observer[0], snap.speed_of_light
    _, delay, _ = apparent_world_positions(scene, obj, obj_eval, rest, snap, shape_keys_too=False, with_delay=True)
    times = t_o - np.asarray(delay, dtype=np.float64)
    fps = animation.frames_per_second(scene)
    step = 1.0 / (int(obj.relativity.samples_per_frame) * fps)
    grid = np.arange(np.floor(times.min() / step), np.ceil(times.max() / step) + 1.0) * step
    bake = modifier.motion_bake(obj)
    if bake is not None:
        first_frame, per_frame, baked = bake
        index = np.clip((grid * fps - first_frame) * per_frame, 0.0, len(baked) - 1.0)
        low = np.floor(index).astype(int)
        high = np.minimum(low + 1, len(baked) - 1)
        part = (index - low)[:, None, None]
        sampled = baked[low, :3, :3] * (1.0 - part) + baked[high, :3, :3] * part
    elif obj.relativity.motion == "ANIMATION":
        own = _path_clock(obj, fps, step, c)(grid) * fps if obj.relativity.use_proper_time else None
        sampled = animation.world_matrices(obj, grid * fps, own_frames=own)[:, :3, :3]
    else:  # CONSTANT playing its own animation at its proper time
        beta_u = np.array(check_velocity(obj.relativity.beta, f"object {obj.name!r} velocity"))
        gamma = 1.0 / np.sqrt(1.0 - beta_u @ beta_u) if obj.relativity.use_proper_time else 1.0
        sampled = animation.world_matrices(obj, grid / gamma * fps)[:, :3, :3]
    # between the samples linearly: a normal turned by the interpolated matrix is within
    # (turn per sample)^2 / 8 of the turned one's direction (0.8 % at 15 degrees per sample)
    position = np.clip((times - grid[0]) / step, 0.0, len(grid) - 1.0)
    low = np.minimum(np.floor(position).astype(int), len(grid) - 1)
    high = np.minimum(low + 1, len(grid) - 1)
    part = (position - low)[:, None, None]
    return sampled[low] * (1.0 - part) + sampled[high] * part


def closed_form(obj: Object, scene: Scene) -> bool:
    """Whether the object's apparent positions have the closed form (STATIC, or CONSTANT without
    an animation of its own to play): each point's from its own rest position alone, so the
    points can be computed a part at a time."""
    motion = obj.relativity.motion
    return motion != "ANIMATION" and not (motion == "CONSTANT" and plays_own_animation(obj, scene))


def keyframes_start_warning(obj: Object, scene: Scene, earliest_time: float) -> str | None:
    """A one-line warning when some point of a keyframed object (Motion Animation, no bake) is seen
    as it was before its keyframes start moving it (``earliest_time``: its earliest retarded time,
    seconds): Blender holds it still there, a motion the user rarely means. None otherwise."""
    settings = obj.relativity
    if settings.motion != "ANIMATION" or settings.use_deformation or modifier.motion_bake(obj) is not None:
        return None
    held_before = animation.held_before_frame(obj)
    earliest = earliest_time * animation.frames_per_second(scene)
    if held_before is None or earliest >= held_before - 1e-6:
        return None
    return (
        f"Mesh {obj.name!r} is seen as it was at frame {earliest:.1f}, before its keyframes move it "
        f"(from frame {held_before:g}): it is held still there; for this frame its keys must start by frame "
        f"{np.floor(earliest):g}"
    )


def check_parent_motion(obj: Object) -> None:
    """RelativityError if the nearest moving mesh among the object's parents (apparent geometry on,
    Motion not Static) has another motion than the object: a child rides on its parent's world line,
    and each object's world line comes from its own settings, so they must agree (the child's own
    keys then play at the proper time of that world line)."""
    parent = obj.parent
    while parent is not None:
        settings = parent.relativity
        if parent.type == "MESH" and settings.enabled and settings.motion != "STATIC":
            own = obj.relativity
            if own.motion != settings.motion or (own.motion == "CONSTANT" and tuple(own.beta) != tuple(settings.beta)):
                how = "Constant Velocity with the same velocity" if settings.motion == "CONSTANT" else "Animation"
                raise RelativityError(
                    f"Object {obj.name!r} rides on its moving parent {parent.name!r}: set its Motion to {how}"
                )
            return
        parent = parent.parent


def plays_own_animation(obj: Object, scene: Scene) -> bool:
    """Whether the object has its own animation to play on a clock of its own: keyframes that turn
    or scale it (or an object parent), or keyframed shape-key values. Objects whose keyframes are
    not their motion (:func:`animation.keyframe_motion_problem`) are left as Blender shows them."""
    if animation.keyframe_motion_problem(obj, scene) is not None:
        return False
    return animation.has_own_animation(obj, scene) or shape_keys.has_animated_shape_keys(obj)


def path_clock(obj: Object, fps: float, step: float, c: float) -> Callable[[npt.ArrayLike], FloatArray]:
    """The object's proper time ``tau(t)`` along its keyframed path (:func:`_path_clock`)."""
    return _path_clock(obj, fps, step, c)


def _path_clock(obj, fps, step, c):
    """``tau(t)`` (seconds to seconds, arrays) of a keyframed object: ``integral dt / gamma`` along
    the path of its origin as its keyframes (all at scene time) draw it, straight between samples
    ``step`` apart (coarser if more than CLOCK_SAMPLES would be needed); 0 at scene time 0. The
    path is kept between updates while the keyframes stay the same
    (``animation.keyframes_signature``) and extended by the samples missing when a time falls
    outside it, so stepping through frames evaluates only the new ones."""
    signature = animation.keyframes_signature(obj)
    key = (obj.name, fps, step, c, signature)
    table = _clock_tables.get(obj.name)
    if table is None or table["key"] != key:
        table = {"key": key, "spacing": step}
        _clock_tables[obj.name] = table

    def path(indices):
        if not len(indices):
            return np.empty((0, 3))
        return animation.world_matrices(obj, indices * table["spacing"] * fps)[:, :3, 3]

    def clock(times):
        times = np.asarray(times, dtype=np.float64)
        low, high = min(0.0, float(times.min())), max(0.0, float(times.max()))
        if "grid" not in table or low < table["grid"][0] or high > table["grid"][-1]:
            first = int(np.floor(low / table["spacing"]))
            last = max(int(np.ceil(high / table["spacing"])), first + 1)
            if "grid" in table:
                old_first, old_last = table["indices"]
                first, last = min(first, old_first), max(last, old_last)
            if last - first > CLOCK_SAMPLES:  # coarser samples: start afresh
                table.pop("grid", None)
                table["spacing"] = (high - low) / CLOCK_SAMPLES
                first, last = int(np.floor(low / table["spacing"])), int(np.ceil(high / table["spacing"]))
            if "grid" in table:
                points = np.concatenate(
                    [path(np.arange(first, old_first)), table["path"], path(np.arange(old_last + 1, last + 1))]
                )
            else:
                points = path(np.arange(first, last + 1))
            grid = np.arange(first, last + 1) * table["spacing"]
            table.update(
                indices=(first, last), grid=grid, path=points, taus=proper_time.path_proper_times(grid, points, c)
            )
        return np.interp(times, table["grid"], table["taus"])

    return clock


def proper_time_apparent_positions(
    obj: Object,
    scene: Scene,
    rest_local: FloatArray,
    t_o: float,
    x_o: npt.ArrayLike,
    beta_o: npt.ArrayLike,
    c: float,
    beta_u: FloatArray | None = None,
    matrix_now: FloatArray | None = None,
    shape_keys_too: bool = True,
) -> Positions:
    """An object with its own animation (:func:`plays_own_animation`: a spinning wheel, a clock's
    hands, shape keys) plays it at its proper time ``tau`` (its clock reads 0 at scene time 0),
    evaluated at each vertex's retarded time by the sampled solver.

    CONSTANT (``beta_u``): ``tau = t / gamma``; the origin moves with ``beta_u`` through where
    Blender draws it at ``t_o`` (``matrix_now``; keyframed location is not a motion of a CONSTANT
    object). ANIMATION: the location keys (under the parents) are the world line, at scene time;
    rotation and scale keys of the object and its parents are its own animation, at ``tau(t) =
    integral dt / gamma`` along the origin's path (:func:`_path_clock`). Shape-key values are read at
    the ``tau`` of each vertex's retarded time (:class:`shape_keys.ShapeKeyMotion`), solving again
    with the shape each vertex had there (SHAPE_PASSES times). With Proper Time off the clock is
    the scene's."""
    fps = animation.frames_per_second(scene)
    step = 1.0 / (int(obj.relativity.samples_per_frame) * fps)
    dilate = bool(obj.relativity.use_proper_time)
    if beta_u is not None:
        gamma = 1.0 / np.sqrt(1.0 - beta_u @ beta_u) if dilate else 1.0
        origin_now = matrix_now[:3, 3].copy()

        def clock(times):
            return np.asarray(times, dtype=np.float64) / gamma

        def matrices(times):
            times = np.asarray(times, dtype=np.float64)
            own = animation.world_matrices(obj, clock(times) * fps)
            own[:, :3, 3] = origin_now + (times - t_o)[:, None] * (beta_u * c)
            return own
    else:
        clock = _path_clock(obj, fps, step, c) if dilate else np.asarray

        def matrices(times):
            times = np.asarray(times, dtype=np.float64)
            return animation.world_matrices(obj, times * fps, own_frames=clock(times) * fps)

    shape = None
    if (
        dilate
        and shape_keys_too
        and shape_keys.has_animated_shape_keys(obj)
        and shape_keys.scene_time_reason(obj) is None
    ):  # else at the scene's time: the object's warnings
        shape = shape_keys.ShapeKeyMotion(obj)
        shape.check(rest_local, scene.frame_current + scene.frame_subframe)
    try:
        now = matrices(np.array([t_o]))[0]
        result = sampling.apparent_positions_from_matrix_function(
            matrices, step, rest_local, t_o, x_o, beta_o, c, world_matrix_now=now
        )
        for _ in range(SHAPE_PASSES if shape is not None else 0):
            shaped = shape.positions(clock(t_o - result[1]) * fps)
            result = sampling.apparent_positions_from_matrix_function(
                matrices, step, shaped, t_o, x_o, beta_o, c, world_matrix_now=now
            )
    except ValueError as error:
        raise RelativityError(f"Object {obj.name!r}: {error}") from None
    return result


def animated_apparent_positions(
    obj: Object,
    scene: Scene,
    rest_local: FloatArray,
    t_o: float,
    x_o: npt.ArrayLike,
    beta_o: npt.ArrayLike,
    c: float,
    max_tries: int = 4,
    obj_eval: Object | None = None,
    shape_keys_too: bool = True,
) -> Positions:
    """Apparent world positions and beta of an ANIMATION object (rigid motion): from its baked
    world matrices when it has a motion bake, else from its keyframes under its parent chain
    (:func:`animation.world_matrices`). An object whose keyframes are not its motion
    (constraints, transform drivers, NLA, ...) and that has no bake raises RelativityError."""
    fps = animation.frames_per_second(scene)
    obj_eval = obj if obj_eval is None else obj_eval
    bake = modifier.motion_bake(obj)
    if bake is not None:
        return _baked_apparent_positions(obj, bake, obj_eval, rest_local, fps, t_o, x_o, beta_o, c)
    problem = animation.keyframe_motion_problem(obj, scene)
    if problem is not None:
        raise RelativityError(
            f"Object {obj.name!r} is moved by more than its keyframes ({problem}): "
            "bake its motion (Bake Motion in the Relativity panel)"
        )
    if obj.relativity.use_proper_time and plays_own_animation(obj, scene):
        return proper_time_apparent_positions(
            obj, scene, rest_local, t_o, x_o, beta_o, c, shape_keys_too=shape_keys_too
        )
    step = 1.0 / (int(obj.relativity.samples_per_frame) * fps)
    try:
        return sampling.apparent_positions_from_matrix_function(
            lambda times: animation.world_matrices(obj, times * fps),
            step,
            rest_local,
            t_o,
            x_o,
            beta_o,
            c,
            max_tries,
            world_matrix_now=matrix_array(obj_eval.matrix_world),
        )
    except ValueError as error:
        raise RelativityError(f"Object {obj.name!r}: {error}") from None


def _baked_apparent_positions(obj, bake, obj_eval, rest_local, fps, t_o, x_o, beta_o, c):
    first_frame, per_frame, matrices = bake
    frame_now = t_o * fps
    index = (frame_now - first_frame) * per_frame
    if abs(index - round(index)) < 1e-6 and 0 <= round(index) < len(matrices):
        # The bake holds this very frame: if the object is elsewhere now, the bake is stale.
        now = matrix_array(obj_eval.matrix_world)
        if np.max(np.abs(matrices[round(index)] - now)) > 1e-5 * (1.0 + np.max(np.abs(now))):
            raise RelativityError(
                f"Object {obj.name!r} moves differently from its motion bake at frame {frame_now:g}: "
                "bake its motion again"
            )
    start, step = first_frame / fps, 1.0 / (per_frame * fps)
    times = start + step * np.arange(len(matrices))
    result = rest_shape.apparent_positions_rigid_rest_shape(times, matrices, rest_local, t_o, x_o, c, beta_o)
    t_e = t_o - result[1]
    if t_e.size and (t_e.min() < times[0] or t_e.max() > times[-1]):
        raise RelativityError(
            f"Object {obj.name!r}: retarded times {t_e.min():.4g}..{t_e.max():.4g} s lie outside the "
            f"baked motion {times[0]:.4g}..{times[-1]:.4g} s; bake a wider frame range"
        )
    return result


def deformed_apparent_positions(
    obj: Object, count: int, t_o: float, x_o: npt.ArrayLike, beta_o: npt.ArrayLike, c: float
) -> Positions:
    """Apparent positions of a deforming object from its baked samples (per-vertex retarded times)."""
    mesh = modifier.bake_mesh(obj)
    if mesh is None:
        raise RelativityError(f"Object {obj.name!r} is deforming but not baked: press Bake Deformation first")
    info = modifier.cache_data(obj)[names.BAKE_KEY]
    if info["points"] != count:
        raise RelativityError(f"Object {obj.name!r}: the mesh changed since the deformation bake; bake again")
    if names.BAKE_ORIGINS_KEY not in info:
        raise RelativityError(
            f"Object {obj.name!r}: the deformation bake has no origin path (an earlier version made it); bake again"
        )
    positions = np.empty((info["samples"], count * 3), dtype=np.float32)
    for i in range(info["samples"]):
        mesh.attributes[f"sample_{i:05d}"].data.foreach_get("vector", positions[i])
    times = info["start"] + info["step"] * np.arange(info["samples"])
    origins = np.array(info[names.BAKE_ORIGINS_KEY], dtype=np.float64).reshape(-1, 3)
    positions = positions.reshape(info["samples"], count, 3).astype(np.float64)
    if obj.relativity.use_proper_time:
        # The origin's path is the world line; the baked shape about it (armature, shape keys,
        # modifiers, rotation, scale) is the object's own animation, played at its proper time.
        try:
            positions = proper_time.own_animation_at_proper_time(times, positions, origins, c)
        except ValueError as error:
            raise RelativityError(f"Object {obj.name!r}: {error}") from None
    result = rest_shape.apparent_positions_deforming_rest_shape(times, positions, origins, t_o, x_o, c, beta_o)
    t_e = t_o - result[1]
    if t_e.min() < times[0] or t_e.max() > times[-1]:
        raise RelativityError(
            f"Object {obj.name!r}: retarded times {t_e.min():.4g}..{t_e.max():.4g} s lie outside the "
            f"baked range {times[0]:.4g}..{times[-1]:.4g} s; bake a wider frame range"
        )
    return result
