"""World poses of prims as the simulation has them, read and written in batches.

Reading: a simulated rigid body's pose comes from MuJoCo (current even inside a
physics step, before the stage is written back), a prim below a body follows that
body through its authored offset, and any other prim is read from the stage;
world poses or poses relative to the parent (:func:`read_local_poses`).

Writing (a replay teleporting the stage): prims are posed parents first; free and
kinematic bodies and plain xforms are authored on the stage (the simulation
teleports them when it syncs), while the links of a kinematic tree, which follow
their joints, are placed by solving their joints' values from the poses
(:mod:`graphsdg.physics.joint_fit`) and their new poses are then written back to
the stage as simulated poses are.

:func:`save_joint_state` / :func:`restore_joint_state` keep the joint values a
replay overwrote, to put the simulation back afterwards.

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(position=(0, 0, 1), name="Cube")
    >>> write_world_poses(["/Cube"], [[1.0, 2.0, 3.0]], [[1.0, 0.0, 0.0, 0.0]])
    >>> positions, orientations = read_world_poses(["/Cube"])
    >>> positions.tolist(), orientations.tolist()
    ([[1.0, 2.0, 3.0]], [[1.0, 0.0, 0.0, 0.0]])
"""
from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np
from pxr import Sdf, UsdGeom

from graphsdg.maths.rotations import compose, decompose, matrix_to_quat_wxyz, quat_wxyz_to_matrix
from graphsdg.physics.joint_fit import fit_joint_positions
from graphsdg.physics.world_pose import set_world_pose
from graphsdg.engine.runtime import runtime
from graphsdg.sim.compiled_scene import CompiledScene
from graphsdg.stage.prims import resolve_prim
from graphsdg.stage.xform import world_matrix


def _pose_arrays(paths: Sequence[str], positions, orientations) -> tuple[np.ndarray, np.ndarray]:
    n = len(paths)
    pos = np.asarray(positions, dtype=np.float64)
    quat = np.asarray(orientations, dtype=np.float64)
    if pos.size != 3 * n or quat.size != 4 * n:
        raise ValueError(f"{n} prims need positions of shape ({n}, 3) and orientations ({n}, 4) (w, x, y, z); "
                         f"got {pos.shape} and {quat.shape}")
    pos, quat = pos.reshape(n, 3), quat.reshape(n, 4)
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(quat))):
        raise ValueError("positions and orientations must be finite")
    norms = np.linalg.norm(quat, axis=1)
    if np.any(norms < 1e-9):
        raise ValueError(f"orientations must be non-zero quaternions (w, x, y, z); rows {np.flatnonzero(norms < 1e-9)}"
                         f" are zero")
    return pos, quat / norms[:, None]


def _body_pose(c: CompiledScene, path: str) -> tuple[np.ndarray, np.ndarray]:
    b = c.bodies[path]
    d = c.data
    if b.mocap_id >= 0:
        return d.mocap_pos[b.mocap_id], d.mocap_quat[b.mocap_id]
    if b.qpos_adr >= 0:
        return d.qpos[b.qpos_adr:b.qpos_adr + 3], d.qpos[b.qpos_adr + 3:b.qpos_adr + 7]
    return d.xpos[b.body_id], d.xquat[b.body_id]


def _simulated_ancestor(c: CompiledScene | None, path: Sdf.Path) -> str | None:
    if c is None or not c.bodies:
        return None
    for ancestor in path.GetPrefixes()[::-1]:
        if str(ancestor) in c.bodies:
            return str(ancestor)
    return None


def _simulated_world_matrices(prims: list) -> list[np.ndarray]:
    """World matrices (row-vector, authored scale kept) of ``prims`` with simulated bodies where the simulation has
    them and prims below a body carried along by their authored offset from it."""
    c = runtime().sim.compiled
    anchors = [_simulated_ancestor(c, p.GetPath()) if p.GetPath() != Sdf.Path.absoluteRootPath else None
               for p in prims]
    if any(a is not None and c.bodies[a].articulated for a in anchors):
        # links' frames are computed from the joints; inside a physics step they lag the step just taken
        mujoco.mj_kinematics(c.model, c.data)
    cache = UsdGeom.XformCache()
    matrices = []
    for prim, anchor in zip(prims, anchors):
        if not prim.IsA(UsdGeom.Xformable):
            matrices.append(np.eye(4))
            continue
        authored = world_matrix(prim, cache)
        if anchor is None:
            matrices.append(authored)
            continue
        pos, quat = _body_pose(c, anchor)
        body_world = authored if anchor == str(prim.GetPath()) else \
            world_matrix(prim.GetStage().GetPrimAtPath(anchor), cache)
        simulated = compose(pos, quat_wxyz_to_matrix(quat), decompose(body_world)[2])
        matrices.append(authored @ np.linalg.inv(body_world) @ simulated)
    return matrices


def _poses(matrices: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    positions = np.zeros((len(matrices), 3))
    orientations = np.zeros((len(matrices), 4))
    for i, m in enumerate(matrices):
        t, r, _ = decompose(m)
        positions[i], orientations[i] = t, matrix_to_quat_wxyz(r)
    return positions, orientations


def read_world_poses(paths: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """World positions (N, 3) and orientations (N, 4, w x y z) of the prims at ``paths`` as simulated now."""
    stage = runtime().stage
    return _poses(_simulated_world_matrices([resolve_prim(p, stage) for p in paths]))


def read_local_poses(paths: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """Poses of the prims at ``paths`` relative to their parents (translations (N, 3), orientations (N, 4)),
    both as simulated now."""
    stage = runtime().stage
    prims = [resolve_prim(p, stage) for p in paths]
    matrices = _simulated_world_matrices(prims + [p.GetParent() for p in prims])
    n = len(prims)
    return _poses([matrices[i] @ np.linalg.inv(matrices[n + i]) for i in range(n)])


def _below_any(path: Sdf.Path, roots: set[Sdf.Path]) -> bool:
    return any(path.HasPrefix(root) and path != root for root in roots)


def write_world_poses(paths: Sequence[str], positions, orientations) -> None:
    """Place the prims at ``paths`` at these world poses (see the module docstring), parents first."""
    pos, quat = _pose_arrays(paths, positions, orientations)
    rt = runtime()
    stage, sim = rt.stage, rt.sim
    prims = [resolve_prim(p, stage) for p in paths]
    not_xformable = [str(p.GetPath()) for p in prims if not p.IsA(UsdGeom.Xformable)]
    if not_xformable:
        raise TypeError(f"prims {not_xformable} are not Xformable; they have no pose to write")
    sim.sync_dirty_prims()
    c = sim.ensure_compiled()
    links = {i for i, p in enumerate(prims) if str(p.GetPath()) in c.bodies and c.bodies[str(p.GetPath())].articulated}
    link_paths = {prims[i].GetPath() for i in links}
    by_depth = sorted((i for i in range(len(prims)) if i not in links), key=lambda i: prims[i].GetPath().pathElementCount)
    before = [i for i in by_depth if not _below_any(prims[i].GetPath(), link_paths)]
    after = [i for i in by_depth if _below_any(prims[i].GetPath(), link_paths)]
    for i in before:
        set_world_pose(prims[i], position=pos[i], orientation=quat[i])
    if links:
        sim.sync_dirty_prims()   # free bodies teleport, a first edit in a new layer may recompile
        c = sim.ensure_compiled()
        fit_joint_positions(c.model, c.data, {c.bodies[str(prims[i].GetPath())].body_id: (pos[i], quat[i])
                                              for i in links})
        mujoco.mj_forward(c.model, c.data)
        sim.write_back_rigid_bodies()
    for i in after:
        set_world_pose(prims[i], position=pos[i], orientation=quat[i])


def save_joint_state() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every tree joint's position and velocity values now, by joint path."""
    sim = runtime().sim
    sim.sync_dirty_prims()
    c = sim.ensure_compiled()
    saved = {}
    for path, j in c.joints.items():
        if j.joint_id < 0:
            continue
        nq, nv = _joint_sizes(c.model, j.joint_id)
        saved[path] = (c.data.qpos[j.qpos_adr:j.qpos_adr + nq].copy(), c.data.qvel[j.dof_adr:j.dof_adr + nv].copy())
    return saved


def _joint_sizes(model: mujoco.MjModel, joint: int) -> tuple[int, int]:
    kind = int(model.jnt_type[joint])
    return {mujoco.mjtJoint.mjJNT_FREE: (7, 6), mujoco.mjtJoint.mjJNT_BALL: (4, 3)}.get(kind, (1, 1))


def restore_joint_state(saved: dict[str, tuple[np.ndarray, np.ndarray]]) -> None:
    """Put back joint values :func:`save_joint_state` kept (joints gone since are skipped) and write back poses."""
    sim = runtime().sim
    sim.sync_dirty_prims()
    c = sim.ensure_compiled()
    for path, (qpos, qvel) in saved.items():
        j = c.joints.get(path)
        if j is None or j.joint_id < 0 or _joint_sizes(c.model, j.joint_id) != (len(qpos), len(qvel)):
            continue
        c.data.qpos[j.qpos_adr:j.qpos_adr + len(qpos)] = qpos
        c.data.qvel[j.dof_adr:j.dof_adr + len(qvel)] = qvel
    mujoco.mj_forward(c.model, c.data)
    sim.write_back_rigid_bodies()
