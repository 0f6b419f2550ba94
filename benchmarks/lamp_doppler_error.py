"""What one Doppler factor per lamp and moving object leaves out (docs/lamp-doppler.md).

    python benchmarks/lamp_doppler_error.py [--beta 0.5] [--count 20000]

A sphere of rest radius 1 moving along +X with ``beta``, Lorentz-contracted in the scene frame, lit
by a point lamp at rest at distance ``d`` in four directions. Per lit surface point, eq. 18 exactly
(``E' = D^2 cos(alpha') I / r^2`` with the point's own ``D``, the rest-frame normal and the photon
direction aberrated into the object's frame) against what the renderer computes (Cycles'
``cos(alpha) I / r^2`` on the scene-frame surface times ``D^2`` of the lamp -> centre direction):

- ``D^2 spread``: largest ``|D_centre^2 / D(x)^2 - 1|`` over the lit points (the one-D approximation alone);
- ``one D``: irradiance-weighted mean ``|error|`` of the one-D factor alone (scene-frame cosines exact);
- ``total``: irradiance-weighted mean ``|E_render - E'| / E'`` with the scene-frame cosine too, with
  the lamp where it is (unturned) and with the copy turned about the centre to the aberrated
  direction (``lamp_doppler.aberrated_lamp_matrix``), on the contracted surface's normals and on
  the rest-frame normals (what the add-on renders, ``blender/lights/rest_normals.py``).

Numpy only (no Blender).
"""

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from relativity_addon.physics import lamp_doppler  # noqa: E402

DIRECTIONS = {
    "ahead": (1.0, 0.0, 0.0),
    "behind": (-1.0, 0.0, 0.0),
    "side": (0.0, -1.0, 0.0),
    "45 deg ahead": (0.7071, -0.7071, 0.0),
}


def table(beta_x, count, distances=(3.0, 10.0, 30.0)):
    beta = np.array([beta_x, 0.0, 0.0])
    points, scene_normals, rest_normals = lamp_doppler.contracted_sphere(1.0, (0.0, 0.0, 0.0), beta, count)
    rows = []
    for distance in distances:
        for name, direction in DIRECTIONS.items():
            lamp = distance * np.array(direction)
            exact = lamp_doppler.exact_irradiance(points, rest_normals, lamp, beta)
            rendered = lamp_doppler.one_factor_irradiance(points, scene_normals, lamp, (0.0, 0.0, 0.0), beta)
            rest_shaded = lamp_doppler.one_factor_irradiance(points, rest_normals, lamp, (0.0, 0.0, 0.0), beta)
            unturned = lamp_doppler.one_factor_irradiance(
                points, scene_normals, lamp, (0.0, 0.0, 0.0), beta, aberrate=False
            )
            offset = points - lamp
            k = offset / np.linalg.norm(offset, axis=-1, keepdims=True)
            per_point = lamp_doppler.lamp_to_object_doppler(k, beta)
            centre = lamp_doppler.lamp_to_object_doppler(-lamp, beta)
            lit = unturned > 0.0
            one_d = centre**2 / per_point**2 - 1.0
            weights = unturned[lit]
            rows.append(
                (
                    distance,
                    name,
                    float(centre),
                    float(np.max(np.abs(one_d[lit]))),
                    float(np.sum(np.abs(one_d[lit]) * weights) / np.sum(weights)),
                    float(np.sum(np.abs(unturned - exact)) / np.sum(exact)),
                    float(np.sum(np.abs(rendered - exact)) / np.sum(exact)),
                    float(np.sum(np.abs(rest_shaded - exact)) / np.sum(exact)),
                )
            )
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--beta", type=float, default=0.5)
    parser.add_argument("--count", type=int, default=20000)
    args = parser.parse_args()
    print(f"sphere of rest radius 1 at {args.beta} c, point lamp at rest at distance d")
    print(
        "| d | lamp | D (centre) | D^2 spread | one D | total, lamp unturned | turned, contracted normals "
        "| turned, rest normals (as rendered) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for distance, name, centre, spread, one_d, unturned, total, rest in table(args.beta, args.count):
        print(
            f"| {distance:g} | {name} | {centre:.3f} | {spread:.1%} | {one_d:.1%} | {unturned:.1%} | {total:.1%} "
            f"| {rest:.1%} |"
        )


if __name__ == "__main__":
    main()
