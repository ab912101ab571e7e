"""graphsdg.maths.rotations: against SciPy's rotations, round trips, and one rotation giving the same bits alone
as in a stack."""
from __future__ import annotations

import ast
import doctest
import math
import pathlib

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from graphsdg.maths import rotations as rot

RNG = np.random.default_rng(22)
ANGLES = np.concatenate([RNG.uniform(-360, 360, (300, 3)),
                         [[0, 0, 0], [180, 0, 0], [0, 180, 0], [0, 0, 180], [90, 90, 90], [0, 90, 0], [0, -90, 0],
                          [30, 90, 40], [-10, -90, 25], [45, 45, 45]]])
QUATS = np.concatenate([RNG.normal(size=(300, 4)), [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1],
                                                   [1e-9, 0.6, 0.8, 0], [-1, 0, 0, 0], [0.5, -0.5, 0.5, -0.5]]])


def _scipy_quat_wxyz(r: Rotation) -> np.ndarray:
    q = r.as_quat()[..., [3, 0, 1, 2]]
    return np.where(q[..., :1] < 0, -q, q)


def _same_up_to_sign(a: np.ndarray, b: np.ndarray) -> bool:
    """Quaternions (or half-turn rotation vectors) equal up to the sign each rotation leaves open."""
    return bool(np.all(np.isclose(a, b, atol=1e-9).all(-1) | np.isclose(a, -b, atol=1e-9).all(-1)))


def _transforms(n: int) -> np.ndarray:
    """Row-vector 4x4 transforms with scales, some mirrored, some sheared."""
    m = np.zeros((n, 4, 4))
    m[:, :3, :3] = np.swapaxes(rot.euler_to_matrix(RNG.uniform(-180, 180, (n, 3))), 1, 2) * \
        RNG.uniform(0.1, 3.0, (n, 3, 1))
    m[:, 3, :3] = RNG.normal(size=(n, 3))
    m[:, 3, 3] = 1.0
    m[: n // 4, 0, :3] *= -1                                   # mirrored
    m[n // 4: n // 2, 1, :3] += 0.2 * m[n // 4: n // 2, 0, :3]    # sheared
    return m


# ---- against SciPy ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("order", rot.ROTATION_ORDERS)
def test_euler_orders_match_scipy_extrinsic_rotations(order):
    """USD's rotate<order> applies the order's first axis first, about fixed axes: SciPy's lowercase sequence."""
    per_axis = ANGLES[:, ["XYZ".index(a) for a in order]]
    want = Rotation.from_euler(order.lower(), per_axis, degrees=True).as_matrix()
    assert np.allclose(rot.euler_to_matrix(ANGLES, order), want, atol=1e-12)


def test_quaternions_and_matrices_match_scipy():
    q = QUATS / np.linalg.norm(QUATS, axis=1, keepdims=True)
    r = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    assert np.allclose(rot.quat_wxyz_to_matrix(QUATS), r.as_matrix(), atol=1e-12)
    assert _same_up_to_sign(rot.matrix_to_quat_wxyz(r.as_matrix()), _scipy_quat_wxyz(r))
    assert np.all(rot.matrix_to_quat_wxyz(r.as_matrix())[:, 0] >= 0)


def test_euler_xyz_extraction_matches_scipy_away_from_gimbal_lock():
    mats = Rotation.from_euler("xyz", ANGLES, degrees=True).as_matrix()
    got = rot.matrix_to_euler_xyz(mats)
    free = np.abs(got[:, 1]) < 89.0
    assert free.sum() > 250
    assert np.allclose(got[free], Rotation.from_matrix(mats[free]).as_euler("xyz", degrees=True), atol=1e-9)


def test_euler_quaternions_match_scipy():
    want = _scipy_quat_wxyz(Rotation.from_euler("xyz", ANGLES, degrees=True))
    assert _same_up_to_sign(rot.euler_xyz_to_quat(ANGLES), want)


def test_quaternion_products_match_scipy_composition():
    a, b = QUATS[:100], QUATS[100:200]
    ra, rb = Rotation.from_quat(a[:, [1, 2, 3, 0]]), Rotation.from_quat(b[:, [1, 2, 3, 0]])
    product = rot.canonical_quat(rot.quat_multiply(rot.unit_quat(a), rot.unit_quat(b)))
    assert _same_up_to_sign(product, _scipy_quat_wxyz(ra * rb))


def test_slerp_matches_scipy():
    a, b = rot.unit_quat(QUATS[:50]), rot.unit_quat(QUATS[50:100])
    for i in range(50):
        key = Rotation.from_quat(np.stack([a[i], b[i]])[:, [1, 2, 3, 0]])
        want = Slerp([0.0, 1.0], key)([0.3]).as_quat()[0, [3, 0, 1, 2]]
        assert _same_up_to_sign(rot.quat_slerp(a[i], b[i], 0.3), want)
    assert _same_up_to_sign(rot.quat_slerp(a, b, 0.0), a)
    assert _same_up_to_sign(rot.quat_slerp(a, b, 1.0), b)


def test_rotation_vectors_match_scipy_including_half_turns():
    mats = rot.quat_wxyz_to_matrix(QUATS)
    got, want = rot.matrix_to_rotation_vector(mats), Rotation.from_matrix(mats).as_rotvec()
    half_turn = np.isclose(np.linalg.norm(want, axis=1), math.pi)     # +-axis: the same rotation
    assert np.allclose(got[~half_turn], want[~half_turn], atol=1e-7)
    assert _same_up_to_sign(got[half_turn], want[half_turn])
    half = rot.matrix_to_rotation_vector(rot.rotation_about(1, np.full(3, math.pi)))
    assert np.allclose(np.abs(half), [0.0, math.pi, 0.0], atol=1e-9)
    assert np.allclose(rot.matrix_to_rotation_vector(np.eye(3)), 0.0)


# ---- round trips and analytic cases -------------------------------------------------------------------------
def test_euler_round_trip_through_matrices_including_gimbal_lock():
    r = rot.euler_to_matrix(ANGLES)
    back = rot.matrix_to_euler_xyz(r)
    assert np.allclose(rot.euler_to_matrix(back), r, atol=1e-9)
    locked = rot.matrix_to_euler_xyz(rot.euler_to_matrix((30, 90, 40)))
    assert locked[1] == pytest.approx(90.0) and locked[2] == 0.0     # the Z turn folds into X


def test_quaternion_round_trip_keeps_w_non_negative():
    back = rot.matrix_to_quat_wxyz(rot.quat_wxyz_to_matrix(QUATS))
    assert np.all(back[:, 0] >= 0)
    assert _same_up_to_sign(back, QUATS / np.linalg.norm(QUATS, axis=1, keepdims=True))


def test_axis_rotations_turn_the_axes_as_expected():
    x, y, z = np.eye(3)
    assert np.allclose(rot.rotation_about(2, math.pi / 2) @ x, y)
    assert np.allclose(rot.rotation_about(0, math.pi / 2) @ y, z)
    assert np.allclose(rot.rotation_about(1, math.pi / 2) @ z, x)
    assert rot.rotation_about(1, np.zeros((2, 5))).shape == (2, 5, 3, 3)


def test_decompose_inverts_composition_keeps_mirrors_and_drops_shear():
    m = _transforms(40)
    t, r, s = rot.decompose(m)
    assert np.allclose(t, m[:, 3, :3])
    assert np.allclose(r @ np.swapaxes(r, 1, 2), np.eye(3), atol=1e-12) and np.allclose(np.linalg.det(r), 1.0)
    clean = slice(0, 10), slice(20, 40)                          # mirrored, and plain
    for rows in clean:
        assert np.allclose(np.swapaxes(r[rows] * s[rows, None, :], 1, 2), m[rows, :3, :3], atol=1e-12)
    assert np.all(s[:10, 0] < 0) and np.all(s[10:, 0] > 0)


def test_look_at_points_minus_z_at_the_target():
    r = rot.look_at_matrix((4.0, -3.0, 2.0), (0.0, 0.0, 0.5))
    forward = np.array([0.0, 0.0, 0.5]) - (4.0, -3.0, 2.0)
    assert np.allclose(r @ (0, 0, -1), forward / np.linalg.norm(forward))
    assert (r @ (0, 1, 0))[2] > 0                                # +Y leans up
    assert np.allclose(r.T @ r, np.eye(3))


def test_zero_quaternions_are_refused():
    with pytest.raises(ValueError, match="non-zero"):
        rot.quat_wxyz_to_matrix((0, 0, 0, 0))
    with pytest.raises(ValueError, match="non-zero"):
        rot.quat_wxyz_to_matrix([(1, 0, 0, 0), (0, 0, 0, 0)])
    with pytest.raises(ValueError, match="must not be zero"):
        rot.unit_quat([(1, 0, 0, 0), (0, 0, 0, 0)])
    with pytest.raises(ValueError, match="rotation_order"):
        rot.euler_to_matrix((0, 0, 0), "XYX")


# ---- one rotation alone gives the bits it gives in a stack --------------------------------------------------
def _bits(a) -> np.ndarray:
    return np.asarray(a, dtype=np.float64).view(np.uint64)


@pytest.mark.parametrize("order", rot.ROTATION_ORDERS)
def test_euler_matrices_alone_equal_stacked_bit_for_bit(order):
    stacked = rot.euler_to_matrix(ANGLES, order)
    for a, r in zip(ANGLES, stacked):
        assert np.array_equal(_bits(rot.euler_to_matrix(a, order)), _bits(r))


def test_conversions_alone_equal_stacked_bit_for_bit():
    mats = np.concatenate([rot.euler_to_matrix(ANGLES), rot.quat_wxyz_to_matrix(QUATS),
                           np.round(rot.euler_to_matrix(ANGLES[-10:]))])     # exact axis permutations too
    mats = np.concatenate([mats, rot.rotation_about(0, np.full(3, math.pi)), np.eye(3)[None]])   # half turn, none
    for one, stacked in ((rot.matrix_to_euler_xyz, rot.matrix_to_euler_xyz(mats)),
                         (rot.matrix_to_quat_wxyz, rot.matrix_to_quat_wxyz(mats)),
                         (rot.matrix_to_rotation_vector, rot.matrix_to_rotation_vector(mats))):
        for m, want in zip(mats, stacked):
            assert np.array_equal(_bits(one(m)), _bits(want)), (one.__name__, m)
    stacked, angles = rot.quat_wxyz_to_matrix(QUATS), rot.quat_wxyz_to_euler_xyz(QUATS)
    assert np.array_equal(_bits(angles), _bits(rot.matrix_to_euler_xyz(stacked)))
    for q, want, want_angles in zip(QUATS, stacked, angles):
        assert np.array_equal(_bits(rot.quat_wxyz_to_matrix(q)), _bits(want))
        assert np.array_equal(_bits(rot.quat_wxyz_to_euler_xyz(q)), _bits(want_angles))


def test_decompose_alone_equals_stacked_bit_for_bit():
    m = _transforms(40)
    stacked = rot.decompose(m)
    for i in range(len(m)):
        for part, want in zip(rot.decompose(m[i]), stacked):
            assert np.array_equal(_bits(part), _bits(want[i]))


def test_stacks_keep_their_leading_axes():
    a = ANGLES[:12].reshape(3, 4, 3)
    assert rot.euler_to_matrix(a).shape == (3, 4, 3, 3)
    assert rot.matrix_to_euler_xyz(rot.euler_to_matrix(a)).shape == (3, 4, 3)
    assert rot.matrix_to_quat_wxyz(rot.euler_to_matrix(a)).shape == (3, 4, 4)
    assert rot.quat_wxyz_to_matrix(QUATS[:12].reshape(3, 4, 4)).shape == (3, 4, 3, 3)
    assert rot.euler_xyz_to_quat(a).shape == (3, 4, 4)
    t, r, s = rot.decompose(_transforms(12).reshape(3, 4, 4, 4))
    assert t.shape == (3, 4, 3) and r.shape == (3, 4, 3, 3) and s.shape == (3, 4, 3)


def test_module_example_runs():
    assert doctest.testmod(rot).failed == 0


def test_maths_imports_nothing_of_graphsdg():
    """stage/, sim/, render/, compat/ and io/ all import the rotations: the folder must sit below all of them."""
    folder = pathlib.Path(rot.__file__).parent
    for path in folder.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            assert not any(n.split(".")[0] == "graphsdg" for n in names), (path.name, names)
