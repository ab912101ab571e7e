"""``rep.writers``: the writer registry's function form.

Example:
    >>> import graphsdg as rep
    >>> "BasicWriter" in rep.writers.get_writers()
    True
"""
from __future__ import annotations

from typing import Any

from graphsdg.io.writer import Writer, WriterRegistry


def register_writer(writer_cls: type[Writer], category: str | None = None) -> None:
    WriterRegistry.register(writer_cls, category)


def unregister_writer(name: str) -> None:
    """Remove writer ``name`` (attached instances detach); an unknown name raises."""
    WriterRegistry.unregister(name)


def register_node_writer(name: str, node_type_id: str, annotators: list, category: str | None = None,
                         **kwargs: Any) -> None:
    """Replicator's OmniGraph node writers; graphsdg has no OmniGraph nodes, so this raises, saying what to do."""
    WriterRegistry.register_node_writer(name, node_type_id, annotators, category, **kwargs)


def get(name: str, init_params: dict | None = None, render_products: Any = None,
        trigger: Any = "omni.replicator.core.OgnOnFrame") -> Writer:
    return WriterRegistry.get(name, init_params=init_params, render_products=render_products, trigger=trigger)


def get_writers(category: str | None = None) -> dict[str, type[Writer]]:
    return WriterRegistry.get_writers(category)


__all__ = ["register_writer", "unregister_writer", "register_node_writer", "get", "get_writers", "Writer",
           "WriterRegistry"]
