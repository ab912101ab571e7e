"""Isaac compat area: ``isaacsim.core.version`` and ``isaacsim.core.deprecation_manager``.

* ``get_version()`` reads Isaac's ``VERSION`` file from ``$ISAAC_PATH`` when that
  folder has one, as Isaac does; otherwise it answers the release whose API
  graphsdg's compat mode implements, Isaac Sim ``6.0.1-rc.7`` (the 6.0.1
  sources' ``VERSION``): ``(core, prerelease, major, minor, patch, pretag,
  prebuild, buildtag)``. ``parse_version`` splits any version string.
* ``import_module(name)`` imports a Python package; when it is missing it logs
  the error (and Isaac's installation notice for ``torch``) and exits the script
  with status 1, as Isaac shuts the app down.

Example:
    >>> parsed = parse_version("2000.0.0-beta.0+branch.0.hash.local")
    >>> parsed.core, parsed.pretag, parsed.prebuild, parsed.buildtag
    ('2000.0.0', 'beta', '0', 'branch.0.hash.local')
    >>> parse_version(IMPLEMENTED_VERSION).major, parse_version(IMPLEMENTED_VERSION).pretag
    ('6', 'rc')
"""
from __future__ import annotations

import importlib
import logging
import os
import sys
import types

from graphsdg.compat.modules import CompatModule, CompatObject

log = logging.getLogger("carb")
IMPLEMENTED_VERSION = "6.0.1-rc.7"   # the VERSION file of the Isaac Sim sources compat mode follows

_TORCH_NOTICE = """
PyTorch (torch) is not installed. graphsdg's core API runs its NumPy backend; a script that needs torch itself
installs it in graphsdg's environment:

    pip install torch
"""


class Version(CompatObject):
    """A parsed version: ``core``, ``prerelease``, ``major``, ``minor``, ``patch``, ``pretag``, ``prebuild``,
    ``buildtag`` (empty strings where absent)."""

    _compat_name = "isaacsim.core.version.Version"

    def __init__(self) -> None:
        self.core = self.prerelease = self.major = self.minor = self.patch = ""
        self.pretag = self.prebuild = self.buildtag = ""


def parse_version(full_version: str) -> Version:
    """Split ``major.minor.patch[-pretag.prebuild][+buildtag]``."""
    if not isinstance(full_version, str) or full_version.count(".") < 2:
        raise ValueError(f"version {full_version!r} is not of the form major.minor.patch[-pre.build][+tag]")
    parsed = Version()
    text = full_version.strip()
    if "+" in text:
        text, parsed.buildtag = text.split("+", 1)
    if "-" in text:
        parsed.core, parsed.prerelease = text.split("-", 1)
        if "." in parsed.prerelease:
            parsed.pretag, parsed.prebuild = parsed.prerelease.split(".", 1)
        else:
            parsed.pretag = parsed.prerelease
    else:
        parsed.core = text
    parsed.major, parsed.minor, parsed.patch = parsed.core.split(".", 2)
    return parsed


def get_version() -> tuple[str, str, str, str, str, str, str, str]:
    """(core, prerelease, major, minor, patch, pretag, prebuild, buildtag) of Isaac's VERSION (see the module
    docstring for which file)."""
    text = IMPLEMENTED_VERSION
    folder = os.environ.get("ISAAC_PATH")
    if folder and os.path.isfile(os.path.join(folder, "VERSION")):
        with open(os.path.join(folder, "VERSION"), encoding="utf-8") as f:
            text = f.readline().strip()
    v = parse_version(text)
    return v.core, v.prerelease, v.major, v.minor, v.patch, v.pretag, v.prebuild, v.buildtag


def import_module(name: str) -> types.ModuleType:
    """Import and return package ``name``; a missing one logs why and exits the script (status 1), as Isaac does."""
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        log.error(f"Import error: {exc}")
        if name == "torch":
            log.warning(_TORCH_NOTICE)
        sys.exit(1)


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.version`` and ``isaacsim.core.deprecation_manager``."""
    return [CompatModule("isaacsim.core.version", Version=Version, parse_version=parse_version,
                         get_version=get_version),
            CompatModule("isaacsim.core.deprecation_manager", import_module=import_module)]


EXTENSIONS = {"isaacsim.core.version": ("isaacsim.core.version",),
              "isaacsim.core.deprecation_manager": ("isaacsim.core.deprecation_manager",)}
