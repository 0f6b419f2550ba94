"""Issue 26: Blender's default keys (Bezier, eased in and out: accelerating at every frame) moving a
mesh without turning it, where one cubic in time follows the sampled motion over the window of its
retarded times to the samples' own float32 rounding, are solved in the modifier on that polynomial
(``physics/polynomial_motion.py``, ``keyframed.py``'s ``Polynomial``): no interval read per point,
no pass over the vertices in Python. The evaluated positions and velocities must be where
docs/physics.md puts them (``_seen`` of the keyframed tests: the keys read with ``fcurve.evaluate``,
the retarded time solved by bisection, the boost) and where the general keyframed solve (the
intervals read per point) puts them; keys whose window crosses a key (the acceleration jumps there)
keep the general solve.
"""

import numpy as np
import pytest
from test_geometry_closed_form import _grid_mesh
from test_geometry_keyframed_modifier import FPS, OBSERVER, OBSERVER_CHANGED, C, _count_passes, _seen
from test_geometry_keyframed_uniform import _accelerating_cube, _inputs
from test_object_type_sweep import _cube_mesh, _link

import geometry_helpers as gh

MODES = ("Keyframed", "Polynomial", "Closed Form")
ONE_STEP = (*MODES, "Polynomial One Step")


def _eased_mover(bpy, scene, adaptive, slower=1):
    """Two Bezier keys on x and z (Blender's default: auto-clamped handles), 0.3c on average and
    about 0.45c at the middle of the motion (``slower`` times as far apart in time: that much
    slower, the acceleration ``slower**2`` times less); rotation and scale held."""
    slower = float(slower)
    mesh = _grid_mesh(bpy, "Mover", 60, 0.6) if adaptive else _cube_mesh(bpy, "Mover", 0.3)
    obj = _link(bpy, scene, "Mover", mesh)
    obj.scale = (1.0, 1.3, 0.8)
    obj.rotation_euler = (0.4, 0.0, -0.7)
    obj.location = (0.0, -0.4, -5.0)
    for frame, x, z in ((round(-240 * slower), -12.0, -6.0), (round(480 * slower), 24.0, -3.0)):
        obj.location.x, obj.location.z = x, z
        obj.keyframe_insert("location", index=0, frame=frame)
        obj.keyframe_insert("location", index=2, frame=frame)
    obj.relativity.motion = "ANIMATION"
    obj.relativity.use_adaptive_tessellation = adaptive
    obj.relativity.tessellation = 4 if adaptive else 0
    return obj


def _count_windows(monkeypatch):
    """A one-item list counting the windows of retarded times sampled (``sampling.motion_intervals``)."""
    sampling = gh.addon_module("geometry.keyframed").sampling
    count = [0]
    original = sampling.motion_intervals

    def counted(*args, **kwargs):
        count[0] += 1
        return original(*args, **kwargs)

    monkeypatch.setattr(sampling, "motion_intervals", counted)
    return count


def _intervals_written(obj):
    """How many sample intervals the cache holds for the modifier to read per point (its points
    before the face codes)."""
    modifier = gh.addon_module("geometry.modifier")
    mod = modifier.find_modifier(obj)
    codes = gh.compat.modifier_input(mod, modifier._identifier(mod.node_group, "Face Codes"))
    return len(modifier.cache_data(obj).vertices) - int(codes)


@pytest.mark.parametrize("adaptive", [False, True])
def test_eased_keys_take_the_polynomial(relativity_addon, monkeypatch, adaptive):
    import bpy

    keyframed = gh.addon_module("geometry.keyframed")
    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _eased_mover(bpy, scene, adaptive)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    assert _intervals_written(obj) == 0  # (main: 128-156 intervals read per point)
    # one closed-form step reaches the roots at the rest box's check points (polynomial_motion.choose_steps)
    assert _inputs(obj, ONE_STEP) == {**dict.fromkeys(ONE_STEP, True), "Closed Form": False}
    calls = _count_passes(monkeypatch)
    windows = _count_windows(monkeypatch)

    scene.relativity.beta = OBSERVER_CHANGED  # as the panel does: the update callback runs
    changed, beta_changed = gh.evaluated_points(bpy, obj, "relativity_beta")
    # the window depends on the observer's event, not on its velocity: kept (main: sampled again)
    assert windows == [0]
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    x_o = np.array(camera.matrix_world.translation)
    expected, velocity = _seen(obj, rest, 12 / FPS, x_o, OBSERVER_CHANGED)
    np.testing.assert_allclose(changed, expected, atol=1e-4)
    np.testing.assert_allclose(beta_changed, velocity, atol=1e-4)
    scene.frame_set(13)
    assert windows == [1]  # a new event: a new window
    stepped, beta_stepped = gh.evaluated_points(bpy, obj, "relativity_beta")
    assert calls == dict.fromkeys(calls, 0), calls
    assert _inputs(obj, MODES) == {"Keyframed": True, "Polynomial": True, "Closed Form": False}
    assert len(rest) == len(obj.data.vertices)  # the grid left whole: the edges' bound cleared it
    expected, velocity = _seen(obj, rest, 13 / FPS, x_o, OBSERVER_CHANGED)
    np.testing.assert_allclose(stepped, expected, atol=1e-4)
    np.testing.assert_allclose(beta_stepped, velocity, atol=1e-4)
    assert np.ptp(np.linalg.norm(beta_stepped, axis=1)) > 1e-4  # each vertex its own velocity

    # the general keyframed solve (the intervals read per point) on the same motion
    monkeypatch.setattr(keyframed, "_box_corners", lambda obj, facts: None)
    scene.frame_set(12)
    scene.frame_set(13)
    assert _inputs(obj, MODES) == {"Keyframed": True, "Polynomial": False, "Closed Form": False}
    assert _intervals_written(obj) > 0
    general, beta_general = gh.evaluated_points(bpy, obj, "relativity_beta")
    # float32 noise: the samples' rounding (keys up to 24 m) moves the intervals' contraction by about
    # 1e-5 and their slopes over 1/192 s (the general solve's velocities) by a few 1e-4, which the
    # polynomial smooths out (as the closed form of test_geometry_keyframed_uniform.py does)
    np.testing.assert_allclose(stepped, general, atol=2e-5)
    # (measured: the general solve's velocities depart from the relation by up to 4.6e-4 on the grid,
    # the polynomial's by 7e-5; positions 1.5e-5 and 7e-6)
    np.testing.assert_allclose(beta_stepped, beta_general, atol=6e-4)


def test_faster_eased_keys_take_two_steps(relativity_addon):
    """The keys of ``test_eased_keys_take_the_polynomial`` at half the time apart (twice the speed,
    about 0.84c at frame 13, four times the acceleration): one closed-form step from the start's line
    leaves the roots at the rest box's check points by more than a tenth of the tolerance, so the
    modifier takes two (``Polynomial One Step`` off), and the mesh and its velocities are where
    docs/physics.md puts them: within 8e-6 scene units (measured on 4.5: 3.8e-6 with two steps, 1.4e-5
    with one step forced). The polynomial's terms are multiply-adds on the rest position's parts: no
    Transform Point per point."""
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _eased_mover(bpy, scene, False, slower=0.5)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    scene.frame_set(13)
    assert _inputs(obj, ONE_STEP) == {
        "Keyframed": True,
        "Polynomial": True,
        "Closed Form": False,
        "Polynomial One Step": False,
    }
    stepped, beta_stepped = gh.evaluated_points(bpy, obj, "relativity_beta")
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    expected, velocity = _seen(obj, rest, 13 / FPS, np.array(camera.matrix_world.translation), OBSERVER)
    np.testing.assert_allclose(stepped, expected, atol=8e-6)
    np.testing.assert_allclose(beta_stepped, velocity, atol=1e-4)
    group = gh.addon_module("geometry.modifier").find_modifier(obj).node_group
    solve = [node.bl_idname for node in group.nodes if node.name.startswith("kp")]
    assert solve and "FunctionNodeTransformPoint" not in solve


def test_keys_whose_window_crosses_a_key_keep_the_general_solve(relativity_addon):
    """Bezier keys (about 0.1c to 0.8c) with a key at frame 0, where the acceleration jumps: at frame 31
    the window of retarded times holds it (the cube is about 5.3 m away at c = 4 m/s: 1.3 s, 32
    frames); no cubic follows that to the samples' rounding, so the intervals are read per point (and
    the mesh is where the relation puts it). At frame 12 the window lies before the key: the
    polynomial."""
    import bpy

    scene, camera, obj = _accelerating_cube(bpy)
    assert _inputs(obj, MODES) == {"Keyframed": True, "Polynomial": True, "Closed Form": False}
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    x_o = np.array(camera.matrix_world.translation)
    for frame, polynomial in ((12, True), (31, False)):
        scene.frame_set(frame)
        assert _inputs(obj, MODES) == {"Keyframed": True, "Polynomial": polynomial, "Closed Form": False}
        expected, _velocity = _seen(obj, rest, frame / FPS, x_o, (0.0, 0.0, 0.0))
        np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], expected, atol=1e-4)


def test_observer_at_rest_skips_the_boost(relativity_addon):
    """An observer at rest (``Observer Moving`` off): the modifier adds no delay term and no velocity
    to the points' own (the boost is the identity), and the mesh and its velocities are still where
    docs/physics.md puts them; a velocity change of the observer turns the boost back on (main: no
    such input, the boost evaluated per point at rest too)."""
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = (0.0, 0.0, 0.0)
    obj = _eased_mover(bpy, scene, False)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    x_o = np.array(camera.matrix_world.translation)
    for frame, beta in ((13, (0.0, 0.0, 0.0)), (14, OBSERVER)):
        scene.relativity.beta = beta
        scene.frame_set(frame)
        moving = any(value != 0.0 for value in beta)
        assert _inputs(obj, (*MODES, "Observer Moving")) == {
            "Keyframed": True,
            "Polynomial": True,
            "Closed Form": False,
            "Observer Moving": moving,
        }
        seen, beta_seen = gh.evaluated_points(bpy, obj, "relativity_beta")
        rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
        expected, velocity = _seen(obj, rest, frame / FPS, x_o, beta)
        np.testing.assert_allclose(seen, expected, atol=1e-4)
        np.testing.assert_allclose(beta_seen, velocity, atol=1e-4)
        assert np.ptp(np.linalg.norm(beta_seen, axis=1)) > 1e-4  # each vertex its own velocity


def test_unfolded_closed_forms(relativity_addon, monkeypatch):
    """With ``Folded`` off (a window too fast for the towards form on every point: here forced by a
    fold limit of 1), each of the polynomial's closed forms picks its form per point, and the mesh
    and its velocities are still where docs/physics.md puts them."""
    import bpy

    monkeypatch.setattr(gh.addon_module("geometry.uniform_motion"), "FOLD_LIMIT", 1.0)
    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _eased_mover(bpy, scene, False)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    scene.frame_set(13)
    assert _inputs(obj, (*MODES, "Folded")) == {
        "Keyframed": True,
        "Polynomial": True,
        "Closed Form": False,
        "Folded": False,
    }
    seen, beta_seen = gh.evaluated_points(bpy, obj, "relativity_beta")
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    expected, velocity = _seen(obj, rest, 13 / FPS, np.array(camera.matrix_world.translation), OBSERVER)
    np.testing.assert_allclose(seen, expected, atol=1e-4)
    np.testing.assert_allclose(beta_seen, velocity, atol=1e-4)
