"""Issue 26: Python's cyclic garbage collector does not run inside the add-on's syncs (the callback's
of a velocity change, the handlers' of a frame step), and is as it was after them (``common/collector.py``).
With the collector's threshold at one allocation, a sync without the pause would start hundreds."""

import gc

import pytest
from test_geometry_many_objects import _scene

import geometry_helpers as gh


@pytest.fixture
def eager_collector():
    """Every container allocation starts a collection of the youngest generation; each is counted."""
    started = []

    def count(phase, _info):
        if phase == "start":
            started.append(1)

    threshold = gc.get_threshold()
    gc.set_threshold(1, 10, 10)
    gc.callbacks.append(count)
    try:
        yield started
    finally:
        gc.callbacks.remove(count)
        gc.set_threshold(*threshold)
        gc.enable()


def test_no_collection_inside_syncs(relativity_addon, eager_collector):
    import bpy

    scene, movers = _scene(bpy, 0)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    meshes, snapshot = gh.addon_module("geometry.apparent_meshes"), gh.addon_module("scene.snapshot")
    inside = []  # collections started inside the syncs' parts (their hooks' own calls allocate outside)

    def counted(original):
        def part(*args, **kwargs):
            before = len(eager_collector)
            result = original(*args, **kwargs)
            inside.append(len(eager_collector) - before)
            return result

        return part

    hooked = ((meshes, "update"), (snapshot, "read"))
    originals = [getattr(module, name) for module, name in hooked]
    for (module, name), original in zip(hooked, originals, strict=True):
        setattr(module, name, counted(original))
    try:
        eager_collector.clear()
        scene.relativity.beta = (0.0, 0.1, 0.0)  # the callback's sync (every mesh moves)
        movers[1].relativity.beta = (0.3, 0.0, 0.0)
        assert gc.isenabled()
        bpy.context.evaluated_depsgraph_get()  # the handler's
        scene.frame_set(scene.frame_current + 1)  # the frame change's two
        assert gc.isenabled()
        assert len(eager_collector) > 0, "the test's collector starts none: it cannot fail"
        assert len(inside) >= 4 and sum(inside) == 0, inside
        gc.disable()  # a caller that paused the collector itself: it stays paused
        scene.relativity.beta = (0.0, 0.2, 0.0)
        assert not gc.isenabled()
    finally:
        for (module, name), original in zip(hooked, originals, strict=True):
            setattr(module, name, original)
