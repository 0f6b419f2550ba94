"""Issue 26: keyframed motion that is uniform over the window of its retarded times (linear location
keys, rotation and scale held) gets the modifier's closed form (``keyframed.modifier_inputs``,
``sampling.uniform_motion``): no interval read per point. The evaluated positions and velocities must
be where docs/physics.md puts them (``_seen`` of the keyframed tests: the keys read with
``fcurve.evaluate``, the retarded time solved by bisection, the boost) and where the Python path puts
them; where the window holds a change of velocity, or the keys accelerate, the modifier solves the
keyframed motion (and the fallback of ``test_geometry_keyframed_modifier.py`` stays).
"""

import numpy as np
import pytest
from test_geometry_closed_form import _grid_mesh
from test_geometry_keyframed_modifier import FPS, OBSERVER, OBSERVER_CHANGED, C, _count_passes, _seen
from test_object_type_sweep import _cube_mesh, _link

import geometry_helpers as gh


def _inputs(obj, names=("Closed Form", "Keyframed")):
    modifier = gh.addon_module("geometry.modifier")
    mod = modifier.find_modifier(obj)
    return {name: bool(gh.compat.modifier_input(mod, modifier._identifier(mod.node_group, name))) for name in names}


def _uniform_mover(bpy, scene, adaptive):
    """Linear location keys (0.25c, then from frame 40 faster: 0.5c), a held rotation and scale."""
    mesh = _grid_mesh(bpy, "Mover", 60, 0.6) if adaptive else _cube_mesh(bpy, "Mover", 0.3)
    obj = _link(bpy, scene, "Mover", mesh)
    obj.scale = (1.0, 1.3, 0.8)
    obj.rotation_euler = (0.4, 0.0, -0.7)
    obj.location = (0.0, -0.4, -5.0)
    gh.keyframe_linear(obj, "location", 0, ((-120, -5.0), (40, -5.0 + 160 / FPS), (100, -5.0 + 160 / FPS + 120 / FPS)))
    obj.relativity.motion = "ANIMATION"
    obj.relativity.use_adaptive_tessellation = adaptive
    obj.relativity.tessellation = 4 if adaptive else 0
    return obj


def _set_up_mover(bpy):
    """The adaptive mover set up at frame 12 behind the observer moving at OBSERVER, evaluated:
    (scene, camera, mover)."""
    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _uniform_mover(bpy, scene, adaptive=True)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    return scene, camera, obj


@pytest.mark.parametrize("adaptive", [False, True])
def test_uniform_keyframed_motion_takes_the_closed_form(relativity_addon, monkeypatch, adaptive):
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _uniform_mover(bpy, scene, adaptive)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    # the closed form's bound on the edges' images clears the grid's here: no edge visited
    edges = ("Measure Edges", "Edges Proven Short")
    assert _inputs(obj, edges) == dict.fromkeys(edges, adaptive)
    calls = _count_passes(monkeypatch)

    scene.relativity.beta = OBSERVER_CHANGED
    gh.evaluated_points(bpy, obj)
    scene.frame_set(13)
    stepped, beta_stepped = gh.evaluated_points(bpy, obj, "relativity_beta")
    assert calls == dict.fromkeys(calls, 0), calls
    assert _inputs(obj) == {"Closed Form": True, "Keyframed": False}
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    assert len(rest) == len(obj.data.vertices)
    x_o = np.array(camera.matrix_world.translation)
    expected, velocity = _seen(obj, rest, 13 / FPS, x_o, OBSERVER_CHANGED)
    np.testing.assert_allclose(stepped, expected, atol=1e-4)
    np.testing.assert_allclose(beta_stepped, velocity, atol=1e-4)

    # the velocity change at frame 40 inside the window: the keyframed motion in the modifier
    scene.frame_set(75)
    assert _inputs(obj) == {"Closed Form": False, "Keyframed": True}
    kinked, beta_kinked = gh.evaluated_points(bpy, obj, "relativity_beta")
    assert calls == dict.fromkeys(calls, 0), calls

    # the Python path: the same motion, solved per vertex in float64
    monkeypatch.setattr(gh.addon_module("geometry.keyframed"), "MAX_INTERVALS", 0)
    # (the Python path's velocities are its samples' slopes: the keys' float32 rounding over 1/192 s
    # moves them by up to about 1e-4 where the closed form has the keys' one velocity)
    for frame, positions, beta, atol in ((75, kinked, beta_kinked, 2e-5), (13, stepped, beta_stepped, 2e-4)):
        scene.frame_set(frame)
        python, beta_python = gh.evaluated_points(bpy, obj, "relativity_beta")
        np.testing.assert_allclose(positions, python, atol=2e-5)
        np.testing.assert_allclose(beta, beta_python, atol=atol)
    assert calls["apparent_world_positions"] > 0
    assert _inputs(obj) == {"Closed Form": False, "Keyframed": False}

    monkeypatch.undo()  # back in the modifier: the closed form again at frame 12
    scene.frame_set(12)
    assert _inputs(obj) == {"Closed Form": True, "Keyframed": False}
    expected, _velocity = _seen(obj, rest, 12 / FPS, x_o, OBSERVER_CHANGED)
    np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], expected, atol=1e-4)


def _accelerating_cube(bpy):
    """A 0.3 m cube on Bezier location keys alone (about 0.1c to 0.8c, a key at frame 0 where the
    acceleration jumps), set up at frame 12 and evaluated: (scene, camera, cube)."""
    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    obj = _link(bpy, scene, "Mover", _cube_mesh(bpy, "Mover", 0.3))
    obj.location = (0.0, -0.4, -5.0)
    for frame, x in ((-120, -3.2), (0, -1.6), (48, 2.2)):
        obj.location.x = x
        obj.keyframe_insert("location", index=0, frame=frame)
    obj.relativity.motion = "ANIMATION"
    obj.relativity.tessellation = 0
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    return scene, camera, obj


def test_accelerating_keys_keep_the_keyframed_solve_and_its_fallback(relativity_addon, monkeypatch):
    """Bezier location keys alone (accelerating from about 0.1c to 0.8c, nothing turning): not a straight
    line, so the modifier solves the keyframed motion; with its window made too narrow (the recorded
    reach made tiny) the verdict sends the update to the Python path, where the relation puts the mesh."""
    import bpy

    keyframed = gh.addon_module("geometry.keyframed")
    modifier = gh.addon_module("geometry.modifier")
    scene, camera, obj = _accelerating_cube(bpy)
    assert _inputs(obj) == {"Closed Form": False, "Keyframed": True}

    modifier.cache_data(obj)[keyframed.REACH_KEY] = 1e-6
    calls = _count_passes(monkeypatch)
    scene.relativity.beta = OBSERVER_CHANGED
    bpy.context.evaluated_depsgraph_get()
    bpy.context.evaluated_depsgraph_get()  # the sync after the evaluation that said so
    assert calls["apparent_world_positions"] > 0
    assert _inputs(obj) == {"Closed Form": False, "Keyframed": False}
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    expected, _velocity = _seen(obj, rest, 12 / FPS, np.array(camera.matrix_world.translation), OBSERVER_CHANGED)
    np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], expected, atol=1e-4)


def _all_inputs(obj):
    """Every input value of the object's modifier but the geometry and the cache, as Python data."""
    modifier = gh.addon_module("geometry.modifier")
    mod = modifier.find_modifier(obj)
    values = {}
    for name, identifier in modifier._input_identifiers(mod.node_group).items():
        if name in ("Geometry", "Cache"):  # (5.2: the geometry input has no value)
            continue
        value = gh.compat.modifier_input(mod, identifier)
        if value is not None:
            values[name] = tuple(value) if hasattr(value, "__len__") else value
    return mod.node_group.name, values


def test_straight_keys_found_without_sampling_give_the_intervals_inputs(relativity_addon, monkeypatch):
    """Issue 26 (the 1,000-object keyframed scene): straight keys take the closed form from the line
    alone (``keyframed._uniform_over_window``, ``sampling.uniform_motion_window``: no key evaluated,
    no window solved) wherever the intervals would have found the keys straight, with the very inputs
    the intervals' path sets, frame after frame across a change of velocity (frame 40) and back."""
    import bpy

    keyframed = gh.addon_module("geometry.keyframed")
    sampling = keyframed.sampling
    animation = gh.addon_module("scene.animation")
    scene, _camera, obj = _set_up_mover(bpy)
    frames = (12, 13, 14, 20, 30, 60, 75, 90, 13)
    calls = {"motion_intervals": 0, "world_matrices": 0}
    for module, name in ((sampling, "motion_intervals"), (animation, "world_matrices")):
        original = getattr(module, name)

        def counted(*args, _original=original, _name=name, **kwargs):
            calls[_name] += _name != "world_matrices" or args[0] == obj  # (the camera's are read at every sync)
            return _original(*args, **kwargs)

        monkeypatch.setattr(module, name, counted)

    def run():
        found = []
        for frame in frames:
            scene.frame_set(frame)
            bpy.context.evaluated_depsgraph_get()
            found.append((dict(calls), _all_inputs(obj)))
        return found

    found = run()
    closed = [frame for frame, (_calls, (_group, values)) in zip(frames, found, strict=True) if values["Closed Form"]]
    assert 12 in closed and 75 not in closed  # 75: the window holds the kink at frame 40
    # frames 13 and 14 after 12: each step is taken from the line alone
    assert found[1][0] == found[0][0] and found[2][0] == found[1][0]
    monkeypatch.setattr(keyframed, "_uniform_over_window", lambda *args: None)
    scene.frame_set(1)  # every frame below is a change again
    bpy.context.evaluated_depsgraph_get()
    intervals = run()
    assert intervals[2][0]["motion_intervals"] > intervals[1][0]["motion_intervals"]
    assert [inputs for _calls, inputs in found] == [inputs for _calls, inputs in intervals]
