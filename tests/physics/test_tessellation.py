"""The adaptive tessellation's measure (physics/tessellation.py) against plane geometry: a map that
bends a straight edge onto a circle leaves the circle's sagitta ``R (1 - cos(theta / 2))`` between
the image of the edge's middle and the middle of the drawn chord; a pinhole camera keeps straight
lines straight (no bend from perspective alone); a pinhole projection by hand."""

import math

import numpy as np
import pytest

from relativity_addon.physics import tessellation

RADIUS = 100.0  # pixels


def _onto_circle(points):
    """Rest points on the x axis (x in [0, 1]) onto a circle of RADIUS pixels: x -> angle x (rad)."""
    angle = points[:, 0]
    return np.stack((RADIUS * np.sin(angle), RADIUS * (1.0 - np.cos(angle)), np.zeros_like(angle)), axis=1)


def _plane(points):
    return points[:, :2].copy()


@pytest.mark.parametrize("theta", [0.05, 0.2, 0.8])
def test_bend_of_an_arc_is_its_sagitta(theta):
    """An edge mapped onto an arc of angle theta: the drawn chord's middle is R (1 - cos(theta/2))
    from the arc's middle; in 2**k pieces, each piece's sagitta over theta / 2**k."""
    a, b = np.array([[0.0, 0.0, 0.0]]), np.array([[theta, 0.0, 0.0]])
    for parts in (1, 2, 8):
        bend = tessellation.segment_bends(a, b, parts, _onto_circle, _plane)
        expected = RADIUS * (1.0 - math.cos(theta / parts / 2.0))
        assert bend[0] == pytest.approx(expected, rel=1e-9, abs=1e-12)


def test_fewest_levels_within_the_tolerance():
    """Each edge gets the smallest k with R (1 - cos(theta / 2**(k+1))) <= tolerance, capped."""
    thetas = np.array([0.004, 0.1, 0.3, 0.6, 2.5])
    rest = np.zeros((2 * len(thetas), 3))
    rest[1::2, 0] = thetas
    edges = np.arange(2 * len(thetas)).reshape(-1, 2)
    tolerance, max_level = 0.5, 3
    levels, left = tessellation.edge_levels(rest, edges, _onto_circle, _plane, tolerance, max_level)
    for theta, level, error in zip(thetas, levels, left, strict=True):
        sagitta = [RADIUS * (1.0 - math.cos(theta / 2**k / 2.0)) for k in range(max_level + 1)]
        wanted = next((k for k, s in enumerate(sagitta) if s <= tolerance), max_level)
        if RADIUS * theta <= tolerance:  # an image no longer than the tolerance is not measured
            wanted = 0
        assert level == wanted
        assert error <= tolerance or level == max_level
    assert left[-1] > tolerance  # 2.5 rad in 8 pieces still bends 1.2 px: the caller warns


def test_perspective_alone_bends_nothing():
    """A straight edge receding from a pinhole camera projects to a straight segment, and the
    drawn segment's middle is the image of the edge's middle: no bend, however foreshortened."""
    rng = np.random.default_rng(3)
    a = rng.uniform([-3, -3, -20], [3, 3, -1], size=(200, 3))
    b = rng.uniform([-3, -3, -20], [3, 3, -1], size=(200, 3))

    def project(points):
        return tessellation.perspective_pixels(points, np.zeros(3), np.eye(3), (-0.5, 0.5, -0.4, 0.4), (1000, 800))

    bend = tessellation.segment_bends(a, b, 1, lambda p: p, project)
    assert np.max(bend) < 1e-9


def test_pinhole_pixels_by_hand():
    """Camera at (1, 2, 3) turned 90 degrees about z (its local x is world y): a point 2 units
    ahead (world -z) and 0.5 along world y is at u = 0.25 on the unit-distance plane."""
    rotation = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # columns: local axes
    eye = np.array([1.0, 2.0, 3.0])
    points = eye + np.array([[0.0, 0.5, -2.0], [0.0, 0.0, -2.0], [0.0, 0.0, 1.0]])
    pixels = tessellation.perspective_pixels(points, eye, rotation.T, (-0.5, 0.5, -0.25, 0.25), (400, 200))
    assert pixels[0] == pytest.approx([(0.25 + 0.5) * 400, 100.0])
    assert pixels[1] == pytest.approx([200.0, 100.0])
    assert np.all(np.isnan(pixels[2]))  # behind the camera


def test_edge_through_the_camera_plane_is_split_to_the_most_levels():
    rest = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])

    def project(points):
        return tessellation.perspective_pixels(points, np.zeros(3), np.eye(3), (-1, 1, -1, 1), (100, 100))

    levels, left = tessellation.edge_levels(rest, [[0, 1]], lambda p: p, project, 0.5, 2)
    assert levels[0] == 2 and not np.isfinite(left[0])


def test_face_levels_and_the_faces_across_the_seam():
    """Three quads in a row (edges 0..9): edge 3, shared by faces 0 and 1, needs 2 levels. Faces
    0 and 1 get 2; face 2 shares edge 6 with face 1, so it is across the seam."""
    loop_edges = [0, 3, 1, 2, 3, 4, 5, 6, 6, 7, 8, 9]
    levels = np.zeros(10, dtype=int)
    levels[3] = 2
    face, across = tessellation.face_levels(levels, loop_edges, [0, 4, 8], [4, 4, 4])
    assert face.tolist() == [2, 2, 0]
    assert across.tolist() == [False, False, True]


def test_bad_tolerance_is_refused():
    with pytest.raises(ValueError, match="tolerance"):
        tessellation.edge_levels(np.zeros((2, 3)), [[0, 1]], lambda p: p, _plane, 0.0, 2)


def test_edges_far_out_of_the_picture_are_not_measured():
    """An arc bending 2.4 px, its image wholly left of a 100 x 100 picture by more than its length:
    no level given the frame; without it, split as any other."""
    rest = np.array([[0.0, 0.0, 0.0], [0.8, 0.0, 0.0]])

    def far_left(points):
        return _plane(points) - np.array([300.0, 0.0])

    measured, _ = tessellation.edge_levels(rest, [[0, 1]], _onto_circle, far_left, 0.5, 3)
    framed, _ = tessellation.edge_levels(rest, [[0, 1]], _onto_circle, far_left, 0.5, 3, frame=(100.0, 100.0))
    assert measured[0] > 0 and framed[0] == 0
