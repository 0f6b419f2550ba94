"""Issue 26, the many-object scene: a change on one of N moving meshes costs that mesh only. The
work a sync does per mesh is counted through hooks on the functions that do it: the signature of
its inputs (``object_signature``), its update, every write of a modifier input
(``compat.set_modifier_input``), the clip-end depth of its evaluated bounds and the panel's mesh
warnings. A velocity change on one mesh must do that work for that mesh only; a frame step with
nothing moving none at all; a frame step where one mesh's keyframes move it, for that mesh only.
The meshes left alone keep their evaluated positions exactly; the changed ones move."""

from collections import Counter

import numpy as np
import pytest
from test_object_type_sweep import _cube_mesh, _link

import geometry_helpers as gh

C = 4.0
FPS = 24
COUNT = 6


def _scene(bpy, tessellation):
    scene, _camera = gh.slow_light_scene(bpy, C, FPS)
    movers = []
    for k in range(COUNT):
        obj = _link(bpy, scene, f"Mover {k}", _cube_mesh(bpy, f"Mover {k}", 0.2))
        obj.location = (0.8 * (k - COUNT / 2), 0.5, -6.0)
        obj.relativity.motion = "CONSTANT"
        obj.relativity.beta = (0.3, 0.0, 0.0)
        if tessellation is not None:
            obj.relativity.tessellation = tessellation
        movers.append(obj)
    scene.frame_set(12)
    return scene, movers


def _count_work(monkeypatch):
    """Patch the per-mesh work of a sync; returns {kind: Counter of object names}."""
    work = {kind: Counter() for kind in ("signature", "update", "turned", "input written", "depth", "warnings")}
    meshes = gh.geometry_module()
    compat = gh.addon_module("common.compat")
    clip_end = gh.addon_module("geometry.clip_end")
    mesh_notes = gh.addon_module("pipeline.mesh_notes")

    def hook(module, name, kind, which):
        original = getattr(module, name)

        def counted(*args, _original=original, **kwargs):
            obj = which(args)
            work[kind][obj.original.name if getattr(obj, "original", None) is not None else obj.name] += 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(module, name, counted)

    hook(meshes, "object_signature", "signature", lambda args: args[1])
    hook(meshes, "update_object", "update", lambda args: args[1])
    hook(compat, "set_modifier_input", "input written", lambda args: args[0].id_data)
    depths = clip_end.bounds_depths

    def counted_depths(snap, evaluated):
        work["depth"].update(obj.original.name for obj in evaluated)
        return depths(snap, evaluated)

    monkeypatch.setattr(clip_end, "bounds_depths", counted_depths)
    hook(mesh_notes, "mesh_warnings", "warnings", lambda args: args[1])
    steps = gh.addon_module("geometry.straight_steps")
    step = steps.step

    def counted_steps(objects, *args, **kwargs):
        objects = list(objects)
        done = step(objects, *args, **kwargs)
        if args[3:4] == (True,) or kwargs.get("turning"):  # an observer's velocity change: recomputed
            work["turned"].update(obj.name for obj in objects if obj.session_uid in done)
        return done

    monkeypatch.setattr(steps, "step", counted_steps)
    return work


def _done(work):
    return {kind: dict(counts) for kind, counts in work.items() if counts}


def _points(bpy, movers):
    return [gh.evaluated_points(bpy, obj)[0] for obj in movers]


def _assert_only_changed(work, before, after, changed):
    """No counted work for any mover but ``Mover {changed}``; the others' evaluated positions are
    unchanged to the bit, and that one moved."""
    others = {f"Mover {k}" for k in range(COUNT) if k != changed}
    touched = {kind: sorted(set(counts) & others) for kind, counts in work.items() if set(counts) & others}
    assert not touched, f"work done for meshes other than Mover {changed}: {touched} (all: {_done(work)})"
    for k in range(COUNT):
        if k != changed:
            np.testing.assert_array_equal(after[k], before[k])
    assert np.abs(after[changed] - before[changed]).max() > 1e-3, f"Mover {changed} did not move"


@pytest.mark.parametrize("tessellation", [0, None], ids=["tessellation-0", "tessellation-default"])
def test_velocity_change_on_one_of_many_meshes_works_on_that_mesh_only(relativity_addon, monkeypatch, tessellation):
    import bpy

    scene, movers = _scene(bpy, tessellation)
    gh.apply_geometry(scene)
    before = _points(bpy, movers)
    work = _count_work(monkeypatch)

    movers[2].relativity.beta = (-0.4, 0.0, 0.0)  # as the panel does: the update callback runs
    bpy.context.evaluated_depsgraph_get()  # the viewport's next redraw
    after = _points(bpy, movers)

    assert work["update"]["Mover 2"] >= 1 and work["input written"]["Mover 2"] >= 1, _done(work)
    _assert_only_changed(work, before, after, 2)


def test_frame_step_works_on_the_meshes_the_frame_moves_only(relativity_addon, monkeypatch):
    import bpy

    scene, movers = _scene(bpy, 0)
    keyed = movers[3]  # Constant Velocity through where its keyframes put it at each frame
    for frame, x in ((1, -0.5), (40, 0.5)):
        keyed.location.x = x
        keyed.keyframe_insert("location", index=0, frame=frame)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    work = _count_work(monkeypatch)
    before = _points(bpy, movers)

    scene.frame_set(13)
    bpy.context.evaluated_depsgraph_get()
    after = _points(bpy, movers)

    assert work["input written"]["Mover 3"] >= 1, _done(work)
    _assert_only_changed(work, before, after, 3)

    for kind in work:
        work[kind].clear()
    scene.frame_set(13)  # the same frame again: nothing to write
    bpy.context.evaluated_depsgraph_get()
    assert not work["update"] and not work["input written"], _done(work)


def _keyframed_scene(bpy):
    """COUNT cubes on linear location keys (about 0.5c along x), Motion Animation."""
    scene, _camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = (0.2, 0.0, 0.0)
    movers = []
    for k in range(COUNT):
        obj = _link(bpy, scene, f"Mover {k}", _cube_mesh(bpy, f"Mover {k}", 0.2))
        x = 0.8 * (k - COUNT / 2)
        obj.location = (x, 0.5, -6.0)
        gh.keyframe_linear(obj, "location", 0, ((-120, x - 10.0), (48, x + 4.0)))
        obj.relativity.motion = "ANIMATION"
        movers.append(obj)
    scene.frame_set(12)
    return scene, movers


def test_observer_change_on_many_keyframed_meshes_evaluates_once(relativity_addon, monkeypatch):
    """A velocity change of the observer moves every keyframed mesh: each is recomputed once, against
    one evaluation of the depsgraph (not one per mesh, each evaluating the meshes updated before it
    again), and ends where a fresh Set Up at that velocity puts it."""
    import bpy

    scene, movers = _keyframed_scene(bpy)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    before = _points(bpy, movers)
    work = _count_work(monkeypatch)
    evaluations = []
    handler = lambda _scene, _depsgraph: evaluations.append(1)  # noqa: E731
    bpy.app.handlers.depsgraph_update_post.append(handler)
    try:
        scene.relativity.beta = (-0.3, 0.1, 0.0)  # as the panel does: the update callback runs
        bpy.context.evaluated_depsgraph_get()  # the viewport's next redraw
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(handler)
    after = _points(bpy, movers)

    # (each updated, or its record of straight keys turned: straight_steps)
    assert work["update"] + work["turned"] == Counter({f"Mover {k}": 1 for k in range(COUNT)}), _done(work)
    assert len(evaluations) <= 2, f"{len(evaluations)} depsgraph evaluations for {COUNT} meshes ({_done(work)})"
    for k in range(COUNT):
        assert np.abs(after[k] - before[k]).max() > 1e-3, f"Mover {k} did not move"

    gh.remove_effect(scene)
    gh.apply_geometry(scene)
    fresh = _points(bpy, movers)
    for k in range(COUNT):
        np.testing.assert_allclose(after[k], fresh[k], atol=1e-6)


def test_observer_change_builds_each_signature_once_before_the_evaluation(relativity_addon, monkeypatch):
    """A velocity change of the observer: the callback's sync builds each mesh's signature once (its
    update's); a signature stored for another observer is not built again only to differ (about 60 us
    a mesh: issue 26's 1,000 keyframed objects), and the meshes end where a fresh Set Up puts them."""
    import bpy

    scene, movers = _keyframed_scene(bpy)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    work = _count_work(monkeypatch)

    scene.relativity.beta = (-0.3, 0.1, 0.0)  # the callback's sync, before Blender evaluates

    # (each updated, or its record of straight keys turned: straight_steps; a turn builds none)
    assert work["update"] + work["turned"] == Counter({f"Mover {k}": 1 for k in range(COUNT)}), _done(work)
    assert work["signature"] == work["update"], _done(work)
    bpy.context.evaluated_depsgraph_get()
    after = _points(bpy, movers)
    gh.remove_effect(scene)
    gh.apply_geometry(scene)
    fresh = _points(bpy, movers)
    for k in range(COUNT):
        np.testing.assert_allclose(after[k], fresh[k], atol=1e-6)


def test_key_change_on_one_of_many_keyframed_meshes_works_on_that_mesh_only(relativity_addon, monkeypatch):
    """One mesh's keys made faster (its velocity changed, as the Graph Editor does): that mesh is
    recomputed, the others are not and keep their evaluated positions exactly."""
    import bpy

    scene, movers = _keyframed_scene(bpy)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    # the first evaluation's verdicts (every retarded time inside the intervals) recompute every mesh
    # once more after Set Up; a sync then finds them current
    gh.addon_module("pipeline.effect").sync(scene)
    before = _points(bpy, movers)
    work = _count_work(monkeypatch)

    fcurve = next(f for f in gh.compat.action_fcurves(movers[2].animation_data) if f.data_path == "location")
    fcurve.keyframe_points[-1].co.y += 6.0
    fcurve.update()
    movers[2].update_tag(refresh={"TIME"})  # what an edit of the keys tags
    bpy.context.evaluated_depsgraph_get()
    after = _points(bpy, movers)

    assert work["update"]["Mover 2"] >= 1, _done(work)
    _assert_only_changed(work, before, after, 2)


def test_keyframed_meshes_solve_their_origin_from_the_knots(relativity_addon, monkeypatch):
    """Issue 26, per-mesh Python of keyframed motion: an observer change and a frame step on many
    keyframed meshes solve each origin's retarded time on the kept knots (Newton from the last one),
    never with the general sampled solver (``sampling.apparent_positions_from_matrix_function``, which
    samples a window around a guess and solves it: most of each mesh's Python before), and every mesh
    ends where the Python path puts it (``keyframed.MAX_INTERVALS`` 0), at the new frame too."""
    import importlib

    import bpy

    scene, movers = _keyframed_scene(bpy)
    for obj in movers:  # no Python edge measure, which solves every point with the general solver
        obj.relativity.tessellation = 0
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    effect = gh.addon_module("pipeline.effect")
    effect.sync(scene)
    sampling = importlib.import_module(f"{gh.ADDON_MODULE}.physics.sampling")
    calls = []
    original = sampling.apparent_positions_from_matrix_function

    def counted(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(sampling, "apparent_positions_from_matrix_function", counted)
    work = _count_work(monkeypatch)
    scene.relativity.beta = (-0.3, 0.1, 0.0)  # as the panel does
    bpy.context.evaluated_depsgraph_get()
    scene.frame_set(13)
    bpy.context.evaluated_depsgraph_get()
    modifier_points = _points(bpy, movers)
    assert work["update"] == Counter({f"Mover {k}": 2 for k in range(COUNT)}), _done(work)
    assert not calls, f"the general solver ran {len(calls)} times for {COUNT} meshes"

    monkeypatch.setattr(sampling, "apparent_positions_from_matrix_function", original)
    monkeypatch.setattr(gh.addon_module("geometry.keyframed"), "MAX_INTERVALS", 0)  # the Python path
    scene.relativity.beta = (-0.3, 0.1, 0.05)
    scene.relativity.beta = (-0.3, 0.1, 0.0)
    bpy.context.evaluated_depsgraph_get()
    python_points = _points(bpy, movers)
    for k in range(COUNT):
        assert np.abs(modifier_points[k] - python_points[k]).max() < 1e-5, f"Mover {k}"
        assert np.abs(python_points[k] - modifier_points[(k + 1) % COUNT]).max() > 1e-2  # meshes tell apart


@pytest.mark.parametrize("interpolation", ["LINEAR", "BEZIER"], ids=["linear-keys", "eased-keys"])
def test_set_up_computes_each_keyframed_mesh_once(relativity_addon, monkeypatch, interpolation):
    """Issue 26, Set Up of many keyframed meshes: Set Up, the evaluation after it and the syncs that
    follow compute each mesh's keyframed inputs once (``keyframed.update``; on main the first
    evaluation's verdicts, which the signature stored at Set Up did not hold yet, made the next sync
    compute every mesh again) and run no Python edge measure where the modifier's check finds every
    edge short (``tessellation.decide``: on main once per mesh before the check), and the meshes are
    where a recomputation from scratch puts them. Linear keys take the closed form, eased (Bezier)
    keys the keyframed solve."""
    import bpy

    scene, movers = _keyframed_scene(bpy)
    for obj in movers:
        obj.relativity.tessellation_tolerance = 10.0  # every edge short, as the benchmark's grids at 64x48
        for fcurve in gh.compat.action_fcurves(obj.animation_data):
            for point in fcurve.keyframe_points:
                point.interpolation = interpolation
    keyframed = gh.addon_module("geometry.keyframed")
    updates = Counter()
    original = keyframed.update

    def counted(obj, *args, **kwargs):
        updates[obj.name] += 1
        return original(obj, *args, **kwargs)

    monkeypatch.setattr(keyframed, "update", counted)
    tessellation = gh.addon_module("geometry.tessellation")
    measured = []
    decide = tessellation.decide
    monkeypatch.setattr(tessellation, "decide", lambda *args: measured.append(args[1].name) or decide(*args))
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()  # the viewport's redraw: the verdicts
    effect = gh.addon_module("pipeline.effect")
    effect.sync(scene)
    bpy.context.evaluated_depsgraph_get()
    points = _points(bpy, movers)
    on = [gh.addon_module("geometry.modifier").find_modifier(obj) for obj in movers]
    assert all(keyframed.is_on(mod) for mod in on) == (interpolation == "BEZIER"), "not the expected path"
    assert updates == Counter({f"Mover {k}": 1 for k in range(COUNT)}), dict(updates)
    assert not measured, f"the Python edge measure ran for {measured}"

    for obj in movers:  # every mesh computed again from scratch, for the same frame and observer
        gh.addon_module("geometry.modifier").cache_data(obj)[gh.addon_module("common.names").SIGNATURE_KEY] = ""
    effect.sync(scene)
    bpy.context.evaluated_depsgraph_get()
    effect.sync(scene)
    for k, again in enumerate(_points(bpy, movers)):
        np.testing.assert_allclose(points[k], again, atol=1e-6)
