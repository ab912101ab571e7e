"""CUDA MPS for a job's processes that share a GPU: their kernels run side by side, not in turns.

Without MPS, the CUDA contexts of several processes on one GPU take turns: each frame's short launches (BVH
refit, uploads, the boxes kernel, the read-back) leave most of the GPU idle while it counts as busy, and the
switches between contexts cost time of their own. NVIDIA's Multi-Process Service runs the processes' work
in one server context, so one process's small kernels fill the SMs another's leave free. It changes when
kernels run, never what they compute: the frames' bytes are those of a run without it.

:func:`shared_gpus` is the switch a multi-process command holds around its processes:

* ``mode="auto"`` (the default): MPS when more than one process shares a GPU and the host has
  ``nvidia-cuda-mps-control``; else the processes run as before, and the session says why;
* ``mode="on"``: MPS or an :class:`MpsUnavailableError` naming what is missing;
* ``mode="off"``: never.

A daemon the machine already runs (``CUDA_MPS_PIPE_DIRECTORY``, else ``/tmp/nvidia-mps``, holds its
``control`` pipe) is used and left running. Otherwise one is started for the job with pipe and log folders
of its own in a temporary folder, its pipe folder is put in this process's environment for the processes it
starts (Ray's local cluster included), and it is stopped, and its folders removed, when the job ends. It
sees every GPU of the machine, numbered as ``nvidia-smi`` numbers them, because a client's
``CUDA_VISIBLE_DEVICES`` counts the server's GPUs.
Processes that started CUDA before it (this one, if it did) keep their own contexts.

Example:
    >>> with shared_gpus("auto", processes_per_gpu=1) as mps:
    ...     mps.active, mps.reason
    (False, 'one process a GPU')
"""
from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from typing import Iterator

from graphsdg.base.environment import patched_environment

CONTROL = "nvidia-cuda-mps-control"
MODES = ("auto", "on", "off")
PIPE_ENV = "CUDA_MPS_PIPE_DIRECTORY"
LOG_ENV = "CUDA_MPS_LOG_DIRECTORY"
DEFAULT_PIPE_DIR = "/tmp/nvidia-mps"        # where the control program looks when PIPE_ENV is unset
START_TIMEOUT_S = 20.0


class MpsUnavailableError(RuntimeError):
    """``--mps on`` on a host where CUDA MPS cannot run."""


@dataclass(frozen=True)
class MpsSession:
    """What :func:`shared_gpus` decided: whether MPS serves the job, its pipe folder, and why."""

    active: bool
    reason: str
    pipe_dir: str | None = None
    started_here: bool = False

    def describe(self) -> str:
        """One line for a run's summary, e.g. ``CUDA MPS: on (daemon started for this run)``."""
        return f"CUDA MPS: {'on' if self.active else 'off'} ({self.reason})"


def check_mode(mode: str) -> str:
    """``mode`` if it is one of :data:`MODES`; else a ValueError naming it."""
    if mode not in MODES:
        raise ValueError(f"--mps {mode!r} is not one of {', '.join(MODES)}")
    return mode


def running_daemon(control: str | None = None, environ=os.environ) -> str | None:
    """The pipe folder of an MPS daemon already running for this process's environment, or None.

    A folder holding a ``control`` pipe is asked for its servers through ``control`` (the control program,
    when the host has one), so a pipe a dead daemon left behind does not count."""
    pipe_dir = environ.get(PIPE_ENV) or DEFAULT_PIPE_DIR
    if not os.path.exists(os.path.join(pipe_dir, "control")):
        return None
    if control is None:
        return pipe_dir
    try:
        answered = subprocess.run([control], input="get_server_list\n", env={**environ, PIPE_ENV: pipe_dir},
                                  capture_output=True, text=True, timeout=START_TIMEOUT_S).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        answered = False
    return pipe_dir if answered else None


def would_share(mode: str, control: str | None = None) -> bool:
    """Whether :func:`shared_gpus` in ``mode`` runs a GPU's several processes under MPS: ``on`` always (or it
    raises), ``off`` never, ``auto`` where a daemon runs already or the host has the control program.

    Example:
        >>> would_share("off"), would_share("on")
        (False, True)
    """
    check_mode(mode)
    if mode != "auto":
        return mode == "on"
    control = control or shutil.which(CONTROL)
    return control is not None or running_daemon(control) is not None


@contextlib.contextmanager
def shared_gpus(mode: str, processes_per_gpu: float, control: str | None = None) -> Iterator[MpsSession]:
    """MPS for the processes started inside the block, as ``mode`` says (module docstring).

    ``processes_per_gpu``: how many of the job's processes share one GPU (the most any GPU gets);
    ``control``: the control program (default: ``nvidia-cuda-mps-control`` on ``PATH``).

    Raises:
        ValueError: ``mode`` is not one of :data:`MODES`.
        MpsUnavailableError: ``mode="on"`` and the host has no control program, or its daemon would not start.
    """
    check_mode(mode)
    if mode == "off":
        yield MpsSession(False, "--mps off")
        return
    if mode == "auto" and processes_per_gpu <= 1:
        yield MpsSession(False, "one process a GPU")
        return
    control = control or shutil.which(CONTROL)
    existing = running_daemon(control)
    if existing is not None:
        yield MpsSession(True, f"the machine's daemon at {existing}", pipe_dir=existing)
        return
    if control is None:
        if mode == "on":
            raise MpsUnavailableError(f"--mps on needs CUDA MPS, but {CONTROL} is not on PATH (it comes with the "
                                      f"NVIDIA driver's utilities); run with --mps auto or off")
        yield MpsSession(False, f"{CONTROL} is not installed")
        return
    with _started_daemon(control, mode) as session:
        yield session


@contextlib.contextmanager
def _started_daemon(control: str, mode: str) -> Iterator[MpsSession]:
    """A daemon of the job's own: started, its pipe folder in the environment, stopped at the end."""
    root = tempfile.mkdtemp(prefix="graphsdg-mps-")
    env = {**os.environ, PIPE_ENV: os.path.join(root, "pipe"), LOG_ENV: os.path.join(root, "log")}
    # a client's CUDA_VISIBLE_DEVICES counts the server's GPUs: the server sees every GPU, numbered as
    # nvidia-smi numbers them, so the index a process is given (graphsdg.render.gpu_assignment) means one GPU
    env.pop("CUDA_VISIBLE_DEVICES", None)
    env["CUDA_DEVICE_ORDER"] = "PCI_BUS_ID"
    for folder in (env[PIPE_ENV], env[LOG_ENV]):
        os.makedirs(folder)
    try:
        done = subprocess.run([control, "-d"], env=env, capture_output=True, text=True, timeout=START_TIMEOUT_S)
        failure = None if done.returncode == 0 else (done.stderr or done.stdout).strip() or f"exit {done.returncode}"
    except (OSError, subprocess.TimeoutExpired) as exc:
        failure = str(exc)
    if failure is not None:
        shutil.rmtree(root, ignore_errors=True)
        if mode == "on":
            raise MpsUnavailableError(f"--mps on: {control} -d would not start the MPS daemon: {failure}")
        yield MpsSession(False, f"the MPS daemon would not start: {failure}")
        return
    try:
        with patched_environment({PIPE_ENV: env[PIPE_ENV], LOG_ENV: env[LOG_ENV]}):
            yield MpsSession(True, "daemon started for this run", pipe_dir=env[PIPE_ENV], started_here=True)
    finally:
        with contextlib.suppress(OSError, subprocess.TimeoutExpired):
            subprocess.run([control], input="quit\n", env=env, capture_output=True, text=True,
                           timeout=START_TIMEOUT_S)
        shutil.rmtree(root, ignore_errors=True)
