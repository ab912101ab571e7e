"""Camera poses written with write-to-fabric: kept beside the stage, read by every render.

With ``/exts/omni.replicator.core/enableWriteToFabric`` on, ``rep.functional.modify.pose`` on cameras lands
here instead of authoring ``xformOp``s: the camera's new local transform is stored by path, and renders
(:func:`graphsdg.render.camera.camera_view`) compose it with the parent's current world transform (a parent
that moves, on the stage or with physics, carries the camera along). As for the geoms of
:mod:`graphsdg.sim.pose_writes.mujoco_poses` (and Replicator's Fabric), the stage keeps its authored pose, so readers of
USD transforms see that one. Authoring the camera's own transform on the stage afterwards makes the stage's
pose count again, as a USD edit reaches Fabric.

Only cameras whose op stack is graphsdg's canonical one (translate, one rotation, scale; what
``rep.functional.create.camera`` authors) are posed here; others are authored as before.

Example:
    >>> import numpy as np
    >>> poses = CameraPoses()
    >>> poses.set_local("/World/Camera", np.eye(4))
    >>> poses.local("/World/Camera").shape
    (4, 4)
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Sequence

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.maths.rotations import compose, decompose, euler_to_matrix, quat_wxyz_to_matrix, unit_quat
from graphsdg.stage.changes import ChangeSet
from graphsdg.stage.prims import prim_facts
from graphsdg.stage.xform import aimed_rotation, parent_world_matrix

if TYPE_CHECKING:
    from graphsdg.sim.scene import SimScene

_ROTATIONS = (UsdGeom.XformOp.TypeRotateXYZ, UsdGeom.XformOp.TypeOrient)


class CameraPoses:
    """Local transforms (row-vector 4x4) of cameras posed with write-to-fabric, by prim path."""

    def __init__(self, parent_world: Callable[[Usd.Prim, str], np.ndarray] | None = None) -> None:
        # (prim, its path) -> its parent's world transform now; the scene's reads are kept until the stage changes
        self._parent_world = parent_world or (lambda prim, path: parent_world_matrix(prim))
        self._local: dict[str, np.ndarray] = {}
        self._parts: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}   # decompose(_local[path])
        self._canonical: dict[str, bool] = {}     # whether a camera's op stack is the canonical one

    def local(self, path: str) -> np.ndarray | None:
        """The camera's local transform if it was posed here since its stage pose last changed, else None."""
        return self._local.get(path)

    def world(self, prim: Usd.Prim) -> np.ndarray | None:
        """The camera's world transform: its local one from here under its parent's current world transform;
        None when it was not posed here."""
        path = prim_facts.path(prim)
        local = self._local.get(path)
        return None if local is None else local @ self._parent_world(prim, path)

    def parent_world(self, prim: Usd.Prim, path: str) -> np.ndarray:
        """The world transform of ``prim``'s parent now (read-only)."""
        return self._parent_world(prim, path)

    def set_local(self, path: str, matrix: np.ndarray,
                  parts: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> None:
        """Pose the camera at ``path`` with the local transform ``matrix``; ``parts``: its (translation,
        rotation, scale), when the caller composed it from them (the next pose starts from them)."""
        self._local[path] = matrix
        if parts is None:
            self._parts.pop(path, None)
        else:
            self._parts[path] = parts

    def local_parts(self, path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(translation, rotation, scale) of :meth:`local`, or None when the camera was not posed here."""
        parts = self._parts.get(path)
        if parts is None:
            local = self._local.get(path)
            if local is None:
                return None
            parts = self._parts[path] = decompose(local)
        return parts

    def forget_edited(self, changes: ChangeSet) -> None:
        """Drop the poses of cameras whose own ``xformOp``s the stage changed, or that a structural change at
        or above them may have replaced."""
        if not self._local and not self._canonical:
            return
        for root in map(str, changes.structural):
            below = root.rstrip("/") + "/"
            for table in (self._local, self._parts, self._canonical):
                for path in [k for k in table if k == root or k.startswith(below)]:
                    del table[path]
        for path, names in changes.edited.items():
            if "*" in names or any(n.startswith("xformOp") for n in names):
                self._local.pop(str(path), None)
                self._parts.pop(str(path), None)
                self._canonical.pop(str(path), None)

    def is_canonical(self, prim: Usd.Prim, path: str | None = None) -> bool:
        """Whether ``prim`` (at ``path``, when the caller has it) is a camera whose op stack is at most a
        translate, one ``rotateXYZ`` or ``orient``, and a scale, in that order, with no reset of the parent's
        transform (cached until the prim's transform is edited or the stage changes above it)."""
        path = prim_facts.path(prim) if path is None else path
        known = self._canonical.get(path)
        if known is None:
            known = self._canonical[path] = prim_facts.is_a(prim, UsdGeom.Camera) and \
                _canonical_stack(UsdGeom.Xformable(prim))
        return known


def _canonical_stack(xf: UsdGeom.Xformable) -> bool:
    if xf.GetResetXformStack():
        return False
    order = (UsdGeom.XformOp.TypeTranslate, _ROTATIONS, UsdGeom.XformOp.TypeScale)
    slot = 0
    for op in xf.GetOrderedXformOps():
        kind = op.GetOpType()
        if op.IsInverseOp() or len(op.GetOpName().split(":")) > 2:   # suffixed ops: pivots, unitsResolve
            return False
        while slot < 3 and not (kind in order[slot] if isinstance(order[slot], tuple) else kind == order[slot]):
            slot += 1
        if slot == 3:
            return False
        slot += 1
    return True


def posed_local(current: np.ndarray, parent: np.ndarray, position: Sequence[float] | None,
                rotation: Sequence[float] | None, look_at: Sequence[float] | None,
                up: Sequence[float]) -> np.ndarray:
    """A camera's new local transform: ``current`` with a new ``position`` (local), ``rotation`` (Euler XYZ
    degrees or a (w, x, y, z) quaternion, local) or aim at the world point ``look_at``, under the parent's
    world transform ``parent``; as :func:`graphsdg.stage.xform.set_local_pose` authors it."""
    return compose(*posed_parts(decompose(current), parent, position, rotation, look_at, up))


def posed_parts(current: tuple[np.ndarray, np.ndarray, np.ndarray], parent: np.ndarray,
                position: Sequence[float] | None, rotation: Sequence[float] | None,
                look_at: Sequence[float] | None, up: Sequence[float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`posed_local` from and to (translation, rotation, scale): a camera posed every frame is not
    decomposed again each time."""
    t, r, s = current
    if position is not None:
        t = np.array(position, dtype=np.float64)   # a copy: the parts are kept for the next pose
    if look_at is not None:
        r = aimed_rotation(t, parent, look_at, up)
    elif rotation is not None:
        rot = np.asarray(rotation, dtype=np.float64)
        r = quat_wxyz_to_matrix(unit_quat(rot)) if rot.shape == (4,) else euler_to_matrix(rot, "XYZ")
    return t, r, s


def write_camera_poses(sim: SimScene, poses: CameraPoses, prims: Sequence[Usd.Prim],
                       positions: np.ndarray | None, rotations: np.ndarray | None, looks: Sequence | None,
                       up: Sequence[float]) -> bool:
    """Pose cameras into ``poses`` without authoring ``sim``'s stage; ``False`` (nothing written) unless every
    prim is a camera with the canonical op stack.

    ``positions`` / ``rotations``: (N, 3) or (N, 4) local values or None; ``looks``: a world point per
    camera or None; ``up``: the up axis of the aim.
    """
    if not prims:
        return False
    sim.sync_dirty_prims()   # edits authored before this write must not undo it at the next sync
    paths = [prim_facts.path(p) for p in prims]
    if not all(poses.is_canonical(p, path) for p, path in zip(prims, paths)):
        return False
    for i, (prim, path) in enumerate(zip(prims, paths)):
        current = poses.local_parts(path)
        if current is None:
            current = decompose(np.array(UsdGeom.Xformable(prim).GetLocalTransformation(Usd.TimeCode.Default()),
                                         dtype=np.float64))
        parts = posed_parts(current, poses.parent_world(prim, path), None if positions is None else positions[i],
                            None if rotations is None else rotations[i], None if looks is None else looks[i], up)
        poses.set_local(path, compose(*parts), parts)
    return True


__all__ = ["CameraPoses", "posed_local", "posed_parts", "write_camera_poses"]
