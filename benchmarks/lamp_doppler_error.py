"""What the renderer leaves out of eq. 18 for lamps at rest lighting a moving object
(docs/lamp-doppler.md): one Doppler factor and one direction per lamp and object (before) against
the stand-ins that give each receiving point its own (now).

    python benchmarks/lamp_doppler_error.py [--beta 0.5] [--count 20000]

A sphere of rest radius 1 moving along +X with ``beta``, Lorentz-contracted in the scene frame (one
scene time, no retardation), lit by a lamp at rest in four directions: a point lamp at ``d`` = 3,
10 and 30 radii from the centre, and a 1 m square area lamp 1 m from the sphere's surface (its
centre 2 radii from the sphere's), facing the centre. Per lit surface point:

- **reference**, written out here from docs/physics.md alone (not the add-on's functions): the
  photon's four-momentum ``(1, k)`` and the emission-absorption separation ``(r, r k)`` boosted
  into the sphere's frame give ``D``, ``k'`` and ``r'``; eq. 18 (bolometric) is
  ``E' = D^4 cos(alpha') I / r'^2`` with ``alpha'`` between the rest normal and ``-k'``; an area
  lamp is summed over 24 x 24 elements (a Lambertian panel: ``I = L cos_e dA`` along ``k``);
- **before**: what the former renderer computed (``lamp_doppler.one_factor_irradiance``): the lamp's
  copy turned about the centre to the centre's aberrated direction, ``D^2`` of the centre,
  Cycles' cosine on the rest normal (an area lamp's panel turned the same way);
- **now**: what the stand-ins render (``lamp_doppler.stand_in_irradiance``), placed as the stage
  places them (``blender/lights/lamps_on_moving_objects.stand_in_placement``: over the bounding
  box's centre, corners, edge midpoints and face centres, and an area lamp's corners): each
  point's own ``D`` and direction, interpolated between the two stand-ins around it; for an area
  lamp per element.

Printed: the irradiance-weighted mean ``|E - E_ref| / E_ref`` over the lit side and the largest
error at a point lit above 10 % of the peak. Numpy only (no Blender).
"""

import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from relativity_addon.physics import lamp_doppler  # noqa: E402

DIRECTIONS = {
    "ahead": (1.0, 0.0, 0.0),
    "behind": (-1.0, 0.0, 0.0),
    "side": (0.0, -1.0, 0.0),
    "45 deg ahead": (0.7071068, -0.7071068, 0.0),
}
PANEL = 1.0  # m, the area lamp's side
PANEL_ELEMENTS = 24
MAX_ANGLE, MAX_STAND_INS, MAX_AREA_STAND_INS = 0.2, 3, 6  # as blender/lights/lamps_on_moving_objects.py


# --- the reference, from docs/physics.md ----------------------------------------------------


def boost(ct, x, beta):
    """The scene-frame event or four-vector ``(ct, x)`` in the frame moving with ``beta``."""
    speed2 = float(beta @ beta)
    gamma = 1.0 / math.sqrt(1.0 - speed2)
    bx = x @ beta
    return gamma * (ct - bx), x + ((gamma - 1.0) * bx / speed2 - gamma * ct)[..., None] * beta


def reference(points, rest_normals, source, beta, intensity):
    """Eq. 18 in the object frame: ``D^4 cos(alpha') I / r'^2`` (``intensity`` I per point, W/sr)."""
    separation = points - source
    r = np.linalg.norm(separation, axis=-1)
    k = separation / r[..., None]
    energy, momentum = boost(np.ones_like(r), k, beta)
    r_object, _ = boost(r, separation, beta)
    cosine = np.maximum(-np.sum(rest_normals * momentum / energy[..., None], axis=-1), 0.0)
    return energy**4 * cosine * intensity / r_object**2


# --- the lamps ------------------------------------------------------------------------------


def panel(centre, axis):
    """Elements of a square panel of side PANEL at ``centre`` emitting along ``axis``: positions,
    the panel's world matrix (its -Z along ``axis``) and each element's area."""
    z = -np.asarray(axis, float)
    x = np.cross((0.0, 0.0, 1.0), z)
    x = x / np.linalg.norm(x) if np.linalg.norm(x) > 1e-9 else np.array([1.0, 0.0, 0.0])
    y = np.cross(z, x)
    matrix = np.eye(4)
    matrix[:3, :3] = np.stack([x, y, z], axis=-1)
    matrix[:3, 3] = centre
    grid = ((np.arange(PANEL_ELEMENTS) + 0.5) / PANEL_ELEMENTS - 0.5) * PANEL
    u, v = (a.ravel() for a in np.meshgrid(grid, grid))
    elements = centre + u[:, None] * x + v[:, None] * y
    return elements, matrix, (PANEL / PANEL_ELEMENTS) ** 2


def stand_ins(receivers, corners, beta, most):
    """The stage's placement: offsets over the receivers (the box's 3 x 3 x 3 points) and the lamp's corners."""
    separation = receivers[None, :, :] - corners[:, None, :]
    distance = np.linalg.norm(separation, axis=-1)
    offsets = lamp_doppler.apparent_lamp_offset(receivers[None, :, :], corners[:, None, :], beta)
    dopplers = lamp_doppler.lamp_to_object_doppler(separation, beta)
    return lamp_doppler.stand_in_offsets(offsets, dopplers * distance, MAX_ANGLE, most)


def _errors(rendered, exact):
    lit = exact > 0.1 * exact.max()
    mean = float(np.sum(np.abs(rendered - exact)) / np.sum(exact))
    return mean, float(np.max(np.abs(rendered[lit] / exact[lit] - 1.0)))


def point_case(points, rest_normals, receivers, beta, lamp):
    exact = reference(points, rest_normals, lamp, beta, 1.0)
    before = lamp_doppler.one_factor_irradiance(points, rest_normals, lamp, (0.0, 0.0, 0.0), beta)
    offsets = stand_ins(receivers, lamp[None], beta, MAX_STAND_INS)
    now = lamp_doppler.stand_in_irradiance(points, rest_normals, lamp, beta, offsets)
    return exact, before, now, len(offsets)


def area_case(points, rest_normals, receivers, beta, centre, axis):
    elements, matrix, area = panel(centre, axis)
    radiance = 1.0 / area  # any: the errors are ratios
    corners = np.array(
        [matrix[:3, :3] @ (sx * PANEL / 2, sy * PANEL / 2, 0.0) + centre for sx in (-1, 1) for sy in (-1, 1)]
    )
    offsets = stand_ins(receivers, np.vstack([centre[None], corners]), beta, MAX_AREA_STAND_INS)
    turned = lamp_doppler.aberrated_lamp_matrix(matrix, (0.0, 0.0, 0.0), -centre, beta)
    turned_axis = -turned[:3, 2]
    centre_factor = lamp_doppler.irradiance_factor(lamp_doppler.lamp_to_object_doppler(-centre, beta))
    speed = float(np.linalg.norm(beta))
    exact, before, now = (np.zeros(len(points)) for _ in range(3))
    for element in elements:
        k = points - element
        k /= np.linalg.norm(k, axis=-1, keepdims=True)
        emitted = np.maximum(k @ axis, 0.0) * radiance * area
        exact += reference(points, rest_normals, element, beta, emitted)
        # before: the panel turned about the centre, its element there, one D^2
        copy = turned[:3, :3] @ (matrix[:3, :3].T @ (element - centre)) + turned[:3, 3]
        towards = copy - points
        t = np.linalg.norm(towards, axis=-1)
        cos_copy = np.maximum(-(towards / t[:, None]) @ turned_axis, 0.0)
        cos_receiver = np.maximum(np.sum(rest_normals * towards, axis=-1) / t, 0.0)
        before += centre_factor * cos_copy * radiance * area * cos_receiver / t**2
        # now: the element's stand-ins (the shifted panels; each emits only where its own face looks)
        lit_by = lamp_doppler.stand_in_irradiance(points, rest_normals, element, beta, offsets, 1.0)
        shifted_face = np.zeros(len(points), bool)
        for u in offsets:
            shifted_face |= ((points - (element + u * beta / speed)) @ axis) > 0.0
        now += np.where(shifted_face, lit_by * emitted, 0.0)
    return exact, before, now, len(offsets)


def table(beta_x, count):
    beta = np.array([beta_x, 0.0, 0.0])
    points, _scene_normals, rest_normals = lamp_doppler.contracted_sphere(1.0, (0.0, 0.0, 0.0), beta, count)
    half = np.abs(points).max(axis=0)
    steps = np.array([(sx, sy, sz) for sx in (-1, 0, 1) for sy in (-1, 0, 1) for sz in (-1, 0, 1)])
    receivers = steps * half  # the bounding box's centre, corners, edge midpoints and face centres
    rows = []
    cases = [
        (f"point, d = {d:g}", name, d, direction) for d in (3.0, 10.0, 30.0) for name, direction in DIRECTIONS.items()
    ]
    cases += [("1 m area lamp, 1 m away", name, 2.0, direction) for name, direction in DIRECTIONS.items()]
    for kind, name, distance, direction in cases:
        where = distance * np.array(direction)
        if kind.startswith("point"):
            exact, before, now, stand_in_count = point_case(points, rest_normals, receivers, beta, where)
        else:
            exact, before, now, stand_in_count = area_case(
                points, rest_normals, receivers, beta, where, -np.array(direction)
            )
        rows.append((kind, name, *_errors(before, exact), *_errors(now, exact), stand_in_count))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--beta", type=float, default=0.5)
    parser.add_argument("--count", type=int, default=20000)
    args = parser.parse_args()
    print(
        f"sphere of rest radius 1 at {args.beta} c; errors against eq. 18 per point (mean over the lit side / largest)"
    )
    print("| lamp | where | before: one D and direction | now: per point | stand-ins |")
    print("|---|---|---|---|---|")
    for kind, name, before_mean, before_max, now_mean, now_max, stand_in_count in table(args.beta, args.count):
        print(
            f"| {kind} | {name} | {before_mean:.1%} / {before_max:.0%} "
            f"| {now_mean:.2%} / {now_max:.1%} | {stand_in_count} |"
        )


if __name__ == "__main__":
    main()
