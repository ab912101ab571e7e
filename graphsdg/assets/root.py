"""Where assets are looked up: the built-in pack, or a tree the user points to.

Isaac Sim scripts build asset URLs as ``get_assets_root_path() + "/Isaac/..."``.
graphsdg answers with the pack shipped inside the package, so those scripts find
stand-ins at the same relative paths. To use another tree (a local copy of
Isaac's assets, a studio library), set either

* the setting ``/persistent/isaac/asset_root/default`` (Isaac's own key), or
* the environment variable ``GRAPHSDG_ASSETS_ROOT``;

the setting wins over the variable, and both win over the built-in pack.

Example:
    >>> import os
    >>> from graphsdg.assets import get_assets_root_path
    >>> os.path.isfile(get_assets_root_path() + "/Isaac/Environments/Simple_Warehouse/Props/SM_PaletteA_01.usd")
    True
"""
from __future__ import annotations

import os
import warnings

from graphsdg.base import settings_store as settings

ASSETS_ROOT_SETTING = "/persistent/isaac/asset_root/default"
ASSETS_ROOT_ENV = "GRAPHSDG_ASSETS_ROOT"


def builtin_pack_root() -> str:
    """Absolute path of the asset pack shipped inside the installed package."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "pack")


def _configured_root() -> tuple[str, str] | None:
    value = settings.get(ASSETS_ROOT_SETTING)
    if value:
        return os.fspath(value), f"setting {ASSETS_ROOT_SETTING}"
    value = os.environ.get(ASSETS_ROOT_ENV)
    if value:
        return value, f"environment variable {ASSETS_ROOT_ENV}"
    return None


def get_assets_root_path(*, skip_check: bool = False) -> str | None:
    """The root that asset paths such as ``/Isaac/Environments/...`` are relative to.

    As in Isaac Sim, a configured root that does not exist gives ``None`` (with a
    warning naming it) unless ``skip_check`` is true. Trailing slashes are removed,
    so ``root + "/Isaac/..."`` is a well-formed path.
    """
    configured = _configured_root()
    if configured is None:
        return builtin_pack_root()
    root, source = configured
    if "://" not in root:
        root = os.path.abspath(os.path.expanduser(root))
    root = root.rstrip("/") or "/"
    if not skip_check and "://" not in root and not os.path.isdir(root):
        warnings.warn(f"asset root {root!r} (from the {source}) is not a directory; get_assets_root_path() "
                      f"returns None. Unset it to use graphsdg's built-in pack at {builtin_pack_root()!r}",
                      stacklevel=2)
        return None
    return root


async def get_assets_root_path_async(*, skip_check: bool = False) -> str | None:
    """Awaitable form of :func:`get_assets_root_path` (Isaac Sim offers both)."""
    return get_assets_root_path(skip_check=skip_check)
