"""The world poses of every link of an articulation, recorded per frame. One (L, 3) / (L, 4) pair of channels a
frame.

The links are the articulation root and the rigid bodies below it (or, for a
tree without rigid bodies, every xformable prim below it), in depth-first child
order, skipping joints; they are found when the session opens and kept in the
manifest, so a replay binds to the same prims in the same order. Poses are read
as simulated (:func:`graphsdg.physics.simulated_poses.read_world_poses`); replay
puts them back by solving the joints that move the links
(:func:`~graphsdg.physics.simulated_poses.write_world_poses`), so what is drawn
is the recorded motion.
"""
from __future__ import annotations

import logging
from collections import deque
from collections.abc import Mapping
from typing import Any

import numpy as np
from pxr import Usd, UsdGeom, UsdPhysics

from graphsdg.episodes.channels import ChannelDescriptor, ReplayPolicy
from graphsdg.episodes.pose_recordables import failed, pose_frame
from graphsdg.episodes.recordable import Recordable
from graphsdg.episodes.registry import register_recordable
from graphsdg.physics.simulated_poses import read_world_poses, write_world_poses

log = logging.getLogger("graphsdg.episodes")


def _walk(root: Usd.Prim, skip: str | None = None) -> list[Usd.Prim]:
    """Active descendants of ``root`` breadth-first in child order, not entering joints (or ``skip``)."""
    found, queue = [], deque(root.GetChildren())
    while queue:
        prim = queue.popleft()
        if not prim.IsValid() or not prim.IsActive() or prim.IsA(UsdPhysics.Joint) or str(prim.GetPath()) == skip:
            continue
        found.append(prim)
        queue.extend(prim.GetChildren())
    return found


def discover_links(stage: Usd.Stage, root_path: str, include_root: bool = True) -> list[str]:
    """The link prims of the articulation rooted at ``root_path`` (see the module docstring)."""
    root = stage.GetPrimAtPath(root_path)
    walk_root = root
    if not root.IsA(UsdGeom.Xformable) or root.IsA(UsdPhysics.Joint):
        # a fixed base's ArticulationRootAPI may sit on a joint: its links live under the nearest xformable ancestor
        walk_root = root.GetParent()
        while walk_root.IsValid() and not walk_root.IsA(UsdGeom.Xformable):
            walk_root = walk_root.GetParent()
        if not walk_root.IsValid() or not any(p.IsA(UsdGeom.Xformable) for p in _walk(walk_root, skip=root_path)):
            return []
    below = [p for p in _walk(walk_root) if p.IsA(UsdGeom.Xformable)]
    rigid = [p for p in below if p.HasAPI(UsdPhysics.RigidBodyAPI)]
    links = [str(p.GetPath()) for p in (rigid or below)]
    root_str = str(walk_root.GetPath())
    if include_root and walk_root.IsA(UsdGeom.Xformable) and root_str not in links:
        links.insert(0, root_str)
    return links


@register_recordable
class ArticulationRecordable(Recordable):
    """World poses of an articulation's links (see the module docstring)."""

    TYPE_ID = "articulation"

    def __init__(self, *, group: str, prim_path: str, link_paths: list[str] | None = None,
                 include_root: bool = True) -> None:
        super().__init__(group=group)
        self.prim_path = str(prim_path)
        self.include_root = bool(include_root)
        self._links: list[str] = [str(p) for p in (link_paths or [])]
        self._bound = False

    @property
    def num_links(self) -> int:
        """How many links are recorded."""
        return len(self._links)

    @property
    def link_paths(self) -> list[str]:
        """The recorded links, in channel row order."""
        return list(self._links)

    def describe_channels(self) -> dict[str, ChannelDescriptor]:
        n = self.num_links
        return {"positions": ChannelDescriptor(shape=(n, 3), dtype="f4", units="meters", space="world"),
                "orientations": ChannelDescriptor(shape=(n, 4), dtype="f4", space="world", quaternion_order="wxyz")}

    def on_session_open(self, stage: Any) -> None:
        if not stage.GetPrimAtPath(self.prim_path).IsValid():
            raise RuntimeError(f"ArticulationRecordable: no prim at {self.prim_path} on the stage")
        if not self._links:
            self._links = discover_links(stage, self.prim_path, self.include_root)
        missing = [p for p in self._links if not stage.GetPrimAtPath(p).IsValid()]
        if missing:
            raise RuntimeError(f"ArticulationRecordable {self.prim_path}: links {missing} are not on the stage")
        self._bound = bool(self._links)
        if not self._links:
            log.warning("ArticulationRecordable %s: no xformable links below it; it records nothing this session",
                        self.prim_path)

    def on_session_close(self) -> None:
        self._bound = False

    def pose_paths(self) -> list[str] | None:
        """Every link, for the shared pose batch."""
        return list(self._links) if self._bound else None

    def consume_pose_batch(self, positions: np.ndarray, orientations: np.ndarray) -> dict[str, Any]:
        return {"positions": positions.reshape(self.num_links, 3), "orientations": orientations.reshape(self.num_links, 4)}

    def sample(self) -> dict[str, Any]:
        if not self._bound:
            return {"positions": np.zeros((0, 3), np.float32), "orientations": np.zeros((0, 4), np.float32)}
        pos, quat = read_world_poses(self._links)
        return {"positions": pos.astype(np.float32), "orientations": quat.astype(np.float32)}

    def apply(self, frame: Mapping[str, np.ndarray], *, policy: ReplayPolicy) -> None:
        what = f"ArticulationRecordable {self.prim_path}"
        if not self._bound:
            failed(policy, what, RuntimeError(f"{what} is not bound to any link"))
            return
        try:
            pos, quat = pose_frame(frame, self.num_links, singular=False)
            write_world_poses(self._links, pos, quat)
        except (RuntimeError, ValueError, TypeError) as exc:
            failed(policy, what, exc)

    def to_manifest(self) -> dict[str, Any]:
        return {"type": self.TYPE_ID, "group": self.group, "prim_path": self.prim_path,
                "include_root": self.include_root, "link_paths": list(self._links)}

    @classmethod
    def from_manifest(cls, entry: Mapping[str, Any]) -> ArticulationRecordable:
        return cls(group=entry["group"], prim_path=entry["prim_path"], link_paths=list(entry.get("link_paths", [])),
                   include_root=bool(entry.get("include_root", True)))
