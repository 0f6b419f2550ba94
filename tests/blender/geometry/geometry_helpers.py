"""Helpers for the apparent-geometry tests: the camera tests' scene builders and pixel measures,
plus evaluated-mesh readers. Expected values come from PHYSICS.md written out in the tests."""

import importlib
import math
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


def tangent_plane_axis_ratio(camera, coverage):
    """Axis ratio of a silhouette in angle space (the camera tests' measure) and its axis."""
    ys, xs = np.nonzero(coverage > 0.0)
    weights = coverage[ys, xs]
    directions = camera.pixel_direction(xs + 0.5, ys + 0.5)
    solid_angle = weights * np.abs(directions[:, 2]) ** 3
    axis = ch.normalized((directions * solid_angle[:, None]).sum(axis=0))
    for _ in range(5):
        e1 = ch.normalized(np.cross(axis, [0.0, 1.0, 0.0]))
        e2 = np.cross(axis, e1)
        cos_axis = directions @ axis
        plane = directions / cos_axis[:, None]
        coords = np.stack([plane @ e1, plane @ e2], axis=1)
        area = solid_angle / cos_axis ** 3
        mean = (coords * area[:, None]).sum(axis=0) / area.sum()
        axis = ch.normalized(axis + mean[0] * e1 + mean[1] * e2)
    centred = coords - mean
    covariance = (centred.T * area) @ centred / area.sum()
    eigenvalues = np.linalg.eigvalsh(covariance)
    return math.sqrt(eigenvalues[0] / eigenvalues[1]), axis
