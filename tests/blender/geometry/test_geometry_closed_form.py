"""Issue 26: Constant Velocity (the closed form) is computed in the modifier. A velocity change and
a frame step set the modifier's inputs and run no per-vertex pass in Python: the apparent positions
(``motion.apparent_world_positions``) and the cache write (``modifier.write_cache``) are counted
through hooks. The evaluated positions must still be where docs/physics.md puts them, solved here
with the test's own numpy: a point of a body in uniform motion ``x(t) = p + u (t - t_o)`` (``p``:
the rest shape turned, scaled and contracted along ``u`` about the origin, at the object's place
at ``t_o``) is seen as it was at ``t_o - tau`` with ``|x_o - x(t_o - tau)| = c tau`` (solved by
bisection), and the emission event relative to the observer event, Lorentz-boosted into the
frame of the moving observer, is where the preview draws it; the velocity attribute is the
point's 4-velocity boosted the same way.
"""

import numpy as np
import pytest
from test_object_type_sweep import _cube_mesh, _link

import geometry_helpers as gh

C = 4.0
FPS = 24
OBSERVER = (0.2, -0.1, -0.4)


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


def _seen(rest, matrix, u, x_o, beta_o):
    """World positions (N, 3) where the moving observer at ``x_o`` sees the rest points, and the
    velocity seen (fraction of c)."""
    u = np.asarray(u, dtype=np.float64)
    gamma_u = 1.0 / np.sqrt(1.0 - u @ u)
    n = u / np.sqrt(u @ u)
    contraction = np.eye(3) - (1.0 - 1.0 / gamma_u) * np.outer(n, n)
    p = (contraction @ matrix[:3, :3] @ rest.T).T + matrix[:3, 3]
    low, high = np.zeros(len(p)), np.full(len(p), 100.0)
    for _ in range(80):  # c tau - |x_o - x(t_o - tau)| increases with tau
        tau = (low + high) / 2.0
        ahead = C * tau > np.linalg.norm(x_o - (p - np.outer(tau, u * C)), axis=1)
        high, low = np.where(ahead, tau, high), np.where(ahead, low, tau)
    tau = (low + high) / 2.0
    events = np.column_stack((-C * tau, p - np.outer(tau, u * C) - x_o))
    boosted = events @ _boost(beta_o).T
    velocity = _boost(beta_o) @ (gamma_u * np.array([1.0, *u]))
    return boosted[:, 1:] + x_o, velocity[1:] / velocity[0]


def _count_passes(monkeypatch):
    motion = gh.addon_module("geometry.motion")
    modifier = gh.addon_module("geometry.modifier")
    return gh.count_calls(monkeypatch, ((motion, "apparent_world_positions"), (modifier, "write_cache")))


def _grid_mesh(bpy, name, side, width):
    """A flat ``side`` x ``side`` vertex grid of quads, ``width`` wide: edges far shorter than a pixel."""
    u = np.linspace(-width / 2.0, width / 2.0, side)
    vertices = [(x, y, 0.0) for y in u for x in u]
    faces = [
        (i + side * j, i + 1 + side * j, i + 1 + side * (j + 1), i + side * (j + 1))
        for j in range(side - 1)
        for i in range(side - 1)
    ]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    return mesh


# (levels, adaptive): none; one level on every face; the default adaptive tessellation on a grid whose
# edges' images stay far below the tolerance (the modifier's own check leaves it whole)
CASES = [(0, False), (1, False), (4, True)]


@pytest.mark.parametrize(("levels", "adaptive"), CASES)
def test_velocity_change_and_frame_step_run_no_per_vertex_python(relativity_addon, monkeypatch, levels, adaptive):
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    mesh = _grid_mesh(bpy, "Mover", 40, 0.6) if adaptive else _cube_mesh(bpy, "Mover", 0.3)
    obj = _link(bpy, scene, "Mover", mesh)
    obj.location = (0.8, -0.4, -5.0)
    obj.rotation_euler = (0.3, -0.5, 0.9)
    obj.scale = (1.0, 1.6, 0.7)
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (0.5, 0.2, 0.0)
    obj.relativity.use_adaptive_tessellation = adaptive
    obj.relativity.tessellation = levels
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()  # the viewport's redraw after Set Up
    calls = _count_passes(monkeypatch)

    obj.relativity.beta = (-0.3, 0.4, 0.1)  # as the panel does: the update callback runs
    changed, beta_changed = gh.evaluated_points(bpy, obj, "relativity_beta")
    scene.frame_set(13)
    stepped, beta_stepped = gh.evaluated_points(bpy, obj, "relativity_beta")
    assert calls == {"apparent_world_positions": 0, "write_cache": 0}, calls

    obj_eval = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    assert len(rest) == len(mesh.vertices) if levels != 1 else 26, len(rest)
    x_o = np.array(camera.matrix_world.translation)
    expected, velocity = _seen(rest, np.array(obj_eval.matrix_world), (-0.3, 0.4, 0.1), x_o, OBSERVER)
    for positions, beta in ((changed, beta_changed), (stepped, beta_stepped)):
        np.testing.assert_allclose(positions, expected, atol=2e-5)
        np.testing.assert_allclose(beta, np.broadcast_to(velocity, beta.shape), atol=1e-6)


def test_group_of_an_older_version_is_rebuilt_keeping_the_cache(relativity_addon):
    """A file set up by an older version holds an older node group: rebuilt, the modifier keeps its
    cache (where the bakes live) and the mesh moves as before (the rebuilt sockets have new
    identifiers)."""
    import bpy

    names = gh.addon_module("common.names")
    modifier = gh.addon_module("geometry.modifier")
    scene, _camera = gh.slow_light_scene(bpy, C, FPS)
    obj = _link(bpy, scene, "Mover", _cube_mesh(bpy, "Mover", 0.3))
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (0.5, 0.2, 0.0)
    gh.apply_geometry(scene)
    before = gh.evaluated_points(bpy, obj)[0]
    cache = modifier.cache_object(obj)
    bpy.data.node_groups[names.GEOMETRY_GROUP][names.GEOMETRY_GROUP_VERSION_KEY] = names.GEOMETRY_GROUP_VERSION - 1

    modifier.ensure_node_group()
    bpy.context.evaluated_depsgraph_get()
    assert modifier.cache_object(obj) == cache
    obj.relativity.beta = (0.5, 0.2, 0.0)  # a sync: the update sets the closed form's inputs again
    np.testing.assert_allclose(gh.evaluated_points(bpy, obj)[0], before, atol=1e-6)
    assert sum(modifier.is_cache(each) for each in bpy.data.objects) == 1


OBSERVER_CHANGED = (-0.3, 0.25, 0.1)


@pytest.mark.parametrize(("levels", "adaptive"), CASES)
def test_observer_velocity_change_turns_every_closed_form_mesh(relativity_addon, monkeypatch, levels, adaptive):
    """The observer's velocity changed in the panel over a moving and a Static mesh: no full update
    (their records turned: ``straight_steps``, the boost's inputs set for all at once), each drawn
    where docs/physics.md puts it for the new observer; an object's velocity changed by a script
    without its callback (``id_data`` untouched: no note) is not turned but updated in full."""
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    movers = []
    for name, motion, place in (("Mover", "CONSTANT", (0.8, -0.4, -5.0)), ("Still", "STATIC", (-0.9, 0.3, -4.0))):
        mesh = _grid_mesh(bpy, name, 40, 0.6) if adaptive else _cube_mesh(bpy, name, 0.3)
        obj = _link(bpy, scene, name, mesh)
        obj.location = place
        obj.rotation_euler = (0.3, -0.5, 0.9)
        obj.relativity.motion = motion
        obj.relativity.use_adaptive_tessellation = adaptive
        obj.relativity.tessellation = levels
        movers.append(obj)
    movers[0].relativity.beta = (0.5, 0.2, 0.0)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    meshes = gh.addon_module("geometry.apparent_meshes")
    calls = gh.count_calls(monkeypatch, ((meshes, "update_object"),))

    scene.relativity.beta = OBSERVER_CHANGED  # as the panel does: the update callback runs
    x_o = np.array(camera.matrix_world.translation)
    for obj, u in zip(movers, ((0.5, 0.2, 0.0), (0.0, 0.0, 0.0)), strict=True):
        positions, beta = gh.evaluated_points(bpy, obj, "relativity_beta")
        matrix = np.array(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).matrix_world)
        rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
        expected, velocity = _seen(rest, matrix, u, x_o, OBSERVER_CHANGED) if any(u) else (None, None)
        if expected is None:  # at rest: the boosted emission of the point itself (tau = |x_o - p| / c)
            p = (matrix[:3, :3] @ rest.T).T + matrix[:3, 3]
            events = np.column_stack((-np.linalg.norm(x_o - p, axis=1), p - x_o)) @ _boost(OBSERVER_CHANGED).T
            expected, velocity = events[:, 1:] + x_o, -np.asarray(OBSERVER_CHANGED)
        np.testing.assert_allclose(positions, expected, atol=2e-5)
        np.testing.assert_allclose(beta, np.broadcast_to(velocity, beta.shape), atol=1e-6)
    assert calls == {"update_object": 0}, calls

    movers[0].relativity["beta"] = (0.1, 0.0, 0.0)  # no callback, no note
    scene.relativity.beta = OBSERVER
    bpy.context.evaluated_depsgraph_get()
    assert calls["update_object"] >= 1, calls
    positions = gh.evaluated_points(bpy, movers[0])[0]
    rest = gh.evaluated_attribute(bpy, movers[0], "relativity_rest")
    matrix = np.array(movers[0].evaluated_get(bpy.context.evaluated_depsgraph_get()).matrix_world)
    np.testing.assert_allclose(positions, _seen(rest, matrix, (0.1, 0.0, 0.0), x_o, OBSERVER)[0], atol=2e-5)
