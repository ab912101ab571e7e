"""Which GPU each process of a job renders on. The host's GPUs, their share of processes, and each process's
environment.

A process renders on one GPU: its CUDA device (Warp, the pbr backend) and its EGL device (the classic
rasteriser, pbr's unoccluded footprints) must be that GPU, chosen before anything in the process
initialises CUDA or EGL. graphsdg does it the way Ray does for its actors: the parent gives each process
``CUDA_VISIBLE_DEVICES`` naming one GPU (by its ``nvidia-smi`` index, with ``CUDA_DEVICE_ORDER=PCI_BUS_ID``
so CUDA numbers the GPUs as ``nvidia-smi`` does) before it starts, CUDA then shows that GPU as
``cuda:0``, and at import graphsdg points EGL at the same GPU
(:func:`graphsdg.render.egl_device.bind_visible_gpu`).

* :func:`host_gpus` lists the machine's NVIDIA GPUs (``nvidia-smi``, or the driver's ``/proc`` files);
* :func:`visible_gpus` applies this process's ``CUDA_VISIBLE_DEVICES`` to them, as CUDA does;
* :func:`choose_gpus` takes the first K of them, or fails naming both counts;
* :func:`gpu_of_process` deals processes out to the chosen GPUs in turn, :func:`process_environment` is
  what one process's environment gets;
* :func:`gpu_share` is the GPU fraction a Ray worker asks for.

Example:
    >>> gpus = parse_nvidia_smi("0, GPU-aa, 00000000:18:00.0, NVIDIA H100\\n1, GPU-bb, 00000000:2A:00.0, NVIDIA H100")
    >>> [g.index for g in visible_gpus(gpus, "1")], [gpu_of_process(i, 2) for i in range(5)]
    ([1], [0, 1, 0, 1, 0])
    >>> process_environment(gpus[1])["CUDA_VISIBLE_DEVICES"]
    '1'
"""
from __future__ import annotations

import glob
import math
import os
import subprocess
from dataclasses import dataclass
from typing import Callable, Sequence

from graphsdg.base.cpu_share import usable_cores
from graphsdg.render.egl_device import BIND_ENV   # at import a process given BIND_ENV renders on that GPU

#: the most processes a default run puts on one GPU whose processes take turns (no CUDA MPS), and on one whose
#: processes' kernels run side by side under MPS (docs/performance.md, "Every GPU of the host")
MAX_DEFAULT_PROCESSES_PER_GPU = 8
MAX_DEFAULT_PROCESSES_PER_GPU_MPS = 16


class GpuCountError(ValueError):
    """More GPUs asked for than this machine shows (the message names both counts)."""


@dataclass(frozen=True)
class GpuInfo:
    """One NVIDIA GPU of the host: its ``nvidia-smi`` index, UUID (``GPU-...``), PCI address and name."""

    index: int
    uuid: str = ""
    pci_bus_id: str = ""
    name: str = ""

    def label(self) -> str:
        """How reports name it: ``GPU 2 (NVIDIA H100 80GB HBM3)``."""
        return f"GPU {self.index}" + (f" ({self.name})" if self.name else "")


def parse_nvidia_smi(text: str) -> list[GpuInfo]:
    """GPUs from ``nvidia-smi --query-gpu=index,uuid,pci.bus_id,name --format=csv,noheader`` output.

    Raises:
        ValueError: a line that is not ``index, uuid, pci address, name``.
    """
    gpus = []
    for line in text.splitlines():
        if not line.strip():
            continue
        fields = [f.strip() for f in line.split(",", 3)]
        if len(fields) != 4 or not fields[0].isdigit():
            raise ValueError(f"unexpected nvidia-smi line {line!r}; expected 'index, uuid, pci.bus_id, name'")
        gpus.append(GpuInfo(int(fields[0]), fields[1], fields[2], fields[3]))
    return sorted(gpus, key=lambda g: g.index)


def _query_nvidia_smi() -> str | None:
    """nvidia-smi's GPU list, or None where it is missing or fails (no driver, no GPU)."""
    try:
        done = subprocess.run(["nvidia-smi", "--query-gpu=index,uuid,pci.bus_id,name", "--format=csv,noheader"],
                              capture_output=True, text=True, timeout=30, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout if done.returncode == 0 else None


def _proc_driver_gpus(root: str = "/proc/driver/nvidia/gpus") -> list[GpuInfo]:
    """GPUs from the NVIDIA driver's ``/proc`` files (where nvidia-smi is missing), in PCI order."""
    gpus = []
    for index, folder in enumerate(sorted(glob.glob(os.path.join(root, "*")))):
        fields = {}
        try:
            with open(os.path.join(folder, "information"), encoding="utf-8") as f:
                for line in f:
                    key, _, value = line.partition(":")
                    fields[key.strip()] = value.strip()
        except OSError:
            continue
        gpus.append(GpuInfo(index, fields.get("GPU UUID", ""), os.path.basename(folder), fields.get("Model", "")))
    return gpus


def host_gpus(query: Callable[[], str | None] | None = None) -> list[GpuInfo]:
    """This machine's NVIDIA GPUs, whatever ``CUDA_VISIBLE_DEVICES`` says (empty without a GPU or driver).

    ``query`` returns nvidia-smi's output (tests pass their own); without it the driver's ``/proc`` files
    are read.
    """
    text = (query or _query_nvidia_smi)()
    if text is not None:
        return parse_nvidia_smi(text)
    return _proc_driver_gpus()


def visible_gpus(gpus: Sequence[GpuInfo], cuda_visible_devices: str | None) -> list[GpuInfo]:
    """The GPUs of ``gpus`` that CUDA shows a process whose ``CUDA_VISIBLE_DEVICES`` is this value, in its order.

    As CUDA reads it: unset (None) shows every GPU; an empty value none; entries are indices or UUIDs
    (``GPU-`` and a unique prefix), and the list stops at the first entry that names no GPU, or one
    already named.

    Example:
        >>> gpus = [GpuInfo(0, "GPU-aa11"), GpuInfo(1, "GPU-bb22"), GpuInfo(2, "GPU-bc33")]
        >>> [g.index for g in visible_gpus(gpus, "2,GPU-aa,7,1")], visible_gpus(gpus, "")
        ([2, 0], [])
    """
    if cuda_visible_devices is None:
        return list(gpus)
    chosen: list[GpuInfo] = []
    for entry in cuda_visible_devices.split(","):
        entry = entry.strip()
        if entry.isdigit():
            match = [g for g in gpus if g.index == int(entry)]
        elif entry.startswith("GPU-"):
            match = [g for g in gpus if g.uuid.startswith(entry)]
        else:
            match = []
        if len(match) != 1 or match[0] in chosen:
            break
        chosen.append(match[0])
    return chosen


def describe_visible(gpus: Sequence[GpuInfo], cuda_visible_devices: str | None) -> str:
    """Where a GPU count came from, for error messages."""
    shown = "unset" if cuda_visible_devices is None else repr(cuda_visible_devices)
    return f"the driver lists {len(gpus)} NVIDIA GPU(s), CUDA_VISIBLE_DEVICES is {shown}"


def choose_gpus(wanted: int, gpus: Sequence[GpuInfo] | None = None,
                cuda_visible_devices: str | None = None, what: str = "--gpus") -> list[GpuInfo]:
    """The first ``wanted`` GPUs this process sees (default: :func:`host_gpus` under its own
    ``CUDA_VISIBLE_DEVICES``).

    Raises:
        GpuCountError: ``wanted`` is more than the GPUs seen, naming both counts.
        ValueError: ``wanted`` is not a positive integer.
    """
    if isinstance(wanted, bool) or not isinstance(wanted, int) or wanted < 1:
        raise ValueError(f"{what} must be a positive integer, got {wanted!r}")
    if gpus is None:
        gpus = host_gpus()
        cuda_visible_devices = os.environ.get("CUDA_VISIBLE_DEVICES")
    seen = visible_gpus(gpus, cuda_visible_devices)
    if wanted > len(seen):
        raise GpuCountError(f"{what} {wanted} asks for {wanted} GPU(s) but this machine has {len(seen)} "
                            f"({describe_visible(gpus, cuda_visible_devices)})")
    return list(seen[:wanted])


def check_egl_sees(chosen: Sequence[GpuInfo], egl_cuda_ids: Sequence[int | None], what: str = "--gpus") -> None:
    """Fail when EGL shows fewer NVIDIA devices than the GPUs chosen (EGL's vendor library missing, say),
    naming both counts; ``egl_cuda_ids`` is :func:`graphsdg.render.egl_device.egl_cuda_devices` here.

    Raises:
        GpuCountError: EGL shows fewer NVIDIA devices than ``len(chosen)``.
    """
    nvidia = [c for c in egl_cuda_ids if c is not None]
    if len(nvidia) < len(chosen):
        raise GpuCountError(f"{what} {len(chosen)} asks for {len(chosen)} GPU(s) but EGL sees {len(nvidia)} "
                            f"NVIDIA device(s) among its {len(egl_cuda_ids)} (CUDA sees "
                            f"{', '.join(g.label() for g in chosen)}); the classic rasteriser could not draw on "
                            f"them: check the NVIDIA EGL vendor library (__EGL_VENDOR_LIBRARY_FILENAMES)")


def gpu_of_process(process: int, gpus: int) -> int:
    """The position, among ``gpus`` chosen GPUs, of the GPU process ``process`` renders on: dealt in turn,
    so the GPUs' process counts differ by at most one."""
    if gpus < 1:
        raise ValueError(f"gpus must be a positive integer, got {gpus!r}")
    return process % gpus


def process_environment(gpu: GpuInfo) -> dict[str, str]:
    """What one process's environment gets so that it renders on ``gpu`` alone (CUDA and EGL)."""
    return {"CUDA_VISIBLE_DEVICES": str(gpu.index), "CUDA_DEVICE_ORDER": "PCI_BUS_ID", BIND_ENV: str(gpu.index)}


def default_processes_per_gpu(gpus: int, cores: int | None = None, mps: bool = False) -> int:
    """Processes a GPU gets by default: the cores' share of each GPU, at most
    :data:`MAX_DEFAULT_PROCESSES_PER_GPU`, or :data:`MAX_DEFAULT_PROCESSES_PER_GPU_MPS` where ``mps`` (the
    processes sharing a GPU run under CUDA MPS), at least 1.

    Example:
        >>> default_processes_per_gpu(1, 16), default_processes_per_gpu(4, 64), default_processes_per_gpu(4, 2)
        (8, 8, 1)
        >>> default_processes_per_gpu(4, 64, mps=True), default_processes_per_gpu(1, 64, mps=True)
        (16, 16)
    """
    cores = cores if cores is not None else usable_cores()
    most = MAX_DEFAULT_PROCESSES_PER_GPU_MPS if mps else MAX_DEFAULT_PROCESSES_PER_GPU
    return max(1, min(most, cores // max(1, gpus)))


def gpu_share(workers: int, gpus: float) -> float:
    """The GPU fraction each of ``workers`` Ray workers asks for so that ``gpus`` GPUs hold them all:
    1/ceil(workers/gpus) cut down to Ray's four decimals (six requests of 0.1667 would not fit one GPU), 1 with
    no more workers than GPUs, 0 without GPUs.

    Ray places fractional requests first-fit on a node's GPUs, so equal requests fill one GPU before the
    next: a worker count that is a multiple of the GPU count loads every GPU alike (``--workers auto`` picks
    one); otherwise the last GPU gets fewer, or none (6 workers on 4 GPUs: 2 + 2 + 2 + 0). Unequal
    fractions could fill every GPU but can also strand a worker for good (1/3 and 1/2 on one GPU).

    Example:
        >>> gpu_share(8, 4), gpu_share(6, 4), gpu_share(12, 2), gpu_share(3, 0), gpu_share(2, 4)
        (0.5, 0.5, 0.1666, 0.0, 1.0)
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be a positive integer, got {workers!r}")
    whole = int(math.floor(gpus + 1e-9))
    if whole < 1:
        return 0.0
    per_gpu = math.ceil(workers / whole)
    return math.floor(10000 / per_gpu) / 10000
