"""Isaac compat area: ``isaacsim.core.utils.numpy`` (tensor, rotations, maths and transformation helpers).

The NumPy backend of Isaac's core API: the deprecated prim views call these
(``view._backend_utils``) and scripts use them directly
(``euler_angles_to_quats``). Quaternions are scalar-first (w, x, y, z);
Euler angles are X, Y, Z, extrinsic (``R = Rz Ry Rx``) unless
``extrinsic=False`` (intrinsic, ``R = Rx Ry Rz``), in radians unless
``degrees=True``. Rotations are computed by :mod:`graphsdg.maths.rotations`
(no SciPy). A ``device`` argument is accepted and ignored, as in Isaac's NumPy
backend.

Example:
    >>> import numpy as np
    >>> from graphsdg.compat.core_numpy import euler_angles_to_quats
    >>> np.round(euler_angles_to_quats(np.array([0.0, 0.0, 90.0]), degrees=True), 6).tolist()
    [0.707107, 0.0, 0.0, 0.707107]
"""
from __future__ import annotations

import types
from typing import Any, Sequence

import numpy as np

from graphsdg.compat.modules import CompatModule
from graphsdg.maths.rotations import (decompose, euler_to_matrix, matrix_to_euler_xyz, matrix_to_quat_wxyz,
                                      matrix_to_rotation_vector, quat_wxyz_to_matrix)

_DTYPES = {"float32": np.float32, "float64": np.float64, "bool": bool, "int32": np.int32, "int64": np.int64,
           "long": np.int64, "uint8": np.uint8}


# ---- tensor ------------------------------------------------------------------------------------------------
def as_type(data: Any, dtype: str) -> np.ndarray:
    """``data`` as a NumPy array of ``dtype`` ("float32", "float64", "bool", "int32", "int64", "long", "uint8")."""
    if dtype not in _DTYPES:
        raise ValueError(f"dtype {dtype!r} is not supported; expected one of {sorted(_DTYPES)}")
    return np.asarray(data).astype(_DTYPES[dtype])


def convert(data: Any, device: Any = None, dtype: str = "float32", indexed: Any = None) -> np.ndarray:
    """``data`` (a list, tuple, array or anything with ``.numpy()``) as a NumPy array of ``dtype``."""
    if hasattr(data, "numpy") and not isinstance(data, np.ndarray):
        data = data.numpy()
    return as_type(np.asarray(data), dtype)


def create_zeros_tensor(shape: Sequence[int], dtype: str, device: Any = None) -> np.ndarray:
    """A zero-filled array of ``shape`` and ``dtype``."""
    return as_type(np.zeros(shape), dtype)


def create_tensor_from_list(data: Sequence, dtype: str, device: Any = None) -> np.ndarray:
    """``data`` as an array of ``dtype``."""
    return as_type(np.array(data), dtype)


def clone_tensor(data: np.ndarray, device: Any = None) -> np.ndarray:
    """A copy of ``data``."""
    return np.copy(data)


def resolve_indices(indices: Any, count: int, device: Any = None) -> np.ndarray:
    """``indices`` as an int64 array (``arange(count)`` when None); raises IndexError naming any out of range."""
    if indices is None:
        return np.arange(count)
    if hasattr(indices, "numpy") and not isinstance(indices, np.ndarray):
        indices = indices.numpy()
    result = np.atleast_1d(np.asarray(indices)).astype(np.int64).reshape(-1)
    bad = [int(i) for i in result if not -count <= i < count]
    if bad:
        raise IndexError(f"indices {bad} are out of range for a view of {count} prims")
    return result


def move_data(data: Any, device: Any = None) -> Any:
    """``data`` unchanged (NumPy has one device)."""
    return data


def tensor_cat(data: Sequence[np.ndarray], device: Any = None, dim: int = -1) -> np.ndarray:
    """Arrays joined along axis ``dim``."""
    return np.concatenate(data, axis=dim)


def expand_dims(data: Any, axis: int) -> np.ndarray:
    """``data`` with a new axis at ``axis``."""
    return np.expand_dims(data, axis)


def pad(data: np.ndarray, pad_width: Any, mode: str = "constant", value: Any = None) -> np.ndarray:
    """``np.pad``; ``value`` is the constant (mode "constant") or the end value (mode "linear_ramp")."""
    if mode == "constant" and value is not None:
        return np.pad(data, pad_width, mode, constant_values=value)
    if mode == "linear_ramp" and value is not None:
        return np.pad(data, pad_width, mode, end_values=value)
    return np.pad(data, pad_width, mode)


def tensor_stack(data: Sequence[np.ndarray], dim: int = 0) -> np.ndarray:
    """Arrays stacked along a new axis ``dim``."""
    return np.stack(data, axis=dim)


def to_list(data: Any) -> list:
    """``data`` as a (nested) Python list."""
    if isinstance(data, list):
        return data
    return np.asarray(data).tolist()


def to_numpy(data: Any) -> np.ndarray:
    """``data`` as a NumPy array."""
    return np.asarray(data)


def assign(src: Any, dst: np.ndarray, indices: Any) -> np.ndarray:
    """``dst[indices] = src`` (a list of index arrays indexes several axes); returns ``dst``."""
    dst[tuple(indices) if isinstance(indices, list) else indices] = src
    return dst


# ---- maths -------------------------------------------------------------------------------------------------
def matmul(matrix_a: np.ndarray, matrix_b: np.ndarray) -> np.ndarray:
    """The matrix product ``a @ b``."""
    return np.matmul(matrix_a, matrix_b)


def sin(data: Any) -> np.ndarray:
    """Element-wise sine."""
    return np.sin(data)


def cos(data: Any) -> np.ndarray:
    """Element-wise cosine."""
    return np.cos(data)


def transpose_2d(data: np.ndarray) -> np.ndarray:
    """The transpose of a 1-D or 2-D array; raises ValueError for more dimensions."""
    arr = np.asarray(data)
    if arr.ndim > 2:
        raise ValueError(f"transpose_2d expects a 1-D or 2-D array, got a {arr.ndim}-D array")
    return np.transpose(arr)


def inverse(data: np.ndarray) -> np.ndarray:
    """The matrix inverse."""
    return np.linalg.inv(data)


# ---- rotations ---------------------------------------------------------------------------------------------
def gf_quat_to_tensor(orientation: Any, device: Any = None) -> np.ndarray:
    """A ``Gf.Quat*`` / ``Gf.Quaternion`` as (w, x, y, z)."""
    return np.array([orientation.GetReal(), *orientation.GetImaginary()], dtype=np.float64)


def _euler_matrices(euler_angles: Any, degrees: bool, extrinsic: bool) -> np.ndarray:
    angles = np.asarray(euler_angles, dtype=np.float64)
    if angles.shape[-1:] != (3,):
        raise ValueError(f"euler angles must have shape (3,) or (N, 3), got {angles.shape}")
    degs = angles if degrees else np.degrees(angles)
    # euler_to_matrix applies its order's first axis first: "XYZ" is Rz Ry Rx, "ZYX" is Rx Ry Rz
    return euler_to_matrix(degs, "XYZ" if extrinsic else "ZYX")


def euler_angles_to_quats(euler_angles: Any, degrees: bool = False, extrinsic: bool = True,
                          device: Any = None) -> np.ndarray:
    """(N, 3) or (3,) X, Y, Z Euler angles -> (N, 4) or (4,) unit quaternions (w, x, y, z), w >= 0."""
    return matrix_to_quat_wxyz(_euler_matrices(euler_angles, degrees, extrinsic))


def _matrices_to_euler(r: np.ndarray, degrees: bool, extrinsic: bool) -> np.ndarray:
    if extrinsic:
        angles = matrix_to_euler_xyz(r)
    else:   # R = Rx(a) Ry(b) Rz(c), so R^T = Rz(-c) Ry(-b) Rx(-a): extrinsic angles of the transpose, negated
        angles = -matrix_to_euler_xyz(np.swapaxes(r, -1, -2))
    return angles if degrees else np.radians(angles)


def quats_to_euler_angles(quaternions: Any, degrees: bool = False, extrinsic: bool = True,
                          device: Any = None) -> np.ndarray:
    """X, Y, Z Euler angles of (N, 4) or (4,) quaternions (w, x, y, z): the inverse of
    :func:`euler_angles_to_quats`."""
    return _matrices_to_euler(quat_wxyz_to_matrix(_quats(quaternions)), degrees, extrinsic)


def rot_matrices_to_quats(rotation_matrices: Any, device: Any = None) -> np.ndarray:
    """(N, 3, 3) or (3, 3) rotation matrices -> unit quaternions (w, x, y, z), w >= 0."""
    m = np.asarray(rotation_matrices, dtype=np.float64)
    if m.shape[-2:] != (3, 3):
        raise ValueError(f"rotation matrices must have shape (3, 3) or (N, 3, 3), got {m.shape}")
    return matrix_to_quat_wxyz(m)


def quats_to_rot_matrices(quaternions: Any, device: Any = None) -> np.ndarray:
    """(N, 4) or (4,) quaternions (w, x, y, z) -> (N, 3, 3) or (3, 3) rotation matrices."""
    return quat_wxyz_to_matrix(_quats(quaternions))


def rotvecs_to_quats(rotation_vectors: Any, degrees: bool = False, device: Any = None) -> np.ndarray:
    """(N, 3) or (3,) rotation vectors (axis times angle) -> unit quaternions (w, x, y, z)."""
    v = np.asarray(rotation_vectors, dtype=np.float64)
    if v.shape[-1:] != (3,):
        raise ValueError(f"rotation vectors must have shape (3,) or (N, 3), got {v.shape}")
    if degrees:
        v = np.radians(v)
    angle = np.linalg.norm(v, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(angle / 2) / angle, with its limit 1/2 at angle 0
    scale = np.where(angle > 1e-12, np.sin(half) / np.where(angle > 1e-12, angle, 1.0), 0.5)
    return np.concatenate([np.cos(half), v * scale], axis=-1)


def quats_to_rotvecs(quaternions: Any, device: Any = None) -> np.ndarray:
    """(N, 4) or (4,) quaternions (w, x, y, z) -> rotation vectors (axis times angle in radians, angle <= pi)."""
    return matrix_to_rotation_vector(quat_wxyz_to_matrix(_quats(quaternions)))


def rad2deg(radian_value: Any, device: Any = None) -> np.ndarray:
    """Radians to degrees."""
    return np.rad2deg(radian_value)


def deg2rad(degree_value: Any, device: Any = None) -> np.ndarray:
    """Degrees to radians."""
    return np.deg2rad(degree_value)


def xyzw2wxyz(q: Any, ret_torch: bool = False) -> np.ndarray:
    """Quaternions (x, y, z, w) -> (w, x, y, z)."""
    return np.roll(np.asarray(q), 1, -1)


def wxyz2xyzw(q: Any, ret_torch: bool = False) -> np.ndarray:
    """Quaternions (w, x, y, z) -> (x, y, z, w)."""
    return np.roll(np.asarray(q), -1, -1)


def _quats(quaternions: Any) -> np.ndarray:
    q = np.asarray(quaternions, dtype=np.float64)
    if q.shape[-1:] != (4,):
        raise ValueError(f"quaternions must have shape (4,) or (N, 4) (w, x, y, z), got {q.shape}")
    return q


# ---- transformations ---------------------------------------------------------------------------------------
def tf_matrices_from_poses(translations: Any, orientations: Any, device: Any = None) -> np.ndarray:
    """(N, 4, 4) column-vector transforms (translation in the last column) of (N, 3) translations and (N, 4)
    quaternions (w, x, y, z), as float32."""
    t = np.asarray(translations, dtype=np.float64).reshape(-1, 3)
    q = _quats(orientations).reshape(-1, 4)
    result = np.zeros((q.shape[0], 4, 4), dtype=np.float32)
    result[:, :3, :3] = quat_wxyz_to_matrix(q)
    result[:, :3, 3] = t
    result[:, 3, 3] = 1.0
    return result


def _pose_of(matrix_column: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Translation and unit quaternion of one column-vector 4x4 (its scale divided out)."""
    t, r, _ = decompose(np.asarray(matrix_column, dtype=np.float64).T)
    return t, matrix_to_quat_wxyz(r)


def get_local_from_world(parent_transforms: Any, positions: Any, orientations: Any,
                         device: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """Local (translations, orientations) under parents whose row-vector world transforms
    (``UsdGeom.Xformable.ComputeLocalToWorldTransform`` as arrays, (N, 4, 4)) are given, for world poses."""
    parents = np.asarray(parent_transforms, dtype=np.float64).reshape(-1, 4, 4)
    world = tf_matrices_from_poses(positions, orientations).astype(np.float64)
    translations = np.zeros((world.shape[0], 3), dtype=np.float32)
    quats = np.zeros((world.shape[0], 4), dtype=np.float32)
    for i in range(world.shape[0]):
        translations[i], quats[i] = _pose_of(np.linalg.inv(parents[i].T) @ world[i])
    return translations, quats


def get_world_from_local(parent_transforms: Any, translations: Any, orientations: Any,
                         device: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """World (positions, orientations) of local poses under parents with row-vector world transforms (N, 4, 4)."""
    parents = np.asarray(parent_transforms, dtype=np.float64).reshape(-1, 4, 4)
    local = tf_matrices_from_poses(translations, orientations).astype(np.float64)
    positions = np.zeros((local.shape[0], 3), dtype=np.float32)
    quats = np.zeros((local.shape[0], 4), dtype=np.float32)
    for i in range(local.shape[0]):
        positions[i], quats[i] = _pose_of(parents[i].T @ local[i])
    return positions, quats


def get_pose(positions: Any, orientations: Any, device: Any = None) -> np.ndarray:
    """(N, 7) poses: positions then orientations."""
    return np.concatenate([np.asarray(positions), np.asarray(orientations)], axis=-1)


def assign_pose(current_positions: np.ndarray, current_orientations: np.ndarray, positions: Any,
                orientations: Any, indices: Any, device: Any = None, pose: Any = None) -> np.ndarray:
    """(N, 7) poses (position, quaternion x, y, z, w: PhysX's tensor layout) with rows ``indices`` replaced."""
    positions = current_positions[indices] if positions is None else np.asarray(positions)
    orientations = current_orientations[indices] if orientations is None else np.asarray(orientations)
    old = get_pose(current_positions, wxyz2xyzw(current_orientations))
    old[indices] = get_pose(positions, wxyz2xyzw(orientations))
    return old


_TENSOR = dict(as_type=as_type, convert=convert, create_zeros_tensor=create_zeros_tensor,
               create_tensor_from_list=create_tensor_from_list, clone_tensor=clone_tensor,
               resolve_indices=resolve_indices, move_data=move_data, tensor_cat=tensor_cat, expand_dims=expand_dims,
               pad=pad, tensor_stack=tensor_stack, to_list=to_list, to_numpy=to_numpy, assign=assign)
_MATHS = dict(matmul=matmul, sin=sin, cos=cos, transpose_2d=transpose_2d, inverse=inverse)
_ROTATIONS = dict(gf_quat_to_tensor=gf_quat_to_tensor, euler_angles_to_quats=euler_angles_to_quats,
                  quats_to_euler_angles=quats_to_euler_angles, rot_matrices_to_quats=rot_matrices_to_quats,
                  quats_to_rot_matrices=quats_to_rot_matrices, rotvecs_to_quats=rotvecs_to_quats,
                  quats_to_rotvecs=quats_to_rotvecs, rad2deg=rad2deg, deg2rad=deg2rad, xyzw2wxyz=xyzw2wxyz,
                  wxyz2xyzw=wxyz2xyzw)
_TRANSFORMATIONS = dict(tf_matrices_from_poses=tf_matrices_from_poses, get_local_from_world=get_local_from_world,
                        get_world_from_local=get_world_from_local, get_pose=get_pose, assign_pose=assign_pose)


def backend_utils() -> types.SimpleNamespace:
    """Every function of the NumPy backend in one namespace (what Isaac's views hold as ``_backend_utils``)."""
    return types.SimpleNamespace(**_TENSOR, **_MATHS, **_ROTATIONS, **_TRANSFORMATIONS)


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.numpy`` and its ``tensor``, ``maths``, ``rotations`` and ``transformations``."""
    parts = {"tensor": _TENSOR, "maths": _MATHS, "rotations": _ROTATIONS, "transformations": _TRANSFORMATIONS}
    subs = [CompatModule(f"isaacsim.core.utils.numpy.{name}", **names) for name, names in parts.items()]
    everything = {k: v for names in parts.values() for k, v in names.items()}
    return [CompatModule("isaacsim.core.utils.numpy", **everything), *subs]
