"""Clip End for the boosted meshes: how far the camera must see them (a fast observer sees what
lies ahead much farther away), and the panel's one line when the camera's Clip End cuts one off."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..common import names
from ..scene import lens
from . import changes, modifier, motion
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


def bounds_depth(snap: Snapshot, obj_eval: Object) -> float:
    """The largest depth along the view axis (scene units) of the corners of the evaluated mesh's
    bounds (the apparent positions of a closed-form object), 0 when none is ahead: at least the
    farthest vertex's depth (a bound: the corners need not lie in the camera's view)."""
    corners = np.array([tuple(corner) for corner in obj_eval.bound_box], dtype=np.float64)
    world = motion.to_world(motion.matrix_array(obj_eval.matrix_world), corners)
    depth = -(snap.world_to_camera @ (world - snap.camera_position).T)[2]
    return float(max(depth.max(initial=0.0), 0.0))


# Object session_uid -> (the farthest seen depth last taken for it, the camera it was taken for:
# None when it was read from the cache without an evaluated depsgraph).
_depths: dict[int, tuple[float, object]] = {}


def note_depth(obj: Object, snap: Snapshot, depth: float) -> None:
    """The depth an update computed for ``obj`` from the snapshot (also kept on its cache)."""
    _depths[obj.session_uid] = (depth, (snap.camera, snap.camera_matrix))


def clip_end_warnings(scene: Scene, snap: Snapshot, depsgraph: Depsgraph | None = None) -> list[str]:
    """One line when the boosted meshes reach beyond the camera's Clip End (they are cut off in the
    viewport and the boosted-mesh render), naming the farthest mesh and the Clip End it needs.
    A closed-form object's depth is its evaluated bounds' (:func:`bounds_depth`), taken from a
    handler's evaluated ``depsgraph`` for another camera or when Blender evaluated the object again
    (``changes.moved``), and kept for the syncs without one; the others' come from their updates
    (:func:`note_depth`)."""
    camera = scene.objects.get(snap.camera)
    if snap.exact_camera or camera is None or camera.type != "CAMERA":
        return []
    view = (snap.camera, snap.camera_matrix)
    moved = changes.moved() if depsgraph is not None else set()
    depths = []
    for obj in applied_objects(scene):
        uid = obj.session_uid
        known = _depths.get(uid)
        if known is not None and uid not in moved and (known[1] == view or depsgraph is None):
            depths.append((known[0], obj.name))
            continue
        data = modifier.cache_data(obj)
        if data is None:
            continue
        closed = modifier.closed_form_on(modifier.find_modifier(obj))
        if depsgraph is not None and closed:
            depth = bounds_depth(snap, obj.evaluated_get(depsgraph))
            if data.get(names.DEPTH_KEY) != depth:
                data[names.DEPTH_KEY] = depth
        depth = float(data.get(names.DEPTH_KEY, 0.0))
        # the cache's depth is the last update's (for this camera) unless the modifier computes it
        _depths[uid] = (depth, view if depsgraph is not None or not closed else None)
        depths.append((depth, obj.name))
    moved.clear()
    depth, name = max(depths, default=(0.0, ""))
    if depth <= camera.data.clip_end:
        return []
    scale = scene.unit_settings.scale_length or 1.0
    return [
        f"Camera {camera.name!r}: Clip End {camera.data.clip_end * scale:.5g} m cuts off mesh {name!r}, "
        f"seen {depth * scale:.5g} m away at this speed: set Clip End to {_round_up(depth * scale * 1.01):.5g} m"
    ]
