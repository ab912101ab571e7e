"""Replicator's semantic filter predicates: parse them and match label sets.

A predicate is a disjunctive normal form over semantic types and labels, as in
Replicator's ``semanticFilter`` init parameter and BasicWriter's
``semantic_filter_predicate``::

    predicate := conjunct (";" conjunct)*        any conjunct holds
    conjunct  := clause ("," clause)*            every clause holds
    clause    := type ":" labels                 some label list of ``type`` satisfies ``labels``
    labels    := term ("|" term)*                any term holds
    term      := literal ("&" literal)*          every literal holds
    literal   := ["!"] (label | "*")             label present (absent with "!"); "*" any label
    type      := name | "*"                      "*" matches every type

Names are runs of characters other than ``: ; , | & !`` with surrounding
spaces stripped (so ``"class: traffic light"`` names the label
``traffic light``). ``semanticTypes=["class", "shape"]`` is the predicate
``"class:*; shape:*"``.

Matching a prim's labels (its own plus inherited ones, ``{type: [labels]}``)
returns the labels that made the predicate true (Replicator's
``matchingLabels``): the named labels that are present, every label of the type
for ``*``, and for a term of negations only, the type's labels that are not
excluded. ``None`` means the prim does not pass.

Example:
    >>> f = SemanticFilter.parse("class: car | truck & !toy ; shape: *")
    >>> f.match({"class": ["car", "red"], "color": ["red"]})
    {'class': ['car']}
    >>> f.match({"class": ["toy", "truck"]}) is None
    True
    >>> SemanticFilter.from_types(["class", "shape"]).text
    'class:*; shape:*'
"""
from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from typing import Iterable, Mapping, Sequence

ANY = "*"
GRAMMAR = ("type:label|label&!label, type:label ; type:label   ('*' = any type or label, "
           "'|' or, '&' and, '!' not, ',' and between clauses, ';' or between conjuncts)")
_TOKEN = re.compile(r"\s*(?:(?P<op>[:;,|&!])|(?P<name>[^:;,|&!]+))")


class SemanticFilterError(ValueError):
    """A semantic filter predicate that does not parse."""


@dataclass(frozen=True)
class Literal:
    name: str           # a label or "*"
    negated: bool = False

    def holds(self, labels: Sequence[str]) -> bool:
        present = bool(labels) if self.name == ANY else self.name in labels
        return present != self.negated

    def __str__(self) -> str:
        return ("!" if self.negated else "") + self.name


@dataclass(frozen=True)
class Clause:
    sem_type: str                                  # a type or "*"
    terms: tuple[tuple[Literal, ...], ...]         # OR of ANDs

    def match(self, labels: Mapping[str, Sequence[str]]) -> dict[str, list[str]] | None:
        matched: dict[str, list[str]] = {}
        types = list(labels) if self.sem_type == ANY else [self.sem_type]
        for t in types:
            values = list(labels.get(t, ()))
            if not values:
                continue
            for term in self.terms:
                if not all(lit.holds(values) for lit in term):
                    continue
                positive = [lit for lit in term if not lit.negated]
                if any(lit.name == ANY for lit in positive) or not positive:
                    excluded = {lit.name for lit in term if lit.negated}
                    keep = [v for v in values if v not in excluded]
                else:
                    named = {lit.name for lit in positive}
                    keep = [v for v in values if v in named]
                bucket = matched.setdefault(t, [])
                bucket.extend(v for v in keep if v not in bucket)
        return matched or None

    def __str__(self) -> str:
        return f"{self.sem_type}:" + "|".join("&".join(str(lit) for lit in term) for term in self.terms)


@dataclass(frozen=True)
class SemanticFilter:
    """A parsed predicate: OR over conjuncts, each an AND over clauses."""

    conjuncts: tuple[tuple[Clause, ...], ...]

    @functools.cached_property
    def text(self) -> str:
        """The normalized predicate (also the cache key of the instance maps it selects: asked several times
        per frame, built once per filter)."""
        return "; ".join(", ".join(str(c) for c in conj) for conj in self.conjuncts)

    @property
    def named_types(self) -> list[str]:
        """Semantic types the predicate names explicitly, in order."""
        out: list[str] = []
        for conj in self.conjuncts:
            for clause in conj:
                if clause.sem_type != ANY and clause.sem_type not in out:
                    out.append(clause.sem_type)
        return out

    def match(self, labels: Mapping[str, Sequence[str]]) -> dict[str, list[str]] | None:
        """The labels of ``labels`` that satisfy the predicate, or ``None`` if it is false."""
        result: dict[str, list[str]] | None = None
        for conj in self.conjuncts:
            parts = [clause.match(labels) for clause in conj]
            if any(p is None for p in parts):
                continue
            result = result or {}
            for part in parts:
                for t, values in part.items():   # type: ignore[union-attr]
                    bucket = result.setdefault(t, [])
                    bucket.extend(v for v in values if v not in bucket)
        if result is None:
            return None
        # Keep the prim's own order of types and labels.
        return {t: [v for v in labels[t] if v in result[t]] for t in labels if t in result}

    @classmethod
    def from_params(cls, params: Mapping) -> "SemanticFilter":
        """The filter an annotator's ``semanticTypes`` / ``semanticFilter`` init params select (all labels if neither)."""
        types, predicate = params.get("semanticTypes"), params.get("semanticFilter")
        if types is not None and predicate is not None:
            raise ValueError(f"pass semanticTypes or semanticFilter, not both (got semanticTypes={types!r} and "
                             f"semanticFilter={predicate!r}); semanticTypes=['a', 'b'] means the filter 'a:*; b:*'")
        if predicate is not None:
            return cls.parse(predicate)
        if types is not None:
            return cls.from_types(types)
        return ALL_LABELS

    @classmethod
    def from_types(cls, types: Iterable[str]) -> "SemanticFilter":
        """The predicate ``"typeA:*; typeB:*"`` (Replicator's translation of ``semanticTypes``)."""
        if isinstance(types, str):
            types = [types]
        try:
            names = list(types)
        except TypeError:
            raise SemanticFilterError(f"semanticTypes must be a non-empty list of type names such as ['class'], "
                                      f"got {types!r}") from None
        if not names or any(not isinstance(t, str) or not t.strip() or _TOKEN_CHARS & set(t) for t in names):
            raise SemanticFilterError(f"semanticTypes must be a non-empty list of type names, got {types!r}")
        return cls(tuple((Clause(t.strip(), ((Literal(ANY),),)),) for t in names))

    @classmethod
    def parse(cls, predicate: str) -> "SemanticFilter":
        """Parse ``predicate``; raise :class:`SemanticFilterError` naming the problem and its position."""
        if not isinstance(predicate, str):
            raise SemanticFilterError(f"semanticFilter must be a string such as 'class:*', got {predicate!r}")
        return _parsed(predicate)


@functools.lru_cache(maxsize=256)
def _parsed(predicate: str) -> SemanticFilter:
    """Parsed filters are immutable, and annotators ask for theirs every frame: each text is parsed once."""
    return _Parser(predicate).parse()


_TOKEN_CHARS = set(":;,|&!")


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.tokens: list[tuple[str, str, int]] = []     # (kind, value, position)
        pos = 0
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None:   # only trailing whitespace is left
                break
            if m.group("op"):
                self.tokens.append(("op", m.group("op"), m.start("op")))
            elif m.group("name").strip():
                self.tokens.append(("name", m.group("name").strip(), m.start("name")))
            pos = m.end()
        self.i = 0

    def fail(self, expected: str) -> SemanticFilterError:
        if self.i < len(self.tokens):
            _, value, pos = self.tokens[self.i]
            where = f"found {value!r} at position {pos}"
        else:
            where = "found the end of the predicate"
        return SemanticFilterError(f"semanticFilter {self.text!r} does not parse: expected {expected}, {where}; "
                                   f"grammar: {GRAMMAR}")

    def peek(self, value: str) -> bool:
        return self.i < len(self.tokens) and self.tokens[self.i][:2] == ("op", value)

    def name(self, what: str) -> str:
        if self.i < len(self.tokens) and self.tokens[self.i][0] == "name":
            self.i += 1
            return self.tokens[self.i - 1][1]
        raise self.fail(what)

    def parse(self) -> SemanticFilter:
        if not self.tokens:
            raise SemanticFilterError(f"semanticFilter {self.text!r} is empty; grammar: {GRAMMAR}")
        conjuncts = [self.conjunct()]
        while self.peek(";"):
            self.i += 1
            if self.i == len(self.tokens):   # a trailing ';' is harmless
                break
            conjuncts.append(self.conjunct())
        if self.i != len(self.tokens):
            raise self.fail("';', ',' or the end")
        return SemanticFilter(tuple(conjuncts))

    def conjunct(self) -> tuple[Clause, ...]:
        clauses = [self.clause()]
        while self.peek(","):
            self.i += 1
            clauses.append(self.clause())
        return tuple(clauses)

    def clause(self) -> Clause:
        sem_type = self.name("a semantic type (or '*')")
        if not self.peek(":"):
            raise self.fail(f"':' after the semantic type {sem_type!r}")
        self.i += 1
        terms = [self.term()]
        while self.peek("|"):
            self.i += 1
            terms.append(self.term())
        return Clause(sem_type, tuple(terms))

    def term(self) -> tuple[Literal, ...]:
        literals = [self.literal()]
        while self.peek("&"):
            self.i += 1
            literals.append(self.literal())
        return tuple(literals)

    def literal(self) -> Literal:
        negated = False
        while self.peek("!"):
            self.i += 1
            negated = not negated
        name = self.name("a label (or '*')")
        if negated and name == ANY:
            raise SemanticFilterError(f"semanticFilter {self.text!r}: '!*' matches nothing; grammar: {GRAMMAR}")
        return Literal(name, negated)


ALL_LABELS = SemanticFilter.parse("*:*")   # every label of every type (annotators' default)
