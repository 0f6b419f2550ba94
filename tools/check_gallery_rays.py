"""Checks three of Gray et al.'s gallery images that look unlike the paper's panels (Figs. 7, 8(b)
and 9(b)) against a chief-ray trace written here in numpy from the physics core's shutter models
and Lorentz transformation (relativity_addon.physics.shutter), independently of the OSL shader
that rendered them.

    PYTHONPATH=. .venv-5.2/bin/python tools/check_gallery_rays.py [--gallery docs/gallery]

For each pixel centre the lens-centre ray is carried into the scene frame and intersected with
the figure's objects (as examples/gallery_scenes.py builds them). Printed: the share of pixels
where trace and render agree on what is seen, counted away from the traced outlines (where the
render's aperture blurs and antialiases), and for Fig. 9(b) the traced and rendered extent of
the scene. Needs bpy only to read the PNGs.
"""

import argparse
import os
import sys

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "examples"))

from relativity_addon.physics import shutter  # noqa: E402

SENSOR_WIDTH_MM = 36.0


def read_png(bpy, path):
    image = bpy.data.images.load(path)
    width, height = image.size
    return np.array(image.pixels[:]).reshape(height, width, 4)[::-1, :, :3]  # top row first


def scene_rays(size, lens_mm, focus, model, beta, **shutter_settings):
    """Scene-frame origins and tracing directions of the lens-centre rays (camera at the origin
    looking down -Z, as the gallery's Gray cameras), one per pixel centre."""
    width, height = size
    half_width = SENSOR_WIDTH_MM / 2.0 / lens_mm
    ys, xs = np.mgrid[0:height, 0:width]
    u, v = (xs + 0.5) / width * 2.0 - 1.0, 1.0 - (ys + 0.5) / height * 2.0
    object_points = np.stack([u * half_width, v * half_width * height / width, -np.ones_like(u)], -1) * focus
    lens_points = np.zeros_like(object_points)
    lens_time = shutter.lens_time(model, lens_points, object_points, c=1.0, beta=beta, **shutter_settings)
    _, origins, forward = shutter.photo_ray_in_scene(lens_points, object_points, lens_time, beta, 1.0)
    return origins, -forward


def cylinder_hits(origins, directions, axis, centre, radius, half_length):
    """Ray parameter of the first hit on a finite open cylinder (inf where none)."""
    e = np.zeros(3)
    e[axis] = 1.0
    offset = origins - centre
    d_perp = directions - directions[..., axis, None] * e
    o_perp = offset - offset[..., axis, None] * e
    a = (d_perp * d_perp).sum(-1)
    b = 2.0 * (d_perp * o_perp).sum(-1)
    c = (o_perp * o_perp).sum(-1) - radius**2
    discriminant = b * b - 4.0 * a * c
    root = np.sqrt(np.maximum(discriminant, 0.0))
    best = np.full(a.shape, np.inf)
    for t in ((-b + root) / (2.0 * a), (-b - root) / (2.0 * a)):  # the nearer one last wins
        along = offset[..., axis] + t * directions[..., axis]
        hit = (discriminant >= 0.0) & (t > 1e-6) & (np.abs(along) <= half_length)
        best = np.where(hit & (t < best), t, best)
    return best


def sphere_hits(origins, directions, centre, radius):
    offset = origins - centre
    b = (offset * directions).sum(-1)
    discriminant = b * b - (offset * offset).sum(-1) + radius**2
    far = -b + np.sqrt(np.maximum(discriminant, 0.0))
    return (discriminant >= 0.0) & (far > 0.0)


def plane_hits(origins, directions, axis, value):
    t = (value - origins[..., axis]) / directions[..., axis]
    return np.where(t > 1e-6, t, np.inf), origins + t[..., None] * directions


def agreement(traced, rendered):
    """Share of pixels where the traced and rendered masks agree, among pixels whose 3 x 3
    neighbourhood is one traced class."""
    height, width = traced.shape
    window = sliding_window_view(np.pad(traced, 1, mode="edge"), (3, 3)).reshape(height, width, 9)
    interior = (window == traced[..., None]).all(-1)
    return float((traced == rendered)[interior].mean()), int(interior.sum())


def fig7(gs, pixels):
    """Focus-surface shutter: the 9 x 9 spheres, white where a chief ray hits one."""
    _, centres = gs.sphere_array_centres(shutter.ShutterModel.FOCUS_SURFACE, -gs.GRAY_FOCUS)
    origins, directions = scene_rays(
        pixels.shape[1::-1],
        gs.GRAY_LENS_MM,
        gs.GRAY_FOCUS,
        "FOCUS_SURFACE",
        np.array(gs.GRAY_BETA),
        shutter_time=-gs.GRAY_FOCUS,
    )
    traced = np.zeros(pixels.shape[:2], bool)
    for centre in centres:
        traced |= sphere_hits(origins, directions, centre, gs.GRAY_SPHERE_RADIUS)
    share, count = agreement(traced, pixels.mean(-1) > 0.5)
    print(
        f"Fig. 7: sphere pixels traced {traced.sum()}, rendered white {(pixels.mean(-1) > 0.5).sum()}; "
        f"agreement {share:.4f} over {count} pixels away from outlines"
    )


def fig8b(gs, pixels):
    """Fixed-point-surface shutter: grey where the nearest hit is a cylinder."""
    origins, directions = scene_rays(
        pixels.shape[1::-1], 50.0, gs.FIXED_PLANE, "FIXED_POINT_SURFACE", np.array(gs.GRAY_BETA)
    )
    nearest = np.full(pixels.shape[:2], np.inf)
    for x in (-1.5, 0.0, 1.5):
        nearest = np.minimum(
            nearest, cylinder_hits(origins, directions, 1, np.array([x, 0.0, -gs.FIXED_PLANE]), 0.08, 2.0)
        )
    for y in (-0.9, 0.9):
        nearest = np.minimum(
            nearest, cylinder_hits(origins, directions, 0, np.array([0.0, y, -gs.FIXED_PLANE]), 0.08, 2.5)
        )
    floor_t, floor_point = plane_hits(origins, directions, 1, -2.0)
    on_floor = (np.abs(floor_point[..., 0]) <= 15.0) & (floor_point[..., 2] <= 0.0) & (floor_point[..., 2] >= -30.0)
    disc_t, disc_point = plane_hits(origins, directions, 2, -gs.FIXED_PLANE)
    on_disc = np.zeros(on_floor.shape, bool)
    for x, y in gs.MARKERS:
        on_disc |= (disc_point[..., 0] - x) ** 2 + (disc_point[..., 1] - y) ** 2 <= 0.06**2
    traced = (
        np.isfinite(nearest)
        & (nearest < np.where(on_floor, floor_t, np.inf))
        & (nearest < np.where(on_disc, disc_t, np.inf))
    )
    grey = (np.abs(pixels[..., 0] - pixels[..., 1]) < 0.03) & (pixels[..., 0] > 0.75)
    share, count = agreement(traced, grey)
    print(
        f"Fig. 8(b): cylinder pixels traced {traced.sum()}, rendered grey {grey.sum()}; "
        f"agreement {share:.4f} over {count} pixels away from outlines"
    )


def fig9b(gs, pixels):
    """Arbitrary-plane shutter at t_S = -1: where the chief rays meet the backdrop (the scene's
    extent), against the rendered non-black region (blurred: the portrait is out of focus)."""
    origins, directions = scene_rays(
        pixels.shape[1::-1],
        50.0,
        4.4,
        "ARBITRARY_PLANE",
        np.array(gs.GRAY_BETA),
        shutter_time=-1.0,
        plane_point=(0.111, 0.0, -1.1),
        plane_normal=gs.GRAY_BETA,
    )
    t, point = plane_hits(origins, directions, 2, -10.0)
    traced = np.isfinite(t) & (np.abs(point[..., 0]) <= 6.0) & (np.abs(point[..., 1]) <= 5.0)
    rendered = pixels.max(-1) > 0.02
    for name, mask in (("traced backdrop", traced), ("rendered non-black", rendered)):
        rows, columns = np.nonzero(mask)
        print(
            f"Fig. 9(b): {name}: {mask.sum()} px, centroid ({columns.mean() + 0.5:.1f}, {rows.mean() + 0.5:.1f}), "
            f"x {columns.min()}-{columns.max()}, y {rows.min()}-{rows.max()}"
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gallery", default=os.path.join(ROOT, "docs", "gallery"))
    options = parser.parse_args()
    import bpy
    import gallery_scenes as gs

    for name, check in (
        ("gray_fig7_focus_surface", fig7),
        ("gray_fig8b_fixed_point_surface", fig8b),
        ("gray_fig9b_moving", fig9b),
    ):
        check(gs, read_png(bpy, os.path.join(options.gallery, f"{name}.png")))


if __name__ == "__main__":
    main()
