"""Write randomized poses and colours straight into MuJoCo (Replicator's write-to-fabric).

With the setting ``/exts/omni.replicator.core/enableWriteToFabric`` on, the
functional ``modify.pose`` / ``display_color`` calls land here: values go into
``mocap_pos``, ``mocap_quat``, ``geom_size`` and ``geom_rgba`` as whole arrays, with
no USD authoring and no change-notice round trip. As in Replicator, the stage is
not updated (saving it keeps the authored values), so readers of USD transforms
see the last authored pose. Prims that are not plain compiled gprims (rigid
bodies, xforms with children, mesh prims whose colliders would need rebuilding)
are not eligible; callers then author USD as usual.
"""
from __future__ import annotations

from typing import Sequence

import mujoco
import numpy as np
from pxr import Usd

from graphsdg.sim.compiler import primitive_size
from graphsdg.sim.scene import SimScene
from graphsdg.stage.xform import decompose, world_matrix


def euler_xyz_to_matrices(angles_deg: np.ndarray) -> np.ndarray:
    """(N, 3) Euler XYZ degrees -> (N, 3, 3) column-vector rotations (R = Rz Ry Rx)."""
    a = np.radians(np.asarray(angles_deg, dtype=np.float64))
    cx, cy, cz = np.cos(a).T
    sx, sy, sz = np.sin(a).T
    r = np.empty((len(a), 3, 3))
    r[:, 0, 0] = cy * cz
    r[:, 0, 1] = sx * sy * cz - cx * sz
    r[:, 0, 2] = cx * sy * cz + sx * sz
    r[:, 1, 0] = cy * sz
    r[:, 1, 1] = sx * sy * sz + cx * cz
    r[:, 1, 2] = cx * sy * sz - sx * cz
    r[:, 2, 0] = -sy
    r[:, 2, 1] = sx * cy
    r[:, 2, 2] = cx * cy
    return r


def matrices_to_quats(r: np.ndarray) -> np.ndarray:
    """(N, 3, 3) rotations -> (N, 4) unit quaternions (w, x, y, z), w >= 0 (Shepperd's method)."""
    r = np.asarray(r, dtype=np.float64)
    m00, m11, m22 = r[:, 0, 0], r[:, 1, 1], r[:, 2, 2]
    q = np.empty((len(r), 4))
    # Take the largest of w, x, y, z from the diagonal for stability, then the rest from off-diagonals.
    cands = np.stack([1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], 1)
    k = np.argmax(cands, axis=1)
    s = np.sqrt(np.maximum(cands[np.arange(len(r)), k], 1e-300)) * 2
    d = lambda i, j: r[:, i, j]  # noqa: E731
    sel = [k == 0, k == 1, k == 2, k == 3]
    q[sel[0]] = np.stack([s / 4, (d(2, 1) - d(1, 2)) / s, (d(0, 2) - d(2, 0)) / s, (d(1, 0) - d(0, 1)) / s], 1)[sel[0]]
    q[sel[1]] = np.stack([(d(2, 1) - d(1, 2)) / s, s / 4, (d(0, 1) + d(1, 0)) / s, (d(0, 2) + d(2, 0)) / s], 1)[sel[1]]
    q[sel[2]] = np.stack([(d(0, 2) - d(2, 0)) / s, (d(0, 1) + d(1, 0)) / s, s / 4, (d(1, 2) + d(2, 1)) / s], 1)[sel[2]]
    q[sel[3]] = np.stack([(d(1, 0) - d(0, 1)) / s, (d(0, 2) + d(2, 0)) / s, (d(1, 2) + d(2, 1)) / s, s / 4], 1)[sel[3]]
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[q[:, 0] < 0] *= -1
    return q


class DirectTargets:
    """Compiled-model indices of a list of prims, cached per compiled model."""

    def __init__(self, sim: SimScene, prims: Sequence[Usd.Prim]) -> None:
        c = sim.ensure_compiled()
        self.paths = [str(p.GetPath()) for p in prims]
        self.bindings = [c.geoms.get(p) for p in self.paths]
        self.eligible = all(b is not None and b.rigid_root is None and b.mocap_id >= 0 for b in self.bindings)
        if not self.eligible:
            return
        self.geom_ids = np.array([b.geom_id for b in self.bindings])
        self.mocap_ids = np.array([b.mocap_id for b in self.bindings])
        parents = [p.GetParent() for p in prims]
        mats = [world_matrix(p) if p and not p.IsPseudoRoot() else np.eye(4) for p in parents]
        self.parent_t = np.array([m[3, :3] for m in mats])
        self.parent_r = np.array([decompose(m)[1] for m in mats])
        self.parent_s = np.array([decompose(m)[2] for m in mats])
        self.is_mesh = np.array([b.type_name in ("Mesh", "Cone") for b in self.bindings])
        self.prims = list(prims)
        # Unit-scale sizes let box, sphere and z-axis cylinder/capsule scales be array products.
        self.is_box = np.array([b.type_name == "Cube" for b in self.bindings])
        self.unit_size = np.zeros((len(self.prims), 3))
        self.simple = np.zeros(len(self.prims), dtype=bool)
        for i, (p, b) in enumerate(zip(self.prims, self.bindings)):
            if b.type_name in ("Cube", "Sphere") or (b.type_name in ("Cylinder", "Capsule")
                                                     and str(p.GetAttribute("axis").Get()) == "Z"):
                self.unit_size[i] = primitive_size(p, np.ones(3))[1]
                self.simple[i] = True
        self.kind = np.array([sim.model.geom_type[b.geom_id] for b in self.bindings])


_cache: dict[tuple, DirectTargets] = {}


def targets_for(sim: SimScene, prims: Sequence[Usd.Prim]) -> DirectTargets:
    sim.sync_dirty_prims()   # structure first: the indices must be current
    key = (id(sim), sim.model_version, tuple(p.GetPath() for p in prims))
    found = _cache.get(key)
    if found is None:
        if len(_cache) > 64:
            _cache.clear()
        found = _cache[key] = DirectTargets(sim, prims)
    return found


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
    sizes = {}
    if scales is not None:
        world_scale = np.asarray(scales, dtype=np.float64).reshape(n, 3) * t.parent_s
        sizes.update(_simple_sizes(t, world_scale))
        for i in range(n):
            if i in sizes:
                continue
            if not t.is_mesh[i]:
                kind, size, _ = primitive_size(t.prims[i], world_scale[i])
                if int(kind) != int(m.geom_type[t.geom_ids[i]]):
                    return False   # e.g. a sphere scaled unevenly becomes an ellipsoid: recompile via USD
                sizes[i] = size
    if positions is not None:
        local = np.asarray(positions, dtype=np.float64).reshape(n, 3)
        d.mocap_pos[t.mocap_ids] = t.parent_t + np.einsum("nij,nj->ni", t.parent_r, local * t.parent_s)
    if rotations is not None:
        rot = np.asarray(rotations, dtype=np.float64)
        if rot.shape[-1] == 4:
            local_r = np.array([_quat_matrix(q) for q in rot.reshape(n, 4)])
        else:
            local_r = euler_xyz_to_matrices(rot.reshape(n, 3))
        d.mocap_quat[t.mocap_ids] = matrices_to_quats(np.einsum("nij,njk->nik", t.parent_r, local_r))
    if scales is not None:
        _write_mesh_scales(sim, t, world_scale)
        rows = np.array(sorted(sizes), dtype=np.int64)
        if rows.size:
            size_arr = np.array([sizes[i] for i in rows])
            gids = t.geom_ids[rows]
            m.geom_size[gids] = size_arr
            m.geom_rbound[gids] = np.linalg.norm(_half_extents(t.kind[rows], size_arr), axis=1)
            for i in rows:
                t.bindings[i].scale = world_scale[i]
    mujoco.mj_kinematics(m, d)
    return True


def write_colors(sim: SimScene, prims: Sequence[Usd.Prim], rgb: np.ndarray) -> bool:
    """Write per-prim display colours into ``geom_rgba``; ``False`` if not eligible."""
    t = targets_for(sim, prims)
    if not t.eligible or any(b.material for b in t.bindings):
        return False
    rgba = np.ones((len(prims), 4))
    rgba[:, :3] = np.asarray(rgb, dtype=np.float64).reshape(len(prims), 3)
    sim.model.geom_rgba[t.geom_ids] = rgba
    return True


def _quat_matrix(q: np.ndarray) -> np.ndarray:
    out = np.empty(9)
    mujoco.mju_quat2Mat(out, np.asarray(q, dtype=np.float64) / max(np.linalg.norm(q), 1e-12))
    return out.reshape(3, 3)


def _write_mesh_scales(sim: SimScene, t: DirectTargets, world_scale: np.ndarray) -> None:
    """Rescale the mesh geoms whose scale changed (compared as one array, not per prim)."""
    mesh_rows = np.flatnonzero(t.is_mesh)
    if not mesh_rows.size:
        return
    old = np.array([t.bindings[i].scale for i in mesh_rows])
    new = world_scale[mesh_rows]
    changed = np.any(np.abs(new - old) > 1e-12 * np.maximum(1.0, np.abs(old)), axis=1)
    for i, row in enumerate(mesh_rows):
        if changed[i]:
            b = t.bindings[row]
            sim.rescale_mesh(b.geom_id, b.scale, new[i])
            b.scale = new[i]


def _half_extents(kinds: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """(N, 3) half extents of primitive geoms of ``kinds`` with ``sizes`` (MuJoCo size convention)."""
    g = mujoco.mjtGeom
    out = np.array(sizes, dtype=np.float64, copy=True)
    sphere = kinds == int(g.mjGEOM_SPHERE)
    out[sphere] = sizes[sphere, :1]
    tube = np.isin(kinds, [int(g.mjGEOM_CYLINDER), int(g.mjGEOM_CAPSULE)])
    out[tube, 1] = sizes[tube, 0]
    out[tube, 2] = sizes[tube, 1]
    capsule = kinds == int(g.mjGEOM_CAPSULE)
    out[capsule, 2] += sizes[capsule, 0]
    return out


def _simple_sizes(t: DirectTargets, world_scale: np.ndarray) -> dict[int, np.ndarray]:
    """Sizes of boxes, uniformly scaled spheres and z-axis cylinders/capsules, as array products."""
    g = mujoco.mjtGeom
    s = np.abs(world_scale)
    out = {}
    box = t.simple & (t.kind == int(g.mjGEOM_BOX))
    sphere = t.simple & (t.kind == int(g.mjGEOM_SPHERE)) & np.all(s == s[:, :1], axis=1)
    tube = t.simple & np.isin(t.kind, [int(g.mjGEOM_CYLINDER), int(g.mjGEOM_CAPSULE)])
    sizes = np.zeros_like(s)
    sizes[box] = t.unit_size[box] * s[box]
    sizes[sphere, 0] = t.unit_size[sphere, 0] * s[sphere, 0]
    sizes[tube, 0] = t.unit_size[tube, 0] * np.maximum(s[tube, 0], s[tube, 1])
    sizes[tube, 1] = t.unit_size[tube, 1] * s[tube, 2]
    for i in np.flatnonzero(box | sphere | tube):
        out[int(i)] = sizes[i]
    return out


__all__ = ["write_poses", "write_colors", "euler_xyz_to_matrices"]
