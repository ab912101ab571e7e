"""Annotator types, the registry, and annotator instances users attach.

An :class:`AnnotatorSpec` names an annotator, the render passes it needs, its
init parameters with defaults, and ``compute(frame, params)`` returning
``{"data": ..., "info": {...}}``. Concrete specs live in ``graphsdg.nodes``.

Example:
    >>> import graphsdg as rep
    >>> rgb = rep.annotators.get("rgb")
    >>> rgb.name
    'rgb'
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable

import numpy as np

from graphsdg.errors import unknown_name
from graphsdg.render.render_product import RenderProduct, registry as rp_registry

ComputeFn = Callable[["FrameView", dict], dict]  # noqa: F821 (FrameView in annotate.frame)


@dataclass(frozen=True)
class AnnotatorSpec:
    """How to compute one annotator."""

    name: str
    passes: frozenset[str]
    compute: ComputeFn
    defaults: dict[str, Any] = field(default_factory=dict)
    doc: str = ""
    validate: Callable[[dict], None] | None = None


class AnnotatorRegistry:
    """Registry of annotator specs (``rep.AnnotatorRegistry``)."""

    _specs: dict[str, AnnotatorSpec] = {}
    _aliases: dict[str, str] = {}

    @classmethod
    def register_spec(cls, spec: AnnotatorSpec, aliases: Iterable[str] = ()) -> None:
        cls._specs[spec.name] = spec
        for alias in aliases:
            cls._aliases[alias] = spec.name

    @classmethod
    def resolve(cls, name: str) -> AnnotatorSpec:
        if not isinstance(name, str):
            raise TypeError(f"annotator name must be a string, got {type(name).__name__}")
        key = cls._aliases.get(name, name)
        if key not in cls._specs and key.endswith("_fast"):
            key = cls._aliases.get(key[:-5], key[:-5])
        spec = cls._specs.get(key)
        if spec is None:
            raise unknown_name("annotator", name, list(cls._specs) + list(cls._aliases))
        return spec

    @classmethod
    def get_annotator(cls, name: str, init_params: dict | None = None, render_product_idxs=None,
                      device: str | None = None, do_array_copy: bool = True) -> "Annotator":
        """A new :class:`Annotator` of type ``name`` with ``init_params``."""
        spec = cls.resolve(name)
        return Annotator(name, spec, init_params or {}, device=device, do_array_copy=do_array_copy)

    @classmethod
    def get_registered_annotators(cls) -> list[str]:
        return sorted(set(cls._specs) | set(cls._aliases))

    @classmethod
    def register_annotator_from_function(cls, name: str, fn: Callable[..., Any], inputs: Iterable[str],
                                         init_params: dict | None = None, doc: str = "") -> None:
        """Register ``fn(**{input: data}, **params)`` over other annotators' outputs as annotator ``name``."""
        deps = [cls.resolve(i) for i in inputs]
        inputs = list(inputs)

        def compute(frame, params):
            args = {i: get_output(frame, d, _params(d, {})) for i, d in zip(inputs, deps)}
            result = fn(**{k: (v["data"] if "data" in v else v) for k, v in args.items()}, **params)
            return result if isinstance(result, dict) and "data" in result else {"data": result}

        passes = frozenset().union(*[d.passes for d in deps]) if deps else frozenset()
        cls.register_spec(AnnotatorSpec(name=name, passes=passes, compute=compute,
                                        defaults=dict(init_params or {}), doc=doc))

    @classmethod
    def unregister(cls, name: str) -> None:
        cls._specs.pop(name, None)
        for alias in [a for a, n in cls._aliases.items() if n == name]:
            del cls._aliases[alias]


def _params(spec: AnnotatorSpec, given: dict) -> dict:
    unknown = set(given) - set(spec.defaults)
    if unknown:
        raise ValueError(f"annotator {spec.name!r} has no init param(s) {sorted(unknown)}; "
                         f"known: {sorted(spec.defaults) or 'none'}")
    params = {**copy.deepcopy(spec.defaults), **given}
    if spec.validate is not None:
        spec.validate(params)
    return params


def output_key(spec: AnnotatorSpec, params: dict) -> tuple:
    return (spec.name, repr(sorted(params.items())))


def get_output(frame, spec: AnnotatorSpec, params: dict) -> dict:
    """``spec``'s output on ``frame``, computed once per frame and parameter set."""
    return frame.cached(("annotator",) + output_key(spec, params), lambda: spec.compute(frame, params))


class Annotator:
    """An annotator instance: attach it to render products, step, then ``get_data()``."""

    def __init__(self, name: str, spec: AnnotatorSpec, init_params: dict, device: str | None = None,
                 do_array_copy: bool = True) -> None:
        if device not in (None, "cpu"):
            raise ValueError(f"annotator device {device!r} is not available; graphsdg annotators return "
                             f"numpy arrays (device=None or 'cpu')")
        self.name = name
        self.spec = spec
        self.init_params = _params(spec, dict(init_params))
        self.do_array_copy = do_array_copy
        self._render_products: list[RenderProduct] = []
        self._latest: dict[str, dict] = {}

    @property
    def render_products(self) -> list[RenderProduct]:
        return list(self._render_products)

    def attach(self, render_products: "RenderProduct | str | Iterable[RenderProduct | str]") -> "Annotator":
        """Attach to one render product or a list of them (objects or paths)."""
        from graphsdg.runtime import runtime
        items = render_products if isinstance(render_products, (list, tuple)) else [render_products]
        if not items:
            raise ValueError(f"annotator {self.name!r}: attach() needs at least one render product")
        for item in items:
            rp = rp_registry.find(item)
            if rp not in self._render_products:
                self._render_products.append(rp)
        runtime().annotators.add(self)
        return self

    def detach(self, render_products=None) -> None:
        """Detach from ``render_products`` (default: all)."""
        from graphsdg.runtime import runtime
        if render_products is None:
            self._render_products.clear()
        else:
            items = render_products if isinstance(render_products, (list, tuple)) else [render_products]
            for item in items:
                self._render_products = [rp for rp in self._render_products
                                         if item not in (rp, rp.path, rp.name)]
        self._latest = {k: v for k, v in self._latest.items()
                        if any(rp.path == k for rp in self._render_products)}
        if not self._render_products:
            runtime().annotators.discard(self)

    def compute_for(self, frame) -> dict:
        out = get_output(frame, self.spec, self.init_params)
        self._latest[frame.render_product.path] = out
        return out

    def get_data(self, device: str | None = None, do_array_copy: bool = False,
                 use_legacy_structure: bool = True) -> Any:
        """The latest step's output, in Replicator's legacy or flat structure.

        Several render products: a dict keyed by render-product name.
        """
        if not self._render_products:
            raise RuntimeError(f"annotator {self.name!r} is not attached to a render product; call "
                               f"attach(render_product) and step first")
        results = {}
        for rp in self._render_products:
            out = self._latest.get(rp.path)
            results[rp.name] = None if out is None else shape_output(out, use_legacy_structure,
                                                                     do_array_copy or self.do_array_copy)
        if len(results) == 1:
            return next(iter(results.values()))
        return results

    def __repr__(self) -> str:
        return f"Annotator({self.name!r}, {self.init_params})"


def shape_output(out: dict, legacy: bool = True, copy_arrays: bool = False) -> Any:
    """Apply Replicator's ``get_data`` rules to a ``{"data", "info"}`` output."""
    data = out.get("data")
    info = out.get("info", {})
    if copy_arrays and isinstance(data, np.ndarray):
        data = data.copy()
    if not legacy:
        return {"data": data, **info} if data is not None else dict(info)
    if data is None:
        return dict(info)
    if not info:
        return data
    return {"data": data, "info": info}
