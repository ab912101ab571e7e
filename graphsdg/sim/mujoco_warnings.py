"""MuJoCo's warnings go to Python's logging (``graphsdg.mujoco``), each distinct message once.

MuJoCo's default handler prints warnings and appends them to ``MUJOCO_LOG.TXT``
in the working folder, which a library must not litter. :func:`route_warnings`
installs a handler that logs instead, unless the program set its own.
"""
from __future__ import annotations

import logging

import mujoco

log = logging.getLogger("graphsdg.mujoco")
_seen: set[str] = set()


def _warn(message: str) -> None:
    key = message.split(" Time =")[0]   # the same warning at another time is the same warning
    if key not in _seen:   # solver warnings repeat every step; once says it
        _seen.add(key)
        log.warning("MuJoCo: %s", message)


def route_warnings() -> None:
    """Send MuJoCo's warnings to the ``graphsdg.mujoco`` logger (kept if a handler is already set)."""
    if mujoco.get_mju_user_warning() is None:
        mujoco.set_mju_user_warning(_warn)
