"""Exception types graphsdg raises. Each message names the bad value and what was expected."""
from __future__ import annotations

import difflib
import re
from typing import Iterable


class GraphSDGError(Exception):
    """Base class of graphsdg's own errors."""


class PrimNotFoundError(GraphSDGError, ValueError):
    """A prim path that does not exist on the stage."""


class InvalidPrimError(GraphSDGError, TypeError):
    """A prim of the wrong kind (for example a render product for a non-camera)."""


class UnknownNameError(GraphSDGError, KeyError, ValueError):
    """An unknown annotator, writer, backend or node name."""

    def __str__(self) -> str:  # KeyError would repr() the message
        return str(self.args[0]) if self.args else ""


class GraphBuildError(GraphSDGError, ValueError):
    """A graph-API call that cannot be built as written."""


class RenderProductDestroyedError(GraphSDGError, RuntimeError):
    """A render product used after ``destroy()``."""


class WriterError(GraphSDGError, RuntimeError):
    """A failure inside a writer or backend worker, re-raised in the script."""


def closest(name: str, known: Iterable[str]) -> str:
    """Return a ``" (did you mean 'x'?)"`` hint, or an empty string."""
    match = difflib.get_close_matches(name, list(known), n=1)
    return f" (did you mean {match[0]!r}?)" if match else ""


def unknown_name(kind: str, name: object, known: Iterable[str]) -> UnknownNameError:
    """Build the standard error for an unknown ``kind`` name."""
    known = sorted(known)
    hint = closest(str(name), known)
    return UnknownNameError(f"unknown {kind} {name!r}{hint}; known {kind}s: {', '.join(known)}")


_TF_ERROR = re.compile(r"Error in '[^']*' at line \d+ in file \S+ : '(.*?)'\s*(?=\n\s*Error in|\Z)", re.S)


def usd_error_text(exc: BaseException) -> str:
    """The messages of a pxr (Tf) error without its C++ locations.

    Example:
        >>> usd_error_text(RuntimeError("\\n\\tError in 'Sdf::Parse' at line 48 in file parser.h : 'a.usda:2:3: "
        ...                             "Expected )'\\n"))
        'a.usda:2:3: Expected )'
    """
    text = str(exc)
    found = [m.strip() for m in _TF_ERROR.findall(text)]
    return "; ".join(found) if found else text.strip()


def describe(value: object) -> str:
    """``repr`` of a bad value for a message, arrays shown as lists (``[nan, 0.0]`` not ``array([nan, 0.])``)."""
    tolist = getattr(value, "tolist", None)
    return repr(tolist()) if callable(tolist) and not isinstance(value, (str, bytes)) else repr(value)
