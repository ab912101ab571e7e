"""Warp's kernel cache for the pbr backend: one folder a node, each kernel compiled once.

Nearly all of a fresh GPU machine's first pbr frame is Warp compiling mujoco-warp-pbr's render megakernel
(one module specialised on the scene: light count, geom types, baked settings; docs/performance.md, "The pbr
kernels' first compile"), and every process that starts meanwhile compiles it again. This module makes that
once a node:

* **One cache folder.** ``GRAPHSDG_KERNEL_CACHE`` (else Warp's own: ``WARP_CACHE_PATH`` or
  ``~/.cache/warp``) for every graphsdg process of the node, Ray workers included (the variable is
  forwarded to them); a container image can bake it in.
* **Compiled once.** :func:`configure_warp` wraps Warp's module compile step in a file lock per module
  (``<module folder>.lock`` beside it): a process that finds another compiling the same module waits, then
  loads what it wrote. Different modules still compile in parallel.
* **One binary format.** CUDA modules are always compiled to a CUBIN for the GPU's own architecture
  (``warp.config.cuda_output = "cubin"``), never to PTX that the driver would compile again at load: the
  files a GPU process looks for are then those a machine without a GPU writes ahead
  (:func:`compile_ahead`), and every process on one GPU model runs the same binary.
* **Side by side.** :func:`compile_in_background` compiles a list of modules into the cache in threads
  (NVRTC runs outside the interpreter lock), so the pbr renderer's first frame finds its scene-independent
  modules compiled while it builds its scene.
* **Compiled ahead.** ``graphsdg warmup`` (:mod:`graphsdg.jobs.warmup`) renders its scenes one frame each
  so their kernels land in the cache; with ``--arch`` it also compiles every module those frames launched
  for that GPU architecture, which needs no GPU (NVRTC runs on the CPU): a CPU build machine can bake the
  cache of an image. :class:`LaunchRecorder` notes the modules and the block sizes the launches asked for.

None of this changes a pixel: the cache holds binaries of the same kernels, so a run never changes
backend or kernels half way. The settings are Warp's (``warp.config``), set before Warp compiles anything.

Example:
    >>> cache_root({"GRAPHSDG_KERNEL_CACHE": "/opt/kernels", "WARP_CACHE_PATH": "/tmp/w"})
    '/opt/kernels'
    >>> cache_root({}) is None
    True
"""
from __future__ import annotations

import contextlib
import fcntl
import logging
import os
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Iterator

log = logging.getLogger("graphsdg.render")

CACHE_ENV = "GRAPHSDG_KERNEL_CACHE"
#: what the cache is told about its modules since this process started (tests and ``graphsdg warmup`` read it)
stats: dict[str, float] = {"compiled": 0, "cached": 0, "lock_wait_s": 0.0}
_stats_lock = threading.Lock()
_configured: str | None = None


def cache_root(environ=os.environ) -> str | None:
    """The cache folder graphsdg asks Warp for: ``GRAPHSDG_KERNEL_CACHE``, else ``WARP_CACHE_PATH``, else
    None (Warp's default, ``~/.cache/warp``). Warp adds a folder per Warp version inside it."""
    return environ.get(CACHE_ENV) or environ.get("WARP_CACHE_PATH") or None


@contextlib.contextmanager
def file_lock(path: str) -> Iterator[float]:
    """Hold an exclusive lock on ``path`` (created if missing); yields the seconds spent waiting for it.

    ``flock`` locks belong to one open file, so two threads of one process exclude each other as two
    processes do; the lock goes with the process if it dies."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    start = time.perf_counter()
    with open(path, "a+b") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield time.perf_counter() - start
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _lock_path(module: Any, output_dir: str | os.PathLike | None, options: dict | None) -> str:
    """The lock file of one module variant's cache folder: ``<folder>.lock`` beside it."""
    import warp as wp
    if output_dir is None:
        block_dim = (options or {}).get("block_dim", module.options.get("block_dim"))
        output_dir = os.path.join(wp.config.kernel_cache_dir, module.get_module_identifier(block_dim=block_dim))
    return os.path.normpath(os.fspath(output_dir)) + ".lock"


def _install_compile_lock() -> None:
    """Wrap Warp's ``Module._compile`` (which returns False when the cache already holds the binary) in the
    module's file lock, once per process."""
    from warp._src import context
    original = context.Module._compile
    if getattr(original, "graphsdg_locked", False):
        return

    def compile_once(self, device=None, output_dir=None, output_name=None, output_arch=None, use_ptx=None,
                     options=None):
        with file_lock(_lock_path(self, output_dir, options)) as waited:
            compiled = original(self, device, output_dir, output_name, output_arch, use_ptx, options)
        with _stats_lock:
            stats["compiled" if compiled else "cached"] += 1
            stats["lock_wait_s"] += waited
        return compiled

    compile_once.graphsdg_locked = True
    context.Module._compile = compile_once


def configure_warp() -> str:
    """Point Warp at the node's cache folder, pin CUBIN output and lock each module's compile; return the
    cache folder Warp uses (its version folder). Call before Warp compiles anything; again is a no-op."""
    global _configured
    import warp as wp
    root = cache_root()
    wp.config.cuda_output = "cubin"
    from warp._src import build, context
    if context.runtime is None:            # before wp.init(): Warp resolves the folder itself
        if root:
            wp.config.kernel_cache_dir = root
        wp.init()
    elif root and _configured is None:     # Warp already started (the backend's GPU probe): move the cache
        build.init_kernel_cache(root)
    _install_compile_lock()
    _configured = wp.config.kernel_cache_dir
    return _configured


@dataclass
class LaunchRecorder:
    """Notes every Warp module a block of code launches, with the block size each launch asked for (what a
    CUDA launch would compile), while patched into ``warp.launch``; a context manager."""

    variants: dict[tuple[int, int], tuple[Any, int]] = field(default_factory=dict)

    def __enter__(self) -> "LaunchRecorder":
        import warp as wp
        self._original = wp.launch

        def recorded_launch(kernel, *args, **kwargs):
            block_dim = kwargs.get("block_dim")
            module = getattr(kernel, "module", None)
            if module is not None:
                size = int(block_dim) if block_dim and int(block_dim) > 0 else int(module.options["block_dim"])
                self.variants[(id(module), size)] = (module, size)
            return self._original(kernel, *args, **kwargs)

        wp.launch = recorded_launch
        return self

    def __exit__(self, *exc) -> None:
        import warp as wp
        wp.launch = self._original


def _compile_variant(module: Any, block_dim: int, device: Any, arch: int | None = None) -> str:
    """Compile one module variant into the cache (nothing when it is there); the binary's path. ``device`` a
    Warp device (its architecture unless ``arch``), or None with ``arch`` for a GPU this machine lacks."""
    import warp as wp
    module.get_module_hash(block_dim)          # the variant's hash names its folder; Module.load's options
    options = module.resolved_options[block_dim]
    folder = os.path.join(wp.config.kernel_cache_dir, module.get_module_identifier(block_dim=block_dim))
    if device is None:
        name = module._get_compile_output_name(None, arch, "", use_ptx=False, block_dim=block_dim)
        module._compile(None, folder, name, arch, False, options)
    else:
        arch = module._get_compile_arch(device)
        name = module._get_compile_output_name(device, block_dim=block_dim)
        module._compile(device, folder, name, arch, options=options)
    return os.path.join(folder, name)


def compile_ahead(recorder: LaunchRecorder, archs: list[int]) -> list[str]:
    """Compile every module variant ``recorder`` saw for each CUDA architecture in ``archs`` (90: H100 and
    H200) into the cache, as CUBINs, without a GPU; returns the binaries' paths (already there or new)."""
    configure_warp()
    return [_compile_variant(module, block_dim, None, arch)
            for module, block_dim in recorder.variants.values() for arch in archs]


def compile_in_background(module_names: tuple[str, ...], device: str) -> list[threading.Thread]:
    """Start compiling the named Warp modules (the variant a launch that names no block size uses) for
    ``device`` into the cache, one thread each, and return the threads. Names of Python modules not
    imported yet are skipped (Warp would make them an empty module).

    A process's first frame compiles its modules one after another as it first launches each; compiled
    beside each other ahead of that (NVRTC runs outside the interpreter lock, and Warp allows modules to
    compile in parallel), the frame finds them in the cache. The threads only write the cache: loading stays
    with the thread that launches (Warp's per-module load state is not shared across threads), and a module
    a thread is still compiling is waited for by the module's file lock. A failure is logged and left to the
    launch that needs the module, which compiles it again and raises."""
    import warp as wp
    configure_warp()
    target = wp.get_device(device)

    def compile_one(name: str) -> None:
        try:
            module = wp.get_module(name)
            # the block size a launch that names none runs at: the module's on a GPU, one on the CPU
            block_dim = 1 if target.is_cpu else int(module.options["block_dim"])
            _compile_variant(module, block_dim, target)
        except Exception as exc:  # noqa: BLE001 - the launch that needs the module reports its own error
            log.warning("compiling Warp module %s ahead failed: %s", name, exc)

    threads = [threading.Thread(target=compile_one, args=(name,), name=f"graphsdg-compile-{name}", daemon=True)
               for name in module_names if name in sys.modules]
    for thread in threads:
        thread.start()
    return threads
