"""The classes of a dataset as the viewers show them. One id and one colour per class name.

A class's colour depends on its name only (the same in every dataset, format and
viewer: the contact sheet, the HTML gallery and the Rerun recording); its id is
its place in the table (1, 2, ...; 0 means "no class" in masks), which grows as
classes are met.

Example:
    >>> table = ClassTable(["cube", "ball"])
    >>> table.id_of("ball"), table.id_of("cube"), table.id_of("cone"), table.names
    (1, 2, 3, ['ball', 'cube', 'cone'])
"""
from __future__ import annotations

import threading
from typing import Iterable

import numpy as np

from graphsdg.annotate.ids import color_of
from graphsdg.dataset.view_frame import relabel, smallest_uint
from graphsdg.rng import stable_key


def class_colour(label: str) -> tuple[int, int, int]:
    """The colour a class is drawn in (the same in every dataset and format)."""
    return tuple(int(c) for c in color_of(stable_key("class", label) % 100_000 + 2)[:3])


class ClassTable:
    """Class names -> ids 1, 2, ... (the names given at first sorted, later ones appended as met)."""

    def __init__(self, names: Iterable[str] = ()) -> None:
        self.names: list[str] = []
        self._ids: dict[str, int] = {}
        self._adding = threading.Lock()   # frames are read on worker threads, each may meet a new class
        for name in sorted(set(names)):
            self.id_of(name)

    def id_of(self, name: str) -> int:
        """The id of class ``name``, added to the table if new."""
        found = self._ids.get(name)
        if found is None:
            with self._adding:
                found = self._ids.get(name)
                if found is None:
                    self.names.append(name)
                    found = self._ids[name] = len(self.names)
        return found

    def known(self, name: str) -> int | None:
        """The id of class ``name`` if the table has it (the table unchanged)."""
        return self._ids.get(name)

    def colour(self, name: str) -> tuple[int, int, int]:
        """The class's colour (:func:`class_colour`)."""
        return class_colour(name)

    def remap(self, values: np.ndarray, names: dict[int, str]) -> np.ndarray:
        """A mask of per-frame values (0 = nothing, ``names``: value -> class) as class ids (smallest unsigned
        type)."""
        return relabel((values, names), self.id_of)[0]

    def __len__(self) -> int:
        return len(self.names)


#: the first stand-in id: above any table's ids
STAND_IN = 1 << 30


class DeferredIds:
    """One frame's class ids, looked up on a reader thread without adding names to the table.

    A name the table has gets its id; a name it lacks gets a stand-in id (``STAND_IN``, ``STAND_IN + 1``, ...
    in the order met) until :meth:`settle`, called for frame after frame on one thread, adds the frame's new
    names to the table in that order and puts their ids in place. Ids then do not depend on which reader
    thread ran first: they are those of reading the frames one by one.
    """

    def __init__(self, table: ClassTable) -> None:
        self.table = table
        self.new: dict[str, int] = {}   # name -> its stand-in id

    def __call__(self, name: str) -> int:
        found = self.table.known(name)
        if found is None:
            found = self.new.setdefault(name, STAND_IN + len(self.new))
        return found

    def settle(self, found: tuple[np.ndarray, dict[int, str]] | None) -> tuple[np.ndarray, dict[int, str]] | None:
        """A mask read with these ids, ``(values, {id: name})``, with every stand-in replaced by the table's id
        of its name (the frame's new names added to the table, in the order they were met)."""
        if not self.new:
            return found
        real = np.array([self.table.id_of(name) for name in self.new], dtype=np.int64)
        if found is None:
            return None
        values, names = found
        out = values.astype(np.int64)
        stand_in = out >= STAND_IN
        out[stand_in] = real[out[stand_in] - STAND_IN]
        ids = [int(real[i - STAND_IN]) if i >= STAND_IN else i for i in names]
        # stand-ins made the values 32-bit; the frame's own ids decide (as read without stand-ins)
        dtype = smallest_uint(max(ids, default=0)) if values.dtype == np.uint32 else values.dtype
        return out.astype(dtype), dict(zip(ids, names.values()))
