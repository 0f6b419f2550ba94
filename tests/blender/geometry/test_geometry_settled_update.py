"""Issue 26: the depsgraph update that follows a setting's update callback is not synced in full again.

A velocity change on one of N meshes runs the callback's sync (every stage, the panel's records);
Blender then evaluates, and ``depsgraph_update_post`` reports that mesh and its data updated.
When that is all it reports, the handler takes again only what the evaluation changed: the mesh's
signature, its clip-end depth from the evaluated bounds, its cache's notes (``pipeline/settled.py``).
Counted through a hook on ``records.record`` (the panel's records: one per full sync). What the
callback's sync could not have seen must still be taken in full: a change made by a script between
the setting and the evaluation, to the same mesh or another (instancing added: refused), and the
evaluated depth the warning about Clip End needs (docs/physics.md: a point approaching at ``beta``
along the line of sight at distance ``d`` is seen where it was, at ``d / (1 - beta)``).
"""

import numpy as np
import pytest
from test_geometry_edits_after_setup import _add_instancing, _refused_at_sync
from test_geometry_many_objects import _scene

import geometry_helpers as gh

CLIP_END = 12.0  # the movers are 6-7 m away at 0.3 c across; at 0.9 c towards the camera ~60 m


def _count_full_syncs(monkeypatch):
    records = gh.addon_module("pipeline.records")
    calls = []
    original = records.record

    def counted(*args, **kwargs):
        calls.append(args[0].name)
        return original(*args, **kwargs)

    monkeypatch.setattr(records, "record", counted)
    return calls


def _set_up(bpy):
    scene, movers = _scene(bpy, 0)
    scene.camera.data.clip_end = CLIP_END
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    bpy.context.evaluated_depsgraph_get()  # the viewport's redraw: every verdict taken
    return scene, movers


def _clip_end_lines(scene):
    return [line for line in gh.addon_module("pipeline.effect").scene_warnings(scene) if "Clip End" in line]


def test_velocity_change_syncs_in_full_once_and_takes_the_evaluated_depth(relativity_addon, monkeypatch):
    import bpy

    scene, movers = _set_up(bpy)
    assert _clip_end_lines(scene) == []
    full = _count_full_syncs(monkeypatch)

    movers[2].relativity.beta = (0.0, 0.0, 0.9)  # towards the camera, along the line of sight
    # a full sync, or none where the last one knew the mesh (Set Up wrote every cache: settled.py)
    assert full in ([scene.name], []), full
    callback = list(full)
    bpy.context.evaluated_depsgraph_get()

    assert full == callback, f"the depsgraph update after the callback synced in full: {full}"
    lines = _clip_end_lines(scene)
    assert len(lines) == 1 and "'Mover 2'" in lines[0], lines  # taken from the evaluated bounds
    seen = float(lines[0].split("seen ")[1].split(" m away")[0])
    distance = movers[2].location.length  # 6 m (the mover's centre; its near corner a little less)
    assert 0.8 * distance / (1.0 - 0.9) < seen < 1.2 * distance / (1.0 - 0.9), seen

    movers[2].relativity.beta = (0.3, 0.0, 0.0)  # dragged again: no full sync (settled.velocity_holds)
    bpy.context.evaluated_depsgraph_get()
    assert _clip_end_lines(scene) == [], "the warning goes with the speed"
    assert full == callback


def _brightest(speed, power):
    """``(gamma (1 + beta))^power``, the largest ``D^power`` at ``speed`` (clamping.py's bound)."""
    return ((1.0 + speed) / (1.0 - speed)) ** (power / 2.0)


def test_a_dragged_velocity_is_drawn_on_the_light_cone_with_the_fastest_clamp(relativity_addon, monkeypatch):
    """A velocity dragged on one of six meshes moving at 0.3 c: after the first change (a full sync)
    each change writes that mesh and the stages only. Every point of the evaluated mesh is where the
    mesh was when the light left it (``t_e = t_o - |x_o - x_a| / c``, the origin moving at ``beta c``
    through where Blender draws it at ``t_o``, the rest shape contracted along ``beta``), and the
    indirect clamp follows the fastest mover (``(gamma (1 + beta))^6`` times the user's 10): faster
    than the others, faster still, then slower than the others again (their 0.3 c read again)."""
    import bpy

    scene, movers = _scene(bpy, 0)
    scene.cycles.sample_clamp_indirect = 10.0
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    full = _count_full_syncs(monkeypatch)
    dragged = gh.count_calls(monkeypatch, [(gh.addon_module("pipeline.records"), "take_stages")])
    mover = movers[2]
    rest = np.array([vertex.co for vertex in mover.data.vertices])
    x_o = np.array(scene.camera.matrix_world.translation)
    t_o = scene.frame_current / scene.render.fps
    c = scene.relativity.speed_of_light
    for beta, fastest in (((0.5, 0.0, 0.0), 0.5), ((0.7, 0.0, 0.2), np.hypot(0.7, 0.2)), ((0.2, 0.0, 0.0), 0.3)):
        mover.relativity.beta = beta
        x_a = gh.evaluated_points(bpy, mover)[0]
        t_e = t_o - np.linalg.norm(x_a - x_o, axis=1) / c
        origin = np.array(mover.matrix_world.translation)
        x_e = origin + gh.contract(rest, beta) + np.outer(t_e - t_o, np.array(beta) * c)
        residual, mismatch = gh.retarded_residuals(x_a, x_e, x_o)
        assert residual.max() < 1e-5 and mismatch.max() < 1e-5, (beta, residual.max(), mismatch.max())
        clamp = scene.cycles.sample_clamp_indirect
        assert clamp == pytest.approx(10.0 * _brightest(fastest, 6), rel=1e-5), (beta, clamp)
    assert len(full) <= 1 and sum(dragged.values()) >= 2, (full, dragged)  # (at most the first in full)


def test_a_dragged_velocity_at_c_is_refused_as_the_first(relativity_addon):
    """The second change of a drag reaching c is refused in one line, as the first would be."""
    import bpy

    scene, movers = _set_up(bpy)
    movers[3].relativity.beta = (0.5, 0.0, 0.0)
    bpy.context.evaluated_depsgraph_get()
    movers[3].relativity.beta = (1.2, 0.0, 0.0)
    bpy.context.evaluated_depsgraph_get()
    warnings = gh.addon_module("pipeline.effect").scene_warnings(scene)
    assert any("'Mover 3'" in line and "below 1" in line for line in warnings), warnings


@pytest.mark.parametrize("dragged", (False, True))
@pytest.mark.parametrize("which", ("changed", "another"))
def test_an_edit_by_script_after_the_callback_is_synced_in_full(relativity_addon, which, dragged):
    """Instancing added without a callback, after a velocity change and before the evaluation, to
    the changed mesh or to another: the depsgraph update reports it, and its sync refuses it
    (``test_geometry_edits_after_setup``'s refusal) as it would without the velocity change;
    ``dragged``: the change is the second of a drag (its callback writes that mesh only)."""
    import bpy

    scene, movers = _set_up(bpy)
    if dragged:
        movers[1].relativity.beta = (0.4, 0.0, 0.0)
        bpy.context.evaluated_depsgraph_get()
    movers[1].relativity.beta = (0.35, 0.0, 0.0)
    edited = movers[1] if which == "changed" else movers[4]
    _add_instancing(bpy, scene, edited, "PARTICLES")
    _refused_at_sync(bpy, scene, edited.name)


@pytest.mark.parametrize("dragged", (False, True))
def test_undo_of_a_velocity_change_draws_the_old_velocity_again(relativity_addon, factory_blender, dragged):
    """A velocity change (its callback's full sync, then the settled update; ``dragged``: then a
    second change writing that mesh only), then Undo: the mesh is drawn where it was before the
    change, to the float, and the Clip End warning goes with it."""
    bpy = factory_blender
    scene, movers = _set_up(bpy)
    before = gh.evaluated_points(bpy, movers[2])[0]
    bpy.ops.ed.undo_push(message="set up")
    if dragged:
        movers[2].relativity.beta = (0.0, 0.0, 0.5)
        bpy.context.evaluated_depsgraph_get()
    movers[2].relativity.beta = (0.0, 0.0, 0.9)
    bpy.context.evaluated_depsgraph_get()
    bpy.ops.ed.undo_push(message="velocity")
    assert len(_clip_end_lines(scene)) == 1
    moved = gh.evaluated_points(bpy, movers[2])[0]
    assert np.abs(moved - before).max() > 1.0, "the change moved the mesh"

    bpy.ops.ed.undo()
    bpy.context.evaluated_depsgraph_get()
    scene = bpy.context.scene
    mover = scene.objects["Mover 2"]  # (undo reads the file's state again: new Python objects)
    assert tuple(mover.relativity.beta) == pytest.approx((0.3, 0.0, 0.0))
    np.testing.assert_allclose(gh.evaluated_points(bpy, mover)[0], before, atol=1e-6)
    assert _clip_end_lines(scene) == []


def test_a_velocity_dragged_after_a_bake_leaves_the_baked_meshes(relativity_addon, factory_blender, tmp_path):
    """Baked for Render Anywhere, the meshes are played back as baked until Remove: a velocity
    dragged then (the second change would otherwise write that mesh only) moves nothing."""
    bpy = factory_blender
    scene, movers = _set_up(bpy)
    movers[2].relativity.beta = (0.4, 0.0, 0.0)
    bpy.context.evaluated_depsgraph_get()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "baked.blend"))
    effect = gh.addon_module("pipeline.effect")
    effect.bake_for_render_anywhere(scene, scene.frame_current, scene.frame_current)
    scene = bpy.context.scene
    mover = scene.objects["Mover 2"]
    baked = gh.evaluated_points(bpy, mover)[0]
    for beta in ((0.6, 0.0, 0.0), (0.1, 0.0, 0.5)):
        mover.relativity.beta = beta
        bpy.context.evaluated_depsgraph_get()
        np.testing.assert_allclose(gh.evaluated_points(bpy, mover)[0], baked, atol=1e-6)


def test_a_velocity_dragged_after_a_mesh_was_swapped_by_script_goes_the_full_way(relativity_addon, monkeypatch):
    """A script deletes a set-up mesh and adds an empty (the scene's object count the same), then
    drags a velocity before any evaluation: the record's meshes are no longer the scene's, so the
    change goes the full way (no error from the removed mesh), and the mesh moves."""
    import bpy

    scene, movers = _set_up(bpy)
    movers[2].relativity.beta = (0.4, 0.0, 0.0)
    bpy.context.evaluated_depsgraph_get()
    before = gh.evaluated_points(bpy, movers[2])[0]
    bpy.data.objects.remove(movers[5])
    scene.collection.objects.link(bpy.data.objects.new("Stand-in empty", None))
    full = _count_full_syncs(monkeypatch)
    movers[2].relativity.beta = (0.6, 0.0, 0.0)
    assert full == [scene.name], full
    after = gh.evaluated_points(bpy, movers[2])[0]
    assert np.abs(after - before).max() > 0.01
