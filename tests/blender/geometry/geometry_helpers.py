"""Helpers for the apparent-geometry tests: the camera tests' scene builders and pixel measures,
plus evaluated-mesh readers. Expected values come from PHYSICS.md written out in the tests."""

import importlib
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "camera"))
import camera_helpers as ch  # noqa: E402

from blender_support import ADDON_MODULE  # noqa: E402


def geometry_module():
    return importlib.import_module(f"{ADDON_MODULE}.blender.geometry")


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
