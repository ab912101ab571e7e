"""Kit extensions in compat mode: which ones graphsdg knows, which are enabled, and enabling them.

Isaac scripts enable extensions before importing their modules
(``enable_extension("isaacsim.test.utils")``, then
``from isaacsim.test.utils.file_validation import ...``). Here an extension is
a name with the compat modules it provides. Most are enabled from the start,
as in Isaac's standalone experience; the few that Isaac leaves off
(:data:`OFF_AT_START`) must be enabled before their modules import, and an
import that comes first fails saying which extension to enable. An extension
graphsdg does not know raises :class:`UnknownExtensionError` naming it.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> from isaacsim.core.utils.extensions import enable_extension
    >>> enable_extension("isaacsim.test.utils")
    True
    >>> from isaacsim.test.utils.file_validation import validate_folder_contents
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Any

from graphsdg.compat.modules import PORTING, CompatImportError, CompatModule, CompatObject

# extension name -> the compat module prefixes it provides (empty: its effect is built into graphsdg)
KNOWN: dict[str, tuple[str, ...]] = {
    "omni.replicator.core": ("omni.replicator.core",),
    "omni.usd": ("omni.usd",),
    "omni.timeline": ("omni.timeline",),
    "omni.kit.app": ("omni.kit.app",),
    "omni.kit.commands": ("omni.kit.commands",),
    "omni.kit.test": ("omni.kit.test",),
    "omni.kit.viewport.utility": ("omni.kit.viewport.utility",),
    "omni.kit.actions.core": ("omni.kit.actions.core",),
    "omni.physx": ("omni.physx",),
    "omni.physics.core": ("omni.physics.core",),
    "omni.physx.fabric": (),
    "omni.simready.explorer": ("omni.simready.explorer",),
    "isaacsim.core.api": (),
    "isaacsim.core.utils": ("isaacsim.core.utils",),
    "isaacsim.core.experimental.materials": ("isaacsim.core.experimental.materials",),
    "isaacsim.core.experimental.objects": ("isaacsim.core.experimental.objects",),
    "isaacsim.core.experimental.prims": ("isaacsim.core.experimental.prims",),
    "isaacsim.core.experimental.utils": ("isaacsim.core.experimental.utils",),
    "isaacsim.core.simulation_manager": ("isaacsim.core.simulation_manager",),
    "isaacsim.storage.native": ("isaacsim.storage.native",),
    "isaacsim.test.utils": ("isaacsim.test.utils",),
    "isaacsim.replicator.writers": (),
    "isaacsim.replicator.examples": (),
    "isaacsim.examples.interactive": ("isaacsim.examples.interactive",),
    "isaacsim.cortex.examples": ("isaacsim.cortex.examples",),
}
# off until enabled, as in Isaac Sim's standalone Python experience
OFF_AT_START: set[str] = {"isaacsim.test.utils", "omni.simready.explorer"}
# Isaac's pre-4.5 extension name -> the extensions replacing it (graphsdg.compat.legacy_names fills it); an old name
# is known once a replacement is, and otherwise its error names the replacements
RENAMED: dict[str, tuple[str, ...]] = {}


def declare(provided: dict[str, tuple[str, ...]], off_at_start=()) -> None:
    """Add a compat area's extensions (name -> module prefixes) to :data:`KNOWN`, some of them off at start."""
    KNOWN.update(provided)
    OFF_AT_START.update(off_at_start)
    _manager._reset()


class UnknownExtensionError(CompatImportError):
    """An extension name graphsdg's compat mode does not know."""


def _check(name: str) -> str:
    ext = str(name).split("-")[0]   # Kit ids carry a version: "omni.simready.explorer-1.2.3"
    from graphsdg.compat import out_of_scope
    why = out_of_scope.reason(ext) if ext not in KNOWN else None
    if why is not None:
        raise UnknownExtensionError(f"extension {name!r} is out of scope for graphsdg's compat mode: {why}. "
                                    f"{PORTING}", name=str(name))
    if ext not in KNOWN and ext in RENAMED:
        raise UnknownExtensionError(f"extension {name!r} is Isaac's pre-4.5 name of {', '.join(RENAMED[ext])}, which "
                                    f"graphsdg's compat mode does not provide. {PORTING}", name=str(name))
    if ext not in KNOWN:
        raise UnknownExtensionError(
            f"extension {name!r} is not available in graphsdg's compat mode; known extensions: "
            f"{', '.join(sorted(KNOWN))}. {PORTING}", name=str(name))
    return ext


class ExtensionManager(CompatObject):
    """omni.kit.app's extension manager: the enabled set of :data:`KNOWN` extensions."""

    _compat_name = "omni.ext.ExtensionManager"

    def __init__(self) -> None:
        self._enabled = set(KNOWN) - OFF_AT_START
        self._folders: dict[str, str] = {}   # extensions whose source folder is on disk (an Isaac tree's tests)

    def set_extension_folder(self, ext_name: str, folder: str) -> None:
        """Record where an extension's folder is (its ``config/extension.toml`` and data), as Kit knows it."""
        self._folders[str(ext_name).split("-")[0]] = str(folder)

    def get_extension_path(self, ext_id: str) -> str:
        """The extension's folder: known for an extension whose tests run from its source tree, else an error."""
        ext = str(ext_id).split("-")[0]
        if ext in self._folders:
            return self._folders[ext]
        _check(ext_id)
        raise CompatImportError(f"extension {ext_id!r} has no folder in graphsdg's compat mode (its modules are part "
                                f"of graphsdg); only an extension whose tests run from its own source folder has one. "
                                f"{PORTING}", name=str(ext_id))

    def get_extension_path_by_module(self, module_name: str) -> str:
        """The folder of the extension that provides the Python module ``module_name``."""
        for ext in sorted(self._folders, key=len, reverse=True):
            if module_name == ext or module_name.startswith(ext + "."):
                return self._folders[ext]
        for ext, prefixes in KNOWN.items():
            if any(module_name == p or module_name.startswith(p + ".") for p in prefixes):
                return self.get_extension_path(ext)
        raise CompatImportError(f"no extension provides the module {module_name!r} in graphsdg's compat mode. "
                                f"{PORTING}", name=str(module_name))

    def is_extension_enabled(self, ext_name: str) -> bool:
        return _check(ext_name) in self._enabled

    def set_extension_enabled(self, ext_name: str, enabled: bool) -> None:
        ext = _check(ext_name)
        (self._enabled.add if enabled else self._enabled.discard)(ext)

    def set_extension_enabled_immediate(self, ext_name: str, enabled: bool) -> bool:
        self.set_extension_enabled(ext_name, enabled)
        return True

    def get_enabled_extension_id(self, ext_name: str) -> str:
        ext = _check(ext_name)
        return ext if ext in self._enabled else ""

    def get_extensions(self) -> list[dict[str, Any]]:
        """One dict per known extension: ``id``, ``name``, ``enabled``."""
        return [{"id": n, "name": n, "enabled": n in self._enabled} for n in sorted(KNOWN)]

    def providing(self, module_name: str) -> str | None:
        """The disabled extension that provides ``module_name``, if one does."""
        for ext, prefixes in KNOWN.items():
            if ext not in self._enabled and any(module_name == p or module_name.startswith(p + ".")
                                                for p in prefixes):
                return ext
        return None

    def _reset(self) -> None:
        self._enabled = set(KNOWN) - OFF_AT_START


_manager = ExtensionManager()


def get_extension_manager() -> ExtensionManager:
    """The process's extension manager (``omni.kit.app.get_app().get_extension_manager()``)."""
    return _manager


def enable_extension(extension_name: str) -> bool:
    """isaacsim.core.utils.extensions.enable_extension: enable a known extension; True once enabled.

    Raises:
        UnknownExtensionError: the name is not a known extension.
    """
    return _manager.set_extension_enabled_immediate(extension_name, True)


def disable_extension(extension_name: str) -> bool:
    """isaacsim.core.utils.extensions.disable_extension."""
    return _manager.set_extension_enabled_immediate(extension_name, False)


def get_extension_id(extension_name: str) -> str:
    """The enabled extension's id ("" when disabled)."""
    return _manager.get_enabled_extension_id(extension_name)


def get_extension_path_from_name(extension_name: str) -> str:
    """The extension's folder where one is known (:meth:`ExtensionManager.get_extension_path`), else an error."""
    return _manager.get_extension_path(extension_name)


class IExt:
    """omni.ext.IExt: the base of a Kit extension's entry class (Kit calls on_startup / on_shutdown on it)."""

    def on_startup(self, ext_id: str) -> None:
        """Called when the extension is enabled; the base does nothing."""

    def on_shutdown(self) -> None:
        """Called when the extension is disabled; the base does nothing."""


def get_extension_name(ext_id: str) -> str:
    """omni.ext.get_extension_name: the name part of a Kit extension id ("omni.foo-1.2.3" -> "omni.foo")."""
    return str(ext_id).split("-")[0]


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.extensions`` (and its older name under ``omni.isaac``-less Isaac 6 layout)."""
    return [CompatModule("omni.ext", IExt=IExt, ExtensionManager=ExtensionManager,
                         get_extension_name=get_extension_name),
            CompatModule("isaacsim.core.utils.extensions", enable_extension=enable_extension,
                         disable_extension=disable_extension, get_extension_id=get_extension_id,
                         get_extension_path_from_name=get_extension_path_from_name)]
