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
    WriterRegistry.unregister(name)


def get(name: str, init_params: dict | None = None, render_products: Any = None,
        trigger: Any = "omni.replicator.core.OgnOnFrame") -> Writer:
    return WriterRegistry.get(name, init_params=init_params, render_products=render_products, trigger=trigger)


def get_writers(category: str | None = None) -> dict[str, type[Writer]]:
    return WriterRegistry.get_writers(category)


__all__ = ["register_writer", "unregister_writer", "get", "get_writers", "Writer", "WriterRegistry"]
