"""Semantic labels through the standard ``UsdSemantics.LabelsAPI``.

A prim's labels are its own plus those of its ancestors. Replicator accepts
``{"class": "cube"}`` (functional API) and ``[("class", "cube")]`` (graph API);
both are accepted here. Several labels of one type are kept as a list.

Example:
    >>> from graphsdg.stage import semantics
    >>> semantics.normalize({"class": ["box", "cardboard"]})
    [('class', 'box'), ('class', 'cardboard')]
"""
from __future__ import annotations

from typing import Iterable, Mapping, Union

from pxr import Usd, UsdSemantics, Vt

SemanticsLike = Union[Mapping[str, object], Iterable[tuple[str, str]], tuple[str, str], None]
SEMANTIC_MODES = ("add", "replace", "clear")


def normalize(semantics: SemanticsLike) -> list[tuple[str, str]]:
    """Return ``semantics`` as an ordered list of ``(type, label)`` pairs."""
    if semantics is None:
        return []
    pairs: list[tuple[str, str]] = []
    if isinstance(semantics, str):
        raise TypeError(f"semantics must be a dict {{'class': 'cube'}} or a list of (type, label) pairs such as "
                        f"[('class', 'cube')], got the string {semantics!r}")
    if isinstance(semantics, Mapping):
        items = semantics.items()
    elif isinstance(semantics, tuple) and len(semantics) == 2 and all(isinstance(s, str) for s in semantics):
        items = [semantics]
    else:
        try:
            items = list(semantics)  # type: ignore[arg-type]
        except TypeError:
            raise TypeError(f"semantics must be a dict {{'class': 'cube'}} or a list of (type, label) "
                            f"pairs, got {semantics!r}") from None
    for item in items:
        if not (isinstance(item, (tuple, list)) and len(item) == 2):
            raise TypeError(f"semantics entries must be (type, label) pairs, got {item!r}")
        sem_type, labels = item
        if not isinstance(sem_type, str) or not sem_type:
            raise ValueError(f"semantic type must be a non-empty string, got {sem_type!r}")
        for label in ([labels] if isinstance(labels, str) else list(labels)):
            if not isinstance(label, str) or not label:
                raise ValueError(f"semantic label of type {sem_type!r} must be a non-empty string, got {label!r}")
            if (sem_type, label) not in pairs:
                pairs.append((sem_type, label))
    return pairs


def apply(prim: Usd.Prim, semantics: SemanticsLike, mode: str = "add") -> None:
    """Write labels on ``prim``. ``mode``: ``add`` (keep existing), ``replace`` (of the given types), ``clear``."""
    if mode not in SEMANTIC_MODES:
        raise ValueError(f"semantics mode must be one of {SEMANTIC_MODES}, got {mode!r}")
    pairs = normalize(semantics)
    if mode == "clear":
        for taxonomy in UsdSemantics.LabelsAPI.GetDirectTaxonomies(prim):
            prim.RemoveAPI(UsdSemantics.LabelsAPI, taxonomy)
            attr = prim.GetAttribute(f"semantics:labels:{taxonomy}")
            if attr:
                prim.RemoveProperty(attr.GetName())
        if not pairs:
            return
    by_type: dict[str, list[str]] = {}
    for sem_type, label in pairs:
        by_type.setdefault(sem_type, []).append(label)
    for sem_type, labels in by_type.items():
        api = UsdSemantics.LabelsAPI.Apply(prim, sem_type)
        attr = api.GetLabelsAttr() or api.CreateLabelsAttr()
        current = list(attr.Get() or []) if mode == "add" else []
        merged = current + [lab for lab in labels if lab not in current]
        attr.Set(Vt.TokenArray(merged))


def direct_labels(prim: Usd.Prim) -> dict[str, list[str]]:
    """Labels authored on ``prim`` itself (LabelsAPI, and Isaac's legacy SemanticsAPI)."""
    out: dict[str, list[str]] = {}
    for taxonomy in UsdSemantics.LabelsAPI.GetDirectTaxonomies(prim):
        attr = UsdSemantics.LabelsAPI(prim, taxonomy).GetLabelsAttr()
        values = attr.Get() if attr else None
        if values:
            out.setdefault(taxonomy, []).extend(str(v) for v in values)
    # Isaac Sim's older semantics schema: semantic:<inst>:params:semanticType / semanticData
    for attr in prim.GetAttributes():
        name = attr.GetName()
        if name.startswith("semantic:") and name.endswith(":params:semanticType"):
            data = prim.GetAttribute(name.replace("semanticType", "semanticData"))
            sem_type, label = attr.Get(), data.Get() if data else None
            if sem_type and label and label not in out.get(sem_type, []):
                out.setdefault(str(sem_type), []).append(str(label))
    return out


def labels(prim: Usd.Prim) -> dict[str, list[str]]:
    """Labels of ``prim`` including those inherited from its ancestors (outermost first)."""
    chain = []
    p = prim
    while p and p.IsValid() and not p.IsPseudoRoot():
        chain.append(p)
        p = p.GetParent()
    out: dict[str, list[str]] = {}
    for p in reversed(chain):
        for sem_type, labs in direct_labels(p).items():
            bucket = out.setdefault(sem_type, [])
            bucket.extend(lab for lab in labs if lab not in bucket)
    return out


def labelled_ancestor(prim: Usd.Prim, types: Iterable[str] | None = None) -> Usd.Prim | None:
    """The nearest ancestor-or-self that carries a label (of one of ``types``, if given)."""
    wanted = set(types) if types is not None else None
    p = prim
    while p and p.IsValid() and not p.IsPseudoRoot():
        direct = direct_labels(p)
        if direct and (wanted is None or wanted & set(direct)):
            return p
        p = p.GetParent()
    return None
