"""The bounce factors of ``physics/bounce.py`` against relations built here from docs/physics.md
alone: material points followed along their own world lines (uniform motion, Lorentz-contracted
rest offsets), where the camera and where a receiving point see them found by iterating the
light-cone condition, solid angles of small rest-surface triangles measured from the directions
themselves, and the receiver's factor from the photon's four-momentum boosted by hand."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from relativity_addon.physics import bounce

CAMERA = np.array([0.0, -8.0, 0.0])


def _gamma(beta):
    return 1.0 / math.sqrt(1.0 - float(beta @ beta))


def _contract(q, beta):
    """Rest offset -> scene-frame offset at one scene time (contracted along ``beta``)."""
    speed = float(np.linalg.norm(beta))
    if speed == 0.0:
        return q
    axis = beta / speed
    return q - (1.0 - 1.0 / _gamma(beta)) * (q @ axis) * axis


def _seen(origin, q, beta, at, at_time):
    """Where an observer at event (``at_time``, ``at``) sees the material point of rest offset
    ``q`` of a body whose origin is at ``origin + beta t`` (times in path lengths): iterate
    ``t = at_time - |at - x(t)|``."""
    t = at_time
    for _ in range(200):
        t = at_time - float(np.linalg.norm(at - (origin + _contract(q, beta) + beta * t)))
    return origin + _contract(q, beta) + beta * t, t


def _case(seed):
    rng = np.random.default_rng(seed)
    beta = rng.normal(size=3)
    beta *= rng.uniform(0.1, 0.8) / np.linalg.norm(beta)
    origin = np.array([-1.5, 1.0, -0.3]) + rng.normal(scale=0.3, size=3)
    receiver = np.array([1.3, 0.8, 0.4]) + rng.normal(scale=0.3, size=3)
    return beta, origin, receiver


@pytest.mark.parametrize("seed", range(6))
def test_where_the_receiver_sees_the_point(seed):
    """The emission point is on the point's world line and on the receiving event's light cone."""
    beta, origin, receiver = _case(seed)
    q = np.array([0.3, -0.2, 0.5])
    snapshot, _ = _seen(origin, q, beta, CAMERA, 0.0)
    t_r = -float(np.linalg.norm(receiver - CAMERA))
    expected, t_e = _seen(origin, q, beta, receiver, t_r)
    source, tau = bounce.emission_seen_from(snapshot, beta, receiver, CAMERA)
    assert_allclose(source, expected, atol=1e-9)
    assert tau == pytest.approx(t_r - t_e, abs=1e-9)


def _solid_angle(at, points):
    """Solid angle of the small triangle ``points`` seen from ``at`` (its directions' area),
    negative when its side ``(p1 - p0) x (p2 - p0)`` faces away from ``at``."""
    u = [(p - at) / np.linalg.norm(p - at) for p in points]
    return -0.5 * float(np.cross(u[1] - u[0], u[2] - u[0]) @ u[0])


@pytest.mark.parametrize("seed", range(12))
def test_solid_angle_ratio_of_a_small_rest_triangle(seed):
    """``J`` is the solid angle of a small rest-surface triangle seen from the receiving point
    where it physically is, over that of its snapshot image (each vertex where the camera sees it)."""
    beta, origin, receiver = _case(seed)
    rng = np.random.default_rng(100 + seed)
    to_receiver = receiver - origin
    normal = to_receiver / np.linalg.norm(to_receiver) + rng.normal(scale=0.3, size=3)
    normal /= np.linalg.norm(normal)
    q0 = 0.8 * normal
    e1 = np.cross(normal, [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    step = 1e-4
    corners = [q0, q0 + step * e1, q0 + step * e2]
    snapshot = [_seen(origin, q, beta, CAMERA, 0.0)[0] for q in corners]
    t_r = -float(np.linalg.norm(receiver - CAMERA))
    physical = [_seen(origin, q, beta, receiver, t_r)[0] for q in corners]
    seen, seen_in_snapshot = _solid_angle(receiver, physical), _solid_angle(receiver, snapshot)
    ratio = bounce.solid_angle_ratio(snapshot[0], normal, beta, receiver, CAMERA)
    if seen > 0.0 and seen_in_snapshot > 0.0:
        assert seen / seen_in_snapshot < bounce.MAX_SOLID_ANGLE_RATIO
        assert ratio == pytest.approx(seen / seen_in_snapshot, rel=2e-3)
    else:  # the element faces away from the receiving point (in either): no light from it
        assert ratio == 0.0


def _boost_photon(k, beta):
    """The photon four-momentum ``(1, k)`` in the frame moving with ``beta``: ``(D, D k')``."""
    gamma = _gamma(beta)
    speed = float(np.linalg.norm(beta))
    axis = beta / speed
    energy = gamma * (1.0 - beta @ k)
    momentum = k + (gamma - 1.0) * (k @ axis) * axis - gamma * beta
    return energy, momentum / energy


@pytest.mark.parametrize("seed", range(6))
def test_receiver_factor(seed):
    """``D_p^2`` (radiance ``D_p^4`` over solid angle ``D_p^2``) times the cosine on the rest normal
    of the photon direction in the receiver's frame over the snapshot's cosine."""
    rng = np.random.default_rng(seed)
    beta = rng.normal(size=3)
    beta *= rng.uniform(0.1, 0.9) / np.linalg.norm(beta)
    k = rng.normal(size=3)
    k /= np.linalg.norm(k)
    k_snapshot = k + rng.normal(scale=0.1, size=3)
    k_snapshot /= np.linalg.norm(k_snapshot)
    doppler, k_frame = _boost_photon(k, beta)
    normal = -(k_frame + k_snapshot) / np.linalg.norm(k_frame + k_snapshot)
    expected = doppler**2 * -(k_frame @ normal) / -(k_snapshot @ normal)
    assert bounce.receiver_factor(k, beta, k_snapshot, normal) == pytest.approx(expected, rel=1e-9)
    assert bounce.receiver_factor(k, beta, k_snapshot) == pytest.approx(doppler**2, rel=1e-9)


def test_at_rest_the_snapshot_is_right():
    """Nothing moves: the snapshot is the scene, the factor 1 (facing elements)."""
    rng = np.random.default_rng(3)
    points = rng.normal(size=(20, 3))
    receiver = np.array([4.0, 1.0, 0.5])
    normals = receiver - points + rng.normal(scale=0.5, size=(20, 3))
    factor = bounce.bounce_correction(points, normals, np.zeros(3), receiver, np.zeros(3), CAMERA, -normals)
    assert_allclose(factor, 1.0, rtol=1e-12)


def test_refuses_light_speed():
    with pytest.raises(ValueError, match="below 1"):
        bounce.bounce_correction(np.zeros(3), [1.0, 0, 0], [1.0, 0, 0], [3.0, 0, 0], np.zeros(3), CAMERA)


def test_receiver_cosine_ratio_is_capped():
    """A snapshot cosine near 0 on a normal that is not the receiver's own (a curved receiver takes
    its box face's on SVM) gives ``c_p`` at most ``MAX_COSINE_RATIO`` (no firefly): at rest, a
    grazing ``k_snapshot`` and a ``k`` along the normal."""
    normal = np.array([0.0, 0.0, 1.0])
    k = -normal
    k_snapshot = np.array([1.0, 0.0, -1.0e-7])
    factor = bounce.receiver_factor(k, np.zeros(3), k_snapshot / np.linalg.norm(k_snapshot), normal)
    assert factor == pytest.approx(bounce.MAX_COSINE_RATIO)
