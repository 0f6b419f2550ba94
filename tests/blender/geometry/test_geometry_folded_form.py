"""Issue 26: the closed form's light-travel distance in one form on every point (``Folded``), the
towards form ``(root - r.w) / (1 - w.w)``, where its rounding on receding points (amplified by at most
``1 / (1 - |w|)``) stays within ``uniform_motion.FOLD_LIMIT`` times float32's; faster, each point takes the
form that avoids cancellation. Either way the evaluated positions and velocities must be where
docs/physics.md puts them (``_seen`` of test_geometry_closed_form.py: bisection on the light cone,
the boost), on the full group (a cube, no tessellation) and on the lean group (a grid the edges'
bound leaves whole).
"""

import numpy as np
import pytest
from test_geometry_closed_form import FPS, OBSERVER, C, _grid_mesh, _seen
from test_geometry_keyframed_uniform import _inputs
from test_object_type_sweep import _cube_mesh, _link

import geometry_helpers as gh

# (velocity, folded, lean): 0.54c (1 / (1 - |w|) = 2.2) on the cube and on the grid the bound
# clears (100 x 100 points: edges about 0.2 px), 0.95c (21, above FOLD_LIMIT) on the cube
CASES = [((0.5, 0.2, 0.0), True, False), ((0.93, 0.2, 0.0), False, False), ((0.5, 0.2, 0.0), True, True)]


@pytest.mark.parametrize(("velocity", "folded", "lean"), CASES)
def test_folded_form_where_it_rounds_well(relativity_addon, velocity, folded, lean):
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    mesh = _grid_mesh(bpy, "Mover", 100, 1.0) if lean else _cube_mesh(bpy, "Mover", 0.3)
    obj = _link(bpy, scene, "Mover", mesh)
    obj.location = (0.3, -0.2, -5.0)
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = velocity
    if not lean:  # the grid: the default tessellation, which the edges' bound clears
        obj.rotation_euler = (0.3, -0.5, 0.9)
        obj.relativity.use_adaptive_tessellation = False
        obj.relativity.tessellation = 0
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    positions, beta = gh.evaluated_points(bpy, obj, "relativity_beta")

    modifier = gh.addon_module("geometry.modifier")
    assert modifier.is_lean(modifier.find_modifier(obj)) == lean
    assert _inputs(obj, ("Closed Form", "Folded")) == {"Closed Form": True, "Folded": folded}
    obj_eval = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
    assert len(rest) == len(mesh.vertices)
    x_o = np.array(camera.matrix_world.translation)
    expected, seen_velocity = _seen(rest, np.array(obj_eval.matrix_world), velocity, x_o, OBSERVER)
    np.testing.assert_allclose(positions, expected, atol=2e-5)
    np.testing.assert_allclose(beta, np.broadcast_to(seen_velocity, beta.shape), atol=1e-6)
