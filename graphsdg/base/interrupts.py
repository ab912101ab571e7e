"""Ctrl-C (SIGINT) and SIGTERM during capture: finish the frame, then stop.

While ``orchestrator.step()`` runs, the two signals are held until the frame has
been handed whole to the writers, then raised (``KeyboardInterrupt``, or
``SystemExit(143)`` for SIGTERM): a script's own step loop stops between frames,
never with half a frame's files queued. During ``orchestrator.run()`` a signal
asks the run to stop after the current frame; ``run()`` then flushes (writers'
``on_final_frame``, the write queue, the run-state file with status
``"interrupted"``) and raises the same exception. A second signal while that
happens interrupts at once.

Only the main thread receives signals, and handlers a script installed itself are
left alone: then nothing here changes how the signal behaves.

Example:
    >>> with deferred() as held:
    ...     pass                      # a capture that must not be cut in half
    >>> held is None or held.received is None
    True
"""
from __future__ import annotations

import _signal   # signal's C functions: the module's wrappers turn every number into an enum (~30 calls a step)
import signal
import threading
from typing import Callable

_SIGNALS = (int(signal.SIGINT), int(signal.SIGTERM))


class HeldSignals:
    """The signals that arrived while a :func:`deferred` block ran."""

    def __init__(self, on_signal: Callable[[int], None] | None) -> None:
        self.received: int | None = None
        self.on_signal = on_signal
        self.saved: dict[int, object] = {}

    def _handler(self, signum: int, frame: object) -> None:
        if self.received is not None:          # a second signal: do not wait any longer
            self.restore()
            raise_for(signum)
        self.received = signum
        if self.on_signal is not None:
            self.on_signal(signum)

    def restore(self) -> None:
        for sig, handler in self.saved.items():
            _signal.signal(sig, handler)
        self.saved.clear()


_active: HeldSignals | None = None
last_signal: int | None = None     # the signal :func:`raise_for` last raised (the exit hook reports it)


def _default(sig: int, handler: object) -> bool:
    return handler is signal.default_int_handler if sig == signal.SIGINT else handler == signal.SIG_DFL


def deferred(on_signal: Callable[[int], None] | None = None) -> "_Deferred":
    """A ``with`` block holding SIGINT/SIGTERM; ``as`` gives the :class:`HeldSignals`, or ``None`` when an
    enclosing block already holds them (or this is not the main thread). The caller decides what to do
    afterwards (see :func:`raise_for`)."""
    return _Deferred(on_signal)


class _Deferred:
    """:func:`deferred`'s block (a class: every step opens one, and a generator context manager costs
    several times as much)."""

    __slots__ = ("on_signal", "held")

    def __init__(self, on_signal: Callable[[int], None] | None) -> None:
        self.on_signal, self.held = on_signal, None

    def __enter__(self) -> HeldSignals | None:
        global _active
        if _active is not None or threading.current_thread() is not threading.main_thread():
            return None
        held = HeldSignals(self.on_signal)
        for sig in _SIGNALS:
            current = _signal.getsignal(sig)
            if _default(sig, current):
                held.saved[sig] = current
                _signal.signal(sig, held._handler)
        _active = self.held = held
        return held

    def __exit__(self, *exc: object) -> bool:
        global _active
        if self.held is not None:
            _active = None
            self.held.restore()
        return False


def raise_for(signum: int) -> None:
    """Raise what the signal would have: ``KeyboardInterrupt`` for SIGINT, ``SystemExit(128 + n)`` otherwise."""
    global last_signal
    last_signal = signum
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise SystemExit(128 + int(signum))


__all__ = ["deferred", "raise_for", "HeldSignals"]
