"""What this process uses right now: memory, CPU time and its GPU. Each figure is read from the system.

* memory (:func:`memory_usage`): resident set (RSS), virtual size (VMS) and unique
  set (USS: pages no other process shares) in bytes, from ``/proc/self``. Where
  there is no ``/proc`` (not Linux) RSS is the peak resident size from
  ``getrusage`` and VMS and USS are 0.
* CPU (:class:`ProcessCpuMeter`): the process's CPU time (user + system, every
  thread) over the wall time since the last reading, in percent of one core
  (two busy cores read as two hundred).
* GPUs (:func:`gpu_devices`): each NVIDIA GPU's name, the memory in use on it and
  the part of that this process holds, from NVML (``libnvidia-ml``, which comes
  with the driver; no package needed). Without a driver the list is empty. A
  process's own share is found by process id, so inside a container whose
  process ids differ from the host's it reads 0.

Example:
    >>> usage = memory_usage()
    >>> usage.rss > 0 and usage.vms >= usage.rss
    True
"""
from __future__ import annotations

import ctypes
import os
import resource
import sys
import time
from dataclasses import dataclass


@dataclass(frozen=True)
class MemoryUsage:
    """A process's memory in bytes: resident, virtual and unique set sizes."""

    rss: int
    vms: int
    uss: int


def _proc_memory() -> MemoryUsage | None:
    try:
        with open("/proc/self/statm", encoding="ascii") as f:
            size_pages, resident_pages = (int(v) for v in f.read().split()[:2])
    except OSError:
        return None
    page = os.sysconf("SC_PAGE_SIZE")
    uss = 0
    try:
        # smaps_rollup sums every mapping's private pages (clean, dirty, huge) in kB
        with open("/proc/self/smaps_rollup", encoding="ascii") as f:
            for line in f:
                if line.startswith(("Private_Clean:", "Private_Dirty:", "Private_Hugetlb:")):
                    uss += int(line.split()[1]) * 1024
    except OSError:
        uss = 0
    return MemoryUsage(rss=resident_pages * page, vms=size_pages * page, uss=uss)


def memory_usage() -> MemoryUsage:
    """This process's memory now (see the module docstring for where each value comes from)."""
    usage = _proc_memory()
    if usage is not None:
        return usage
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return MemoryUsage(rss=peak if sys.platform == "darwin" else peak * 1024, vms=0, uss=0)


class ProcessCpuMeter:
    """Process CPU use in percent of one core since the previous :meth:`percent` (or since creation)."""

    def __init__(self) -> None:
        self._last = self._now()

    @staticmethod
    def _now() -> tuple[float, float]:
        t = os.times()
        return t.user + t.system, time.perf_counter()

    def percent(self) -> float:
        """CPU time over wall time since the last reading, x100 (0.0 when no wall time passed)."""
        cpu, wall = self._now()
        last_cpu, last_wall = self._last
        self._last = (cpu, wall)
        elapsed = wall - last_wall
        return 100.0 * (cpu - last_cpu) / elapsed if elapsed > 0 else 0.0


def cpu_count() -> int:
    """Logical CPUs of the machine."""
    return os.cpu_count() or 1


@dataclass(frozen=True)
class GpuDevice:
    """One GPU: its name, the bytes in use on it (every process) and the bytes this process holds."""

    name: str
    used_bytes: int
    process_bytes: int


class _NvmlMemory(ctypes.Structure):
    _fields_ = [("total", ctypes.c_ulonglong), ("free", ctypes.c_ulonglong), ("used", ctypes.c_ulonglong)]


class _NvmlProcessInfo(ctypes.Structure):
    _fields_ = [("pid", ctypes.c_uint), ("usedGpuMemory", ctypes.c_ulonglong), ("gpuInstanceId", ctypes.c_uint),
                ("computeInstanceId", ctypes.c_uint)]


_NVML_SUCCESS = 0
_NVML_INSUFFICIENT_SIZE = 7
_nvml: ctypes.CDLL | None | bool = None   # None: not tried yet; False: no NVML here


def _nvml_library() -> ctypes.CDLL | None:
    global _nvml
    if _nvml is None:
        try:
            lib = ctypes.CDLL("libnvidia-ml.so.1")
            _nvml = lib if lib.nvmlInit_v2() == _NVML_SUCCESS else False
        except (OSError, AttributeError):
            _nvml = False
    return _nvml or None


def _process_bytes(lib: ctypes.CDLL, handle: ctypes.c_void_p) -> int:
    """GPU memory this process holds on the device, over its compute and graphics contexts."""
    pid, total = os.getpid(), 0
    for fn_name in ("nvmlDeviceGetComputeRunningProcesses_v3", "nvmlDeviceGetGraphicsRunningProcesses_v3"):
        fn = getattr(lib, fn_name, None)
        if fn is None:
            continue
        count = ctypes.c_uint(0)
        status = fn(handle, ctypes.byref(count), None)
        if status not in (_NVML_SUCCESS, _NVML_INSUFFICIENT_SIZE) or count.value == 0:
            continue
        count.value += 8   # processes may start between the two calls
        infos = (_NvmlProcessInfo * count.value)()
        if fn(handle, ctypes.byref(count), infos) != _NVML_SUCCESS:
            continue
        # NVML reports an unknown amount (no privileges to read it) as all ones
        total += sum(int(i.usedGpuMemory) for i in infos[:count.value]
                     if i.pid == pid and i.usedGpuMemory < (1 << 63))
    return total


def gpu_devices() -> list[GpuDevice]:
    """The NVIDIA GPUs NVML sees, in its order (empty without an NVIDIA driver)."""
    lib = _nvml_library()
    if lib is None:
        return []
    count = ctypes.c_uint(0)
    if lib.nvmlDeviceGetCount_v2(ctypes.byref(count)) != _NVML_SUCCESS:
        return []
    devices = []
    for index in range(count.value):
        handle = ctypes.c_void_p()
        if lib.nvmlDeviceGetHandleByIndex_v2(index, ctypes.byref(handle)) != _NVML_SUCCESS:
            continue
        name = ctypes.create_string_buffer(96)
        memory = _NvmlMemory()
        lib.nvmlDeviceGetName(handle, name, 96)
        used = int(memory.used) if lib.nvmlDeviceGetMemoryInfo(handle, ctypes.byref(memory)) == 0 else 0
        devices.append(GpuDevice(name=name.value.decode(errors="replace"), used_bytes=used,
                                 process_bytes=_process_bytes(lib, handle)))
    return devices
