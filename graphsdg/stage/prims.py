"""Finding prims and naming new ones."""
from __future__ import annotations

import re
from typing import Iterable, Sequence, Union

from pxr import Sdf, Tf, Usd

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
    if isinstance(value, (list, tuple)) and checked_batch.holds(value):
        return list(value)
    if isinstance(value, (list, tuple)) and all(type(v) is Usd.Prim for v in value) and \
            all(map(Usd.Prim.IsValid, value)):
        checked_batch.remember(value)
        return list(value)   # the common case of a batch of live prims, without a Python call per prim
    return [resolve_prim(v, stage) for v in value]


class StructureClock:
    """Counts structural changes: resyncs on any stage (``ObjectsChanged`` notices with resynced paths) and
    stage replacements. What is known about a prim object holds while the count stands still: a prim is
    removed, deactivated or retyped only by a resync of it or an ancestor."""

    def __init__(self) -> None:
        self.count = 0
        self._listener = None

    def start(self) -> None:
        """Begin counting resyncs (once; the count is only read by caches that started it)."""
        if self._listener is None:
            self._listener = Tf.Notice.RegisterGlobally(Usd.Notice.ObjectsChanged, self._changed)

    def _changed(self, notice, sender) -> None:
        if notice.GetResyncedPaths():
            self.count += 1

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """A replaced stage changes the structure: what was known about prims no longer holds."""
        self.count += 1


#: The process's structure clock (held by the session, :mod:`graphsdg.engine.session`).
structure_clock = StructureClock()


def structure_version() -> int:
    """A number that changes whenever any stage's structure changes (a prim added, removed, deactivated,
    retyped; a stage replaced): what a cache of prim objects is valid for."""
    structure_clock.start()
    return structure_clock.count


class CheckedBatch:
    """The last large batch of prims found valid, kept until any stage's structure changes.

    Randomizers pass the same list of the same prims every frame, and ``IsValid``
    costs ~0.5 us a prim (2.4 ms a call for 5,000 prims, twice a frame in the
    benchmark). A prim stops being valid only when it or an ancestor is removed or
    deactivated, which resyncs it, or when its stage is released (a stage replaced, or every prim of it
    expired: the first one is checked each time). So a batch of the same prim objects as the one checked,
    with no resync since (:class:`StructureClock`), is valid without asking each prim again.
    """

    MIN_SIZE = 32   # smaller batches are checked each time (a few microseconds)

    def __init__(self) -> None:
        self._prims: list[Usd.Prim] = []
        self._at = -1

    def remember(self, prims: Sequence[Usd.Prim]) -> None:
        if len(prims) < self.MIN_SIZE:
            return
        structure_clock.start()
        self._prims, self._at = list(prims), structure_clock.count

    def holds(self, prims: Sequence[Usd.Prim]) -> bool:
        """Whether ``prims`` are the remembered prims (each the same object) and nothing was resynced since."""
        if self._at != structure_clock.count or len(prims) != len(self._prims) or not self._prims:
            return False
        # list equality compares identical elements without calling Usd.Prim.__eq__ (~5 us for 5,000); the
        # first prim expires with its stage
        same = self._prims == (prims if isinstance(prims, list) else list(prims))
        return same and self._prims[0].IsValid()


class PrimFacts:
    """A prim object's path and schema types, asked of USD once until any stage's structure changes.

    A frame asks them of the same few prim objects (the cameras a script poses, say), and inside a capture
    loop each USD call pays for cold caches (``IsA`` ~30 us, ``GetPath`` ~20 us measured on the CPU
    machine). Facts are kept by prim object (held, so its ``id`` is not reused) while the structure clock
    stands still; at most :attr:`MAX_PRIMS` objects.

    Example:
        >>> from pxr import UsdGeom
        >>> stage = Usd.Stage.CreateInMemory()
        >>> cam = UsdGeom.Camera.Define(stage, "/Cam").GetPrim()
        >>> facts = PrimFacts()
        >>> facts.path(cam), facts.is_a(cam, UsdGeom.Camera)
        ('/Cam', True)
    """

    MAX_PRIMS = 64   # a frame asks of a few cameras; when full, the table starts over

    def __init__(self) -> None:
        self._facts: dict[int, tuple[Usd.Prim, dict]] = {}
        self._at = -1

    def _of(self, prim: Usd.Prim) -> dict:
        if self._at != structure_clock.count or self._at < 0:
            self._facts.clear()
            self._at = structure_version()
        entry = self._facts.get(id(prim))
        if entry is None or entry[0] is not prim:
            if len(self._facts) >= self.MAX_PRIMS:
                self._facts.clear()
            entry = self._facts[id(prim)] = (prim, {})
        return entry[1]

    def path(self, prim: Usd.Prim) -> str:
        """``str(prim.GetPath())``."""
        facts = self._of(prim)
        path = facts.get("path")
        if path is None:
            path = facts["path"] = str(prim.GetPath())
        return path

    def is_a(self, prim: Usd.Prim, schema: type) -> bool:
        """``prim.IsA(schema)`` (False for an expired prim)."""
        facts = self._of(prim)
        known = facts.get(schema)
        if known is None:
            known = facts[schema] = bool(prim.IsValid() and prim.IsA(schema))
        return known


#: The last large batch of prims found valid, and what is known of a frame's prims (held by the session).
checked_batch = CheckedBatch()
prim_facts = PrimFacts()


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
