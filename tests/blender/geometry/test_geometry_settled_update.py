"""Issue 26: the depsgraph update that follows a setting's update callback is not synced in full again.

A velocity change on one of N meshes runs the callback's sync (every stage, the panel's records);
Blender then evaluates, and ``depsgraph_update_post`` reports that mesh and its data updated.
When that is all it reports, the handler takes again only what the evaluation changed: the mesh's
signature, its clip-end depth from the evaluated bounds, its cache's notes (``pipeline/settled.py``).
Counted through a hook on ``effect._record`` (the panel's records: one per full sync). What the
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
    effect = gh.addon_module("pipeline.effect")
    calls = []
    original = effect._record

    def counted(*args, **kwargs):
        calls.append(args[0].name)
        return original(*args, **kwargs)

    monkeypatch.setattr(effect, "_record", counted)
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
    assert full == [scene.name], "the callback's sync is a full one"
    bpy.context.evaluated_depsgraph_get()

    assert full == [scene.name], f"the depsgraph update after the callback synced in full again: {full}"
    lines = _clip_end_lines(scene)
    assert len(lines) == 1 and "'Mover 2'" in lines[0], lines  # taken from the evaluated bounds
    seen = float(lines[0].split("seen ")[1].split(" m away")[0])
    distance = movers[2].location.length  # 6 m (the mover's centre; its near corner a little less)
    assert 0.8 * distance / (1.0 - 0.9) < seen < 1.2 * distance / (1.0 - 0.9), seen

    movers[2].relativity.beta = (0.3, 0.0, 0.0)
    bpy.context.evaluated_depsgraph_get()
    assert _clip_end_lines(scene) == [], "the warning goes with the speed"
    assert len(full) == 2


@pytest.mark.parametrize("which", ("changed", "another"))
def test_an_edit_by_script_after_the_callback_is_synced_in_full(relativity_addon, which):
    """Instancing added without a callback, after a velocity change and before the evaluation, to
    the changed mesh or to another: the depsgraph update reports it, and its sync refuses it
    (``test_geometry_edits_after_setup``'s refusal) as it would without the velocity change."""
    import bpy

    scene, movers = _set_up(bpy)
    movers[1].relativity.beta = (0.35, 0.0, 0.0)
    edited = movers[1] if which == "changed" else movers[4]
    _add_instancing(bpy, scene, edited, "PARTICLES")
    _refused_at_sync(bpy, scene, edited.name)


def test_undo_of_a_velocity_change_draws_the_old_velocity_again(relativity_addon, factory_blender):
    """A velocity change (its callback's full sync, then the settled update), then Undo: the mesh is
    drawn where it was before the change, to the float, and the Clip End warning goes with it."""
    bpy = factory_blender
    scene, movers = _set_up(bpy)
    before = gh.evaluated_points(bpy, movers[2])[0]
    bpy.ops.ed.undo_push(message="set up")
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
