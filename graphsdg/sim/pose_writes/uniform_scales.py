"""Uniform rescales of a batch of prims, written into MuJoCo in a few array operations.

A randomizer that scales a batch (``rep.functional.modify.pose(prims, scale_value=...)`` with
write-to-fabric) most often gives each prim one factor for all three axes. The general path of
:mod:`graphsdg.sim.pose_writes.mujoco_poses` then still works out, every frame, which rows are boxes, spheres or
tubes, whether the meshes are distinct and their vertices one run, and checks each step.
:class:`UniformScalePlan` works those out once per target list and compile, so a frame's uniform rescale
is a third of the operations (docs/performance.md, "Uniform rescales"). Every value written is the one
the general path writes, bit for bit (the sizes are the unit sizes times the factor, products the general
path computes the same way).

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> from graphsdg.sim.pose_writes.targets import targets_for
    >>> _ = rep.stage.new_stage()
    >>> cubes = rep.functional.create_batch.cube(count=3)
    >>> sim = runtime().sim
    >>> plan = targets_for(sim, cubes).uniform_plan(sim.model)
    >>> scales = np.array([[2.0] * 3, [0.5] * 3, [1.0] * 3])
    >>> prepared = plan.prepare(scales, targets_for(sim, cubes).current_scales())
    >>> plan.write(sim, prepared, scales, targets_for(sim, cubes).current_scales())
    >>> sim.model.geom_size[targets_for(sim, cubes).geom_ids, 0].tolist()
    [1.0, 0.25, 0.5]
"""
from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple, Protocol

import mujoco
import numpy as np

if TYPE_CHECKING:
    from graphsdg.sim.scene import SimScene

_EYE = np.eye(3)


class PreparedScales(NamedTuple):
    """A frame's checked uniform scales: each prim's factor, and the meshes' factors from their current scale."""

    factors: np.ndarray
    mesh_factors: np.ndarray


class ScaleTargets(Protocol):
    """What a plan reads of a batch's targets (:class:`~graphsdg.sim.pose_writes.targets.DirectTargets` is one)."""

    geom_ids: np.ndarray     # each row's MuJoCo geom
    is_mesh: np.ndarray      # each row is a mesh geom
    mesh_rows: np.ndarray    # the rows that are meshes
    simple: np.ndarray       # each row's primitive is sized by one product of its scale
    is_capsule: np.ndarray   # each row is a capsule

class UniformScalePlan:
    """What a batch's uniform rescale writes where, worked out once per target list and compile.

    Built by :meth:`DirectTargets.uniform_plan <graphsdg.sim.pose_writes.targets.DirectTargets.uniform_plan>`,
    which gives None where the batch does not fit: a primitive
    sized otherwise than by a product (capsules, tubes along x or y, planes), repeated meshes, or mesh
    vertices not in one run.
    """

    def __init__(self, t: ScaleTargets, model: mujoco.MjModel, unit_sizes: np.ndarray,
                 unit_half_extents: np.ndarray) -> None:
        self.prim_rows = np.flatnonzero(~t.is_mesh)
        self.prim_geoms = t.geom_ids[self.prim_rows]
        self.unit_sizes = unit_sizes              # each primitive's geom_size at scale 1
        self.unit_half_extents = unit_half_extents
        self.mesh_rows = t.mesh_rows
        self.mesh_geoms = t.geom_ids[self.mesh_rows]
        self.mesh_ids = np.asarray(model.geom_dataid[self.mesh_geoms], dtype=np.int64)
        starts = np.asarray(model.mesh_vertadr[self.mesh_ids], dtype=np.int64)
        counts = np.asarray(model.mesh_vertnum[self.mesh_ids], dtype=np.int64)
        order = np.argsort(starts, kind="stable")
        self.vertex_run = (int(starts[order][0]), int((starts + counts)[order][-1])) if order.size else (0, 0)
        # each vertex of the run: the row of its mesh (meshes compiled one after another sit in one run)
        self.vertex_rows = np.repeat(order, counts[order])

    @staticmethod
    def fits(t: ScaleTargets, model: mujoco.MjModel) -> bool:
        """Whether ``t``'s batch can be rescaled by a plan."""
        prims = ~t.is_mesh
        if not t.simple[prims].all() or t.is_capsule[prims].any():
            return False
        mesh_ids = np.asarray(model.geom_dataid[t.geom_ids[t.mesh_rows]], dtype=np.int64)
        if not mesh_ids.size:
            return True
        if (mesh_ids < 0).any() or np.unique(mesh_ids).size != mesh_ids.size:
            return False
        starts, counts = model.mesh_vertadr[mesh_ids], model.mesh_vertnum[mesh_ids]
        order = np.argsort(starts, kind="stable")
        return bool((starts[order][1:] == (starts + counts)[order][:-1]).all())

    def prepare(self, world_scale: np.ndarray, current: np.ndarray) -> PreparedScales | None:
        """The frame's factors, or None (nothing written) where the general path must write them: a scale that
        differs between axes, a mesh whose scale did not change (the general path leaves it as it is) or whose
        current scale is not uniform."""
        factors = world_scale[:, 0]
        if not (world_scale == factors[:, None]).all():
            return None
        if not self.mesh_rows.size:
            return PreparedScales(factors, factors[:0])
        old, new = current[self.mesh_rows], world_scale[self.mesh_rows]
        ratios = new / old
        if not (ratios == ratios[:, :1]).all():
            return None
        if not (np.abs(new - old) > 1e-12 * np.maximum(1.0, np.abs(old))).any(axis=1).all():
            return None
        return PreparedScales(factors, ratios[:, 0])

    def write(self, sim: SimScene, prepared: PreparedScales, world_scale: np.ndarray, current: np.ndarray) -> None:
        """Write a prepared frame's sizes, bounds and mesh rescales, and record the new ``current`` scales."""
        m = sim.model
        if self.mesh_rows.size:
            k = prepared.mesh_factors
            start, end = self.vertex_run
            m.mesh_vert[start:end] *= k.astype(m.mesh_vert.dtype)[self.vertex_rows][:, None]
            geoms, size = self.mesh_geoms, np.abs(k)
            m.geom_pos[geoms] *= k[:, None]
            m.geom_aabb[geoms] *= size[:, None]
            m.geom_rbound[geoms] *= size
            sim.render_link.meshes_rescaled(self.mesh_ids, k[:, None, None] * _EYE, distinct=True)
            current[self.mesh_rows] = world_scale[self.mesh_rows]
        if self.prim_rows.size:
            size = np.abs(prepared.factors[self.prim_rows])[:, None]
            m.geom_size[self.prim_geoms] = self.unit_sizes * size
            m.geom_rbound[self.prim_geoms] = np.linalg.norm(self.unit_half_extents * size, axis=1)
            current[self.prim_rows] = world_scale[self.prim_rows]


__all__ = ["UniformScalePlan", "PreparedScales"]
