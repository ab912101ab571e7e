"""Recordables of one prim's pose. A rigid body, any xform (world or local), a camera with its lens.

Each records ``position`` (3, metres) and ``orientation`` (4, quaternion w, x, y,
z). World-space ones take part in the session's pose batch (one read of every
pose per tick, :func:`graphsdg.physics.simulated_poses.read_world_poses`, which
reads simulated bodies from the simulation itself); local-space ones read the
prim's own transform. Replay writes the pose back
(:func:`~graphsdg.physics.simulated_poses.write_world_poses`), so a free body
or a mocap body teleports and a link of a kinematic tree moves its joint.
"""
from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Any

import numpy as np
from pxr import UsdGeom

from graphsdg.episodes.channels import ChannelDescriptor, ReplayPolicy
from graphsdg.episodes.recordable import Recordable
from graphsdg.episodes.registry import register_recordable
from graphsdg.functional import modify
from graphsdg.physics.simulated_poses import read_local_poses, read_world_poses, write_world_poses

log = logging.getLogger("graphsdg.episodes")
SPACES = ("world", "local")


def failed(policy: ReplayPolicy, what: str, exc: BaseException) -> None:
    """Raise ``exc`` under a strict policy, else log that ``what`` was skipped."""
    if policy.strict:
        raise exc
    log.warning("%s skipped: %s", what, exc)


def pose_channels(space: str) -> dict[str, ChannelDescriptor]:
    """The position and orientation channels of a pose recorded in ``space``."""
    return {"position": ChannelDescriptor(shape=(3,), dtype="f4", units="meters", space=space),
            "orientation": ChannelDescriptor(shape=(4,), dtype="f4", space=space, quaternion_order="wxyz")}


def pose_frame(frame: Mapping[str, Any], rows: int, singular: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """The (rows, 3) positions and (rows, 4) orientations of a recorded frame (ValueError if malformed)."""
    keys = ("position", "orientation") if singular else ("positions", "orientations")
    missing = [k for k in keys if k not in frame]
    if missing:
        raise ValueError(f"frame has no {missing[0]!r} channel; it has {sorted(frame)}")
    return (np.asarray(frame[keys[0]], dtype=np.float64).reshape(rows, 3),
            np.asarray(frame[keys[1]], dtype=np.float64).reshape(rows, 4))


class PoseRecordable(Recordable):
    """The pose of one prim in world or local space (the shared part of the pose recordables)."""

    def __init__(self, *, group: str, prim_path: str, space: str = "world") -> None:
        super().__init__(group=group)
        if space not in SPACES:
            raise ValueError(f"{type(self).__name__} space must be one of {SPACES}, got {space!r}")
        self.prim_path = str(prim_path)
        self.space = space
        self._prim: Any = None

    def describe_channels(self) -> dict[str, ChannelDescriptor]:
        return pose_channels(self.space)

    def on_session_open(self, stage: Any) -> None:
        prim = stage.GetPrimAtPath(self.prim_path) if stage is not None else None
        if prim is None or not prim.IsValid():
            raise RuntimeError(f"{type(self).__name__}: no prim at {self.prim_path} on the stage")
        if not prim.IsA(UsdGeom.Xformable):
            raise RuntimeError(f"{type(self).__name__}: prim {self.prim_path} ({prim.GetTypeName()}) has no pose")
        self._prim = prim

    def on_session_close(self) -> None:
        self._prim = None

    def _bound(self) -> Any:
        if self._prim is None or not self._prim.IsValid():
            raise RuntimeError(f"{type(self).__name__} {self.prim_path} is not bound; open a session first")
        return self._prim

    def pose_paths(self) -> list[str] | None:
        """The prim, for the shared batch, when recorded in world space."""
        return [self.prim_path] if self.space == "world" else None

    def consume_pose_batch(self, positions: np.ndarray, orientations: np.ndarray) -> dict[str, Any]:
        return {"position": positions[0], "orientation": orientations[0]}

    def sample(self) -> dict[str, Any]:
        prim = self._bound()
        if self.space == "world":
            pos, quat = read_world_poses([self.prim_path])
            return {"position": pos[0].astype(np.float32), "orientation": quat[0].astype(np.float32)}
        pos, quat = read_local_poses([str(prim.GetPath())])
        return {"position": pos[0].astype(np.float32), "orientation": quat[0].astype(np.float32)}

    def apply(self, frame: Mapping[str, np.ndarray], *, policy: ReplayPolicy) -> None:
        what = f"{type(self).__name__} {self.prim_path}"
        try:
            prim = self._bound()
            pos, quat = pose_frame(frame, 1)
            if self.space == "world":
                write_world_poses([self.prim_path], pos, quat)
            else:
                modify.pose(prim, position_value=pos[0], rotation_value=quat[0])
        except (RuntimeError, ValueError, TypeError) as exc:
            failed(policy, what, exc)

    def to_manifest(self) -> dict[str, Any]:
        return {"type": self.TYPE_ID, "group": self.group, "prim_path": self.prim_path}

    @classmethod
    def from_manifest(cls, entry: Mapping[str, Any]) -> PoseRecordable:
        return cls(group=entry["group"], prim_path=entry["prim_path"])


@register_recordable
class RigidBodyRecordable(PoseRecordable):
    """The world pose of one rigid body (as simulated)."""

    TYPE_ID = "rigid_body"

    def __init__(self, *, group: str, prim_path: str) -> None:
        super().__init__(group=group, prim_path=prim_path, space="world")


@register_recordable
class XformRecordable(PoseRecordable):
    """The pose of any xformable prim, in world or local (parent) space."""

    TYPE_ID = "xform"

    def to_manifest(self) -> dict[str, Any]:
        return {**super().to_manifest(), "space": self.space}

    @classmethod
    def from_manifest(cls, entry: Mapping[str, Any]) -> XformRecordable:
        return cls(group=entry["group"], prim_path=entry["prim_path"], space=entry.get("space", "world"))


_LENS = {"focal_length": "focalLength", "horizontal_aperture": "horizontalAperture",
         "vertical_aperture": "verticalAperture"}


@register_recordable
class CameraRecordable(PoseRecordable):
    """A camera's world pose and lens (focal length, apertures, clipping range) per frame."""

    TYPE_ID = "camera"

    def __init__(self, *, group: str, prim_path: str, resolution: tuple[int, int] | None = None) -> None:
        super().__init__(group=group, prim_path=prim_path, space="world")
        self.resolution = None if resolution is None else (int(resolution[0]), int(resolution[1]))

    def describe_channels(self) -> dict[str, ChannelDescriptor]:
        lens = {name: ChannelDescriptor(shape=(), dtype="f4") for name in _LENS}
        return {**pose_channels("world"), **lens, "clipping_range": ChannelDescriptor(shape=(2,), dtype="f4")}

    def on_session_open(self, stage: Any) -> None:
        super().on_session_open(stage)
        if not self._prim.IsA(UsdGeom.Camera):
            raise RuntimeError(f"CameraRecordable: prim {self.prim_path} is a {self._prim.GetTypeName()}, "
                               f"not a Camera")

    def _lens(self) -> dict[str, Any]:
        camera = UsdGeom.Camera(self._bound())
        values = {name: np.float32(camera.GetPrim().GetAttribute(attr).Get() or 0.0) for name, attr in _LENS.items()}
        clip = camera.GetClippingRangeAttr().Get()
        values["clipping_range"] = np.asarray([clip[0], clip[1]] if clip is not None else [0.0, 0.0], np.float32)
        return values

    def consume_pose_batch(self, positions: np.ndarray, orientations: np.ndarray) -> dict[str, Any]:
        return {**super().consume_pose_batch(positions, orientations), **self._lens()}

    def sample(self) -> dict[str, Any]:
        return {**super().sample(), **self._lens()}

    def apply(self, frame: Mapping[str, np.ndarray], *, policy: ReplayPolicy) -> None:
        super().apply(frame, policy=policy)
        self.apply_besides_pose_batch(frame, policy=policy)

    def apply_besides_pose_batch(self, frame: Mapping[str, np.ndarray], *, policy: ReplayPolicy) -> None:
        """Author the recorded lens values of ``frame`` on the camera."""
        try:
            prim = self._bound()
            for name, attr in _LENS.items():
                if name in frame:
                    prim.GetAttribute(attr).Set(float(frame[name]))
            if "clipping_range" in frame:
                near, far = (float(v) for v in np.asarray(frame["clipping_range"]).reshape(2))
                UsdGeom.Camera(prim).GetClippingRangeAttr().Set((near, far))
        except (RuntimeError, ValueError) as exc:
            failed(policy, f"CameraRecordable {self.prim_path} lens", exc)

    def to_manifest(self) -> dict[str, Any]:
        entry = super().to_manifest()
        if self.resolution is not None:
            entry["resolution"] = list(self.resolution)
        return entry

    @classmethod
    def from_manifest(cls, entry: Mapping[str, Any]) -> CameraRecordable:
        res = entry.get("resolution")
        return cls(group=entry["group"], prim_path=entry["prim_path"], resolution=None if res is None else tuple(res))
