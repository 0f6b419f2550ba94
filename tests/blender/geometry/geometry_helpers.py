"""Helpers for the apparent-geometry tests: the camera tests' scene builders and pixel measures,
plus evaluated-mesh readers. Expected values come from docs/physics.md written out in the tests."""

import importlib
import sys
from pathlib import Path

import numpy as np

from relativity_addon.blender.common import compat

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "camera"))
import camera_helpers as ch  # noqa: E402
from blender_support import ADDON_MODULE  # noqa: E402


def geometry_module():
    return importlib.import_module(f"{ADDON_MODULE}.blender.geometry.apparent_meshes")


def addon_module(name):
    return importlib.import_module(f"{ADDON_MODULE}.blender.{name}")


def count_calls(monkeypatch, hooked, counts=lambda _name, _result: 1):
    """Hooks on ``hooked`` ((module, name) pairs) that add ``counts(name, result)`` per call to the
    returned {name: count}."""
    calls = dict.fromkeys((name for _module, name in hooked), 0)
    for module, name in hooked:
        original = getattr(module, name)

        def counted(*args, _original=original, _name=name, **kwargs):
            result = _original(*args, **kwargs)
            calls[_name] += counts(_name, result)
            return result

        monkeypatch.setattr(module, name, counted)
    return calls


def apply_geometry(scene, objects=None):
    """Set the scene up for Apparent Geometry as the Set Up button does (``effect.apply``)."""
    scene.relativity.method = "GEOMETRY"
    return addon_module("pipeline.effect").apply(scene, objects=objects)


def remove_effect(scene):
    """What the Remove button does; returns the number of things removed."""
    return addon_module("pipeline.effect").remove(scene)


def evaluated_points(bpy, obj, attribute=None):
    """World positions of the evaluated mesh (depsgraph), and optionally a vector attribute."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        co = np.empty(len(mesh.vertices) * 3)
        mesh.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3)
        matrix = np.array(obj_eval.matrix_world)
        world = co @ matrix[:3, :3].T + matrix[:3, 3]
        values = None
        if attribute is not None:
            data = mesh.attributes[attribute].data
            values = np.empty(len(data) * 3)
            data.foreach_get("vector", values)
            values = values.reshape(-1, 3)
    finally:
        obj_eval.to_mesh_clear()
    return world, values


tangent_plane_axis_ratio = ch.tangent_plane_axis_ratio  # the camera tests' measure


def retarded_residuals(x_a, x_e, x_o):
    """For apparent positions ``x_a`` seen from ``(t_o, x_o)`` and the true positions ``x_e`` at
    each point's retarded time ``t_e = t_o - |x_o - x_a| / c`` (so ``c (t_o - t_e) = |x_o - x_a|``):
    the light-cone residual ``||x_o - x_e| - c (t_o - t_e)| / (c (t_o - t_e))`` and the position
    mismatch ``|x_a - x_e| / (c (t_o - t_e))`` per point."""
    light_path = np.linalg.norm(x_a - x_o, axis=1)
    residual = np.abs(np.linalg.norm(x_o - x_e, axis=1) - light_path) / light_path
    mismatch = np.linalg.norm(x_a - x_e, axis=1) / light_path
    return residual, mismatch


def contract(relative, beta):
    """Lorentz contraction (docs/architecture.md, "Motion sources and the rest shape"): offsets
    ``relative`` (``(N, 3)``) from the origin of a body moving with ``beta`` (``(3,)`` or
    ``(N, 3)``) keep 1/gamma of their component along beta."""
    beta = np.broadcast_to(np.asarray(beta, float), np.shape(relative))
    speed = np.linalg.norm(beta, axis=-1, keepdims=True)
    bhat = np.divide(beta, speed, out=np.zeros_like(beta), where=speed > 0)
    along = np.sum(relative * bhat, axis=-1, keepdims=True)
    return relative - (1.0 - np.sqrt(1.0 - speed**2)) * along * bhat


def _frame_set_time(scene, t, fps):
    frame = t * fps
    whole = int(np.floor(frame))
    scene.frame_set(whole, subframe=float(frame - whole))


def world_lines_by_frame_set(bpy, scene, obj, local_points, times, fps, c=None, velocity_step=0.01):
    """Blender's own evaluation of ``obj`` (constraints, drivers, parents) at each time (seconds):
    ``scene.frame_set`` at the (sub-)frame, ``matrix_world`` applied to the matching local point.
    With ``c`` the local points are the rest shape (the add-on's convention): the offset from the
    origin is contracted along the origin's velocity, the central difference of ``matrix_world``'s
    translation over ``+-velocity_step`` seconds, divided by ``c``. Restores the scene's frame."""
    saved = scene.frame_current, scene.frame_subframe
    points = np.empty((len(times), 3))
    for i, t in enumerate(times):
        beta = np.zeros(3)
        if c is not None:
            _frame_set_time(scene, t + velocity_step, fps)
            ahead = np.array(obj.matrix_world.translation)
            _frame_set_time(scene, t - velocity_step, fps)
            beta = (ahead - np.array(obj.matrix_world.translation)) / (2.0 * velocity_step * c)
        _frame_set_time(scene, t, fps)
        matrix = np.array(obj.matrix_world)
        points[i] = contract((matrix[:3, :3] @ local_points[i])[None], beta)[0] + matrix[:3, 3]
    scene.frame_set(saved[0], subframe=saved[1])
    return points


def slow_light_scene(bpy, c, fps):
    """64x48 Cycles scene with a camera at the origin, light at ``c`` units/s, ``fps`` frames/s."""
    scene, camera_object = ch.new_scene(bpy, resolution=(64, 48), samples=1)
    scene.relativity.speed_of_light = c
    scene.render.fps, scene.render.fps_base = fps, 1.0
    return scene, camera_object


def evaluated_attribute(bpy, obj, name):
    """A vector point attribute of the evaluated mesh, ``(N, 3)``."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        data = mesh.attributes[name].data
        values = np.empty(len(data) * 3)
        data.foreach_get("vector", values)
    finally:
        obj_eval.to_mesh_clear()
    return values.reshape(-1, 3)


def file_fingerprint(bpy):
    """What the effect and its bakes may touch, as one string: every object (transform, parent,
    modifiers, constraints, ID properties), every mesh (vertices, attributes, ID properties), the
    node groups, and the scene frame."""

    def idprops(owner):
        return repr(sorted((key, repr(owner[key])) for key in compat.custom_property_keys(owner)))

    objects = [
        (
            o.name,
            tuple(map(tuple, o.matrix_world)),
            o.parent.name if o.parent else "",
            repr(o.data),
            [(m.name, m.type, m.show_viewport) for m in o.modifiers],
            [c.name for c in o.constraints],
            idprops(o),
        )
        for o in bpy.data.objects
    ]
    meshes = []
    for mesh in bpy.data.meshes:
        co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
        meshes.append((mesh.name, co.tobytes().hex(), sorted(a.name for a in mesh.attributes), idprops(mesh)))
    scene = bpy.context.scene
    return repr(
        (objects, meshes, sorted(g.name for g in bpy.data.node_groups), scene.frame_current, scene.frame_subframe)
    )


class _RecordingLayout:
    """Stand-in for ``UILayout`` (no UI in background Blender): records labels and operators,
    accepts any other layout call."""

    def __init__(self, log):
        self.log = log

    def __getattr__(self, name):
        return lambda *args, **kwargs: _RecordingLayout(self.log)

    def label(self, text="", icon="NONE", **kwargs):
        self.log.append(("label", text, icon))

    def operator(self, idname, text="", icon="NONE", **kwargs):
        self.log.append(("operator", idname))
        return _RecordingLayout(self.log)


def draw_object_panel(bpy, scene, obj):
    """What ``RELATIVITY_PT_object`` draws for ``obj``: [("label", text, icon) | ("operator", idname)]."""
    panel_class = bpy.types.RELATIVITY_PT_object
    context = type("Context", (), {"scene": scene, "object": obj})()
    assert panel_class.poll(context)
    log = []
    panel_class.draw(type("PanelShim", (), {"layout": _RecordingLayout(log)})(), context)
    return log


def keyframe_linear(obj, path, index, points):
    """Keys ``(frame, value)`` on ``obj.<path>[index]`` with linear interpolation and extrapolation.
    Returns the F-curve."""
    for frame, value in points:
        getattr(obj, path)[index] = value
        obj.keyframe_insert(path, index=index, frame=frame)
    fcurve = next(
        f for f in compat.action_fcurves(obj.animation_data) if f.data_path == path and f.array_index == index
    )
    for point in fcurve.keyframe_points:
        point.interpolation = "LINEAR"
    fcurve.extrapolation = "LINEAR"
    fcurve.update()
    return fcurve


def coloured_emission(bpy, name, colour):
    material = ch.emission_material(bpy, name)
    material.node_tree.nodes["Emission"].inputs["Color"].default_value = (*colour, 1.0)
    return material


def clock_face(bpy, scene, radius):
    """A linked object "Clock" with Apparent Geometry on: a red dot at its origin (the centre) and
    a green dot at (``radius``, 0, 0) (the hand's tip)."""
    import bmesh

    mesh = bpy.data.meshes.new("Clock")
    bm = bmesh.new()
    for index, offset in enumerate(((0.0, 0.0, 0.0), (radius, 0.0, 0.0))):
        created = bmesh.ops.create_uvsphere(bm, u_segments=16, v_segments=8, radius=0.09)
        bmesh.ops.translate(bm, vec=offset, verts=created["verts"])
        for face in {f for v in created["verts"] for f in v.link_faces}:
            face.material_index = index
    bm.to_mesh(mesh)
    bm.free()
    mesh.materials.append(coloured_emission(bpy, "Centre", (1.0, 0.0, 0.0)))
    mesh.materials.append(coloured_emission(bpy, "Tip", (0.0, 1.0, 0.0)))
    clock = bpy.data.objects.new("Clock", mesh)
    scene.collection.objects.link(clock)
    clock.relativity.enabled = True
    return clock
