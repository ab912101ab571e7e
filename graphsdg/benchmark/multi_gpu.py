"""``graphsdg bench --gpus K``: the benchmark's processes spread over K GPUs. A row per GPU, and the scaling.

The processes are dealt out to the first K GPUs this process sees
(:mod:`graphsdg.render.gpu_assignment`): each starts with ``CUDA_VISIBLE_DEVICES`` naming its GPU, so its
CUDA device (Warp, the pbr backend) and, at import, its EGL device (the classic rasteriser) are that GPU.
The table has the run's total row (:func:`graphsdg.benchmark.throughput.summarize_processes`, with the share
of the machine's CPU time a virtual machine's host took meanwhile: :mod:`graphsdg.benchmark.host_steal`) and a
row per GPU: its processes, their frames/s over their common window and while all of them ran, the CPU time a
frame, and how busy the GPU was and at what clock (``nvidia-smi``, :mod:`graphsdg.benchmark.gpu_sampler`).
Several counts (``--gpus 1 2 4``) run one after the other and end with a scaling table: frames/s, frames/s a
GPU, and the scaling efficiency, each count's rate a GPU over the smallest count's. With ``--rounds K`` the
counts run K times in turn (1, 2, 4, 1, 2, 4, ...): runs of one configuration on a shared host vary by tens of
percent, so :func:`round_rows` gives each round's rates and its own ratios, and the scaling table is made of
each count's median run (:func:`median_runs`).

Example:
    >>> one = GpuRun(gpus=[GpuInfo(0)], total={"processes": 8, "aggregate frames/s (all frames / common window)":
    ...              1500.0, "CPU ms per frame (all threads)": 8.5}, per_gpu=[])
    >>> four = GpuRun(gpus=[GpuInfo(i) for i in range(4)], total={"processes": 32,
    ...               "aggregate frames/s (all frames / common window)": 5700.0, "CPU ms per frame (all threads)": 9.0},
    ...               per_gpu=[])
    >>> [row["scaling efficiency"] for row in scaling_rows([one, four])]
    [1.0, 0.95]
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

from graphsdg.base.cpu_share import cpu_list
from graphsdg.benchmark.gpu_sampler import GpuSampler, summarize
from graphsdg.benchmark.host_steal import CpuTimesSampler, steal_percent
from graphsdg.benchmark.throughput import BenchConfig, _steady_rate, launch_processes, summarize_processes
from graphsdg.render.gpu_assignment import GpuInfo, gpu_of_process, process_environment

AGGREGATE = "aggregate frames/s (all frames / common window)"


@dataclass
class GpuRun:
    """One ``--gpus K`` run: the GPUs used, the total row and a row per GPU."""

    gpus: list[GpuInfo]
    total: dict
    per_gpu: list[dict] = field(default_factory=list)


def run_on_gpus(config: BenchConfig, processes: int, gpus: list[GpuInfo],
                cores: dict[int, list[int]] | None = None) -> GpuRun:
    """``processes`` benchmark processes dealt out to ``gpus`` in turn (:func:`gpu_of_process`), each bound to
    its GPU's ``cores`` where given (:func:`graphsdg.render.gpu_cores.gpu_cores`); the total and per-GPU rows.

    Raises:
        ValueError: fewer processes than GPUs (a GPU would stay idle).
    """
    if processes < len(gpus):
        raise ValueError(f"--processes {processes} cannot keep --gpus {len(gpus)} busy: give each GPU at least "
                         f"one process (--processes {len(gpus)} or more)")
    placed = [gpus[gpu_of_process(i, len(gpus))] for i in range(processes)]
    environments = [process_environment(gpu) for gpu in placed]
    bound = [cores[gpu.index] for gpu in placed] if cores is not None else None
    started = time.time()
    with GpuSampler() as sampler, CpuTimesSampler() as host:
        results, elapsed, config = launch_processes(config, processes, environments, bound)
    total = summarize_processes(results, config, elapsed)
    lo = max((r["start"] for r in results), default=started)
    hi = min((r["start"] + r["wall"] for r in results), default=time.time())
    stolen = steal_percent(host.samples, lo, hi)
    total = {"GPUs": len(gpus), **total, "CPU stolen by the host %": "-" if stolen is None else stolen}
    busy = summarize(sampler.samples, lo, hi)
    return GpuRun(gpus=list(gpus), total=total, per_gpu=per_gpu_rows(results, gpus, busy, cores))


def per_gpu_rows(results: list[dict], gpus: list[GpuInfo], busy: dict[int, tuple[float, float, float]],
                 cores: dict[int, list[int]] | None = None) -> list[dict]:
    """A row per GPU from the processes' results (each names its ``gpu`` index) and ``busy``
    (:func:`graphsdg.benchmark.gpu_sampler.summarize`: index -> (busy %, memory MiB, SM clock MHz)); with
    ``cores``, the cores its processes were bound to.

    Example:
        >>> a = {"gpu": 0, "frames": 100, "start": 0.0, "wall": 10.0, "cpu": 5.0, "frame_ends": [10.0]}
        >>> b = {"gpu": 1, "frames": 50, "start": 0.0, "wall": 10.0, "cpu": 5.0, "frame_ends": [10.0]}
        >>> rows = per_gpu_rows([a, b], [GpuInfo(0), GpuInfo(1)], {0: (90.0, 4000.0, 1980.0)})
        >>> [(r["GPU"], r["frames/s"], r["CPU ms per frame"], r["GPU busy %"]) for r in rows]
        [('GPU 0', 10.0, 50.0, 90.0), ('GPU 1', 5.0, 100.0, '-')]
    """
    rows = []
    for gpu in gpus:
        mine = [r for r in results if r.get("gpu") == gpu.index]
        if not mine:
            continue
        window = max(r["start"] + r["wall"] for r in mine) - min(r["start"] for r in mine)
        frames = sum(r["frames"] for r in mine)
        steady = _steady_rate(mine)
        percent, memory, clock = busy.get(gpu.index, ("-", "-", "-"))
        rows.append({"GPU": gpu.label(), "processes": len(mine),
                     "frames/s": round(frames / window, 1) if window > 0 else 0.0,
                     "steady frames/s": round(steady, 1) if steady == steady else "-",
                     "CPU ms per frame": round(1000 * sum(r["cpu"] for r in mine) / frames, 1) if frames else 0.0,
                     "GPU busy %": percent, "GPU memory MiB": memory, "SM clock MHz": clock})
        if cores is not None:
            rows[-1]["cores"] = cpu_list(cores[gpu.index])
    return rows


def median_runs(rounds: list[list[GpuRun]]) -> list[GpuRun]:
    """Each GPU count's run of median frames/s over the rounds (the lower middle one of an even number).

    Example:
        >>> def run(gpus, rate):
        ...     return GpuRun(gpus=[GpuInfo(i) for i in range(gpus)], total={AGGREGATE: rate})
        >>> [r.total[AGGREGATE] for r in median_runs([[run(1, 10.0), run(4, 30.0)], [run(1, 12.0), run(4, 20.0)],
        ...                                           [run(1, 11.0), run(4, 40.0)]])]
        [11.0, 30.0]
    """
    by_count: dict[int, list[GpuRun]] = {}
    for one_round in rounds:
        for run in one_round:
            by_count.setdefault(len(run.gpus), []).append(run)
    medians = []
    for count in sorted(by_count):
        ranked = sorted(by_count[count], key=lambda r: r.total[AGGREGATE])
        medians.append(ranked[(len(ranked) - 1) // 2])
    return medians


def round_rows(rounds: list[list[GpuRun]]) -> list[dict]:
    """A row per round: each GPU count's frames/s, and each count's ratio to the fewest GPUs of that round.

    Example:
        >>> def run(gpus, rate):
        ...     return GpuRun(gpus=[GpuInfo(i) for i in range(gpus)], total={AGGREGATE: rate})
        >>> rows = round_rows([[run(1, 10.0), run(4, 30.0)], [run(1, 12.0), run(4, 42.0)]])
        >>> [(r["round"], r["4 GPU(s) frames/s"], r["x 1 GPU(s) with 4"]) for r in rows]
        [(1, 30.0, 3.0), (2, 42.0, 3.5)]
    """
    rows = []
    for number, one_round in enumerate(rounds, 1):
        ordered = sorted(one_round, key=lambda r: len(r.gpus))
        base = ordered[0]
        row: dict = {"round": number}
        for run in ordered:
            row[f"{len(run.gpus)} GPU(s) frames/s"] = round(run.total[AGGREGATE], 1)
        for run in ordered[1:]:
            ratio = run.total[AGGREGATE] / base.total[AGGREGATE] if base.total[AGGREGATE] else 0.0
            row[f"x {len(base.gpus)} GPU(s) with {len(run.gpus)}"] = round(ratio, 2)
        rows.append(row)
    return rows


def scaling_rows(runs: list[GpuRun]) -> list[dict]:
    """The scaling table of several ``--gpus`` runs: each one's frames/s, frames/s a GPU, CPU ms a frame, and
    its efficiency (frames/s a GPU over that of the run with the fewest GPUs; 1.0 is perfect scaling)."""
    if not runs:
        return []
    base = min(runs, key=lambda r: len(r.gpus))
    base_rate = base.total[AGGREGATE] / len(base.gpus)
    rows = []
    for run in sorted(runs, key=lambda r: len(r.gpus)):
        per_gpu = run.total[AGGREGATE] / len(run.gpus)
        rows.append({"GPUs": len(run.gpus), "processes": run.total["processes"],
                     "frames/s": round(run.total[AGGREGATE], 1), "frames/s a GPU": round(per_gpu, 1),
                     f"x {len(base.gpus)} GPU(s)": round(run.total[AGGREGATE] / base.total[AGGREGATE], 2),
                     "CPU ms per frame": run.total["CPU ms per frame (all threads)"],
                     "scaling efficiency": round(per_gpu / base_rate, 2) if base_rate else 0.0})
    return rows
