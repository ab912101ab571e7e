"""Nucleus (``omniverse://``) URLs, read from local folders: graphsdg has no Nucleus client.

Isaac Sim scripts often name assets by their Nucleus URL, either the versioned
asset root (``omniverse://localhost/NVIDIA/Assets/Isaac/4.5/Isaac/Props/...``)
or the older server layout (``omniverse://localhost/Isaac/...``,
``omniverse://localhost/NVIDIA/Materials/...``). :func:`local_path` answers such
a URL with a local file of the same path:

1. in a *mirror* of the server, if one is configured: a folder holding the
   server's top-level folders (``NVIDIA/``, ``Isaac/``, ``Projects/``, ...), named
   by the setting ``/graphsdg/assets/nucleusMirror`` or else the environment
   variable ``GRAPHSDG_NUCLEUS_MIRROR``; ``omniverse://<any host>/<path>`` is
   ``<mirror>/<path>``;
2. for ``/Isaac/...`` and ``/NVIDIA/...`` (with or without the versioned root
   ``/NVIDIA/Assets/Isaac/<version>`` in front), in the asset root that
   :func:`~graphsdg.assets.root.get_assets_root_path` gives: the built-in pack
   unless another local tree is configured (a root configured as a URL, such as
   ``omniverse://localhost/NVIDIA/Assets/Isaac/4.5``, is served by the pack).

Any other URL, or one whose file no local tree holds, raises
:class:`NucleusUnavailableError` naming it. :func:`resolve_asset_path` is the one
place graphsdg turns an asset path it is given into a file it can open: a URL
becomes its local file, anything else passes through unchanged.

Example:
    >>> from graphsdg.assets.nucleus import local_path
    >>> path = local_path("omniverse://localhost/NVIDIA/Assets/Isaac/4.5/Isaac/Environments/Simple_Warehouse/"
    ...                   "Props/SM_PaletteA_01.usd")
    >>> path.endswith("/pack/Isaac/Environments/Simple_Warehouse/Props/SM_PaletteA_01.usd")
    True
"""
from __future__ import annotations

import os
import posixpath
import re
from urllib.parse import unquote, urlsplit

from graphsdg.base import settings_store as settings
from graphsdg.assets.root import builtin_pack_root, get_assets_root_path

SCHEME = "omniverse"
NUCLEUS_MIRROR_SETTING = "/graphsdg/assets/nucleusMirror"
NUCLEUS_MIRROR_ENV = "GRAPHSDG_NUCLEUS_MIRROR"
# the top-level folders of Isaac's asset root: what the built-in pack (or a configured asset root) stands in for
ASSET_ROOT_FOLDERS = ("Isaac", "NVIDIA")
# a versioned asset root on a Nucleus server, e.g. /NVIDIA/Assets/Isaac/4.5, in front of /Isaac/... or /NVIDIA/...
_VERSIONED_ROOT = re.compile(r"^/NVIDIA/Assets/Isaac/\d+(?:\.\d+)*(?=/(?:Isaac|NVIDIA)(?:/|$)|/?$)")


class NucleusUnavailableError(FileNotFoundError):
    """An ``omniverse://`` URL that no local tree holds: there is no Nucleus server to ask."""


def is_nucleus_url(path: object) -> bool:
    """Whether ``path`` is an ``omniverse://`` URL (any case of the scheme)."""
    return isinstance(path, (str, os.PathLike)) and os.fspath(path)[:len(SCHEME) + 3].lower() == SCHEME + "://"


def url_path(url: str) -> str:
    """The server path of an ``omniverse://`` URL: percent-decoded, normalised, without host, query or fragment."""
    parts = urlsplit(url)
    path = posixpath.normpath("/" + unquote(parts.path).lstrip("/"))
    return "/" if path in ("/", "//") else path


def nucleus_mirror() -> tuple[str, str] | None:
    """The configured mirror folder and where it was configured (setting first, then environment), or None."""
    value = settings.get(NUCLEUS_MIRROR_SETTING)
    if value:
        return os.path.abspath(os.path.expanduser(os.fspath(value))), f"setting {NUCLEUS_MIRROR_SETTING}"
    value = os.environ.get(NUCLEUS_MIRROR_ENV)
    if value:
        return os.path.abspath(os.path.expanduser(value)), f"environment variable {NUCLEUS_MIRROR_ENV}"
    return None


def _asset_root_path(path: str) -> str | None:
    """``path`` relative to Isaac's asset root (``Isaac/...``, ``NVIDIA/...``), or None if it is not under one."""
    path = _VERSIONED_ROOT.sub("", path) or "/"
    if path == "/":
        return ""
    top = path.lstrip("/").split("/", 1)[0]
    return path.lstrip("/") if top in ASSET_ROOT_FOLDERS else None


def _local_asset_root() -> str | None:
    """The local folder standing in for Isaac's asset root: the configured one, or the built-in pack where the
    configured root is itself a URL (a Nucleus or S3 asset root that nothing here can reach)."""
    root = get_assets_root_path(skip_check=True)
    if root is not None and "://" in root:
        root = builtin_pack_root()
    if root is None or not os.path.isdir(root):
        return None
    return root


def find_local(url: str) -> str | None:
    """The local file or folder holding ``url``'s path, or None where no local tree has it.

    Raises:
        NucleusUnavailableError: a mirror is configured but is not a folder.
    """
    path = url_path(url)
    mirror = nucleus_mirror()
    if mirror is not None:
        folder, source = mirror
        if not os.path.isdir(folder):
            raise NucleusUnavailableError(f"cannot read {url!r}: the Nucleus mirror {folder!r} (from the {source}) "
                                          f"is not a folder")
        candidate = os.path.join(folder, path.lstrip("/"))
        if os.path.exists(candidate):
            return os.path.normpath(candidate)
    relative = _asset_root_path(path)
    root = _local_asset_root()
    if relative is not None and root is not None:
        candidate = os.path.join(root, relative) if relative else root
        if os.path.exists(candidate):
            return os.path.normpath(candidate)
    return None


def unavailable(url: str) -> NucleusUnavailableError:
    """The error for ``url``: which local trees were searched and how to point graphsdg at a local copy."""
    path = url_path(url)
    mirror = nucleus_mirror()
    searched = []
    if mirror is not None:
        searched.append(f"the Nucleus mirror {mirror[0]!r} (from the {mirror[1]}) has no {path.lstrip('/')!r}")
    relative = _asset_root_path(path)
    root = _local_asset_root()
    if relative is not None and root is not None:
        searched.append(f"the asset root {root!r} has no {relative!r}")
    elif relative is None:
        searched.append(f"the asset root (the built-in pack unless configured) stands in only for paths under "
                        f"{' and '.join('/' + f for f in ASSET_ROOT_FOLDERS)}")
    return NucleusUnavailableError(
        f"cannot read {url!r}: no Nucleus server is reachable here (graphsdg reads omniverse:// URLs from local "
        f"folders); {'; '.join(searched)}. To use a local copy of the server, set the environment variable "
        f"{NUCLEUS_MIRROR_ENV} (or the setting {NUCLEUS_MIRROR_SETTING}) to a folder holding its top-level folders "
        f"(NVIDIA/, Isaac/, ...); omniverse://<host>/<path> then reads <folder>/<path>")


def local_path(url: str | os.PathLike) -> str:
    """The local file or folder holding the ``omniverse://`` URL ``url``.

    Raises:
        NucleusUnavailableError: no local tree holds the URL's path (the message says
            how to configure a mirror), or ``url`` is not an ``omniverse://`` URL.
    """
    url = os.fspath(url)
    if not is_nucleus_url(url):
        raise NucleusUnavailableError(f"{url!r} is not an omniverse:// URL")
    found = find_local(url)
    if found is None:
        raise unavailable(url)
    return found


def writable_path(url: str | os.PathLike) -> str:
    """The local path a write to the ``omniverse://`` URL ``url`` goes to: its place in the configured mirror.

    Only a mirror takes writes (the asset root, the built-in pack above all, is
    read-only here); the path's folders are not created.

    Raises:
        NucleusUnavailableError: no mirror is configured (or it is not a folder).
    """
    url = os.fspath(url)
    if not is_nucleus_url(url):
        raise NucleusUnavailableError(f"{url!r} is not an omniverse:// URL")
    mirror = nucleus_mirror()
    if mirror is None:
        raise NucleusUnavailableError(
            f"cannot write {url!r}: no Nucleus server is reachable here and no local mirror is configured. Set the "
            f"environment variable {NUCLEUS_MIRROR_ENV} (or the setting {NUCLEUS_MIRROR_SETTING}) to a local folder; "
            f"omniverse://<host>/<path> is then written to <folder>/<path>")
    folder, source = mirror
    if not os.path.isdir(folder):
        raise NucleusUnavailableError(f"cannot write {url!r}: the Nucleus mirror {folder!r} (from the {source}) is "
                                      f"not a folder")
    return os.path.normpath(os.path.join(folder, url_path(url).lstrip("/")))


def resolve_asset_path(path: str | os.PathLike) -> str:
    """The path graphsdg opens for the asset path ``path``: a Nucleus URL's local file, else ``path`` unchanged.

    Raises:
        NucleusUnavailableError: ``path`` is an ``omniverse://`` URL no local tree holds.
    """
    path = os.fspath(path)
    return local_path(path) if is_nucleus_url(path) else path


__all__ = ["NUCLEUS_MIRROR_ENV", "NUCLEUS_MIRROR_SETTING", "NucleusUnavailableError", "find_local",
           "is_nucleus_url", "local_path", "nucleus_mirror", "resolve_asset_path", "unavailable", "url_path",
           "writable_path"]
