"""Recordable classes by ``TYPE_ID``, so a replayer rebuilds a session's recordables from its manifest.

Example:
    >>> import graphsdg.episodes   # registers the built-in recordables
    >>> registered_types()[:3]
    ['articulation', 'camera', 'rigid_body']
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from graphsdg.episodes.recordable import Recordable

_classes: dict[str, type[Recordable]] = {}


def register_recordable(cls: type[Recordable]) -> type[Recordable]:
    """Register ``cls`` under its ``TYPE_ID`` (a class decorator); another class claiming the id is an error."""
    type_id = getattr(cls, "TYPE_ID", "")
    if not type_id:
        raise ValueError(f"{cls.__name__} needs a non-empty TYPE_ID to be registered")
    held = _classes.get(type_id)
    if held is not None and held is not cls and held.__qualname__ != cls.__qualname__:
        raise RuntimeError(f"recordable TYPE_ID {type_id!r} is taken by {held.__module__}.{held.__qualname__}; "
                           f"{cls.__module__}.{cls.__qualname__} cannot register it too")
    _classes[type_id] = cls   # the same class reloaded replaces its earlier self
    return cls


def unregister_recordable(type_id: str) -> None:
    """Forget ``type_id`` (an unknown id is ignored)."""
    _classes.pop(type_id, None)


def get_registered(type_id: str) -> type[Recordable] | None:
    """The class registered as ``type_id``, or None."""
    return _classes.get(type_id)


def registered_types() -> list[str]:
    """Every registered ``TYPE_ID``, sorted."""
    return sorted(_classes)


def rehydrate(entry: Mapping[str, Any]) -> Recordable:
    """The recordable a manifest entry describes (KeyError for a missing or unknown ``type``)."""
    if "type" not in entry:
        raise KeyError(f"manifest entry {dict(entry)!r} has no 'type'")
    cls = _classes.get(entry["type"])
    if cls is None:
        raise KeyError(f"unknown recordable type {entry['type']!r}; registered types: {registered_types()}")
    return cls.from_manifest(entry)
