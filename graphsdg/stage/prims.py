"""Finding prims and naming new ones."""
from __future__ import annotations

import re
from typing import Iterable, Sequence, Union

from pxr import Sdf, Usd

from graphsdg.errors import InvalidPrimError, PrimNotFoundError
from graphsdg.stage.context import get_stage

PrimLike = Union[Usd.Prim, str, Sdf.Path]
_NAME_RE = re.compile(r"[^A-Za-z0-9_]")


def resolve_prim(value: PrimLike, stage: Usd.Stage | None = None) -> Usd.Prim:
    """Return the valid ``Usd.Prim`` that ``value`` (prim, path string or ``Sdf.Path``) names."""
    stage = stage or get_stage()
    if isinstance(value, Usd.Prim):
        if not value.IsValid():
            raise PrimNotFoundError(f"prim {value} is not valid (was it removed from the stage?)")
        return value
    if hasattr(value, "GetPrim") and callable(value.GetPrim):  # schema objects (UsdGeom.Xform, ...)
        return resolve_prim(value.GetPrim(), stage)
    if isinstance(value, (str, Sdf.Path)):
        path = str(value)
        if not Sdf.Path.IsValidPathString(path) or not path.startswith("/"):
            raise PrimNotFoundError(f"{path!r} is not an absolute prim path (expected e.g. '/World/Cube')")
        prim = stage.GetPrimAtPath(path)
        if not prim.IsValid():
            raise PrimNotFoundError(f"no prim at path {path!r} on the current stage")
        return prim
    raise InvalidPrimError(f"expected a Usd.Prim or a prim path string, got {type(value).__name__}: {value!r}")


def resolve_prims(value: PrimLike | Iterable[PrimLike], stage: Usd.Stage | None = None) -> list[Usd.Prim]:
    """Like :func:`resolve_prim` for one prim or a list of them."""
    if isinstance(value, (Usd.Prim, str, Sdf.Path)) or hasattr(value, "GetPrim"):
        return [resolve_prim(value, stage)]
    if value is None:
        raise InvalidPrimError("expected a prim or a list of prims, got None")
    if isinstance(value, (list, tuple)) and all(type(v) is Usd.Prim for v in value) and \
            all(map(Usd.Prim.IsValid, value)):
        return list(value)   # the common case of a batch of live prims, without a Python call per prim
    return [resolve_prim(v, stage) for v in value]


def sanitize_name(name: str) -> str:
    """Make ``name`` a valid USD prim name (letters, digits, underscores; no leading digit)."""
    if not isinstance(name, str) or not name:
        raise ValueError(f"prim name must be a non-empty string, got {name!r}")
    clean = _NAME_RE.sub("_", name)
    return "_" + clean if clean[0].isdigit() else clean


def parent_path(parent: PrimLike | None, stage: Usd.Stage | None = None) -> Sdf.Path:
    """The path of ``parent`` (must exist), or the root for ``None``."""
    if parent is None:
        return Sdf.Path.absoluteRootPath
    prim = resolve_prim(parent, stage) if not isinstance(parent, (str, Sdf.Path)) else None
    if prim is None:
        path = str(parent)
        stage = stage or get_stage()
        if not stage.GetPrimAtPath(path).IsValid():
            raise PrimNotFoundError(f"parent {path!r} does not exist on the stage; create it first "
                                    f"(e.g. rep.functional.create.xform(name=...))")
        return Sdf.Path(path)
    return prim.GetPath()


def unique_child_path(parent: Sdf.Path, name: str, stage: Usd.Stage | None = None) -> Sdf.Path:
    """``parent/name``, or ``parent/name_01``, ``_02``... if that path is taken."""
    stage = stage or get_stage()
    name = sanitize_name(name)
    path = parent.AppendChild(name)
    i = 0
    while stage.GetPrimAtPath(path).IsValid():
        i += 1
        path = parent.AppendChild(f"{name}_{i:02d}")
    return path


def as_list(value: object) -> list:
    """Wrap a scalar prim-ish value in a list; leave sequences as lists."""
    if isinstance(value, (Usd.Prim, str, Sdf.Path)):
        return [value]
    if isinstance(value, Sequence):
        return list(value)
    return [value]
