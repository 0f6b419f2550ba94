"""Issue 26: keyframed rigid motion is computed in the modifier. An observer change and a frame step
write a few sample intervals of the object's motion and set the modifier's inputs: no pass over the
vertices in Python (``motion.apparent_world_positions``, the rest read and its fingerprint, the
Python edge measure are counted through hooks).

The evaluated positions and velocities must still be where docs/physics.md puts them, solved here
with the test's own numpy: the object's keyframes read with ``fcurve.evaluate`` on a fine time grid
(the world matrix built from location, Euler rotation and scale, straight between grid points), the
rest shape contracted about the origin along the origin's velocity there (docs/architecture.md,
"Motion sources and the rest shape"); each point is seen as it was at ``t_o - tau`` with ``|x_o -
x(t_o - tau)| = c tau`` (bisection), the emission event relative to the observer event
Lorentz-boosted into the frame of the moving observer, and the velocity attribute the point's
4-velocity at its retarded time boosted the same way. They must also match the Python path
(``keyframed.MAX_INTERVALS`` 0 sends the object there) to float32 rounding.
"""

import numpy as np
import pytest
from test_geometry_closed_form import _grid_mesh
from test_object_type_sweep import _cube_mesh, _link

import geometry_helpers as gh

C = 4.0
FPS = 24
OBSERVER = (0.2, -0.1, -0.4)
OBSERVER_CHANGED = (-0.3, 0.25, 0.1)
FINE = 1.0 / (FPS * 64)  # the reference's time grid (seconds)
# Velocities from differences over +-SPAN seconds: fcurve.evaluate rounds to float32
SPAN = 16 * FINE


def _boost(beta):
    """The 4x4 Lorentz boost of events ``(c t, x, y, z)`` into the frame moving with ``beta``."""
    beta = np.asarray(beta, dtype=np.float64)
    b2 = beta @ beta
    gamma = 1.0 / np.sqrt(1.0 - b2)
    matrix = np.eye(4)
    matrix[0, 0] = gamma
    matrix[0, 1:] = matrix[1:, 0] = -gamma * beta
    if b2 > 0.0:
        matrix[1:, 1:] += (gamma - 1.0) * np.outer(beta, beta) / b2
    return matrix


def _keyed(obj, path, index):
    for fcurve in gh.compat.action_fcurves(obj.animation_data):
        if fcurve.data_path == path and fcurve.array_index == index:
            return fcurve
    return None


def _matrices(obj, times):
    """World matrices ``(K, 4, 4)`` at ``times`` from the object's F-curves (no parent), Euler XYZ."""
    import mathutils

    frames = np.asarray(times) * FPS
    channels = {}
    for path in ("location", "rotation_euler", "scale"):
        columns = []
        for index in range(3):
            fcurve = _keyed(obj, path, index)
            value = getattr(obj, path)[index]
            columns.append([fcurve.evaluate(f) for f in frames] if fcurve is not None else [value] * len(frames))
        channels[path] = np.array(columns).T
    result = np.empty((len(frames), 4, 4))
    for k in range(len(frames)):
        rotation = mathutils.Euler(channels["rotation_euler"][k], "XYZ").to_matrix()
        result[k] = np.array(
            mathutils.Matrix.LocRotScale(mathutils.Vector(channels["location"][k]), rotation, channels["scale"][k])
        )
    return result


def _contracted(matrices):
    """The rest shape contracted about the origin along the origin's velocity (central differences)."""
    n = round(SPAN / FINE)
    origins = matrices[:, :3, 3]
    velocity = np.empty_like(origins)
    velocity[n:-n] = (origins[2 * n :] - origins[: -2 * n]) / (2.0 * SPAN * C)
    velocity[:n], velocity[-n:] = velocity[n], velocity[-n - 1]
    result = matrices.copy()
    for k, beta in enumerate(velocity):
        b2 = beta @ beta
        assert b2 < 1.0
        if b2 > 0.0:
            n = beta / np.sqrt(b2)
            result[k, :3, :3] = (np.eye(3) - (1.0 - np.sqrt(1.0 - b2)) * np.outer(n, n)) @ matrices[k, :3, :3]
    return result


def _seen(obj, rest, t_o, x_o, beta_o):
    """World positions where the moving observer sees the rest points at ``t_o``, and their velocities
    seen (fraction of c)."""
    times = np.arange(np.floor((t_o - 4.0) / FINE), np.ceil(t_o / FINE) + 2) * FINE
    matrices = _contracted(_matrices(obj, times))

    def at(t):
        s = (t - times[0]) / FINE
        k = np.clip(np.floor(s).astype(int), 0, len(times) - 2)
        f = (s - k)[:, None, None]
        m = matrices[k] * (1.0 - f) + matrices[k + 1] * f
        return np.einsum("nij,nj->ni", m[:, :3, :3], rest) + m[:, :3, 3]

    low, high = np.zeros(len(rest)), np.full(len(rest), times[-1] - times[0] - t_o + 3.5)
    for _ in range(60):  # c tau - |x_o - x(t_o - tau)| increases with tau
        tau = (low + high) / 2.0
        ahead = C * tau > np.linalg.norm(x_o - at(t_o - tau), axis=1)
        high, low = np.where(ahead, tau, high), np.where(ahead, low, tau)
    tau = (low + high) / 2.0
    emitted = at(t_o - tau)
    velocity = (at(t_o - tau + SPAN) - at(t_o - tau - SPAN)) / (2.0 * SPAN * C)
    events = np.column_stack((-C * tau, emitted - x_o)) @ _boost(beta_o).T
    gamma = 1.0 / np.sqrt(1.0 - np.einsum("ij,ij->i", velocity, velocity))
    four = np.column_stack((gamma, gamma[:, None] * velocity)) @ _boost(beta_o).T
    return events[:, 1:] + x_o, four[:, 1:] / four[:, :1]


def _count_passes(monkeypatch):
    """Hooks on what passes over the vertices in Python."""
    motion = gh.addon_module("geometry.motion")
    modifier = gh.addon_module("geometry.modifier")
    meshes = gh.addon_module("geometry.apparent_meshes")
    tessellation = gh.addon_module("geometry.tessellation")
    hooked = (
        (motion, "apparent_world_positions"),
        (modifier, "evaluated_rest_positions"),
        (meshes, "rest_fingerprint"),
        (tessellation, "_mesh_arrays"),  # the Python edge measure reads the vertices
    )
    calls = dict.fromkeys((name for _module, name in hooked), 0)
    for module, name in hooked:
        original = getattr(module, name)

        def counted(*args, _original=original, _name=name, **kwargs):
            calls[_name] += 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(module, name, counted)
    return calls


def _keyframed_mover(bpy, scene, adaptive, levels, accelerating, proper_time=False):
    """A mesh turning on keyframes, moving along x on linear keys, or (``accelerating``) on Bezier
    keys from about 0.1c to 0.8c; its rotation keys played at its proper time or the scene's."""
    mesh = _grid_mesh(bpy, "Mover", 60, 0.6) if adaptive else _cube_mesh(bpy, "Mover", 0.3)
    obj = _link(bpy, scene, "Mover", mesh)
    obj.scale = (1.0, 1.3, 0.8)
    obj.location = (0.0, -0.4, -5.0)
    if accelerating:
        for frame, x in ((-120, -3.2), (0, -1.6), (48, 2.2)):
            obj.location.x = x
            obj.keyframe_insert("location", index=0, frame=frame)
    else:
        gh.keyframe_linear(obj, "location", 0, ((-120, -5.0), (48, 2.0)))
    gh.keyframe_linear(obj, "rotation_euler", 2, ((-120, -4.0), (48, 1.6)))
    for frame, angle in ((-120, 0.4), (0, -0.3), (48, 0.5)):
        obj.rotation_euler.x = angle
        obj.keyframe_insert("rotation_euler", index=0, frame=frame)
    obj.relativity.motion = "ANIMATION"
    obj.relativity.use_proper_time = proper_time
    obj.relativity.use_adaptive_tessellation = adaptive
    obj.relativity.tessellation = levels
    return obj


# (levels, adaptive, accelerating, proper time): none; one level on every face; the default adaptive
# tessellation on a grid whose edges' images stay far below the tolerance (the modifier's own check
# leaves it whole). With proper time the rotation keys play on the object's clock: compared with the
# Python path only (the reference here plays them at scene time).
CASES = [(0, False, False, False), (0, False, True, False), (1, False, True, False), (4, True, True, False)]
CASES += [(0, False, True, True)]


@pytest.mark.parametrize(("levels", "adaptive", "accelerating", "proper_time"), CASES)
def test_keyframed_motion_in_the_modifier(relativity_addon, monkeypatch, levels, adaptive, accelerating, proper_time):
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _keyframed_mover(bpy, scene, adaptive, levels, accelerating, proper_time)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()  # the viewport's redraw after Set Up
    calls = _count_passes(monkeypatch)

    scene.relativity.beta = OBSERVER_CHANGED  # as the panel does: the update callback runs
    changed, beta_changed = gh.evaluated_points(bpy, obj, "relativity_beta")
    scene.frame_set(13)
    stepped, beta_stepped = gh.evaluated_points(bpy, obj, "relativity_beta")
    assert calls == dict.fromkeys(calls, 0), calls

    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    assert len(rest) == (26 if levels == 1 else len(obj.data.vertices)), len(rest)
    x_o = np.array(camera.matrix_world.translation)
    if not proper_time:
        expected, velocity = _seen(obj, rest, 13 / FPS, x_o, OBSERVER_CHANGED)
        np.testing.assert_allclose(stepped, expected, atol=1e-4)
        np.testing.assert_allclose(beta_stepped, velocity, atol=1e-4)
    assert np.ptp(np.linalg.norm(beta_stepped, axis=1)) > 1e-3  # each vertex its own velocity

    # the Python path: the same motion, solved per vertex in float64
    monkeypatch.setattr(gh.addon_module("geometry.keyframed"), "MAX_INTERVALS", 0)
    scene.relativity.beta = OBSERVER  # back at frame 13
    scene.relativity.beta = OBSERVER_CHANGED
    python, beta_python = gh.evaluated_points(bpy, obj, "relativity_beta")
    assert calls["apparent_world_positions"] > 0
    np.testing.assert_allclose(stepped, python, atol=2e-5)
    np.testing.assert_allclose(beta_stepped, beta_python, atol=2e-5)
    scene.frame_set(12)
    np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], changed, atol=2e-5)


def test_retarded_time_outside_the_intervals_falls_back_and_widens(relativity_addon, monkeypatch):
    """A window too narrow for the mesh (its recorded reach made tiny, as after an edit that grew the
    mesh): the modifier finds retarded times outside its intervals and says so; the next sync puts
    the object on the Python path for that update (the mesh where the relation puts it, its reach
    measured again) and the next change is back in the modifier with a wider window."""
    import bpy

    keyframed = gh.addon_module("geometry.keyframed")
    modifier = gh.addon_module("geometry.modifier")
    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    obj = _keyframed_mover(bpy, scene, False, 0, True)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    data = modifier.cache_data(obj)
    reach = data[keyframed.REACH_KEY]
    data[keyframed.REACH_KEY] = 1e-6
    calls = _count_passes(monkeypatch)

    scene.relativity.beta = OBSERVER_CHANGED
    bpy.context.evaluated_depsgraph_get()
    bpy.context.evaluated_depsgraph_get()  # the sync after the evaluation that said so
    assert calls["apparent_world_positions"] > 0
    assert not keyframed.is_on(modifier.find_modifier(obj))
    assert data[keyframed.REACH_KEY] == pytest.approx(reach)
    assert data[keyframed.WIDEN_KEY] == 2.0
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    expected, _velocity = _seen(obj, rest, 12 / FPS, np.array(camera.matrix_world.translation), OBSERVER_CHANGED)
    np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], expected, atol=1e-4)

    scene.frame_set(13)
    assert keyframed.is_on(modifier.find_modifier(obj))
    assert keyframed.window_found(obj.evaluated_get(bpy.context.evaluated_depsgraph_get())) is True
    expected, _velocity = _seen(obj, rest, 13 / FPS, np.array(camera.matrix_world.translation), OBSERVER_CHANGED)
    np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], expected, atol=1e-4)
