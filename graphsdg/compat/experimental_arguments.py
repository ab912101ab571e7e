"""Isaac compat: the batched arguments of ``isaacsim.core.experimental`` wrappers.

Every wrapper (prims, objects, materials) reads its inputs the way Isaac does:
values broadcast to ``(N, width)`` by NumPy's rules, ``indices`` select a subset,
paths come as one path or a list. A setting graphsdg stores but cannot use warns
once per process.

Example:
    >>> from graphsdg.compat.experimental_arguments import resolve_indices, rows
    >>> rows([1.0, 2.0, 3.0], 2, 3, "positions").tolist()
    [[1.0, 2.0, 3.0], [1.0, 2.0, 3.0]]
    >>> resolve_indices([-1], 3)
    [2]
"""
from __future__ import annotations

import warnings
from typing import Any, Sequence

import numpy as np
from PIL import ImageColor
from pxr import Sdf, Usd

_warned: set[str] = set()


def warn_once(what: str, why: str) -> None:
    """Warn once per process that ``what`` has no effect in graphsdg (``why``)."""
    if what not in _warned:
        _warned.add(what)
        warnings.warn(f"{what} has no effect in graphsdg: {why}", UserWarning, stacklevel=3)


def rows(values: Any, count: int, width: int, name: str) -> np.ndarray:
    """``values`` broadcast to ``(count, width)`` floats (NumPy rules, as Isaac); a ``ValueError`` names bad input."""
    raw = values.numpy() if hasattr(values, "numpy") else values
    try:
        arr = np.asarray(raw, dtype=np.float64)
        if arr.ndim <= 1 and width == 1:
            arr = arr.reshape(-1, 1)
        out = np.broadcast_to(arr, (count, width)).copy()
    except (TypeError, ValueError):
        raise ValueError(f"{name} {values!r} cannot be broadcast to shape ({count}, {width}); expected "
                         f"{'a number or ' if width == 1 else ''}{width} value(s) per prim or one row for all")
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{name} {values!r} holds a value that is not finite")
    return out


def flags(values: Any, count: int, name: str) -> list[bool]:
    """Booleans broadcast to ``count`` values."""
    raw = values.numpy() if hasattr(values, "numpy") else values
    arr = np.asarray(raw).reshape(-1)
    if arr.size not in (1, count) or arr.dtype.kind not in "bui":
        raise ValueError(f"{name} {values!r} must be one bool or {count} bools")
    return [bool(v) for v in np.broadcast_to(arr, (count,))]


def tokens(values: Any, count: int, name: str, allowed: Sequence[str]) -> list[str]:
    """Strings broadcast to ``count`` values, each one of ``allowed``."""
    items = [values] if isinstance(values, str) else list(values)
    if len(items) not in (1, count):
        raise ValueError(f"{name} {values!r} must be one value or {count} values")
    items = items * count if len(items) == 1 else items
    for item in items:
        if item not in allowed:
            raise ValueError(f"{name} {item!r} is not one of {list(allowed)}")
    return [str(v) for v in items]


def resolve_indices(indices: Any, count: int) -> list[int]:
    """Prim indices to process (all when ``None``); out-of-range indices raise ``IndexError``."""
    if indices is None:
        return list(range(count))
    raw = indices.numpy() if hasattr(indices, "numpy") else indices
    out = [int(i) for i in np.atleast_1d(np.asarray(raw)).reshape(-1)]
    bad = [i for i in out if not -count <= i < count]
    if bad:
        raise IndexError(f"indices {bad} out of range for {count} prims")
    return [i % count for i in out]


def as_paths(paths: Any) -> list[str]:
    """One path, a list of paths (or prims) as strings; an empty list raises."""
    if isinstance(paths, (str, Sdf.Path, Usd.Prim)):
        paths = [paths]
    out = [str(p.GetPath()) if isinstance(p, Usd.Prim) else str(p) for p in paths]
    if not out:
        raise ValueError("no prim paths given; expected a path or a non-empty list of paths")
    return out


# matplotlib's one-letter base colours (Isaac parses colour strings with matplotlib); names and hex codes go
# through Pillow's CSS / X11 table
_BASE_COLORS = {"b": (0.0, 0.0, 1.0), "g": (0.0, 0.5, 0.0), "r": (1.0, 0.0, 0.0), "c": (0.0, 0.75, 0.75),
                "m": (0.75, 0.0, 0.75), "y": (0.75, 0.75, 0.0), "k": (0.0, 0.0, 0.0), "w": (1.0, 1.0, 1.0)}


def parse_color(color: str) -> tuple[float, float, float]:
    """An RGB triple in [0, 1] from a colour name (CSS4 / X11, any case), a hex code or a base-colour letter."""
    text = color.strip().lower()
    if text in _BASE_COLORS:
        return _BASE_COLORS[text]
    try:
        rgb = ImageColor.getrgb(text)
    except ValueError:
        raise ValueError(f"invalid colour string {color!r}: expected a CSS4 / X11 colour name ('white', "
                         f"'darkorange'), a hex code ('#ff8800') or a base colour letter ('r', 'g', 'b', ...)") from None
    return tuple(c / 255.0 for c in rgb[:3])  # type: ignore[return-value]


def color_rows(colors: Any, count: int, name: str = "colors") -> np.ndarray:
    """Colours (rgb rows in [0, 1] or colour strings) broadcast to ``(count, 3)``."""
    if isinstance(colors, str):
        colors = parse_color(colors)
    elif isinstance(colors, (list, tuple)):
        colors = [parse_color(c) if isinstance(c, str) else c for c in colors]
    data = rows(colors, count, 3, name)
    if data.min() < 0 or data.max() > 1:
        raise ValueError(f"{name} {colors!r} must be rgb values in [0, 1]")
    return data
