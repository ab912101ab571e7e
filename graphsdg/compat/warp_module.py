"""``import warp`` in compat mode without warp-lang installed. It raises an error naming graphsdg's ``warp`` extra.

Isaac's augmentation scripts import Warp at the top (``import warp as wp``) even when they run their NumPy
path. Warp is an optional dependency of graphsdg (``pip install 'graphsdg[warp]'``, Warp kernels run on
its CPU device); where it is missing, compat mode answers the import with a
:class:`~graphsdg.compat.modules.CompatImportError` saying so, instead of Python's bare
``No module named 'warp'``. Where Warp is installed, this area does nothing: scripts get the real module.

Example:
    >>> from graphsdg.compat import warp_module
    >>> warp_module.WARP_INSTALL_HINT
    "pip install 'graphsdg[warp]'"
"""
from __future__ import annotations

import importlib.abc
import importlib.util
import sys
import types

from graphsdg.annotate.augmentation import WARP_INSTALL_HINT
from graphsdg.compat.modules import CompatImportError


class MissingWarpFinder(importlib.abc.MetaPathFinder):
    """Answers ``import warp`` (and its submodules) with an error naming the extra that installs it."""

    def find_spec(self, fullname: str, path=None, target=None):
        if fullname.split(".")[0] != "warp":
            return None
        raise CompatImportError(f"{fullname}: the script uses NVIDIA Warp, which is not installed; graphsdg runs "
                                f"Warp kernels (augmentations) on Warp's CPU device once it is: {WARP_INSTALL_HINT}",
                                name=fullname)


_finder: MissingWarpFinder | None = None


def modules() -> list[types.ModuleType]:
    """No Isaac module names: this area only answers ``import warp`` when Warp is missing."""
    return []


def install() -> None:
    """Put the finder in place where Warp cannot be imported."""
    global _finder
    if _finder is not None or "warp" in sys.modules or importlib.util.find_spec("warp") is not None:
        return
    _finder = MissingWarpFinder()
    sys.meta_path.insert(0, _finder)


def uninstall() -> None:
    """Remove the finder."""
    global _finder
    if _finder is not None and _finder in sys.meta_path:
        sys.meta_path.remove(_finder)
    _finder = None
