"""Which ray caster the sensors use. ``mj_multiRay`` on CPU threads, or Warp on a GPU.

Chosen like the render backend, from the setting ``/graphsdg/sensors/rayBackend``:

* ``cpu``: :class:`~graphsdg.sensors.ray_caster.CpuRayCaster` (``/graphsdg/sensors/rayThreads`` threads);
* ``gpu``: :class:`~graphsdg.sensors.warp_rays.WarpRayCaster` (the scene's triangles and primitives in world
  coordinates under BVHs, :mod:`graphsdg.sensors.warp_ray_scene`, on ``cuda:0``); it needs the ``graphsdg[gpu]``
  extra and a CUDA GPU, and raises naming what is missing;
* ``auto`` (default): ``gpu`` where it can run, else ``cpu``.

Both return the same :class:`~graphsdg.sensors.ray_caster.RayHits` for the same rays.

Example:
    >>> from graphsdg.base import settings_store
    >>> settings_store.set("/graphsdg/sensors/rayBackend", "cpu")
    >>> ray_caster().name
    'cpu'
    >>> settings_store.set("/graphsdg/sensors/rayBackend", "auto")
"""
from __future__ import annotations

import importlib.util
import sys
from typing import Any

from graphsdg.base import settings_store as settings
from graphsdg.sensors.ray_caster import CpuRayCaster

BACKEND_KEY = "/graphsdg/sensors/rayBackend"
GPU_MODULES = {"warp": "warp-lang==1.19.0", "mujoco_warp": "mujoco-warp==3.17.0"}
INSTALL_HINT = "pip install 'graphsdg[gpu]' (Python >= 3.12)"


class RayBackendUnavailableError(RuntimeError):
    """The GPU ray backend was asked for on a machine that cannot run it (the message says what is missing)."""


def _installed(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except ImportError:
        return False


def gpu_missing() -> list[str]:
    """What this machine lacks to cast rays on the GPU (empty when it can)."""
    if sys.version_info < (3, 12):
        return [f"Python >= 3.12 for MuJoCo Warp (this is {sys.version_info.major}.{sys.version_info.minor})"]
    absent = [pin for name, pin in GPU_MODULES.items() if not _installed(name)]
    if absent:
        return [f"the gpu extra ({', '.join(absent)} not installed): {INSTALL_HINT}"]
    try:
        import warp as wp

        wp.init()
        if wp.get_cuda_device_count() < 1:
            return ["a CUDA GPU (Warp finds no CUDA device)"]
    except Exception as exc:   # a broken driver is "no usable GPU"
        return [f"a working CUDA GPU (Warp failed: {exc})"]
    return []


_casters: dict[str, Any] = {}
_machine_lacks: list[list[str]] = []


def resolve_ray_backend() -> str:
    """``cpu`` or ``gpu`` for the current setting on this machine (raises when ``gpu`` cannot run)."""
    wanted = str(settings.get(BACKEND_KEY, "auto")).strip().lower()
    if wanted == "cpu":
        return "cpu"
    if not _machine_lacks:
        _machine_lacks.append(gpu_missing())
    lacks = _machine_lacks[0]
    if wanted == "gpu" and lacks:
        raise RayBackendUnavailableError(f"setting {BACKEND_KEY} = 'gpu' needs " + "; and ".join(lacks)
                                         + f". Set {BACKEND_KEY} to 'cpu' (or 'auto') to cast rays on the CPU.")
    return "cpu" if lacks else "gpu"


def ray_caster() -> Any:
    """The ray caster the settings choose (one per kind per process)."""
    kind = resolve_ray_backend()
    threads = int(settings.get("/graphsdg/sensors/rayThreads", 0) or 0)
    key = f"{kind}:{threads}"
    caster = _casters.get(key)
    if caster is None:
        if kind == "gpu":
            from graphsdg.sensors.warp_rays import WarpRayCaster

            caster = WarpRayCaster()
        else:
            caster = CpuRayCaster(threads or None)
        _casters[key] = caster
    return caster
