"""Issue 26: a velocity change on a fine closed-form grid whose edge images (or bends) the bound
(physics/edge_bounds.edge_image_bound) shows short visits no edge: the add-on sets the modifier's
``Edges Proven Short`` and runs no measure and no read of the mesh, and the modifier leaves the
mesh whole without its per-edge check (shown by a tolerance the check would fail: the verdict
stays, and turns when the bound's input is off). An edit of the mesh is followed (the bound's rest
box and longest edge are read again), and a coarse box near the camera is not cleared (the check
and the measure subdivide it; test_adaptive_tessellation.py renders its outline)."""

from contextlib import contextmanager

import numpy as np
from test_geometry_closed_form import _grid_mesh
from test_object_type_sweep import _link

import geometry_helpers as gh
from relativity_addon.blender.common import compat

C = 4.0
FPS = 24
SIDE = 100  # 1 m wide, 5 m away at 64 x 48: edges about 0.2 px


def _verdict(bpy, obj):
    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    attribute = mesh.attributes.get("relativity_edges_short")
    return None if attribute is None else bool(attribute.data[0].value), len(mesh.vertices)


def _input(mod, name):
    identifier = gh.addon_module("common.nodes").interface_identifier(mod.node_group, name)
    return mod, identifier


@contextmanager
def _without_addon_handlers(bpy):
    taken = []
    for name in dir(bpy.app.handlers):
        handlers = getattr(bpy.app.handlers, name)
        if isinstance(handlers, list):
            for handler in list(handlers):
                if getattr(handler, "__module__", "").endswith("pipeline.handlers"):
                    handlers.remove(handler)
                    taken.append((handlers, handler))
    try:
        yield
    finally:
        for handlers, handler in taken:
            handlers.append(handler)


def _counted(monkeypatch, module, name, calls):
    original = getattr(module, name)

    def counted(*args, **kwargs):
        calls[name] = calls.get(name, 0) + 1
        return original(*args, **kwargs)

    monkeypatch.setattr(module, name, counted)


def _fine_grid(bpy):
    scene, _camera = gh.slow_light_scene(bpy, C, FPS)
    obj = _link(bpy, scene, "Grid", _grid_mesh(bpy, "Grid", SIDE, 1.0))
    obj.location = (0.3, -0.2, -5.0)
    obj.relativity.motion = "CONSTANT"
    obj.relativity.beta = (0.5, 0.0, 0.0)
    scene.frame_set(12)
    return scene, obj


def _keyed_grid(bpy, last):
    """The fine grid moved by two linear location keys at 0.6c (frames -40 and ``last``), its panel
    velocity zero."""
    scene, obj = _fine_grid(bpy)
    obj.relativity.beta = (0.0, 0.0, 0.0)
    obj.relativity.motion = "ANIMATION"
    step = 0.6 * C / FPS  # metres per frame at 0.6c
    for frame in (-40, last):
        obj.location.x = 0.3 + (frame - 12) * step
        obj.keyframe_insert("location", frame=frame)
    for fcurve in compat.action_fcurves(obj.animation_data):
        for point in fcurve.keyframe_points:
            point.interpolation = "LINEAR"
    return scene, obj


def test_velocity_change_on_a_fine_grid_visits_no_edge(relativity_addon, monkeypatch):
    import bpy

    tessellation = gh.addon_module("geometry.tessellation")
    modifier = gh.addon_module("geometry.modifier")
    scene, obj = _fine_grid(bpy)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    calls = {}
    edge_bounds = gh.addon_module("geometry.edge_bounds")
    for module, name in ((tessellation, "decide"), (tessellation, "_mesh_arrays"), (edge_bounds, "_read_rest_bounds")):
        _counted(monkeypatch, module, name, calls)

    for beta in ((0.52, 0.1, 0.0), (0.48, 0.0, 0.1), (0.5, 0.1, 0.0)):  # as the panel does, one after another
        obj.relativity.beta = beta
        verdict, vertices = _verdict(bpy, obj)
    mod = modifier.find_modifier(obj)
    assert compat.modifier_input(*_input(mod, "Edges Proven Short"))
    assert verdict is True and vertices == SIDE * SIDE
    assert calls == {}, calls  # no measure, no read of the mesh

    # the bound clears the grid: the modifier has the lean group (no edge check in it)
    assert modifier.is_lean(mod)
    # the per-edge check is not run: a tolerance it would fail leaves the verdict as it is ...
    with _without_addon_handlers(bpy):  # the add-on's syncs would set its own inputs again
        assert modifier.set_inputs(mod, {"Tolerance": 1e-6}) and modifier.is_lean(mod)
        obj.update_tag()
        assert _verdict(bpy, obj)[0] is True
        # ... in the full group too, given the same inputs (the lean group kept them) ...
        modifier._give_group(mod, modifier.ensure_node_group())
        obj.update_tag()
        assert _verdict(bpy, obj)[0] is True
        # ... and fails it once the bound's input is off (the check runs again)
        compat.set_modifier_input(*_input(mod, "Edges Proven Short"), False)
        obj.update_tag()
        assert _verdict(bpy, obj)[0] is False
        assert compat.modifier_input(*_input(mod, "Tolerance")) < 1e-5


def test_an_edit_of_the_mesh_is_read_again(relativity_addon, monkeypatch):
    """The rest box and longest edge are kept while only the add-on evaluates the object; after an
    edit (a vertex pulled far out: the grid's longest edge now long on screen) they are read again,
    the bound no longer clears the grid and the modifier's check decides."""
    import bpy

    modifier = gh.addon_module("geometry.modifier")
    scene, obj = _fine_grid(bpy)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    calls = {}
    _counted(monkeypatch, gh.addon_module("geometry.edge_bounds"), "_read_rest_bounds", calls)
    for beta in ((0.51, 0.0, 0.0), (0.49, 0.0, 0.0)):
        obj.relativity.beta = beta
        bpy.context.evaluated_depsgraph_get()
    assert calls == {}, calls

    obj.data.vertices[SIDE + 1].co.z += 1.5
    obj.data.update()
    bpy.context.evaluated_depsgraph_get()
    obj.relativity.beta = (0.5, 0.0, 0.0)
    bpy.context.evaluated_depsgraph_get()
    assert calls.get("_read_rest_bounds", 0) >= 1, calls
    assert not compat.modifier_input(*_input(modifier.find_modifier(obj), "Edges Proven Short"))


def test_coarse_box_near_the_camera_is_not_cleared(relativity_addon):
    """The 12-face box 2 m from the camera at 0.9c (test_adaptive_tessellation.py): the bound does
    not clear it, and it is subdivided."""
    import bpy
    from test_adaptive_tessellation import _box_scene

    modifier = gh.addon_module("geometry.modifier")
    scene, _camera, box, _origin = _box_scene(bpy)
    gh.apply_geometry(scene)
    box.relativity.beta = tuple(box.relativity.beta)  # a velocity change
    _, vertices = _verdict(bpy, box)
    assert not compat.modifier_input(*_input(modifier.find_modifier(box), "Edges Proven Short"))
    assert vertices > 8


def test_keyframed_motion_is_bounded_with_its_keys_velocity(relativity_addon, monkeypatch):
    """The bound knows uniform motion only: the same fine grid moved by its keyframes at 0.6c is
    bounded with the keys' velocity, not the panel's (zero: with it, the bound cleared its edges
    stretched and bent by the motion unseen), and cleared by it."""
    import bpy

    modifier = gh.addon_module("geometry.modifier")
    edge_bounds = gh.addon_module("geometry.edge_bounds")
    scene, obj = _keyed_grid(bpy, 40)
    velocities = []
    original = edge_bounds.edge_image_bound

    def recorded(obj, matrix, snap, size, tolerance, velocity=None, *rest):
        velocities.append(velocity)
        return original(obj, matrix, snap, size, tolerance, velocity, *rest)

    monkeypatch.setattr(edge_bounds, "edge_image_bound", recorded)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    verdict, vertices = _verdict(bpy, obj)
    mod = modifier.find_modifier(obj)
    assert compat.modifier_input(*_input(mod, "Measure Edges")), "the modifier checks the edges"
    keyed = [v for v in velocities if v is not None and abs(float(v[0]) - 0.6) < 1e-3 and abs(float(v[1])) < 1e-6]
    assert keyed, velocities
    assert compat.modifier_input(*_input(mod, "Edges Proven Short"))
    assert verdict is True and vertices == SIDE * SIDE


def test_fine_grid_at_a_large_render_size_is_cleared_by_its_bends(relativity_addon, monkeypatch):
    """The fine grid rendered 1920 x 1440: its edges' images are about 5 px long, so neither the
    length bound nor the modifier's length check clears them (before the bend bound each velocity
    change ran the Python measure over every edge: issue 26's 216x at 320 x 240), while they bend by
    thousandths of a pixel: velocity changes run no measure, read no mesh, and leave it whole."""
    import bpy

    tessellation = gh.addon_module("geometry.tessellation")
    modifier = gh.addon_module("geometry.modifier")
    scene, obj = _fine_grid(bpy)
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 1920, 1440, 100
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    calls = {}
    edge_bounds = gh.addon_module("geometry.edge_bounds")
    for module, name in ((tessellation, "decide"), (tessellation, "_mesh_arrays"), (edge_bounds, "_read_rest_bounds")):
        _counted(monkeypatch, module, name, calls)
    for beta in ((0.52, 0.1, 0.0), (0.48, 0.0, 0.1), (0.5, 0.1, 0.0)):
        obj.relativity.beta = beta
        verdict, vertices = _verdict(bpy, obj)
    mod = modifier.find_modifier(obj)
    assert compat.modifier_input(*_input(mod, "Edges Proven Short"))
    assert verdict is True and vertices == SIDE * SIDE
    assert calls == {}, calls
    # the length check alone fails at this size: the bend bound is what cleared it
    with _without_addon_handlers(bpy):
        modifier._give_group(mod, modifier.ensure_node_group())
        compat.set_modifier_input(*_input(mod, "Edges Proven Short"), False)
        obj.update_tag()
        assert _verdict(bpy, obj)[0] is False


def test_straight_keys_frame_steps_reuse_the_swept_bound(relativity_addon, monkeypatch):
    """On straight keys the bound is taken over the origin's way through the next frames
    (``edge_bounds.SWEEP_FRAMES``): stepping through them computes no bound and the verdict holds;
    a step past them computes one again."""
    import bpy

    modifier = gh.addon_module("geometry.modifier")
    tessellation = gh.addon_module("geometry.tessellation")
    edge_bounds = gh.addon_module("geometry.edge_bounds")
    scene, obj = _keyed_grid(bpy, 80)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    calls = {}
    _counted(monkeypatch, tessellation.tessellation, "edge_image_bound", calls)
    mod = modifier.find_modifier(obj)
    for frame in range(13, 12 + edge_bounds.SWEEP_FRAMES):
        scene.frame_set(frame)
        verdict, vertices = _verdict(bpy, obj)
        assert compat.modifier_input(*_input(mod, "Edges Proven Short")), frame
        assert verdict is True and vertices == SIDE * SIDE
    assert calls == {}, calls
    scene.frame_set(12 + 3 * edge_bounds.SWEEP_FRAMES)
    bpy.context.evaluated_depsgraph_get()
    assert calls.get("edge_image_bound", 0) >= 1
    assert compat.modifier_input(*_input(mod, "Edges Proven Short"))


def test_straight_keys_keep_half_the_sweep_where_the_whole_does_not_clear(relativity_addon, monkeypatch):
    """Where the bound over the origin's whole way to come (``SWEEP_FRAMES``) does not clear the
    tolerance (made so here: the bound over it is refused), the bound over the way's first half is
    kept: frame steps through that half compute no bound and the verdict holds; a full update past it
    bounds the half way again, and does not try the whole way again for the same inputs."""
    import bpy

    modifier = gh.addon_module("geometry.modifier")
    tessellation = gh.addon_module("geometry.tessellation")
    edge_bounds = gh.addon_module("geometry.edge_bounds")
    scene, obj = _keyed_grid(bpy, 200)
    per_frame = 0.6 * C / FPS
    whole = edge_bounds.SWEEP_FRAMES * per_frame  # (the grid is far larger than a frame's way)
    tried = {"whole": 0, "half": 0}
    bound = edge_bounds._bound

    def refusing(arguments, tolerance, acceleration, sweep):
        if sweep is not None:
            length = float(np.linalg.norm(sweep))
            if abs(length - whole) < 1e-6 * whole:
                tried["whole"] += 1
                return float("inf")
            assert abs(length - whole / 2) < 1e-6 * whole, (length, whole)
            tried["half"] += 1
        return bound(arguments, tolerance, acceleration, sweep)

    monkeypatch.setattr(edge_bounds, "_bound", refusing)
    scene.frame_set(12)
    gh.apply_geometry(scene)
    bpy.context.evaluated_depsgraph_get()
    assert tried["whole"] >= 1 and tried["half"] >= 1, tried
    start, sweep = edge_bounds.swept_bound(obj)
    np.testing.assert_allclose(np.linalg.norm(sweep), whole / 2, rtol=1e-6)
    after_setup = dict(tried)
    calls = {}
    _counted(monkeypatch, tessellation.tessellation, "edge_image_bound", calls)
    mod = modifier.find_modifier(obj)
    for frame in range(13, 12 + edge_bounds.SWEEP_FRAMES // 2):
        scene.frame_set(frame)
        verdict, vertices = _verdict(bpy, obj)
        assert compat.modifier_input(*_input(mod, "Edges Proven Short")), frame
        assert verdict is True and vertices == SIDE * SIDE
    assert calls == {} and tried == after_setup, (calls, tried)
    scene.frame_set(12 + edge_bounds.SWEEP_FRAMES)
    bpy.context.evaluated_depsgraph_get()
    assert tried["half"] > after_setup["half"] and tried["whole"] == after_setup["whole"], tried
    assert compat.modifier_input(*_input(mod, "Edges Proven Short"))
