"""Augmentations: a NumPy function or a Warp kernel applied to an annotator's output (Replicator's ``Augmentation``).

An :class:`Augmentation` wraps a function of the annotator's array:

* a Python function ``fn(data_in, **params)`` returning the new array (or ``None`` after editing
  ``data_in`` in place). ``data_in`` is a copy of the annotator's array with a channel axis always
  present, ``(H, W, C)``: a 2-D output such as ``distance_to_camera`` arrives as ``(H, W, 1)``, as in
  Replicator; a result whose channel axis is 1 goes back to ``(H, W)``. A function may also return
  ``{"data": array, "info": {...}}`` to add info fields to the output.
* a Warp kernel ``kernel(data_in, data_out, *params)`` (``pip install 'graphsdg[warp]'``), launched on
  Warp's CPU device over the image's ``(H, W)``; ``data_in`` has the kernel's declared array type (an
  ``array2d`` gets ``(H, W)``), ``data_out`` is made with ``data_out_shape`` (``-1`` keeps an axis of the
  input; default: the input's shape) and the kernel's declared dtype.

A parameter named ``seed`` receives a new integer each frame, drawn from a stream keyed on the
augmentation's ``seed`` (or, when that is ``None`` or negative, the global seed and the augmented
annotator) and on the render product and frame: the same script and seed give the same noise, and
any frame's noise can be recomputed on its own.

Replicator's augmentation *nodes* (``Augmentation.from_node("omni.replicator.core.AugPixellateExp")``)
map onto graphsdg's own NumPy implementations (:mod:`graphsdg.annotate.augmentations_default`
registers them); there is no OmniGraph.

Example:
    >>> import numpy as np
    >>> from graphsdg.annotate.augmentation import Augmentation
    >>> def invert(data_in):
    ...     return 255 - data_in
    >>> aug = Augmentation.from_function(invert)
    >>> aug.run(np.zeros((2, 2, 4), np.uint8), seed_key=("doc",))[0, 0].tolist()
    [255, 255, 255, 255]
"""
from __future__ import annotations

import inspect
from typing import Any, Callable, Hashable

import numpy as np

from graphsdg import rng
from graphsdg.errors import GraphSDGError, closest

WARP_INSTALL_HINT = "pip install 'graphsdg[warp]'"
#: the parameters the augmentation machinery fills in itself
RESERVED = ("data_in", "data_out", "seed")
SEED_RANGE = 2147483647   # seeds handed to functions and kernels are in [0, 2**31 - 1), as Replicator's


class AugmentationError(GraphSDGError, ValueError):
    """An augmentation that cannot be built or applied as given."""


def is_warp_kernel(fn: Any) -> bool:
    """Whether ``fn`` is a Warp kernel (``@wp.kernel``), told without importing Warp."""
    cls = type(fn)
    return cls.__name__ == "Kernel" and cls.__module__.split(".")[0] == "warp"


def import_warp():
    """The ``warp`` module, or an ImportError naming the extra that installs it."""
    try:
        import warp
    except ImportError as exc:
        raise ImportError(f"Warp augmentations need the warp-lang package, which is not installed: "
                          f"{WARP_INSTALL_HINT}") from exc
    return warp


def _check_shape(data_out_shape: Any) -> tuple[int, ...] | None:
    if data_out_shape is None:
        return None
    if not isinstance(data_out_shape, (tuple, list)) or not data_out_shape or not all(
            isinstance(s, (int, np.integer)) and not isinstance(s, bool) and (s == -1 or s > 0)
            for s in data_out_shape):
        raise AugmentationError(f"data_out_shape must be a tuple of positive integers or -1 (keep the input's "
                                f"axis), got {data_out_shape!r}")
    return tuple(int(s) for s in data_out_shape)


class Augmentation:
    """An operation on an annotator's array: a Python function or a Warp kernel, with its parameters.

    Build one with :meth:`from_function` (or :meth:`from_node` for Replicator's augmentation node
    types), then ``annotator.augment(aug)``, ``rep.annotators.augment(...)`` or
    ``rep.annotators.register_augmentation(name, aug)``.
    """

    def __init__(self, augmentation: Callable[..., Any], data_out_shape: tuple[int, ...] | None = None,
                 documentation: str | None = None, node_type_id: str | None = None, **kwargs: Any) -> None:
        if not callable(augmentation) and not is_warp_kernel(augmentation):
            raise AugmentationError(f"an augmentation must be a Python function or a Warp kernel, got "
                                    f"{type(augmentation).__name__} {augmentation!r}")
        self.function = augmentation
        self.is_kernel = is_warp_kernel(augmentation)
        self.data_out_shape = _check_shape(data_out_shape)
        self._documentation = documentation
        self._kwargs = dict(kwargs)
        target = augmentation.func if self.is_kernel else augmentation
        self.parameters = dict(inspect.signature(target).parameters)
        self.name = getattr(target, "__name__", type(target).__name__)
        self.node_type_id = node_type_id or ("omni.replicator.core.OgnAugment" if self.is_kernel
                                             else "omni.replicator.core.OgnAugmentCPU")
        if "data_in" not in self.parameters:
            raise AugmentationError(f"augmentation {self.name!r} must take a data_in parameter (the annotator's "
                                    f"array); its parameters are {list(self.parameters)}")
        if self.is_kernel and "data_out" not in self.parameters:
            raise AugmentationError(f"Warp kernel augmentation {self.name!r} must take a data_out parameter "
                                    f"(the array it writes); its parameters are {list(self.parameters)}")
        if not self.is_kernel and "data_out" in self.parameters:
            raise AugmentationError(f"Python augmentation {self.name!r} takes data_out, which only Warp kernels "
                                    f"take: return the new array instead")
        self._check_names(self._kwargs)   # required parameters may still come when it is used

    @property
    def documentation(self) -> str | None:
        """The augmentation's documentation, if it was given one."""
        return self._documentation

    @property
    def kwargs(self) -> dict[str, Any]:
        """The parameters the augmentation was made with (a copy)."""
        return dict(self._kwargs)

    @staticmethod
    def from_function(augmentation: Callable[..., Any], data_out_shape: tuple[int, ...] | None = None,
                      documentation: str | None = None, **kwargs: Any) -> "Augmentation":
        """An augmentation from a Python function or a Warp kernel taking ``data_in`` (see the module doc).

        ``kwargs`` set the function's other parameters; ``data_out_shape`` sets a Warp kernel's output
        shape (``-1`` keeps the input's axis).

        Example:
            >>> import graphsdg as rep
            >>> def brighten(data_in, gain):
            ...     return (data_in * gain).clip(0, 255).astype(data_in.dtype)
            >>> rep.annotators.Augmentation.from_function(brighten, gain=1.5).kwargs
            {'gain': 1.5}
        """
        return Augmentation(augmentation, data_out_shape=data_out_shape, documentation=documentation, **kwargs)

    @staticmethod
    def from_node(node_type_id: str, attributes_mapping: dict | None = None,
                  data_out_shape: tuple[int, ...] | None = None, documentation: str | None = None,
                  **kwargs: Any) -> "Augmentation":
        """Replicator's augmentation node types (``omni.replicator.core.AugPixellateExp``, ...), as graphsdg's
        NumPy implementations of them (:data:`NODE_TYPES`); ``kwargs`` are the node's input attributes."""
        if attributes_mapping:
            raise AugmentationError(f"Augmentation.from_node({node_type_id!r}): attributes_mapping connects "
                                    f"OmniGraph attributes, which graphsdg does not have; pass the node's "
                                    f"inputs as keyword arguments")
        function = NODE_TYPES.get(node_type_id) if isinstance(node_type_id, str) else None
        if function is None:
            known = sorted(NODE_TYPES)
            raise AugmentationError(f"unknown augmentation node type {node_type_id!r}"
                                    f"{closest(str(node_type_id), known)}; graphsdg implements: "
                                    f"{', '.join(known) or 'none'}")
        return Augmentation(function, data_out_shape=data_out_shape, documentation=documentation,
                            node_type_id=node_type_id, **kwargs)

    def _check_names(self, params: dict[str, Any]) -> None:
        takes_any = any(p.kind == p.VAR_KEYWORD for p in self.parameters.values())
        unknown = [k for k in params if (k not in self.parameters and not takes_any) or k in ("data_in", "data_out")]
        if unknown:
            raise AugmentationError(f"augmentation {self.name!r} has no parameter(s) {unknown}; it takes "
                                    f"{[p for p in self.parameters if p not in ('data_in', 'data_out')]}")

    def check_params(self, params: dict[str, Any]) -> None:
        """Raise naming any parameter the function does not take, or a required one ``params`` lacks."""
        self._check_names(params)
        missing = [n for n, p in self.parameters.items() if n not in RESERVED and n not in params
                   and p.default is inspect.Parameter.empty
                   and p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)]
        if missing:
            raise AugmentationError(f"augmentation {self.name!r} is missing required argument(s) {missing}; "
                                    f"pass them to from_function(...) or augment(...)")

    def bind(self, **kwargs: Any) -> dict[str, Any]:
        """The parameters of one use: the augmentation's own, overridden by ``kwargs`` (checked)."""
        params = {**self._kwargs, **kwargs}
        self.check_params(params)
        return params

    def run(self, data: np.ndarray, seed_key: tuple[Hashable, ...], params: dict[str, Any] | None = None,
            data_out_shape: tuple[int, ...] | None = None, instance: Hashable = None) -> Any:
        """Apply the augmentation to ``data``; ``seed_key`` names what is augmented, the product and the frame,
        ``instance`` the augmented annotator (it keys the seed only when the seed is the global one, so two
        annotators augmented alike with one explicit seed get the same noise, as that seed says).

        Returns the new array, or ``{"data": array, "info": {...}}`` where the function returned one.
        """
        params = self.bind(**(params or {}))
        if not isinstance(data, np.ndarray):
            raise AugmentationError(f"augmentation {self.name!r} needs an array to augment, got "
                                    f"{type(data).__name__}")
        if "seed" in self.parameters:
            seed = params.get("seed")
            explicit = seed is not None and not isinstance(seed, bool) and isinstance(seed, (int, np.integer)) \
                and seed >= 0
            params["seed"] = frame_seed(seed, seed_key if explicit else seed_key + (instance,))
        shape = _check_shape(data_out_shape) or self.data_out_shape
        if self.is_kernel:
            return _run_kernel(self, data, params, shape)
        return _run_function(self, data, params)

    def apply(self, annotator: Any, name: str | None = None, **kwargs: Any) -> Any:
        """Augment ``annotator`` (an annotator object or a registered annotator's name); returns it."""
        if isinstance(annotator, str):
            if annotator_lookup is None:
                raise AugmentationError("no annotator registry is loaded (import graphsdg first)")
            annotator = annotator_lookup(annotator)
        if not hasattr(annotator, "augment"):
            raise AugmentationError(f"cannot augment {annotator!r} ({type(annotator).__name__}); expected an "
                                    f"annotator or an annotator name")
        return annotator.augment(self, name=name, **kwargs)

    def __repr__(self) -> str:
        kind = "Warp kernel" if self.is_kernel else "function"
        return f"Augmentation({kind} {self.name!r}, {self._kwargs})"


#: annotator name -> a new annotator of it; set by :mod:`graphsdg.annotate.annotator`, which imports this module
#: (annotators sit above augmentations, so the registry hands its lookup down instead of being imported back)
annotator_lookup: Callable[[str], Any] | None = None

#: Replicator's augmentation node type id -> graphsdg's NumPy implementation (filled by augmentations_default)
NODE_TYPES: dict[str, Callable[..., Any]] = {}


def frame_seed(seed: Any, key: tuple[Hashable, ...]) -> int:
    """The integer a ``seed`` parameter receives for one frame: from ``seed`` when it is a non-negative
    integer, else from the global seed, and from ``key`` (annotator, render product, frame)."""
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer))):
        raise AugmentationError(f"augmentation seed must be an integer or None, got {seed!r}")
    base = rng.get_global_seed() if seed is None or seed < 0 else int(seed)
    sequence = np.random.SeedSequence([base, rng.stable_key("augmentation", *key)])
    return int(np.random.default_rng(sequence).integers(SEED_RANGE))


def _run_function(aug: Augmentation, data: np.ndarray, params: dict[str, Any]) -> Any:
    squeeze = data.ndim == 2
    data_in = (data[..., None] if squeeze else data).copy()   # the source's cached array stays untouched
    result = aug.function(data_in=data_in, **params)
    info = None
    if isinstance(result, dict):
        if "data" not in result:
            raise AugmentationError(f"augmentation {aug.name!r} returned a dict without 'data': "
                                    f"{sorted(result)}")
        info, result = dict(result.get("info") or {}), result["data"]
    if result is None:
        result = data_in   # edited in place
    if not isinstance(result, np.ndarray):
        raise AugmentationError(f"augmentation {aug.name!r} returned {type(result).__name__}; expected a numpy "
                                f"array (or None after editing data_in in place)")
    if result.ndim == 3 and result.shape[2] == 1 and squeeze:
        result = result[..., 0]
    return result if info is None else {"data": result, "info": info}


def _run_kernel(aug: Augmentation, data: np.ndarray, params: dict[str, Any],
                data_out_shape: tuple[int, ...] | None) -> np.ndarray:
    wp = import_warp()
    # the kernel's argument types as Warp resolved them (annotations may be strings under postponed evaluation)
    types = {arg.label: arg.type for arg in aug.function.adj.args}
    array_in, array_out = types["data_in"], types["data_out"]
    data_in = _kernel_input(aug, data, array_in)
    shape = data_in.shape if data_out_shape is None else _out_shape(aug, data_out_shape, data_in.shape)
    device = "cpu"
    inputs = []
    for name in aug.parameters:
        if name == "data_in":
            inputs.append(wp.array(data_in, dtype=array_in.dtype, device=device))
        elif name == "data_out":
            out = wp.zeros(shape, dtype=array_out.dtype, device=device)
            inputs.append(out)
        elif name in params:
            inputs.append(params[name])
        else:
            inputs.append(aug.parameters[name].default)
    wp.launch(aug.function, dim=data_in.shape[:2], inputs=inputs, device=device)
    return out.numpy()


def _kernel_input(aug: Augmentation, data: np.ndarray, array_type: Any) -> np.ndarray:
    ndim = getattr(array_type, "ndim", None)
    if ndim is None:
        raise AugmentationError(f"Warp kernel {aug.name!r}: data_in must be annotated as a Warp array "
                                f"(wp.array2d / wp.array3d), got {array_type!r}")
    if ndim == 2 and data.ndim == 3 and data.shape[2] == 1:
        data = data[..., 0]
    elif ndim == 3 and data.ndim == 2:
        data = data[..., None]
    if data.ndim != ndim:
        raise AugmentationError(f"Warp kernel {aug.name!r} takes a {ndim}-D data_in; the annotator gives "
                                f"shape {data.shape}")
    return np.ascontiguousarray(data)


def _out_shape(aug: Augmentation, requested: tuple[int, ...], in_shape: tuple[int, ...]) -> tuple[int, ...]:
    if len(requested) != len(in_shape) and -1 in requested[len(in_shape):]:
        raise AugmentationError(f"Warp kernel {aug.name!r}: data_out_shape {requested} keeps (-1) an axis the "
                                f"input of shape {in_shape} does not have")
    return tuple(in_shape[i] if s == -1 else s for i, s in enumerate(requested))


# ---- the registry of named augmentations -------------------------------------------------------------
_registered: dict[str, Augmentation] = {}
#: names Replicator registers that graphsdg cannot provide, with the reason
UNAVAILABLE: dict[str, str] = {}


def register_augmentation(name: str, augmentation: "Augmentation | str") -> None:
    """Register ``augmentation`` under ``name`` (an Augmentation, a registered name or a node type id)."""
    if not isinstance(name, str) or not name:
        raise AugmentationError(f"augmentation name must be a non-empty string, got {name!r}")
    if isinstance(augmentation, str):
        augmentation = (_registered[augmentation] if augmentation in _registered
                        else Augmentation.from_node(augmentation))
    if not isinstance(augmentation, Augmentation):
        raise AugmentationError(f"register_augmentation({name!r}, ...) needs an Augmentation (see "
                                f"Augmentation.from_function), a registered augmentation's name or a node type id, "
                                f"got {type(augmentation).__name__}")
    _registered[name] = augmentation


def unregister_augmentation(name: str) -> None:
    """Remove the augmentation registered as ``name``."""
    if name not in _registered:
        raise AugmentationError(f"no augmentation registered as {name!r}{closest(str(name), _registered)}; "
                                f"registered: {', '.join(sorted(_registered))}")
    del _registered[name]


def get_augmentation(name: str) -> Augmentation:
    """The augmentation registered as ``name``."""
    if not isinstance(name, str):
        raise AugmentationError(f"augmentation name must be a string, got {type(name).__name__} {name!r}")
    found = _registered.get(name)
    if found is None:
        if name in UNAVAILABLE:
            raise AugmentationError(f"augmentation {name!r} is not available in graphsdg: {UNAVAILABLE[name]}")
        raise AugmentationError(f"no augmentation registered as {name!r}{closest(name, _registered)}; "
                                f"registered: {', '.join(sorted(_registered))}")
    return found


def registered_augmentations() -> list[str]:
    """The names :func:`get_augmentation` answers."""
    return sorted(_registered)


def as_augmentation(augmentation: Any, data_out_shape: tuple[int, ...] | None = None,
                    **kwargs: Any) -> Augmentation:
    """What ``annotator.augment(augmentation, ...)`` accepts, as an Augmentation: one already, a registered
    name, a node type id, or a function or Warp kernel (made with ``kwargs``)."""
    if isinstance(augmentation, Augmentation):
        return augmentation
    if isinstance(augmentation, str):
        if augmentation in _registered:
            return _registered[augmentation]
        if augmentation in NODE_TYPES:
            return Augmentation.from_node(augmentation, data_out_shape=data_out_shape)
        return get_augmentation(augmentation)   # raises, naming what is registered
    if callable(augmentation) or is_warp_kernel(augmentation):
        return Augmentation.from_function(augmentation, data_out_shape=data_out_shape, **kwargs)
    raise AugmentationError(f"cannot augment with {type(augmentation).__name__} {augmentation!r}; expected an "
                            f"Augmentation, a registered augmentation's name, a function or a Warp kernel")
