"""Finding asset files in a folder: USD files and texture sets. USD files for ``rep.utils.get_usd_files``, texture
sets grouped by suffix for ``rep.utils.get_files_group``.

Local folders are listed with :mod:`os`; an ``omniverse://`` URL lists the local folder holding it (the asset
pack or a Nucleus mirror) and names its files by URL; other URLs are not listed (nothing is fetched at run time)
and raise, naming the URL.

Example:
    >>> import os, tempfile
    >>> from graphsdg.io.file_search import get_usd_files
    >>> root = tempfile.mkdtemp()
    >>> for name in ("b.usda", "a.usd", "notes.txt"):
    ...     open(os.path.join(root, name), "w").close()
    >>> [os.path.basename(p) for p in get_usd_files(root)]
    ['a.usd', 'b.usda']
"""
from __future__ import annotations

import json
import os
import re
from pathlib import Path

from graphsdg.assets import nucleus

USD_FILE = re.compile(r"^.*\.(usd|usda|usdc|usdz)$", re.IGNORECASE)


def _local_folder(path: str, what: str) -> str:
    """``path`` as a local folder, or an error naming it (URLs are not listed, missing folders not guessed).

    An ``omniverse://`` URL is the local folder holding it (the asset pack or a configured Nucleus mirror).
    """
    text = os.fspath(path)
    if nucleus.is_nucleus_url(text):
        return nucleus.local_path(text)
    if "://" in text and not text.startswith("file://"):
        raise ValueError(f"{what}: {text!r} is a URL; graphsdg lists local folders only (nothing is fetched at run "
                         f"time): point it at a local copy")
    text = text[len("file://"):] if text.startswith("file://") else text
    if not os.path.isdir(text):
        raise FileNotFoundError(f"{what}: {text!r} is not a folder")
    return text


def get_usd_files(path: str, recursive: bool = False, path_filter: str | None = None) -> list[str]:
    """The USD files (``.usd``, ``.usda``, ``.usdc``, ``.usdz``) in folder ``path``, sorted.

    ``recursive`` also searches sub-folders; ``path_filter`` is a regular expression a file's path must
    contain (``re.search``). A path that is itself a USD file is returned as the one result.
    """
    text = os.fspath(path)
    if os.path.isfile(text) and USD_FILE.match(text):
        return [text] if path_filter is None or re.search(path_filter, text) else []
    folder = _local_folder(text, "get_usd_files")
    # A URL's files are named by URL too (as Replicator lists a Nucleus folder), so from_usd and the script's own
    # string handling see the paths they asked for.
    prefix = text.rstrip("/") if nucleus.is_nucleus_url(text) else folder.rstrip(os.sep).replace(os.sep, "/")
    found: list[str] = []
    for root, dirs, files in os.walk(folder):
        dirs.sort()
        relative_root = os.path.relpath(root, folder).replace(os.sep, "/")
        for name in sorted(files):
            full = f"{prefix}/{name}" if relative_root == "." else f"{prefix}/{relative_root}/{name}"
            if USD_FILE.match(name) and (path_filter is None or re.search(path_filter, full)):
                found.append(full)
        if not recursive:
            break
    return sorted(found)


def get_files_group(folder_path: str, file_suffixes: list[str] | None = None, ignore_case: bool = True,
                    file_type: str = "png") -> list[str]:
    """Files of type ``file_type`` in ``folder_path`` grouped by the stem before each of ``file_suffixes``.

    Each group is a JSON string ``{"<stem>": {"<suffix>": "<path>", ...}}`` (Replicator's format, fed to a
    ``texture_group`` argument); groups are sorted. ``wood_D.png`` and ``wood_N.png`` with suffixes
    ``["_D", "_N"]`` make one group ``wood``.
    """
    folder = _local_folder(folder_path, "get_files_group")
    if not file_suffixes:
        raise ValueError("get_files_group: file_suffixes is empty; give the suffixes that name each file of a "
                         "set, e.g. ['_D', '_N']")
    flags = re.IGNORECASE if ignore_case else 0
    extension = re.compile(rf"^.*\.({file_type})$", flags)
    names = sorted(n for n in os.listdir(folder) if extension.match(n) and os.path.isfile(os.path.join(folder, n)))
    groups: dict[str, dict[str, str]] = {}
    for suffix in file_suffixes:
        pattern = re.compile(rf"^(\w*)({re.escape(suffix)})$", flags)
        for name in names:
            match = pattern.fullmatch(name.rsplit(".", 1)[0])
            if match:
                groups.setdefault(match.group(1), {})[suffix] = Path(folder).joinpath(name).as_posix()
    return sorted(json.dumps({stem: files}) for stem, files in groups.items())


__all__ = ["get_usd_files", "get_files_group"]
