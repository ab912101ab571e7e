"""Run a user's script the way ``graphsdg run`` does. Optional Isaac compat, seed and output overrides.

Scripts written for Isaac Sim's Script Editor schedule a coroutine with
``asyncio.ensure_future(...)`` and rely on Kit's running loop; after the script
body returns, this runner drives the event loop until those tasks finish.

:func:`build_script` runs a script only up to its first capture (``graphsdg graph``):
the orchestrator's capture calls stop it, and disk backends write nothing.
"""
from __future__ import annotations

import asyncio
import contextlib
import os
import runpy
import sys
from typing import Iterator, Sequence

from graphsdg import orchestrator, rng
from graphsdg.base import settings_store as settings
from graphsdg.io.location import normalize
from graphsdg.io.write_queue import get_write_queue
from graphsdg.render.attachments import attachments

# the orchestrator's entry points that capture frames (build_script turns them into a stop)
CAPTURE_CALLS = ("step", "step_async", "run", "run_async", "run_until_complete", "run_until_complete_async",
                 "preview", "preview_async", "resume")


class ScriptStopped(Exception):
    """Raised inside a script by a capture call while the script is only being built."""

    def __init__(self, call: str) -> None:
        super().__init__(f"the script reached orchestrator.{call}()")
        self.call = call


def _configure(path: str, compat: str | None, seed: int | None, out_dir: str | None, frames: int | None,
               resolution_scale: float | None = None) -> bool:
    """Apply the run's overrides; return whether the Isaac module names were installed for this script."""
    if not os.path.isfile(path):
        raise FileNotFoundError(f"script {path!r} does not exist")
    if compat not in (None, "isaac"):
        raise ValueError(f"unknown compat mode {compat!r}; available: 'isaac'")
    if seed is not None:
        rng.set_global_seed(seed)
    if out_dir is not None:
        # relative writer output dirs (graphsdg's default) resolve under this root: a folder or an s3:// prefix
        settings.set("/omni/replicator/backends/disk/root_dir", normalize(out_dir))
    if frames is not None:
        settings.set("/graphsdg/run/numFrames", int(frames))
    if resolution_scale is not None:
        settings.set("/graphsdg/render/resolutionScale", float(resolution_scale))
    installed_here = False
    if compat == "isaac":
        from graphsdg.compat import isaac
        installed_here = not isaac.is_installed()
        isaac.install()
    return installed_here


def _uninstall_compat(installed_here: bool) -> None:
    if installed_here:   # the Isaac names lived for this script only
        from graphsdg.compat import isaac
        isaac.uninstall()


def _execute(path: str, args: Sequence[str]) -> None:
    loop = asyncio.new_event_loop()
    asyncio.set_event_loop(loop)
    saved_argv, saved_path = sys.argv, list(sys.path)
    sys.argv = [path, *args]
    sys.path.insert(0, os.path.dirname(os.path.abspath(path)))
    try:
        runpy.run_path(path, run_name="__main__")
        pending = [t for t in asyncio.all_tasks(loop) if not t.done()]
        while pending:
            loop.run_until_complete(asyncio.gather(*pending))
            pending = [t for t in asyncio.all_tasks(loop) if not t.done()]
    finally:
        for task in asyncio.all_tasks(loop):
            task.cancel()
        sys.argv, sys.path[:] = saved_argv, saved_path
        asyncio.set_event_loop(None)
        loop.close()


def run_script(path: str, args: Sequence[str] = (), compat: str | None = None, seed: int | None = None,
               out_dir: str | None = None, frames: int | None = None,
               resolution_scale: float | None = None) -> None:
    """Execute ``path`` as ``__main__`` with ``sys.argv = [path, *args]``."""
    installed_here = _configure(path, compat, seed, out_dir, frames, resolution_scale)
    try:
        _execute(path, args)
        orchestrator.wait_until_complete()
    finally:
        _uninstall_compat(installed_here)


@contextlib.contextmanager
def capture_stopped() -> Iterator[None]:
    """Within the block, orchestrator capture calls raise :class:`ScriptStopped` and disk writes are dropped."""
    saved = {name: getattr(orchestrator, name) for name in CAPTURE_CALLS}

    def stopper(name: str):
        def stop(*args, **kwargs):
            raise ScriptStopped(name)
        return stop

    discard = settings.get("/graphsdg/io/discardWrites", False)
    settings.set("/graphsdg/io/discardWrites", True)
    attached_before = set(map(id, attachments.writers))
    for name in CAPTURE_CALLS:
        setattr(orchestrator, name, stopper(name))
    try:
        yield
    finally:
        for name, fn in saved.items():
            setattr(orchestrator, name, fn)
        # the stopped script's writers flush what they hold (aggregate files) while writes are still dropped;
        # left attached, they would write it at exit, into the working folder
        for writer in [w for w in attachments.writers if id(w) not in attached_before]:
            writer.detach()
        get_write_queue().wait_until_done()
        settings.set("/graphsdg/io/discardWrites", discard)


def build_script(path: str, args: Sequence[str] = (), compat: str | None = None,
                 seed: int | None = None) -> str | None:
    """Run ``path`` up to its first capture call without rendering or writing anything.

    Returns the name of the capture call that stopped it (``"run"``, ``"step"``...),
    or None if the script ended without capturing. The graph it built is
    ``graphsdg.graph.current_graph()``.
    """
    installed_here = _configure(path, compat, seed, None, None)
    try:
        with capture_stopped():
            try:
                _execute(path, args)
            except ScriptStopped as stop:
                return stop.call
        return None
    finally:
        _uninstall_compat(installed_here)
