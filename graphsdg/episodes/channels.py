"""What one recorded signal looks like. Also how often recordables are sampled, and how strict replay is.

:class:`ChannelDescriptor` is the per-frame shape and dtype of one dataset of a
session file (plus units, space and quaternion order, stored as dataset
attributes); :class:`SamplingConfig` picks the tick that samples a session and a
decimation; :class:`ReplayPolicy` says whether replay logs and skips a failed
binding or raises.

Example:
    >>> ChannelDescriptor(shape=(3,), dtype="f4", units="meters").shape
    (3,)
    >>> ChannelDescriptor(shape=(4,), dtype="f4", quaternion_order="zyxw")
    Traceback (most recent call last):
    ...
    ValueError: ChannelDescriptor quaternion_order must be 'wxyz' or 'xyzw', got 'zyxw'
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

SAMPLING_MODES = ("physics_post_step", "app_update")
STRICTNESS_LEVELS = ("best_effort", "strict")


@dataclass(frozen=True)
class ChannelDescriptor:
    """The per-frame shape and NumPy dtype code of one recorded signal, with optional unit and frame tags."""

    shape: tuple[int, ...]
    dtype: str
    units: str | None = None
    space: str | None = None
    quaternion_order: str | None = None
    attrs: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        shape = tuple(self.shape)
        object.__setattr__(self, "shape", shape)
        bad = [d for d in shape if isinstance(d, bool) or not isinstance(d, int) or d < 0]
        if bad:
            raise ValueError(f"ChannelDescriptor shape {shape!r} must hold non-negative ints, got {bad!r}")
        if not isinstance(self.dtype, str):
            raise TypeError(f"ChannelDescriptor dtype must be a NumPy dtype code such as 'f4', "
                            f"got {type(self.dtype).__name__}")
        try:
            np.dtype(self.dtype)
        except TypeError as exc:
            raise ValueError(f"ChannelDescriptor dtype {self.dtype!r} is not a NumPy dtype code") from exc
        if self.quaternion_order not in (None, "wxyz", "xyzw"):
            raise ValueError(f"ChannelDescriptor quaternion_order must be 'wxyz' or 'xyzw', "
                             f"got {self.quaternion_order!r}")


@dataclass
class SamplingConfig:
    """When a session samples its recordables: after every physics step or every app update, every Nth tick."""

    mode: str = "physics_post_step"
    decimation: int = 1

    def __post_init__(self) -> None:
        if self.mode not in SAMPLING_MODES:
            raise ValueError(f"SamplingConfig mode must be one of {SAMPLING_MODES}, got {self.mode!r}")
        if isinstance(self.decimation, bool) or not isinstance(self.decimation, int) or self.decimation < 1:
            raise ValueError(f"SamplingConfig decimation must be an int >= 1, got {self.decimation!r}")


@dataclass
class ReplayPolicy:
    """How replay treats a recordable that cannot bind or apply: log and skip (best_effort) or raise (strict)."""

    strictness: str = "best_effort"

    def __post_init__(self) -> None:
        if self.strictness not in STRICTNESS_LEVELS:
            raise ValueError(f"ReplayPolicy strictness must be one of {STRICTNESS_LEVELS}, got {self.strictness!r}")

    @property
    def strict(self) -> bool:
        """Whether a failure raises instead of being logged."""
        return self.strictness == "strict"
