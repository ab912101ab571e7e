"""Scale-out on Ray: K shards of one job, then merged. ``graphsdg run SCRIPT --workers K`` runs them.

Each shard is a Ray actor: its own process, so its own GL context and MuJoCo
model. Shard ``i`` runs the whole script with the job's seed and captures the
frames ``i, i + K, ...`` of its ``orchestrator.run(num_frames)`` (the scheduler
seeks to each, so every frame holds the values of one uninterrupted run and the
union of the shards is that run's dataset). Actors ask for one CPU and
``gpus_per_worker`` GPUs (by default an even share of every GPU of the cluster,
:func:`~graphsdg.render.gpu_assignment.gpu_share`; ``--gpus K`` uses K of them); Ray
shows each actor its GPU through ``CUDA_VISIBLE_DEVICES`` and the EGL device follows
it, so CUDA (the pbr backend) and EGL render on the GPU Ray assigned. ``--workers auto``
puts the cores' share of workers on each GPU (:func:`default_workers`). The driver then
merges the shards (:mod:`graphsdg.dataset.merge`) and writes ``graphsdg_index.json``;
its summary has a row per GPU (:func:`gpu_rows`).

With ``address`` the driver joins that Ray cluster; otherwise it starts a local
one for the job and shuts it down afterwards. Every node needs graphsdg, and
either the output folder on a shared filesystem at the same path or an
``s3://bucket/prefix`` output root: then shards write objects, and the merge
step and ``graphsdg_index.json`` work in the bucket, so the nodes share no disk.
Shards are spread over the nodes (Ray's ``SPREAD`` strategy); each reports the
node it ran on.

Ray is optional: ``pip install 'graphsdg[ray]'``.
"""
from __future__ import annotations

import contextlib
import logging
import math
import os
import tempfile
import time
from dataclasses import replace

from graphsdg.base.cpu_share import cores_per_process, cpu_list, usable_core_set, usable_cores
from graphsdg.render.cuda_mps import MpsSession, check_mode, shared_gpus, would_share
from graphsdg.render.gpu_assignment import GpuCountError, default_processes_per_gpu, host_gpus, visible_gpus
from graphsdg.render.gpu_cores import assigned_share
from graphsdg.io import object_store
from graphsdg.io.location import normalize
from graphsdg.io.write_queue import threads_per_process
from graphsdg.jobs.job import JobSpec, run_job

log = logging.getLogger("graphsdg.jobs.scaleout")
RAY_HINT = "pip install 'graphsdg[ray]'"
SHARD_COLUMNS = ("shard", "frames", "seconds", "node", "pid", "gpu_ids", "egl_device", "cores", "write_threads",
                 "image_threads")   # per-shard summary
# what the shards need from the driver's environment: rendering, reproducible dates, and where S3 is (the
# endpoint and region; credentials come from each node's own AWS chain, never through Ray), and the node's
# Warp kernel cache (graphsdg.render.kernel_cache: a worker loads what another compiled), and the allocator's
# settings (graphsdg.base.heap: large freed blocks kept)
FORWARDED_ENV = ("MUJOCO_GL", "PYOPENGL_PLATFORM", "SOURCE_DATE_EPOCH", "GRAPHSDG_KERNEL_CACHE",
                 "WARP_CACHE_PATH", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_") + object_store.ENVIRONMENT


class RayMissingError(ImportError):
    """``--workers`` without Ray installed."""


class ShardFailedError(RuntimeError):
    """A shard of a sharded run failed or its node died; what it wrote is kept for ``--resume``."""


def import_ray():
    """The ``ray`` module, or a clear error saying how to get it."""
    try:
        import ray
    except ImportError as exc:
        raise RayMissingError(f"--workers runs shards on Ray, which is not installed; {RAY_HINT} "
                              f"(or run without --workers)") from exc
    return ray


class ShardWorker:
    """One shard's process (made a Ray actor by :func:`run_sharded`)."""

    def __init__(self, bind_cores: bool = True) -> None:
        import ray
        from graphsdg.render.egl_device import follow_assigned_gpu
        self.gpu_ids = list(ray.get_gpu_ids())
        self.node = ray.get_runtime_context().get_node_id()
        self.egl_device = follow_assigned_gpu(self.gpu_ids)   # before the first GL context
        self.cores = bind_to_assigned_gpu(self.gpu_ids) if bind_cores else None

    def run(self, job: JobSpec, index: int, count: int, write_threads: int | None = None,
            image_threads: int | None = None) -> dict:
        """Run shard ``index`` of ``count``; ``write_threads`` is the default writer pool size here
        (the script may still set ``/omni/replicator/backend/writeThreads`` itself), ``image_threads``
        OpenCV's pool size (None: its default)."""
        from graphsdg.base import settings_store as settings
        from graphsdg.base.cpu_share import limit_image_threads
        from graphsdg.io.frame_plan import FramePlan
        from graphsdg.io.write_queue import THREADS_KEY, get_write_queue
        if write_threads is not None:
            settings.set(THREADS_KEY, write_threads)
        if image_threads is not None:
            limit_image_threads(image_threads)
        summary = run_job(script_here(job), FramePlan(index, count, job.resume))
        summary.update(node=self.node, pid=os.getpid(), cores=self.cores,
                       gpu_ids=[str(g) for g in self.gpu_ids], egl_device=self.egl_device,
                       write_threads=get_write_queue().num_threads, image_threads=image_threads)
        return summary


def bind_to_assigned_gpu(gpu_ids: list) -> str | None:
    """Bind this process (its threads to come) to the cores of the one GPU Ray gave it, where its node has
    several (:func:`~graphsdg.render.gpu_cores.assigned_share`): a GPU's workers share its cores and keep off
    the other GPUs' (``graphsdg bench --bind-cores``, docs/performance.md); the cores as a list, or None."""
    share = assigned_share(gpu_ids, host_gpus(), usable_core_set())
    if share is None:
        return None
    os.sched_setaffinity(0, share)
    return cpu_list(share)


def script_here(job: JobSpec) -> JobSpec:
    """``job`` with a script path readable on this node: the driver's path where it holds the same bytes (a
    shared filesystem), else a copy written from the bytes the driver sent (nodes that share no disk)."""
    if job.script_source is None:
        return job
    try:
        with open(job.script, "rb") as f:
            if f.read() == job.script_source:
                return job
    except OSError:
        pass
    folder = tempfile.mkdtemp(prefix="graphsdg-job-")
    path = os.path.join(folder, os.path.basename(job.script))
    with open(path, "wb") as f:
        f.write(job.script_source)
    return replace(job, script=path)


def run_sharded(job: JobSpec, workers: int | str, address: str | None = None, gpus_per_worker: float | None = None,
                num_cpus: int | None = None, gpus: int | None = None, mps: str = "auto",
                bind_cores: bool = True) -> dict:
    """Run ``job`` as ``workers`` Ray shards (``"auto"``: :func:`default_workers`), merge them; return the job
    summary (with per-shard and per-GPU rows).

    ``gpus``: use that many GPUs (default: all the cluster's); more than the machine or cluster has is an
    error naming both counts. Each worker asks for :func:`~graphsdg.render.gpu_assignment.gpu_share` of a GPU
    unless ``gpus_per_worker`` says otherwise. ``mps`` (auto, on, off): CUDA MPS for the workers that share a
    GPU of the local cluster (:mod:`graphsdg.render.cuda_mps`); a cluster joined with ``address`` runs its
    nodes' own daemons. ``bind_cores``: each worker given one GPU of a node with several runs on that GPU's
    share of the node's cores (:func:`bind_to_assigned_gpu`).
    """
    from graphsdg.dataset import merge
    from graphsdg.render.gpu_assignment import choose_gpus, gpu_share

    if workers != "auto" and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"--workers must be a positive integer or 'auto', got {workers!r}")
    if job.out is None:
        raise ValueError("--workers needs --out DIR: the shards write into one output root (on a shared "
                         "filesystem, or an s3://bucket/prefix, when the cluster has several machines)")
    check_mode(mps)
    if address and mps == "on":
        raise ValueError(f"--mps on starts a CUDA MPS daemon on this machine; the nodes of the cluster at {address} "
                         f"run their own (start one on each node), so give --mps auto or off with --address")
    ray = import_ray()
    start = time.perf_counter()
    started_here = not ray.is_initialized()
    daemon = contextlib.ExitStack()
    mps_session = MpsSession(False, "a cluster joined with --address runs its nodes' own daemons" if address else
                             "Ray was already running in this process")
    if started_here:
        if address:
            ray.init(address=address, log_to_driver=True)
        else:
            # this machine's GPUs, checked before Ray starts: the local cluster gets them (or the first --gpus)
            local_gpus = len(choose_gpus(gpus)) if gpus is not None else _visible_gpu_count()
            # address="local": a new cluster of this process's own, never one another run left on the machine
            cores = num_cpus or usable_cores()
            wanted = default_workers(local_gpus, cores, mps=would_share(mps)) if workers == "auto" else workers
            # before Ray starts, so its workers (children of this process) find the daemon's pipe
            mps_session = daemon.enter_context(
                shared_gpus(mps, math.ceil(wanted / local_gpus) if local_gpus else 0))
            ray.init(address="local", num_cpus=max(wanted, cores), num_gpus=local_gpus,
                     include_dashboard=False, log_to_driver=True)
    try:
        cluster_gpus = float(ray.cluster_resources().get("GPU", 0))
        if gpus is not None and gpus > cluster_gpus:
            raise GpuCountError(f"--gpus {gpus} asks for {gpus} GPU(s) but the Ray cluster has {cluster_gpus:g}")
        used_gpus = float(gpus) if gpus is not None else cluster_gpus
        if workers == "auto":
            workers = default_workers(int(used_gpus), int(ray.cluster_resources().get("CPU", 1)),
                                      mps=mps_session.active)
        per_worker = gpus_per_worker if gpus_per_worker is not None else gpu_share(workers, used_gpus)
        if per_worker > cluster_gpus:
            raise GpuCountError(f"--gpus-per-worker {per_worker:g} but the cluster has {cluster_gpus:g} GPU(s)")
        if per_worker and used_gpus >= 1 and workers % int(used_gpus):
            log.warning("%d workers on %d GPUs: Ray fills one GPU before the next, so the last GPU gets fewer "
                        "workers (a multiple of the GPU count, or --workers auto, loads them alike)",
                        workers, int(used_gpus))
        env = {k: v for k, v in os.environ.items() if k in FORWARDED_ENV}
        with open(job.script, "rb") as f:
            source = f.read()
        job = replace(job, out=normalize(job.out), script=os.path.abspath(job.script), env=env,
                      script_source=source)
        # one shard per node first: on a cluster each node's cores and GPUs are used
        actor = ray.remote(num_cpus=1, num_gpus=per_worker, scheduling_strategy="SPREAD")(ShardWorker)
        actors = [actor.remote(bind_cores) for _ in range(workers)]
        # shards of a local cluster share this machine's cores: a writer pool each of their share of them
        threads = None if address else threads_per_process(workers, num_cpus or usable_cores())
        image_threads = None if address else cores_per_process(workers, num_cpus or usable_cores())
        pending = {a.run.remote(job, i, workers, threads, image_threads): i for i, a in enumerate(actors)}
        results: list[dict] = []
        try:
            while pending:
                done, _ = ray.wait(list(pending), num_returns=1)
                index = pending.pop(done[0])
                try:
                    result = ray.get(done[0])
                except Exception as exc:   # noqa: BLE001 - one line naming the shard, the cause kept
                    cause = getattr(exc, "cause", None) or exc
                    first = (str(cause).strip().splitlines() or [""])[0]
                    raise ShardFailedError(f"shard {index} of {workers} failed: {type(cause).__name__}: {first}; "
                                           f"the frames written so far are kept in {job.out}: rerun with --resume "
                                           f"to capture the rest") from exc
                log.info("shard %d: %d frames in %.1f s", index, result["frames"], result["seconds"])
                results.append(result)
        finally:
            for a in actors:
                ray.kill(a)
    finally:
        if started_here:
            ray.shutdown()
        daemon.close()
    results.sort(key=lambda r: r["shard"])
    datasets = merge.merge_shards(results)
    seconds = time.perf_counter() - start
    frames = sum(r["frames"] for r in results)
    per_gpu = gpu_rows(results)
    summary = {"frames": frames, "files": sum(r["files"] for r in results),
               "bytes": sum(r["bytes"] for r in results), "seconds": round(seconds, 3),
               "frames/s": round(frames / seconds, 2) if seconds > 0 else 0.0, "workers": workers,
               "gpus_per_worker": per_worker, "gpus": len(per_gpu), "per_gpu": per_gpu,
               "mps": mps_session.describe(),
               "shards": [{k: r[k] for k in SHARD_COLUMNS} for r in results]}
    job_info = job.describe()
    summary["index"] = merge.write_index(job.out, {**job_info, "workers": workers, "shards": summary["shards"]},
                                         datasets)
    return summary


def _visible_gpu_count() -> int:
    """The GPUs this process sees (the local cluster gets them all)."""
    return len(visible_gpus(host_gpus(), os.environ.get("CUDA_VISIBLE_DEVICES")))


def default_workers(gpus: int, cores: int, mps: bool = False) -> int:
    """``--workers auto``: on GPUs, each GPU's default share of processes
    (:func:`~graphsdg.render.gpu_assignment.default_processes_per_gpu`; more where a GPU's workers run under
    CUDA MPS, ``mps``), a multiple of the GPU count so every GPU gets as many; without GPUs, one a core.

    Example:
        >>> default_workers(4, 64), default_workers(2, 16), default_workers(0, 16), default_workers(4, 64, mps=True)
        (32, 16, 16, 64)
    """
    if gpus < 1:
        return max(1, cores)
    return gpus * default_processes_per_gpu(gpus, cores, mps=mps)


def gpu_rows(results: list[dict]) -> list[dict]:
    """A row per GPU the shards rendered on (node and Ray GPU id): its workers, frames and frames/s (its
    frames over its slowest shard's seconds). Shards without a GPU make no row.

    Example:
        >>> shards = [{"node": "n1", "gpu_ids": ["0"], "frames": 50, "seconds": 5.0},
        ...           {"node": "n1", "gpu_ids": ["0"], "frames": 50, "seconds": 10.0},
        ...           {"node": "n1", "gpu_ids": ["1"], "frames": 40, "seconds": 4.0}]
        >>> [(r["gpu"], r["workers"], r["frames/s"]) for r in gpu_rows(shards)]
        [('0', 2, 10.0), ('1', 1, 10.0)]
    """
    groups: dict[tuple, list[dict]] = {}
    for r in results:
        if r.get("gpu_ids"):
            groups.setdefault((r["node"], ",".join(map(str, r["gpu_ids"]))), []).append(r)
    rows = []
    for (node, gpu), shards in sorted(groups.items()):
        seconds = max(s["seconds"] for s in shards)
        frames = sum(s["frames"] for s in shards)
        rows.append({"node": node, "gpu": gpu, "workers": len(shards), "frames": frames,
                     "frames/s": round(frames / seconds, 2) if seconds > 0 else 0.0})
    return rows


def format_gpu_rows(summary: dict) -> str | None:
    """The summary's GPU line: how many GPUs and each one's frames/s (None when no shard had a GPU)."""
    rows = summary.get("per_gpu") or []
    if not rows:
        return None
    nodes = len({r["node"] for r in rows})
    where = f" on {nodes} nodes" if nodes > 1 else ""
    parts = [(f"node {r['node'][:8]} " if nodes > 1 else "") + f"GPU {r['gpu']}: {r['workers']} workers, "
             f"{r['frames/s']:.2f} frames/s" for r in rows]
    return f"{len(rows)} GPU(s){where}: " + "; ".join(parts)
