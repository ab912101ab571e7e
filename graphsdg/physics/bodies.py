"""World poses and velocities of rigid bodies (Isaac's ``RigidPrim``).

A :class:`RigidBodyView` names one or more prims with ``UsdPhysics.RigidBodyAPI``
(paths, prims, or a regular expression over rigid-body paths) and reads or
writes their simulated state. Quaternions are (w, x, y, z); velocities are in the
world frame, angular in rad/s.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.physics.bodies import RigidBodyView
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(position=(0, 0, 2))
    >>> rep.functional.physics.apply_rigid_body(cube)
    >>> view = RigidBodyView(str(cube.GetPath()))
    >>> positions, orientations = view.get_world_poses()
    >>> positions.tolist(), orientations.tolist()
    ([[0.0, 0.0, 2.0]], [[1.0, 0.0, 0.0, 0.0]])
"""
from __future__ import annotations

import re
from typing import Iterable, Sequence

import numpy as np
from pxr import Sdf, Usd, UsdPhysics

from graphsdg.engine.runtime import runtime
from graphsdg.sim.rigid_bodies import rigid_root
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import PrimLike
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz
from graphsdg.stage.xform import world_matrix


def _rigid_paths(stage: Usd.Stage) -> list[str]:
    return [str(p.GetPath()) for p in stage.Traverse() if p.HasAPI(UsdPhysics.RigidBodyAPI)]


def _resolve(paths: PrimLike | Iterable[PrimLike]) -> list[str]:
    stage = get_stage()
    items = [paths] if isinstance(paths, (str, Sdf.Path, Usd.Prim)) else list(paths)
    if not items:
        raise ValueError("RigidBodyView needs at least one rigid-body path")
    out: list[str] = []
    for item in items:
        if isinstance(item, Usd.Prim):
            item = item.GetPath()
        text = str(item)
        prim = stage.GetPrimAtPath(text) if Sdf.Path.IsValidPathString(text) else Usd.Prim()
        if prim and prim.IsValid():
            if rigid_root(prim) is None:
                raise ValueError(f"prim {text} is not a rigid body (no enabled UsdPhysics.RigidBodyAPI on it or "
                                 f"above it); apply rep.functional.physics.apply_rigid_body first")
            out.append(text)
            continue
        pattern = re.compile(text)
        matched = [p for p in _rigid_paths(stage) if pattern.fullmatch(p)]
        if not matched:
            raise ValueError(f"{text!r} names no prim and, as a regular expression, matches no rigid body "
                             f"on the stage")
        out += matched
    return out


class RigidBodyView:
    """Simulated state of a set of rigid bodies (see the module docstring)."""

    def __init__(self, paths: PrimLike | Iterable[PrimLike]) -> None:
        self.paths: list[str] = _resolve(paths)

    def __len__(self) -> int:
        return len(self.paths)

    @property
    def count(self) -> int:
        return len(self.paths)

    def _select(self, indices: Sequence[int] | np.ndarray | None) -> list[str]:
        if indices is None:
            return list(self.paths)
        idx = np.atleast_1d(np.asarray(indices, dtype=np.int64))
        bad = [int(i) for i in idx if not -len(self.paths) <= i < len(self.paths)]
        if bad:
            raise IndexError(f"indices {bad} out of range for a view of {len(self.paths)} bodies")
        return [self.paths[int(i)] for i in idx]

    @staticmethod
    def _sim():
        sim = runtime().sim
        sim.sync_dirty_prims()
        return sim

    def _root(self, path: str) -> str:
        root = rigid_root(get_stage().GetPrimAtPath(path))
        if root is None:
            raise ValueError(f"prim {path} is no longer a rigid body")
        return str(root.GetPath())

    def get_world_poses(self, indices: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(positions (k, 3), orientations (k, 4) w, x, y, z) of the selected bodies."""
        sim = self._sim()
        pos, quat = [], []
        for path in self._select(indices):
            root = self._root(path)
            if root == path:
                p, q = sim.body_pose(path)
            else:   # a body folded into an outer one: where the stage says it is
                t, r, _ = decompose(world_matrix(get_stage().GetPrimAtPath(path)))
                p, q = t, matrix_to_quat_wxyz(r)
            pos.append(p)
            quat.append(q)
        return np.array(pos, dtype=np.float64).reshape(-1, 3), np.array(quat, dtype=np.float64).reshape(-1, 4)

    def set_world_poses(self, positions: np.ndarray | None = None, orientations: np.ndarray | None = None,
                        indices: Sequence[int] | None = None) -> None:
        """Move the selected bodies (velocities kept); (k, 3) positions, (k, 4) quaternions."""
        paths = self._select(indices)
        pos = None if positions is None else np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        quat = None if orientations is None else np.asarray(orientations, dtype=np.float64).reshape(-1, 4)
        for name, arr in (("positions", pos), ("orientations", quat)):
            if arr is not None and len(arr) != len(paths):
                raise ValueError(f"{name} has {len(arr)} rows for {len(paths)} selected bodies")
        sim = self._sim()
        for i, path in enumerate(paths):
            if self._root(path) != path:
                raise ValueError(f"{path} moves with the rigid body {self._root(path)} it is nested in; "
                                 f"set that body's pose instead")
            sim.set_body_pose(path, None if pos is None else pos[i], None if quat is None else quat[i])

    def get_velocities(self, indices: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(linear (k, 3) m/s, angular (k, 3) rad/s), world frame, at each body's origin."""
        sim = self._sim()
        lin, ang = [], []
        for path in self._select(indices):
            root = self._root(path)
            v, w = sim.body_velocity(root)
            if root != path:
                offset = world_matrix(get_stage().GetPrimAtPath(path))[3, :3] - sim.body_pose(root)[0]
                v = v + np.cross(w, offset)
            lin.append(v)
            ang.append(w)
        return np.array(lin).reshape(-1, 3), np.array(ang).reshape(-1, 3)

    def get_linear_velocities(self, indices: Sequence[int] | None = None) -> np.ndarray:
        return self.get_velocities(indices)[0]

    def get_angular_velocities(self, indices: Sequence[int] | None = None) -> np.ndarray:
        return self.get_velocities(indices)[1]

    def set_velocities(self, linear: np.ndarray | None = None, angular: np.ndarray | None = None,
                       indices: Sequence[int] | None = None) -> None:
        """Set world-frame linear (k, 3) and angular (k, 3, rad/s) velocities of dynamic bodies."""
        paths = self._select(indices)
        lin = None if linear is None else np.asarray(linear, dtype=np.float64).reshape(-1, 3)
        ang = None if angular is None else np.asarray(angular, dtype=np.float64).reshape(-1, 3)
        for name, arr in (("linear", lin), ("angular", ang)):
            if arr is not None and len(arr) != len(paths):
                raise ValueError(f"{name} velocities have {len(arr)} rows for {len(paths)} selected bodies")
        sim = self._sim()
        for i, path in enumerate(paths):
            sim.set_body_velocity(self._root(path), None if lin is None else lin[i], None if ang is None else ang[i])

    def get_masses(self, indices: Sequence[int] | None = None) -> np.ndarray:
        """Simulated mass (kg) of each selected body's root."""
        sim = self._sim()
        return np.array([float(sim.model.body_mass[sim.body(self._root(p)).body_id]) for p in self._select(indices)])
