"""Issue 26: a change on one moving mesh recomputes that mesh only. The add-on's reads of a mesh's
geometry (the evaluated rest positions, their fingerprint, the lamp stage's centre) are counted
through hooks on the functions that make them; meshes whose inputs did not change must not be
read again, and their evaluated positions must not change. The moved mesh is checked against the
retarded-position relation of docs/physics.md (observer at rest at the origin: a point of a body
moving with velocity u is seen at x_e = p - u tau, tau = ((D.u) + sqrt((D.u)^2 + (c^2 - u.u) D.D))
/ (c^2 - u.u), D = x_o - p)."""

from collections import Counter

import numpy as np
from test_object_type_sweep import _cube_mesh, _link

import geometry_helpers as gh

C = 4.0
FPS = 24


def _scene(bpy, count=3):
    scene, _camera = gh.slow_light_scene(bpy, C, FPS)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.location = (0.0, 3.0, -4.0)
    scene.collection.objects.link(lamp)
    movers = []
    for k in range(count):
        obj = _link(bpy, scene, f"Mover {k}", _cube_mesh(bpy, f"Mover {k}", 0.3))
        obj.location = (1.2 * (k - 1), 0.5, -6.0)
        obj.relativity.motion = "CONSTANT"
        obj.relativity.beta = (0.3, 0.0, 0.0)
        obj.relativity.tessellation = 0
        movers.append(obj)
    scene.frame_set(12)
    return scene, movers


def _count_reads(monkeypatch):
    """Patch the add-on's geometry reads; returns the Counter of object names they were made for."""
    reads = Counter()
    meshes = gh.geometry_module()
    modifier = gh.addon_module("geometry.modifier")
    lamps = gh.addon_module("lights.lamps_on_moving_objects")
    for module, name in (
        (meshes, "rest_fingerprint"),
        (modifier, "evaluated_rest_positions"),
        (lamps, "_local_box"),
    ):
        original = getattr(module, name)

        def counted(obj, *args, _original=original, **kwargs):
            reads[obj.original.name if obj.original is not None else obj.name] += 1
            return _original(obj, *args, **kwargs)

        monkeypatch.setattr(module, name, counted)
    return reads


def _world(bpy, obj):
    return gh.evaluated_points(bpy, obj)[0]


def test_velocity_change_on_one_mesh_reads_and_recomputes_that_mesh_only(relativity_addon, monkeypatch):
    import bpy

    scene, movers = _scene(bpy)
    gh.apply_geometry(scene)
    before = [_world(bpy, obj) for obj in movers]
    reads = _count_reads(monkeypatch)

    movers[1].relativity.beta = (-0.4, 0.0, 0.0)  # as the panel does: the update callback runs
    bpy.context.evaluated_depsgraph_get()  # the viewport's next redraw
    after = [_world(bpy, obj) for obj in movers]

    assert reads["Mover 1"] >= 1, reads
    assert reads["Mover 0"] == 0 and reads["Mover 2"] == 0, f"unchanged meshes read again: {dict(reads)}"
    np.testing.assert_array_equal(after[0], before[0])
    np.testing.assert_array_equal(after[2], before[2])
    # the changed one where the relation puts it: its points now (rest shape contracted about the
    # origin along u) seen at their retarded positions
    u = np.array([-0.4, 0.0, 0.0]) * C
    gamma = 1.0 / np.sqrt(1.0 - 0.16)
    corners = np.array([(x, y, z) for x in (-0.3, 0.3) for y in (-0.3, 0.3) for z in (-0.3, 0.3)])
    now = np.array(movers[1].location) + corners * np.array([1.0 / gamma, 1.0, 1.0])
    delta = -now
    du, uu = delta @ u, u @ u
    tau = (du + np.sqrt(du * du + (C * C - uu) * np.einsum("ij,ij->i", delta, delta))) / (C * C - uu)
    np.testing.assert_allclose(np.sort(after[1], axis=0), np.sort(now - u * tau[:, None], axis=0), atol=1e-4)


def test_edit_of_one_mesh_after_setup_recomputes_it_and_reads_no_other(relativity_addon, monkeypatch):
    import bpy

    scene, movers = _scene(bpy)
    gh.apply_geometry(scene)
    before = [_world(bpy, obj) for obj in movers]
    reads = _count_reads(monkeypatch)

    mesh = movers[2].data
    mesh.vertices[0].co.x -= 0.2  # an edit of the mesh after Set Up
    mesh.update()
    bpy.context.evaluated_depsgraph_get()
    after = [_world(bpy, obj) for obj in movers]

    assert reads["Mover 2"] >= 1, reads
    assert reads["Mover 0"] == 0 and reads["Mover 1"] == 0, f"unchanged meshes read again: {dict(reads)}"
    np.testing.assert_array_equal(after[0], before[0])
    np.testing.assert_array_equal(after[1], before[1])
    moved = np.abs(after[2] - before[2]).max(axis=1) > 1e-6
    assert moved.sum() == 1, "the edited vertex (only) is drawn elsewhere"
