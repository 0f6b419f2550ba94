"""The docs' aberration map (tools/make_plots.py, docs/images/plots/aberration_map.png): the grid
seen by an observer moving toward longitude 0 is mirror-symmetric about longitude 0 (the scene
grid is, and so is aberration along the x axis), and no line is drawn across the map where it
leaves one edge and comes back at the other."""

import numpy as np
import pytest
from make_plots import aberration_map_lines


def _raster(lines, cell_deg=1.0):
    """Map cells (longitude, latitude) the drawn segments pass through, as matplotlib joins points:
    straight segments between consecutive finite points."""
    cells = set()
    t = np.linspace(0.0, 1.0, 64)[:, None]
    for _kind, x, y in lines:
        drawn = np.isfinite(x[:-1] + x[1:] + y[:-1] + y[1:])
        x0, x1, y0, y1 = x[:-1][drawn], x[1:][drawn], y[:-1][drawn], y[1:][drawn]
        xs, ys = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
        cells.update(
            zip(np.round(xs / cell_deg).astype(int).ravel(), np.round(ys / cell_deg).astype(int).ravel(), strict=True)
        )
    return cells


@pytest.mark.parametrize("speed", [0.5, 0.9])
def test_aberration_map_is_mirror_symmetric(speed):
    cells = _raster(aberration_map_lines(speed))
    mirrored = {(-i, j) for i, j in cells}
    assert len(cells ^ mirrored) < 0.001 * len(cells), sorted(cells ^ mirrored)[:20]
    # the meridian behind the observer runs along both edges, most of their height
    for edge in (-180, 180):
        assert len({j for i, j in cells if i == edge}) > 120, edge


@pytest.mark.parametrize("speed", [0.5, 0.9])
def test_aberration_map_draws_no_line_across_the_map(speed):
    for kind, x, y in aberration_map_lines(speed):
        step = np.abs(np.diff(x))
        assert not (step[np.isfinite(step)] > 90.0).any(), kind
        assert np.isfinite(x).sum() > 100 and np.isfinite(y).sum() > 100
