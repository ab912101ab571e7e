"""PhysX's tensor view of rigid bodies (``omni.physics.tensors`` ``RigidBodyView``) on the MuJoCo model.

One row per rigid body of a :class:`~graphsdg.physics.bodies.RigidBodyView`:
transforms (N, 7: x, y, z and a quaternion x, y, z, w, PhysX's order),
velocities (N, 6: linear, angular, world frame), masses (N, 1), inertias (N, 9),
and per collision shape (:mod:`graphsdg.physics.shape_properties`) material
properties (N, S, 3) and contact / rest offsets (N, S). Setters take the full
(N, ...) table and the ``indices`` of the rows to write, as PhysX's do (a table
of only the selected rows is accepted too). What they write reaches MuJoCo's
``MjModel`` / ``MjData`` at once and lasts across recompiles.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> _ = rep.stage.new_stage()
    >>> box = rep.functional.create.cube(position=(0, 0, 1), name="Box")
    >>> rep.functional.physics.apply_collider(box); rep.functional.physics.apply_rigid_body(box)
    >>> view = RigidBodyTensorView("/Box")
    >>> view.set_masses(np.array([[2.5]]), np.array([0]))
    >>> float(runtime().sim.model.body_mass[1])
    2.5
"""
from __future__ import annotations

from typing import Iterable, Sequence

import numpy as np

from graphsdg.maths.rotations import quat_wxyz_to_matrix
from graphsdg.physics import body_properties
from graphsdg.physics.bodies import RigidBodyView
from graphsdg.physics.forces import apply_force_at_pos
from graphsdg.physics.shape_properties import ShapeTable
from graphsdg.engine.runtime import runtime
from graphsdg.sim.scene import SimScene
from graphsdg.stage.prims import PrimLike


def row_indices(indices: Sequence[int] | np.ndarray | None, count: int) -> np.ndarray:
    """``indices`` as an int array of rows of a ``count``-row view (every row when None); out of range raises."""
    if indices is None:
        return np.arange(count)
    idx = np.atleast_1d(np.asarray(indices)).astype(np.int64).reshape(-1)
    bad = idx[(idx < 0) | (idx >= count)]
    if bad.size:
        raise IndexError(f"indices {bad.tolist()} out of range for a view of {count} rows")
    return idx


def selected_rows(data: np.ndarray, idx: np.ndarray, count: int, width: int, what: str,
                  finite: bool = True) -> np.ndarray:
    """The rows of ``data`` for the selected ``idx``: (len(idx), width) from a full (count, ...) table or from
    one of only the selected rows; ``finite`` False lets infinities through (limits), never NaN."""
    arr = np.asarray(data, dtype=np.float64)
    flat = arr.reshape(-1, width) if arr.size % width == 0 else None
    if flat is None:
        raise ValueError(f"{what}: expected {width} value(s) a row, got shape {arr.shape}")
    if flat.shape[0] == count:      # a full table (PhysX's form): the selected rows of it
        flat = flat[idx]
    elif flat.shape[0] != len(idx):
        raise ValueError(f"{what}: expected {count} rows (every row) or {len(idx)} (the selected ones), got "
                         f"{flat.shape[0]}")
    if np.any(np.isnan(flat)) or (finite and not np.all(np.isfinite(flat))):
        raise ValueError(f"{what}: values must be {'finite' if finite else 'numbers'}, got {arr.tolist()}")
    return flat


class RigidBodyTensorView:
    """Tensor-style rows of a set of rigid bodies (see the module docstring)."""

    def __init__(self, paths: PrimLike | Iterable[PrimLike]) -> None:
        self.bodies = RigidBodyView(paths)
        self._shapes: ShapeTable | None = None
        self._shapes_key: tuple | None = None

    @property
    def sim(self) -> SimScene:
        sim = runtime().sim
        sim.sync_dirty_prims()
        return sim

    @property
    def count(self) -> int:
        return len(self.bodies)

    def __len__(self) -> int:
        return len(self.bodies)

    @property
    def prim_paths(self) -> list[str]:
        return list(self.bodies.paths)

    def _roots(self) -> list[str]:
        return [self.bodies._root(p) for p in self.bodies.paths]

    @property
    def shapes(self) -> ShapeTable:
        """The view's collision shapes (found again after a recompile)."""
        sim = self.sim
        key = (id(sim), sim.model_version)
        if self._shapes is None or self._shapes_key != key:
            self._shapes = ShapeTable(sim, [[r] for r in self._roots()])
            self._shapes_key = key
        return self._shapes

    @property
    def max_shapes(self) -> int:
        return self.shapes.max_shapes

    # ---- state -------------------------------------------------------------------------------------------
    def get_transforms(self) -> np.ndarray:
        """(N, 7): position and orientation quaternion (x, y, z, w) of each body."""
        pos, quat = self.bodies.get_world_poses()
        return np.concatenate([pos, quat[:, [1, 2, 3, 0]]], axis=1)

    def set_transforms(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        """Teleport the bodies of rows ``indices`` to (x, y, z, qx, qy, qz, qw) rows."""
        idx = row_indices(indices, self.count)
        rows = selected_rows(data, idx, self.count, 7, "transforms")
        self.bodies.set_world_poses(rows[:, :3], rows[:, [6, 3, 4, 5]], idx)

    def get_velocities(self) -> np.ndarray:
        """(N, 6): world-frame linear (m/s) and angular (rad/s) velocity of each body."""
        lin, ang = self.bodies.get_velocities()
        return np.concatenate([lin, ang], axis=1)

    def set_velocities(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        """Set the linear and angular velocities of rows ``indices``."""
        idx = row_indices(indices, self.count)
        rows = selected_rows(data, idx, self.count, 6, "velocities")
        self.bodies.set_velocities(rows[:, :3], rows[:, 3:], idx)

    def apply_forces(self, data: np.ndarray, indices: Sequence[int] | None = None, is_global: bool = True) -> None:
        """Push the bodies of rows ``indices`` with (N, 3) forces during the next physics step (PhysX's rule);
        ``is_global`` False: forces in each body's frame."""
        idx = row_indices(indices, self.count)
        rows = selected_rows(data, idx, self.count, 3, "forces")
        sim = self.sim
        roots = self._roots()
        for row, force in zip(idx, rows):
            root = roots[int(row)]
            if not is_global:
                force = quat_wxyz_to_matrix(sim.body_pose(root)[1]) @ force
            centre = sim.data.xipos[sim.body(root).body_id]      # at the centre of mass: no torque
            apply_force_at_pos(root, force, centre, mode="Force")

    # ---- mass properties -----------------------------------------------------------------------------------
    def get_masses(self) -> np.ndarray:
        """(N, 1): each body's mass (kg)."""
        compiled = self.sim.ensure_compiled()
        return np.array([[body_properties.mass(compiled, r)] for r in self._roots()]).reshape(-1, 1)

    def get_inv_masses(self) -> np.ndarray:
        return 1.0 / self.get_masses()

    def set_masses(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        """Write the masses (kg) of rows ``indices`` into the model (inertias kept)."""
        idx = row_indices(indices, self.count)
        rows = selected_rows(data, idx, self.count, 1, "masses")
        sim, roots = self.sim, self._roots()
        for row, value in zip(idx, rows[:, 0]):
            body_properties.set_mass(sim, roots[int(row)], float(value))

    def get_inertias(self) -> np.ndarray:
        """(N, 9): each body's inertia matrix (kg m², about its centre of mass, body frame), row-major."""
        compiled = self.sim.ensure_compiled()
        return np.array([body_properties.inertia_matrix(compiled, r).reshape(9) for r in self._roots()]).reshape(-1, 9)

    def get_inv_inertias(self) -> np.ndarray:
        return np.array([np.linalg.inv(m.reshape(3, 3)).reshape(9) for m in self.get_inertias()]).reshape(-1, 9)

    def set_inertias(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        """Write the (9-value) inertia matrices of rows ``indices`` into the model."""
        idx = row_indices(indices, self.count)
        rows = selected_rows(data, idx, self.count, 9, "inertias")
        sim, roots = self.sim, self._roots()
        for row, value in zip(idx, rows):
            body_properties.set_inertia(sim, roots[int(row)], value.reshape(3, 3))

    # ---- collision shapes ----------------------------------------------------------------------------------
    def get_material_properties(self) -> np.ndarray:
        """(N, max_shapes, 3): static friction, dynamic friction, restitution of each shape."""
        return self.shapes.get_material_properties()

    def set_material_properties(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self.shapes.set_material_properties(data, row_indices(indices, self.count))

    def get_contact_offsets(self) -> np.ndarray:
        """(N, max_shapes): contact offsets (m)."""
        return self.shapes.get_contact_offsets()

    def set_contact_offsets(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self.shapes.set_contact_offsets(data, row_indices(indices, self.count))

    def get_rest_offsets(self) -> np.ndarray:
        """(N, max_shapes): rest offsets (m)."""
        return self.shapes.get_rest_offsets()

    def set_rest_offsets(self, data: np.ndarray, indices: Sequence[int] | None = None) -> None:
        self.shapes.set_rest_offsets(data, row_indices(indices, self.count))
