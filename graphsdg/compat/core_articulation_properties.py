"""Isaac compat area: the link mass properties and PhysX solver settings of ``isaacsim.core.prims.Articulation``.

:class:`ArticulationProperties` is a part of
:class:`~graphsdg.compat.core_articulations.Articulation` (a mixin): link masses,
inertias and centres of mass go through the running MuJoCo model (the tensor
view's ``get_masses`` / ``get_inertias``, ``body_ipos`` / ``body_iquat``);
PhysX's articulation settings (solver iterations, sleep and stabilisation
thresholds) are authored on each articulation root as ``physxArticulation:*``
attributes with PhysX's fallbacks where unset, and have no MuJoCo counterpart
except ``enabledSelfCollisions``, which the compiler reads.

Example:
    >>> ArticulationProperties.get_solver_position_iteration_counts.__doc__.split(" (")[0]
    '``physxArticulation:solverPositionIterationCount``'
"""
from __future__ import annotations

from typing import Any

import numpy as np

from graphsdg.engine.runtime import runtime
from graphsdg.stage import physx_schemas

_ARTICULATION_API = "PhysxArticulationAPI"


class ArticulationProperties:
    """The link mass properties and PhysX articulation settings of an ``Articulation`` (see the module docstring)."""

    # Articulation provides _view(), _indices(), _backend_utils and _prims

    def get_body_masses(self, indices: Any = None, body_indices: Any = None, clone: bool = True) -> np.ndarray | None:
        """Link masses (M, B) kg."""
        view = self._view()
        if view is None:
            return None
        cols = self._backend_utils.resolve_indices(body_indices, view.max_links)
        return view.get_masses()[np.ix_(self._indices(indices), cols)].astype(np.float32)

    def get_body_inv_masses(self, indices: Any = None, body_indices: Any = None,
                            clone: bool = True) -> np.ndarray | None:
        """``1 / mass`` of the links (M, B) (0 for a massless link)."""
        masses = self.get_body_masses(indices, body_indices)
        if masses is None:
            return None
        with np.errstate(divide="ignore"):
            return np.where(masses > 0, 1.0 / masses, 0.0).astype(np.float32)

    def set_body_masses(self, values: Any, indices: Any = None, body_indices: Any = None) -> None:
        """Set link masses (M, B) kg in the running model (inertias kept, as PhysX's tensor mass writes)."""
        self._set_links("get_masses", "set_masses", values, indices, body_indices, 1)

    def get_body_inertias(self, indices: Any = None, body_indices: Any = None,
                          clone: bool = True) -> np.ndarray | None:
        """Link inertia matrices (M, B, 9) about each centre of mass, in the link's frame."""
        view = self._view()
        if view is None:
            return None
        cols = self._backend_utils.resolve_indices(body_indices, view.max_links)
        return view.get_inertias()[np.ix_(self._indices(indices), cols)].astype(np.float32)

    def get_body_inv_inertias(self, indices: Any = None, body_indices: Any = None,
                              clone: bool = True) -> np.ndarray | None:
        """Inverses of the link inertia matrices (M, B, 9) (0 where singular)."""
        inertias = self.get_body_inertias(indices, body_indices)
        if inertias is None:
            return None
        out = np.zeros_like(inertias)
        for idx in np.ndindex(inertias.shape[:2]):
            m = inertias[idx].reshape(3, 3).astype(np.float64)
            if abs(np.linalg.det(m)) > 0:
                out[idx] = np.linalg.inv(m).reshape(9)
        return out

    def set_body_inertias(self, values: Any, indices: Any = None, body_indices: Any = None) -> None:
        """Set link inertia matrices (M, B, 9) in the running model."""
        self._set_links("get_inertias", "set_inertias", values, indices, body_indices, 9)

    def get_body_coms(self, indices: Any = None, body_indices: Any = None,
                      clone: bool = True) -> tuple[np.ndarray, np.ndarray] | None:
        """(positions (M, B, 3), orientations (M, B, 4) w, x, y, z) of the links' centres of mass and principal
        axes in each link's frame (MuJoCo's ``body_ipos`` / ``body_iquat``)."""
        view = self._view()
        if view is None:
            return None
        from graphsdg.physics.body_properties import body_id
        compiled = runtime().sim.compiled
        rows = self._indices(indices)
        cols = self._backend_utils.resolve_indices(body_indices, view.max_links)
        positions = np.zeros((len(rows), len(cols), 3), dtype=np.float32)
        orientations = np.zeros((len(rows), len(cols), 4), dtype=np.float32)
        for a, row in enumerate(rows):
            links = view.link_paths[int(row)]
            for b, col in enumerate(cols):
                bid = body_id(compiled, links[int(col)])
                positions[a, b] = compiled.model.body_ipos[bid]
                orientations[a, b] = compiled.model.body_iquat[bid]
        return positions, orientations

    def _set_links(self, read: str, write: str, values: Any, indices: Any, body_indices: Any, width: int) -> None:
        view = self._view()
        if view is None:
            return
        rows = self._indices(indices)
        cols = self._backend_utils.resolve_indices(body_indices, view.max_links)
        table = getattr(view, read)().copy().reshape(view.count, view.max_links, width)
        values = np.asarray(values, dtype=np.float64).reshape(len(rows), len(cols), width)
        table[np.ix_(rows, cols)] = values
        getattr(view, write)(table.reshape(view.count, -1) if width > 1 else table[..., 0], rows)

    # ---- PhysX articulation settings (authored on each root; see docs/porting.md) --------------------------------
    def _set_root_property(self, name: str, values: Any, indices: Any, cast: Any) -> None:
        rows = self._indices(indices)
        values = np.asarray(values).reshape(-1)
        for k, row in enumerate(rows):
            definition = physx_schemas.schema(_ARTICULATION_API).attribute(name)
            self._prims[int(row)].CreateAttribute(f"physxArticulation:{name}", definition.value_type).Set(
                cast(values[k]))

    def _get_root_property(self, name: str, indices: Any, dtype: str) -> np.ndarray:
        rows = self._indices(indices)
        out = []
        for row in rows:
            prim = self._prims[int(row)]
            value = physx_schemas.resolved_value(prim, _ARTICULATION_API, name)
            out.append(physx_schemas.schema(_ARTICULATION_API).attribute(name).fallback if value is None else value)
        return np.array(out, dtype=dtype)

    def set_solver_position_iteration_counts(self, counts: Any, indices: Any = None) -> None:
        """Author ``physxArticulation:solverPositionIterationCount`` (PhysX's solver; no MuJoCo counterpart)."""
        self._set_root_property("solverPositionIterationCount", counts, indices, int)

    def get_solver_position_iteration_counts(self, indices: Any = None) -> np.ndarray:
        """``physxArticulation:solverPositionIterationCount`` (PhysX's 32 where unset)."""
        return self._get_root_property("solverPositionIterationCount", indices, "int32")

    def set_solver_velocity_iteration_counts(self, counts: Any, indices: Any = None) -> None:
        """Author ``physxArticulation:solverVelocityIterationCount`` (no MuJoCo counterpart)."""
        self._set_root_property("solverVelocityIterationCount", counts, indices, int)

    def get_solver_velocity_iteration_counts(self, indices: Any = None) -> np.ndarray:
        """``physxArticulation:solverVelocityIterationCount`` (PhysX's 1 where unset)."""
        return self._get_root_property("solverVelocityIterationCount", indices, "int32")

    def set_stabilization_thresholds(self, thresholds: Any, indices: Any = None) -> None:
        """Author ``physxArticulation:stabilizationThreshold`` (no MuJoCo counterpart)."""
        self._set_root_property("stabilizationThreshold", thresholds, indices, float)

    def get_stabilization_thresholds(self, indices: Any = None) -> np.ndarray:
        """``physxArticulation:stabilizationThreshold``."""
        return self._get_root_property("stabilizationThreshold", indices, "float32")

    def set_sleep_thresholds(self, thresholds: Any, indices: Any = None) -> None:
        """Author ``physxArticulation:sleepThreshold`` (MuJoCo bodies do not sleep)."""
        self._set_root_property("sleepThreshold", thresholds, indices, float)

    def get_sleep_thresholds(self, indices: Any = None) -> np.ndarray:
        """``physxArticulation:sleepThreshold``."""
        return self._get_root_property("sleepThreshold", indices, "float32")

    def set_enabled_self_collisions(self, flags: Any, indices: Any = None) -> None:
        """Author ``physxArticulation:enabledSelfCollisions``: False excludes the links' contacts with each other
        in MuJoCo (the compiler reads it)."""
        self._set_root_property("enabledSelfCollisions", flags, indices, bool)

    def get_enabled_self_collisions(self, indices: Any = None) -> np.ndarray:
        """``physxArticulation:enabledSelfCollisions`` per articulation (True where unset)."""
        return self._get_root_property("enabledSelfCollisions", indices, "uint8")
