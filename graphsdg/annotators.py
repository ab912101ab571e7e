"""``rep.annotators``: get annotators by name.

Example:
    >>> import graphsdg as rep
    >>> "bounding_box_2d_tight" in rep.annotators.get_registered_annotators()
    True
"""
from __future__ import annotations

from graphsdg.annotate.annotator import Annotator, AnnotatorRegistry


def get(name: str, init_params: dict | None = None, render_product_idxs=None, device: str | None = None,
        do_array_copy: bool = True) -> Annotator:
    """A new annotator of type ``name`` (see :func:`get_registered_annotators`)."""
    return AnnotatorRegistry.get_annotator(name, init_params=init_params, render_product_idxs=render_product_idxs,
                                           device=device, do_array_copy=do_array_copy)


def get_registered_annotators() -> list[str]:
    return AnnotatorRegistry.get_registered_annotators()


__all__ = ["get", "get_registered_annotators", "Annotator", "AnnotatorRegistry"]
