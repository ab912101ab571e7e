"""Simulation state carried across a recompile, element by element (joints, actuators, time)."""
from __future__ import annotations

import mujoco

from graphsdg.sim.compiled_scene import CompiledScene

_QPOS_SIZE = {int(mujoco.mjtJoint.mjJNT_FREE): 7, int(mujoco.mjtJoint.mjJNT_BALL): 4,
              int(mujoco.mjtJoint.mjJNT_SLIDE): 1, int(mujoco.mjtJoint.mjJNT_HINGE): 1}
_DOF_SIZE = {int(mujoco.mjtJoint.mjJNT_FREE): 6, int(mujoco.mjtJoint.mjJNT_BALL): 3,
             int(mujoco.mjtJoint.mjJNT_SLIDE): 1, int(mujoco.mjtJoint.mjJNT_HINGE): 1}


def carry_state(old: CompiledScene, new: CompiledScene) -> None:
    """Copy the simulation state of ``old`` into ``new`` by element name.

    Time, every joint's position, velocity and solver warm start (free joints of
    rigid bodies and the joints of kinematic trees) and every actuator's control,
    velocity target and activation carry over, so a model recompiled for a
    render-only edit (a light, a material, a texture) continues the simulation
    bit for bit. Weld constraints are compiled from the stage (whoever switches
    one authors ``physics:jointEnabled`` and the joint frames, see
    :func:`graphsdg.physics.articulations.set_fixed_joint`); elements new to ``new``
    keep what the stage says.
    """
    om, od, nm, nd = old.model, old.data, new.model, new.data
    nd.time = od.time
    for jid in range(nm.njnt):
        name = mujoco.mj_id2name(nm, mujoco.mjtObj.mjOBJ_JOINT, jid)
        oid = mujoco.mj_name2id(om, mujoco.mjtObj.mjOBJ_JOINT, name) if name else -1
        if oid < 0 or om.jnt_type[oid] != nm.jnt_type[jid]:
            continue
        kind = int(nm.jnt_type[jid])
        nq, nv = _QPOS_SIZE[kind], _DOF_SIZE[kind]
        qa, oqa = nm.jnt_qposadr[jid], om.jnt_qposadr[oid]
        va, ova = nm.jnt_dofadr[jid], om.jnt_dofadr[oid]
        nd.qpos[qa:qa + nq] = od.qpos[oqa:oqa + nq]
        nd.qvel[va:va + nv] = od.qvel[ova:ova + nv]
        nd.qacc_warmstart[va:va + nv] = od.qacc_warmstart[ova:ova + nv]
    for aid in range(nm.nu):
        name = mujoco.mj_id2name(nm, mujoco.mjtObj.mjOBJ_ACTUATOR, aid)
        oid = mujoco.mj_name2id(om, mujoco.mjtObj.mjOBJ_ACTUATOR, name) if name else -1
        if oid < 0:
            continue
        nd.ctrl[aid] = od.ctrl[oid]
        nm.actuator_biasprm[aid, 0] = om.actuator_biasprm[oid, 0]      # the drive's velocity target
        if nm.actuator_actnum[aid] and nm.actuator_actnum[aid] == om.actuator_actnum[oid]:
            na = nm.actuator_actnum[aid]
            nd.act[nm.actuator_actadr[aid]:nm.actuator_actadr[aid] + na] = \
                od.act[om.actuator_actadr[oid]:om.actuator_actadr[oid] + na]
