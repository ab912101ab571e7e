"""Isaac compat area: ``isaacsim.core.utils.transformations``, ``.mesh``, ``.random``, ``.distance_metrics``,
``.math`` and ``.constants`` (also reached as ``omni.isaac.core.utils.*``).

Matrices follow Isaac's convention: 4x4 NumPy arrays acting on column vectors
(the translation in the last column), i.e. the transpose of USD's row-vector
``Gf.Matrix4d``. Quaternions are (w, x, y, z).

* ``transformations``: ``tf_matrix_from_pose`` / ``pose_from_tf_matrix``
  (through ``Gf.Transform``, as Isaac), ``tf_matrices_from_poses`` (the NumPy
  backend's, float32), ``get_relative_transform(source, target)`` (source frame
  to target frame, from the prims' world transforms at the default time),
  ``get_translation_from_target``, ``get_world_pose_from_relative``,
  ``get_transform_with_normalized_rotation`` (scale divided out of the rotation
  columns).
* ``mesh.get_mesh_vertices_relative_to(mesh, coord_prim)``: the mesh's points in
  the other prim's frame, in metres (times the stage's metres per unit).
* ``random``: poses in a camera's view, drawn with Python's ``random`` module as
  Isaac draws them (``random.seed`` reproduces Isaac's draws).
* ``distance_metrics``: translational and rotational distances of 4x4 / 3x3
  matrices (``Gf`` matrices are transposed first, as Isaac does).

Example:
    >>> import numpy as np
    >>> from pxr import UsdGeom
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> a = rep.functional.create.xform(name="A", position=(1, 0, 0))
    >>> b = rep.functional.create.xform(name="B", position=(0, 2, 0), rotation=(0, 0, 90))
    >>> np.round(get_translation_from_target(np.zeros(3), a, b), 6).tolist()   # A's origin seen from B
    [-2.0, -1.0, 0.0]
    >>> t, q = pose_from_tf_matrix(tf_matrix_from_pose([1, 2, 3], [0.0, 0.0, 0.0, 1.0]))
    >>> t.tolist(), np.round(np.abs(q), 6).tolist()
    ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0, 1.0])
"""
from __future__ import annotations

import copy
import math
import random as _random
import types
from collections.abc import Sequence
from typing import Any

import numpy as np
from pxr import Gf, Usd, UsdGeom

from graphsdg.compat import core_numpy
from graphsdg.compat.core_utils import euler_angles_to_quat, get_stage_units, gf_quat_to_np_array
from graphsdg.compat.modules import CompatModule


# ---- transformations ---------------------------------------------------------------------------------------------
def tf_matrix_from_pose(translation: Sequence[float], orientation: Sequence[float]) -> np.ndarray:
    """The 4x4 (column-vector) transform of a translation and a quaternion (w, x, y, z; normalised)."""
    translation = np.asarray(translation, dtype=np.float64)
    orientation = np.asarray(orientation, dtype=np.float64)
    mat = Gf.Transform()
    mat.SetRotation(Gf.Rotation(Gf.Quatd(*orientation.tolist())))
    mat.SetTranslation(Gf.Vec3d(*translation.tolist()))
    return np.transpose(np.array(mat.GetMatrix()))


def pose_from_tf_matrix(transformation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(translation (3,), quaternion (w, x, y, z) (4,)) of a 4x4 column-vector transform."""
    mat = Gf.Transform()
    mat.SetMatrix(Gf.Matrix4d(np.transpose(np.asarray(transformation, dtype=np.float64)).tolist()))
    return np.array(mat.GetTranslation()), gf_quat_to_np_array(mat.GetRotation().GetQuat())


def tf_matrices_from_poses(translations: Any, orientations: Any) -> np.ndarray:
    """(N, 4, 4) float32 transforms of (N, 3) translations and (N, 4) quaternions (the NumPy backend's)."""
    return core_numpy.tf_matrices_from_poses(translations, orientations)


def _world_column(prim: Usd.Prim) -> np.ndarray:
    row = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
    return np.transpose(np.array(row))


def get_relative_transform(source_prim: Usd.Prim, target_prim: Usd.Prim) -> np.ndarray:
    """The 4x4 transform from ``source_prim``'s frame to ``target_prim``'s (column vectors)."""
    return np.linalg.inv(_world_column(target_prim)) @ _world_column(source_prim)


def get_translation_from_target(translation_from_source: np.ndarray, source_prim: Usd.Prim,
                                target_prim: Usd.Prim) -> np.ndarray:
    """A point given in ``source_prim``'s frame, expressed in ``target_prim``'s frame (3,)."""
    homogeneous = np.pad(np.asarray(translation_from_source, dtype=np.float64), (0, 1), constant_values=1.0)
    return (homogeneous @ np.transpose(get_relative_transform(source_prim, target_prim)))[:-1]


def get_world_pose_from_relative(coord_prim: Usd.Prim, relative_translation: np.ndarray,
                                 relative_orientation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The world pose of a pose given relative to ``coord_prim``'s frame: (position, quaternion (w, x, y, z))."""
    relative = tf_matrix_from_pose(relative_translation, relative_orientation)
    return pose_from_tf_matrix(_world_column(coord_prim) @ relative)


def get_transform_with_normalized_rotation(transform: np.ndarray) -> np.ndarray:
    """``transform`` with each rotation column divided by its length (scale removed; zero columns kept)."""
    transform = np.asarray(transform)
    result = np.copy(transform.astype(float))
    rotation = transform[:3, :3]
    magnitudes = np.linalg.norm(rotation, axis=0)
    magnitudes = np.where(magnitudes == 0, 1.0, magnitudes)
    result[:3, :3] = rotation / magnitudes
    return result


# ---- mesh --------------------------------------------------------------------------------------------------------
def get_mesh_vertices_relative_to(mesh_prim: Any, coord_prim: Usd.Prim) -> np.ndarray:
    """The mesh's points in ``coord_prim``'s frame, in metres (N, 3); (0, 3) when it has none."""
    prim = mesh_prim.GetPrim() if isinstance(mesh_prim, UsdGeom.Mesh) else mesh_prim
    points = UsdGeom.Mesh(prim).GetPointsAttr().Get()
    if points is None:
        return np.empty((0, 3), dtype=np.float64)
    homogeneous = np.pad(np.array(points, dtype=np.float64), ((0, 0), (0, 1)), constant_values=1.0)
    relative = homogeneous @ np.transpose(get_relative_transform(prim, coord_prim))
    return relative[:, :-1] * get_stage_units()


# ---- random ------------------------------------------------------------------------------------------------------
def get_random_values_in_range(min_range: np.ndarray, max_range: np.ndarray) -> np.ndarray:
    """One ``random.uniform(lo, hi)`` per element pair."""
    return np.array([_random.uniform(lo, hi) for lo, hi in zip(min_range, max_range)])


def get_random_translation_from_camera(min_distance: float, max_distance: float, fov_x: float, fov_y: float,
                                       fraction_to_screen_edge: float) -> np.ndarray:
    """A random point in the camera's frame (looking down -Z) within the given fraction of its field of view."""
    distance = _random.uniform(min_distance, max_distance)
    max_x = distance * math.tan(fraction_to_screen_edge * fov_x / 2.0)
    max_y = distance * math.tan(fraction_to_screen_edge * fov_y / 2.0)
    x = _random.uniform(-max_x, max_x)
    y = _random.uniform(-max_y, max_y)
    return np.array([x, y, -distance])


def get_random_world_pose_in_view(camera_prim: Usd.Prim, min_distance: float, max_distance: float, fov_x: float,
                                  fov_y: float, fraction_to_screen_edge: float, coord_prim: Usd.Prim,
                                  min_rotation_range: np.ndarray,
                                  max_rotation_range: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A world pose in the camera's view, its orientation random XYZ Euler angles (degrees) in ``coord_prim``'s
    frame: (position, quaternion (w, x, y, z))."""
    from_camera = get_random_translation_from_camera(min_distance, max_distance, fov_x, fov_y,
                                                     fraction_to_screen_edge)
    from_prim = get_translation_from_target(from_camera, camera_prim, coord_prim)
    rotation = get_random_values_in_range(min_rotation_range, max_rotation_range)
    return get_world_pose_from_relative(coord_prim, from_prim, euler_angles_to_quat(rotation, degrees=True))


# ---- distance_metrics --------------------------------------------------------------------------------------------
def _transform_matrix(t: Any) -> np.ndarray:
    if np.shape(t) != (4, 4):
        raise ValueError(f"Input transformation matrix has the wrong shape: {np.shape(t)} != (4, 4).")
    return np.array(t).T if isinstance(t, Gf.Matrix4d) else np.array(t)


def _rotation_matrix(r: Any) -> np.ndarray:
    if np.shape(r) == (4, 4):
        return _transform_matrix(r)[:3, :3]
    if np.shape(r) != (3, 3):
        raise ValueError(f"Rotation matrix has the wrong shape: {np.shape(r)} != (3, 3).")
    return np.array(r).T if isinstance(r, Gf.Matrix3d) else np.array(r)


def _translation_vector(t: Any) -> np.ndarray:
    if np.shape(t) == (4, 4):
        return _transform_matrix(t)[:3, 3].flatten()
    t = np.array(t).flatten()
    if t.shape != (3,):
        raise ValueError(f"Translation vector has the wrong shape: {np.shape(t)} != (3,).")
    return t


def weighted_translational_distance(t1: Any, t2: Any, weight_matrix: np.ndarray = np.eye(3)) -> np.ndarray:
    """``sqrt(x^T W x)`` of ``x = t1 - t2`` (translations or the translations of 4x4 transforms)."""
    x = _translation_vector(t1) - _translation_vector(t2)
    return np.sqrt(x.T @ weight_matrix @ x)


def rotational_distance_angle(r1: Any, r2: Any) -> np.ndarray:
    """The angle (radians) of the rotation from ``r1`` to ``r2``."""
    r1, r2 = _rotation_matrix(r1), _rotation_matrix(r2)
    return np.arccos(np.clip((np.trace(r1 @ r2.T) - 1) / 2, -1, 1))


def rotational_distance_identity_matrix_deviation(r1: Any, r2: Any) -> np.ndarray:
    """The Frobenius norm of ``I - r1 r2^T``."""
    r1, r2 = _rotation_matrix(r1), _rotation_matrix(r2)
    return np.linalg.norm(np.eye(3) - r1 @ r2.T)


def rotational_distance_single_axis(r1: Any, r2: Any, axis: np.ndarray) -> np.ndarray:
    """The angle between ``r1 axis`` and ``r2 axis`` (``axis`` normalised; a zero axis raises ValueError)."""
    r1, r2 = _rotation_matrix(r1), _rotation_matrix(r2)
    if len(axis) != 3:
        raise ValueError(f"Rotation axis has the wrong shape: {len(axis)} != 3.")
    axis = np.array(axis, dtype=float)
    norm = np.linalg.norm(axis)
    if norm == 0:
        raise ValueError("Rotation axis has zero magnitude.")
    axis = axis / norm
    return np.arccos(np.clip(np.dot(r1 @ axis, r2 @ axis), -1, 1))


# ---- math --------------------------------------------------------------------------------------------------------
def radians_to_degrees(rad_angles: np.ndarray) -> np.ndarray:
    """Degrees of radians."""
    return rad_angles * (180.0 / np.pi)


def cross(a: Any, b: Any) -> np.ndarray:
    """The cross product of two 3-vectors."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def normalize(v: np.ndarray) -> np.ndarray:
    """Normalise ``v`` in place (a zero vector stays) and return it."""
    norm = np.linalg.norm(v)
    if norm == 0:
        return v
    v /= norm
    return v


def normalized(v: np.ndarray | None) -> np.ndarray | None:
    """A normalised copy of ``v`` (None stays None)."""
    return None if v is None else normalize(copy.deepcopy(v))


# ---- constants ---------------------------------------------------------------------------------------------------
AXES_INDICES = {"X": 0, "x": 0, "Y": 1, "y": 1, "Z": 2, "z": 2}
AXES_TOKEN = {"X": UsdGeom.Tokens.x, "x": UsdGeom.Tokens.x, "Y": UsdGeom.Tokens.y, "y": UsdGeom.Tokens.y,
              "Z": UsdGeom.Tokens.z, "z": UsdGeom.Tokens.z}


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.transformations``, ``.mesh``, ``.random``, ``.distance_metrics``, ``.math``,
    ``.constants``."""
    return [
        CompatModule("isaacsim.core.utils.transformations", tf_matrix_from_pose=tf_matrix_from_pose,
                     pose_from_tf_matrix=pose_from_tf_matrix, tf_matrices_from_poses=tf_matrices_from_poses,
                     get_relative_transform=get_relative_transform,
                     get_translation_from_target=get_translation_from_target,
                     get_world_pose_from_relative=get_world_pose_from_relative,
                     get_transform_with_normalized_rotation=get_transform_with_normalized_rotation),
        CompatModule("isaacsim.core.utils.mesh", get_mesh_vertices_relative_to=get_mesh_vertices_relative_to),
        CompatModule("isaacsim.core.utils.random", get_random_values_in_range=get_random_values_in_range,
                     get_random_translation_from_camera=get_random_translation_from_camera,
                     get_random_world_pose_in_view=get_random_world_pose_in_view),
        CompatModule("isaacsim.core.utils.distance_metrics",
                     weighted_translational_distance=weighted_translational_distance,
                     rotational_distance_angle=rotational_distance_angle,
                     rotational_distance_identity_matrix_deviation=rotational_distance_identity_matrix_deviation,
                     rotational_distance_single_axis=rotational_distance_single_axis),
        CompatModule("isaacsim.core.utils.math", radians_to_degrees=radians_to_degrees, cross=cross,
                     normalize=normalize, normalized=normalized),
        CompatModule("isaacsim.core.utils.constants", AXES_INDICES=AXES_INDICES, AXES_TOKEN=AXES_TOKEN),
    ]
