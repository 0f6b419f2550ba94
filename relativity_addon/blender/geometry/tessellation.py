"""Adaptive tessellation: which faces of a mesh the modifier subdivides, and how often
(``physics/tessellation.py`` measures the edges).

With *Adaptive* on (the default), an edge whose apparent image, drawn as straight pieces between
moved vertices, strays from the true image by more than the object's *Tolerance* (pixels at the
render resolution, measured through the scene camera for the boosted-mesh preview) marks its
faces for subdivision; the faces so marked get the fewest levels, up to *Tessellation*, that bring
every such edge within the tolerance. The others keep their topology. Faces across the seam
from a subdivided one are marked too (code 2): the modifier puts the seam's new vertices on their
straight edges, so the surface has no crack there.

The decision is made on the object's own mesh: with an enabled modifier before the relativity
one, a deformation bake, or a camera that is not a perspective one, every face gets one level
(at most *Tessellation*), the default before *Adaptive*; *Adaptive* off gives every face the
*Tessellation* levels. While a render runs (and behind the exact camera of
the final render) the decision of the last update is kept: its topology must not change where
the depsgraph cannot be evaluated again.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import bpy
import numpy as np

from ...physics import tessellation
from ..common import busy, compat, names
from . import modifier, motion

if TYPE_CHECKING:
    import numpy.typing as npt
    from bpy.types import Depsgraph, Mesh, Modifier, Object, Scene

    from ...physics.arrays import BoolArray, FloatArray
    from ..scene.snapshot import Snapshot

SUBDIVIDED, ACROSS_SEAM = 1.0, 2.0  # face codes (0: left as it is)
# Adaptive where the edges cannot be measured: every face gets at most this many levels (the
# default before adaptive tessellation), not Tessellation's most
UNMEASURED_LEVELS = 1


@dataclass(frozen=True)
class Decision:
    """``level`` for the faces subdivided; ``codes`` (float32 per face) or None: every face;
    ``weld``: the distance (object space) within which the seam's vertex copies are one vertex;
    ``warning``: edges still bent beyond the tolerance at the highest level (one line), "" when the
    edges were measured and none is, None when they were not measured (uniform subdivision)."""

    level: int
    codes: np.ndarray | None = None
    weld: float = 0.0
    warning: str | None = None
    # the measured mesh's vertices and what the update computes for them (apparent positions,
    # light delays, velocities): reused when the evaluated rest points are these vertices
    vertices: tuple | None = None

    def key(self) -> str:
        codes = None if self.codes is None else (len(self.codes), zlib.crc32(self.codes.tobytes()))
        return repr((self.level, codes, self.weld))


def _own_mesh(obj: Object) -> bool:
    """Whether the modifier's incoming mesh is the object's own (no enabled modifier before it)."""
    ours = modifier.find_modifier(obj)
    for each in obj.modifiers:
        if each == ours:
            return True
        if each.show_viewport or each.show_render:
            return False
    return True


def _mesh_arrays(mesh: Mesh) -> tuple[FloatArray, np.ndarray]:
    """Vertices (object space) and edges."""
    rest = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", rest)
    edges = np.empty(len(mesh.edges) * 2, dtype=np.int32)
    mesh.edges.foreach_get("vertices", edges)
    return rest.reshape(-1, 3).astype(np.float64), edges.reshape(-1, 2)


def _face_arrays(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The faces' loop edges, loop starts and loop totals."""
    loop_edges = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("edge_index", loop_edges)
    starts = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("loop_start", starts)
    totals = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("loop_total", totals)
    return loop_edges, starts, totals


def render_size(scene: Scene) -> tuple[float, float]:
    """The rendered image's width and height in pixels."""
    render = scene.render
    scale = render.resolution_percentage / 100.0
    return max(1.0, render.resolution_x * scale), max(1.0, render.resolution_y * scale)


def decide(scene: Scene, obj: Object, obj_eval: Object, snap: Snapshot) -> Decision | None:
    """The subdivision of ``obj`` for the snapshot (None: keep the last one). Raises ValueError
    from the physics core (superluminal motion), as the update does."""
    settings = obj.relativity
    if not settings.use_adaptive_tessellation or settings.tessellation == 0:
        return Decision(int(settings.tessellation))
    uniform = Decision(min(int(settings.tessellation), UNMEASURED_LEVELS))
    if snap.exact_camera or busy.rendering():  # a render's handlers must not evaluate the depsgraph again
        return None
    mesh = cast("Mesh", obj.data)
    if (
        not _own_mesh(obj)
        or (settings.motion == "ANIMATION" and settings.use_deformation)
        or not snap.projection
        or snap.projection[0] != "PERSP"
        or len(mesh.polygons) == 0
    ):
        return uniform
    rest, edges = _mesh_arrays(mesh)
    eye = snap.mesh_observer[1]
    world_to_camera = snap.world_to_camera
    window = tuple(snap.projection[1:5])
    size = render_size(scene)

    seen = []

    def apparent(points: FloatArray) -> FloatArray:
        if not seen and points.shape == rest.shape and np.may_share_memory(points, rest):
            # every vertex (edge_levels' first call, a view of ``rest``): as the update computes them
            seen.extend(motion.apparent_world_positions(scene, obj, obj_eval, points, snap, with_delay=True))
            return seen[0]
        return motion.apparent_world_positions(scene, obj, obj_eval, points, snap, shape_keys_too=False)[0]

    def project(points: FloatArray) -> FloatArray:
        return tessellation.perspective_pixels(points, eye, world_to_camera, window, size)

    tolerance = float(settings.tessellation_tolerance)
    levels, left = tessellation.edge_levels(rest, edges, apparent, project, tolerance, int(settings.tessellation), size)
    warning = ""
    if np.any(left > tolerance):
        worst = float(np.max(left))
        bend = "reach behind the camera" if not np.isfinite(worst) else f"still bend up to {worst:.1f} px"
        warning = (
            f"Mesh {obj.name!r}: edges {bend} at Tessellation {settings.tessellation} "
            f"(tolerance {tolerance:g} px): raise Tessellation"
        )
    if not np.any(levels):
        return Decision(0, warning=warning, vertices=(rest, *seen) if seen else None)
    loop_edges, starts, totals = _face_arrays(mesh)
    face_level, across = tessellation.face_levels(levels, loop_edges, starts, totals)
    level = int(face_level.max(initial=0))
    if level == 0:  # only loose edges bend
        return Decision(0, warning=warning, vertices=(rest, *seen) if seen else None)
    if np.all(face_level > 0):
        return Decision(level, warning=warning)
    subdivided = face_level > 0
    codes = np.where(subdivided, SUBDIVIDED, np.where(across, ACROSS_SEAM, 0.0)).astype(np.float32)
    return Decision(level, codes, _weld_distance(rest, edges, loop_edges, subdivided, totals, level), warning)


def edge_measure_inputs(scene: Scene, obj: Object, obj_eval: Object, snap: Snapshot) -> dict[str, object] | None:
    """The modifier's inputs for its edge verdict (``node_group.EDGE_MEASURE_INPUTS``, ``Tolerance``)
    on a closed-form object, or None where :func:`decide` measures no edges or keeps the last
    decision (the verdict is then off, and the modifier subdivides as the decision says)."""
    settings = obj.relativity
    if (
        not settings.use_adaptive_tessellation
        or settings.tessellation == 0
        or snap.exact_camera
        or busy.rendering()
        or not _own_mesh(obj)
        or not snap.projection
        or snap.projection[0] != "PERSP"
        or len(cast("Mesh", obj.data).polygons) == 0
    ):
        return None
    matrix = motion.matrix_array(obj_eval.matrix_world)
    view = np.asarray(snap.world_to_camera, dtype=np.float64) @ matrix[:3, :3]
    left, right, bottom, top = snap.projection[1:5]
    width, height = render_size(scene)
    tolerance = float(settings.tessellation_tolerance)
    return {
        "Camera X": tuple(view[:, 0]),
        "Camera Y": tuple(view[:, 1]),
        "Camera Z": tuple(view[:, 2]),
        "Camera Offset": camera_offset(matrix, snap),
        "Pixel Scale": (width / (right - left), height / (top - bottom), 1.0),
        "Window Low": (left, bottom, 0.0),
        "Tolerance": tolerance,
        # the bound knows uniform motion only: a keyframed object's edges are always checked
        "Edges Proven Short": motion.closed_form(obj, scene)
        and bool(edge_image_bound(obj, matrix, snap, (width, height), tolerance) <= PROVEN_MARGIN * tolerance),
    }


def camera_offset(matrix: FloatArray, snap: Snapshot) -> tuple[float, ...]:
    """The edge check's ``Camera Offset``: the object's origin (world ``matrix``) from the observer, in
    the camera's axes."""
    return tuple(camera_offsets(np.asarray(matrix, dtype=np.float64)[None, :3, 3], snap)[0].tolist())


def camera_offsets(translations: FloatArray, snap: Snapshot) -> FloatArray:
    """:func:`camera_offset` of each object origin (rows of ``translations``, N x 3)."""
    rotation = np.asarray(snap.world_to_camera, dtype=np.float64)
    return (translations - np.asarray(snap.mesh_observer[1], dtype=np.float64)) @ rotation.T


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
    window = _window(snap)
    view = (x_o, beta_o, snap.world_to_camera, window, size)
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
                try:
                    bend = tessellation.edge_bend_bound(
                        *rests[row],
                        matrices[row],
                        velocities[row],
                        x_o,
                        beta_o,
                        snap.world_to_camera,
                        window,
                        size,
                        sweep=sweeps[index],
                    )
                except ValueError:
                    return proven
                bound = min(bound, bend)
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


def _bound(arguments: tuple, tolerance: float, acceleration: float, sweep: FloatArray | None) -> float:
    """The lengths' bound, or where it does not clear the tolerance the least of it and the bends'."""
    low, high, longest, matrix, beta, x_o, beta_o, rotation, window, size = arguments
    view = (matrix, beta, x_o, beta_o, rotation, window, size)
    bound = tessellation.edge_image_bound(low, high, longest, *view, sweep=sweep)
    if not bound <= PROVEN_MARGIN * tolerance:
        bend = tessellation.edge_bend_bound(low, high, longest, *view, acceleration=acceleration, sweep=sweep)
        bound = min(bound, bend)
    return bound


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


def edges_short(obj_eval: Object) -> bool | None:
    """The modifier's verdict at its last evaluation: every edge's image within the tolerance (True;
    the mesh was then left whole), not (False), or None (not measured there)."""
    mesh = obj_eval.data if obj_eval.type == "MESH" else None
    attribute = mesh.attributes.get(names.EDGES_SHORT_ATTRIBUTE) if mesh is not None else None
    if attribute is None or len(attribute.data) == 0:
        return None
    return bool(attribute.data[0].value)


def _weld_distance(rest, edges, loop_edges, subdivided, totals, level):
    """Far below the shortest piece of a subdivided edge, above float32 rounding of the positions."""
    face_of_loop = np.repeat(np.arange(len(totals)), totals)
    used = edges[loop_edges[subdivided[face_of_loop]]]
    shortest = float(np.min(np.linalg.norm(rest[used[:, 1]] - rest[used[:, 0]], axis=1), initial=np.inf))
    piece = shortest / 2**level if np.isfinite(shortest) and shortest > 0.0 else 1e-6
    rounding = 8.0 * float(np.finfo(np.float32).eps) * float(np.max(np.abs(rest), initial=1.0))
    return min(max(1e-3 * piece, rounding), 0.1 * piece)


def apply(obj: Object, mod: Modifier, cache: Object, decision: Decision) -> bool:
    """Set the modifier's inputs for ``decision`` and, with face codes, write them into the cache
    (no positions yet, so the modifier moves nothing until the update writes them). Returns
    whether anything changed (the object must then be evaluated again before its rest positions
    are read)."""
    group = mod.node_group
    data = cast("Mesh", cache.data)
    count = 0 if decision.codes is None else len(decision.codes)
    wanted = {"Tessellation": decision.level, "Face Codes": count, "Weld Distance": decision.weld}
    changed = data.get(names.TESSELLATION_KEY) != decision.key()
    for name, value in wanted.items():
        identifier = modifier.input_identifier(group, name)
        current = compat.modifier_input(mod, identifier)
        # a float socket may hold the value in single precision: equal within its rounding
        if current is None or not math.isclose(float(current), float(value), rel_tol=1e-6, abs_tol=0.0):
            compat.set_modifier_input(mod, identifier, value)
            changed = True
    if decision.warning is not None:
        data[names.TESSELLATION_WARNING_KEY] = decision.warning
    elif names.TESSELLATION_WARNING_KEY in data:
        del data[names.TESSELLATION_WARNING_KEY]
    if changed:
        modifier.write_cache(data, np.zeros((0, 3)), np.zeros((1, 3)), decision.codes)
        data[names.TESSELLATION_KEY] = decision.key()
        announce(obj)
        obj.update_tag()
    return changed


def face_codes(cache: Object, mod: Modifier) -> np.ndarray | None:
    """The face codes the cache holds for the modifier (kept when the decision is), or None."""
    count = modifier.input_value(mod, "Face Codes")
    attribute = cache.data.attributes.get(names.FACE_CODE_ATTRIBUTE) if count else None
    if attribute is None or len(attribute.data) < count:
        return None
    values = np.empty(len(attribute.data), dtype=np.float32)
    attribute.data.foreach_get("value", values)
    return values[len(values) - count :]


def warning(obj: Object) -> str | None:
    """The last update's one line about edges still too bent, "" when it measured them and none
    is, None when it did not measure them (the coarse-edge measure then applies)."""
    data = modifier.cache_data(obj)
    return data.get(names.TESSELLATION_WARNING_KEY) if data is not None else None


# An edge longer than this fraction of its distance to the camera is too coarse for the
# apparent-geometry path to curve (aberration bends straight lines; only vertices move).
COARSE_EDGE_FRACTION = 0.25


def longest_edge_fraction(obj: Object, camera_position: npt.ArrayLike) -> float:
    """Longest mesh edge divided by its midpoint's distance to the camera (world units)."""
    mesh = obj.data
    if len(mesh.edges) == 0 or len(mesh.edges) > 200_000:
        return 0.0
    coordinates = np.empty(len(mesh.vertices) * 3)
    mesh.vertices.foreach_get("co", coordinates)
    world = motion.to_world(np.array(obj.matrix_world), coordinates.reshape(-1, 3))
    edges = np.empty(len(mesh.edges) * 2, dtype=np.int64)
    mesh.edges.foreach_get("vertices", edges)
    a, b = world[edges[0::2]], world[edges[1::2]]
    lengths = np.linalg.norm(b - a, axis=1)
    distances = np.linalg.norm((a + b) / 2.0 - np.asarray(camera_position), axis=1)
    return float(np.max(lengths / np.maximum(distances, 1e-9)))


def coarse_mesh_warning(obj: Object, camera_position: npt.ArrayLike) -> str | None:
    """A one-line warning when the tessellated mesh is too coarse to show curved lines, or None:
    with adaptive tessellation, edges left bent beyond the tolerance at the last update (nothing
    before Set Up: the update measures them); without, or where the update could not measure them,
    edges long for their distance to the camera."""
    level = obj.relativity.tessellation
    advice = "raise Tessellation"
    if obj.relativity.use_adaptive_tessellation:
        measured = warning(obj)
        if measured is not None or modifier.find_modifier(obj) is None:
            return measured or None
        level = min(level, UNMEASURED_LEVELS)  # what the update gives every face then
        advice = "set Adaptive off and raise Tessellation (Adaptive cannot measure this mesh)"
    # the modifier halves every edge once per tessellation level before moving the vertices
    fraction = longest_edge_fraction(obj, camera_position) / 2**level
    if fraction > COARSE_EDGE_FRACTION:
        return f"Edges up to {fraction:.2f}x their distance to the camera: too coarse to curve, {advice}"
    return None
