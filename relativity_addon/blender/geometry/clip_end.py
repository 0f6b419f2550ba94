"""Clip End for the boosted meshes: how far the camera must see them (a fast observer sees what
lies ahead much farther away), and the panel's one line when the camera's Clip End cuts one off."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..common import names
from ..scene import lens
from . import changes, modifier
from .modifier import applied_objects

if TYPE_CHECKING:
    import numpy.typing as npt
    from bpy.types import Depsgraph, Object, Scene

    from ..scene.snapshot import Snapshot


def farthest_seen_depth(scene: Scene, snap: Snapshot, world: npt.ArrayLike) -> float:
    """The largest depth along the view axis (scene units) of the apparent vertices ``world``
    (N, 3) in the boosted preview's camera view (a tenth of the view wider on each side), 0 when
    none: how far Clip End must reach. Fast observers see what lies ahead much farther away (a
    point at distance d ahead at gamma (1 + beta) d, docs/physics.md)."""
    camera = scene.objects.get(snap.camera)
    if snap.exact_camera or camera is None or len(world) == 0:
        return 0.0
    world = np.asarray(world, dtype=np.float64)
    local = (snap.world_to_camera @ (world - snap.camera_position).T).T
    depth = -local[:, 2]
    seen = depth > 0.0
    if camera.data.type != "ORTHO":
        left, right, bottom, top = lens.view_window(scene, camera)
        x, y = local[:, 0] / np.maximum(depth, 1e-30), local[:, 1] / np.maximum(depth, 1e-30)
        margin_x, margin_y = 0.1 * (right - left), 0.1 * (top - bottom)
        seen &= (x >= left - margin_x) & (x <= right + margin_x) & (y >= bottom - margin_y) & (y <= top + margin_y)
    return float(depth[seen].max()) if np.any(seen) else 0.0


def _round_up(value):
    """``value`` rounded up to two significant digits."""
    step = 10.0 ** (math.floor(math.log10(value)) - 1)
    return math.ceil(value / step - 1e-9) * step


def bounds_depths(snap: Snapshot, evaluated: list[Object]) -> list[float]:
    """The largest depth along the view axis (scene units) of the corners of each evaluated mesh's
    bounds (the apparent positions of a closed-form object), 0 when none is ahead: at least the
    farthest vertex's depth (a bound: the corners need not lie in the camera's view). One numpy pass
    over the objects (a 1,000-object frame step takes every object's)."""
    if not evaluated:
        return []
    corners = np.array([[tuple(corner) for corner in obj_eval.bound_box] for obj_eval in evaluated], dtype=np.float64)
    matrices = np.array([[tuple(row) for row in obj_eval.matrix_world] for obj_eval in evaluated], dtype=np.float64)
    world = np.einsum("nij,nkj->nki", matrices[:, :3, :3], corners) + matrices[:, None, :3, 3]
    depth = -np.einsum("j,nkj->nk", np.asarray(snap.world_to_camera, dtype=np.float64)[2], world - snap.camera_position)
    return np.maximum(depth.max(axis=1), 0.0).tolist()


# Object session_uid -> (the farthest seen depth last taken for it, the camera it was taken for:
# None when it was read from the cache without an evaluated depsgraph).
_depths: dict[int, tuple[float, object]] = {}


def note_depth(obj: Object, snap: Snapshot, depth: float) -> None:
    """The depth an update computed for ``obj`` from the snapshot (also kept on its cache)."""
    _depths[obj.session_uid] = (depth, (snap.camera, snap.camera_matrix))


def clip_end_warnings(scene: Scene, snap: Snapshot, depsgraph: Depsgraph | None = None) -> list[str]:
    """One line when the boosted meshes reach beyond the camera's Clip End (they are cut off in the
    viewport and the boosted-mesh render), naming the farthest mesh and the Clip End it needs.
    A closed-form object's depth is its evaluated bounds' (:func:`bounds_depths`), taken from a
    handler's evaluated ``depsgraph`` for another camera or when Blender evaluated the object again
    (``changes.moved``), and kept for the syncs without one; the others' come from their updates
    (:func:`note_depth`)."""
    camera = scene.objects.get(snap.camera)
    if snap.exact_camera or camera is None or camera.type != "CAMERA":
        return []
    view = (snap.camera, snap.camera_matrix)
    moved = changes.moved() if depsgraph is not None else set()
    depths = []
    taken = []  # (uid, name, cache mesh, evaluated object): the closed-form objects' depths taken now
    for obj in applied_objects(scene):
        uid = obj.session_uid
        known = _depths.get(uid)
        if known is not None and uid not in moved and (known[1] == view or depsgraph is None):
            depths.append((known[0], obj.name))
            continue
        mod = modifier.find_modifier(obj)
        data = modifier.cache_data(obj, mod) if mod is not None else None
        if data is None:
            continue
        closed = modifier.closed_form_on(mod)
        if depsgraph is not None and closed:
            taken.append((uid, obj.name, data, obj.evaluated_get(depsgraph)))
            continue
        # the cache's depth is the last update's (for this camera) unless the modifier computes it
        depth = float(data.get(names.DEPTH_KEY, 0.0))
        _depths[uid] = (depth, view if depsgraph is not None or not closed else None)
        depths.append((depth, obj.name))
    for (uid, name, data, _obj_eval), depth in zip(taken, bounds_depths(snap, [t[3] for t in taken]), strict=True):
        if data.get(names.DEPTH_KEY) != depth:
            data[names.DEPTH_KEY] = depth
        _depths[uid] = (depth, view)
        depths.append((depth, name))
    moved.clear()
    depth, name = max(depths, default=(0.0, ""))
    if depth <= camera.data.clip_end:
        return []
    scale = scene.unit_settings.scale_length or 1.0
    return [
        f"Camera {camera.name!r}: Clip End {camera.data.clip_end * scale:.5g} m cuts off mesh {name!r}, "
        f"seen {depth * scale:.5g} m away at this speed: set Clip End to {_round_up(depth * scale * 1.01):.5g} m"
    ]
