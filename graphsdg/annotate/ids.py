"""Stable semantic and instance ids, shared by every annotator of a run.

Ids are assigned in first-seen order and never reused, so the same prim has
the same instance id in segmentation images, box rows and mapping files of
every frame, and two runs of the same script assign the same ids.

Reserved ids (Replicator's): 0 = BACKGROUND, 1 = UNLABELLED.
"""
from __future__ import annotations

import json
from typing import Mapping, Sequence

import numpy as np

BACKGROUND_ID = 0
UNLABELLED_ID = 1
FIRST_ID = 2


def labels_key(labels: Mapping[str, Sequence[str]]) -> str:
    """Canonical text of a label set (types sorted, labels in order)."""
    return json.dumps({k: list(v) for k, v in sorted(labels.items())}, separators=(",", ":"))


class IdTable:
    """Maps keys to consecutive ids starting at :data:`FIRST_ID`."""

    def __init__(self) -> None:
        self._ids: dict[str, int] = {}

    def id_of(self, key: str) -> int:
        found = self._ids.get(key)
        if found is None:
            found = self._ids[key] = FIRST_ID + len(self._ids)
        return found

    def clear(self) -> None:
        self._ids.clear()


class IdTables:
    """The run's id tables: semantic (per label set), instance (per labelled prim), mesh (per gprim)."""

    def __init__(self) -> None:
        self.semantic = IdTable()
        self.instance = IdTable()
        self.mesh = IdTable()

    def clear(self) -> None:
        self.semantic.clear()
        self.instance.clear()
        self.mesh.clear()


def color_of(id_: int) -> tuple[int, int, int, int]:
    """The RGBA colour of an id in colorized images; 0 transparent black, 1 opaque black."""
    if id_ == BACKGROUND_ID:
        return (0, 0, 0, 0)
    if id_ == UNLABELLED_ID:
        return (0, 0, 0, 255)
    # Multiplying by an odd constant modulo 2**24 is a bijection, so distinct ids get
    # distinct colours, and neighbouring ids land far apart in colour.
    x = (id_ * 0x5BD1E9) % (1 << 24)
    return ((x >> 16) & 0xFF, (x >> 8) & 0xFF, x & 0xFF, 255)


def sorted_unique(values: np.ndarray) -> np.ndarray:
    """``np.unique(values)`` for a 1-D integer array, through a Python set: a frame's id tables (a few to a
    few thousand ids) come out in half the time, and much less inside a capture loop, where each NumPy call
    pays for cold caches.

    >>> sorted_unique(np.array([3, -1, 3, 0], dtype=np.int32)).tolist()
    [-1, 0, 3]
    """
    return np.array(sorted(set(values.tolist())), dtype=values.dtype)
