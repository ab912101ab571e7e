"""Recordables of values that are not poses: the simulation clock and any USD attribute.

:class:`SimTimeRecordable` records ``sim_time`` (seconds), ``physics_step`` and
``wall_time`` (seconds since the epoch) every frame; every session has one
(group ``meta/time``) unless told otherwise, and a replay uses its times to move
the timeline. :class:`AttributeRecordable` records one attribute's value, its
shape and dtype probed when the session opens and kept in the manifest.
"""
from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from graphsdg.episodes import sim_clock
from graphsdg.episodes.channels import ChannelDescriptor, ReplayPolicy
from graphsdg.episodes.pose_recordables import failed
from graphsdg.episodes.recordable import Recordable
from graphsdg.episodes.registry import register_recordable

SIM_TIME_GROUP = "meta/time"


@register_recordable
class SimTimeRecordable(Recordable):
    """Simulated time, physics step count and wall-clock time per frame; applying a frame changes nothing."""

    TYPE_ID = "sim_time"

    def __init__(self, *, group: str = SIM_TIME_GROUP) -> None:
        super().__init__(group=group)

    def describe_channels(self) -> dict[str, ChannelDescriptor]:
        return {"sim_time": ChannelDescriptor(shape=(), dtype="f8", units="seconds"),
                "physics_step": ChannelDescriptor(shape=(), dtype="i8"),
                "wall_time": ChannelDescriptor(shape=(), dtype="f8", units="seconds")}

    def sample(self) -> dict[str, Any]:
        seconds, steps = sim_clock.read()
        return {"sim_time": float(seconds), "physics_step": int(steps), "wall_time": time.time()}

    def apply(self, frame: Mapping[str, np.ndarray], *, policy: ReplayPolicy) -> None:
        """Nothing to put back: the replayer moves the timeline to the recorded times itself."""

    def to_manifest(self) -> dict[str, Any]:
        return {"type": self.TYPE_ID, "group": self.group}

    @classmethod
    def from_manifest(cls, entry: Mapping[str, Any]) -> SimTimeRecordable:
        return cls(group=entry.get("group", SIM_TIME_GROUP))


def probe_shape_dtype(value: Any) -> tuple[tuple[int, ...], str]:
    """The per-frame shape and dtype code of an attribute value (bool, int, float, vector, array)."""
    if value is None:
        return (), "f4"
    if isinstance(value, (bool, np.bool_)):
        return (), "bool"
    if isinstance(value, (int, np.integer)):
        return (), "i8"
    if isinstance(value, float):
        return (), "f4"
    arr = np.asarray(value)
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"attribute values of type {type(value).__name__} ({arr.dtype}) cannot be recorded; "
                        f"numbers, vectors and numeric arrays can")
    return tuple(arr.shape), arr.dtype.str.lstrip("<>|=")


@register_recordable
class AttributeRecordable(Recordable):
    """One USD attribute's value per frame (channel ``value``)."""

    TYPE_ID = "usd_attribute"

    def __init__(self, *, group: str, prim_path: str, attribute_name: str, shape: tuple[int, ...] | None = None,
                 dtype: str | None = None) -> None:
        super().__init__(group=group)
        self.prim_path = str(prim_path)
        self.attribute_name = str(attribute_name)
        self._shape = None if shape is None else tuple(int(d) for d in shape)
        self._dtype = dtype
        self._stage: Any = None

    def describe_channels(self) -> dict[str, ChannelDescriptor]:
        return {"value": ChannelDescriptor(shape=self._shape or (), dtype=self._dtype or "f4")}

    def _attribute(self) -> Any:
        prim = self._stage.GetPrimAtPath(self.prim_path) if self._stage is not None else None
        if prim is None or not prim.IsValid():
            raise RuntimeError(f"AttributeRecordable: no prim at {self.prim_path}")
        attr = prim.GetAttribute(self.attribute_name)
        if not attr:
            raise RuntimeError(f"AttributeRecordable: {self.prim_path} has no attribute {self.attribute_name!r}")
        return attr

    def on_session_open(self, stage: Any) -> None:
        self._stage = stage
        if self._shape is None or self._dtype is None:
            shape, dtype = probe_shape_dtype(self._attribute().Get())
            self._shape = shape if self._shape is None else self._shape
            self._dtype = dtype if self._dtype is None else self._dtype

    def on_session_close(self) -> None:
        self._stage = None

    def sample(self) -> dict[str, Any]:
        value = self._attribute().Get()
        if value is None:
            return {"value": np.zeros(self._shape or (), dtype=self._dtype or "f4")}
        return {"value": np.asarray(value).astype(self._dtype or "f4")}

    def apply(self, frame: Mapping[str, np.ndarray], *, policy: ReplayPolicy) -> None:
        what = f"AttributeRecordable {self.prim_path}.{self.attribute_name}"
        try:
            attr = self._attribute()
            if "value" not in frame:
                raise ValueError(f"frame has no 'value' channel; it has {sorted(frame)}")
            raw = np.asarray(frame["value"])
            attr.Set(raw.item() if raw.ndim == 0 else raw.tolist())
        except (RuntimeError, ValueError, TypeError) as exc:
            failed(policy, what, exc)

    def to_manifest(self) -> dict[str, Any]:
        return {"type": self.TYPE_ID, "group": self.group, "prim_path": self.prim_path,
                "attribute_name": self.attribute_name, "shape": None if self._shape is None else list(self._shape),
                "dtype": self._dtype}

    @classmethod
    def from_manifest(cls, entry: Mapping[str, Any]) -> AttributeRecordable:
        shape = entry.get("shape")
        return cls(group=entry["group"], prim_path=entry["prim_path"], attribute_name=entry["attribute_name"],
                   shape=None if shape is None else tuple(shape), dtype=entry.get("dtype"))
