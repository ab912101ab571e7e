"""Kit experience files in compat mode: ``$EXP_PATH`` and ``SimulationApp(experience=...)``.

Isaac's launcher sets ``EXP_PATH`` to the folder of its ``.kit`` experiences, and scripts name one
(``f'{os.environ["EXP_PATH"]}/isaacsim.exp.base.zero_delay.kit'``). While compat mode is installed,
``EXP_PATH`` (unless already set) is graphsdg's folder of experiences of the same names
(``graphsdg/compat/apps``), and :func:`apply_experience` reads an experience's ``[settings]`` into carb's
settings as Kit does at start-up. A path that does not exist fails naming it.

Example:
    >>> flat_settings({"app": {"name": "x", "window": {"width": 3}}})
    {'/app/name': 'x', '/app/window/width': 3}
"""
from __future__ import annotations

import os
import tomllib
import types
from pathlib import Path
from typing import Any

from graphsdg.base import settings_store as settings

APPS_DIR = Path(__file__).resolve().parent / "apps"
_set_exp_path = False


def modules() -> list[types.ModuleType]:
    """No modules of its own: the area only sets ``EXP_PATH`` while compat mode is installed."""
    return []


def install() -> None:
    """Point ``EXP_PATH`` at graphsdg's experiences unless the environment already names a folder."""
    global _set_exp_path
    if "EXP_PATH" not in os.environ:
        os.environ["EXP_PATH"] = str(APPS_DIR)
        _set_exp_path = True


def uninstall() -> None:
    """Take back the ``EXP_PATH`` :func:`install` set."""
    global _set_exp_path
    if _set_exp_path and os.environ.get("EXP_PATH") == str(APPS_DIR):
        del os.environ["EXP_PATH"]
    _set_exp_path = False


def flat_settings(table: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """A ``.kit`` file's ``[settings]`` table as carb setting paths; Kit's ``"++"`` list appends are skipped."""
    flat: dict[str, Any] = {}
    for key, value in table.items():
        if key == "++":
            continue
        path = f"{prefix}/{key}"
        if isinstance(value, dict):
            flat.update(flat_settings(value, path))
        else:
            flat[path] = value
    return flat


def apply_experience(path: str) -> str:
    """Read the experience ``path`` and set its ``[settings]`` in carb's settings; returns the path.

    Raises ``FileNotFoundError`` naming a path that is no file, and ``ValueError`` for one that is not TOML.
    """
    if not os.path.isfile(path):
        raise FileNotFoundError(f"SimulationApp experience {path!r} is not a file; graphsdg's experiences are in "
                                f"{APPS_DIR} (EXP_PATH in compat mode)")
    try:
        document = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"SimulationApp experience {path!r} is not a .kit (TOML) file: {exc}") from None
    for key, value in flat_settings(document.get("settings", {})).items():
        settings.set(key, value)
    return path
