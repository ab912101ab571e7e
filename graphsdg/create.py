"""``rep.create``: graph-API creators (prims under ``/Replicator``) and render products.

Every call returns a :class:`~graphsdg.graph.ReplicatorItem`. Prims are made when
the call is built; arguments given as distributions are re-sampled (one value
per prim) each time the enclosing trigger fires. Each creator is its node type in
``nodes/create.py``, made callable by :mod:`graphsdg.graph.calls`.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> lights = rep.create.light(light_type="Sphere", intensity=5000, count=2)
    >>> [str(p.GetPath()) for p in lights.get_output_prims()["prims"]]
    ['/Replicator/SphereLight_Xform/SphereLight', '/Replicator/SphereLight_Xform_01/SphereLight']
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.calls import family_calls
from graphsdg.graph.registration import register_function
from graphsdg.render.render_product import create_render_product as render_product

_calls = family_calls("create")
globals().update(_calls)


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.create.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = [*_calls, "register", "render_product"]
