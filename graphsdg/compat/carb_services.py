"""Isaac compat area: Carbonite services scripts call: ``carb.tokens``, ``carb.profiler``, ``carb.logging``,
``carb.get_framework``.

* ``carb.tokens.get_tokens_interface()``: ``resolve("${temp}/rgb")`` by Carbonite's
  rules (``$$`` is ``$``; a token with no value becomes ``""``, or stays as
  written with ``RESOLVE_FLAG_LEAVE_TOKEN_IF_NOT_FOUND``; values may hold tokens).
  graphsdg's tokens: ``temp`` (a folder of this process, made on first use),
  ``app`` and ``kit`` (graphsdg's installed package), ``cache``, ``data``,
  ``logs``, ``config`` and their ``omni_`` forms (graphsdg's user folders),
  ``omni_global_config``, ``omni_documents``, ``python`` (the interpreter);
  ``set_value`` adds more. A token nobody set logs a warning once.
* ``carb.profiler``: ``begin``/``end`` zones and the ``profile`` decorator time
  for real into graphsdg's profiling tables (:mod:`graphsdg.base.profiling`,
  accumulator ``carb:<zone>``; ``rep.orchestrator.get_profile()`` and
  ``graphsdg bench --profile`` show them), filtered by the capture mask;
  ``value_*`` samples and instant events are kept (:func:`profiler_samples`).
* ``carb.logging``: ``LEVEL_*`` and ``acquire_logging()``: loggers added with
  ``add_logger(fn)`` get ``fn(source, level, filename, line, message)`` for
  every Python log record; ``set_log_enabled`` / ``set_level_threshold`` act on
  the ``carb`` logger. ``carb.log_verbose`` and ``carb.log_fatal`` join
  ``log_info`` / ``log_warn`` / ``log_error``.
* ``carb.get_framework()``: there are no native plugins; ``get_plugins()`` is
  empty and ``load_plugins`` raises naming the plugins asked for.
"""
from __future__ import annotations

import asyncio
import functools
import logging
import os
import re
import sys
import tempfile
import threading
import time
import types
from typing import Any, Callable

from graphsdg.base import profiling
from graphsdg.compat.modules import PORTING, CompatError, CompatModule, CompatObject

log = logging.getLogger("carb")

# ---- carb.tokens ----------------------------------------------------------------------------------------------------
RESOLVE_FLAG_NONE = 0
RESOLVE_FLAG_LEAVE_TOKEN_IF_NOT_FOUND = 1
_TOKEN = re.compile(r"\$\$|\$\{([^}]*)\}")


def _user_folder(kind: str) -> str:
    """graphsdg's per-user folder of ``kind`` (XDG locations; not created here)."""
    home = os.path.expanduser("~")
    bases = {"cache": os.environ.get("XDG_CACHE_HOME") or os.path.join(home, ".cache"),
             "data": os.environ.get("XDG_DATA_HOME") or os.path.join(home, ".local", "share"),
             "config": os.environ.get("XDG_CONFIG_HOME") or os.path.join(home, ".config")}
    if kind == "logs":
        return os.path.join(bases["data"], "graphsdg", "logs")
    return os.path.join(bases[kind], "graphsdg")


class ITokens(CompatObject):
    """carb.tokens.ITokens: named string values substituted for ``${name}`` in strings."""

    _compat_name = "carb.tokens.ITokens"

    def __init__(self) -> None:
        self._values: dict[str, str | Callable[[], str]] = {}
        self._lock = threading.Lock()
        self._warned: set[str] = set()
        self._temp: str | None = None
        package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        defaults: dict[str, str | Callable[[], str]] = {
            "app": package, "kit": package, "python": sys.executable, "temp": self._temp_folder,
            "omni_global_config": os.path.join(os.path.expanduser("~"), ".nvidia-omniverse", "config"),
            "omni_documents": os.path.join(os.path.expanduser("~"), "Documents", "graphsdg")}
        for kind in ("cache", "data", "logs", "config"):
            defaults[kind] = defaults[f"omni_{kind}"] = _user_folder(kind)
        self._values.update(defaults)

    def _temp_folder(self) -> str:
        if self._temp is None:   # made once per process, on first use (Kit makes it at startup)
            self._temp = tempfile.mkdtemp(prefix="graphsdg-kit-")
        return self._temp

    def set_value(self, name: str, value: str) -> bool:
        """Set the token ``name``; True."""
        with self._lock:
            self._values[str(name)] = str(value)
        return True

    def set_initial_value(self, name: str, value: str) -> None:
        """Set the token ``name`` unless it already has a value."""
        with self._lock:
            self._values.setdefault(str(name), str(value))

    def remove_token(self, name: str) -> bool:
        """Forget the token ``name``; whether it had a value."""
        with self._lock:
            return self._values.pop(str(name), None) is not None

    def exists(self, name: str) -> bool:
        """Whether the token ``name`` has a value."""
        return str(name) in self._values

    def _value(self, name: str) -> str | None:
        value = self._values.get(name)
        return value() if callable(value) else value

    def resolve(self, str: str, flags: int = RESOLVE_FLAG_NONE, _depth: int = 0) -> str:  # noqa: A002 - carb's name
        """``str`` with every ``${name}`` replaced by its value (values are resolved too) and ``$$`` by ``$``."""
        def replace(match: re.Match) -> str:
            if match.group(0) == "$$":
                return "$"
            name = match.group(1)
            value = self._value(name)
            if value is None:
                if name not in self._warned:
                    self._warned.add(name)
                    log.warning(f"carb.tokens: token ${{{name}}} has no value in graphsdg (known: "
                                f"{', '.join(sorted(self._values))}); it resolves to "
                                f"{'itself' if flags & RESOLVE_FLAG_LEAVE_TOKEN_IF_NOT_FOUND else 'an empty string'}")
                return match.group(0) if flags & RESOLVE_FLAG_LEAVE_TOKEN_IF_NOT_FOUND else ""
            if _depth < 16 and "${" in value:   # a value naming tokens (bounded: a cycle stops resolving)
                return self.resolve(value, flags, _depth + 1)
            return value
        return _TOKEN.sub(replace, os.fspath(str))


_tokens = ITokens()


def get_tokens_interface() -> ITokens:
    """The process's tokens."""
    return _tokens


# ---- carb.profiler --------------------------------------------------------------------------------------------------
_capture_mask = [0xFFFFFFFFFFFFFFFF]
_zones = threading.local()
_samples: dict[str, list[float]] = {}
_events: list[tuple[float, str]] = []


def _stack() -> list[tuple[int, str, float]]:
    try:
        return _zones.stack
    except AttributeError:
        _zones.stack = []
        return _zones.stack


def begin(mask: int, name: str, stack_offset: int = 0) -> None:
    """Open the zone ``name`` on this thread (timed into the profiling table ``carb:<name>`` at :func:`end`)."""
    _stack().append((int(mask), str(name), time.perf_counter()))


def end(mask: int) -> None:
    """Close this thread's innermost zone and add its time (when its mask is captured)."""
    stack = _stack()
    if not stack:
        raise RuntimeError("carb.profiler.end() without an open zone on this thread (begin() was not called)")
    zone_mask, name, start = stack.pop()
    if zone_mask & _capture_mask[0] or zone_mask == 0:
        profiling.add(f"carb:{name}", time.perf_counter() - start)


def profile(func: Callable | None = None, mask: int = 1, zone_name: str | None = None,
            add_args: bool = False) -> Callable:
    """Decorator timing each call of a function (or coroutine function) as a zone (``@carb.profiler.profile`` or
    ``@carb.profiler.profile(mask=..., zone_name=..., add_args=...)``)."""
    def decorate(function: Callable) -> Callable:
        name = zone_name or function.__qualname__

        def zone(args: tuple, kwargs: dict) -> str:
            return f"{name}({', '.join([repr(a) for a in args] + [f'{k}={v!r}' for k, v in kwargs.items()])})" \
                if add_args else name

        if asyncio.iscoroutinefunction(function):
            @functools.wraps(function)
            async def timed_async(*args: Any, **kwargs: Any) -> Any:
                begin(mask, zone(args, kwargs))
                try:
                    return await function(*args, **kwargs)
                finally:
                    end(mask)
            return timed_async

        @functools.wraps(function)
        def timed(*args: Any, **kwargs: Any) -> Any:
            begin(mask, zone(args, kwargs))
            try:
                return function(*args, **kwargs)
            finally:
                end(mask)
        return timed
    return decorate(func) if func is not None else decorate


def is_profiler_active() -> bool:
    """True: zones are always timed into graphsdg's profiling tables."""
    return True


def supports_dynamic_source_locations() -> bool:
    """True: zones are named at run time."""
    return True


def profiler_samples() -> dict[str, list[float]]:
    """The ``value_*`` samples sent so far, by name (graphsdg's own accessor; Kit shows them in its profiler)."""
    return {name: list(values) for name, values in _samples.items()}


class IProfiler(CompatObject):
    """carb.profiler.IProfiler: zones, values and markers (zones go to graphsdg's profiling tables)."""

    _compat_name = "carb.profiler.IProfiler"

    def startup(self) -> None:
        """Profiling is always on."""

    def shutdown(self) -> None:
        """Profiling is always on; the tables stay readable."""

    def begin(self, mask: int, name: str) -> None:
        begin(mask, name)

    def end(self, mask: int) -> None:
        end(mask)

    def set_capture_mask(self, mask: int) -> int:
        """Capture only zones whose mask shares a bit with ``mask``; returns the previous mask."""
        previous, _capture_mask[0] = _capture_mask[0], int(mask)
        return previous

    def get_capture_mask(self) -> int:
        return _capture_mask[0]

    def _value(self, mask: int, value: float, name: str) -> None:
        if int(mask) & _capture_mask[0] or int(mask) == 0:
            _samples.setdefault(str(name), []).append(value)

    def value_float(self, mask: int, value: float, name: str) -> None:
        self._value(mask, float(value), name)

    def value_int(self, mask: int, value: int, name: str) -> None:
        self._value(mask, int(value), name)

    def value_uint(self, mask: int, value: int, name: str) -> None:
        if int(value) < 0:
            raise ValueError(f"carb.profiler value_uint {name!r}: {value} is negative")
        self._value(mask, int(value), name)

    def instant(self, mask: int, type: Any, name: str) -> None:  # noqa: A002 - carb's name
        """Record an instant event (time and name)."""
        _events.append((time.perf_counter(), str(name)))

    def frame(self, mask: int, name: str) -> None:
        """Record a frame marker (time and name)."""
        _events.append((time.perf_counter(), f"frame:{name}"))

    def is_python_profiling_enabled(self) -> bool:
        return False

    def set_python_profiling_enabled(self, enable: bool) -> None:
        if enable:
            raise CompatError(f"carb.profiler: cProfile-level Python profiling is not available in graphsdg's compat "
                              f"mode; time code with carb.profiler.profile or zones. {PORTING}")


_profiler = IProfiler()


def acquire_profiler_interface(plugin_name: str | None = None, library_path: str | None = None) -> IProfiler:
    """The profiler (whatever plugin is named: graphsdg's tables stand in for Tracy, NVTX, ...)."""
    return _profiler


# ---- carb.logging ---------------------------------------------------------------------------------------------------
LEVEL_VERBOSE, LEVEL_INFO, LEVEL_WARN, LEVEL_ERROR, LEVEL_FATAL = -2, -1, 0, 1, 2
_TO_PYTHON = {LEVEL_VERBOSE: logging.DEBUG, LEVEL_INFO: logging.INFO, LEVEL_WARN: logging.WARNING,
              LEVEL_ERROR: logging.ERROR, LEVEL_FATAL: logging.CRITICAL}


def _carb_level(python_level: int) -> int:
    for level in (LEVEL_FATAL, LEVEL_ERROR, LEVEL_WARN, LEVEL_INFO):
        if python_level >= _TO_PYTHON[level]:
            return level
    return LEVEL_VERBOSE


class _Forward(logging.Handler):
    """Hands each Python log record to one carb logger callback."""

    def __init__(self, callback: Callable[[str, int, str, int, str], Any]) -> None:
        super().__init__(logging.NOTSET)
        self.callback = callback

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self.callback(record.name, _carb_level(record.levelno), record.pathname, record.lineno,
                          record.getMessage())
        except Exception:   # a failing logger must not break the code that logged
            self.handleError(record)


class ILogging(CompatObject):
    """carb.logging.ILogging: loggers that receive every log record, and the ``carb`` log's switches."""

    _compat_name = "carb.logging.ILogging"

    def add_logger(self, callback: Callable[[str, int, str, int, str], Any]) -> _Forward:
        """Call ``callback(source, level, filename, line_number, message)`` for each record; returns its handle."""
        handler = _Forward(callback)
        logging.getLogger().addHandler(handler)
        return handler

    def remove_logger(self, handle: _Forward) -> None:
        logging.getLogger().removeHandler(handle)

    def set_log_enabled(self, enabled: bool) -> None:
        """Turn the ``carb`` log (``carb.log_*``, compat mode's messages) on or off."""
        log.disabled = not enabled

    def is_log_enabled(self) -> bool:
        return not log.disabled

    def set_level_threshold(self, level: int) -> None:
        """Drop ``carb`` records below the carb ``level`` (``LEVEL_*``)."""
        log.setLevel(_TO_PYTHON[int(level)])

    def get_level_threshold(self) -> int:
        return _carb_level(log.getEffectiveLevel())


_logging = ILogging()


def acquire_logging() -> ILogging:
    """The process's logging interface."""
    return _logging


def log_verbose(msg: str) -> None:
    """Log ``msg`` at carb's verbose level (Python's DEBUG) on the ``carb`` logger."""
    log.debug(msg)


def log_fatal(msg: str) -> None:
    """Log ``msg`` at carb's fatal level (Python's CRITICAL) on the ``carb`` logger."""
    log.critical(msg)


# ---- carb.get_framework ---------------------------------------------------------------------------------------------
class Framework(CompatObject):
    """carb.Framework: graphsdg loads no native Carbonite plugins."""

    _compat_name = "carb.Framework"

    def get_plugins(self) -> list:
        """No plugins are loaded."""
        return []

    def load_plugins(self, loaded_file_wildcards: list[str] | None = None, search_paths: list[str] | None = None
                     ) -> None:
        raise CompatError(f"carb.Framework.load_plugins({loaded_file_wildcards!r}): graphsdg's compat mode loads no "
                          f"native Carbonite plugins (graphsdg runs without Kit). {PORTING}")


_framework = Framework()


def get_framework() -> Framework:
    """The process's Carbonite framework stand-in."""
    return _framework


def modules() -> list[types.ModuleType]:
    """``carb.tokens``, ``carb.profiler``, ``carb.logging`` and ``carb``'s ``get_framework``, ``log_verbose``,
    ``log_fatal``."""
    tokens = CompatModule("carb.tokens", get_tokens_interface=get_tokens_interface,
                          acquire_tokens_interface=get_tokens_interface, ITokens=ITokens,
                          RESOLVE_FLAG_NONE=RESOLVE_FLAG_NONE,
                          RESOLVE_FLAG_LEAVE_TOKEN_IF_NOT_FOUND=RESOLVE_FLAG_LEAVE_TOKEN_IF_NOT_FOUND)
    profiler = CompatModule("carb.profiler", begin=begin, end=end, profile=profile,
                            is_profiler_active=is_profiler_active,
                            supports_dynamic_source_locations=supports_dynamic_source_locations,
                            acquire_profiler_interface=acquire_profiler_interface, IProfiler=IProfiler)
    logging_module = CompatModule("carb.logging", acquire_logging=acquire_logging, ILogging=ILogging,
                                  LEVEL_VERBOSE=LEVEL_VERBOSE, LEVEL_INFO=LEVEL_INFO, LEVEL_WARN=LEVEL_WARN,
                                  LEVEL_ERROR=LEVEL_ERROR, LEVEL_FATAL=LEVEL_FATAL)
    carb = CompatModule("carb", get_framework=get_framework, Framework=Framework, log_verbose=log_verbose,
                        log_fatal=log_fatal)
    return [tokens, profiler, logging_module, carb]
