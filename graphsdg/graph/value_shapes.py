"""How a per-prim argument's value is spread over a node's prims (Replicator's value shapes).

Every graph call that edits prims (``rep.modify.*``, ``rep.randomizer.*``, the re-sampled arguments of
``rep.create.*``, ``rep.physics.*``) reads its per-prim arguments through :func:`spread_value` and
:func:`spread_samples`, so every call accepts the same shapes. For ``N`` target prims, with *element*
the shape of one prim's value (``()`` for a visibility or an intensity, ``(3,)`` for a position or a
colour; ``scale`` takes ``()`` or ``(3,)``):

* one element (``True``, ``(0, 0, 1)``, a path): every prim gets it; a list holding one element too
  (``texture_scale=[(0.5, 0.5)]``, as Replicator's array inputs read it);
* ``N`` elements (``[True, False, True]``, ``[(0, 0, 1), (0, 0, 2), (0, 0, 3)]``): prim ``i`` gets the
  ``i``-th;
* a distribution that draws per prim (``uniform``, ``normal``, ``log_uniform``, ``choice``,
  ``combine``): each execution draws ``N`` elements, one per prim; but when one draw is itself
  ``N`` elements (``choice([(True, False, True), (False, True, False)])`` on three prims), the
  execution draws once and the draw is split over the prims;
* a distribution that draws once per execution (``sequence``): the draw is one element (every prim
  gets it) or ``N`` elements (``sequence([(True, False, True), ...])``: one per prim).

An element shape is checked first, so ``position=(1, 2, 3)`` on three prims is one position, not three
numbers. Anything else raises ``ValueError`` naming the call, the value, its shape and what fits.

Example:
    >>> from graphsdg.graph.value_shapes import spread_value, SCALAR
    >>> spread_value([True, False, True], 3, SCALAR, "visibility value")
    [True, False, True]
    >>> spread_value(True, 2, SCALAR, "visibility value")
    [True, True]
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from pxr import Sdf, Usd

from graphsdg.graph.samples import Samples

Shape = tuple[int, ...]
SCALAR: tuple[Shape, ...] = ((),)
VEC2: tuple[Shape, ...] = ((2,),)
VEC3: tuple[Shape, ...] = ((3,),)
SCALAR_OR_VEC3: tuple[Shape, ...] = ((), (3,))
WHOLE = None   # a value that is never split over prims (an array attribute's value is a whole list)


def value_shape(value: Any) -> Shape | None:
    """The array shape of ``value``: ``()`` for a number, string, path or prim; ``None`` when ragged."""
    if isinstance(value, (str, bytes, Sdf.Path, Usd.Prim, Sdf.AssetPath)) or value is None:
        return ()
    if isinstance(value, np.ndarray):
        return value.shape if value.dtype != object else _sequence_shape(list(value))
    if isinstance(value, (list, tuple)):
        return _sequence_shape(value)
    if hasattr(value, "__len__") and hasattr(value, "__getitem__") and not isinstance(value, dict):
        return _sequence_shape(list(value))   # Gf vectors
    return ()


def _sequence_shape(items: Sequence[Any]) -> Shape | None:
    if len(items) == 0:
        return (0,)
    inner = {value_shape(v) for v in items}
    if len(inner) != 1 or None in inner:
        return None
    return (len(items),) + inner.pop()


def _elements(value: Any) -> list[Any]:
    """``value``'s first-axis entries (rows of an array, items of a list)."""
    if isinstance(value, np.ndarray):
        return [value[i] for i in range(value.shape[0])]
    return list(value)


def _describe(value: Any) -> str:
    text = repr(value.tolist() if isinstance(value, np.ndarray) else value)
    return text if len(text) <= 120 else text[:117] + "..."


def _fits(shape: Shape | None, shapes: Sequence[Shape]) -> bool:
    return shape is not None and tuple(shape) in [tuple(s) for s in shapes]


def spread_value(value: Any, n: int, shapes: Sequence[Shape] | None, what: str) -> list[Any]:
    """``value`` as ``n`` per-prim values: one element for all, one element in a list for all, or ``n`` elements.

    ``shapes`` None (:data:`WHOLE`) means a value is never split: every prim gets all of it.
    """
    if shapes is None:
        return [value] * n
    shape = value_shape(value)
    if _fits(shape, shapes):
        return [value] * n
    if shape is not None and len(shape) >= 1 and _fits(shape[1:], shapes):
        if shape[0] == n:
            return _elements(value)
        if shape[0] == 1:
            return _elements(value) * n
    per_prim = f" for every prim, or a list of {n} of them (one per prim)" if n > 1 else ""
    raise ValueError(f"{what}: got {_describe(value)} (shape {shape if shape is not None else 'ragged'}) for "
                     f"{n} prim{'s' if n != 1 else ''}; expected one value ({_shape_names(shapes)}){per_prim}")


def spread_samples(samples: Samples, n: int, shapes: Sequence[Shape] | None, what: str) -> list[Any]:
    """This execution's draws of ``samples`` as ``n`` per-prim values (see the module docstring)."""
    if samples.per_execution:
        drawn = samples.one()
        if isinstance(drawn, Samples):   # a sequence of distributions: this execution's distribution draws
            return spread_samples(drawn, n, shapes, what)
        return spread_value(drawn, n, shapes, f"{what} (one draw of {samples.node.name!r})")
    first = samples.one()            # a prefix of any larger draw of this execution: no extra randomness
    shape = value_shape(first)
    if shapes is None or _fits(shape, shapes):
        return _first(samples.take(n), n)
    if shape is not None and len(shape) >= 1 and shape[0] == 1 and _fits(shape[1:], shapes):
        return [_elements(v)[0] for v in _first(samples.take(n), n)]   # draws of one-item lists (prim lists)
    return spread_value(first, n, shapes, f"{what} (one draw of {samples.node.name!r})")


def _first(drawn: Any, n: int) -> list[Any]:
    """``n`` per-prim draws (a fixed ``num_samples`` draw of one value serves every prim)."""
    values = _elements(drawn)
    return values[:n] if len(values) >= n else values * n


def spread(value: Any, n: int, shapes: Sequence[Shape] | None, what: str) -> list[Any]:
    """:func:`spread_samples` for a distribution's draws, :func:`spread_value` for a plain value."""
    if isinstance(value, Samples):
        return spread_samples(value, n, shapes, what)
    return spread_value(value, n, shapes, what)


def spread_rows(value: Any, n: int, width: int, what: str) -> np.ndarray:
    """A numeric per-prim value as ``(n, width)`` float rows, by the same shapes (a number fills its row).

    A distribution drawing one number or one ``width``-vector per prim is read straight from its draws (no
    per-prim Python objects: graphs with thousands of prims stay cheap); every other shape goes through
    :func:`spread`.
    """
    if isinstance(value, Samples) and not value.per_execution:
        first = np.asarray(value.one())
        if first.dtype.kind in "biuf" and first.shape in ((), (width,)):
            drawn = np.asarray(value.take(n), dtype=np.float64)
            drawn = drawn[:n] if drawn.shape[0] >= n else np.repeat(drawn[:1], n, axis=0)
            return np.repeat(drawn[:, None], width, axis=1) if drawn.ndim == 1 else drawn
    values = spread(value, n, ((), (width,)), what)
    return np.array([np.broadcast_to(np.asarray(v, dtype=np.float64), (width,)) for v in values])


def _shape_names(shapes: Sequence[Shape]) -> str:
    names = {(): "a scalar", (2,): "(a, b)", (3,): "(x, y, z)", (4,): "(a, b, c, d)"}
    return " or ".join(names.get(tuple(s), str(tuple(s))) for s in shapes)


def attribute_shapes(type_name: Sdf.ValueTypeName | None) -> tuple[Shape, ...] | None:
    """The element shape of one value of a USD attribute type (``float3`` -> ``(3,)``); None (:data:`WHOLE`)
    for array types, whose one value is a whole list."""
    if type_name is None or not type_name:
        return SCALAR
    if type_name.isArray:
        return WHOLE
    if "quat" in str(type_name.scalarType):
        return ((4,),)
    shape = value_shape(type_name.defaultValue)
    return (shape,) if shape else SCALAR


__all__ = ["Shape", "SCALAR", "VEC2", "VEC3", "SCALAR_OR_VEC3", "WHOLE", "value_shape", "spread_value", "spread_samples",
           "spread", "spread_rows", "attribute_shapes"]
