"""Issue 37's byte checks on a multi-GPU host, without Ray: a job sharded over K GPUs writes the bytes of one
process, and a shard killed half way resumes to the same bytes.

Each shard is its own process started as ``graphsdg bench --gpus`` starts its processes
(:func:`graphsdg.render.gpu_assignment.process_environment`: ``CUDA_VISIBLE_DEVICES`` naming one GPU, EGL bound
to it at import) and runs :func:`graphsdg.jobs.job.run_job` for its frame plan, as a Ray shard does; the
parent merges the shards (:func:`graphsdg.dataset.merge.merge_shards`) and compares every file with a
one-process run of the same job on GPU 0. ``--kill-after S`` SIGKILLs shard 1 that many seconds into its
run, then reruns every shard with ``--resume`` and compares again. ``--shards-per-gpu N`` puts N shards on
each GPU, under CUDA MPS as ``--mps`` says (:mod:`graphsdg.render.cuda_mps`; default auto).

Usage (on the GPU host): python3 bench/gpu_shards.py --gpus 4 --frames 48 [--kill-after 20] [--backend pbr]
                         [--shards-per-gpu 2] [--mps auto|on|off]
Prints one Markdown table row per check; exits 1 if any check fails.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import time

#: the job: graphsdg demo's scene as a graph script, given --size and --backend as its arguments
JOB = os.path.join(os.path.dirname(os.path.abspath(__file__)), "demo_graph.py")


def _job(script_args: tuple[str, ...], out: str, frames: int, resume: bool):
    """The :class:`~graphsdg.jobs.job.JobSpec` every run of one check shares (its resume fingerprint too)."""
    from graphsdg.jobs.job import JobSpec
    return JobSpec(JOB, args=script_args, seed=7, out=out, frames=frames, resume=resume)


def _shard_main(script_args: tuple[str, ...], out: str, frames: int, index: int, count: int, resume: bool) -> None:
    """Inside a shard process: run the job's frames of shard ``index``; print its summary as JSON."""
    from graphsdg import orchestrator
    from graphsdg.io.frame_plan import FramePlan
    from graphsdg.jobs.job import run_job
    job = _job(script_args, out, frames, resume)
    summary = run_job(job, FramePlan(index, count, resume) if count > 1 else None)
    orchestrator.wait_until_complete()
    print("SHARD " + json.dumps(summary, default=str), flush=True)


def _start(script_args, out, frames, index, count, resume, gpu):
    from graphsdg.render.gpu_assignment import process_environment
    env = {**os.environ, **process_environment(gpu)}
    args = [sys.executable, __file__, "--shard", str(index), "--count", str(count), "--out", out,
            "--frames", str(frames), *script_args] + (["--resume"] if resume else [])
    return subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _summary(process) -> dict:
    out, err = process.communicate()
    if process.returncode != 0:
        raise RuntimeError(f"shard failed ({process.returncode}): {err[-2000:]}")
    return json.loads([line for line in out.splitlines() if line.startswith("SHARD ")][-1][6:])


def _run(script_args, out, frames, gpus, resume=False, kill_after=None, per_gpu=1) -> tuple[list[dict], float]:
    """Every shard at once, ``per_gpu`` a GPU (dealt in turn); shard 1 killed after ``kill_after`` s if given."""
    from graphsdg.dataset import merge
    from graphsdg.jobs.job import check_job_file
    check_job_file(_job(script_args, out, frames, resume))
    count = len(gpus) * per_gpu
    start = time.perf_counter()
    procs = [_start(script_args, out, frames, i, count, resume, gpus[i % len(gpus)]) for i in range(count)]
    if kill_after is not None:
        time.sleep(kill_after)
        procs[1].send_signal(signal.SIGKILL)
        procs[1].wait()
        for p in procs[:1] + procs[2:]:
            p.communicate()
        return [], time.perf_counter() - start
    results = sorted((_summary(p) for p in procs), key=lambda r: r["shard"] or 0)
    seconds = time.perf_counter() - start
    if count > 1:
        merge.merge_shards(results)
    return results, seconds


def _digest(root: str) -> dict[str, str]:
    out = {}
    base = os.path.join(root, "basic")
    for name in sorted(os.listdir(base)):
        with open(os.path.join(base, name), "rb") as f:
            out[name] = hashlib.sha256(f.read()).hexdigest()
    return out


def _sharded_checks(args, script_args: tuple[str, ...], work: str, gpus, one: dict, one_s: float, mps) -> bool:
    """The sharded run against the one-process files, then (``--kill-after``) a killed shard resumed; prints a
    row each and says whether every check held."""
    per_gpu = args.shards_per_gpu
    results, many_s = _run(script_args, os.path.join(work, "many"), args.frames, gpus, per_gpu=per_gpu)
    many = _digest(os.path.join(work, "many"))
    ok = one == many and len(one) > 0
    differ = sorted(k for k in one if one.get(k) != many.get(k))
    print("| check | GPUs | frames | files | seconds | result |\n|---|---|---|---|---|---|")
    print(f"| one process on GPU 0 | 1 | {args.frames} | {len(one)} | {one_s:.1f} | reference |")
    print(f"| {len(gpus) * per_gpu} shards, {per_gpu} a GPU ({mps.describe()}) | {len(gpus)} | "
          f"{sum(r['frames'] for r in results)} | {len(many)} | "
          f"{many_s:.1f} | {'byte-identical' if ok else f'DIFFERENT: {len(differ)} files, e.g. {differ[:3]}'} |")
    if args.kill_after is not None and len(gpus) * per_gpu > 1:
        out = os.path.join(work, "killed")
        _run(script_args, out, args.frames, gpus, kill_after=args.kill_after, per_gpu=per_gpu)
        partial = len(os.listdir(os.path.join(out, "basic"))) if os.path.isdir(os.path.join(out, "basic")) else 0
        _, resume_s = _run(script_args, out, args.frames, gpus, resume=True, per_gpu=per_gpu)
        resumed = _digest(out)
        same = resumed == one
        ok = ok and same
        print(f"| shard 1 killed after {args.kill_after:g} s ({partial} files), all resumed | {len(gpus)} | "
              f"{args.frames} | {len(resumed)} | {resume_s:.1f} | {'byte-identical' if same else 'DIFFERENT'} |")
    return ok


def _script_args(args: argparse.Namespace) -> tuple[str, ...]:
    """The job script's arguments: its product's size and the backend."""
    return ("--size", str(args.size), "--backend", args.backend)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gpus", type=int, default=4)
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--backend", default="pbr", choices=("pbr", "classic"))
    parser.add_argument("--kill-after", type=float)
    parser.add_argument("--shards-per-gpu", type=int, default=1)
    parser.add_argument("--mps", default="auto", choices=("auto", "on", "off"))
    parser.add_argument("--shard", type=int)
    parser.add_argument("--count", type=int)
    parser.add_argument("--out")
    parser.add_argument("--resume", action="store_true")
    args = parser.parse_args()
    if args.shard is not None:
        _shard_main(_script_args(args), args.out, args.frames, args.shard, args.count, args.resume)
        return 0
    from graphsdg.render.gpu_assignment import choose_gpus
    gpus = choose_gpus(args.gpus)
    work = tempfile.mkdtemp(prefix="graphsdg-gpu-shards-", dir="/dev/shm" if os.path.isdir("/dev/shm") else None)
    script_args = _script_args(args)
    _, one_s = _run(script_args, os.path.join(work, "one"), args.frames, gpus[:1])
    one = _digest(os.path.join(work, "one"))
    from graphsdg.render.cuda_mps import shared_gpus
    with shared_gpus(args.mps, args.shards_per_gpu) as mps:
        ok = _sharded_checks(args, script_args, work, gpus, one, one_s, mps)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
