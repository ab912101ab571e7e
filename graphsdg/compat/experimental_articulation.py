"""Isaac compat: ``isaacsim.core.experimental.prims.Articulation`` over MuJoCo's joints.

An ``Articulation`` wraps the ``ArticulationRootAPI`` prim at or below each given
path (the first one, breadth first). Each one is a
:class:`graphsdg.physics.articulation_dofs.ArticulationDofs`: its DOFs are the
revolute and prismatic joints of the tree (MuJoCo's order, parents first), in
radians / metres. Data is batched as Isaac's: ``(N, D)`` arrays (N articulations, D
DOFs; ``indices`` and ``dof_indices`` select), inputs broadcast by NumPy's rules,
results NumPy arrays that also answer warp's ``.numpy()``. All wrapped
articulations must have the same DOFs, as in Isaac's physics views.

* State (positions, velocities, drive targets, efforts) is written into MuJoCo
  directly, as Isaac's tensor API writes PhysX; ``set_dof_positions`` also sets the
  position targets, as Isaac does. Targets given to DOFs without a drive have no
  effect (as in PhysX) and warn once.
* Properties (limits, gains, maximum efforts, armatures) are authored on the USD
  joints (angular values in degrees there) and take effect when the stage next
  syncs (a recompile that keeps the simulation state); getters read the compiled model.
* The simulation is MuJoCo's, available without playing the timeline, so the
  physics tensor entity is valid as soon as the articulation compiles.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from pxr import UsdGeom, UsdPhysics
    >>> from isaacsim.core.experimental.prims import Articulation
    >>> _ = omni.usd.get_context().new_stage()
    >>> stage = omni.usd.get_context().get_stage()
    >>> robot_prim = UsdGeom.Xform.Define(stage, "/Robot").GetPrim()
    >>> link = UsdGeom.Cube.Define(stage, "/Robot/Link").GetPrim()
    >>> UsdPhysics.RigidBodyAPI.Apply(link); UsdPhysics.CollisionAPI.Apply(link)  # doctest: +ELLIPSIS
    UsdPhysics...
    >>> UsdPhysics.ArticulationRootAPI.Apply(robot_prim)  # doctest: +ELLIPSIS
    UsdPhysics.ArticulationRootAPI(...)
    >>> _ = UsdPhysics.RevoluteJoint.Define(stage, "/Robot/Hinge").CreateBody1Rel().SetTargets(["/Robot/Link"])
    >>> robot = Articulation("/Robot")
    >>> robot.num_dofs, robot.dof_names
    (1, ['Hinge'])
    >>> isaac.uninstall()
"""
from __future__ import annotations

import enum
from typing import Any, Sequence

import numpy as np
from pxr import UsdPhysics

from graphsdg.compat.experimental_arguments import as_paths, resolve_indices, rows, warn_once
from graphsdg.compat.experimental_prim_base import Prim
from graphsdg.compat.experimental_prims import XformPrim
from graphsdg.compat.experimental_stage_scope import current_stage
from graphsdg.compat.warp_arrays import WarpLikeArray
from graphsdg.compat.warp_arrays import as_warp_like as _warp
from graphsdg.physics.articulation_dofs import ArticulationDofs
from graphsdg.physics.bodies import RigidBodyView


class DofType(enum.IntEnum):
    """``omni.physics.tensors.DofType``: how a DOF moves."""

    Rotation = 0
    Translation = 1


class JointType(enum.IntEnum):
    """``omni.physics.tensors.JointType``: the joints graphsdg compiles into a tree."""

    Fixed = 0
    Revolute = 1
    Prismatic = 2
    Spherical = 3


_JOINT_TYPES = {"fixed": JointType.Fixed, "revolute": JointType.Revolute, "prismatic": JointType.Prismatic,
                "spherical": JointType.Spherical}
CONTROL_MODES = ("position", "velocity", "effort")


def _first_root(path: str) -> str | None:
    """The first prim at or below ``path`` (breadth first) with ``ArticulationRootAPI``."""
    queue = [current_stage().GetPrimAtPath(path)]
    while queue:
        prim = queue.pop(0)
        if prim.HasAPI(UsdPhysics.ArticulationRootAPI):
            return prim.GetPath().pathString
        queue.extend(prim.GetChildren())
    return None


class Articulation(XformPrim):
    """``isaacsim.core.experimental.prims.Articulation`` (see the module docstring)."""

    _compat_name = "isaacsim.core.experimental.prims.Articulation"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = False) -> None:
        if resolve_paths:
            existent, nonexistent = Prim.resolve_paths(paths)
            if nonexistent:
                raise ValueError(f"Specified paths must correspond to existing prims: {', '.join(nonexistent)}")
            found = [_first_root(p) for p in existent]
            missing = [p for p, r in zip(existent, found) if r is None]
        else:
            found = as_paths(paths)
            missing = [p for p in found if not current_stage().GetPrimAtPath(p).HasAPI(UsdPhysics.ArticulationRootAPI)]
        if missing:
            raise ValueError(f"no prim with UsdPhysics.ArticulationRootAPI at or below {missing}; Articulation wraps "
                             f"articulation roots")
        roots = [r for r in found if r is not None]
        self._views = [ArticulationDofs(r) for r in roots]
        names = self._views[0].dof_names
        for view in self._views[1:]:
            if view.dof_names != names:
                raise ValueError(f"articulations {roots[0]} and {view.root_path} have different DOFs ({names} and "
                                 f"{view.dof_names}); one Articulation wraps articulations of the same structure")
        self._default: dict[str, np.ndarray | None] = {k: None for k in (
            "positions", "orientations", "linear_velocities", "angular_velocities", "dof_positions",
            "dof_velocities", "dof_efforts")}
        self._default_gains: tuple[np.ndarray, np.ndarray] | None = None
        self._undriven_targets: dict[tuple[int, int, str], float] = {}
        super().__init__(roots, resolve_paths=False, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)

    @staticmethod
    def fetch_articulation_root_api_prim_paths(paths: str | Sequence[str]) -> list[str | None]:
        """For each matched prim, the first prim at or below it with ``ArticulationRootAPI`` (None where none)."""
        existent, nonexistent = Prim.resolve_paths(paths)
        if nonexistent:
            raise ValueError(f"Specified paths must correspond to existing prims: {', '.join(nonexistent)}")
        return [_first_root(p) for p in existent]

    # ---- structure ------------------------------------------------------------------------------------------
    @property
    def num_dofs(self) -> int:
        """DOFs per articulation."""
        return len(self._views[0].dof_names)

    @property
    def dof_names(self) -> list[str]:
        """The DOFs' joint names, in order."""
        return self._views[0].dof_names

    @property
    def dof_paths(self) -> list[list[str]]:
        """The DOFs' joint paths, one list per articulation."""
        return [v.dof_paths for v in self._views]

    @property
    def dof_types(self) -> list[DofType]:
        """``DofType.Rotation`` (revolute) or ``DofType.Translation`` (prismatic) per DOF."""
        return [DofType.Rotation if k == "revolute" else DofType.Translation for k in self._views[0].dof_kinds]

    @property
    def num_joints(self) -> int:
        """Joints per articulation (fixed ones of the tree too)."""
        return len(self._views[0].joint_paths)

    @property
    def joint_names(self) -> list[str]:
        """The joints' names: DOF joints in DOF order, then fixed joints."""
        return [p.rsplit("/", 1)[-1] for p in self._views[0].joint_paths]

    @property
    def joint_paths(self) -> list[list[str]]:
        """The joints' paths, one list per articulation."""
        return [v.joint_paths for v in self._views]

    @property
    def joint_types(self) -> list[JointType]:
        """The type of each joint."""
        return [_JOINT_TYPES[k] for k in self._views[0].joint_kinds]

    @property
    def num_links(self) -> int:
        """Links (rigid bodies) per articulation."""
        return len(self._views[0].link_paths)

    @property
    def link_names(self) -> list[str]:
        """The links' names, the root link first."""
        return [p.rsplit("/", 1)[-1] for p in self._views[0].link_paths]

    @property
    def link_paths(self) -> list[list[str]]:
        """The links' paths, one list per articulation."""
        return [v.link_paths for v in self._views]

    def is_physics_tensor_entity_valid(self) -> bool:
        """Whether the articulations are simulated (they are once compiled: MuJoCo needs no play)."""
        return all(v.dof_paths is not None for v in self._views)

    def is_physics_tensor_entity_initialized(self) -> bool:
        """Same as :meth:`is_physics_tensor_entity_valid` here."""
        return self.is_physics_tensor_entity_valid()

    @staticmethod
    def _indices_of(names: str | Sequence[str], known: list[str], what: str) -> WarpLikeArray:
        items = [names] if isinstance(names, str) else list(names)
        unknown = [n for n in items if n not in known]
        if unknown:
            raise ValueError(f"unknown {what} name(s) {unknown}; the {what}s are {known}")
        return _warp(np.array([known.index(n) for n in items], dtype=np.int32))

    def get_dof_indices(self, names: str | Sequence[str]) -> WarpLikeArray:
        """Indices of the named DOFs."""
        return self._indices_of(names, self.dof_names, "DOF")

    def get_joint_indices(self, names: str | Sequence[str]) -> WarpLikeArray:
        """Indices of the named joints."""
        return self._indices_of(names, self.joint_names, "joint")

    def get_link_indices(self, names: str | Sequence[str]) -> WarpLikeArray:
        """Indices of the named links."""
        return self._indices_of(names, self.link_names, "link")

    # ---- batching -----------------------------------------------------------------------------------------
    def _select(self, indices: Any, dof_indices: Any) -> tuple[list[int], list[int]]:
        self._check_valid()
        return resolve_indices(indices, len(self)), resolve_indices(dof_indices, self.num_dofs)

    def _get(self, method: str, indices: Any, dof_indices: Any) -> WarpLikeArray:
        idx, dof = self._select(indices, dof_indices)
        data = [getattr(self._views[i], method)(dof) for i in idx]
        return _warp(np.array(data, dtype=np.float32).reshape(len(idx), len(dof)))

    def _set(self, method: str, values: Any, indices: Any, dof_indices: Any, name: str) -> list[str]:
        idx, dof = self._select(indices, dof_indices)
        data = rows_2d(values, len(idx), len(dof), name)
        out: list[str] = []
        for row, i in enumerate(idx):
            out += getattr(self._views[i], method)(data[row], dof) or []
        return out

    def _warn_undriven(self, undriven: list[str], what: str) -> None:
        if undriven:
            warn_once(f"Articulation {what} of DOFs without a drive",
                      f"DOFs {sorted(set(undriven))} have no drive (UsdPhysics.DriveAPI), so their {what} do not "
                      f"move them, as in PhysX")

    # ---- DOF state --------------------------------------------------------------------------------------------
    def get_dof_positions(self, *, indices: Any = None, dof_indices: Any = None) -> WarpLikeArray:
        """DOF positions (rad or m), shape (N, D)."""
        return self._get("get_positions", indices, dof_indices)

    def set_dof_positions(self, positions: Any, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Teleport DOFs to ``positions`` (N, D) and make them the drives' position targets too."""
        self._set("set_positions", positions, indices, dof_indices, "positions")
        self._store_undriven("position", positions, indices, dof_indices)
        self._set("set_position_targets", positions, indices, dof_indices, "positions")

    def get_dof_velocities(self, *, indices: Any = None, dof_indices: Any = None) -> WarpLikeArray:
        """DOF velocities (rad/s or m/s), shape (N, D)."""
        return self._get("get_velocities", indices, dof_indices)

    def set_dof_velocities(self, velocities: Any, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Set DOF velocities (N, D)."""
        self._set("set_velocities", velocities, indices, dof_indices, "velocities")

    def get_dof_efforts(self, *, indices: Any = None, dof_indices: Any = None) -> WarpLikeArray:
        """Efforts applied with :meth:`set_dof_efforts` (N m or N), shape (N, D)."""
        return self._get("get_efforts", indices, dof_indices)

    def set_dof_efforts(self, efforts: Any, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Apply joint efforts (N, D) from the next physics step on, until changed."""
        self._set("set_efforts", efforts, indices, dof_indices, "efforts")

    def get_dof_position_targets(self, *, indices: Any = None, dof_indices: Any = None) -> WarpLikeArray:
        """The drives' position targets (N, D); a DOF without a drive reads back the target last given."""
        return self._targets("get_position_targets", "position", indices, dof_indices)

    def set_dof_position_targets(self, positions: Any, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Set the drives' position targets (N, D): the PD drives pull the DOFs towards them."""
        self._store_undriven("position", positions, indices, dof_indices)
        self._warn_undriven(self._set("set_position_targets", positions, indices, dof_indices, "positions"),
                            "position targets")

    def get_dof_velocity_targets(self, *, indices: Any = None, dof_indices: Any = None) -> WarpLikeArray:
        """The drives' velocity targets (N, D)."""
        return self._targets("get_velocity_targets", "velocity", indices, dof_indices)

    def set_dof_velocity_targets(self, velocities: Any, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Set the drives' velocity targets (N, D): the damping term pulls the DOF velocities towards them."""
        self._store_undriven("velocity", velocities, indices, dof_indices)
        self._warn_undriven(self._set("set_velocity_targets", velocities, indices, dof_indices, "velocities"),
                            "velocity targets")

    def _store_undriven(self, kind: str, values: Any, indices: Any, dof_indices: Any) -> None:
        idx, dof = self._select(indices, dof_indices)
        data = rows_2d(values, len(idx), len(dof), f"{kind} targets")
        for row, i in enumerate(idx):
            for col, d in enumerate(dof):
                self._undriven_targets[(i, d, kind)] = float(data[row, col])

    def _targets(self, method: str, kind: str, indices: Any, dof_indices: Any) -> WarpLikeArray:
        idx, dof = self._select(indices, dof_indices)
        out = np.zeros((len(idx), len(dof)), dtype=np.float32)
        for row, i in enumerate(idx):
            values = getattr(self._views[i], method)(dof)
            for col, d in enumerate(dof):
                out[row, col] = values[col] if np.isfinite(values[col]) else \
                    self._undriven_targets.get((i, d, kind), 0.0)
        return _warp(out)

    # ---- DOF properties (authored on the USD joints) -------------------------------------------------------
    def get_dof_limits(self, *, indices: Any = None, dof_indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(lower, upper) DOF limits (rad or m; -inf / inf where unlimited), each (N, D)."""
        idx, dof = self._select(indices, dof_indices)
        pairs = [self._views[i].get_limits(dof) for i in idx]
        return (_warp(np.array([p[0] for p in pairs], dtype=np.float32).reshape(len(idx), len(dof))),
                _warp(np.array([p[1] for p in pairs], dtype=np.float32).reshape(len(idx), len(dof))))

    def set_dof_limits(self, lower: Any = None, upper: Any = None, *, indices: Any = None,
                       dof_indices: Any = None) -> None:
        """Author DOF limits (rad or m) on the joints; they apply when the stage next syncs."""
        if lower is None and upper is None:
            raise ValueError("set_dof_limits needs lower and / or upper limits")
        idx, dof = self._select(indices, dof_indices)
        lo = None if lower is None else rows_2d(lower, len(idx), len(dof), "lower")
        hi = None if upper is None else rows_2d(upper, len(idx), len(dof), "upper")
        for row, i in enumerate(idx):
            self._views[i].author_limits(None if lo is None else lo[row], None if hi is None else hi[row], dof)

    def get_dof_gains(self, *, indices: Any = None, dof_indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(stiffnesses, dampings) of the DOF drives (per rad or m; 0 without a drive), each (N, D)."""
        idx, dof = self._select(indices, dof_indices)
        pairs = [self._views[i].get_gains(dof) for i in idx]
        return (_warp(np.array([p[0] for p in pairs], dtype=np.float32).reshape(len(idx), len(dof))),
                _warp(np.array([p[1] for p in pairs], dtype=np.float32).reshape(len(idx), len(dof))))

    def set_dof_gains(self, stiffnesses: Any = None, dampings: Any = None, *, indices: Any = None,
                      dof_indices: Any = None, update_default_gains: bool = True) -> None:
        """Author the DOF drives' stiffness and / or damping (per rad or m); a DOF without a drive gains one."""
        if stiffnesses is None and dampings is None:
            raise ValueError("set_dof_gains needs stiffnesses and / or dampings")
        idx, dof = self._select(indices, dof_indices)
        kp = None if stiffnesses is None else rows_2d(stiffnesses, len(idx), len(dof), "stiffnesses")
        kd = None if dampings is None else rows_2d(dampings, len(idx), len(dof), "dampings")
        for name, values in (("stiffnesses", kp), ("dampings", kd)):
            if values is not None and np.any(values < 0):
                raise ValueError(f"{name} must be >= 0, got {values.tolist()}")
        if not update_default_gains and self._default_gains is None:
            self._default_gains = tuple(np.asarray(g, dtype=np.float64) for g in self.get_dof_gains())
        for row, i in enumerate(idx):
            self._views[i].author_gains(None if kp is None else kp[row], None if kd is None else kd[row], dof)
        if update_default_gains and self._default_gains is not None:
            for stored, values in zip(self._default_gains, (kp, kd)):
                if values is not None:
                    stored[np.ix_(idx, dof)] = values

    def switch_dof_control_mode(self, mode: str, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Set gains for ``"position"`` (the default gains), ``"velocity"`` (no stiffness) or ``"effort"``
        (neither) control of the selected DOFs."""
        if mode not in CONTROL_MODES:
            raise ValueError(f"Invalid control mode: {mode!r}. Supported modes are: {list(CONTROL_MODES)}")
        if self._default_gains is None:
            self._default_gains = tuple(np.asarray(g, dtype=np.float64) for g in self.get_dof_gains())
        idx, dof = self._select(indices, dof_indices)
        kp, kd = (g[np.ix_(idx, dof)] for g in self._default_gains)
        if mode != "position":
            kp = np.zeros_like(kp)
        if mode == "effort":
            kd = np.zeros_like(kd)
        self.set_dof_gains(kp, kd, indices=idx, dof_indices=dof, update_default_gains=False)

    def get_dof_max_efforts(self, *, indices: Any = None, dof_indices: Any = None) -> WarpLikeArray:
        """The drives' maximum forces (inf where unlimited or undriven), shape (N, D)."""
        return self._get("get_max_efforts", indices, dof_indices)

    def set_dof_max_efforts(self, max_efforts: Any, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Author the drives' maximum forces (N m or N)."""
        idx, dof = self._select(indices, dof_indices)
        data = rows_2d(max_efforts, len(idx), len(dof), "max_efforts")
        if np.any(data < 0):
            raise ValueError(f"max_efforts must be >= 0, got {data.tolist()}")
        for row, i in enumerate(idx):
            self._views[i].author_max_efforts(data[row], dof)

    def get_dof_armatures(self, *, indices: Any = None, dof_indices: Any = None) -> WarpLikeArray:
        """DOF armatures, shape (N, D)."""
        return self._get("get_armatures", indices, dof_indices)

    def set_dof_armatures(self, armatures: Any, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Author DOF armatures (``physxJoint:armature``)."""
        idx, dof = self._select(indices, dof_indices)
        data = rows_2d(armatures, len(idx), len(dof), "armatures")
        if np.any(data < 0):
            raise ValueError(f"armatures must be >= 0, got {data.tolist()}")
        for row, i in enumerate(idx):
            self._views[i].author_armatures(data[row], dof)

    def get_dof_drive_types(self, *, indices: Any = None, dof_indices: Any = None) -> list[list[str | None]]:
        """``"force"`` or ``"acceleration"`` per DOF drive (None without a drive), from ``drive:*:physics:type``."""
        idx, dof = self._select(indices, dof_indices)
        stage = current_stage()
        out = []
        for i in idx:
            row = []
            for d in dof:
                prim = stage.GetPrimAtPath(self._views[i].dof_paths[d])
                name = "angular" if self._views[i].dof_kinds[d] == "revolute" else "linear"
                row.append(str(UsdPhysics.DriveAPI(prim, name).GetTypeAttr().Get())
                           if prim.HasAPI(UsdPhysics.DriveAPI, name) else None)
            out.append(row)
        return out

    # ---- links -------------------------------------------------------------------------------------------------
    def _links(self, indices: Any, link_indices: Any) -> tuple[list[int], list[int]]:
        self._check_valid()
        return resolve_indices(indices, len(self)), resolve_indices(link_indices, self.num_links)

    def get_link_masses(self, *, indices: Any = None, link_indices: Any = None, inverse: bool = False
                        ) -> WarpLikeArray:
        """Link masses (kg), shape (N, L) (their inverses with ``inverse``)."""
        idx, links = self._links(indices, link_indices)
        data = np.array([self._views[i].link_masses()[links] for i in idx], dtype=np.float32)
        with np.errstate(divide="ignore"):
            return _warp(1.0 / data if inverse else data)

    def get_link_coms(self, *, indices: Any = None, link_indices: Any = None
                      ) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(centre-of-mass positions (N, L, 3), orientations (N, L, 4) w, x, y, z) in each link's frame."""
        idx, links = self._links(indices, link_indices)
        pairs = [self._views[i].link_coms() for i in idx]
        return (_warp(np.array([p[0][links] for p in pairs], dtype=np.float32)),
                _warp(np.array([p[1][links] for p in pairs], dtype=np.float32)))

    def get_link_inertias(self, *, indices: Any = None, link_indices: Any = None, inverse: bool = False
                          ) -> WarpLikeArray:
        """Link inertia tensors flattened to 9 values (N, L, 9), about the centre of mass in the inertial axes."""
        idx, links = self._links(indices, link_indices)
        data = np.array([self._views[i].link_inertias()[links] for i in idx], dtype=np.float64)
        if inverse:
            data = np.linalg.inv(data)
        return _warp(data.reshape(len(idx), len(links), 9).astype(np.float32))

    # ---- root velocities and default state ------------------------------------------------------------------
    def _root_bodies(self, idx: list[int]) -> RigidBodyView:
        return RigidBodyView([self._views[i].link_paths[0] for i in idx])

    def get_velocities(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """Root link (linear (N, 3), angular (N, 3)) velocities, world frame."""
        idx = resolve_indices(indices, len(self))
        lin, ang = self._root_bodies(idx).get_velocities()
        return _warp(lin.astype(np.float32)), _warp(ang.astype(np.float32))

    def set_velocities(self, linear_velocities: Any = None, angular_velocities: Any = None, *,
                       indices: Any = None) -> None:
        """Set the root links' world velocities (floating-base articulations)."""
        idx = resolve_indices(indices, len(self))
        lin = None if linear_velocities is None else rows(linear_velocities, len(idx), 3, "linear_velocities")
        ang = None if angular_velocities is None else rows(angular_velocities, len(idx), 3, "angular_velocities")
        self._root_bodies(idx).set_velocities(lin, ang)

    def set_default_state(self, positions: Any = None, orientations: Any = None, linear_velocities: Any = None,
                          angular_velocities: Any = None, dof_positions: Any = None, dof_velocities: Any = None,
                          dof_efforts: Any = None, *, indices: Any = None, dof_indices: Any = None) -> None:
        """Remember root poses / velocities and DOF positions / velocities / efforts for
        :meth:`reset_to_default_state`."""
        idx, dof = self._select(indices, dof_indices)
        for key, values, width in (("positions", positions, 3), ("orientations", orientations, 4),
                                   ("linear_velocities", linear_velocities, 3),
                                   ("angular_velocities", angular_velocities, 3)):
            if values is not None:
                stored = self._default[key]
                if stored is None:
                    stored = self._default[key] = np.full((len(self), width), np.nan)
                stored[idx] = rows(values, len(idx), width, key)
        for key, values in (("dof_positions", dof_positions), ("dof_velocities", dof_velocities),
                            ("dof_efforts", dof_efforts)):
            if values is not None:
                stored = self._default[key]
                if stored is None:
                    stored = self._default[key] = np.full((len(self), self.num_dofs), np.nan)
                stored[np.ix_(idx, dof)] = rows_2d(values, len(idx), len(dof), key)

    def get_default_state(self, *, indices: Any = None, dof_indices: Any = None) -> tuple:
        """The default (positions, orientations, linear velocities, angular velocities, DOF positions,
        DOF velocities, DOF efforts); None where never set."""
        idx, dof = self._select(indices, dof_indices)
        out = []
        for key in self._default:
            stored = self._default[key]
            if stored is None:
                out.append(None)
            elif key.startswith("dof_"):
                out.append(_warp(stored[np.ix_(idx, dof)].astype(np.float32)))
            else:
                out.append(_warp(stored[idx].astype(np.float32)))
        return tuple(out)

    def reset_to_default_state(self, *, warn_on_non_default_state: bool = False) -> None:
        """Teleport to the default state set (root poses, velocities, DOF positions, velocities, efforts)."""
        if all(v is None for v in self._default.values()):
            if warn_on_non_default_state:
                warn_once("Articulation.reset_to_default_state", "no default state is set")
            return
        d = self._default
        for i in range(len(self)):
            pick = lambda key: None if d[key] is None or np.isnan(d[key][i]).any() else [d[key][i]]  # noqa: E731
            if pick("positions") is not None or pick("orientations") is not None:
                self.set_world_poses(pick("positions"), pick("orientations"), indices=[i])
            if pick("linear_velocities") is not None or pick("angular_velocities") is not None:
                self.set_velocities(pick("linear_velocities"), pick("angular_velocities"), indices=[i])
            for key, setter in (("dof_positions", self.set_dof_positions), ("dof_velocities", self.set_dof_velocities),
                                ("dof_efforts", self.set_dof_efforts)):
                if d[key] is not None:
                    cols = [c for c in range(self.num_dofs) if np.isfinite(d[key][i, c])]
                    if cols:
                        setter([d[key][i, cols]], indices=[i], dof_indices=cols)


def rows_2d(values: Any, count: int, width: int, name: str) -> np.ndarray:
    """``values`` broadcast to ``(count, width)`` floats (NumPy rules); a ValueError names bad input."""
    raw = values.numpy() if hasattr(values, "numpy") else values
    try:
        arr = np.broadcast_to(np.asarray(raw, dtype=np.float64), (count, width)).copy()
    except (TypeError, ValueError):
        raise ValueError(f"{name} {values!r} cannot be broadcast to shape ({count}, {width}): {count} "
                         f"articulation(s) x {width} DOF(s)") from None
    if not np.all(np.isfinite(arr)) and name not in ("lower", "upper", "max_efforts"):
        raise ValueError(f"{name} {values!r} holds a value that is not finite")
    return arr
