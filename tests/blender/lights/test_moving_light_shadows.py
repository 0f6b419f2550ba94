"""Shadows of a moving light behind the exact camera (method CAMERA, an OSL camera): the stand-in
lamps of blender/lights/stand_in_lamps.py, measured in a real Cycles render against the exact shadow of eq. 19
with retarded positions written out in numpy (test_moving_point_light.py's helpers).

The scene is that module's floor with a black square 0.5 above it, under the lamp (height 1,
0.5c): a harsh case, since each floor point sees the lamp at a different retarded position and the
exact shadow is the square stretched along the motion (1672 px here). The stand-in lamps put each
floor point's shadow ray to one of the two lamps around its retarded position, so the rendered
shadow is a blend of the neighbouring lamps' square shadows: its edges are measured here against
the exact ones, and against a single lamp at one retarded position per frame.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import test_moving_point_light as floor  # noqa: E402


def _dark_span(dark):
    """(first, last) dark column of each row, NaN where a row has none."""
    columns = np.arange(dark.shape[1])
    first = np.where(dark.any(1), np.where(dark, columns, dark.shape[1]).min(1), np.nan)
    last = np.where(dark.any(1), np.where(dark, columns, -1).max(1), np.nan)
    return first, last


def measure(image, points, lit, source, label):
    """Compare a render's floor (``image``, one channel) with the exact shadow of eq. 19: ``points``
    the floor point of each pixel, ``lit`` its radiance without the occluder, ``source`` the lamp's
    retarded position for it. Returns the mean error away from the shadow (fraction of the peak),
    the light the shadow takes away over the exact, the mean offset of the shadow's edges along the
    rows (px), the same for one lamp at one retarded position per frame, the pixels judged dark/lit
    wrong and the exact shadow's size (px)."""
    exact = np.where(floor._blocked(source, points), 0.0, lit)
    seen = floor._blocked(np.broadcast_to(floor.CAMERA, points.shape), points)  # pixels showing the occluder
    floor_px = ~seen
    peak = lit.max()

    # away from the shadow the floor is eq. 19 (the profile test's check, here with the occluder)
    shadowed = floor._blocked(source, points)
    near = shadowed.copy()
    for shift in range(-12, 13):
        near |= np.roll(shadowed, shift, axis=1)
    for shift in range(-6, 7):
        near |= np.roll(shadowed, shift, axis=0)
    clear = floor_px & ~near
    clear_error = np.abs(image - exact)[clear].mean() / peak
    # the light the shadow takes away, in total
    deficit = (lit - image)[floor_px].sum() / (lit - exact)[floor_px].sum()
    # the shadow's edges along the rows (dark: below half the unshadowed light)
    rows = shadowed.any(1)
    first, last = _dark_span((image < 0.5 * lit) & floor_px)
    first_exact, last_exact = _dark_span(shadowed & floor_px)
    edge_error = np.nanmean(np.abs(np.concatenate([first - first_exact, last - last_exact])[np.r_[rows, rows]]))
    # one lamp per frame instead: the retarded position of the floor point under the shadow's middle
    middle = np.unravel_index(np.argmax(shadowed * lit), shadowed.shape)
    one_lamp = floor._blocked(np.broadcast_to(source[middle], points.shape), points)
    first_one, last_one = _dark_span(one_lamp & floor_px)
    one_lamp_offsets = np.concatenate([first_one - first_exact, last_one - last_exact])
    one_lamp_error = np.nanmean(np.abs(one_lamp_offsets[np.r_[rows, rows]]))
    wrong = int((((image < 0.5 * lit) != shadowed) & floor_px & (lit > 0.05 * peak)).sum())
    print(
        f"{label}: away from the shadow: mean error {clear_error:.4f} of the peak; shadow deficit {deficit:.3f} "
        f"of the exact; edges along the rows: mean {edge_error:.1f} px off (one lamp per frame: "
        f"{one_lamp_error:.1f} px); {wrong} px dark/lit wrong of {shadowed.sum()} in the exact shadow"
    )
    return clear_error, deficit, edge_error, one_lamp_error, wrong, int(shadowed.sum())


def test_shadow_behind_the_exact_camera(relativity_addon, factory_blender, tmp_path):
    bpy = factory_blender
    scene, camera, _lamp = floor._floor_scene(bpy, occluder=True, samples=floor.SAMPLES_LAMPS)
    floor._effect().apply(scene)
    # the stand-ins' places on the path (each lamp a line of three strips, all at its place)
    lights = [obj for obj in scene.objects if obj.type == "LIGHT" and not obj.hide_render]
    stand_ins = {tuple(round(v, 6) for v in obj.location) for obj in lights}
    image = floor._render(bpy, scene, tmp_path / "shadow.exr")[..., 1]
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    points = floor._floor_points(bpy, scene, camera)
    lit, source, _ = floor._expected_radiance(points, floor.BETA)
    clear_error, deficit, edge_error, one_lamp_error, _wrong, _size = measure(
        image, points, lit, source, f"{len(stand_ins)} stand-in lamps"
    )
    assert 2 <= len(stand_ins) <= 16
    assert clear_error < 0.02
    assert abs(deficit - 1.0) < 0.2
    assert edge_error < 8.0
    assert edge_error < 0.5 * one_lamp_error
