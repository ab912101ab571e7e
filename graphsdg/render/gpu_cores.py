"""The CPU cores each GPU's processes run on: its own share of the host's cores, near it where known.

On a multi-GPU server a capture process does most of its work on the CPU (randomizing, annotating, encoding)
and the rest through its GPU: processes of one GPU kept on cores of the GPU's own NUMA node read the
page-locked frames the GPU wrote into that node's memory, and processes of different GPUs do not move
between each other's cores. :func:`gpu_cores` gives each GPU of the host an equal share of the cores this
process may run on: the GPUs whose PCI device lists the same local cores (``local_cpulist`` in sysfs; a
host that tells nothing, or a virtual machine with one node, lists every core) split those cores into
contiguous runs in GPU order.

The share is a GPU's whatever the number of GPUs a run uses, so ``graphsdg bench --gpus 1 2 4 --bind-cores``
compares runs that each give a GPU the same cores: the scaling of the whole host, GPU by GPU, rather than one
GPU with every core against all of them sharing the cores.

Example:
    >>> from graphsdg.render.gpu_assignment import GpuInfo
    >>> host = [GpuInfo(i) for i in range(4)]
    >>> shares = gpu_cores(host, range(64), local=lambda gpu: None)
    >>> [(min(shares[g]), max(shares[g])) for g in range(4)]
    [(0, 15), (16, 31), (32, 47), (48, 63)]
"""
from __future__ import annotations

import os
from typing import Callable, Iterable, Sequence

from graphsdg.base.cpu_share import parse_cpu_list
from graphsdg.render.gpu_assignment import GpuInfo

SYSFS_PCI = "/sys/bus/pci/devices"


def local_cores(gpu: GpuInfo, root: str = SYSFS_PCI) -> set[int] | None:
    """The cores sysfs lists as local to ``gpu``'s PCI device, or None where it lists none (no PCI address,
    no sysfs, an unreadable file)."""
    if not gpu.pci_bus_id:
        return None
    domain, _, rest = gpu.pci_bus_id.lower().partition(":")
    address = f"{domain[-4:]:0>4}:{rest}"        # nvidia-smi's 8-digit PCI domain, sysfs's 4
    try:
        with open(os.path.join(root, address, "local_cpulist")) as f:
            return parse_cpu_list(f.read()) or None
    except (OSError, ValueError):
        return None


def gpu_cores(host: Sequence[GpuInfo], usable: Iterable[int],
              local: Callable[[GpuInfo], set[int] | None] = local_cores) -> dict[int, list[int]]:
    """Each host GPU's cores (by ``nvidia-smi`` index): the ``usable`` cores local to it (all of them where
    ``local`` says none, or none of its local cores is usable), split evenly among the GPUs with the same
    local cores, in GPU order; a share is never empty (GPUs outnumbering their cores share them round-robin).

    Raises:
        ValueError: no usable cores.
    """
    usable = sorted(set(usable))
    if not usable:
        raise ValueError("no usable CPU cores to share among the GPUs")
    groups: dict[tuple[int, ...], list[GpuInfo]] = {}
    for gpu in sorted(host, key=lambda g: g.index):
        near = sorted((local(gpu) or set()) & set(usable)) or usable
        groups.setdefault(tuple(near), []).append(gpu)
    shares: dict[int, list[int]] = {}
    for cores, gpus in groups.items():
        for position, gpu in enumerate(gpus):
            if len(cores) >= len(gpus):
                lo, hi = position * len(cores) // len(gpus), (position + 1) * len(cores) // len(gpus)
                shares[gpu.index] = list(cores[lo:hi])
            else:
                shares[gpu.index] = [cores[position % len(cores)]]
    return shares


def assigned_share(gpu_ids: Sequence, host: Sequence[GpuInfo], usable: Iterable[int],
                   local: Callable[[GpuInfo], set[int] | None] = local_cores) -> list[int] | None:
    """The cores a process a scheduler gave ``gpu_ids`` (Ray's ids: the host's ``nvidia-smi`` indices) should
    run on: its GPU's :func:`gpu_cores` share (``local``: as there), where the host has several GPUs and the
    process one of them; None (every usable core) otherwise, or where the id is not one of the host's GPUs.

    Example:
        >>> from graphsdg.render.gpu_assignment import GpuInfo
        >>> host = [GpuInfo(i) for i in range(4)]
        >>> assigned_share(["2"], host, range(64)), assigned_share([], host, range(64))
        ([32, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 45, 46, 47], None)
    """
    if len(host) < 2 or len(gpu_ids) != 1 or not str(gpu_ids[0]).isdigit():
        return None
    return gpu_cores(host, usable, local).get(int(gpu_ids[0]))


__all__ = ["SYSFS_PCI", "assigned_share", "gpu_cores", "local_cores"]
