"""Removing the apparent geometry gives back the scene exactly; undo/redo of apply and remove.

Undo in the bpy wheel: ``bpy.ops.ed.undo_push``/``undo``/``redo`` work headless (global memfile
undo); Python references to IDs are invalid after an undo step, so objects are looked up again.
"""

import hashlib

import numpy as np

import geometry_helpers as gh
from geometry_helpers import ch


def _mesh_arrays(mesh):
    arrays = {}
    for name, collection, attribute, width in (
        ("co", mesh.vertices, "co", 3),
        ("edges", mesh.edges, "vertices", 2),
        ("loops", mesh.loops, "vertex_index", 1),
        ("poly_start", mesh.polygons, "loop_start", 1),
    ):
        dtype = np.float32 if name == "co" else np.int32
        values = np.empty(len(collection) * width, dtype=dtype)
        collection.foreach_get(attribute, values)
        arrays[name] = values
    return arrays


def _state_hash(bpy, obj):
    """Hash of what the effect may touch: the mesh arrays and attribute names, the modifier
    stack, and the names of every object, mesh and node group in the file."""
    digest = hashlib.sha256()
    for name, values in sorted(_mesh_arrays(obj.data).items()):
        digest.update(name.encode())
        digest.update(values.tobytes())
    digest.update(repr(sorted(a.name for a in obj.data.attributes)).encode())
    digest.update(repr([(m.name, m.type, m.show_viewport) for m in obj.modifiers]).encode())
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.node_groups):
        digest.update(repr(sorted(item.name for item in collection)).encode())
    return digest.hexdigest()


def _scene_with_mesh(bpy):
    scene, _ = ch.new_scene(bpy, resolution=(64, 48), samples=1)
    scene.relativity.speed_of_light = 3.0
    obj = ch.add_sphere(bpy, scene, (0.0, 0.0, -5.0), 1.0, ch.emission_material(bpy), name="Ball", segments=16, rings=8)
    obj.modifiers.new("Bevel", "BEVEL")
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (0.8, 0.0, 0.0)
    return scene, obj


def test_remove_restores_mesh_and_stack_exactly(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, obj = _scene_with_mesh(bpy)
    before_arrays = _mesh_arrays(obj.data)
    before_hash = _state_hash(bpy, obj)
    rest_world, _ = gh.evaluated_points(bpy, obj)

    gh.apply_geometry(scene)
    assert [m.name for m in obj.modifiers][0] == "Bevel"
    deformed, beta = gh.evaluated_points(bpy, obj, "relativity_beta")
    assert len(deformed) > len(rest_world)  # tessellated
    assert np.allclose(beta, [0.8, 0.0, 0.0], atol=1e-6)
    assert _state_hash(bpy, obj) != before_hash
    for name, values in _mesh_arrays(obj.data).items():  # the original mesh is never written
        assert np.array_equal(values, before_arrays[name])

    assert gh.remove_effect(scene) == 1
    assert _state_hash(bpy, obj) == before_hash
    after_world, _ = gh.evaluated_points(bpy, obj)
    assert np.array_equal(after_world, rest_world)
    assert gh.remove_effect(scene) == 0


def test_undo_redo_of_apply_and_remove(relativity_addon, factory_blender):
    bpy = factory_blender
    scene, obj = _scene_with_mesh(bpy)
    bpy.ops.ed.undo_push(message="scene built")
    before_hash = _state_hash(bpy, obj)
    gh.apply_geometry(scene)
    bpy.ops.ed.undo_push(message="apply")
    applied_hash = _state_hash(bpy, obj)
    applied_points, _ = gh.evaluated_points(bpy, obj)
    gh.remove_effect(scene)
    bpy.ops.ed.undo_push(message="remove")
    assert _state_hash(bpy, bpy.data.objects["Ball"]) == before_hash

    bpy.ops.ed.undo()  # back to "apply"
    obj = bpy.data.objects["Ball"]
    assert _state_hash(bpy, obj) == applied_hash
    points, _ = gh.evaluated_points(bpy, obj)
    assert np.allclose(points, applied_points, atol=1e-6)
    bpy.ops.ed.undo()  # back to "scene built"
    assert _state_hash(bpy, bpy.data.objects["Ball"]) == before_hash
    bpy.ops.ed.redo()
    obj = bpy.data.objects["Ball"]
    assert _state_hash(bpy, obj) == applied_hash
    points, _ = gh.evaluated_points(bpy, obj)
    assert np.allclose(points, applied_points, atol=1e-6)
    bpy.ops.ed.redo()
    assert _state_hash(bpy, bpy.data.objects["Ball"]) == before_hash
