"""The edges' bound of a closed-form mesh (issue 26): from its rest box and longest edge alone
(``physics/tessellation.edge_image_bound`` and ``edge_bend_bound``), whether every edge's image stays
within the *Tolerance*, so that the modifier visits no edge and the update measures none
(``tessellation.edge_measure_inputs`` sets ``Edges Proven Short``). The rest box is read once per
rest shape; a bound over the origin's way through the frames to come (straight keys) holds for a
frame step on that way (``straight_steps``), and an observer's velocity change takes the bounds of
many meshes at once (:func:`prove_over_ways`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, cast

import bpy
import numpy as np

from ...physics import tessellation

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Mesh, Object

    from ...physics.arrays import BoolArray, FloatArray
    from ..scene.snapshot import Snapshot

    # One mesh's bound's arguments (``physics/tessellation.edge_image_bound``'s, in order): the rest box's low
    # and high, the longest edge, the world matrix, the velocity, the observer's place and velocity, the
    # camera's rotation, window and render size.
    _Arguments = tuple[
        FloatArray,
        FloatArray,
        float,
        FloatArray,
        Any,
        Any,
        Any,
        Any,
        tuple[float, float, float, float],
        tuple[float, float],
    ]

# The bound must clear the tolerance by this much (the modifier measures in float32).
PROVEN_MARGIN = 0.99
CHUNK_EDGES = 1 << 20  # edges whose lengths are computed at once
# Object name -> (the mesh's key, rest box low, high, longest edge) of its own mesh, read once per
# rest shape; forgotten when Blender evaluates the object's geometry again for a reason the add-on
# did not announce (:func:`note_updates`).
_rest_bounds: dict[str, tuple] = {}
# object name -> (the bound's inputs but the origin, the origin, the sweep it holds over or None, the
# bound, how many of the sweeps (:func:`_sweeps`) failed to clear the tolerance for these inputs)
_last_bound: dict[str, tuple] = {}
_announced: set[str] = set()


def _mesh_key(mesh: Mesh) -> tuple:
    return mesh.name, mesh.as_pointer(), len(mesh.vertices), len(mesh.edges)


def rest_bounds(obj: Object) -> tuple[FloatArray, FloatArray, float] | None:
    """The rest box (low, high) and longest edge of the object's own mesh (object space), the
    modifier's incoming mesh, or None where that is not the mesh (edit mode, shape keys)."""
    mesh = cast("Mesh", obj.data)
    if mesh.is_editmode or mesh.shape_keys is not None or len(mesh.vertices) == 0:
        return None
    known = _rest_bounds.get(obj.name)
    if known is not None and known[0] == _mesh_key(mesh):
        return known[1:]
    _rest_bounds[obj.name] = (_mesh_key(mesh), *_read_rest_bounds(mesh))
    return _rest_bounds[obj.name][1:]


def _read_rest_bounds(mesh: Mesh) -> tuple[FloatArray, FloatArray, float]:
    """The mesh's box (low, high) and longest edge: one read of its positions and edges."""
    rest = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.attributes["position"].data.foreach_get("vector", rest)
    rest = rest.reshape(-1, 3)
    edges = np.empty(len(mesh.edges) * 2, dtype=np.int32)
    mesh.edges.foreach_get("vertices", edges)
    longest = 0.0
    for start in range(0, len(edges), 2 * CHUNK_EDGES):  # bounds the float64 temporaries
        part = edges[start : start + 2 * CHUNK_EDGES].reshape(-1, 2)
        step = rest[part[:, 1]].astype(np.float64) - rest[part[:, 0]]  # exact: float32 ends
        longest = max(longest, float(np.einsum("ij,ij->i", step, step).max(initial=0.0)))
    longest = math.sqrt(longest) * (1.0 + 1e-9)
    return rest.min(axis=0).astype(np.float64), rest.max(axis=0).astype(np.float64), longest


def edge_image_bound(
    obj: Object,
    matrix: FloatArray,
    snap: Snapshot,
    size: tuple[float, float],
    tolerance: float,
    velocity: object = None,
    acceleration: float = 0.0,
    way: FloatArray | None = None,
) -> float:
    """A bound (pixels) on what the modifier's check and :func:`decide` measure of a closed-form
    object's edges, inf where it cannot be computed: a velocity change whose bound clears the
    tolerance needs no edge visited. The image lengths' bound
    (``physics/tessellation.edge_image_bound``), and where that does not clear ``tolerance`` the
    bends' (``edge_bend_bound``: no edge then needs subdividing either), whichever is less.
    ``velocity`` (fraction of c): the uniform motion's, when not the object's setting (keyframed
    motion uniform over its window, ``keyframed.py``; ``matrix`` then at the observer's time), with
    the window's ``acceleration`` (``edge_bend_bound``). ``way`` (world units): the origin's way
    through one frame on a straight world line: the bound is taken over the next frames' way
    (:func:`_sweep`), and one that clears the tolerance is kept for every origin on it (a frame step
    on the line computes none)."""
    bounds = rest_bounds(obj)
    if bounds is None:
        return float("inf")
    beta = tuple(obj.relativity.beta) if obj.relativity.motion == "CONSTANT" else (0.0, 0.0, 0.0)
    if velocity is not None:
        beta = tuple(map(float, cast("tuple[float, float, float]", velocity)))
    _t_o, x_o, beta_o = snap.mesh_observer
    window = _window(snap)
    key = _bound_key(bounds, matrix, beta, snap, size, tolerance, acceleration)
    origin = matrix[:3, 3]
    last = _last_bound.get(obj.name)
    # (a full update past the way's first half sweeps again: a frame step's record gets the new way)
    if last is not None and last[0] == key and on_way(origin, last[1], last[2], 0.5):
        return last[3]
    low, high, longest = bounds
    arguments = (low, high, longest, matrix, beta, x_o, beta_o, snap.world_to_camera, window, size)
    sweeps = [] if way is None else _sweeps(low, high, matrix, np.asarray(way, dtype=np.float64))
    # the sweeps that did not clear the tolerance with these inputs: not tried again
    tried = last[4] if last is not None and last[0] == key else 0
    kept = None
    try:
        for sweep in sweeps[tried:]:
            bound = _bound(arguments, tolerance, acceleration, sweep)
            if bound <= PROVEN_MARGIN * tolerance:
                kept = sweep
                break
            tried += 1
        if kept is None:
            bound = _bound(arguments, tolerance, acceleration, None)
    except ValueError:  # a velocity not below c: the update reports it
        bound, kept = float("inf"), None
    _last_bound[obj.name] = (key, origin.copy(), kept, bound, tried)
    return bound


def _window(snap: Snapshot) -> tuple[float, float, float, float]:
    return cast("tuple[float, float, float, float]", tuple(snap.projection[1:5]))


def _bound_key(
    bounds: tuple, matrix: FloatArray, beta: tuple, snap: Snapshot, size: tuple, tolerance: float, acceleration: float
) -> tuple:
    """What an object's edges' bound depends on but its origin: while it stays (a frame step, for most
    objects), the last bound stands."""
    _t_o, x_o, beta_o = snap.mesh_observer
    return (
        bounds[0].tobytes(),
        bounds[1].tobytes(),
        bounds[2],
        matrix[:3, :3].tobytes(),
        beta,
        tuple(x_o),
        tuple(beta_o),
        snap.camera_matrix,  # the camera's rotation comes from it (a numpy repr took milliseconds)
        _window(snap),
        size,
        tolerance,
        acceleration,
    )


def prove_over_ways(
    objects: list[Object],
    matrices: FloatArray,
    velocities: FloatArray,
    ways: FloatArray,
    snap: Snapshot,
    size: tuple[float, float],
) -> list[bool]:
    """:func:`edge_image_bound` of many objects in uniform motion at once (``matrices`` (N, 4, 4) at the
    observer's time, ``velocities`` (N, 3) fractions of c, ``ways`` (N, 3) their origins' way through a
    frame), only over a sweep (:func:`_sweeps`): for each object, whether it clears the object's
    tolerance, kept as its last bound (:func:`swept_bound`) where it does. The lengths' bound for all at
    once, the bends' for each whose lengths' bound does not clear (:func:`_bound`). The others (no rest
    box, or no sweep clearing) are left to their full update (the bound without a sweep, and else the
    modifier's check). An observer's velocity change on many objects (issue 26)."""
    proven = [False] * len(objects)
    rests = {row: rest for row, obj in enumerate(objects) if (rest := rest_bounds(obj)) is not None}
    rows = np.array(sorted(rests), dtype=np.int64)
    if not len(rows):
        return proven
    lows, highs = np.array([rests[row][0] for row in rows]), np.array([rests[row][1] for row in rows])
    longest = np.array([rests[row][2] for row in rows])
    tolerances = PROVEN_MARGIN * np.array([float(objects[row].relativity.tessellation_tolerance) for row in rows])
    frames = _sweep_frames(lows, highs, matrices[rows], ways[rows])
    _t_o, x_o, beta_o = snap.mesh_observer
    view = (x_o, beta_o, snap.world_to_camera, _window(snap), size)
    left = np.ones(len(rows), dtype=bool)  # not proven yet
    for tried, parts in enumerate((frames, frames // 2)):  # the longer sweep first, then half of it
        left &= parts > 0
        if not left.any():
            break
        sweeps = ways[rows] * parts[:, None]
        try:
            bounds = tessellation.edge_image_bounds(
                lows[left],
                highs[left],
                longest[left],
                matrices[rows[left]],
                velocities[rows[left]],
                *view,
                sweeps[left],
            )
        except ValueError:  # a velocity not below c: the full update reports it
            return proven
        for index, bound in zip(np.flatnonzero(left).tolist(), bounds.tolist(), strict=True):
            row = int(rows[index])
            if not bound <= tolerances[index]:  # the bends' bound then, one object's (as _bound)
                arguments = (*rests[row], matrices[row], velocities[row], *view)
                try:
                    bound = min(bound, _bends(arguments, 0.0, sweeps[index]))
                except ValueError:
                    return proven
            if bound <= tolerances[index]:
                proven[row] = True
                # (no key: the next full update takes its bound again; the sweep holds)
                _last_bound[objects[row].name] = (None, matrices[row, :3, 3].copy(), sweeps[index], bound, tried)
        left = ~np.array([proven[row] for row in rows.tolist()])
    return proven


# Straight keys: the edges' bound is taken over the origin's way through up to this many frames to
# come, and up to SWEEP_SIZES times the object's size (the bound's box grows by the sweep), one frame's
# at least; where that bound does not clear the tolerance, over half that way.
SWEEP_FRAMES = 16
SWEEP_SIZES = 32.0


def _sweeps(low: FloatArray, high: FloatArray, matrix: FloatArray, way: FloatArray) -> list[FloatArray]:
    """The origin's ways over the frames the bound is taken for (world units), longest first."""
    frames = int(_sweep_frames(low[None], high[None], matrix[None], way[None])[0])
    return [way * frames] + ([way * (frames // 2)] if frames > 1 else [])


def _sweep_frames(lows: FloatArray, highs: FloatArray, matrices: FloatArray, ways: FloatArray) -> np.ndarray:
    """How many frames each object's longest sweep spans (:func:`_sweeps`; rows: the objects)."""
    sizes = np.sqrt(
        ((highs - lows) ** 2).sum(axis=1) * (matrices[:, :3, :3] ** 2).sum(axis=(1, 2))
    )  # the box's at least
    steps = np.sqrt((ways * ways).sum(axis=1))
    with np.errstate(divide="ignore", invalid="ignore"):
        fewer = np.maximum(1, np.nan_to_num(SWEEP_SIZES * sizes / steps, posinf=SWEEP_FRAMES).astype(np.int64))
    return np.where(steps * SWEEP_FRAMES <= SWEEP_SIZES * sizes, SWEEP_FRAMES, fewer)


def _bound(arguments: _Arguments, tolerance: float, acceleration: float, sweep: FloatArray | None) -> float:
    """The lengths' bound, or where it does not clear the tolerance the least of it and the bends'."""
    bound = tessellation.edge_image_bound(*arguments, sweep=sweep)
    if not bound <= PROVEN_MARGIN * tolerance:
        bound = min(bound, _bends(arguments, acceleration, sweep))
    return bound


def _bends(arguments: _Arguments, acceleration: float, sweep: FloatArray | None) -> float:
    """The bends' bound (``physics/tessellation.edge_bend_bound``) of :func:`_bound`'s ``arguments``."""
    return tessellation.edge_bend_bound(*arguments, acceleration=acceleration, sweep=sweep)


def swept_bound(obj: Object) -> tuple[FloatArray, FloatArray] | None:
    """``(origin, sweep)``: the segment of origins over which the object's last edges' bound holds
    (:func:`edge_image_bound` with ``way``), or None (no sweep)."""
    last = _last_bound.get(obj.name)
    return None if last is None or last[2] is None else (last[1], last[2])


def on_way(origin: FloatArray, start: FloatArray, sweep: FloatArray | None, part: float = 1.0) -> bool:
    """Whether ``origin`` is ``start`` or on the segment from it along ``sweep`` (its first ``part``;
    float rounding allowed across it: far below anything the bounds resolve)."""
    if np.array_equal(origin, start):
        return True
    if sweep is None:
        return False
    return bool(on_ways(np.asarray(origin)[None], np.asarray(start)[None], np.asarray(sweep)[None], part)[0])


def on_ways(origins: FloatArray, starts: FloatArray, sweeps: FloatArray, part: float = 1.0) -> BoolArray:
    """:func:`on_way` of each row of ``origins`` (N, 3), ``starts`` and ``sweeps``."""
    moved = origins - starts
    along = (moved * sweeps).sum(axis=1) / np.maximum((sweeps * sweeps).sum(axis=1), 1e-300)
    across = moved - along[:, None] * sweeps
    scale = 1e-9 * (1.0 + np.abs(starts).max(axis=1) + np.abs(sweeps).max(axis=1))
    inside = (along >= -1e-9) & (along <= part + 1e-9) & (np.abs(across).max(axis=1) <= scale)
    return (origins == starts).all(axis=1) | inside


def announce(obj: Object) -> None:
    """The next evaluation of ``obj``'s geometry is the add-on's (its settings or the modifier's
    inputs changed): its rest shape is not read again for it."""
    _announced.add(obj.name)


def note_updates(depsgraph: Depsgraph) -> None:
    """Forget the rest bounds of the objects whose geometry Blender evaluated again unannounced
    (an edit of the mesh, or of anything else). An announcement holds for one evaluation only."""
    for update in depsgraph.updates:
        if update.is_updated_geometry and isinstance(update.id, bpy.types.Object):
            if update.id.name not in _announced:
                _rest_bounds.pop(update.id.name, None)
    _announced.clear()
