"""Issue 26, a frame step of keyframed objects (1,000 of them in ``benchmarks/artist_chain.py
--scenes objects``): the keys are evaluated at the window's new samples only and read for nothing
else (``keyframed._kept_samples``, ``keyframed._keyed_facts``, both kept under
``animation.keyframes_signature``, which a frame step does not change). Counted through a hook on
``animation.world_matrices`` (the frames it is asked for). A key edited between steps is followed:
the positions after each step are where docs/physics.md puts them (``_seen`` of the keyframed
tests: the keys read with ``fcurve.evaluate``, the retarded time by bisection, the boost)."""

import numpy as np
import pytest
from test_geometry_keyframed_modifier import FPS, OBSERVER, C, _keyframed_mover, _seen
from test_geometry_keyframed_uniform import _inputs, _uniform_mover

import geometry_helpers as gh


def _count_frames(monkeypatch):
    """Hook on the keyframe evaluation the modifier's inputs use: the number of frames asked for."""
    animation = gh.addon_module("scene.animation")
    original = animation.world_matrices
    asked = [0]

    def counted(obj, frames, *args, **kwargs):
        asked[0] += len(np.atleast_1d(frames))
        return original(obj, frames, *args, **kwargs)

    monkeypatch.setattr(animation, "world_matrices", counted)
    return asked


def _check_seen(bpy, camera, obj, frame):
    positions, velocities = gh.evaluated_points(bpy, obj, "relativity_beta")
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    expected, velocity = _seen(obj, rest, frame / FPS, np.array(camera.matrix_world.translation), OBSERVER)
    np.testing.assert_allclose(positions, expected, atol=1e-4)
    np.testing.assert_allclose(velocities, velocity, atol=2e-4)


@pytest.mark.parametrize("form", ["Closed Form", "Keyframed"])
def test_frame_step_evaluates_the_new_samples_only_and_follows_a_key_edit(relativity_addon, monkeypatch, form):
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    if form == "Closed Form":  # linear keys: uniform motion over the window
        obj = _uniform_mover(bpy, scene, False)
    else:  # Bezier keys, turning: the sample intervals
        obj = _keyframed_mover(bpy, scene, False, 0, True)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    scene.frame_set(13)
    bpy.context.evaluated_depsgraph_get()
    assert _inputs(obj)[form], _inputs(obj)
    asked = _count_frames(monkeypatch)

    scene.frame_set(14)
    _check_seen(bpy, camera, obj, 14)

    per_frame = int(obj.relativity.samples_per_frame)
    # the window moves by one frame: its new samples, and a margin of one frame's for the solve
    assert asked[0] <= 2 * per_frame, f"{asked[0]} frames evaluated for a step of {per_frame} samples"

    fcurve = next(f for f in gh.compat.action_fcurves(obj.animation_data) if f.data_path == "location")
    fcurve.keyframe_points[0].co.y -= 0.5  # the first key moved (the window's motion changes)
    fcurve.keyframe_points[0].handle_left.y -= 0.5
    fcurve.keyframe_points[0].handle_right.y -= 0.5
    fcurve.update()
    scene.frame_set(15)
    _check_seen(bpy, camera, obj, 15)
    assert asked[0] > 2 * per_frame, "the edited keys were evaluated again"
