"""Run a user's script the way ``graphsdg run`` does: optional Isaac compat, seed and output overrides.

Scripts written for Isaac Sim's Script Editor schedule a coroutine with
``asyncio.ensure_future(...)`` and rely on Kit's running loop; after the script
body returns, this runner drives the event loop until those tasks finish.
"""
from __future__ import annotations

import asyncio
import os
import runpy
import sys
from typing import Sequence

from graphsdg import orchestrator, rng, settings


def run_script(path: str, args: Sequence[str] = (), compat: str | None = None, seed: int | None = None,
               out_dir: str | None = None, frames: int | None = None,
               resolution_scale: float | None = None) -> None:
    """Execute ``path`` as ``__main__`` with ``sys.argv = [path, *args]``."""
    if not os.path.isfile(path):
        raise FileNotFoundError(f"script {path!r} does not exist")
    if compat not in (None, "isaac"):
        raise ValueError(f"unknown compat mode {compat!r}; available: 'isaac'")
    if seed is not None:
        rng.set_global_seed(seed)
    if out_dir is not None:
        # relative writer output dirs (graphsdg's default) resolve under this root
        settings.set("/omni/replicator/backends/disk/root_dir", os.path.abspath(out_dir))
    if frames is not None:
        settings.set("/graphsdg/run/numFrames", int(frames))
    if resolution_scale is not None:
        settings.set("/graphsdg/render/resolutionScale", float(resolution_scale))
    installed_here = False
    if compat == "isaac":
        from graphsdg.compat import isaac
        installed_here = not isaac.is_installed()
        isaac.install()
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
        orchestrator.wait_until_complete()
    finally:
        sys.argv, sys.path[:] = saved_argv, saved_path
        asyncio.set_event_loop(None)
        loop.close()
        if installed_here:   # the Isaac names lived for this script only
            from graphsdg.compat import isaac
            isaac.uninstall()
