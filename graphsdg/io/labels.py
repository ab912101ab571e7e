"""Class names and stable class ids for dataset formats.

Annotators label instances with ``{semantic type: "label"}`` (several labels of
one type joined with ``","``); formats want one class per object.
:func:`class_name` picks it, :class:`ClassTable` numbers classes.

Example:
    >>> class_name({"shape": "box", "class": "pallet"}, ["class", "shape"])
    'pallet'
    >>> table = ClassTable(first_id=1)
    >>> table.id_of("pallet"), table.id_of("box"), table.id_of("pallet")
    (1, 2, 1)
"""
from __future__ import annotations

from typing import Iterable, Mapping, Sequence


def class_name(labels: Mapping[str, str] | None, semantic_types: Sequence[str] | None = None) -> str | None:
    """The label of the first of ``semantic_types`` (in order) that ``labels`` has; any type if None."""
    if not labels:
        return None
    for semantic_type in (semantic_types or list(labels)):
        if semantic_type == "*":
            return next(iter(labels.values()))
        if semantic_type in labels:
            return labels[semantic_type]
    return None


class ClassTable:
    """Class name -> integer id: the given ``names`` first, then new names in first-seen order.

    With ``fixed=True`` only the given names have ids (:meth:`id_of` returns None for others).
    """

    def __init__(self, names: Iterable[str] | Mapping[str, int] | None = None, first_id: int = 0,
                 fixed: bool = False) -> None:
        self.first_id = first_id
        self.fixed = fixed
        if isinstance(names, Mapping):
            self._ids = {str(k): int(v) for k, v in names.items()}
        else:
            self._ids = {str(n): first_id + i for i, n in enumerate(names or [])}
        if fixed and not self._ids:
            raise ValueError("a fixed class table needs at least one class name")

    def id_of(self, name: str) -> int | None:
        if name in self._ids:
            return self._ids[name]
        if self.fixed:
            return None
        new = max(self._ids.values(), default=self.first_id - 1) + 1
        self._ids[name] = new
        return new

    def names(self) -> dict[int, str]:
        """``{id: name}`` sorted by id."""
        return {i: n for n, i in sorted(self._ids.items(), key=lambda kv: kv[1])}

    def __len__(self) -> int:
        return len(self._ids)
