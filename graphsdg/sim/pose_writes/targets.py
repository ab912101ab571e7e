"""Compiled-model indices of a list of prims, the eligibility test of write-to-fabric's MuJoCo path.

:func:`targets_for` gives a prim list's :class:`DirectTargets` (geom, mocap and size-convention arrays),
cached per compile and prim list: a script passes the same prims every frame. A list is eligible when every
prim is a plain compiled gprim (no rigid body, no xform with children, no mesh whose colliders would need
rebuilding); otherwise its poses and colours are authored on the stage.
"""
from __future__ import annotations

import operator
from typing import Sequence

import mujoco
import numpy as np
from pxr import Usd

from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz
from graphsdg.sim.gprims import primitive_size
from graphsdg.sim.pose_writes.uniform_scales import UniformScalePlan
from graphsdg.sim.scene import SimScene
from graphsdg.stage.xform import parent_world_matrix


_NOT_WORKED_OUT = object()


class DirectTargets:
    """Compiled-model indices of a list of prims, cached per compiled model."""

    _uniform_plan: UniformScalePlan | None | object = _NOT_WORKED_OUT   # see uniform_plan()

    def __init__(self, sim: SimScene, prims: Sequence[Usd.Prim]) -> None:
        c = sim.ensure_compiled()
        self.paths = [str(p.GetPath()) for p in prims]
        self.bindings = [c.geoms.get(p) for p in self.paths]
        self.eligible = all(b is not None and b.rigid_root is None and b.mocap_id >= 0 for b in self.bindings)
        if not self.eligible:
            return
        self.has_material = any(b.material for b in self.bindings)
        self.geom_ids = np.array([b.geom_id for b in self.bindings])
        self.mocap_ids = np.array([b.mocap_id for b in self.bindings])
        mats = np.array([parent_world_matrix(p) for p in prims])
        self.parent_t, self.parent_r, self.parent_s = decompose(mats.reshape(-1, 4, 4))
        self.parent_q = matrix_to_quat_wxyz(self.parent_r)
        # most batches sit under an untransformed parent: their local poses are world poses
        self.parent_is_identity = bool(np.allclose(self.parent_t, 0.0, atol=0.0) and
                                       np.allclose(self.parent_r, np.eye(3), atol=0.0) and
                                       np.allclose(self.parent_s, 1.0, atol=0.0))
        self.is_mesh = np.array([b.type_name in ("Mesh", "Cone") for b in self.bindings])
        self.prims = list(prims)
        # Unit-scale sizes let box, sphere and z-axis cylinder/capsule scales be array products.
        self.unit_size = np.zeros((len(self.prims), 3))
        self.simple = np.zeros(len(self.prims), dtype=bool)
        for i, (p, b) in enumerate(zip(self.prims, self.bindings)):
            if b.type_name in ("Cube", "Sphere") or (b.type_name in ("Cylinder", "Capsule")
                                                     and str(p.GetAttribute("axis").Get()) == "Z"):
                self.unit_size[i] = primitive_size(p, np.ones(3))[1]
                self.simple[i] = True
        self.kind = np.array([sim.model.geom_type[b.geom_id] for b in self.bindings])
        g = mujoco.mjtGeom   # geom kinds (size conventions), whether or not sized by array products
        self.is_box = self.kind == int(g.mjGEOM_BOX)
        self.is_sphere = self.kind == int(g.mjGEOM_SPHERE)
        self.is_tube = np.isin(self.kind, [int(g.mjGEOM_CYLINDER), int(g.mjGEOM_CAPSULE)])
        self.is_capsule = self.kind == int(g.mjGEOM_CAPSULE)
        self.mesh_rows = np.flatnonzero(self.is_mesh)
        # The bindings' scales as rows of one array: each binding's ``scale`` is made a view of its row, so
        # a frame's new scales are one array write (a Python assignment per prim cost ~0.4 us each)
        self.scales = np.array([b.scale for b in self.bindings], dtype=np.float64).reshape(-1, 3)
        self.scale_rows = list(self.scales)
        for b, row in zip(self.bindings, self.scale_rows):
            b.scale = row

    def uniform_plan(self, model: mujoco.MjModel) -> UniformScalePlan | None:
        """How this batch's uniform rescales are written (:mod:`~graphsdg.sim.pose_writes.uniform_scales`), or
        None where they take the general path; worked out on first use (the targets are cached per compile)."""
        if self._uniform_plan is _NOT_WORKED_OUT:
            plan = None
            if UniformScalePlan.fits(self, model):
                prims = np.flatnonzero(~self.is_mesh)
                unit = simple_sizes(self, np.ones((len(self.prims), 3)))[1][prims]
                plan = UniformScalePlan(self, model, unit, half_extents(self, prims, unit))
            self._uniform_plan = plan
        return self._uniform_plan

    def current_scales(self) -> np.ndarray:
        """:attr:`scales`, after taking back the rows of bindings whose ``scale`` was replaced since (a USD
        edit synced, another prim list's targets); checked for every prim by identity, at C speed."""
        if not all(map(operator.is_, map(_SCALE, self.bindings), self.scale_rows)):
            for i, (b, row) in enumerate(zip(self.bindings, self.scale_rows)):
                if b.scale is not row:
                    self.scales[i] = b.scale
                    b.scale = row
        return self.scales


_SCALE = operator.attrgetter("scale")


class _TargetsCache:
    """:class:`DirectTargets` by scene, compile and prim list.

    A script passes the same prims every frame: the last lists are kept and
    compared element by element (identity first, so ~1 us for 50 prims) before
    falling back to a key of paths.
    """

    def __init__(self) -> None:
        self.by_key: dict[tuple, DirectTargets] = {}
        self.recent: list[tuple[int, int, list, DirectTargets]] = []

    def get(self, sim: SimScene, prims: Sequence[Usd.Prim]) -> DirectTargets:
        version = sim.model_version
        for sim_id, v, listed, found in self.recent:
            if sim_id == id(sim) and v == version and listed == prims:
                return found
        key = (id(sim), version, tuple(map(Usd.Prim.GetPath, prims)))
        found = self.by_key.get(key)
        if found is None:
            if len(self.by_key) > 64:
                self.by_key.clear()
            found = self.by_key[key] = DirectTargets(sim, prims)
        self.recent = [(id(sim), version, list(prims), found)] + self.recent[:7]
        return found

    def clear(self) -> None:
        self.by_key.clear()
        self.recent.clear()


_cache = _TargetsCache()


def targets_for(sim: SimScene, prims: Sequence[Usd.Prim]) -> DirectTargets:
    """The model indices of ``prims`` in ``sim``'s compiled model (cached per compile)."""
    sim.sync_dirty_prims()   # structure first: the indices must be current
    return _cache.get(sim, prims)


def half_extents(t: DirectTargets, rows: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """(len(rows), 3) half extents of the primitive geoms of ``t``'s ``rows`` with ``sizes`` (MuJoCo's size
    convention)."""
    out = np.array(sizes, dtype=np.float64, copy=True)
    sphere, tube, capsule = t.is_sphere[rows], t.is_tube[rows], t.is_capsule[rows]
    out[sphere] = sizes[sphere, :1]
    out[tube, 1] = sizes[tube, 0]
    out[tube, 2] = sizes[tube, 1]
    out[capsule, 2] += sizes[capsule, 0]
    return out


def simple_sizes(t: DirectTargets, world_scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(which rows, (N, 3) sizes) of boxes, uniformly scaled spheres and z-axis cylinders/capsules, as array
    products; other rows are zero."""
    s = np.abs(world_scale)
    sphere = t.simple & t.is_sphere & (s[:, 0] == s[:, 1]) & (s[:, 0] == s[:, 2])
    box, tube = t.simple & t.is_box, t.simple & t.is_tube
    sizes = np.zeros_like(s)
    sizes[box] = t.unit_size[box] * s[box]
    sizes[sphere, 0] = t.unit_size[sphere, 0] * s[sphere, 0]
    sizes[tube, 0] = t.unit_size[tube, 0] * np.maximum(s[tube, 0], s[tube, 1])
    sizes[tube, 1] = t.unit_size[tube, 1] * s[tube, 2]
    return box | sphere | tube, sizes


__all__ = ["DirectTargets", "targets_for", "simple_sizes", "half_extents"]
