"""Isaac compat area: ``isaacsim.storage.native`` (and its 4.x home ``isaacsim.core.utils.nucleus``).

Isaac's storage helpers (asset roots, "servers", path utilities, USD reference
checks) by their documented contracts, over :mod:`graphsdg.compat.omni_client`:
local files, the asset pack and a Nucleus mirror stand in for the Nucleus server.
A "server" here is a root URL or folder whose paths ``omni.client`` can reach
(``omniverse://localhost`` reaches the asset pack's ``/Isaac`` and ``/NVIDIA``).

* asset roots: ``get_assets_root_path[_async]`` (Isaac Sim 6's: the value of the
  setting ``/persistent/isaac/asset_root/default``, checked, raising ``RuntimeError``
  where unset or unreachable; installing compat mode gives the setting Isaac's
  ``ISAACSIM_ASSET_ROOT`` environment variable, as Isaac's extension does at startup,
  else graphsdg's root: the built-in pack), ``get_full_asset_path[_async]``, ``get_server_path[_async]``,
  ``get_url_root``, ``verify_asset_root_path``, ``check_server[_async]``,
  ``build_server_list``, and the deprecated finders (which answer None / False
  and warn, as in Isaac);
* files: ``is_file[_async]``, ``is_dir[_async]``, ``list_folder``,
  ``recursive_list_folder``, ``create_folder``, ``delete_folder``,
  ``download_assets_async`` (a copy from a reachable source: nothing downloads),
  ``path_exists``, ``resolve_asset_path[_async]``, ``find_files_recursive``,
  ``find_filtered_files[_async]``;
* paths: ``path_join``, ``path_relative``, ``path_dirname``, ``is_local_path``,
  ``is_absolute_path``, ``is_valid_usd_file``, ``is_mdl_file``, ``is_path_external``;
* USD: ``get_stage_references``, ``find_absolute_paths_in_usds``,
  ``find_external_references``, ``count_asset_references``,
  ``find_missing_references``, ``layer_has_missing_references``,
  ``prim_spec_has_missing_references``, ``prim_has_missing_references``.
"""
from __future__ import annotations

import asyncio
import json
import logging
import os
import re
import types
from collections import namedtuple
from typing import Any, Callable, Iterable
from urllib.parse import urlparse, urlunparse

from pxr import Sdf, Usd, UsdUtils

from graphsdg.base import settings_store as settings
from graphsdg.assets import root as asset_root
from graphsdg.compat import omni_client as client
from graphsdg.compat.modules import CompatModule

log = logging.getLogger("carb")
DEFAULT_ASSET_ROOT_PATH_SETTING = asset_root.ASSETS_ROOT_SETTING
DEFAULT_ASSET_ROOT_TIMEOUT_SETTING = "/persistent/isaac/asset_root/timeout"
ASSET_ROOT_ENV_VAR = "ISAACSIM_ASSET_ROOT"
_URL_SCHEMES = ("omniverse://", "https://", "http://", "ftp://", "sftp://")
_USD_EXTENSIONS = (".usd", ".usda", ".usdc", ".usdz")


class Version(namedtuple("Version", "major minor patch")):
    """A ``major.minor.patch`` version parsed from a string (``Version("4.5.0")``), ordered as a tuple."""

    def __new__(cls, s: str) -> "Version":
        return super().__new__(cls, *map(int, str(s).strip().split(".")))

    def __repr__(self) -> str:
        return ".".join(map(str, self))


# ---- paths --------------------------------------------------------------------------------------------------------
def path_join(base: str, name: str) -> str:
    """``base`` joined with ``name``; for URLs with ``/``, ``./`` dropped and each ``../`` climbing one level."""
    if "://" not in base:
        return os.path.join(base, name)
    name = name.replace("\\", "/")
    name = name[2:] if name.startswith("./") else name
    while name.startswith("../"):
        base, name = base.rsplit("/", 1)[0], name[3:]
    return base.rstrip("/") + "/" + name


def is_local_path(path: str) -> bool:
    """Whether ``path`` is on this machine (not an ``omniverse://``, ``http(s)://``, ``(s)ftp://`` URL)."""
    return not path or not path.strip().startswith(_URL_SCHEMES)


def is_absolute_path(path: str) -> bool:
    """Whether ``path`` is absolute: an ``omniverse://``, ``file://``, ``http(s)://`` URL or an absolute path."""
    return path.lower().startswith(("omniverse://", "file://", "http://", "https://")) or os.path.isabs(path)


def is_valid_usd_file(item: str, excludes: Iterable[str]) -> bool:
    """Whether ``item`` ends in a USD extension and contains none of ``excludes``."""
    return not any(e in item for e in excludes) and os.path.splitext(item)[1] in _USD_EXTENSIONS


def is_mdl_file(item: str) -> bool:
    """Whether ``item`` is an ``.mdl`` file name."""
    return os.path.splitext(item)[1] == ".mdl"


def is_path_external(path: str, base_path: str) -> bool:
    """Whether ``path`` lies outside ``base_path`` (does not contain it)."""
    return base_path not in path


def path_relative(path: str, start: str) -> str:
    """``os.path.relpath`` for paths and URLs (the same scheme and host, else ``ValueError``)."""
    start = start.rstrip("/\\")
    parsed_path, parsed_start = urlparse(path), urlparse(start)
    if parsed_path.scheme and parsed_path.netloc:
        if (parsed_path.scheme, parsed_path.netloc) != (parsed_start.scheme, parsed_start.netloc):
            raise ValueError(f"path_relative: {path!r} and {start!r} differ in URL scheme or host")
        return os.path.relpath(parsed_path.path, parsed_start.path)
    return os.path.relpath(os.path.normpath(path), os.path.normpath(start))


def path_dirname(path: str) -> str:
    """The folder of ``path`` (a path or URL), ending in a separator."""
    parsed = urlparse(path)
    if parsed.scheme and parsed.netloc:
        folder = os.path.dirname(parsed.path)
        return urlunparse((parsed.scheme, parsed.netloc, folder if folder.endswith("/") else folder + "/", "", "",
                           ""))
    return os.path.dirname(os.path.normpath(path)) + os.sep


def get_url_root(url: str) -> str:
    """The ``scheme://host`` of an ``omniverse`` or ``http(s)`` URL (``RuntimeError`` for anything else)."""
    parsed = urlparse(url)
    if parsed.scheme not in ("omniverse", "http", "https"):
        raise RuntimeError(f"get_url_root: {url!r} is not an omniverse:// or http(s):// URL")
    return f"{parsed.scheme}://{parsed.netloc}"


# ---- files --------------------------------------------------------------------------------------------------------
def is_file(path: str) -> bool:
    """Whether ``path`` is a file (``Exception`` naming it when it cannot be reached)."""
    result, entry = client.stat(path)
    if result != client.Result.OK:
        raise Exception(f"Failed to determine if {path} is a file: {result}")
    return not entry.flags & client.ItemFlags.CAN_HAVE_CHILDREN


def is_dir(path: str) -> bool:
    """Whether ``path`` is a folder with something in it, as Isaac answers (``Exception`` when unreachable)."""
    result, entries = client.list(path)
    if result != client.Result.OK:
        raise Exception(f"Failed to determine if {path} is a folder: {result}")
    return len(entries) > 0


async def is_file_async(path: str) -> bool:
    """Awaitable :func:`is_file`."""
    return is_file(path)


async def is_dir_async(path: str) -> bool:
    """Awaitable :func:`is_dir`."""
    return is_dir(path)


async def list_folder(path: str) -> tuple[list[str], list[str]]:
    """``(files, folders)`` directly inside ``path``, as full URLs or paths (folders ending in ``/``)."""
    result, entries = client.list(path)
    if result != client.Result.OK:
        raise Exception(f"Failed to list entries for {path}: {result}")
    files, folders = [], []
    for entry in entries:
        full = client.urls.combine_urls(path if path.endswith("/") else path + "/", entry.relative_path)
        (folders.append(full + "/") if entry.flags & client.ItemFlags.CAN_HAVE_CHILDREN else files.append(full))
    return files, folders


async def recursive_list_folder(path: str) -> list[str]:
    """Every file below ``path``."""
    files, folders = await list_folder(path if path.endswith("/") else path + "/")
    for found in await asyncio.gather(*(recursive_list_folder(folder) for folder in folders)):
        files.extend(found)
    return files


def create_folder(server: str, path: str) -> bool:
    """Make the folder ``server + path``; True when it was made."""
    ok = client.create_folder(f"{server}{path}") == client.Result.OK
    (log.info if ok else log.warning)(f"{'created' if ok else 'could not create'} folder {path} on {server}")
    return ok


def delete_folder(server: str, path: str) -> bool:
    """Delete the folder ``server + path`` and everything in it; True when it was deleted."""
    ok = client.delete(f"{server}{path}") == client.Result.OK
    (log.info if ok else log.warning)(f"{'deleted' if ok else 'could not delete'} folder {path} on {server}")
    return ok


def check_server(server: str, path: str, timeout: float = 10.0) -> bool:
    """Whether ``server + path`` can be reached."""
    return client.stat(f"{server}{path}")[0] == client.Result.OK


async def check_server_async(server: str, path: str, timeout: float = 10.0) -> bool:
    """Awaitable :func:`check_server` (no retries needed: nothing here times out)."""
    return check_server(server, path, timeout)


async def path_exists(path: str) -> bool:
    """Whether ``path`` (a path or URL) can be reached."""
    return client.stat(path)[0] == client.Result.OK


async def download_assets_async(src: str, dst: str, progress_callback: Callable[[int, int], Any],
                                concurrency: int = 10, copy_behaviour: client.CopyBehavior =
                                client.CopyBehavior.OVERWRITE, copy_after_delete: bool = True,
                                timeout: float = 300.0) -> client.Result:
    """Copy the file or tree ``src`` to ``dst`` file by file, calling ``progress_callback(done, total)``.

    The source must be reachable here (a local tree, the asset pack, a mirror):
    nothing is downloaded. Returns ``Result.OK``, or the first failure's code.
    """
    if copy_after_delete and check_server(dst, ""):
        delete_folder(dst, "")
    if is_file(src):
        root, paths = os.path.dirname(src), [src]
    else:
        root, paths = src, await recursive_list_folder(src)
    result = client.Result.ERROR_NOT_FOUND if not paths else client.Result.OK
    for count, path in enumerate(sorted(paths), start=1):
        relative = path[len(root):].lstrip("/")
        result = client.copy(path, f"{dst.rstrip('/')}/{relative}", copy_behaviour)
        if result != client.Result.OK:
            log.warning(f"download_assets_async: could not copy {path} to {dst}: {result.name}")
            return client.Result.ERROR_ACCESS_LOST
        progress_callback(count, len(paths))
    return result


def find_files_recursive(abs_path: list[str], filter_fn: Callable[[str], bool] = lambda a: True) -> list[str]:
    """Every file below the given folders whose name ``filter_fn`` accepts."""
    files, folders = [], list(abs_path)
    while folders:
        path = folders.pop()
        result, entries = client.list(path)
        if result != client.Result.OK:
            continue
        for entry in entries:
            full = path_join(path, entry.relative_path)
            if entry.flags & client.ItemFlags.CAN_HAVE_CHILDREN:
                folders.append(full)
            elif filter_fn(entry.relative_path):
                files.append(full)
    return files


def find_filtered_files(abs_paths: list[str], max_depth: int | None = None,
                        filepath_excludes: list[str] | None = None, filter_patterns: list[str] | None = None,
                        match_all: bool = False) -> set[str]:
    """USD files below ``abs_paths`` (to ``max_depth`` folders down; 0: those folders only), without
    ``filepath_excludes`` substrings, matching any (or, ``match_all``, every) regular expression of
    ``filter_patterns`` on the full path."""
    excludes = filepath_excludes or []
    patterns = []
    for pattern in filter_patterns or []:
        try:
            patterns.append(re.compile(pattern))
        except re.error:
            log.warning(f"find_filtered_files: invalid regex pattern {pattern!r} ignored")
    found: set[str] = set()
    folders = [(path, 0) for path in abs_paths]
    while folders:
        path, depth = folders.pop()
        result, entries = client.list(path)
        if result != client.Result.OK:
            log.warning(f"find_filtered_files: could not list {path!r}: {result.name}")
            continue
        for entry in entries:
            full = path_join(path, entry.relative_path)
            if entry.flags & client.ItemFlags.CAN_HAVE_CHILDREN:
                if max_depth is None or depth < max_depth:
                    folders.append((full, depth + 1))
            elif is_valid_usd_file(full, excludes) and (
                    not patterns or (all if match_all else any)(p.search(full) for p in patterns)):
                found.add(full)
    return found


async def find_filtered_files_async(root_path: str, filter_patterns: list[str] | None = None,
                                    match_all: bool = False, filepath_excludes: list[str] | None = None,
                                    max_depth: int | None = None) -> set[str]:
    """Awaitable :func:`find_filtered_files` of one root, run on a worker thread."""
    return await asyncio.get_running_loop().run_in_executor(
        None, find_filtered_files, [root_path], max_depth, filepath_excludes, filter_patterns, match_all)


# ---- asset roots and servers --------------------------------------------------------------------------------------
# the Isaac Sim release compat mode follows: an asset tree's version.txt must match its major.minor
ISAAC_SIM_VERSION = "6.0.1"


def get_assets_root_path(*, skip_check: bool = False) -> str:
    """The asset root setting's value, checked (unless ``skip_check``) to hold ``/Isaac`` and ``/NVIDIA``.

    As Isaac Sim 6: a setting set to nothing raises ``RuntimeError`` (``... setting is not set``), a root
    without those folders raises ``RuntimeError`` (``Could not find assets root folder: ...``). Never set
    (graphsdg's settings reset), it is graphsdg's own root (:mod:`graphsdg.assets.root`: the built-in pack
    unless ``GRAPHSDG_ASSETS_ROOT`` names another tree); :func:`install` writes that into the setting, as
    Kit's configuration gives the setting its default.
    """
    value = settings.get(DEFAULT_ASSET_ROOT_PATH_SETTING)
    if value is None:
        value = asset_root.get_assets_root_path(skip_check=True)
    if not value:
        raise RuntimeError(f"The '{DEFAULT_ASSET_ROOT_PATH_SETTING}' setting is not set")
    value = str(value)
    if skip_check or (check_server(value, "/Isaac") and check_server(value, "/NVIDIA")):
        return value
    raise RuntimeError(f"Could not find assets root folder: {value} (it holds no /Isaac and /NVIDIA folders that "
                       f"graphsdg can read; see docs/assets.md)")


async def get_assets_root_path_async(*, skip_check: bool = False) -> str:
    """Awaitable :func:`get_assets_root_path`."""
    return get_assets_root_path(skip_check=skip_check)


def build_server_list() -> list[str]:
    """The servers of the setting ``/persistent/app/omniverse/mountedDrives`` (a name -> URL mapping or its JSON)."""
    drives = settings.get("/persistent/app/omniverse/mountedDrives")
    if isinstance(drives, str):
        drives = json.loads(drives) if drives.strip() else {}
    return [str(url) for url in (drives or {}).values()]


def get_full_asset_path(path: str) -> str:
    """``path`` under the asset root, else under the first mounted server that has it (``RuntimeError`` if none)."""
    for root in [asset_root.get_assets_root_path(skip_check=True)] + build_server_list():
        if root and check_server(root, path):
            return root + path
    raise RuntimeError(f"Could not find assets path: {path} (searched the asset root "
                       f"{asset_root.get_assets_root_path(skip_check=True)!r} and the mounted drives "
                       f"{build_server_list()})")


async def get_full_asset_path_async(path: str) -> str:
    """Awaitable :func:`get_full_asset_path`."""
    return get_full_asset_path(path)


def get_server_path(suffix: str = "") -> str:
    """The server (``scheme://host``, or the asset root folder) of the asset root, if it has ``suffix``."""
    root = settings.get(DEFAULT_ASSET_ROOT_PATH_SETTING) or asset_root.get_assets_root_path(skip_check=True) or ""
    server = get_url_root(root) if "://" in root else root
    if server and check_server(server, suffix):
        return server
    raise RuntimeError(f"Could not find Nucleus server with {suffix} folder (asset root {root!r})")


async def get_server_path_async(suffix: str = "") -> str:
    """Awaitable :func:`get_server_path`."""
    return get_server_path(suffix)


def verify_asset_root_path(path: str) -> tuple[client.Result, Version | str]:
    """``(Result.OK, version)`` when ``path/version.txt`` names a release of the Isaac Sim line compat mode follows;
    ``(ERROR_NOT_FOUND, "")`` without a readable version file, ``(ERROR_BAD_VERSION, version)`` for another line."""
    result, _, content = client.read_file(client.urls.combine_urls(path.rstrip("/") + "/", "version.txt"))
    try:
        version = Version(bytes(content).decode()) if result == client.Result.OK else None
    except (ValueError, UnicodeDecodeError):
        version = None
    if version is None:
        return client.Result.ERROR_NOT_FOUND, ""
    if version[:2] != Version(ISAAC_SIM_VERSION)[:2]:
        return client.Result.ERROR_BAD_VERSION, version
    return client.Result.OK, version


def find_nucleus_server(suffix: str) -> tuple[bool, str]:
    """Deprecated in Isaac (use :func:`get_assets_root_path`): warns and answers ``(False, "")``."""
    log.warning("find_nucleus_server() is deprecated. Use get_assets_root_path().")
    return False, ""


def get_nvidia_asset_root_path() -> None:
    """Deprecated in Isaac (use :func:`get_assets_root_path`): warns and answers None."""
    log.warning("get_nvidia_asset_root_path() has been deprecated. Use get_assets_root_path().")


def get_isaac_asset_root_path() -> None:
    """Deprecated in Isaac (use :func:`get_assets_root_path`): warns and answers None."""
    log.warning("get_isaac_asset_root_path() has been deprecated. Use get_assets_root_path().")


def get_assets_server() -> None:
    """Deprecated in Isaac (use :func:`get_server_path`): warns and answers None."""
    log.warning("get_assets_server() is deprecated. Use get_server_path().")


def resolve_asset_path(original_path: str) -> str | None:
    """``original_path`` where it exists, else the asset root joined with it where that exists, else None."""
    if client.stat(original_path)[0] == client.Result.OK:
        return original_path
    try:
        root = get_assets_root_path()
    except RuntimeError as exc:
        log.warning(f"resolve_asset_path: could not get the asset root: {exc}")
        return None
    if root:
        alternate = root + original_path if original_path.startswith("/") else root + "/" + original_path
        if client.stat(alternate)[0] == client.Result.OK:
            return alternate
    return None


async def resolve_asset_path_async(original_path: str) -> str | None:
    """Awaitable :func:`resolve_asset_path`."""
    return resolve_asset_path(original_path)


# ---- USD references -----------------------------------------------------------------------------------------------
def _local(path: str) -> str:
    found, result = client._locate(path)
    if found is None:
        raise FileNotFoundError(f"{path!r} cannot be read here ({result.name})")
    return found


def get_stage_references(stage_path: str, resolve_relatives: bool = True) -> list[str]:
    """Every asset path the USD file ``stage_path`` and the layers it brings in name (references, payloads,
    sublayers, asset attributes), as authored; without ``resolve_relatives``, those layers' identifiers. Sorted."""
    layers, _, _ = UsdUtils.ComputeAllDependencies(_local(stage_path))
    if not resolve_relatives:
        return sorted({layer.identifier for layer in layers})
    paths: set[str] = set()

    def collect(path: str) -> str:
        paths.add(path)
        return path
    for layer in layers:
        dirty = layer.dirty
        UsdUtils.ModifyAssetPaths(layer, collect)
        if not dirty and layer.dirty:   # nothing changed: keep the layer clean for a later save
            layer.Reload()
    paths.discard("")
    return sorted(paths)


def _usd_files(base_path: str) -> list[str]:
    return sorted(find_files_recursive([base_path], lambda item: is_valid_usd_file(item, [])))


async def find_absolute_paths_in_usds(base_path: str) -> dict[str, list[str]]:
    """USD files below ``base_path`` -> the absolute asset paths each names (files naming none are left out)."""
    found = {}
    for item in _usd_files(base_path):
        absolute = [p for p in get_stage_references(item) if is_absolute_path(p)]
        if absolute:
            found[item] = absolute
    return found


async def find_external_references(base_path: str) -> dict[str, list[str]]:
    """USD files below ``base_path`` -> the layers they bring in from outside ``base_path``."""
    found = {}
    for item in _usd_files(base_path):
        external = [p for p in get_stage_references(item, resolve_relatives=False) if is_path_external(p, base_path)]
        if external:
            found[item] = external
    return found


async def count_asset_references(base_path: str) -> dict[str, int]:
    """Every file below ``base_path`` -> how many USD files there name it, fewest first."""
    counts = dict.fromkeys(sorted(find_files_recursive([base_path])), 0)
    for item in counts:
        if not is_valid_usd_file(item, []):
            continue
        for path in get_stage_references(item):
            name = os.path.normpath(path_join(os.path.dirname(item), path)) if "://" not in item else \
                path_join(os.path.dirname(item), path)
            if name in counts:
                counts[name] += 1
    return dict(sorted(counts.items(), key=lambda kv: kv[1]))


def find_missing_references(base_path: str) -> None:
    """Print each USD file below ``base_path`` that names assets which do not resolve, with those paths."""
    for item in _usd_files(base_path):
        _, _, unresolved = UsdUtils.ComputeAllDependencies(_local(item))
        if unresolved:
            print(item, list(unresolved))


def layer_has_missing_references(layer_identifier: str) -> bool:
    """Whether ``layer_identifier`` or a layer it brings in (transitively) cannot be opened."""
    queue, seen = [layer_identifier], set()
    while queue:
        identifier = queue.pop(0)
        if identifier in seen:
            continue
        seen.add(identifier)
        try:
            layer = Sdf.Layer.FindOrOpen(_local(identifier) if "://" in identifier else identifier)
        except Exception:   # pxr's parse errors and unreachable URLs alike: the layer is missing
            layer = None
        if layer is None:
            return True
        queue += [layer.ComputeAbsolutePath(p) for p in layer.GetCompositionAssetDependencies() if p]
    return False


def prim_spec_has_missing_references(prim_spec: Sdf.PrimSpec) -> bool:
    """Whether a USD file ``prim_spec`` references is missing or misses a layer of its own."""
    for item in prim_spec.referenceList.GetAddedOrExplicitItems():
        if item.assetPath and os.path.splitext(item.assetPath.split("?")[0])[1] in _USD_EXTENSIONS:
            if layer_has_missing_references(prim_spec.layer.ComputeAbsolutePath(item.assetPath)):
                return True
    return False


def prim_has_missing_references(prim: Usd.Prim) -> bool:
    """Whether any spec of ``prim`` references a USD file that is missing (or misses layers)."""
    return any(prim_spec_has_missing_references(spec) for spec in prim.GetPrimStack())


# ---- the modules --------------------------------------------------------------------------------------------------
_NUCLEUS = ["Version", "get_url_root", "create_folder", "delete_folder", "download_assets_async", "check_server",
            "check_server_async", "build_server_list", "find_nucleus_server", "get_server_path",
            "get_server_path_async", "verify_asset_root_path", "get_full_asset_path", "get_full_asset_path_async",
            "get_nvidia_asset_root_path", "get_isaac_asset_root_path", "get_assets_root_path",
            "get_assets_root_path_async", "get_assets_server", "is_dir_async", "is_dir", "is_file_async", "is_file",
            "recursive_list_folder", "list_folder"]
_FILE_UTILS = ["path_join", "is_local_path", "find_files_recursive", "find_filtered_files", "get_stage_references",
               "is_absolute_path", "is_valid_usd_file", "is_mdl_file", "find_absolute_paths_in_usds",
               "is_path_external", "find_external_references", "count_asset_references", "find_missing_references",
               "path_exists", "layer_has_missing_references", "prim_spec_has_missing_references",
               "prim_has_missing_references", "path_relative", "path_dirname", "resolve_asset_path_async",
               "resolve_asset_path", "find_filtered_files_async"]
_CONSTANTS = {"DEFAULT_ASSET_ROOT_PATH_SETTING": DEFAULT_ASSET_ROOT_PATH_SETTING,
              "DEFAULT_ASSET_ROOT_TIMEOUT_SETTING": DEFAULT_ASSET_ROOT_TIMEOUT_SETTING}


def modules() -> list[types.ModuleType]:
    """``isaacsim.storage.native`` (with its ``nucleus`` submodule) and ``isaacsim.core.utils.nucleus``."""
    here = globals()
    every = {name: here[name] for name in _NUCLEUS + _FILE_UTILS}
    native = CompatModule("isaacsim.storage.native", __all__=list(every), **every, **_CONSTANTS,
                          ASSET_ROOT_ENV_VAR=ASSET_ROOT_ENV_VAR)
    nucleus = CompatModule("isaacsim.storage.native.nucleus", **{name: here[name] for name in _NUCLEUS},
                           **_CONSTANTS)
    core_nucleus = CompatModule("isaacsim.core.utils.nucleus", **every, **_CONSTANTS)
    file_utils = CompatModule("isaacsim.storage.native.impl.file_utils", _URL_SCHEMES=_URL_SCHEMES,
                              **{name: here[name] for name in _FILE_UTILS})
    extension = CompatModule("isaacsim.storage.native.impl.extension", ASSET_ROOT_ENV_VAR=ASSET_ROOT_ENV_VAR)
    return [native, nucleus, core_nucleus, file_utils, extension]


def install() -> None:
    """Called by :func:`graphsdg.compat.isaac.install`: the asset root setting gets its value, as in Kit: Isaac's
    ``ISAACSIM_ASSET_ROOT`` environment variable if set (Isaac's storage extension applies it at startup), else
    graphsdg's root (the built-in pack or ``GRAPHSDG_ASSETS_ROOT``); a value already set stays."""
    if settings.get(DEFAULT_ASSET_ROOT_PATH_SETTING) is not None:
        return
    value = os.environ.get(ASSET_ROOT_ENV_VAR)
    value = value.rstrip("/") if value else asset_root.get_assets_root_path(skip_check=True)
    if value:
        settings.set(DEFAULT_ASSET_ROOT_PATH_SETTING, value)
