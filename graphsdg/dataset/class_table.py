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
from graphsdg.dataset.view_frame import relabel
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

    def colour(self, name: str) -> tuple[int, int, int]:
        """The class's colour (:func:`class_colour`)."""
        return class_colour(name)

    def remap(self, values: np.ndarray, names: dict[int, str]) -> np.ndarray:
        """A mask of per-frame values (0 = nothing, ``names``: value -> class) as class ids (smallest unsigned
        type)."""
        return relabel((values, names), self.id_of)[0]

    def __len__(self) -> int:
        return len(self.names)
