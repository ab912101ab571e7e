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
import itertools
import re
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Iterable

import numpy as np

from graphsdg.annotate import augmentation as augmentations
from graphsdg.annotate.augmentation import Augmentation, AugmentationError, as_augmentation
from graphsdg.annotate.semantic_filter import SemanticFilter
from graphsdg.errors import UnknownNameError, closest, unknown_name
from graphsdg.render.attachments import attachments
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
    # Computed from the capture's pixels, camera and labels alone (no live scene state), so it may
    # run after the script has moved the scene on: what lets step(wait_for_render=False) pipeline.
    pixels_only: bool = False
    # The class mask it colours from the ids for its params, as (kind, semantic filter) of
    # FrameView.colorized_id_image, or None: a renderer may colour that where the ids are drawn.
    id_colours: Callable[[dict], tuple[str, SemanticFilter] | None] | None = None


@dataclass(frozen=True)
class AovSource:
    """A raw render output (Replicator's AOV) that annotators can be registered from."""

    name: str
    passes: frozenset[str]
    read: Callable[["FrameView"], np.ndarray]   # noqa: F821  (H, W) or (H, W, C)
    doc: str = ""


class AnnotatorRegistryError(UnknownNameError):
    """An annotator name the registry does not know, or a bad registry call (Replicator's error type)."""


class AnnotatorRegistry:
    """Registry of annotator specs (``rep.AnnotatorRegistry``)."""

    _specs: dict[str, AnnotatorSpec] = {}
    _aliases: dict[str, str] = {}
    _aovs: dict[str, AovSource] = {}
    #: names of the annotators graphsdg ships (Replicator keeps this list for its telemetry; scripts append to it)
    _default_annotators: list[str] = []

    @classmethod
    def register_spec(cls, spec: AnnotatorSpec, aliases: Iterable[str] = ()) -> None:
        """Register ``spec`` under its name, its ``aliases`` and ``<name>_fast``."""
        cls._specs[spec.name] = spec
        for alias in (*aliases, f"{spec.name}_fast"):
            if alias not in cls._specs:
                cls._aliases[alias] = spec.name

    @classmethod
    def resolve(cls, name: str) -> AnnotatorSpec:
        """The spec registered as ``name`` (an alias or a ``_fast`` variant included)."""
        if not isinstance(name, str):
            raise TypeError(f"annotator name must be a string, got {type(name).__name__}")
        key = cls._aliases.get(name, name)
        if key not in cls._specs and key.endswith("_fast"):
            key = cls._aliases.get(key[:-5], key[:-5])
        spec = cls._specs.get(key)
        if spec is None:
            raise AnnotatorRegistryError(str(unknown_name("annotator", name, cls.get_registered_annotators())))
        return spec

    @classmethod
    def get_annotator(cls, name: str, init_params: dict | None = None, render_product_idxs=None,
                      device: str | None = None, do_array_copy: bool = True) -> "Annotator":
        """A new :class:`Annotator` of type ``name`` with ``init_params``."""
        spec = cls.resolve(name)
        if init_params is not None and not isinstance(init_params, dict):
            raise TypeError(f"init_params of annotator {name!r} must be a dict, got {init_params!r}")
        return Annotator(name, spec, init_params or {}, device=device, do_array_copy=do_array_copy)

    @classmethod
    def get_registered_annotators(cls) -> list[str]:
        """Every name ``get_annotator`` accepts."""
        return sorted(set(cls._specs) | set(cls._aliases))

    @classmethod
    def get_aovs(cls) -> list[str]:
        """The raw outputs :meth:`register_annotator_from_aov` accepts."""
        return sorted(cls._aovs)

    @classmethod
    def register_aov(cls, source: AovSource, aliases: Iterable[str] = ()) -> None:
        """Make a raw render output available to :meth:`register_annotator_from_aov`."""
        for name in (source.name, *aliases):
            cls._aovs[name] = source

    @classmethod
    def register_annotator_from_aov(cls, aov: str, output_data_type: Any = None, output_channels: int = 1,
                                    name: str | None = None, documentation: str | None = None) -> str:
        """Register an annotator that returns the raw output ``aov`` (see :meth:`get_aovs`).

        ``output_data_type`` converts the array (default: the AOV's own dtype);
        ``output_channels`` keeps that many channels (1 gives (H, W)). Returns the
        annotator's name (``name`` or ``aov``).

        Example:
            >>> import graphsdg as rep
            >>> rep.AnnotatorRegistry.register_annotator_from_aov("DepthLinearized", name="my_depth")
            'my_depth'
        """
        source = cls._aovs.get(aov) if isinstance(aov, str) else None
        if source is None:
            raise unknown_name("AOV", aov, cls._aovs)
        channels = int(output_channels)
        if channels < 1:
            raise ValueError(f"output_channels must be >= 1, got {output_channels!r}")
        dtype = np.dtype(output_data_type) if output_data_type is not None else None
        label = name or aov

        def compute(frame, params):
            arr = np.asarray(source.read(frame))
            have = 1 if arr.ndim == 2 else arr.shape[2]
            if channels > have:
                raise ValueError(f"annotator {label!r}: AOV {aov!r} has {have} channel(s), "
                                 f"output_channels={channels} asked for more")
            out = arr if arr.ndim == 2 else (arr[..., 0] if channels == 1 else arr[..., :channels])
            return {"data": np.ascontiguousarray(out.astype(dtype) if dtype is not None else out)}

        cls.register_spec(AnnotatorSpec(name=label, passes=source.passes, compute=compute,
                                        doc=documentation or source.doc))
        return label

    @classmethod
    def register_annotator_from_node(cls, name: str, *args: Any, **kwargs: Any) -> None:
        """Replicator builds annotators from OmniGraph node types, which graphsdg does not have."""
        raise NotImplementedError(
            f"register_annotator_from_node({name!r}, ...) needs an OmniGraph node type; graphsdg has none. "
            f"Use AnnotatorRegistry.register_annotator_from_function(name, fn, inputs=[...]) to compute an "
            f"annotator in Python from other annotators, or register_annotator_from_aov(aov) for a raw output")

    @classmethod
    def register_annotator_from_function(cls, name: str, fn: Callable[..., Any],
                                         inputs: Iterable["str | Annotator"], init_params: dict | None = None,
                                         doc: str = "") -> str:
        """Register ``fn(**{input: data}, **params)`` over other annotators' outputs as annotator ``name``.

        ``inputs`` are annotator names (default init params) or
        ``rep.annotators.get(...)`` objects (their init params); ``fn`` receives each
        input's ``data`` (or its whole dict when it has no array), keyed by the input's
        name, plus this annotator's init params. It may return an array or a
        ``{"data": ..., "info": {...}}`` dict.

        Example:
            >>> import numpy as np, graphsdg as rep
            >>> rep.AnnotatorRegistry.register_annotator_from_function(
            ...     "box_count", lambda bounding_box_2d_tight: np.array([len(bounding_box_2d_tight)]),
            ...     inputs=["bounding_box_2d_tight"])
            'box_count'
        """
        if not isinstance(name, str) or not name:
            raise ValueError(f"annotator name must be a non-empty string, got {name!r}")
        if not callable(fn):
            raise TypeError(f"annotator {name!r}: fn must be callable, got {fn!r}")
        deps: list[tuple[str, AnnotatorSpec, dict]] = []
        for entry in inputs:
            if isinstance(entry, Annotator):
                deps.append((entry.name, entry.spec, dict(entry.init_params)))
            else:
                spec = cls.resolve(entry)
                deps.append((entry, spec, _params(spec, {})))
        if not deps:
            raise ValueError(f"annotator {name!r} needs at least one input annotator")

        def compute(frame, params):
            args = {}
            for key, spec, dep_params in deps:
                out = get_output(frame, spec, dep_params)
                args[key] = out["data"] if out.get("data") is not None else {**out.get("info", {})}
            result = fn(**args, **params)
            if isinstance(result, dict) and ("data" in result or "info" in result):
                return result
            return {"data": result}

        passes = frozenset().union(*[spec.passes for _, spec, _ in deps])
        cls.register_spec(AnnotatorSpec(name=name, passes=passes, compute=compute,
                                        defaults=dict(init_params or {}), doc=doc or (fn.__doc__ or "")))
        return name

    @classmethod
    def detach(cls, annotator: "Annotator | str", render_products=None) -> None:
        """Detach ``annotator`` (an object, or the name of attached ones) from ``render_products`` (default all)."""
        if isinstance(annotator, Annotator):
            annotator.detach(render_products)
            return
        found = [a for a in attachments.annotators if a.name == annotator]
        if not found:
            raise ValueError(f"no attached annotator named {annotator!r}; attached: "
                             f"{sorted({a.name for a in attachments.annotators})}")
        for a in found:
            a.detach(render_products)

    @classmethod
    def unregister(cls, name: str) -> None:
        """Remove annotator ``name`` and its aliases (nothing happens for an unknown name)."""
        cls._specs.pop(name, None)
        cls._aliases.pop(name, None)
        for alias in [a for a, n in cls._aliases.items() if n == name]:
            del cls._aliases[alias]

    @classmethod
    def unregister_annotator(cls, name: str) -> None:
        """Remove annotator ``name`` (Replicator's call); an unknown name raises, listing the registered ones."""
        if not isinstance(name, str):
            raise AnnotatorRegistryError(f"annotator name must be a string, got {type(name).__name__} {name!r}")
        if name not in cls._specs and name not in cls._aliases:
            raise AnnotatorRegistryError(str(unknown_name("annotator", name, cls.get_registered_annotators())))
        cls.unregister(name)

    @classmethod
    def register(cls, name: str, annotator: "Annotator | str") -> str:
        """Register ``annotator`` (an object, augmentations and init params included, or a registered name)
        under ``name``; ``get_annotator(name)`` then makes annotators like it.

        Example:
            >>> import graphsdg as rep
            >>> noisy = rep.annotators.get("distance_to_camera").augment(
            ...     rep.annotators.Augmentation.from_function(lambda data_in: data_in + 1.0))
            >>> rep.annotators.register("depth_plus_one", noisy)
            'depth_plus_one'
        """
        if not isinstance(name, str) or not name:
            raise AnnotatorRegistryError(f"annotator name must be a non-empty string, got {name!r}")
        if isinstance(annotator, Annotator):
            spec, params = annotator.spec, dict(annotator.init_params)
        elif isinstance(annotator, str):
            spec = cls.resolve(annotator)
            params = dict(spec.defaults)
        else:
            raise AnnotatorRegistryError(f"register({name!r}, ...) needs an annotator or an annotator's name, got "
                                         f"{type(annotator).__name__}")
        cls.unregister(name)
        cls._specs[name] = replace(spec, defaults=params)
        return name

    # ---- augmentations (graphsdg.annotate.augmentation keeps them) ----
    @classmethod
    def register_augmentation(cls, name: str, augmentation: "Augmentation | str") -> None:
        """Register ``augmentation`` as ``name`` (``annotator.augment(name)`` then applies it)."""
        augmentations.register_augmentation(name, augmentation)

    @classmethod
    def unregister_augmentation(cls, name: str) -> None:
        """Remove the augmentation registered as ``name``."""
        augmentations.unregister_augmentation(name)

    @classmethod
    def get_augmentation(cls, name: str) -> Augmentation:
        """The augmentation registered as ``name``."""
        return augmentations.get_augmentation(name)


def _params(spec: AnnotatorSpec, given: dict) -> dict:
    unknown = set(given) - set(spec.defaults)
    if unknown:
        hints = "".join(closest(str(u), spec.defaults) for u in sorted(unknown))
        raise ValueError(f"annotator {spec.name!r} has no init param(s) {sorted(unknown)}{hints}; "
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

    def initialize(self, **init_params: Any) -> "Annotator":
        """Set init params (Replicator's ``annotator.initialize(...)``), checked as ``get(name, init_params)``."""
        self.init_params = _params(self.spec, {**self.init_params, **init_params})
        return self

    def attach(self, render_products: "RenderProduct | str | Iterable[RenderProduct | str]") -> "Annotator":
        """Attach to one render product or a list of them (objects or paths)."""
        items = render_products if isinstance(render_products, (list, tuple)) else [render_products]
        if not items:
            raise ValueError(f"annotator {self.name!r}: attach() needs at least one render product")
        for item in items:
            rp = rp_registry.find(item)
            if rp not in self._render_products:
                self._render_products.append(rp)
        attachments.annotators.add(self)
        return self

    def detach(self, render_products=None) -> None:
        """Detach from ``render_products`` (default: all)."""
        attachments.complete_capture()
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
            attachments.annotators.discard(self)

    def augment(self, augmentation: "Augmentation | str | Callable[..., Any]",
                data_out_shape: tuple[int, ...] | None = None, name: str | None = None, device: str | None = None,
                **kwargs: Any) -> "Annotator":
        """Apply ``augmentation`` to this annotator's output from now on; returns the annotator itself.

        ``augmentation`` is an :class:`~graphsdg.annotate.augmentation.Augmentation`, a registered
        augmentation's name, or a function / Warp kernel taking ``data_in``; ``kwargs`` set its parameters
        for this use, ``name`` renames the annotator (its key in writers' data).

        Example:
            >>> import graphsdg as rep
            >>> def swap_red_blue(data_in):
            ...     return data_in[..., [2, 1, 0, 3]]
            >>> rep.annotators.get("rgb").augment(swap_red_blue, name="bgr").name
            'bgr'
        """
        if device not in (None, "cpu"):
            raise ValueError(f"augmentation device {device!r} is not available; graphsdg runs augmentations on "
                             f"the CPU (device=None or 'cpu'; Warp kernels run on Warp's CPU device)")
        aug = as_augmentation(augmentation, data_out_shape, **kwargs)
        params = aug.bind(**kwargs)
        self.spec = _augmented_spec(self.spec, aug, params, data_out_shape)
        if name:
            self.name = name
        return self

    def augment_compose(self, augmentations: "Iterable[Augmentation | str]", name: str | None = None) -> "Annotator":
        """Apply several augmentations in order (each to the previous one's output); returns the annotator."""
        if isinstance(augmentations, (str, Augmentation)) or not isinstance(augmentations, Iterable):
            raise AugmentationError(f"augment_compose needs a list of augmentations, got {augmentations!r}")
        items = list(augmentations)
        bad = [type(a).__name__ for a in items if not isinstance(a, (str, Augmentation))]
        if bad or not items:
            raise AugmentationError(f"augment_compose needs a non-empty list of Augmentations or registered "
                                    f"augmentation names, got {bad or items}")
        for aug in items:
            self.augment(aug)
        if name:
            self.name = name
        return self

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
        attachments.complete_capture()   # a pipelined step's outputs are computed when first asked for
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


_augmented = itertools.count()


def _augmented_spec(source: AnnotatorSpec, aug: Augmentation, params: dict,
                    data_out_shape: tuple[int, ...] | None) -> AnnotatorSpec:
    """``source`` with ``aug`` applied to its array: a spec of its own name, so frames cache both outputs."""
    key = f"{source.name}+{aug.name}#{next(_augmented)}"
    # what is augmented, without the counters that make names unique: seeds keyed on it do not depend on how
    # many augmentations the process made before
    recipe = f"{re.sub(r'#[0-9]+', '', source.name)}+{aug.name}{sorted(params.items())!r}"

    def compute(frame, init_params: dict) -> dict:
        out = get_output(frame, source, init_params)
        data = out.get("data")
        if data is None:
            raise AugmentationError(f"annotator {source.name!r} has no data array for augmentation {aug.name!r} "
                                    f"to work on (its output holds only {sorted(out.get('info', {}))})")
        result = aug.run(data, (recipe, frame.render_product.path, frame.frame_index), params, data_out_shape,
                         instance=key)
        info = dict(out.get("info") or {})
        if isinstance(result, dict):
            info.update(result["info"])
            result = result["data"]
        return {"data": result, "info": info} if info else {"data": result}

    return replace(source, name=key, compute=compute,
                   doc=f"{source.doc}\n\nAugmented with {aug.name!r} {params}.".strip())


# augmentations resolve annotator names through the registry (the augmentation module cannot import this one)
augmentations.annotator_lookup = AnnotatorRegistry.get_annotator


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
