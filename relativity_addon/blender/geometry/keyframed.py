"""Keyframed rigid motion computed in the modifier (``keyframed_nodes.py``): the glue that picks the
objects it can show, gives the modifier the few sample intervals of the object's motion that its
retarded times need (``physics/sampling.motion_intervals``: the same samples, contraction and
Catmull-Rom cubic as the Python path, ``motion.animated_apparent_positions``), and reads back the
modifier's verdict that every retarded time lay inside them.

A frame step or an observer change then evaluates the object's keyframes at those samples, writes
their coefficients into the cache's first points (4x4 attributes, a few hundred at most) and sets a
few inputs: no pass over the vertices in Python. Motion bakes, deformation bakes and animated shape
keys stay on the Python path, as do motions whose intervals number more than MAX_INTERVALS
(rotation and scale keys played at the proper time are in the sampled matrices, as there). The
window's bound needs the rest points' reach from the origin: read once (Set Up), and again by every
update on the Python path. An evaluation that found a retarded time outside the intervals (or one
that did not converge) widens the next window; the object's update in between runs on the Python
path (its verdict is in the object's signature).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, cast

import numpy as np

from ...errors import RelativityError
from ...physics import polynomial_motion, sampling
from ..common import names
from ..scene import animation
from . import edge_bounds, modifier, motion, shape_keys, tessellation, uniform_motion

if TYPE_CHECKING:
    from bpy.types import Depsgraph, Mesh, Modifier, Object, Scene

    from ...physics.arrays import FloatArray
    from ..scene.snapshot import Snapshot

# Most sample intervals the modifier is given (4 matrices each, read by Sample Index).
MAX_INTERVALS = 1024
# Most widenings of the window after verdicts that a retarded time lay outside it.
MAX_WIDENING = 8.0
REACH_KEY = "relativity_reach"  # on the cache mesh: the rest points' largest distance from the origin
WIDEN_KEY = "relativity_widen"  # on the cache mesh: the window's factor after outside verdicts


def can_show(obj: Object, scene: Scene) -> bool:
    """Whether the object's motion is keyframed rigid motion the modifier can compute (Motion
    Animation from keyframes alone, no bake, no animated shape keys; rotation and scale keys at the
    proper time too: the sampled matrices carry the clock)."""
    settings = obj.relativity
    return (
        settings.motion == "ANIMATION"
        and not settings.use_deformation
        and modifier.motion_bake_range(obj) is None
        and animation.keyframe_motion_problem(obj, scene) is None
        and not shape_keys.has_animated_shape_keys(obj)
    )


def off_their_keys(scene: Scene) -> list[Object]:
    """The scene's objects whose keyframed transform holds values their keys do not give at the
    current frame (``animation.off_keys``: moved without a key). A render evaluates their keys
    again, as does every frame change: what the add-on computed from the values shown is not what
    would be rendered."""
    frame = scene.frame_current + scene.frame_subframe
    return [obj for obj in scene.objects if obj.animation_data is not None and animation.off_keys(obj, frame)]


def _matrix_function(obj, scene, fps, step, c, signature):
    """The world matrices at scene times (seconds) that the Python path samples: the keyframes, with
    the rotation and scale keys at the proper time when the object plays them there
    (``motion.proper_time_apparent_positions``)."""
    if obj.relativity.use_proper_time and motion.plays_own_animation(obj, scene):
        clock = motion.path_clock(obj, fps, step, c)
        return lambda times: animation.world_matrices(obj, times * fps, own_frames=clock(times) * fps)
    function = lambda times: animation.world_matrices(obj, times * fps)  # noqa: E731
    return _kept_samples(obj, (signature, fps, step), function, step)


# Object session_uid -> (keyframes signature, {name: value}): what the keys alone decide (where they
# hold the object still, whether they only move it, its held rotation and scale), kept while they
# stay: a frame step or an observer change of 1,000 keyframed objects (issue 26) reads no key for it.
_facts: dict[int, tuple[object, dict[str, object]]] = {}


def _keyed_facts(obj: Object, signature: object) -> dict[str, object]:
    """The object's kept facts (:data:`_facts`), new when its keys' ``signature`` changed."""
    known = _facts.get(obj.session_uid)
    if known is None or known[0] != signature:
        known = _facts[obj.session_uid] = (signature, {})
    return known[1]


def _fact(facts, name, compute):
    if name not in facts:
        facts[name] = compute()
    return facts[name]


# Object session_uid -> (key, {grid index: world matrix}): the keyframes' world matrices at the sample
# times ``index * step`` evaluated so far, kept while the keys (``animation.keyframes_signature``), the
# frame rate and the step stay. A frame step or an observer change then evaluates only the samples
# it has not evaluated before (a frame step moves the window by Samples per Frame), and the widenings
# of one window (``sampling.motion_intervals``) none twice.
_samples: dict[int, tuple[object, dict[int, FloatArray]]] = {}
MAX_KEPT_SAMPLES = 4096  # per object: forgotten beyond (an object stepping through a long animation)


def _kept_samples(obj, key, function, step):
    """``function`` (world matrices at scene times) evaluated once per grid time: the kept samples
    for times on the grid ``index * step`` (as ``sampling`` builds them), ``function`` for others."""
    known = _samples.get(obj.session_uid)
    if known is None or known[0] != key or len(known[1]) > MAX_KEPT_SAMPLES:
        known = (key, {})
        _samples[obj.session_uid] = known
    kept = known[1]

    def sampled(times):
        times = np.asarray(times, dtype=np.float64)
        grid = np.rint(times / step)
        if times.ndim != 1 or not np.array_equal(grid * step, times):
            return function(times)
        indices = grid.astype(np.int64).tolist()
        missing = sorted({index for index in indices if index not in kept})
        if missing:
            kept.update(zip(missing, np.asarray(function(np.asarray(missing, dtype=np.float64) * step)), strict=True))
        return np.stack([kept[index] for index in indices])

    return sampled


# Object session_uid -> the origin's light-travel time at its last update: where the next solve
# starts (a frame step or an observer change moves it a little).
_last_tau: dict[int, float] = {}


def is_on(mod: Modifier | None) -> bool:
    """Whether the modifier computes keyframed motion itself."""
    if mod is None:
        return False
    return bool(modifier.input_value(mod, "Keyframed"))


def verdicts_made(mod: Modifier) -> tuple[bool, bool]:
    """Whether the modifier's inputs make its verdicts: on the edges (``Measure Edges``, with the closed
    form or keyframed motion on) and on the window (keyframed motion on). The inputs an update found
    are those of the last evaluation: a new modifier (Set Up) has made none yet."""
    measured = bool(modifier.input_value(mod, "Measure Edges"))
    return measured and modifier.closed_form_on(mod), is_on(mod)


def window_found(obj_eval: Object) -> bool | None:
    """The modifier's verdict at its last evaluation: every retarded time inside its intervals (True),
    not (False), or None (it did not compute keyframed motion there)."""
    mesh = obj_eval.data if obj_eval.type == "MESH" else None
    attribute = mesh.attributes.get(names.WINDOW_OK_ATTRIBUTE) if mesh is not None else None
    if attribute is None or len(attribute.data) == 0:
        return None
    return bool(attribute.data[0].value)


def note_rest(data: Mesh, rest: FloatArray) -> None:
    """Record the rest points' reach (object space) on the cache mesh ``data``: the window's bound."""
    reach = float(np.sqrt(np.max(np.einsum("ij,ij->i", rest, rest), initial=0.0)))
    if data.get(REACH_KEY) != reach:
        data[REACH_KEY] = reach


def modifier_inputs(
    obj: Object, obj_eval: Object, snap: Snapshot, scene: Scene, reach: float
) -> tuple[dict[str, object], FloatArray | None] | None:
    """The modifier's keyframed inputs (``keyframed_nodes.KEYFRAMED_INPUTS``) and the intervals'
    coefficients ``(K, 4, 3, 4)`` for the snapshot's observer event; the closed form's inputs and None
    where the keys move the object uniformly over the intervals (``animation.straight_keys``: no
    interval read per point); or None when the intervals would be more than MAX_INTERVALS or reach
    back before the keyframes start moving the object (the Python path then, which warns when a
    point is seen there). Raises RelativityError."""
    t_o, x_o, beta_o = snap.mesh_observer  # behind the exact camera: the scene frame
    c = snap.speed_of_light
    _lines.pop(obj.session_uid, None)
    motion.check_parent_motion(obj)
    fps = animation.frames_per_second(scene)
    step = 1.0 / (int(obj.relativity.samples_per_frame) * fps)
    signature = animation.keyframes_signature(obj)
    facts = _keyed_facts(obj, signature)
    uniform = _uniform_over_window(obj, obj_eval, facts, snap, fps, step, reach)
    if uniform is not None:
        return uniform, None
    corners = _box_corners(obj, facts)
    window = _window(obj, scene, signature, facts, corners, (fps, step, t_o, x_o, c, reach))
    if window is None:
        return None  # the Python path then (and its warning when a point is seen before the keys move it)
    pieces, line, found = window
    beta_o = np.asarray(beta_o, dtype=np.float64)
    x_o = np.asarray(x_o, dtype=np.float64)
    matrix = motion.matrix_array(obj_eval.matrix_world)
    inverse = motion.affine_inverse(matrix)[:3, :3]
    if line is not None:
        start, per_frame = line
        # straight keys hold the rotation and scale (one value each): the shape at any frame
        shape = _fact(facts, "held shape", lambda: animation.world_matrices(obj, [t_o * fps])[0, :3, :3])
        origin = start + per_frame * (t_o * fps)
        closed = uniform_motion.uniform_motion_inputs(shape, origin, per_frame * fps / c, matrix, x_o, beta_o)
        return {"Keyframed": False, "Closed Form": True, **closed}, None
    grid_now, grid_per_distance = t_o / step - pieces.first, 1.0 / (c * step)
    polynomial, form, steps = found if found is not None else (None, None, None)
    gamma = 1.0 / np.sqrt(1.0 - float(beta_o @ beta_o))
    # e' = B e + gamma sigma beta_o (the boost of the emission event relative to the observer)
    boost = np.eye(3) + (gamma * gamma / (gamma + 1.0)) * np.outer(beta_o, beta_o)
    emission = inverse @ boost

    def vector(values):
        return tuple(float(v) for v in values)

    inputs = {
        "Keyframed": True,
        "Closed Form": False,
        "Polynomial": polynomial is not None,
        "Last Interval": float(len(pieces.coefficients) - 1),
        "Grid Now": grid_now,
        "Grid Per Distance": grid_per_distance,
        "Start Distance": pieces.start_distance,
        "Emission X": vector(emission[:, 0]),
        "Emission Y": vector(emission[:, 1]),
        "Emission Z": vector(emission[:, 2]),
        "Emission Offset": vector(inverse @ (x_o - matrix[:3, 3])),
        "Emission Delay": vector(gamma * (inverse @ beta_o)),
        "Observer Velocity": vector(-beta_o),
        "Observer Inverse Gamma": 1.0 / gamma,
        "Observer Factor": gamma / (gamma + 1.0),
        "Observer Moving": bool(np.any(beta_o != 0.0)),
    }
    if polynomial is None or form is None:
        return inputs, pieces.coefficients
    inputs.update(
        {
            "Polynomial One Step": steps == 1,
            "Polynomial Centre": form.centre,
            "Polynomial Start Offset": form.start_offset,
            "Polynomial Start Slope": form.start_slope,
            # the closed forms' towards form on every point (as the closed form's, uniform_motion.FOLD_LIMIT)
            "Folded": 1.0 / (1.0 - pieces.fastest) <= uniform_motion.FOLD_LIMIT,
            **{
                f"Polynomial {power} {part}": vector(form.coefficients[power][:, column])
                for power in range(polynomial_motion.DEGREE + 1)
                for column, part in enumerate(("X", "Y", "Z", "Offset"))
            },
        }
    )
    _polynomials[obj.session_uid] = polynomial
    return inputs, None  # no interval read: the cache holds the face codes alone


# Object session_uid -> (key, (intervals, straight line, polynomial found)) of the last update: the
# window depends on the observer's event, not on its velocity, so an observer's velocity change (the
# same event, keys, step, reach and rest box) samples, contracts and fits nothing again.
_windows: dict[int, tuple[object, tuple[object, object, object]]] = {}


def _window(obj, scene, signature, facts, corners, event):
    """The intervals of the observer ``event`` (``(fps, step, t_o, x_o, c, reach)``), the keys' straight
    line over them (``animation.straight_keys``) and else the polynomial found (``_window_polynomial``:
    None where there is none or no rest box); None for the Python path (too many intervals, or
    intervals before the keys start moving the object). Raises RelativityError."""
    fps, step, t_o, x_o, c, reach = event
    box = None if corners is None else tuple(float(v) for v in np.ravel(corners))
    proper = bool(obj.relativity.use_proper_time)
    event_key = (fps, step, float(t_o), tuple(float(v) for v in x_o), float(c), float(reach))
    key = (signature, proper, *event_key, box, MAX_INTERVALS)
    kept = _windows.get(obj.session_uid)
    if kept is not None and kept[0] == key:
        return kept[1]
    try:
        function = _matrix_function(obj, scene, fps, step, c, signature)
        guess = _last_tau.get(obj.session_uid)
        pieces = sampling.motion_intervals(function, step, t_o, x_o, c, reach, MAX_INTERVALS, guess)
    except ValueError as error:
        raise RelativityError(f"Object {obj.name!r}: {error}") from None
    if pieces is not None:
        _last_tau[obj.session_uid] = pieces.start_distance / c
    held_before = _fact(facts, "held before", lambda: animation.held_before_frame(obj))
    if pieces is None or (held_before is not None and pieces.first * step * fps < held_before):
        return None
    # keys drawing a straight line over every knot the intervals use: uniform motion, the closed form
    line = animation.straight_keys(
        obj, (pieces.first - 1) * step * fps, (pieces.first + len(pieces.coefficients) + 1) * step * fps
    )
    found = None
    if line is None and corners is not None:
        grid_now, grid_per_distance = t_o / step - pieces.first, 1.0 / (c * step)
        x_o = np.asarray(x_o, dtype=np.float64)
        found = _window_polynomial(pieces, corners, grid_now, grid_per_distance, x_o, reach, step, c)
    _windows[obj.session_uid] = (key, (pieces, line, found))
    return pieces, line, found


def _uniform_over_window(obj, obj_eval, facts, snap, fps, step, reach):
    """The closed form's inputs where the keys draw one straight line over every sample
    ``sampling.motion_intervals`` would read (``sampling.uniform_motion_window``: found from the
    line alone, no key evaluated, no window solved), else None (the intervals decide then). The
    same inputs as the intervals' straight-keys case below: the same line, shape and observer."""
    if not _fact(facts, "translates only", lambda: animation.translates_only(obj)):
        return None  # a rotation or scale keyed anywhere: the shape is not one matrix
    t_o, x_o, beta_o = snap.mesh_observer
    c = snap.speed_of_light
    guess = (t_o - _last_tau.get(obj.session_uid, 0.0)) * fps
    span = facts.get("straight span")
    if span is None or not span[2] <= guess <= span[3]:  # the line the keys draw around the guess
        span = facts["straight span"] = animation.straight_span(obj, guess) or (None, None, math.inf, -math.inf)
    start, per_frame, first_frame, last_frame = span
    if start is None:
        return None
    shape = _fact(facts, "held shape", lambda: animation.world_matrices(obj, [t_o * fps])[0, :3, :3])
    size = _fact(facts, "held size", lambda: float(np.linalg.svd(shape, compute_uv=False)[0]))
    window = sampling.uniform_motion_window(start, per_frame * fps, size, step, t_o, x_o, c, reach, MAX_INTERVALS)
    if window is None:
        return None
    low, high, tau = window
    held_before = _fact(facts, "held before", lambda: animation.held_before_frame(obj))
    if held_before is not None and low * fps < held_before:
        return None  # the intervals decide (the Python path, and its warning, before the keys move it)
    if not (first_frame <= low * fps and high * fps <= last_frame):
        return None  # the window reaches past the line (the intervals decide: a change of velocity in it)
    _last_tau[obj.session_uid] = tau
    # the observer's latest time this line still holds the window (the window's ends rise with t_o):
    # the sweep's frames ahead, else half as many (a change of velocity that near)
    for frames in (edge_bounds.SWEEP_FRAMES, edge_bounds.SWEEP_FRAMES // 2):
        ahead = t_o + frames / fps
        later = sampling.uniform_motion_window(start, per_frame * fps, size, step, ahead, x_o, c, reach, MAX_INTERVALS)
        if later is not None and first_frame <= later[0] * fps and later[1] * fps <= last_frame:
            _lines[obj.session_uid] = (start, per_frame, shape, fps, t_o, ahead)
            break
    matrix = motion.matrix_array(obj_eval.matrix_world)
    origin = start + per_frame * (t_o * fps)
    beta_o, x_o = np.asarray(beta_o, dtype=np.float64), np.asarray(x_o, dtype=np.float64)
    closed = uniform_motion.uniform_motion_inputs(shape, origin, per_frame * fps / c, matrix, x_o, beta_o)
    return {"Keyframed": False, "Closed Form": True, **closed}


# Object session_uid -> (line start, way per frame, held 3x3, fps, the observer's time of the update,
# the latest time the line holds the window) of its last update on the closed form of straight keys
# (``_uniform_over_window``); read by ``straight_steps`` (a frame step on the line sets three inputs).
_lines: dict[int, tuple[FloatArray, FloatArray, FloatArray, float, float, float]] = {}


def steppable_line(obj: Object) -> tuple[FloatArray, FloatArray, FloatArray, float, float, float] | None:
    """The object's line of its last update (:data:`_lines`) where that update proved every edge short
    over the origin's way to come (``edge_bounds.swept_bound``), else None."""
    line = _lines.get(obj.session_uid)
    return line if line is not None and edge_bounds.swept_bound(obj) is not None else None


# Object session_uid -> the window's polynomial at its last update (the edges' bound reads it).
_polynomials: dict[int, polynomial_motion.WindowPolynomial] = {}


def _box_corners(obj, facts):
    """The rest box (object space: its low and high corners) of an object whose keys only move it
    (``animation.translates_only``: the polynomial may serve it), else None."""
    bounds = edge_bounds.rest_bounds(obj)
    if bounds is None or not _fact(facts, "translates only", lambda: animation.translates_only(obj)):
        return None
    return np.asarray(bounds[0], dtype=np.float64), np.asarray(bounds[1], dtype=np.float64)


def _window_polynomial(pieces, box, grid_now, grid_per_distance, x_o, reach, step, c):
    """One polynomial over the intervals (``physics/polynomial_motion.py``), the modifier's form of it
    and its closed-form steps, where it follows them to the samples' rounding and the steps converge
    at the rest ``box``'s check points (``choose_steps``: one where one does), else None
    (the intervals then, read per point). No verdict is taken over the points: the window was bounded
    for every point within ``reach`` of the origin, and the rest box's farthest corner must lie
    within it (a box whose corners reach farther than its points, a sphere's, keeps the intervals)."""
    corners = np.where(np.arange(8)[:, None] >> np.arange(3) & 1, box[1], box[0])
    if float(np.max(np.linalg.norm(corners, axis=1))) > reach * (1.0 + 1e-6):  # (float32 reads)
        return None  # the window holds only points within reach (a stale reach: the verdict says so)
    tolerance = polynomial_motion.rounding_tolerance(pieces, x_o, reach, step, c)
    polynomial = polynomial_motion.fit_window(pieces, grid_now, grid_per_distance, reach, tolerance)
    if polynomial is None:
        return None
    found = polynomial_motion.choose_steps(polynomial, polynomial_motion.box_points(*box, polynomial))
    return None if found is None else (polynomial, *found)


def write_intervals(data: Mesh, coefficients: FloatArray, face_codes: FloatArray | None) -> None:
    """The intervals' coefficients into the cache mesh's first points (one 4x4 attribute per power,
    column-major as Blender stores matrices), the face codes after them."""
    count = len(coefficients)
    modifier.write_cache(data, np.zeros((count, 3)), np.zeros((1, 3)), face_codes)
    total = len(data.vertices)
    for power, name in enumerate(names.MOTION_ATTRIBUTES):
        attribute = data.attributes.get(name)
        if attribute is None:
            attribute = data.attributes.new(name, "FLOAT4X4", "POINT")
        matrices = np.zeros((total, 4, 4), dtype=np.float32)
        matrices[:count, :3, :] = coefficients[:, power]
        matrices[:, 3, 3] = 1.0
        attribute.data.foreach_set("value", np.ascontiguousarray(matrices.transpose(0, 2, 1)).ravel())
    data.update()


def _edge_bound(obj, obj_eval, snap, scene, inputs, tolerance):
    """The closed form's bound on the edges' images or bends (pixels; ``edge_bounds.edge_image_bound``)
    for the closed form's ``inputs``; for the polynomial's, the largest of the bounds of the uniform
    motions through the origin at the window's centre with the origin's velocity at the window's two
    ends and centre (the motion departs from each by less than the samples' rounding over the
    retarded times' spread), the bends' with the polynomial's largest acceleration over the window."""
    x_o = np.asarray(snap.mesh_observer[1])
    size = tessellation.render_size(scene)
    acceleration = 0.0
    way = None
    if not inputs.get("Keyframed"):
        velocity = np.asarray(cast("tuple[float, float, float]", inputs["Velocity"]), dtype=np.float64)
        motions = [(np.asarray(cast("tuple[float, float, float]", inputs["Scene Offset"])), inputs["Velocity"])]
        way = velocity * snap.speed_of_light / animation.frames_per_second(scene)  # a frame's, world units
    else:
        polynomial = _polynomials[obj.session_uid]
        origin = polynomial.coefficients[:, :, 3]  # (D + 1, 3): the origin relative to the observer
        motions = []
        for u in (-1.0, 0.0, 1.0):
            powers = np.arange(1, len(origin))
            w = (powers * u ** (powers - 1)) @ origin[1:] / polynomial.half
            motions.append((origin[0] + polynomial.centre * origin[1] / polynomial.half, tuple(w)))
        # |d^2 x / ds^2| <= sum p (p - 1) |c_p| / half^2 over the window (|u| <= 1)
        powers = np.arange(2, len(origin))
        acceleration = float(powers * (powers - 1) @ np.linalg.norm(origin[2:], axis=1)) / polynomial.half**2
    bound = 0.0
    for offset, velocity in motions:
        at_t_o = motion.matrix_array(obj_eval.matrix_world).copy()
        at_t_o[:3, 3] = offset + x_o
        bound = max(
            bound, edge_bounds.edge_image_bound(obj, at_t_o, snap, size, tolerance, velocity, acceleration, way)
        )
    return bound


def update(
    obj: Object,
    depsgraph: Depsgraph,
    snap: Snapshot,
    scene: Scene,
    mod: Modifier,
    cache: Object,
    codes: FloatArray | None,
    measure: dict[str, object] | None,
) -> bool | None:
    """Set the modifier's keyframed inputs and intervals for the snapshot (``measure``: the adaptive
    check's inputs, or None). Returns whether anything changed, or None when the modifier cannot
    compute this frame (a verdict of a retarded time outside the intervals, or
    too many intervals: the Python path then)."""
    data = cast("Mesh", cache.data)
    obj_eval = obj.evaluated_get(depsgraph)
    reach = data.get(REACH_KEY)
    if reach is None:  # once (Set Up): the rest points' reach, the window's bound
        rest = modifier.evaluated_rest_positions(obj, depsgraph, dtype=np.float32)
        if rest is None:
            return None
        note_rest(data, rest)
        reach = data[REACH_KEY]
    widen = float(data.get(WIDEN_KEY, 1.0))
    if is_on(mod) and window_found(obj_eval) is False:
        data[WIDEN_KEY] = widen * 2.0
        return None  # this frame on the Python path; the next tries the wider window
    if widen > MAX_WIDENING:
        return None
    found = modifier_inputs(obj, obj_eval, snap, scene, float(reach) * widen)
    if found is None:
        return None
    inputs, coefficients = found
    if coefficients is not None:
        write_intervals(data, coefficients, codes)  # the cache changed: the object is evaluated again
    else:  # the closed form, or the polynomial
        if len(data.vertices) != (0 if codes is None else len(codes)):  # the face codes alone
            modifier.write_cache(data, np.zeros((0, 3)), np.zeros((1, 3)), codes)
        if measure is not None and not measure["Edges Proven Short"]:  # the closed form's bound applies
            bound = _edge_bound(obj, obj_eval, snap, scene, inputs, measure["Tolerance"])
            measure = {**measure, "Edges Proven Short": bound <= edge_bounds.PROVEN_MARGIN * measure["Tolerance"]}
    if measure is None or not measure["Edges Proven Short"]:  # the modifier's verdict decides: no step
        _lines.pop(obj.session_uid, None)
    # one call: the group (full or lean) is chosen once, on every input's new value
    modifier.set_inputs(mod, {**inputs, "Measure Edges": measure is not None, **(measure or {})})
    if coefficients is None:  # the next evaluation (the caller tags the object) is ours: the rest box stays
        edge_bounds.announce(obj)
    return True
