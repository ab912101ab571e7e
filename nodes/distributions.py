"""Distribution nodes: each execution outputs count-aware :class:`Samples` of its law.

Scalars and tuples work element-wise (``uniform((0, 0, 0), (1, 1, 1))`` draws RGB
triples). A consumer that targets N prims takes N samples, one per prim.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from graphsdg.graph.calls import Call
from graphsdg.graph.node import ExecContext, Node, Port, ReplicatorItem, iter_refs
from graphsdg.graph.registry import register_node
from graphsdg.graph.samples import Samples
from graphsdg.rng import stream


def _has_refs(value: Any) -> bool:
    return any(True for _ in iter_refs(value))


def _numeric(value: Any, what: str) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a number or a tuple of numbers, got {value!r}") from None
    if arr.ndim > 1 or not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be a finite number or a flat tuple of numbers, got {value!r}")
    return arr


def as_list(value: Any) -> Any:
    """An iterable of values as a list (so tuples and generators are kept); a string, item or scalar as is."""
    if isinstance(value, (str, ReplicatorItem)) or value is None or not hasattr(value, "__iter__"):
        return value
    return list(value)


def _listed(values: dict[str, Any], *ports: str) -> dict[str, Any]:
    """``values`` with the given ports' iterables made lists."""
    return {k: as_list(v) if k in ports else v for k, v in values.items()}


def _num_samples(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"num_samples must be a positive integer, got {value!r}")
    return int(value)


class Distribution(Node):
    """Base of distribution nodes: ``draw(gen, n, ctx)`` makes ``n`` samples."""

    family = "distribution"
    call = Call()
    outputs = {"samples": Port("samples")}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        _num_samples(self.value_of("num_samples") if "num_samples" in self.inputs else 1)
        self.validate()

    def validate(self) -> None:
        """Raise ValueError naming a bad plain input."""

    def draw(self, gen: np.random.Generator, n: int, ctx: ExecContext) -> Any:
        raise NotImplementedError

    def compute(self, ctx: ExecContext) -> dict[str, Any]:
        num = int(self.value_of("num_samples")) if "num_samples" in self.inputs else 1
        return {"samples": Samples(self, lambda: ctx.rng, lambda gen, n: self.draw(gen, n, ctx), num)}


def _pair(node: Node, a: str, b: str) -> tuple[np.ndarray, np.ndarray] | None:
    va, vb = node.value_of(a), node.value_of(b)
    if _has_refs(va) or _has_refs(vb):
        return None
    lo, hi = _numeric(va, f"{node.type_name.split('.')[-1]} {a}"), _numeric(vb, f"{node.type_name.split('.')[-1]} {b}")
    if lo.shape != hi.shape:
        raise ValueError(f"{node.type_name.split('.')[-1]}: {a} {va!r} and {b} {vb!r} have different shapes "
                         f"{lo.shape} and {hi.shape}; give both as numbers or as tuples of one length")
    return lo, hi


def _resolved_pair(ctx: ExecContext, a: str, b: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    def val(port: str) -> np.ndarray:
        v = ctx.value(port)
        return np.asarray(v.take(n) if isinstance(v, Samples) else v, dtype=np.float64)
    return val(a), val(b)


@register_node
class Uniform(Distribution):
    """Uniform in [lower, upper), element-wise for tuples."""

    type_name = "distribution.uniform"
    inputs = {"lower": Port("number|tuple", required=True), "upper": Port("number|tuple", required=True),
              "num_samples": Port(int, 1), "seed": Port(int)}

    def validate(self) -> None:
        pair = _pair(self, "lower", "upper")
        if pair is not None and np.any(pair[0] > pair[1]):
            raise ValueError(f"uniform: lower {self.value_of('lower')!r} is greater than upper "
                             f"{self.value_of('upper')!r}; expected lower <= upper element-wise")

    def draw(self, gen, n, ctx):
        lo, hi = _resolved_pair(ctx, "lower", "upper", n)
        return gen.uniform(lo, hi, size=(n,) + np.broadcast_shapes(lo.shape, hi.shape)) if lo.ndim <= 1 \
            else gen.uniform(lo, hi)


@register_node
class Normal(Distribution):
    """Gaussian with ``mean`` and standard deviation ``std`` (>= 0), element-wise."""

    type_name = "distribution.normal"
    inputs = {"mean": Port("number|tuple", required=True), "std": Port("number|tuple", required=True),
              "num_samples": Port(int, 1), "seed": Port(int)}

    def validate(self) -> None:
        mean, std = self.value_of("mean"), self.value_of("std")
        if _has_refs(mean) or _has_refs(std):
            return
        m, s = _numeric(mean, "normal mean"), _numeric(std, "normal std")
        try:
            np.broadcast_shapes(m.shape, s.shape)
        except ValueError:
            raise ValueError(f"normal: mean {mean!r} and std {std!r} have incompatible shapes") from None
        if np.any(s < 0):
            raise ValueError(f"normal: std {std!r} is negative; expected std >= 0")

    def draw(self, gen, n, ctx):
        m, s = _resolved_pair(ctx, "mean", "std", n)
        return gen.normal(m, s, size=(n,) + np.broadcast_shapes(m.shape, s.shape))


@register_node
class LogUniform(Distribution):
    """``exp(uniform(log(lower), log(upper)))`` (lower > 0)."""

    type_name = "distribution.log_uniform"
    inputs = {"lower": Port("number|tuple", required=True), "upper": Port("number|tuple", required=True),
              "num_samples": Port(int, 1), "seed": Port(int)}

    def validate(self) -> None:
        pair = _pair(self, "lower", "upper")
        if pair is None:
            return
        if np.any(pair[0] <= 0):
            raise ValueError(f"log_uniform: lower {self.value_of('lower')!r} must be > 0")
        if np.any(pair[0] > pair[1]):
            raise ValueError(f"log_uniform: lower {self.value_of('lower')!r} is greater than upper "
                             f"{self.value_of('upper')!r}")

    def draw(self, gen, n, ctx):
        lo, hi = _resolved_pair(ctx, "lower", "upper", n)
        return np.exp(gen.uniform(np.log(lo), np.log(hi), size=(n,) + lo.shape))


def _stack(values: list) -> Any:
    """An array when every value is numeric (or every one boolean: kept boolean) and of one shape, else the list."""
    try:
        kept = np.asarray(values)
    except (TypeError, ValueError):
        return values
    if kept.dtype == bool:
        return kept
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        return values
    return arr if arr.ndim >= 1 and arr.dtype != object else values


def _expand(values: list) -> list:
    """Choices that are distributions contribute one draw each."""
    return [v.one() if isinstance(v, Samples) else v for v in values]


@register_node
class Choice(Distribution):
    """One of ``choices`` per sample, with probabilities ``weights`` (normalised) if given."""

    type_name = "distribution.choice"
    inputs = {"choices": Port(list, required=True), "weights": Port(list), "num_samples": Port(int, 1),
              "seed": Port(int, -1), "with_replacements": Port(bool, True)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        if values.get("weights") is not None:
            values["weights"] = list(values["weights"])
        super().__init__(name=name, **_listed(values, "choices"))

    def validate(self) -> None:
        choices, weights = self.value_of("choices"), self.value_of("weights")
        if isinstance(choices, (str, ReplicatorItem)) or not hasattr(choices, "__len__"):
            raise ValueError(f"choice: choices must be a list, got {choices!r}")
        if len(choices) == 0:
            raise ValueError("choice: choices is empty ([]); give at least one value to choose from")
        if weights is not None:
            w = np.asarray(weights, dtype=np.float64)
            if w.shape != (len(choices),):
                raise ValueError(f"choice: weights {list(weights)!r} has {w.size} entries but there are "
                                 f"{len(choices)} choices")
            if np.any(w < 0) or not np.all(np.isfinite(w)) or w.sum() <= 0:
                raise ValueError(f"choice: weights {list(weights)!r} must be non-negative and sum to a "
                                 f"positive number")

    def probabilities(self) -> np.ndarray | None:
        weights = self.value_of("weights")
        if weights is None:
            return None
        w = np.asarray(weights, dtype=np.float64)
        return w / w.sum()

    def draw(self, gen, n, ctx):
        choices = list(ctx.value("choices"))
        replace = bool(self.value_of("with_replacements"))
        if not replace and n > len(choices):
            raise ValueError(f"choice {self.name!r}: {n} samples without replacement from only "
                             f"{len(choices)} choices")
        idx = gen.choice(len(choices), size=n, replace=replace, p=self.probabilities())
        return _stack(_expand([choices[int(i)] for i in idx]))


@register_node
class Sequence(Distribution):
    """The next of ``items`` on each execution, wrapping around (a fixed shuffle if ``ordered=False``).

    One draw per execution, whatever the number of target prims (Replicator's sequence has no
    ``num_samples``): every prim gets the item, or, when the item holds one value per prim
    (``sequence([(True, False, True), ...])`` on three prims), prim ``i`` its ``i``-th value.
    ``stride`` makes each draw ``stride`` consecutive items (one per prim when it equals their count).
    """

    type_name = "distribution.sequence"
    call = Call(name_before="stride")
    inputs = {"items": Port(list, required=True), "ordered": Port(bool, True), "seed": Port(int, -1),
              "stride": Port(int)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **_listed(values, "items"))

    def validate(self) -> None:
        items = self.value_of("items")
        if isinstance(items, (str, ReplicatorItem)) or not hasattr(items, "__len__"):
            raise ValueError(f"sequence: items must be a list, got {items!r}")
        if len(items) == 0:
            raise ValueError("sequence: items is empty ([]); give at least one item to step through")
        stride = self.value_of("stride")
        if stride is not None and (isinstance(stride, bool) or not isinstance(stride, int) or stride < 1):
            raise ValueError(f"sequence: stride must be a positive integer, got {stride!r}")

    def compute(self, ctx: ExecContext) -> dict[str, Any]:
        return {"samples": Samples(self, lambda: ctx.rng, lambda gen, n: self.draw(gen, n, ctx), 1,
                                   per_execution=True)}

    def draw(self, gen, n, ctx):
        items = list(ctx.value("items"))
        stride = self.value_of("stride")
        order = np.arange(len(items))
        if not self.value_of("ordered"):
            seed = self.value_of("seed")
            perm_gen = (np.random.default_rng(int(seed)) if seed is not None and seed != -1
                        else stream("graph-node", self.stable_id, "permutation"))
            order = perm_gen.permutation(len(items))
        if stride is None:
            pick = items[int(order[ctx.exec_index % len(items)])]
            return [pick if isinstance(pick, Samples) else _stack([pick])[0] if _numeric_item(pick) else pick]
        start = ctx.exec_index * int(stride)
        chunk = [items[int(order[(start + i) % len(items)])] for i in range(int(stride))]
        return [_stack(_expand(chunk))]


def _numeric_item(value: Any) -> bool:
    """Whether ``value`` is a number or a flat/nested tuple of numbers (drawn as an array)."""
    if isinstance(value, (bool, np.bool_, str, ReplicatorItem)) or value is None:
        return False
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        return False
    return arr.dtype.kind in "iuf" and arr.dtype != object


@register_node
class Combine(Distribution):
    """Samples that concatenate one sample of each part (distributions or plain values)."""

    # combine([uniform(0, 1), 2.0, normal(0, 1)]) draws vectors (u, 2.0, g)
    type_name = "distribution.combine"
    inputs = {"distributions": Port(list, required=True)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **_listed(values, "distributions"))

    def validate(self) -> None:
        parts = self.value_of("distributions")
        if isinstance(parts, (str, ReplicatorItem)) or not hasattr(parts, "__len__") or len(parts) == 0:
            raise ValueError(f"combine: distributions must be a non-empty list, got {parts!r}")

    def draw(self, gen, n, ctx):
        cols = []
        for part in ctx.value("distributions"):
            v = part.take(n) if isinstance(part, Samples) else np.broadcast_to(
                np.asarray(part, dtype=np.float64), (n,) + np.shape(part))
            v = np.asarray(v, dtype=np.float64)
            cols.append(v.reshape(n, -1))
        return np.concatenate(cols, axis=1)
