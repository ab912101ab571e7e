"""Isaac compat area: ``omni.kit.commands``' command classes and their registry.

A script or extension defines a command as a subclass of :class:`Command` with a
``do()`` method (and optionally ``undo()``), registers it with :func:`register` or
:func:`register_all_commands_in_module`, then runs it by name with
``omni.kit.commands.execute("Name", **kwargs)``: the class is instantiated with the
keyword arguments and ``do()``'s result comes back as ``(True, result)``. A class
registers under its name less a ``Command`` suffix; either spelling executes it,
as in Kit. :func:`create` builds a command (registered or one of graphsdg's
built-in Kit commands, :mod:`graphsdg.compat.kit_commands`) for the caller to
``do()`` itself; ``omni.usd.commands`` holds the built-in ones as classes
(``omni.usd.commands.DeletePrimsCommand(["/World/Cube"]).do()``). There is no undo stack here: ``undo()`` is the command's own
method, called by whoever holds the command.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.kit.commands
    >>> class AppendOrangeCommand(omni.kit.commands.Command):
    ...     def __init__(self, basket: list):
    ...         self._basket = basket
    ...     def do(self):
    ...         self._basket.append("orange")
    ...         return len(self._basket)
    >>> omni.kit.commands.register(AppendOrangeCommand)
    >>> basket = []
    >>> omni.kit.commands.execute("AppendOrange", basket=basket)
    (True, 1)
    >>> omni.kit.commands.unregister(AppendOrangeCommand)
    >>> isaac.uninstall()
"""
from __future__ import annotations

import importlib
import inspect
import types
from typing import Any

from graphsdg.compat.kit import delete_prims, execute
from graphsdg.compat.kit_commands import COMMANDS
from graphsdg.compat.modules import CompatError, CompatModule

_registered: dict[str, type["Command"]] = {}


class Command:
    """``omni.kit.commands.Command``: the base of a command class (``do()``, optional ``undo()``)."""

    def do(self) -> Any:
        """Run the command; what it returns is ``execute``'s result."""
        raise NotImplementedError(f"{type(self).__name__} must define do()")

    def modify_callback_info(self, cb_type: str, args: dict[str, Any]) -> dict[str, Any]:
        """The arguments Kit passes to command callbacks (the given ones, unchanged)."""
        return args


def _name(command_class: type) -> str:
    return command_class.__name__.removesuffix("Command") or command_class.__name__


def _check_class(command_class: Any) -> type[Command]:
    if not (inspect.isclass(command_class) and issubclass(command_class, Command)):
        raise TypeError(f"{command_class!r} is not an omni.kit.commands.Command subclass")
    return command_class


def _runner(command_class: type[Command]):
    """The callable :func:`graphsdg.compat.kit.execute` runs: instantiate with the arguments, then ``do()``."""
    def run(**kwargs: Any) -> Any:
        return command_class(**kwargs).do()
    run.command_class = command_class  # type: ignore[attr-defined]
    return run


def register(command_class: type[Command]) -> None:
    """Register a command class under its name less a ``Command`` suffix (replacing one of that name)."""
    name = _name(_check_class(command_class))
    builtin = COMMANDS.get(name)
    if builtin is not None and getattr(builtin, "command_class", None) is None:
        raise ValueError(f"cannot register {command_class.__name__}: {name!r} is one of graphsdg's built-in Kit "
                         f"commands")
    _registered[name] = command_class
    COMMANDS[name] = _runner(command_class)


def unregister(command_class: type[Command]) -> None:
    """Unregister a command class (one that is not registered is ignored)."""
    name = _name(_check_class(command_class))
    if _registered.get(name) is command_class:
        del _registered[name]
        COMMANDS.pop(name, None)


class CommandAccessor:
    """What :func:`register_all_commands_in_module` returns: one method per registered command, running it."""

    def __init__(self, classes: list[type[Command]]) -> None:
        self._classes = list(classes)
        for cls in classes:
            setattr(self, _name(cls), self._caller(_name(cls)))

    @staticmethod
    def _caller(name: str):
        def call(**kwargs: Any) -> Any:
            return execute(name, **kwargs)[1]
        call.__name__ = name
        return call

    @property
    def command_classes(self) -> list[type[Command]]:
        """The command classes registered with this accessor."""
        return list(self._classes)


def register_all_commands_in_module(module: str | types.ModuleType) -> CommandAccessor:
    """Register every ``Command`` subclass defined in ``module`` (a module or its name)."""
    target = importlib.import_module(module) if isinstance(module, str) else module
    classes = [value for value in vars(target).values() if inspect.isclass(value) and issubclass(value, Command)
               and value is not Command and value.__module__ == target.__name__]
    for cls in classes:
        register(cls)
    return CommandAccessor(classes)


def unregister_module_commands(command_interface: CommandAccessor | None) -> None:
    """Unregister the commands :func:`register_all_commands_in_module` registered."""
    if command_interface is None:
        return
    if not isinstance(command_interface, CommandAccessor):
        raise TypeError(f"unregister_module_commands takes what register_all_commands_in_module returned, got "
                        f"{command_interface!r}")
    for cls in command_interface.command_classes:
        unregister(cls)


def get_command_class(name: str) -> type[Command] | None:
    """The registered command class of ``name`` (with or without ``Command``), or None."""
    return _registered.get(name) or _registered.get(name.removesuffix("Command"))


def get_commands_list() -> list[type[Command]]:
    """Every registered command class."""
    return list(_registered.values())


def _builtin_class(name: str, fn: Any) -> type[Command]:
    """A ``Command`` class for one of graphsdg's built-in Kit commands: its constructor takes the command's
    arguments (checked against its signature at once), ``do()`` runs it."""
    signature = inspect.signature(fn)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        try:
            self._arguments = signature.bind(*args, **kwargs)
        except TypeError as exc:
            raise TypeError(f"{name}Command: {exc}") from None

    def do(self) -> Any:
        return fn(*self._arguments.args, **self._arguments.kwargs)

    return type(f"{name}Command", (Command,), {"__init__": __init__, "do": do, "__doc__": fn.__doc__,
                                                "__module__": __name__})


# graphsdg's built-in Kit commands as classes (``omni.usd.commands.DeletePrimsCommand([path]).do()``)
BUILTIN_CLASSES: dict[str, type[Command]] = {name: _builtin_class(name, fn) for name, fn in
                                             {**COMMANDS, "DeletePrims": delete_prims}.items()}
# the commands Kit's omni.usd.commands module defines (the others come from omni.kit.primitive.mesh and
# omni.kit.material.library)
OMNI_USD_COMMANDS = ("CreatePrim", "CreatePrimWithDefaultXform", "ChangeProperty", "CreateReference", "AddReference",
                     "MovePrim", "MovePrims", "CopyPrim", "CopyPrims", "TransformPrim", "TransformPrimSRT",
                     "DeletePrims", "CreateMdlMaterialPrim", "BindMaterial")


def create(name: str, **kwargs: Any) -> Command:
    """A command object for ``name`` with ``kwargs``, not yet run (call its ``do()``)."""
    command_class = get_command_class(name) or BUILTIN_CLASSES.get(name) or \
        BUILTIN_CLASSES.get(name.removesuffix("Command"))
    if command_class is None:
        raise CompatError(f"omni.kit.commands {name!r} is not available in graphsdg's compat mode; available: "
                          f"{', '.join(sorted({*BUILTIN_CLASSES, *_registered}))}. See docs/porting.md.")
    return command_class(**kwargs)


def modules() -> list[types.ModuleType]:
    """The compat modules of this area (merged into the ``omni.kit.commands`` isaac.py maps)."""
    return [CompatModule("omni.kit.commands", Command=Command, register=register, unregister=unregister,
                         register_all_commands_in_module=register_all_commands_in_module,
                         unregister_module_commands=unregister_module_commands, create=create,
                         get_command_class=get_command_class, get_commands_list=get_commands_list),
            CompatModule("omni.usd.commands", **{f"{name}Command": BUILTIN_CLASSES[name] for name in OMNI_USD_COMMANDS})]
