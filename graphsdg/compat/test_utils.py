"""isaacsim.test.utils: checks Isaac's example scripts run on their own output (file counts by extension).

This area also makes the package ``isaacsim.test.utils`` itself and the submodules of UI
helpers graphsdg cannot provide; the image comparison, image files, capture, timing and
stage polling helpers come from :mod:`graphsdg.compat.test_utils_images` and
:mod:`graphsdg.compat.test_utils_capture`.

The functions follow the contracts of Isaac Sim's ``isaacsim.test.utils.file_validation``:

* :func:`validate_folder_contents` - True when a folder holds the expected number
  of files per extension (exactly, or at least), optionally recursive, with no
  empty or undersized files and no extensions beyond an allowed set;
* :func:`get_folder_file_summary` - file counts per extension (and sizes);
* :func:`validate_file_list` - which of a list of files are missing, empty or undersized.

Extensions are compared without their dot and case-insensitively; files without
an extension are not counted.

Example:
    >>> import pathlib, tempfile
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "rgb_0000.png").write_bytes(b"x"); _ = (d / "labels.json").write_text("{}")
    >>> validate_folder_contents(d, {"png": 1, "json": 1})
    True
    >>> validate_folder_contents(d, {"png": 2})
    False
"""
from __future__ import annotations

import types
from collections import Counter
from pathlib import Path

from graphsdg.compat.modules import CompatModule


def _files(path: Path, recursive: bool) -> list[Path]:
    entries = path.rglob("*") if recursive else path.iterdir()
    return sorted(f for f in entries if f.is_file())


def _extension(f: Path) -> str:
    return f.suffix[1:].lower()


def _size(f: Path) -> int | None:
    try:
        return f.stat().st_size
    except OSError:
        return None


def validate_folder_contents(path: str | Path, expected_counts: dict[str, int], *, recursive: bool = False,
                             fail_on_empty_files: bool = False, allowed_extra_extensions: set[str] | None = None,
                             min_file_size_bytes: int = 0, exact_match: bool = True) -> bool:
    """Whether ``path`` holds ``expected_counts[ext]`` files of each extension.

    Args:
        path: the folder (False if it does not exist or is not a folder).
        expected_counts: extension without its dot -> count.
        recursive: count files in subfolders too.
        fail_on_empty_files: False if any counted file has 0 bytes.
        allowed_extra_extensions: when given, False if a file has an extension neither
            expected nor in this set; when None, other extensions are ignored.
        min_file_size_bytes: False if any counted file is smaller.
        exact_match: counts must be equal (True) or at least the expected ones (False).
    """
    folder = Path(path)
    if not folder.is_dir():
        return False
    files = [f for f in _files(folder, recursive) if f.suffix]
    if fail_on_empty_files or min_file_size_bytes > 0:
        for f in files:
            size = _size(f)
            if size is None or (fail_on_empty_files and size == 0) or size < min_file_size_bytes:
                return False
    counts = Counter(_extension(f) for f in files)
    for ext, expected in expected_counts.items():
        found = counts.get(str(ext).lower().lstrip("."), 0)
        if (found != expected) if exact_match else (found < expected):
            return False
    if allowed_extra_extensions is not None:
        allowed = {str(e).lower().lstrip(".") for e in [*expected_counts, *allowed_extra_extensions]}
        if any(ext not in allowed for ext in counts):
            return False
    return True


def get_folder_file_summary(path: str | Path, *, recursive: bool = False,
                            include_file_sizes: bool = False) -> dict:
    """``{"total_files", "extension_counts"}`` and, with ``include_file_sizes``, ``"file_details"``:
    extension -> list of ``{"path", "size_bytes"}`` (-1 where the size cannot be read)."""
    folder = Path(path)
    if not folder.is_dir():
        return {"total_files": 0, "extension_counts": {}, "file_details": {} if include_file_sizes else None}
    files = _files(folder, recursive)
    with_ext = [f for f in files if f.suffix]
    summary: dict = {"total_files": len(files), "extension_counts": dict(Counter(_extension(f) for f in with_ext))}
    if include_file_sizes:
        details: dict[str, list[dict]] = {}
        for f in with_ext:
            size = _size(f)
            details.setdefault(_extension(f), []).append({"path": str(f), "size_bytes": -1 if size is None else size})
        summary["file_details"] = details
    return summary


def validate_file_list(file_paths: list[str | Path], *, fail_on_missing: bool = True,
                       fail_on_empty_files: bool = False, min_file_size_bytes: int = 0) -> dict:
    """``{"passed", "missing_files", "empty_files", "undersized_files"}`` for a list of files
    (a folder or an unreadable file counts as missing)."""
    missing, empty, undersized = [], [], []
    for p in map(Path, file_paths):
        size = _size(p) if p.is_file() else None
        if size is None:
            missing.append(str(p))
            continue
        if fail_on_empty_files and size == 0:
            empty.append(str(p))
        if size < min_file_size_bytes:
            undersized.append(str(p))
    passed = not ((fail_on_missing and missing) or (fail_on_empty_files and empty)
                  or (min_file_size_bytes > 0 and undersized))
    return {"passed": passed, "missing_files": missing, "empty_files": empty, "undersized_files": undersized}


NO_UI = ("graphsdg has no Kit UI (omni.ui windows, menus, omni.kit.ui_test mouse emulation), so the UI test "
         "helpers (MenuUITestCase, menu_utils, button_utils, layout_utils, viewport_utils.project_world_to_screen) "
         "are not provided")
NO_ARTICULATION_COMPARE = ("usd_utils.compare_usd_files compares PhysX articulation properties of loaded robots, "
                           "which graphsdg does not provide")
UI_MODULES = ("menu_utils", "menu_ui_test", "button_utils", "layout_utils", "viewport_utils")


def modules() -> list[types.ModuleType]:
    """``isaacsim.test.utils``, its ``file_validation`` submodule, and the UI and USD-comparison submodules (which
    name what they lack)."""
    names = dict(validate_folder_contents=validate_folder_contents, get_folder_file_summary=get_folder_file_summary,
                 validate_file_list=validate_file_list)
    found = [CompatModule("isaacsim.test.utils", hint=f"{NO_UI}; {NO_ARTICULATION_COMPARE}.", **names),
             CompatModule("isaacsim.test.utils.file_validation", **names),
             CompatModule("isaacsim.test.utils.usd_utils", hint=f"{NO_ARTICULATION_COMPARE}.")]
    found += [CompatModule(f"isaacsim.test.utils.{name}", hint=f"{NO_UI}.") for name in UI_MODULES]
    return found
