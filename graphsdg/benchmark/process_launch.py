"""Benchmark processes started together, each with its own environment, released at once by a barrier.

``graphsdg bench --processes P [--gpus K]`` runs P benchmark processes; with ``--gpus`` each must render on
its own GPU, which only its environment can say before CUDA or EGL start in it (``CUDA_VISIBLE_DEVICES``,
:mod:`graphsdg.render.gpu_assignment`). A pool's workers all inherit the parent's environment, so
:func:`run_in_processes` starts one spawned process per task with the parent's environment patched for
that task while it starts (and, for ``--bind-cores``, bound to the task's cores: a child inherits the affinity
of the thread that starts it). Every task gets the same barrier (``before_timing``): they build and warm up
apart, then time together. A task that fails aborts the barrier, so the others stop waiting, and the
first failure is raised here naming the process.

Example:
    >>> run_in_processes(_echo_environment, [("A",), ("A",)], [{"A": "1"}, {"A": "2"}])
    ['1', '2']
"""
from __future__ import annotations

import multiprocessing
import os
import queue as queues
from typing import Any, Callable, Iterable, Sequence

from graphsdg.base.cpu_share import bound_to
from graphsdg.base.environment import patched_environment


class BenchProcessError(RuntimeError):
    """A benchmark process failed or died (the message names it and its error)."""


def _run_task(target: Callable, args: tuple, barrier, results, index: int) -> None:
    """One process: ``target(*args, before_timing=barrier.wait)``, its value (or its error) into ``results``."""
    try:
        value = target(*args, before_timing=barrier.wait)
    except BaseException as exc:   # noqa: BLE001 - reported to the parent, which raises it
        try:
            barrier.abort()
        except Exception:   # noqa: BLE001 - the manager may be gone; the parent still hears of the error
            pass
        results.put((index, False, f"{type(exc).__name__}: {exc}"))
        return
    results.put((index, True, value))


def run_in_processes(target: Callable, args: Sequence[tuple], environments: Sequence[dict[str, str]],
                     poll_seconds: float = 1.0,
                     cores: Sequence[Iterable[int] | None] | None = None) -> list[Any]:
    """``target(*args[i], before_timing=wait)`` in process i, started with ``environments[i]`` added to this
    process's environment (and, where ``cores`` gives them, bound to ``cores[i]``); their return values in order.

    ``target`` must be importable by name (processes are spawned) and take a ``before_timing`` callable,
    the shared barrier's ``wait``.

    Raises:
        BenchProcessError: a process raised (its error's first line) or died without answering.
    """
    if len(args) != len(environments):
        raise ValueError(f"{len(args)} tasks but {len(environments)} environments")
    cores = list(cores) if cores is not None else [None] * len(args)
    if len(cores) != len(args):
        raise ValueError(f"{len(args)} tasks but {len(cores)} core sets")
    ctx = multiprocessing.get_context("spawn")
    count = len(args)
    with ctx.Manager() as manager:
        barrier = manager.Barrier(count)
        results = ctx.Queue()
        processes = []
        try:
            for i, (task_args, env, bound) in enumerate(zip(args, environments, cores)):
                with patched_environment(env), bound_to(bound):
                    process = ctx.Process(target=_run_task, args=(target, tuple(task_args), barrier, results, i),
                                          name=f"graphsdg-bench-{i}")
                    process.start()
                processes.append(process)
            values: list[Any] = [None] * count
            pending = set(range(count))
            while pending:
                try:
                    index, ok, value = results.get(timeout=poll_seconds)
                except queues.Empty:
                    dead = [i for i in pending if processes[i].exitcode is not None]
                    if dead:
                        i = dead[0]
                        raise BenchProcessError(f"benchmark process {i} of {count} died (exit code "
                                                f"{processes[i].exitcode}) before reporting") from None
                    continue
                if not ok:
                    first = (str(value).strip().splitlines() or [""])[0]
                    raise BenchProcessError(f"benchmark process {index} of {count} failed: {first}")
                values[index] = value
                pending.discard(index)
            return values
        finally:
            for process in processes:
                process.join(timeout=30 if process.exitcode is None else 0)
                if process.exitcode is None:    # a process still waiting after a failure elsewhere
                    process.terminate()
                    process.join()


def _echo_environment(name: str, before_timing: Callable[[], Any]) -> str | None:
    """The value of environment variable ``name`` in this process, after the barrier (the doctest's task)."""
    before_timing()
    return os.environ.get(name)
