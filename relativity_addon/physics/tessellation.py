"""Where a mesh must be subdivided so that its apparent image stays right (adaptive tessellation).

The apparent-geometry path moves only vertices: between two vertices the renderer draws a straight
segment, while the apparent image of a straight edge is curved (light-travel time, aberration;
docs/physics.md, "Light-travel time (retarded positions)"). The error an edge leaves is measured
where it is largest for a gently curved image, at its middle: the image of the edge's apparent
midpoint against the image of the midpoint of the drawn segment (the point the renderer puts there,
texture included), in pixels. An edge split into ``2**k`` parts (``k`` levels of subdivision) is
measured the same way on each part.

Everything is vectorised over edges; the apparent map and the projection are given as functions
of arrays of points, so this module knows no camera model and no motion.
"""

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from .arrays import ArrayLike, BoolArray, FloatArray, IndexArray

# rest points (M, 3) -> apparent positions (M, 3), any frame the projection takes
ApparentMap = Callable[[FloatArray], FloatArray]
# positions (M, 3) -> image positions in pixels (M, 2); NaN for points the camera cannot see
# (behind it)
Projection = Callable[[FloatArray], FloatArray]


def perspective_pixels(
    points: ArrayLike,
    eye: ArrayLike,
    world_to_camera: ArrayLike,
    window: tuple[float, float, float, float],
    resolution: tuple[float, float],
) -> FloatArray:
    """Pixel positions ``(M, 2)`` (x right, y up, from the image's lower-left corner) of world
    points seen by a pinhole camera at ``eye`` with rotation ``world_to_camera`` (3, 3; the camera
    looks down its local -Z, Blender's convention) whose image on the plane at unit distance is
    ``window = (left, right, bottom, top)``, rendered at ``resolution = (width, height)`` pixels.
    Points at or behind the camera's plane are NaN."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    local = (np.asarray(world_to_camera, dtype=np.float64) @ (points - np.asarray(eye, dtype=np.float64)).T).T
    depth = -local[:, 2]
    left, right, bottom, top = window
    width, height = resolution
    with np.errstate(divide="ignore", invalid="ignore"):
        x = (local[:, 0] / depth - left) * (width / (right - left))
        y = (local[:, 1] / depth - bottom) * (height / (top - bottom))
    pixels = np.stack((x, y), axis=1)
    pixels[~(depth > 1e-9 * (1.0 + np.abs(local[:, 0]) + np.abs(local[:, 1])))] = np.nan
    return pixels


def segment_bends(
    rest_a: ArrayLike, rest_b: ArrayLike, parts: int, apparent: ApparentMap, project: Projection
) -> FloatArray:
    """The largest image error in pixels (``(E,)``) over the ``parts`` equal pieces of each edge
    ``rest_a[i] -> rest_b[i]`` (rest positions, ``(E, 3)``) drawn as straight segments between
    the pieces' apparent end points: for each piece, the distance between the image of the
    apparent position of its rest midpoint and the image of the midpoint of its apparent end
    points. Infinite where a piece is partly in front of the camera and partly not (it must be
    split); zero where the camera sees none of it."""
    a = np.asarray(rest_a, dtype=np.float64).reshape(-1, 3)
    b = np.asarray(rest_b, dtype=np.float64).reshape(-1, 3)
    if len(a) == 0:
        return np.zeros(0)
    # 2 * parts + 1 points along each edge: the pieces' end points are the even ones
    fractions = np.arange(2 * parts + 1, dtype=np.float64) / (2 * parts)
    rest = a[:, None, :] + fractions[None, :, None] * (b - a)[:, None, :]
    seen = np.asarray(apparent(rest.reshape(-1, 3)), dtype=np.float64).reshape(rest.shape)
    ends_a, middles, ends_b = seen[:, 0:-1:2], seen[:, 1::2], seen[:, 2::2]
    image_middle = np.asarray(project(middles.reshape(-1, 3))).reshape(len(a), parts, 2)
    image_drawn = np.asarray(project(((ends_a + ends_b) / 2.0).reshape(-1, 3))).reshape(len(a), parts, 2)
    image_ends = np.asarray(project(seen[:, 0::2].reshape(-1, 3))).reshape(len(a), parts + 1, 2)
    return np.max(_piece_bends(image_middle, image_drawn, image_ends[:, :-1], image_ends[:, 1:]), axis=1)


def _piece_bends(
    image_middle: FloatArray, image_drawn: FloatArray, image_a: FloatArray, image_b: FloatArray
) -> FloatArray:
    """The pieces' errors from the images of their middles, drawn middles and ends (``(..., 2)``):
    infinite where some of these are seen and some not, zero where none is."""
    bend = np.linalg.norm(image_middle - image_drawn, axis=-1)
    seen = [np.isfinite(image[..., 0]) for image in (image_middle, image_drawn, image_a, image_b)]
    visible = seen[0] | seen[1] | seen[2] | seen[3]
    hidden = ~(seen[0] & seen[1] & seen[2] & seen[3])
    return np.where(visible & hidden, np.inf, np.where(visible, bend, 0.0))


def _whole_edge_bends(
    rest: FloatArray, edges: IndexArray, seen: FloatArray, image: FloatArray, apparent: ApparentMap, project: Projection
) -> FloatArray:
    """:func:`segment_bends` of whole edges (one piece) given their ends' apparent positions
    ``seen`` and images ``image`` (per vertex): one apparent position more per edge, not three."""
    a, b = edges[:, 0], edges[:, 1]
    middles = np.asarray(apparent((rest[a] + rest[b]) / 2.0), dtype=np.float64)
    image_drawn = np.asarray(project((seen[a] + seen[b]) / 2.0))
    return _piece_bends(np.asarray(project(middles)), image_drawn, image[a], image[b])


def edge_levels(
    rest: ArrayLike,
    edges: ArrayLike,
    apparent: ApparentMap,
    project: Projection,
    tolerance: float,
    max_level: int,
    frame: tuple[float, float] | None = None,
) -> tuple[IndexArray, FloatArray]:
    """For each edge (``edges``: ``(E, 2)`` indices into the rest points ``rest``, ``(V, 3)``) the
    fewest subdivision levels ``k <= max_level`` after which every piece's image error
    (:func:`segment_bends`) is at most ``tolerance`` pixels, and the error left at that level
    (above ``tolerance`` only where ``max_level`` is not enough).

    Edges whose image (the segment between the images of its apparent end points) is at most
    ``tolerance`` pixels long are not measured: an image arc of about that length cannot stray
    further than its length from its chord's middle, so they need no level; nor, given the
    picture's ``frame`` (width, height in pixels), edges further out of it than their length. The apparent map is
    evaluated once for every vertex and then only for the edges still too bent, level by level."""
    if not np.isfinite(tolerance) or tolerance <= 0.0:
        raise ValueError(f"tolerance must be a positive number of pixels, got {tolerance!r}")
    if max_level < 0:
        raise ValueError(f"max_level must be 0 or more, got {max_level!r}")
    rest = np.asarray(rest, dtype=np.float64).reshape(-1, 3)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    levels = np.zeros(len(edges), dtype=np.int64)
    left = np.zeros(len(edges))
    if len(edges) == 0:
        return levels, left
    seen = np.asarray(apparent(rest), dtype=np.float64)
    image = np.asarray(project(seen))
    ends_a, ends_b = image[edges[:, 0]], image[edges[:, 1]]
    length = np.linalg.norm(ends_b - ends_a, axis=1)
    both_seen = np.isfinite(length)
    neither_seen = ~np.isfinite(ends_a[:, 0]) & ~np.isfinite(ends_b[:, 0])
    # short images need nothing, nor edges with both ends out of the camera's sight; an edge with
    # one end behind the camera is measured (and split)
    todo = np.flatnonzero(
        ~(both_seen & (length <= tolerance)) & ~neither_seen & ~_off_frame(ends_a, ends_b, length, frame)
    )
    for level in range(max_level + 1):
        if len(todo) == 0:
            break
        bend = np.concatenate(
            [
                _whole_edge_bends(rest, edges[chunk], seen, image, apparent, project)
                if level == 0
                else segment_bends(rest[edges[chunk, 0]], rest[edges[chunk, 1]], 2**level, apparent, project)
                for chunk in np.array_split(todo, -(-len(todo) // CHUNK))
            ]
        )
        levels[todo] = level
        left[todo] = bend
        todo = todo[bend > tolerance]
    return levels, left


# edges measured at once (bounds the memory of the pieces' points)
CHUNK = 200_000


def _off_frame(
    ends_a: FloatArray, ends_b: FloatArray, length: FloatArray, frame: tuple[float, float] | None
) -> BoolArray:
    """Edges whose image lies beyond one side of the ``frame`` (width, height in pixels) by more
    than its length: as for short images, the arc cannot reach back into the picture."""
    if frame is None:
        return np.zeros(len(length), dtype=bool)
    width, height = frame
    with np.errstate(invalid="ignore"):
        x_low = np.maximum(ends_a[:, 0], ends_b[:, 0]) < -length
        x_high = np.minimum(ends_a[:, 0], ends_b[:, 0]) > width + length
        y_low = np.maximum(ends_a[:, 1], ends_b[:, 1]) < -length
        y_high = np.minimum(ends_a[:, 1], ends_b[:, 1]) > height + length
    return np.asarray(x_low | x_high | y_low | y_high)


def face_levels(
    edge_level: ArrayLike, loop_edges: ArrayLike, loop_starts: ArrayLike, loop_totals: ArrayLike
) -> tuple[IndexArray, BoolArray]:
    """Per face the largest level of its edges (``edge_level`` per edge; a face's edges are
    ``loop_edges[loop_starts[f]:loop_starts[f] + loop_totals[f]]``, Blender's loops), and which
    unsubdivided faces share an edge with a subdivided one (the seam, where the subdivided side
    has vertices the other side's edge does not)."""
    edge_level = np.asarray(edge_level, dtype=np.int64)
    loop_edges = np.asarray(loop_edges, dtype=np.int64)
    starts = np.asarray(loop_starts, dtype=np.int64)
    totals = np.asarray(loop_totals, dtype=np.int64)
    levels = np.zeros(len(totals), dtype=np.int64)
    if len(loop_edges) == 0:
        return levels, np.zeros(len(totals), dtype=bool)
    # a face's loops are contiguous from its loop start (Blender's offsets)
    by_start = np.argsort(starts, kind="stable")
    face_of_loop = np.repeat(by_start, totals[by_start])
    np.maximum.at(levels, face_of_loop, edge_level[loop_edges])
    subdivided_edge = np.zeros(len(edge_level), dtype=bool)
    subdivided_edge[loop_edges[levels[face_of_loop] > 0]] = True
    touches = np.zeros(len(totals), dtype=bool)
    np.logical_or.at(touches, face_of_loop, subdivided_edge[loop_edges])
    return levels, touches & (levels == 0)


# the eight corners of a box: which of (low, high) each coordinate takes
_CORNER_BITS = ((np.arange(8)[:, None] >> np.arange(3)) & 1).astype(bool)
_EYE3 = np.eye(3)
_EYE3.flags.writeable = False


class _BoxView(NamedTuple):
    """What both edge bounds need of meshes in uniform motion over rest boxes (one value per box, or
    per object where every box is one object's: arrays that broadcast over the boxes): the pixels per
    unit of ``|v| / d`` (``scale``), the largest distance and least depth of the apparent points
    (``distance``, ``depth``; ``depth <= 0``: not every point is in front), the least light-travel
    distance ``s_low``, a lower bound on ``1 + n.w`` (``approach``, ``n`` the unit vector from the
    observer to the emission), the motion's ``speed`` and ``gamma``, ``|h|`` (``e' = B r + s h``), the
    norms of ``B A`` and of the object's 3x3 matrix and the observer's ``gamma_o``."""

    scale: float
    distance: FloatArray
    depth: FloatArray
    s_low: FloatArray
    approach: FloatArray
    speed: FloatArray
    gamma: FloatArray
    h_norm: FloatArray
    norm_ba: FloatArray
    norm_m: FloatArray
    gamma_o: float


def _light_distance(r: FloatArray, along: FloatArray, speed: FloatArray) -> FloatArray:
    """``s = c tau`` of points ``r`` (relative to the observer, at its time) moving with ``w``
    (``along = r . w``, ``|w| = speed < 1``): the root of ``|r - s w| = s``,
    ``retarded.light_travel_time_uniform`` with ``Delta = -r`` and ``c = 1`` (that one validates its
    inputs: too slow here, per box and part)."""
    return (np.sqrt(along * along + (1.0 - speed * speed) * (r * r).sum(axis=-1)) - along) / (1.0 - speed * speed)


def _contractions(w: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(speed, gamma, contraction)`` of velocities ``w`` (N, 3) below c: ``apparent.lorentz_contraction_matrix``
    written out for N at once (that one validates one velocity: a third of a box view's time)."""
    speed_squared = (w * w).sum(axis=1)
    gamma = 1.0 / np.sqrt(1.0 - speed_squared)
    factor = (gamma - 1.0) / gamma / np.maximum(speed_squared, 1e-300)
    return np.sqrt(speed_squared), gamma, _EYE3 - factor[:, None, None] * (w[:, :, None] * w[:, None, :])


def _box_view(
    rest_low: ArrayLike,
    rest_high: ArrayLike,
    object_matrix: ArrayLike,
    object_beta: ArrayLike,
    observer_position: ArrayLike,
    observer_beta: ArrayLike,
    world_to_camera: ArrayLike,
    window: tuple[float, float, float, float],
    resolution: tuple[float, float],
) -> _BoxView:
    """Rest boxes (``rest_low``/``rest_high``: ``(3,)`` or ``(K, 3)``) seen through the closed form
    (docs/performance.md, "A bound on the edges' images", steps 1-6, and "A bound on the edges'
    bends"), drawn with ``object_matrix`` (``(4, 4)``, or ``(K, 4, 4)``: each box its own object's)
    and moving with ``object_beta`` (``(3,)`` or ``(K, 3)``)."""
    low = np.asarray(rest_low, dtype=np.float64).reshape(-1, 1, 3)
    high = np.asarray(rest_high, dtype=np.float64).reshape(-1, 1, 3)
    matrix = np.asarray(object_matrix, dtype=np.float64).reshape(-1, 4, 4)
    w = np.asarray(object_beta, dtype=np.float64).reshape(-1, 3)
    beta_o = np.asarray(observer_beta, dtype=np.float64).reshape(3)
    speed_o = math.sqrt(float(beta_o @ beta_o))
    if not (np.all((w * w).sum(axis=1) < 1.0) and speed_o < 1.0):
        raise ValueError("velocities must be below the speed of light")
    speed, gamma, contraction = _contractions(w)
    gamma_o = 1.0 / math.sqrt(1.0 - speed_o * speed_o)
    # r = A x + k: the rest point at the observer's time, relative to the observer
    a = contraction @ matrix[:, :3, :3]
    k = matrix[:, :3, 3] - np.asarray(observer_position, dtype=np.float64).reshape(3)
    r = np.where(_CORNER_BITS, high, low) @ a.transpose(0, 2, 1) + k[:, None, :]  # (K, 8, 3)
    # s = c tau from |r - s w| = s (docs/physics.md with Delta = -r): convex in r, so largest at a
    # corner of the box's image
    along = (r * w[:, None, :]).sum(axis=-1)
    s = _light_distance(r, along, speed[:, None])
    s_high = s.max(axis=1)
    centre = r.sum(axis=1)
    toward = centre / np.maximum(np.sqrt((centre * centre).sum(axis=-1)), 1e-300)[:, None]
    s_low = np.maximum(0.0, (r * toward[:, None, :]).sum(axis=-1).min(axis=1)) / (1.0 + speed)  # |r| <= (1 + |w|) s
    # convex: at least its tangent plane at the box's centre, least at a corner (grad s = n / (1 + n.w),
    # 1 + n.w >= 1 - |w| > 0)
    mid = centre / 8.0
    s_mid = _light_distance(mid, (mid * w).sum(axis=-1), speed)
    n_mid = (mid - s_mid[:, None] * w) / np.maximum(s_mid, 1e-300)[:, None]
    grad = n_mid / (1.0 + (n_mid * w).sum(axis=-1))[:, None]
    tangent = s_mid + ((r - mid[:, None, :]) * grad[:, None, :]).sum(axis=-1).min(axis=1)
    s_low = np.maximum(s_low, np.where(s_mid > 0.0, tangent, 0.0))
    # the emission event boosted: e' = B r + s h, with |e'| = gamma_o (s + beta_o . e) <= gamma_o (1 + |beta_o|) s
    boost = _EYE3 + (gamma_o * gamma_o / (gamma_o + 1.0)) * np.outer(beta_o, beta_o)
    h = gamma_o * beta_o - w @ boost  # (B symmetric: B w)
    forward = -np.asarray(world_to_camera, dtype=np.float64).reshape(3, 3)[2]
    ahead, ahead_s = r @ (boost @ forward), h @ forward
    # depth f.e': concave in r when f.h <= 0 (least at a corner), else at least its linear part's least
    depth = np.where(ahead_s <= 0.0, (ahead + s * ahead_s[:, None]).min(axis=1), ahead.min(axis=1) + s_low * ahead_s)
    distance = gamma_o * (1.0 + speed_o) * s_high
    left, right, bottom, top = window
    width, height = resolution
    scale = max(width / (right - left), height / (top - bottom))
    norm_ba, norm_m = _norms(np.matmul(boost, a), matrix[:, :3, :3])
    # 1 + n.w = 1 - w.w + r.w / s (n = (r - s w) / s): r.w linear, least at a corner; s_low <= s <= s_high
    least_along = along.min(axis=1)
    least_ratio = np.where(least_along < 0.0, least_along / np.maximum(s_low, 1e-300), least_along / s_high)
    approach = np.maximum(1.0 - speed, np.where(s_low > 0.0, 1.0 - speed * speed + least_ratio, 0.0))
    h_norm = np.sqrt((h * h).sum(axis=-1))
    return _BoxView(scale, distance, depth, s_low, approach, speed, gamma, h_norm, norm_ba, norm_m, gamma_o)


# (B A, M) as bytes -> their largest singular values: the same for every part and every frame step
_known_norms: dict[bytes, tuple[FloatArray, FloatArray]] = {}


def _norms(ba: FloatArray, shape: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``||B A||`` and ``||M||`` (largest singular values) of each object's (N, 3, 3); one object's
    kept: two SVDs per call cost more than the rest of a box view."""
    key = ba.tobytes() + shape.tobytes() if len(ba) == 1 else None
    known = _known_norms.get(key) if key is not None else None
    if known is None:
        norms = np.linalg.svd(np.concatenate((ba, shape)), compute_uv=False)[:, 0]
        known = (norms[: len(ba)], norms[len(ba) :])
        if key is not None:
            if len(_known_norms) > 4096:
                _known_norms.clear()
            _known_norms[key] = known
    return known


def _swept(
    rest_low: FloatArray,
    rest_high: FloatArray,
    object_matrix: FloatArray,
    object_beta: FloatArray,
    sweep: FloatArray | None,
) -> tuple[FloatArray, FloatArray]:
    """The rest boxes (N, 3), widened (object space) so that each object drawn with its origin anywhere
    on the segment from its matrix's translation to it plus ``sweep`` (N, 3; world units) keeps every
    point inside the box drawn at the translation: ``r = A x + k + t d = A (x + t A^-1 d) + k``."""
    if sweep is None:
        return rest_low, rest_high
    w = np.asarray(object_beta, dtype=np.float64)
    below = (w * w).sum(axis=1) < 1.0  # (not below c: the box view refuses it)
    a = _contractions(np.where(below[:, None], w, 0.0))[2] @ object_matrix[:, :3, :3]
    try:
        step = np.linalg.solve(a, sweep[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:  # a flattened object: no box holds the sweep
        flat = np.linalg.det(a) == 0.0
        step = np.linalg.solve(np.where(flat[:, None, None], _EYE3, a), sweep[:, :, None])[:, :, 0]
        step[flat] = np.inf
    return np.minimum(rest_low, rest_low + step), np.maximum(rest_high, rest_high + step)


def edge_image_bounds(
    rest_lows: ArrayLike,
    rest_highs: ArrayLike,
    longest_edges: ArrayLike,
    object_matrices: ArrayLike,
    object_betas: ArrayLike,
    observer_position: ArrayLike,
    observer_beta: ArrayLike,
    world_to_camera: ArrayLike,
    window: tuple[float, float, float, float],
    resolution: tuple[float, float],
    sweeps: ArrayLike | None = None,
) -> FloatArray:
    """:func:`edge_image_bound` of N meshes at once (rows: each mesh's rest box ``(N, 3)``, longest
    edge ``(N,)``, matrix ``(N, 4, 4)``, velocity ``(N, 3)`` and sweep ``(N, 3)``), seen by one observer
    and camera: one numpy pass (an observer's velocity change on 1,000 meshes, issue 26). Raises
    ValueError where a velocity is not below c."""
    matrices = np.asarray(object_matrices, dtype=np.float64).reshape(-1, 4, 4)
    betas = np.asarray(object_betas, dtype=np.float64).reshape(-1, 3)
    lows = np.asarray(rest_lows, dtype=np.float64).reshape(-1, 3)
    highs = np.asarray(rest_highs, dtype=np.float64).reshape(-1, 3)
    sweep = None if sweeps is None else np.asarray(sweeps, dtype=np.float64).reshape(-1, 3)
    low, high = _swept(lows, highs, matrices, betas, sweep)
    bounds = np.full(len(low), np.inf)
    finite = np.isfinite(low).all(axis=1) & np.isfinite(high).all(axis=1)
    if not finite.any():
        return bounds
    if finite.all():  # (no copies: one mesh's bound at each full update)
        finite = slice(None)
    view = _box_view(
        low[finite],
        high[finite],
        matrices[finite],
        betas[finite],
        observer_position,
        observer_beta,
        world_to_camera,
        window,
        resolution,
    )
    in_front = view.depth > 1e-9 * view.distance
    depth = np.where(in_front, view.depth, 1.0)
    # |d pixels| <= scale |v| / depth^2 |dv|;  De' = B A + h (A^T n)^T / (1 + n.w), n = e / s
    stretch = view.norm_ba + view.h_norm * view.norm_m * view.gamma * (1.0 + view.speed)
    longest = np.asarray(longest_edges, dtype=np.float64).reshape(-1)[finite]
    bounds[finite] = np.where(in_front, view.scale * view.distance / (depth * depth) * stretch * longest, np.inf)
    return bounds


def edge_image_bound(
    rest_low: ArrayLike,
    rest_high: ArrayLike,
    longest_edge: float,
    object_matrix: ArrayLike,
    object_beta: ArrayLike,
    observer_position: ArrayLike,
    observer_beta: ArrayLike,
    world_to_camera: ArrayLike,
    window: tuple[float, float, float, float],
    resolution: tuple[float, float],
    sweep: ArrayLike | None = None,
) -> float:
    """An upper bound, in pixels, on the image length of every edge of a mesh in uniform motion
    (the closed form: docs/performance.md, "A bound on the edges' images"), from its rest shape's
    bounding box ``rest_low``/``rest_high`` and ``longest_edge`` (object space) alone: the length
    :func:`edge_levels` compares with the tolerance, the segment between the images of the edge's
    apparent end points seen by the pinhole of :func:`perspective_pixels` at ``observer_position``.
    Infinite when the bound cannot show every apparent point in front of the camera.

    The object is drawn with ``object_matrix`` (4, 4) at the observer's time, its rest shape
    contracted along ``object_beta`` (fraction of c) about its origin; the observer moves with
    ``observer_beta``; docs/physics.md, "Light-travel time" and "Lorentz boost of an event".
    ``sweep`` (world units): the bound holds for the origin anywhere from the matrix's translation
    to that plus ``sweep`` (the observer's later times on a straight world line)."""
    view = (object_matrix, object_beta, observer_position, observer_beta, world_to_camera, window, resolution)
    return float(edge_image_bounds(rest_low, rest_high, [longest_edge], *view, sweep)[0])


# The bend bound splits the rest box into up to this many parts along each of its axes (each part
# widened by the longest edge, so that it holds every edge that starts in it): the farthest and the
# nearest apparent points, and the points that recede fastest, are then no longer taken together.
BEND_PARTS = 4


def _parts(low: FloatArray, high: FloatArray, longest: float) -> tuple[FloatArray, FloatArray]:
    """The rest box's parts (``(K, 3)`` lows and highs): an axis is split where it is longer than
    ``BEND_PARTS`` edges."""
    cuts = []
    for axis in range(3):
        extent = high[axis] - low[axis]
        count = BEND_PARTS if extent > BEND_PARTS * longest else 1
        edges = low[axis] + extent * np.arange(count + 1) / count
        cuts.append((np.maximum(edges[:-1] - longest, low[axis]), np.minimum(edges[1:] + longest, high[axis])))
    grid = np.stack(np.meshgrid(*[np.arange(len(c[0])) for c in cuts], indexing="ij"), axis=-1).reshape(-1, 3)
    lows = np.stack([cuts[axis][0][grid[:, axis]] for axis in range(3)], axis=1)
    highs = np.stack([cuts[axis][1][grid[:, axis]] for axis in range(3)], axis=1)
    return lows, highs


def edge_bend_bound(
    rest_low: ArrayLike,
    rest_high: ArrayLike,
    longest_edge: float,
    object_matrix: ArrayLike,
    object_beta: ArrayLike,
    observer_position: ArrayLike,
    observer_beta: ArrayLike,
    world_to_camera: ArrayLike,
    window: tuple[float, float, float, float],
    resolution: tuple[float, float],
    acceleration: float = 0.0,
    sweep: ArrayLike | None = None,
) -> float:
    """An upper bound, in pixels, on the bend :func:`edge_levels` measures on every edge left whole
    (:func:`segment_bends` with one piece: the image of the apparent midpoint against the image of
    the drawn segment's middle), for the mesh of :func:`edge_image_bound`; infinite where it cannot
    show every apparent point in front of the camera. It falls with the square of ``longest_edge``
    (the length bound with its first power): a dense mesh seen at a large render size clears it where
    its edges' images are pixels long (docs/performance.md, "A bound on the edges' bends").

    ``acceleration``: where the origin's world line is not straight, a bound on ``|d^2 x / d(ct)^2|``
    (per unit length) over the light-travel times the edges span, ``object_beta`` the velocity the
    line is measured from (keyframed motion over its window); ``sweep``: as for
    :func:`edge_image_bound`."""
    matrix = np.asarray(object_matrix, dtype=np.float64).reshape(1, 4, 4)
    low, high = _swept(
        np.asarray(rest_low, dtype=np.float64).reshape(1, 3),
        np.asarray(rest_high, dtype=np.float64).reshape(1, 3),
        matrix,
        np.asarray(object_beta, dtype=np.float64).reshape(1, 3),
        None if sweep is None else np.asarray(sweep, dtype=np.float64).reshape(1, 3),
    )
    if not (np.all(np.isfinite(low)) and np.all(np.isfinite(high))):
        return float("inf")
    lows, highs = _parts(low[0], high[0], float(longest_edge))
    view = _box_view(
        lows, highs, object_matrix, object_beta, observer_position, observer_beta, world_to_camera, window, resolution
    )
    if not np.all(view.depth > 1e-9 * view.distance) or not np.all(view.s_low > 0.0):
        return float("inf")
    # along an edge r(t) = r_a + t u, |u| <= ||M|| L (the contraction shortens): the apparent
    # point e'(t) = B r(t) + s(t) h, so e'(1/2) - (e'(0) + e'(1)) / 2 = h (s(1/2) - (s(0) + s(1)) / 2),
    # at most |h| max|s''| / 8; s'' = (|u - s' w|^2 - s'^2) / (s (1 + n.w)) <= gamma_w^2 |u|^2 / (s (1 + n.w))
    u2 = (view.norm_m * float(longest_edge)) ** 2
    s_second = view.gamma * view.gamma * u2 / (view.s_low * view.approach)
    spatial: FloatArray | float = 0.0
    if acceleration > 0.0:
        # a world line bent by a: e'' = B x'' s'^2 + h s'', |s'| <= |u| / (1 + n.w), and s'' gains
        # a |s'|^2 / (1 + n.w) (docs/performance.md)
        s_second = s_second + acceleration * u2 / view.approach**3
        spatial = view.gamma_o * acceleration * u2 / view.approach**2
    bend = (spatial + view.h_norm * s_second) / 8.0
    # |P(y1) - P(y2)| <= scale |v|_max / d_min^2 |y1 - y2| (both points in the part's apparent hull)
    return float(np.max(view.scale * view.distance / (view.depth * view.depth) * bend))
