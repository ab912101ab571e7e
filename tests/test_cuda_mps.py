"""CUDA MPS for processes that share a GPU (graphsdg.render.cuda_mps): when it is used, and the errors.

Starting a daemon needs an NVIDIA driver; bench/multi_gpu.sh measures that on a GPU host. These tests cover
the decisions and the failures on any machine."""
from __future__ import annotations

import os

import pytest

from graphsdg.jobs.cli import main
from graphsdg.render import cuda_mps
from graphsdg.render.cuda_mps import MpsUnavailableError, shared_gpus


@pytest.fixture
def no_daemon(monkeypatch, tmp_path):
    """A machine whose PATH has no MPS control program and no daemon running."""
    monkeypatch.setenv("PATH", str(tmp_path / "empty-bin"))
    monkeypatch.setenv(cuda_mps.PIPE_ENV, str(tmp_path / "no-pipe"))
    return tmp_path


def test_auto_uses_mps_only_where_processes_share_a_gpu(no_daemon) -> None:
    with shared_gpus("auto", processes_per_gpu=1) as mps:
        assert not mps.active and mps.reason == "one process a GPU"
    with shared_gpus("off", processes_per_gpu=8) as mps:
        assert not mps.active and mps.describe() == "CUDA MPS: off (--mps off)"
    with shared_gpus("auto", processes_per_gpu=8) as mps:      # shared, but the host cannot
        assert not mps.active and "nvidia-cuda-mps-control is not installed" in mps.reason


def test_on_names_what_is_missing(no_daemon) -> None:
    with pytest.raises(MpsUnavailableError,
                       match="--mps on needs CUDA MPS, but nvidia-cuda-mps-control is not on PATH"):
        with shared_gpus("on", processes_per_gpu=8):
            pass
    with pytest.raises(ValueError, match="--mps 'sometimes' is not one of auto, on, off"):
        with shared_gpus("sometimes", processes_per_gpu=8):
            pass


def test_a_daemon_that_will_not_start(no_daemon) -> None:
    """A control program that exits non-zero: auto runs without MPS and leaves no folder; on is an error."""
    before = set(os.listdir(no_daemon))
    with shared_gpus("auto", processes_per_gpu=4, control="/bin/false") as mps:
        assert not mps.active and mps.reason.startswith("the MPS daemon would not start")
        assert cuda_mps.LOG_ENV not in os.environ
    with pytest.raises(MpsUnavailableError, match="/bin/false -d would not start the MPS daemon"):
        with shared_gpus("on", processes_per_gpu=4, control="/bin/false"):
            pass
    assert set(os.listdir(no_daemon)) == before


def test_the_machines_own_daemon_is_used_and_left_running(no_daemon, monkeypatch) -> None:
    pipe = no_daemon / "pipe"
    pipe.mkdir()
    os.mkfifo(pipe / "control")                  # what a running daemon keeps in its pipe folder
    monkeypatch.setenv(cuda_mps.PIPE_ENV, str(pipe))
    with shared_gpus("on", processes_per_gpu=4) as mps:     # no control program to ask: the pipe stands
        assert mps.active and not mps.started_here and mps.pipe_dir == str(pipe)
    assert (pipe / "control").exists()
    # a control program that cannot reach it: a dead daemon's pipe, so one of the run's own is started
    with shared_gpus("auto", processes_per_gpu=4, control="/bin/false") as mps:
        assert not mps.active and mps.reason.startswith("the MPS daemon would not start")


def test_cli_bench_mps_on_without_mps_fails_before_any_process(no_daemon, capsys) -> None:
    code = main(["bench", "--processes", "2", "--mps", "on", "--num-frames", "20", "--resolution", "64", "64"])
    assert code != 0
    assert "--mps on needs CUDA MPS, but nvidia-cuda-mps-control is not on PATH" in capsys.readouterr().err


def test_sharded_run_with_address_leaves_mps_to_the_nodes(tmp_path) -> None:
    from graphsdg.jobs.job import JobSpec
    from graphsdg.jobs.scaleout import run_sharded
    job = JobSpec(script=str(tmp_path / "job.py"), out=str(tmp_path / "out"))
    with pytest.raises(ValueError, match="--mps on starts a CUDA MPS daemon on this machine; the nodes of the "
                                         "cluster at ray://head:10001 run their own"):
        run_sharded(job, 2, address="ray://head:10001", mps="on")
    with pytest.raises(ValueError, match="--mps 'always' is not one of auto, on, off"):
        run_sharded(job, 2, mps="always")
