"""Rotation and object matrices (physics/transforms.py) against hand-built single-axis matrices,
Rodrigues' formula, quaternion rotation by Hamilton products, scipy's rotations (where scipy is
installed: the Blender 5.2 environment does not pull it in) and the defining properties of
rotations. mathutils needs bpy, so it is not used here."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from relativity_addon.physics import transforms

RNG = np.random.default_rng(11)


def _hand_built(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    return {
        "X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def _scipy_rotation():
    return pytest.importorskip("scipy.spatial.transform").Rotation


def _hamilton(p, q):
    """Quaternion products p q of rows (w, x, y, z)."""
    pw, pv, qw, qv = p[:, :1], p[:, 1:], q[:, :1], q[:, 1:]
    return np.concatenate(
        [pw * qw - np.sum(pv * qv, axis=1, keepdims=True), pw * qv + qw * pv + np.cross(pv, qv)], axis=1
    )


def _rodrigues(axis, angle):
    """R v = v cos + (k x v) sin + k (k.v)(1 - cos) for a unit axis k, as a matrix."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def _assert_rotations(matrices):
    """Orthonormal with determinant +1 (proper rotations)."""
    assert_allclose(matrices @ np.swapaxes(matrices, -1, -2), np.broadcast_to(np.eye(3), matrices.shape), atol=1e-14)
    assert_allclose(np.linalg.det(matrices), 1.0, atol=1e-14)


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_single_axis_rotations_match_hand_built_matrices(axis):
    angles = RNG.uniform(-7, 7, 20)
    matrices = transforms.axis_rotation_matrices(axis, angles)
    expected = np.array([_hand_built("XYZ"[axis], a) for a in angles])
    assert_allclose(matrices, expected, atol=1e-15)
    # A quarter turn about Z takes X to Y (right-handed, column vectors).
    if axis == 2:
        assert_allclose(transforms.axis_rotation_matrices(2, [np.pi / 2])[0] @ [1, 0, 0], [0, 1, 0], atol=1e-15)


@pytest.mark.parametrize("order", transforms.EULER_ORDERS)
def test_euler_matrices_apply_the_first_letter_first(order):
    angles = RNG.uniform(-4, 4, (30, 3))
    matrices = transforms.euler_matrices(angles, order)
    _assert_rotations(matrices)
    # R = R_last @ R_middle @ R_first with hand-built matrices.
    for k in range(len(angles)):
        first, middle, last = (_hand_built(letter, angles[k, "XYZ".index(letter)]) for letter in order)
        assert_allclose(matrices[k], last @ middle @ first, atol=1e-13)


@pytest.mark.parametrize("order", transforms.EULER_ORDERS)
def test_euler_matrices_match_scipy_extrinsic_sequences(order):
    rotation = _scipy_rotation()
    angles = RNG.uniform(-4, 4, (30, 3))
    # scipy's lower-case (extrinsic) sequence applies the first letter first about fixed axes.
    columns = ["XYZ".index(letter) for letter in order]
    expected = rotation.from_euler(order.lower(), angles[:, columns]).as_matrix()
    assert_allclose(transforms.euler_matrices(angles, order), expected, atol=1e-13)


def test_euler_xyz_is_rz_ry_rx():
    ax, ay, az = 0.3, -1.1, 2.0
    expected = _hand_built("Z", az) @ _hand_built("Y", ay) @ _hand_built("X", ax)
    assert_allclose(transforms.euler_matrices([ax, ay, az], "XYZ")[0], expected, atol=1e-15)
    with pytest.raises(ValueError, match="order"):
        transforms.euler_matrices([ax, ay, az], "XYX")


def test_quaternion_matrices_rotate_as_hamilton_products_and_ignore_length():
    q = RNG.normal(size=(40, 4))  # (w, x, y, z), not normalised
    matrices = transforms.quaternion_matrices(q)
    _assert_rotations(matrices)
    unit = q / np.linalg.norm(q, axis=1, keepdims=True)
    conjugate = unit * [1.0, -1.0, -1.0, -1.0]
    vectors = RNG.normal(size=(40, 3))
    rotated = _hamilton(_hamilton(unit, np.column_stack([np.zeros(40), vectors])), conjugate)  # q v q*
    assert_allclose(np.einsum("kij,kj->ki", matrices, vectors), rotated[:, 1:], atol=1e-13)
    assert_allclose(transforms.quaternion_matrices(3.5 * q), matrices, atol=1e-14)
    assert_allclose(transforms.quaternion_matrices(-q), matrices, atol=1e-14)  # q and -q: same rotation


def test_quaternion_matrices_match_scipy():
    rotation = _scipy_rotation()
    q = RNG.normal(size=(40, 4))
    expected = rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()  # scipy: scalar last
    assert_allclose(transforms.quaternion_matrices(q), expected, atol=1e-13)


def test_zero_quaternion_is_a_half_turn_about_x_as_blender_normalises_it():
    matrices = transforms.quaternion_matrices([[0.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
    assert_allclose(matrices[0], np.diag([1.0, -1.0, -1.0]), atol=0)
    assert_allclose(matrices[1], np.eye(3), atol=0)


def test_axis_angle_matrices_match_rotation_vectors():
    angles = RNG.uniform(-7, 7, 40)
    axes = RNG.normal(size=(40, 3)) * RNG.uniform(0.1, 5.0, (40, 1))  # not normalised
    matrices = transforms.axis_angle_matrices(np.column_stack([angles, axes]))
    _assert_rotations(matrices)
    unit = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    assert_allclose(matrices, [_rodrigues(k, a) for k, a in zip(unit, angles, strict=True)], atol=1e-13)
    # Composing two turns about the same axis adds the angles.
    half = transforms.axis_angle_matrices(np.column_stack([0.5 * angles, axes]))
    assert_allclose(half @ half, matrices, atol=1e-13)
    # Rotation about an axis leaves the axis fixed.
    assert_allclose(np.einsum("kij,kj->ki", matrices, unit), unit, atol=1e-13)


def test_axis_angle_matrices_match_scipy_rotation_vectors():
    rotation = _scipy_rotation()
    angles, axes = RNG.uniform(-7, 7, 40), RNG.normal(size=(40, 3))
    unit = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    assert_allclose(
        transforms.axis_angle_matrices(np.column_stack([angles, axes])),
        rotation.from_rotvec(angles[:, None] * unit).as_matrix(),
        atol=1e-13,
    )


def test_zero_axis_is_no_rotation():
    assert_allclose(transforms.axis_angle_matrices([[1.3, 0.0, 0.0, 0.0]])[0], np.eye(3), atol=0)


def test_compose_basis_matrices_is_translate_rotate_scale():
    count = 25
    location = RNG.normal(size=(count, 3))
    rotation = transforms.euler_matrices(RNG.uniform(-3, 3, (count, 3)), "YZX")
    scale = RNG.uniform(-2, 2, (count, 3))
    matrices = transforms.compose_basis_matrices(location, rotation, scale)
    assert matrices.shape == (count, 4, 4) and matrices.dtype == np.float64
    assert_allclose(matrices[:, 3], np.broadcast_to([0, 0, 0, 1.0], (count, 4)), atol=0)
    points = RNG.normal(size=(count, 3))
    homogeneous = np.einsum("kij,kj->ki", matrices, np.column_stack([points, np.ones(count)]))
    expected = location + np.einsum("kij,kj->ki", rotation, scale * points)  # scale, rotate, translate
    assert_allclose(homogeneous[:, :3], expected, atol=1e-13)
    # Column lengths of the 3x3 part are the absolute scales.
    assert_allclose(np.linalg.norm(matrices[:, :3, :3], axis=1), np.abs(scale), atol=1e-13)


def test_compose_basis_matrices_broadcasts_single_samples_and_checks_shapes():
    rotation = transforms.quaternion_matrices(RNG.normal(size=(4, 4)))
    matrices = transforms.compose_basis_matrices([1.0, 2.0, 3.0], rotation, [1.0, 1.0, 1.0])
    assert matrices.shape == (4, 4, 4)
    assert_allclose(matrices[:, :3, 3], np.broadcast_to([1.0, 2.0, 3.0], (4, 3)), atol=0)
    with pytest.raises(ValueError):
        transforms.compose_basis_matrices(np.zeros((3, 3)), rotation, np.ones(3))
    with pytest.raises(ValueError, match="finite"):
        transforms.euler_matrices([[0.0, np.nan, 0.0]])
