"""Issue 26: a frame step of a mesh on straight keys sets the closed form's two offsets from what the
last update kept (``straight_steps.step``), not a full update. What the mesh shows must be where
docs/physics.md puts it (``_seen`` of the keyframed tests) at every frame stepped, and the step must
give way to the full update wherever its record does not hold: the window reaching a change of velocity,
a parent moved by a script, a key inserted by a script together with the frame step. An observer's
velocity change turns the records (the boost's inputs set with the offsets, the edges' bound taken again
for all of them at once) instead of a full update."""

import numpy as np
import pytest
from test_geometry_keyframed_modifier import FPS, OBSERVER, OBSERVER_CHANGED, C, _seen
from test_geometry_keyframed_uniform import _inputs, _set_up_mover, _uniform_mover

import geometry_helpers as gh


def _counted_updates(monkeypatch):
    """{"update_object": full updates, "step": objects the records stepped}."""
    meshes = gh.addon_module("geometry.apparent_meshes")
    steps = gh.addon_module("geometry.straight_steps")
    hooked = ((meshes, "update_object"), (steps, "step"))
    return gh.count_calls(monkeypatch, hooked, lambda name, result: 1 if name == "update_object" else len(result))


def _check(bpy, obj, camera, frame, observer=OBSERVER):
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    expected, velocity = _seen(obj, rest, frame / FPS, np.array(camera.matrix_world.translation), observer)
    positions, beta = gh.evaluated_points(bpy, obj, "relativity_beta")
    np.testing.assert_allclose(positions, expected, atol=1e-4)
    np.testing.assert_allclose(beta, velocity, atol=1e-4)


def test_frame_steps_on_straight_keys_set_the_offsets_alone(relativity_addon, monkeypatch):
    import bpy

    scene, camera, obj = _set_up_mover(bpy)
    calls = _counted_updates(monkeypatch)
    for frame in range(13, 31):
        scene.frame_set(frame)
        _check(bpy, obj, camera, frame)
        assert _inputs(obj) == {"Closed Form": True, "Keyframed": False}
    # the edges' sweep holds for SWEEP_FRAMES (16) frames ahead: a full update at most every few frames
    assert calls["step"] >= 12, calls
    assert calls["update_object"] >= 1, calls

    # the window reaches the change of velocity at frame 40: the full update (keyframed solve)
    scene.frame_set(75)
    assert _inputs(obj) == {"Closed Form": False, "Keyframed": True}
    _check(bpy, obj, camera, 75)


def test_a_step_gives_way_to_a_moved_parent_and_a_new_key(relativity_addon, monkeypatch):
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _uniform_mover(bpy, scene, adaptive=True)
    parent = bpy.data.objects.new("Holder", None)
    scene.collection.objects.link(parent)
    obj.parent = parent
    scene.frame_set(12)
    gh.apply_geometry(scene)
    scene.frame_set(13)
    scene.frame_set(14)
    calls = _counted_updates(monkeypatch)
    reference = gh.evaluated_points(bpy, obj)[0]

    # a script moves the (unkeyed) parent and steps: the matrix leaves the keys' line
    parent.location = (0.3, 0.0, 0.0)
    scene.frame_set(15)
    moved = gh.evaluated_points(bpy, obj)[0]
    assert calls["update_object"] >= 1, calls
    parent.location = (0.0, 0.0, 0.0)
    scene.frame_set(14)
    np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], reference, atol=1e-5)
    assert np.abs(moved - reference).max() > 0.1

    # a script inserts a key (the motion changes from frame 14 on) and steps in one go
    scene.frame_set(15)
    _check(bpy, obj, camera, 15)
    obj.location.x += 0.5
    obj.keyframe_insert("location", index=0, frame=16)
    before = calls["update_object"]
    scene.frame_set(16)
    assert calls["update_object"] > before, calls
    _check(bpy, obj, camera, 16)


def test_an_observer_velocity_change_turns_the_records(relativity_addon, monkeypatch):
    """The observer's velocity changed in the panel (the keyframed scene of issue 26's benchmark): the
    mesh shows the new observer's view (docs/physics.md's boost of the retarded emission, solved in the
    test) with no full update, and the frame steps after it keep stepping; back at the first velocity,
    the first view."""
    import bpy

    scene, camera, obj = _set_up_mover(bpy)
    scene.frame_set(13)
    _check(bpy, obj, camera, 13)
    steps = gh.addon_module("geometry.straight_steps")
    calls = _counted_updates(monkeypatch)
    turned = []
    original = steps.step

    def step(objects, seen, snap, depsgraph, turning=False):
        result = original(objects, seen, snap, depsgraph, turning)
        turned.extend(result if turning else ())
        return result

    monkeypatch.setattr(steps, "step", step)
    scene.relativity.beta = OBSERVER_CHANGED
    _check(bpy, obj, camera, 13, OBSERVER_CHANGED)
    assert turned == [obj.session_uid], turned
    assert calls["update_object"] == 0, calls
    assert _inputs(obj) == {"Closed Form": True, "Keyframed": False}
    for frame in (14, 15):
        scene.frame_set(frame)
        _check(bpy, obj, camera, frame, OBSERVER_CHANGED)
    assert calls["update_object"] == 0, calls
    scene.relativity.beta = OBSERVER
    _check(bpy, obj, camera, 15)
    assert len(turned) == 2 and calls["update_object"] == 0, (turned, calls)


def test_undo_of_an_observer_velocity_change_draws_the_old_view(relativity_addon, factory_blender):
    """An observer's velocity change (the records turned), then Undo: the mesh is drawn as before the
    change, to the float, and a frame step after it is still the physics' view at the old velocity."""
    bpy = factory_blender
    scene, camera, obj = _set_up_mover(bpy)
    scene.frame_set(13)
    before = gh.evaluated_points(bpy, obj)[0]
    bpy.ops.ed.undo_push(message="set up")
    scene.relativity.beta = OBSERVER_CHANGED
    bpy.context.evaluated_depsgraph_get()
    bpy.ops.ed.undo_push(message="velocity")
    assert np.abs(gh.evaluated_points(bpy, obj)[0] - before).max() > 0.1, "the change moved the mesh"

    bpy.ops.ed.undo()
    bpy.context.evaluated_depsgraph_get()
    scene, obj = bpy.context.scene, bpy.context.scene.objects["Mover"]
    assert tuple(scene.relativity.beta) == pytest.approx(OBSERVER)
    np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], before, atol=1e-6)
    scene.frame_set(14)
    _check(bpy, obj, scene.camera, 14)


def test_an_observer_velocity_change_in_a_sunlit_scene(relativity_addon, monkeypatch):
    """A sun in the scene (the lamp stage's light-linked copy of it for the mover): the turned mesh is
    the physics' view at the new velocity, and the sun's copy stays what a Set Up at that velocity makes
    (its colour and place: the sun's light on the mover does not depend on the observer)."""
    import bpy

    scene, camera, obj = _set_up_mover(bpy)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.rotation_euler = (0.6, 0.3, 0.0)
    scene.collection.objects.link(sun)
    scene.frame_set(13)
    lamps = gh.addon_module("lights.lamps_on_moving_objects")

    def copies():
        found = [o for o in scene.objects if lamps.is_copy(o)]
        return {o.name: (tuple(o.data.color), tuple(map(tuple, o.matrix_world))) for o in found}

    bpy.context.evaluated_depsgraph_get()
    first = copies()
    calls = _counted_updates(monkeypatch)
    scene.relativity.beta = OBSERVER_CHANGED
    _check(bpy, obj, camera, 13, OBSERVER_CHANGED)
    assert calls["update_object"] == 0, calls
    turned = copies()
    assert turned == first  # (eq. 18's factor is the mover's, in its frame: no observer in it)
    assert len(turned) == 1, turned
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    for name, (colour, matrix) in copies().items():
        np.testing.assert_allclose(colour, turned[name][0], rtol=1e-6)
        np.testing.assert_allclose(matrix, turned[name][1], atol=1e-6)


def test_observer_velocity_changes_after_opening_the_file_again(
    relativity_addon, factory_blender, tmp_path, monkeypatch
):
    """The records outlive a file (kept per object's session_uid): after the file is opened again (new
    session_uids), the first observer's velocity change updates the mesh in full, the next one turns it,
    and both draw the physics' view."""
    bpy = factory_blender
    scene, camera, obj = _set_up_mover(bpy)
    scene.frame_set(13)
    path = str(tmp_path / "turned.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    scene.relativity.beta = OBSERVER_CHANGED  # a turn in this session
    bpy.context.evaluated_depsgraph_get()
    bpy.ops.wm.open_mainfile(filepath=path)
    scene = bpy.context.scene
    obj, camera = scene.objects["Mover"], scene.camera
    calls = _counted_updates(monkeypatch)
    scene.relativity.beta = OBSERVER_CHANGED
    _check(bpy, obj, camera, 13, OBSERVER_CHANGED)
    full = calls["update_object"]
    assert full >= 1, calls
    scene.relativity.beta = OBSERVER
    _check(bpy, obj, camera, 13)
    assert calls["update_object"] == full and calls["step"] >= 1, calls
