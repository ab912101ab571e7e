"""``rep.annotators``: get annotators by name, register them, and augment their outputs.

Example:
    >>> import graphsdg as rep
    >>> "bounding_box_2d_tight" in rep.annotators.get_registered_annotators()
    True
    >>> "RgbToHsv" in rep.annotators.get_registered_augmentations()
    True
"""
from __future__ import annotations

from typing import Any, Callable, Iterable

from graphsdg.annotate import augmentation as _augmentation
from graphsdg.annotate.annotator import Annotator, AnnotatorRegistry, AnnotatorRegistryError
from graphsdg.annotate.augmentation import Augmentation, AugmentationError


def get(name: str, init_params: dict | None = None, render_product_idxs=None, device: str | None = None,
        do_array_copy: bool = True) -> Annotator:
    """A new annotator of type ``name`` (see :func:`get_registered_annotators`)."""
    return AnnotatorRegistry.get_annotator(name, init_params=init_params, render_product_idxs=render_product_idxs,
                                           device=device, do_array_copy=do_array_copy)


def get_registered_annotators() -> list[str]:
    """Every annotator name :func:`get` accepts."""
    return AnnotatorRegistry.get_registered_annotators()


def register(name: str, annotator: "Annotator | str") -> str:
    """Register ``annotator`` (an object, augmentations included, or a registered name) as ``name``."""
    return AnnotatorRegistry.register(name, annotator)


def _source(source_annotator: "Annotator | str", call: str) -> Annotator:
    if isinstance(source_annotator, str):
        return AnnotatorRegistry.get_annotator(source_annotator)
    if not isinstance(source_annotator, Annotator):
        raise AnnotatorRegistryError(f"{call}: source_annotator must be an annotator or an annotator's name, got "
                                     f"{type(source_annotator).__name__} {source_annotator!r}")
    return source_annotator


def augment(source_annotator: "Annotator | str", augmentation: "Augmentation | str | Callable[..., Any]",
            data_out_shape: tuple[int, ...] | None = None, name: str | None = None, device: str | None = None,
            **kwargs: Any) -> Annotator:
    """``source_annotator`` (an object, augmented in place, or a name: a new annotator) with ``augmentation``
    applied to its output; ``name`` renames it in writers' data."""
    return _source(source_annotator, "augment").augment(augmentation, data_out_shape=data_out_shape, name=name,
                                                        device=device, **kwargs)


def augment_compose(source_annotator: "Annotator | str", augmentations: "Iterable[Augmentation | str]",
                    name: str | None = None) -> Annotator:
    """``source_annotator`` with ``augmentations`` applied in order."""
    return _source(source_annotator, "augment_compose").augment_compose(augmentations, name=name)


def register_augmentation(name: str, augmentation: "Augmentation | str") -> None:
    """Register ``augmentation`` as ``name`` (then ``annotator.augment(name)`` or :func:`get_augmentation`)."""
    AnnotatorRegistry.register_augmentation(name, augmentation)


def unregister_augmentation(name: str) -> None:
    """Remove the augmentation registered as ``name``."""
    AnnotatorRegistry.unregister_augmentation(name)


def get_augmentation(name: str) -> Augmentation:
    """The augmentation registered as ``name``."""
    return AnnotatorRegistry.get_augmentation(name)


def get_registered_augmentations() -> list[str]:
    """Every name :func:`get_augmentation` answers."""
    return _augmentation.registered_augmentations()


__all__ = ["get", "get_registered_annotators", "register", "augment", "augment_compose", "register_augmentation",
           "unregister_augmentation", "get_augmentation", "get_registered_augmentations", "Annotator",
           "AnnotatorRegistry", "AnnotatorRegistryError", "Augmentation", "AugmentationError"]
