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

import numpy as np

from ...physics import tessellation
from ..common import busy, compat, names
from . import edge_bounds, modifier, motion
from .edge_bounds import PROVEN_MARGIN

if TYPE_CHECKING:
    import numpy.typing as npt
    from bpy.types import Mesh, Modifier, Object, Scene

    from ...physics.arrays import FloatArray
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
        and bool(
            edge_bounds.edge_image_bound(obj, matrix, snap, (width, height), tolerance) <= PROVEN_MARGIN * tolerance
        ),
    }


def camera_offset(matrix: FloatArray, snap: Snapshot) -> tuple[float, ...]:
    """The edge check's ``Camera Offset``: the object's origin (world ``matrix``) from the observer, in
    the camera's axes."""
    return tuple(camera_offsets(np.asarray(matrix, dtype=np.float64)[None, :3, 3], snap)[0].tolist())


def camera_offsets(translations: FloatArray, snap: Snapshot) -> FloatArray:
    """:func:`camera_offset` of each object origin (rows of ``translations``, N x 3)."""
    rotation = np.asarray(snap.world_to_camera, dtype=np.float64)
    return (translations - np.asarray(snap.mesh_observer[1], dtype=np.float64)) @ rotation.T


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
        edge_bounds.announce(obj)
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
