"""Issue 26: a velocity change at constant velocity builds no node group's description again. The
modifier's group and the materials' colour groups are in the file and current; describing them
anew (``node_group.node_group_spec``, the materials' ``GROUP_BUILDERS``: a few hundred node specs
in Python) at every update callback and update was part of the change's fixed cost. Counted
through hooks; the mesh must still be where docs/physics.md puts it (``test_geometry_closed_form``'s
own solution)."""

import numpy as np
from test_geometry_closed_form import FPS, OBSERVER, C, _grid_mesh, _seen
from test_object_type_sweep import _link

import geometry_helpers as gh


def _count_group_descriptions(monkeypatch):
    modifier = gh.addon_module("geometry.modifier")
    materials = gh.addon_module("colour.materials")
    calls = {"geometry group": 0, "colour groups": 0}
    original = modifier.node_group_spec

    def geometry_spec():
        calls["geometry group"] += 1
        return original()

    def counted(builder):
        def build(*args, **kwargs):
            calls["colour groups"] += 1
            return builder(*args, **kwargs)

        return build

    monkeypatch.setattr(modifier, "node_group_spec", geometry_spec)
    monkeypatch.setattr(materials, "GROUP_BUILDERS", tuple(counted(builder) for builder in materials.GROUP_BUILDERS))
    return calls


def test_velocity_change_describes_no_node_group_again(relativity_addon, monkeypatch):
    import bpy

    scene, camera = gh.slow_light_scene(bpy, C, FPS)
    scene.relativity.beta = OBSERVER
    obj = _link(bpy, scene, "Mover", _grid_mesh(bpy, "Mover", 40, 0.6))
    obj.location = (0.8, -0.4, -5.0)
    obj.rotation_euler = (0.3, -0.5, 0.9)
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (0.5, 0.2, 0.0)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    calls = _count_group_descriptions(monkeypatch)

    for beta in ((-0.3, 0.4, 0.1), (0.6, 0.0, -0.2)):
        obj.relativity.beta = beta  # the panel's way: the update callback runs, then the depsgraph
        positions, velocities = gh.evaluated_points(bpy, obj, "relativity_beta")
        rest = gh.evaluated_attribute(bpy, obj, "relativity_rest")
        obj_eval = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        x_o = np.array(camera.matrix_world.translation)
        expected, velocity = _seen(rest, np.array(obj_eval.matrix_world), beta, x_o, OBSERVER)
        np.testing.assert_allclose(positions, expected, atol=2e-5)
        np.testing.assert_allclose(velocities, np.broadcast_to(velocity, velocities.shape), atol=1e-6)
    assert calls == {"geometry group": 0, "colour groups": 0}, calls
