"""Issue 26 (F12 on the 1,000-object scene): a constant-velocity mesh whose edges' bound clears gets
the lean node group (``node_group.LEAN_WHEN``: the closed form, the rest positions, the velocity and
the verdict, nothing else), and the full group back as soon as that changes: a velocity the bound
does not clear, Adaptive switched off (every face subdivided: the mesh still curves), the cache's
path. Positions and velocities are checked against docs/physics.md's relation solved in the test
(``test_geometry_closed_form._seen``), and Remove leaves neither group in the file."""

import numpy as np
from test_geometry_closed_form import _grid_mesh, _seen
from test_object_type_sweep import _link

import geometry_helpers as gh

C = 4.0
FPS = 24
SIDE = 100  # 1 m wide, 5 m away at 64 x 48: edges about 0.2 px
OBSERVER = (0.1, 0.0, -0.2)


def _group_name(modifier, obj):
    return modifier.find_modifier(obj).node_group.name


def _check_positions(bpy, camera, obj, velocity):
    positions, beta = gh.evaluated_points(bpy, obj, "relativity_beta")
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    matrix = np.array(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).matrix_world)
    expected, seen_velocity = _seen(rest, matrix, velocity, np.array(camera.matrix_world.translation), OBSERVER)
    np.testing.assert_allclose(positions, expected, atol=2e-5, rtol=2e-6)  # float32: up to 35 m away at 0.97c
    np.testing.assert_allclose(beta, np.broadcast_to(seen_velocity, beta.shape), atol=1e-6)
    return len(positions)


def test_lean_group_while_the_bound_clears_and_the_full_group_after(relativity_addon):
    import bpy

    names = gh.addon_module("common.names")
    modifier = gh.addon_module("geometry.modifier")
    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _link(bpy, scene, "Grid", _grid_mesh(bpy, "Grid", SIDE, 1.0))
    obj.location = (0.3, -0.2, -5.0)
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (0.5, 0.0, 0.0)
    scene.frame_set(12)
    before = gh.file_fingerprint(bpy)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()

    # the bound clears the grid: the lean group, the same positions and velocities
    assert _group_name(modifier, obj) == names.LEAN_GEOMETRY_GROUP
    assert _check_positions(bpy, camera, obj, (0.5, 0.0, 0.0)) == SIDE * SIDE
    obj.relativity.beta = (0.45, 0.1, 0.0)  # a velocity change the bound still clears
    assert _group_name(modifier, obj) == names.LEAN_GEOMETRY_GROUP
    assert _check_positions(bpy, camera, obj, (0.45, 0.1, 0.0)) == SIDE * SIDE

    # a velocity, tolerance and size the bound does not clear (at 0.97c the edges bend 0.005 px at
    # most at 64 x 48, which clears the default 0.5 px: a 0.01 px tolerance at 256 x 192 does not):
    # the full group and its edge check (left whole or not)
    obj.relativity.beta = (0.97, 0.0, 0.0)
    obj.relativity.tessellation_tolerance = 0.01
    scene.render.resolution_percentage = 400
    bpy.context.evaluated_depsgraph_get()
    mod = modifier.find_modifier(obj)
    assert mod.node_group.name == names.GEOMETRY_GROUP
    assert not gh.addon_module("common.compat").modifier_input(
        mod, modifier._input_identifiers(mod.node_group)["Edges Proven Short"]
    )
    _check_positions(bpy, camera, obj, (0.97, 0.0, 0.0))

    # back within the bound: lean again; then Adaptive off: every face at one level, the full group
    obj.relativity.beta = (0.5, 0.0, 0.0)
    obj.relativity.tessellation_tolerance = 0.5
    scene.render.resolution_percentage = 100
    bpy.context.evaluated_depsgraph_get()
    assert _group_name(modifier, obj) == names.LEAN_GEOMETRY_GROUP
    obj.relativity.use_adaptive_tessellation = False
    obj.relativity.tessellation = 1
    bpy.context.evaluated_depsgraph_get()
    # the new vertices (edge midpoints, face centres) moved by the closed form: the surface curves
    assert _check_positions(bpy, camera, obj, (0.5, 0.0, 0.0)) == (2 * SIDE - 1) ** 2
    assert _group_name(modifier, obj) == names.GEOMETRY_GROUP

    # Adaptive on again: lean; Static keeps the closed form (lean), a motion bake takes the cache's path
    obj.relativity.use_adaptive_tessellation = True
    bpy.context.evaluated_depsgraph_get()
    assert _group_name(modifier, obj) == names.LEAN_GEOMETRY_GROUP
    assert bpy.data.node_groups.get(names.GEOMETRY_GROUP) is not None  # kept for the others

    assert gh.remove_effect(scene)
    for name in (names.GEOMETRY_GROUP, names.LEAN_GEOMETRY_GROUP):
        assert bpy.data.node_groups.get(name) is None, name
    assert gh.file_fingerprint(bpy) == before


def test_many_meshes_share_the_lean_group_and_a_changed_one_leaves_it(relativity_addon):
    """Six grids: all lean; a velocity change of one beyond the bound gives that one the full group,
    the others keep the lean one and their evaluated positions exactly."""
    import bpy

    names = gh.addon_module("common.names")
    modifier = gh.addon_module("geometry.modifier")
    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    grids = []
    for k in range(6):
        obj = _link(bpy, scene, f"Grid {k}", _grid_mesh(bpy, f"Grid {k}", 30, 0.3))
        obj.location = (-0.8 + 0.32 * k, 0.1 * k, -5.0)
        obj.relativity.motion = "CONSTANT"
        obj.relativity.beta = (0.4, 0.05 * k, 0.0)
        grids.append(obj)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    assert {_group_name(modifier, obj) for obj in grids} == {names.LEAN_GEOMETRY_GROUP}
    kept = [gh.evaluated_points(bpy, obj)[0] for obj in grids[1:]]

    grids[0].relativity.beta = (0.97, 0.0, 0.0)
    # 0.97c alone: the bends' bound clears it (0.004 px); with a 0.01 px tolerance, three times the
    # size, it does not (0.04 px)
    grids[0].relativity.tessellation_tolerance = 0.01
    grids[0].scale = (3.0, 3.0, 3.0)
    bpy.context.evaluated_depsgraph_get()
    assert _group_name(modifier, grids[0]) == names.GEOMETRY_GROUP
    _check_positions(bpy, camera, grids[0], (0.97, 0.0, 0.0))
    for obj, positions in zip(grids[1:], kept, strict=True):
        assert _group_name(modifier, obj) == names.LEAN_GEOMETRY_GROUP
        np.testing.assert_array_equal(gh.evaluated_points(bpy, obj)[0], positions)
