"""The harsh moving-light shadow (issue 27, item 2): a bar close to the floor under a light moving
fast, behind the exact camera (stand-ins of blender/lights/stand_in_lamps.py), against the analytic
retarded-time shadow computed here from docs/physics.md ("Light-travel time"): each floor point's
retarded light position (test_moving_point_light's fixed-point iteration, not the add-on's closed
form) and the bar's shadow from there.

The bar lies across the motion, so its shadow's two long edges run across it: each floor point along
them sees the light at its own retarded position, and the exact edges are smooth curves. Point lamps
on the path put every point's shadow ray to one of two fixed lamps: the edge jumps from one lamp's
shadow to the next one's where the weights cross one half (a stepped edge). The default draws each
lamp out into a line along the path, whose shadow is soft along the motion: the two lamps' soft
shadows, weighted, interpolate the edge (docs/moving-lights.md). Measured per image row:
where the floor's light crosses half its unshadowed value (linear between pixel centres), against
where the exact shadow's edge crosses that row (bisection on the exact shadow); the offset's mean
and its scatter about a smooth curve (a cubic in the row) bound the edge's position and straightness.
"""

import importlib
import math
import sys
from pathlib import Path

import numpy as np

from blender_support import ADDON_MODULE

sys.path.insert(0, str(Path(__file__).resolve().parent))
import test_moving_point_light as floor  # noqa: E402

BETA = np.array([0.7, 0.0, 0.0])  # fast
LAMP = np.array([3.0, 0.0, 1.0])  # where Blender draws it (1 above the floor)
BAR_CENTRE = np.array([-1.5, 0.0, 0.25])  # close to the floor
BAR_HALF = (0.3, 1.0)  # across the motion
SAMPLES = 128  # 64 passes too (measured: edges 0.25 px off on average, scatter rms 0.33 px)
RESOLUTION = (160, 120)


def _blocked(start, end):
    s = (BAR_CENTRE[2] - start[..., 2]) / (end[..., 2] - start[..., 2])
    hit = start + s[..., None] * (end - start)
    inside = (np.abs(hit[..., 0] - BAR_CENTRE[0]) < BAR_HALF[0]) & (np.abs(hit[..., 1] - BAR_CENTRE[1]) < BAR_HALF[1])
    return inside & (s > 0.0) & (s < 1.0)


def _floor_point(model, px, py):
    view = model.pixel_direction(px, py) @ model.rotation.T
    return floor.CAMERA + (-floor.CAMERA[2] / view[..., 2])[..., None] * view


def _exact_shadowed(model, px, py):
    """Whether the floor point seen at pixel coordinates (px, py) is in the exact retarded shadow."""
    points = _floor_point(model, px, py)
    return _blocked(floor._retarded_lamp(points, BETA), points)


def exact_edges(model, row, width):
    """The exact shadow's edges crossing pixel row ``row``: (x, side) with x the pixel coordinate (by
    bisection between pixel centres) and side +1 where the shadow starts going right, -1 where it ends."""
    px = np.arange(width) + 0.5
    py = np.full(width, row + 0.5)
    dark = _exact_shadowed(model, px, py)
    edges = []
    for index in np.nonzero(dark[1:] != dark[:-1])[0]:
        low, high = px[index], px[index + 1]
        for _ in range(30):
            middle = 0.5 * (low + high)
            if bool(_exact_shadowed(model, np.array([middle]), np.array([row + 0.5]))[0]) == bool(dark[index + 1]):
                high = middle
            else:
                low = middle
        edges.append((0.5 * (low + high), 1 if dark[index + 1] else -1))
    return edges


def rendered_edge(ratio, row, exact, side, reach=10):
    """Where the rendered light over the unshadowed light crosses one half along ``row`` near the
    exact edge ``exact``: coming in from the lit side, the first pixel under one half (linear between
    pixel centres); None where the bar itself (``ratio`` NaN) or the image's border comes first."""
    centre = int(math.floor(exact))
    columns = np.arange(centre - side * reach, centre + side * reach, side)
    if columns.min() < 0 or columns.max() >= ratio.shape[1]:
        return None
    values = ratio[row, columns]
    below = np.nonzero(~(values >= 0.5))[0]  # under one half, or the bar itself (NaN)
    if len(below) == 0 or below[0] == 0 or not np.isfinite(values[below[0]]):
        return None
    j = below[0]
    a, b = values[j - 1], values[j]
    return columns[j - 1] + 0.5 + side * (a - 0.5) / (a - b)


def measure(image, lit, seen, model, label, brightest=0.2):
    """The rendered shadow edges against the exact ones, on the rows they cross where the floor gets
    at least ``brightest`` of the peak (noise): the share of exact edge points the render has an edge
    near, the offsets (px) and their scatter about each side's mean offset (px; steps, or a straight
    edge where the exact one curves, make it large)."""
    height, width = image.shape
    ratio = np.where(seen, np.nan, image / np.maximum(lit, 1e-30))
    found, exact_count = {1: [], -1: []}, 0
    for row in range(height):
        for exact, side in exact_edges(model, row, width):
            column = min(int(exact), width - 1)
            if lit[row, column] < brightest * lit.max() or np.isnan(ratio[row, column]):
                continue
            exact_count += 1
            measured = rendered_edge(ratio, row, exact, side)
            if measured is not None:
                found[side].append(measured - exact)
    offsets = [np.array(values) for values in found.values() if values]
    assert exact_count > 20 and offsets, "no shadow edge measured"
    offset = np.concatenate(offsets)
    scatter = np.concatenate([np.abs(values - values.mean()) for values in offsets])
    share = len(offset) / exact_count
    print(
        f"{label}: edge found near {len(offset)} of {exact_count} exact edge points; offset from the exact edge: "
        f"mean |.| {np.abs(offset).mean():.2f} px, mean {offset.mean():+.2f} px, largest {np.abs(offset).max():.2f} "
        f"px; scatter about its mean: rms {np.sqrt((scatter**2).mean()):.2f} px, largest {scatter.max():.2f} px"
    )
    return share, np.abs(offset).mean(), scatter


def _scene(bpy):
    floor.LAMP = LAMP
    scene, camera, _lamp = floor._floor_scene(bpy, beta=BETA, samples=SAMPLES)
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    black = bpy.data.materials.new("Black")
    tree = floor.compat.material_node_tree(black)
    tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    mesh = bpy.data.meshes.new("Bar")
    hx, hy = BAR_HALF
    mesh.from_pydata([(-hx, -hy, 0.0), (hx, -hy, 0.0), (hx, hy, 0.0), (-hx, hy, 0.0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(black)
    bar = bpy.data.objects.new("Bar", mesh)
    bar.location = tuple(BAR_CENTRE)
    scene.collection.objects.link(bar)
    return scene, camera


def _render_and_measure(bpy, tmp_path, shadows, clear_px=3):
    """Render the harsh shadow with Moving Shadows ``shadows`` (None: the default) and measure its
    edges; the light away from the shadow (``clear_px`` clear of it) is checked against eq. 19."""
    saved = floor.LAMP
    try:
        scene, camera = _scene(bpy)
        if shadows is None:
            shadows = "default"
        else:
            scene.relativity.moving_light_shadows = shadows
        floor._effect().apply(scene)
        image = floor._render(bpy, scene, tmp_path / f"{shadows}.exr")[..., 1]
        assert np.all(np.isfinite(image)) and image.min() >= 0.0
        points = floor._floor_points(bpy, scene, camera)
        lit, source, _ = floor._expected_radiance(points, BETA)
        seen = _blocked(np.broadcast_to(floor.CAMERA, points.shape), points)  # pixels showing the bar
        model = floor.ch.pinhole_model(bpy, scene, camera)
        # the light away from the shadow: eq. 19 (the mean over the bright floor, clear_px clear of the shadow)
        shadowed = _blocked(source, points)
        near = shadowed | seen
        for shift in range(-clear_px, clear_px + 1):
            near = near | np.roll(shadowed | seen, shift, axis=0) | np.roll(shadowed | seen, shift, axis=1)
        clear = ~near & (lit > 0.2 * lit.max())
        brightness = image[clear].mean() / lit[clear].mean()
        print(f"{shadows}: the bright floor {clear_px} px clear of the shadow at {brightness:.4f} of eq. 19")
        assert abs(brightness - 1.0) < 0.03
        return measure(image, lit, seen, model, f"{shadows}, {SAMPLES} samples")
    finally:
        floor.LAMP = saved
        floor._effect().remove(bpy.context.scene)
        left = [obj.name for obj in bpy.data.objects if obj.name.startswith("Relativity Lamp")]
        assert not left, f"Remove left stand-ins: {left}"
        assert not [light.name for light in bpy.data.lights if light.name.startswith("Relativity Lamp")]


def test_harsh_shadow_edges_follow_the_retarded_shadow(relativity_addon, factory_blender, tmp_path):
    """Continuous shadows: the edge within 1 px of the exact one on average, found near it on nearly
    every row, and as smooth as the exact edge (no steps)."""
    share, mean_offset, scatter = _render_and_measure(factory_blender, tmp_path, "CONTINUOUS")
    assert share > 0.9
    assert mean_offset < 1.0
    assert np.sqrt((scatter**2).mean()) < 0.5
    assert scatter.max() < 1.5


def test_default_harsh_shadow_follows_the_retarded_shadow(relativity_addon, factory_blender, tmp_path):
    """The default setting (Blended Lamps, each lamp a line along the path): the edge within 1 px of
    the exact one on average, found near it on nearly every row, as smooth as the exact edge (no
    steps). The lines soften the shadow along the motion (over 1.25 lamp spacings through the bar,
    about 9 px here): the bright floor is judged 8 px clear of it."""
    share, mean_offset, scatter = _render_and_measure(factory_blender, tmp_path, None, clear_px=8)
    assert share > 0.9
    assert mean_offset < 1.0
    assert np.sqrt((scatter**2).mean()) < 0.5
    assert scatter.max() < 1.5


def test_point_lamps_step_the_harsh_shadow(relativity_addon, factory_blender, tmp_path):
    """The same lamps as points (``stand_in_lamps.LINE = 0``, the default before): the edge jumps from
    one lamp's shadow to the next one's, a straight edge and a half-shadow band where the exact edge
    curves."""
    module = importlib.import_module(f"{ADDON_MODULE}.blender.lights.stand_in_lamps")
    saved = module.LINE
    module.LINE = 0.0
    try:
        share, mean_offset, _scatter = _render_and_measure(factory_blender, tmp_path, "BLENDED")
    finally:
        module.LINE = saved
    assert share < 0.6 or mean_offset > 2.0
