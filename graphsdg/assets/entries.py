"""What one item of the asset pack is. Its path, its size and the code that writes it.

:class:`UsdAsset` and :class:`ImageAsset` describe the pack's files;
:mod:`graphsdg.assets.catalog` gathers them from the modules that build them.

Example:
    >>> a = UsdAsset("cube", "/Isaac/Props/cube.usd", (1.0, 1.0, 1.0), "a cube", lambda root: [])
    >>> a.path
    '/Isaac/Props/cube.usd'
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class UsdAsset:
    """A USD file of the pack: where it lives, its bounding-box size (m) and how to build it."""

    key: str
    path: str
    size: tuple[float, float, float]
    description: str
    build: Callable[[str], list[str]]


@dataclass(frozen=True)
class ImageAsset:
    """A texture or sky image of the pack."""

    key: str
    path: str
    shape: tuple[int, int]       # (rows, cols)
    description: str
    build: Callable[[str], list[str]]


def pack_file(root: str, rel: str) -> str:
    """The absolute path of pack-relative path ``rel`` (``/Isaac/...``) under ``root``."""
    return os.path.join(root, rel.lstrip("/"))
