"""Isaac compat area: ``omni.client`` over local files, the asset pack and a Nucleus mirror.

Omniverse's client library reads and writes files by URL and reports each
outcome as a :class:`Result` code. graphsdg has no Nucleus server, so here:

* raw local paths and ``file:`` URLs are the local file system;
* ``omniverse://<host>/<path>`` reads from the configured Nucleus mirror, else
  (``/Isaac/...``, ``/NVIDIA/...``) from the asset root, the built-in pack by
  default (:mod:`graphsdg.assets.nucleus`); writes go to the mirror only. A URL
  that no local tree serves answers ``ERROR_NOT_FOUND`` where a tree is meant to
  hold it and ``ERROR_CONNECTION`` otherwise (there is no server to ask), and
  logs (logger ``carb``) why and how to configure a mirror;
* ``http(s)://`` and other schemes answer ``ERROR_NOT_SUPPORTED``: nothing is
  downloaded at run time.

The built-in pack is read-only (writes into it answer ``ERROR_ACCESS_DENIED``).
Each operation has its blocking form, ``<name>_async`` and
``<name>_with_callback`` (the callback runs before it returns, and a finished
:class:`Request` comes back). URL parsing is :mod:`graphsdg.compat.omni_client_urls`.

Example:
    >>> from graphsdg.compat import omni_client as client
    >>> result, entry = client.stat("omniverse://localhost/Isaac/Environments/Grid/default_environment.usd")
    >>> result == client.Result.OK and entry.flags & client.ItemFlags.READABLE_FILE > 0
    True
"""
from __future__ import annotations

import asyncio
import datetime
import enum
import functools
import hashlib
import logging
import os
import shutil
import types
from dataclasses import dataclass
from typing import Any, Callable

from graphsdg import __version__
from graphsdg.assets import nucleus
from graphsdg.assets.root import builtin_pack_root
from graphsdg.compat import omni_client_urls as urls
from graphsdg.compat.modules import CompatModule, CompatObject

log = logging.getLogger("carb")


class Result(enum.IntEnum):
    """omni.client.Result: the outcome of an operation."""

    OK = 0
    OK_LATEST = 1
    OK_NOT_YET_FOUND = 2
    ERROR = 3
    ERROR_CONNECTION = 4
    ERROR_NOT_SUPPORTED = 5
    ERROR_ACCESS_DENIED = 6
    ERROR_NOT_FOUND = 7
    ERROR_BAD_VERSION = 8
    ERROR_ALREADY_EXISTS = 9
    ERROR_SOURCE_IS_DEST = 10
    ERROR_ACCESS_LOST = 11
    ERROR_LOCKED = 12
    ERROR_BAD_REQUEST = 13
    ERROR_FOLDER_NOT_EMPTY = 14
    ERROR_WRONG_TYPE = 15
    ERROR_UNSUPPORTED_VERSION = 16


class ItemFlags(enum.IntFlag):
    """omni.client.ItemFlags: what an item is and what can be done with it (bits of ``ListEntry.flags``)."""

    READABLE_FILE = 1
    WRITEABLE_FILE = 2
    CAN_HAVE_CHILDREN = 4
    DOES_NOT_HAVE_CHILDREN = 8
    IS_MOUNT = 16
    IS_INSIDE_MOUNT = 32
    CAN_LIVE_UPDATE = 64
    IS_OMNI_OBJECT = 128
    IS_CHANNEL = 256
    IS_CHECKPOINTED = 512
    IS_DELETED = 1024


class AccessFlags(enum.IntFlag):
    """omni.client.AccessFlags: the caller's access to an item (bits of ``ListEntry.access``)."""

    READ = 1
    WRITE = 2
    ADMIN = 4


class CopyBehavior(enum.IntEnum):
    """omni.client.CopyBehavior: what a copy or move does where the destination exists."""

    ERROR_IF_EXISTS = 0
    OVERWRITE = 1


class ListIncludeOption(enum.IntEnum):
    """omni.client.ListIncludeOption: deleted items are never listed here (no soft delete on local files)."""

    NO_DELETED_FILES = 0
    INCLUDE_DELETED_FILES = 1
    ONLY_DELETED_FILES = 2


class Content(bytes):
    """omni.client.Content: a file's bytes (``memoryview(content).tobytes()`` works, as with Kit's buffer)."""


_EPOCH = datetime.datetime.fromtimestamp(0, tz=datetime.timezone.utc)


@dataclass(frozen=True)
class ListEntry:
    """omni.client.ListEntry: one item of a ``list`` or the item of a ``stat``."""

    relative_path: str
    access: int
    flags: int
    size: int
    modified_time: datetime.datetime
    created_time: datetime.datetime
    modified_by: str = ""
    created_by: str = ""
    version: str = ""
    hash: str = ""
    comment: str = ""
    deleted_by: str = ""
    deleted_time: datetime.datetime = _EPOCH
    locked_by: str = ""


@dataclass(frozen=True)
class WriteFileExInfo:
    """omni.client.WriteFileExInfo: what ``write_file_ex`` wrote (the content's SHA-256 as its hash)."""

    version: str = ""
    hash: str = ""


class Request(CompatObject):
    """omni.client.Request: a request object; every request here has finished when it is returned."""

    _compat_name = "omni.client.Request"
    _next_id = 0

    def __init__(self) -> None:
        Request._next_id += 1
        self.id = Request._next_id

    def is_finished(self) -> bool:
        return True

    def wait(self) -> None:
        """Returns at once: the request finished before it was returned."""

    def stop(self) -> None:
        """Nothing to stop: the request finished before it was returned."""

    def __enter__(self) -> "Request":
        return self

    def __exit__(self, *exc: object) -> None:
        return None


class Registration(CompatObject):
    """omni.client.Registration: what ``register_*_callback`` returns; dropping it ends the registration."""

    _compat_name = "omni.client.Registration"

    def __enter__(self) -> "Registration":
        return self

    def __exit__(self, *exc: object) -> None:
        return None


# ---- where a URL is on this machine -------------------------------------------------------------------------------
_explained: set[str] = set()


def _explain(url: str, message: str) -> None:
    if url not in _explained:   # once per URL: scripts poll stat() in loops
        _explained.add(url)
        log.warning(message)


def _pack_root() -> str:
    return os.path.realpath(builtin_pack_root())


def _in_pack(path: str) -> bool:
    real = os.path.realpath(path)
    return real == _pack_root() or real.startswith(_pack_root() + os.sep)


def _locate(url: str, write: bool = False) -> tuple[str | None, Result]:
    """The local path ``url`` reads from (or, ``write``, goes to) and OK, or None and the Result saying why not."""
    url = os.fspath(url)
    local = urls.local_file_path(url)
    if local is not None:
        if write and _in_pack(local):
            _explain(url, f"omni.client: {url!r} is inside graphsdg's built-in asset pack, which is read-only")
            return None, Result.ERROR_ACCESS_DENIED
        return local, Result.OK
    if nucleus.is_nucleus_url(url):
        try:
            if write:
                return nucleus.writable_path(url), Result.OK
            found = nucleus.find_local(url)
        except nucleus.NucleusUnavailableError as exc:
            _explain(url, f"omni.client: {exc}")
            return None, Result.ERROR_CONNECTION
        if found is not None:
            return found, Result.OK
        _explain(url, f"omni.client: {nucleus.unavailable(url)}")
        served = nucleus.nucleus_mirror() is not None or nucleus._asset_root_path(nucleus.url_path(url)) is not None
        return None, Result.ERROR_NOT_FOUND if served else Result.ERROR_CONNECTION
    _explain(url, f"omni.client: {url!r} is not read in graphsdg (no network access: nothing downloads at run "
                  f"time); use a local file or an omniverse:// URL served by a local mirror")
    return None, Result.ERROR_NOT_SUPPORTED


def _entry(path: str, name: str) -> ListEntry:
    info = os.stat(path)
    folder = os.path.isdir(path)
    writable = os.access(path, os.W_OK) and not _in_pack(path)
    flags = ItemFlags.CAN_HAVE_CHILDREN if folder else ItemFlags.READABLE_FILE | ItemFlags.DOES_NOT_HAVE_CHILDREN
    if writable and not folder:
        flags |= ItemFlags.WRITEABLE_FILE
    access = (AccessFlags.READ if os.access(path, os.R_OK) else 0) | (AccessFlags.WRITE if writable else 0)
    return ListEntry(relative_path=name, access=int(access), flags=int(flags), size=0 if folder else info.st_size,
                     modified_time=datetime.datetime.fromtimestamp(info.st_mtime, tz=datetime.timezone.utc),
                     created_time=datetime.datetime.fromtimestamp(info.st_ctime, tz=datetime.timezone.utc))


# ---- operations ---------------------------------------------------------------------------------------------------
def stat(url: str, include_deleted_option: ListIncludeOption = ListIncludeOption.NO_DELETED_FILES
         ) -> tuple[Result, ListEntry | None]:
    """The item at ``url``: ``(Result.OK, ListEntry)``, or ``(ERROR_NOT_FOUND, None)`` and the like."""
    path, result = _locate(url)
    if path is None:
        return result, None
    if not os.path.exists(path):
        return Result.ERROR_NOT_FOUND, None
    return Result.OK, _entry(path, os.path.basename(path.rstrip(os.sep)) or path)


def list(url: str, include_deleted_option: ListIncludeOption = ListIncludeOption.NO_DELETED_FILES  # noqa: A001
         ) -> tuple[Result, tuple[ListEntry, ...]]:
    """The items inside the folder ``url``, by name; a file has none (``OK`` and an empty tuple)."""
    path, result = _locate(url)
    if path is None:
        return result, ()
    if not os.path.exists(path):
        return Result.ERROR_NOT_FOUND, ()
    if not os.path.isdir(path):
        return Result.OK, ()
    return Result.OK, tuple(_entry(os.path.join(path, name), name) for name in sorted(os.listdir(path)))


def read_file(url: str) -> tuple[Result, str, Content]:
    """``(Result, version, content)`` of the file at ``url`` (version is empty: local files have none)."""
    path, result = _locate(url)
    if path is None:
        return result, "", Content()
    if not os.path.exists(path):
        return Result.ERROR_NOT_FOUND, "", Content()
    if os.path.isdir(path):
        return Result.ERROR_WRONG_TYPE, "", Content()
    with open(path, "rb") as f:
        return Result.OK, "", Content(f.read())


def write_file(url: str, content: Any, message: str = "") -> Result:
    """Write ``content`` (bytes-like, or str as UTF-8) to ``url``, making its folders."""
    return write_file_ex(url, content, message)[0]


def write_file_ex(url: str, content: Any, message: str = "", skip_checkpoint: bool = False
                  ) -> tuple[Result, WriteFileExInfo | None]:
    """As :func:`write_file`, also giving the written content's SHA-256 as its hash."""
    path, result = _locate(url, write=True)
    if path is None:
        return result, None
    data = content.encode("utf-8") if isinstance(content, str) else bytes(memoryview(content))
    if os.path.isdir(path):
        return Result.ERROR_WRONG_TYPE, None
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    temporary = f"{path}.graphsdg-partial"
    with open(temporary, "wb") as f:   # whole or not at all, as a server-side write
        f.write(data)
    os.replace(temporary, path)
    return Result.OK, WriteFileExInfo(hash=hashlib.sha256(data).hexdigest())


def create_folder(url: str) -> Result:
    """Make the folder ``url`` (and its parents); ``ERROR_ALREADY_EXISTS`` where something is there."""
    path, result = _locate(url, write=True)
    if path is None:
        return result
    if os.path.exists(path):
        return Result.ERROR_ALREADY_EXISTS
    os.makedirs(path)
    return Result.OK


def _delete(url: str, single: bool) -> Result:
    path, result = _locate(url, write=True)
    if path is None:
        return result
    if not os.path.lexists(path):
        return Result.ERROR_NOT_FOUND
    if os.path.isdir(path) and not os.path.islink(path):
        if single and os.listdir(path):
            return Result.ERROR_FOLDER_NOT_EMPTY
        shutil.rmtree(path)
    else:
        os.remove(path)
    return Result.OK


def delete(url: str) -> Result:
    """Delete the file or folder (with everything in it) at ``url``."""
    return _delete(url, single=False)


def delete_single(url: str) -> Result:
    """Delete the file or *empty* folder at ``url`` (``ERROR_FOLDER_NOT_EMPTY`` otherwise)."""
    return _delete(url, single=True)


def _copy(src_url: str, dst_url: str, behavior: CopyBehavior, kind: str | None) -> Result:
    src, result = _locate(src_url)
    if src is None:
        return result
    dst, result = _locate(dst_url, write=True)
    if dst is None:
        return result
    if not os.path.exists(src):
        return Result.ERROR_NOT_FOUND
    folder = os.path.isdir(src)
    if (kind == "file" and folder) or (kind == "folder" and not folder):
        return Result.ERROR_WRONG_TYPE
    real_src, real_dst = os.path.realpath(src), os.path.realpath(dst)
    if real_dst == real_src or (folder and real_dst.startswith(real_src + os.sep)):
        return Result.ERROR_SOURCE_IS_DEST
    if os.path.exists(dst):
        if behavior != CopyBehavior.OVERWRITE or os.path.isdir(dst) != folder:
            return Result.ERROR_ALREADY_EXISTS
    os.makedirs(os.path.dirname(dst) or ".", exist_ok=True)
    if folder:
        shutil.copytree(src, dst, dirs_exist_ok=True)
    else:
        shutil.copyfile(src, dst)
    return Result.OK


def copy(src_url: str, dst_url: str, behavior: CopyBehavior = CopyBehavior.ERROR_IF_EXISTS,
         message: str = "") -> Result:
    """Copy the file or folder ``src_url`` to ``dst_url`` (folders made as needed)."""
    return _copy(src_url, dst_url, behavior, None)


def copy_file(src_url: str, dst_url: str, behavior: CopyBehavior = CopyBehavior.ERROR_IF_EXISTS,
              message: str = "") -> Result:
    """:func:`copy` of a file (``ERROR_WRONG_TYPE`` for a folder)."""
    return _copy(src_url, dst_url, behavior, "file")


def copy_folder(src_url: str, dst_url: str, behavior: CopyBehavior = CopyBehavior.ERROR_IF_EXISTS,
                message: str = "") -> Result:
    """:func:`copy` of a folder (``ERROR_WRONG_TYPE`` for a file)."""
    return _copy(src_url, dst_url, behavior, "folder")


def move(src_url: str, dst_url: str, behavior: CopyBehavior = CopyBehavior.ERROR_IF_EXISTS,
         message: str = "") -> tuple[Result, bool]:
    """Move ``src_url`` to ``dst_url``: ``(Result, copied)``, ``copied`` True where it took a copy and a delete."""
    src, result = _locate(src_url, write=True)
    if src is None:
        return result, False
    dst, result = _locate(dst_url, write=True)
    if dst is None:
        return result, False
    if not os.path.exists(src):
        return Result.ERROR_NOT_FOUND, False
    if os.path.exists(dst) and behavior != CopyBehavior.OVERWRITE:
        return Result.ERROR_ALREADY_EXISTS, False
    os.makedirs(os.path.dirname(dst) or ".", exist_ok=True)
    copied = os.stat(src).st_dev != os.stat(os.path.dirname(dst) or ".").st_dev   # another file system: copy+delete
    if os.path.isdir(dst) and not os.path.isdir(src):
        return Result.ERROR_ALREADY_EXISTS, False
    if os.path.exists(dst):
        _delete(dst, single=False)
    shutil.move(src, dst)
    return Result.OK, copied


def get_local_file(url: str, download: bool = True) -> tuple[Result, str]:
    """The local file holding ``url``: ``(Result.OK, path)`` (no cache: every served file is local already)."""
    path, result = _locate(url)
    if path is None:
        return result, ""
    if not os.path.exists(path):
        return Result.ERROR_NOT_FOUND, ""
    return Result.OK, path


def resolve(url: str, search_urls: Any) -> tuple[Result, ListEntry | None, str]:
    """The first of ``url`` itself and ``url`` combined with each search URL that exists: ``(Result, entry, url)``."""
    for candidate in [url] + [urls.combine_urls(s.rstrip("/") + "/", url) for s in search_urls or ()]:
        result, entry = stat(candidate)
        if result == Result.OK:
            return result, entry, candidate
    return Result.ERROR_NOT_FOUND, None, ""


def get_result_string(result: Result) -> str:
    """A readable name of ``result`` (``"OK"``, ``"ERROR_NOT_FOUND"``, ...)."""
    return Result(result).name


def get_version() -> str:
    """The client library's version: graphsdg's, as it stands in for the library here."""
    return f"graphsdg {__version__} (local files, no Nucleus)"


_settings: dict[str, Any] = {}


def set_hang_detection_time_ms(milliseconds: int) -> None:
    """Recorded only: local file operations do not hang on a network."""
    _settings["hang_detection_time_ms"] = int(milliseconds)


def initialize() -> bool:
    """Nothing to start: True."""
    return True


def shutdown() -> None:
    """Nothing to stop."""


def sign_out(url: str) -> None:
    """No server connections to close."""


def reconnect(url: str) -> None:
    """No server connections to re-open."""


def register_authentication_callback(callback: Callable) -> Registration:
    """Kept for scripts that register one: no server ever asks for credentials here."""
    return Registration()


# ---- async and callback forms -------------------------------------------------------------------------------------
def _async_form(function: Callable) -> Callable:
    @functools.wraps(function)
    async def run(*args: Any, **kwargs: Any) -> Any:
        await asyncio.sleep(0)   # yield once, as a request that completes on a later loop turn
        return function(*args, **kwargs)
    run.__name__ = f"{function.__name__}_async"
    run.__doc__ = f"Awaitable form of :func:`{function.__name__}`."
    return run


def _callback_form(function: Callable) -> Callable:
    def run(*args: Any, callback: Callable, **kwargs: Any) -> Request:
        result = function(*args, **kwargs)
        callback(*result) if isinstance(result, tuple) else callback(result)
        return Request()
    run.__name__ = f"{function.__name__}_with_callback"
    run.__doc__ = f":func:`{function.__name__}` calling ``callback`` with its outcome; returns a finished Request."
    return run


_OPERATIONS = (stat, list, read_file, write_file, write_file_ex, create_folder, delete, delete_single, copy,
               copy_file, copy_folder, move, get_local_file, resolve)
_FORMS = {f"{op.__name__}_async": _async_form(op) for op in _OPERATIONS}
_FORMS.update({f"{op.__name__}_with_callback": _callback_form(op) for op in _OPERATIONS})


def modules() -> list[types.ModuleType]:
    """``omni.client`` (and ``omni.client.impl`` for scripts that reach for it)."""
    names: dict[str, Any] = {op.__name__: op for op in _OPERATIONS}
    names.update(_FORMS)
    names.update(Result=Result, ItemFlags=ItemFlags, AccessFlags=AccessFlags, CopyBehavior=CopyBehavior,
                 ListIncludeOption=ListIncludeOption, Content=Content, ListEntry=ListEntry, Url=urls.Url,
                 WriteFileExInfo=WriteFileExInfo, Request=Request, Registration=Registration,
                 get_result_string=get_result_string, get_version=get_version,
                 set_hang_detection_time_ms=set_hang_detection_time_ms, initialize=initialize, shutdown=shutdown,
                 sign_out=sign_out, reconnect=reconnect,
                 register_authentication_callback=register_authentication_callback,
                 break_url=urls.break_url, break_url_reference=urls.break_url_reference, make_url=urls.make_url,
                 make_file_url=urls.make_file_url, make_relative_url=urls.make_relative_url,
                 normalize_url=urls.normalize_url, combine_urls=urls.combine_urls,
                 combine_with_base_url=urls.combine_with_base_url, push_base_url=urls.push_base_url,
                 pop_base_url=urls.pop_base_url, get_base_url=urls.get_base_url)
    return [CompatModule("omni.client", hint="Live sessions, checkpoints, ACLs, channels and server groups need a "
                         "Nucleus server, which graphsdg does not have.", **names)]


EXTENSIONS = {"omni.client": ("omni.client",)}
