"""Gprim poses written into MuJoCo's mocap and size arrays: write-to-fabric's MuJoCo path.

Positions and rotations go into ``mocap_pos`` / ``mocap_quat``, scales into ``geom_size`` and ``geom_rbound``
(meshes are rescaled in place, :meth:`~graphsdg.sim.scene.SimScene.rescale_meshes`), all as whole arrays,
with no USD authoring and no change-notice round trip. As in Replicator, the stage keeps its authored values,
so readers of USD transforms see the last authored pose.
"""
from __future__ import annotations

from typing import Sequence

import mujoco
import numpy as np
from pxr import Usd

from graphsdg.maths.rotations import canonical_quat, euler_xyz_to_quat, quat_multiply, unit_quat
from graphsdg.sim.gprims import primitive_size
from graphsdg.sim.pose_writes.targets import DirectTargets, half_extents, simple_sizes, targets_for
from graphsdg.sim.scene import SimScene


def write_poses(sim: SimScene, prims: Sequence[Usd.Prim], positions: np.ndarray | None,
                rotations: np.ndarray | None, scales: np.ndarray | None) -> bool:
    """Write per-prim local poses into MuJoCo; ``False`` (nothing written) if not eligible.

    ``rotations`` are Euler XYZ degrees (N, 3) or quaternions (N, 4).
    """
    t = targets_for(sim, prims)
    if not t.eligible:
        return False
    m, d = sim.model, sim.data
    n = len(prims)
    uniform = None
    if scales is not None:
        world_scale = np.asarray(scales, dtype=np.float64).reshape(n, 3)
        if not t.parent_is_identity:
            world_scale = world_scale * t.parent_s
        current = t.current_scales()
        plan = t.uniform_plan(m)
        if plan is not None:
            uniform = plan.prepare(world_scale, current)
    if scales is not None and uniform is None:
        sized, sizes = simple_sizes(t, world_scale)
        for i in np.flatnonzero(~sized & ~t.is_mesh):   # unevenly scaled spheres, x/y-axis tubes
            kind, size, _ = primitive_size(t.prims[i], world_scale[i])
            if int(kind) != int(m.geom_type[t.geom_ids[i]]):
                return False   # e.g. a sphere scaled unevenly becomes an ellipsoid: recompile via USD
            sizes[i] = size
            sized[i] = True
    if positions is not None:
        local = np.asarray(positions, dtype=np.float64).reshape(n, 3)
        d.mocap_pos[t.mocap_ids] = local if t.parent_is_identity else \
            t.parent_t + np.einsum("nij,nj->ni", t.parent_r, local * t.parent_s)
    if rotations is not None:
        rot = np.asarray(rotations, dtype=np.float64)
        local_q = unit_quat(rot.reshape(n, 4)) if rot.shape[-1] == 4 else euler_xyz_to_quat(rot.reshape(n, 3))
        d.mocap_quat[t.mocap_ids] = local_q if t.parent_is_identity else \
            canonical_quat(quat_multiply(t.parent_q, local_q))
    if uniform is not None:
        plan.write(sim, uniform, world_scale, current)
    elif scales is not None:
        _write_mesh_scales(sim, t, world_scale, current)
        rows = np.flatnonzero(sized)
        if rows.size:
            gids = t.geom_ids[rows]
            m.geom_size[gids] = sizes[rows]
            m.geom_rbound[gids] = np.linalg.norm(half_extents(t, rows, sizes[rows]), axis=1)
            current[rows] = world_scale[rows]   # every binding's scale (its row of this array)
    mujoco.mj_kinematics(m, d)
    return True


def _write_mesh_scales(sim: SimScene, t: DirectTargets, world_scale: np.ndarray, current: np.ndarray) -> None:
    """Rescale the mesh geoms whose scale changed (compared as one array, not per prim); ``current`` is
    :meth:`DirectTargets.current_scales`."""
    rows = t.mesh_rows
    if not rows.size:
        return
    old = current[rows]
    new = world_scale[rows]
    changed = np.any(np.abs(new - old) > 1e-12 * np.maximum(1.0, np.abs(old)), axis=1)
    if not changed.any():
        return
    rows, old, new = rows[changed], old[changed], new[changed]
    sim.rescale_meshes(t.geom_ids[rows], old, new)
    current[rows] = new


__all__ = ["write_poses"]
