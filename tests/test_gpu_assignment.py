"""Which GPU each process renders on (issue 37): the host's GPUs, CUDA_VISIBLE_DEVICES, bench --gpus, Ray.

Everything here runs without a GPU: nvidia-smi's output and EGL's device list are given as text and lists,
the benchmark's processes really start with their own CUDA_VISIBLE_DEVICES (and render with Mesa), and
Ray gets logical GPUs.
"""
from __future__ import annotations

import doctest
import importlib
import math
import os
import re

import pytest

from graphsdg.jobs.cli import main
from graphsdg.render.gpu_assignment import (GpuCountError, GpuInfo, check_egl_sees, choose_gpus,
                                          default_processes_per_gpu, gpu_of_process, gpu_share, parse_nvidia_smi,
                                          process_environment, visible_gpus)
from graphsdg.render.egl_device import EglDeviceError, bind_visible_gpu, egl_index_of
from graphsdg.render.gpu_cores import gpu_cores, local_cores
from graphsdg.base.cpu_share import bound_to, cpu_list, parse_cpu_list

SMI = """0, GPU-0a1b2c3d-0000-0000-0000-000000000000, 00000000:18:00.0, NVIDIA H100 80GB HBM3
1, GPU-1a1b2c3d-0000-0000-0000-000000000000, 00000000:2A:00.0, NVIDIA H100 80GB HBM3
2, GPU-2a1b2c3d-0000-0000-0000-000000000000, 00000000:3A:00.0, NVIDIA H100 80GB HBM3
3, GPU-3a1b2c3d-0000-0000-0000-000000000000, 00000000:5D:00.0, NVIDIA H100 80GB HBM3
"""
HOST = parse_nvidia_smi(SMI)


def test_nvidia_smi_lines_give_index_uuid_address_and_name():
    assert [g.index for g in HOST] == [0, 1, 2, 3]
    assert HOST[2] == GpuInfo(2, "GPU-2a1b2c3d-0000-0000-0000-000000000000", "00000000:3A:00.0",
                              "NVIDIA H100 80GB HBM3")
    assert HOST[2].label() == "GPU 2 (NVIDIA H100 80GB HBM3)"
    with pytest.raises(ValueError, match="'No devices were found'"):
        parse_nvidia_smi("No devices were found")


@pytest.mark.parametrize("value, expected", [
    (None, [0, 1, 2, 3]),              # unset: every GPU
    ("", []),                          # set and empty: none
    ("2", [2]),
    ("3,1", [3, 1]),                   # CUDA's order is the variable's
    ("GPU-1a1b,0", [1, 0]),            # a UUID prefix names one GPU
    ("1,7,2", [1]),                    # the list stops at an index no GPU has...
    ("0,GPU-,3", [0]),                 # ...at a prefix several share...
    ("2,2,3", [2]),                    # ...at a GPU named twice...
    ("-1,0", []),                      # ...and at anything else
    ("MIG-1a1b", []),
])
def test_cuda_visible_devices_is_read_as_cuda_reads_it(value, expected):
    assert [g.index for g in visible_gpus(HOST, value)] == expected


def test_gpus_beyond_the_machine_fail_naming_both_counts():
    assert [g.index for g in choose_gpus(2, HOST, "3,1,0")] == [3, 1]
    with pytest.raises(GpuCountError, match=r"--gpus 4 asks for 4 GPU\(s\) but this machine has 3 .*lists 4 NVIDIA "
                                            r"GPU\(s\), CUDA_VISIBLE_DEVICES is '3,1,0'"):
        choose_gpus(4, HOST, "3,1,0")
    with pytest.raises(GpuCountError, match=r"--gpus 2 asks for 2 GPU\(s\) but this machine has 0 .*lists 0"):
        choose_gpus(2, [], None)                     # a machine without a GPU
    for bad in (0, -1, True, 1.5):
        with pytest.raises(ValueError, match="positive integer"):
            choose_gpus(bad, HOST, None)


def test_gpus_that_egl_cannot_see_fail_naming_both_counts():
    check_egl_sees(HOST[:2], [0, 1, None])                      # Mesa's device besides two NVIDIA ones: fine
    with pytest.raises(GpuCountError, match=r"--gpus 4 asks for 4 GPU\(s\) but EGL sees 2 NVIDIA device\(s\) among "
                                            r"its 3"):
        check_egl_sees(HOST, [0, 1, None])


@pytest.mark.parametrize("processes, gpus", [(16, 1), (16, 2), (32, 4), (10, 4), (4, 4), (7, 3)])
def test_processes_are_dealt_out_so_gpu_loads_differ_by_at_most_one(processes, gpus):
    counts = [0] * gpus
    for i in range(processes):
        counts[gpu_of_process(i, gpus)] += 1
    assert sum(counts) == processes and max(counts) - min(counts) <= 1 and min(counts) >= 1


def test_each_process_environment_names_its_gpu_for_cuda_and_egl():
    env = process_environment(HOST[2])
    assert env == {"CUDA_VISIBLE_DEVICES": "2", "CUDA_DEVICE_ORDER": "PCI_BUS_ID", "GRAPHSDG_GPU": "2"}
    assert [g.index for g in visible_gpus(HOST, env["CUDA_VISIBLE_DEVICES"])] == [2]


def test_default_processes_share_the_cores_among_the_gpus():
    assert [default_processes_per_gpu(g, 64) for g in (1, 2, 4, 8)] == [8, 8, 8, 8]
    assert [default_processes_per_gpu(g, 16) for g in (1, 2, 4)] == [8, 8, 4]
    assert default_processes_per_gpu(4, 2) == 1


# ---- EGL follows CUDA ------------------------------------------------------------------
def test_the_egl_device_is_the_gpu_cuda_shows():
    # drivers that number EGL devices over all GPUs, and those that number only the visible one
    assert egl_index_of([0, 1, 2, 3], 2) == 2
    assert egl_index_of([3, 2, 1, 0], 2) == 1              # EGL's own order differs from CUDA's
    assert egl_index_of([None, None, 0, None], 2) == 2
    assert egl_index_of([0, None], 0) == 0
    assert egl_index_of([None, None], 1) is None           # Mesa only


def test_binding_sets_mujocos_egl_device_and_keeps_one_the_user_set():
    env = {"CUDA_VISIBLE_DEVICES": "2"}
    value = bind_visible_gpu(2, env, cuda_ids=[3, 2, 1, 0], host_has_gpu=True)
    # MuJoCo 4 counts among the GPUs CUDA shows (this one is the first); older MuJoCo counts EGL's list
    assert value == env["MUJOCO_EGL_DEVICE_ID"] and value in ("0", "1")
    env = {"CUDA_VISIBLE_DEVICES": "2", "MUJOCO_EGL_DEVICE_ID": "5"}
    assert bind_visible_gpu(2, env, cuda_ids=[0, 1], host_has_gpu=True) == "5"


def test_a_gpu_egl_cannot_see_fails_naming_both_counts():
    env = {"CUDA_VISIBLE_DEVICES": "3"}
    with pytest.raises(EglDeviceError, match=r"GPU 3 \(CUDA_VISIBLE_DEVICES='3'\) is not among EGL's 2 device\(s\), "
                                             r"of which 1 NVIDIA"):
        bind_visible_gpu(3, env, cuda_ids=[1, None], host_has_gpu=True)
    assert "MUJOCO_EGL_DEVICE_ID" not in env
    # logical GPUs on a machine without one (Ray's, in tests): EGL's default device, no error
    assert bind_visible_gpu(1, env, cuda_ids=[None], host_has_gpu=False) is None


# ---- Ray: shares that fill every GPU and never strand a worker -------------------------
def _first_fit(shares: list[float], gpus: int) -> list[int] | None:
    """Workers per GPU as Ray's first-fit places requests in its fixed point (1e-4), or None if one is left."""
    free = [10000] * gpus
    placed = [0] * gpus
    for share in shares:
        need = round(share * 10000)
        slot = next((g for g in range(gpus) if free[g] >= need), None)
        if slot is None:
            return None
        free[slot] -= need
        placed[slot] += 1
    return placed


@pytest.mark.parametrize("gpus", [1, 2, 3, 4, 8])
def test_every_worker_fits_and_a_multiple_of_the_gpus_loads_them_alike(gpus):
    for workers in range(1, 41):
        share = gpu_share(workers, gpus)
        placed = _first_fit([share] * workers, gpus)
        assert placed is not None and sum(placed) == workers, (workers, gpus, share)
        if workers % gpus == 0:
            assert placed == [workers // gpus] * gpus
        if workers <= gpus:
            assert share == 1.0
    assert gpu_share(5, 0) == 0.0 and gpu_share(6, 1) == 0.1666


def test_the_gpu_flags_fail_before_anything_runs_on_a_machine_without_that_many(capsys, monkeypatch, job_script):
    monkeypatch.setattr("graphsdg.render.gpu_assignment._query_nvidia_smi", lambda: "")
    monkeypatch.setattr("graphsdg.render.gpu_assignment._proc_driver_gpus", lambda: [])
    monkeypatch.delenv("CUDA_VISIBLE_DEVICES", raising=False)
    assert main(["bench", "--gpus", "2", "--num-frames", "1", "--resolution", "16", "16"]) == 1
    err = capsys.readouterr().err
    assert "--gpus 2 asks for 2 GPU(s) but this machine has 0" in err and "hint: nvidia-smi" in err
    pytest.importorskip("ray")
    assert main(["run", job_script, "--workers", "2", "--gpus", "2", "--out", str(job_script) + ".out"]) == 1
    assert "--gpus 2 asks for 2 GPU(s) but this machine has 0" in capsys.readouterr().err
    assert main(["run", job_script, "--gpus", "1"]) == 1
    assert "without --workers" in capsys.readouterr().err


@pytest.fixture
def job_script(tmp_path):
    path = tmp_path / "job.py"
    path.write_text(JOB)
    return str(path)


JOB = '''
import graphsdg as rep
rep.stage.new_stage()
rep.functional.create.xform(name="World")
rep.functional.create.dome_light(intensity=500, parent="/World")
rep.functional.create.cube(parent="/World", semantics={"class": "cube"})
cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0), parent="/World")
rp = rep.create.render_product(cam, (32, 24))
with rep.trigger.on_frame():
    with rep.get.prims(semantics=[("class", "cube")]):
        rep.modify.pose(position=rep.distribution.uniform((-1.5, -1.5, 0), (1.5, 1.5, 0)))
basic = rep.writers.get("BasicWriter")
basic.initialize(output_dir="basic", rgb=True, bounding_box_2d_tight=True)
basic.attach(rp)
rep.orchestrator.run()
'''


def test_ray_spreads_workers_over_every_gpu_and_reports_each(job_script, tmp_path, capsys):
    ray = pytest.importorskip("ray")
    from graphsdg.jobs.job import JobSpec, run_job
    from graphsdg.jobs.scaleout import format_gpu_rows, run_sharded
    import graphsdg as rep
    single = JobSpec(job_script, seed=3, out=str(tmp_path / "single"), frames=8)
    run_job(single)
    rep.orchestrator.wait_until_complete()
    ray.init(address="local", num_cpus=4, num_gpus=2, include_dashboard=False)   # two logical GPUs
    try:
        summary = run_sharded(JobSpec(job_script, seed=3, out=str(tmp_path / "sharded"), frames=8), 4)
    finally:
        ray.shutdown()
    assert summary["gpus_per_worker"] == 0.5 and summary["gpus"] == 2
    assert sorted(tuple(s["gpu_ids"]) for s in summary["shards"]) == [("0",), ("0",), ("1",), ("1",)]
    rows = summary["per_gpu"]
    assert [(r["gpu"], r["workers"], r["frames"]) for r in rows] == [("0", 2, 4), ("1", 2, 4)]
    assert all(math.isclose(r["frames/s"], r["frames"] / max(s["seconds"] for s in summary["shards"]
                                                             if s["gpu_ids"] == [r["gpu"]]), rel_tol=0.01)
               for r in rows)
    assert format_gpu_rows(summary).startswith("2 GPU(s): GPU 0: 2 workers, ")
    files = {}
    for root in ("single", "sharded"):
        base = tmp_path / root / "basic"
        files[root] = {p: (base / p).read_bytes() for p in os.listdir(base)}
    assert files["single"] == files["sharded"]
    assert len([p for p in files["single"] if p.startswith("rgb_")]) == 8


def test_bench_processes_each_start_on_their_own_gpu(monkeypatch):
    from graphsdg.benchmark.multi_gpu import run_on_gpus
    from graphsdg.benchmark.throughput import BenchConfig
    config = BenchConfig(frames=2, warmup=1, resolution=(32, 24), asset_count=1, skip_write=True,
                         render_backend="classic")
    gpus = [GpuInfo(0, name="first"), GpuInfo(3, name="fourth")]
    run = run_on_gpus(config, 3, gpus)          # no NVIDIA GPU here: each renders with Mesa, bound to nothing
    assert run.total["GPUs"] == 2 and run.total["processes"] == 3
    assert [(r["GPU"], r["processes"]) for r in run.per_gpu] == [("GPU 0 (first)", 2), ("GPU 3 (fourth)", 1)]
    assert all(r["frames/s"] > 0 and r["GPU busy %"] == "-" and r["SM clock MHz"] == "-" for r in run.per_gpu)
    stolen = run.total["CPU stolen by the host %"]
    assert stolen == "-" or 0.0 <= stolen <= 100.0
    with pytest.raises(ValueError, match="--processes 1 cannot keep --gpus 2 busy"):
        run_on_gpus(config, 1, gpus)


def test_cpu_lists_read_as_linux_writes_them():
    assert parse_cpu_list("0-3,8,10-11\n") == {0, 1, 2, 3, 8, 10, 11} and parse_cpu_list("5") == {5}
    for bad in ("0-x", "3-1", "-2", "a"):
        with pytest.raises(ValueError, match=f"{bad!r} is not a CPU list"):
            parse_cpu_list(bad)
    assert cpu_list({8, 0, 1, 2, 3, 10}) == "0-3,8,10"


def test_a_gpus_local_cores_come_from_its_pci_device_in_sysfs(tmp_path):
    for address, cores in (("0000:18:00.0", "0-31"), ("0000:3a:00.0", "32-63\n")):
        (tmp_path / address).mkdir()
        (tmp_path / address / "local_cpulist").write_text(cores)
    assert local_cores(HOST[0], root=str(tmp_path)) == set(range(32))            # 00000000:18:00.0
    assert local_cores(HOST[2], root=str(tmp_path)) == set(range(32, 64))        # 00000000:3A:00.0
    assert local_cores(HOST[1], root=str(tmp_path)) is None                      # no such device here
    assert local_cores(GpuInfo(0), root=str(tmp_path)) is None                   # no PCI address known


def test_each_gpu_gets_an_equal_run_of_the_cores_near_it():
    shares = gpu_cores(HOST, range(64), local=lambda gpu: None)                 # one node (a VM): split in order
    assert [shares[i] for i in range(4)] == [list(range(16 * i, 16 * i + 16)) for i in range(4)]
    near = {0: set(range(32)), 1: set(range(32)), 2: set(range(32, 64)), 3: set(range(32, 64))}
    shares = gpu_cores(HOST, range(64), local=lambda gpu: near[gpu.index])      # two sockets, two GPUs each
    assert [(min(shares[i]), max(shares[i])) for i in range(4)] == [(0, 15), (16, 31), (32, 47), (48, 63)]
    shares = gpu_cores(HOST, range(40), local=lambda gpu: near[gpu.index])      # cores 40-63 not ours
    assert shares[2] == list(range(32, 36)) and shares[3] == list(range(36, 40))
    shares = gpu_cores(HOST, [0, 1], local=lambda gpu: None)                    # more GPUs than cores
    assert [shares[i] for i in range(4)] == [[0], [1], [0], [1]]
    with pytest.raises(ValueError, match="no usable CPU cores"):
        gpu_cores(HOST, [], local=lambda gpu: None)


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity") or len(os.sched_getaffinity(0)) < 2,
                    reason="needs two cores this process may run on")
def test_bench_processes_bound_to_cores_run_there_and_the_parent_keeps_its_own():
    from graphsdg.benchmark.throughput import BenchConfig, launch_processes
    ours = os.sched_getaffinity(0)
    first, second = sorted(ours)[:2]
    config = BenchConfig(frames=2, warmup=1, resolution=(32, 24), asset_count=1, skip_write=True,
                         render_backend="classic")
    results, _, ran = launch_processes(config, 3, [{}] * 3, cores=[[first], [second], [first]])
    assert [r["cores"] for r in results] == [[first], [second], [first]]
    assert ran.write_threads == 1 and ran.image_threads == 1       # two processes share one core
    assert os.sched_getaffinity(0) == ours
    with pytest.raises(ValueError, match="cannot bind processes to cores"):
        with bound_to([10 ** 6]):
            pass


def test_bind_cores_needs_gpus(capsys):
    assert main(["bench", "--bind-cores", "--num-frames", "1"]) == 1
    assert "--bind-cores needs --gpus" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["graphsdg.render.gpu_assignment", "graphsdg.render.egl_device",
                                  "graphsdg.benchmark.multi_gpu", "graphsdg.benchmark.gpu_sampler",
                                  "graphsdg.jobs.scaleout", "graphsdg.render.gpu_cores",
                                  "graphsdg.base.cpu_share"])
def test_the_docstring_examples_run(name):
    result = doctest.testmod(importlib.import_module(name))
    assert result.attempted > 0 and result.failed == 0


def test_gpu_rounds_take_each_counts_median_run_and_give_each_rounds_ratio():
    from graphsdg.benchmark.multi_gpu import AGGREGATE, GpuRun, median_runs, round_rows, scaling_rows

    def run(gpus: int, rate: float) -> GpuRun:
        return GpuRun(gpus=HOST[:gpus], total={AGGREGATE: rate, "processes": 16 * gpus,
                                               "CPU ms per frame (all threads)": 9.0})
    rounds = [[run(1, 2000.0), run(4, 6000.0)], [run(1, 2500.0), run(4, 4200.0)], [run(1, 1900.0), run(4, 6700.0)]]
    assert [r["x 1 GPU(s) with 4"] for r in round_rows(rounds)] == [3.0, 1.68, 3.53]
    medians = median_runs(rounds)
    assert [(len(r.gpus), r.total[AGGREGATE]) for r in medians] == [(1, 2000.0), (4, 6000.0)]
    assert [row["x 1 GPU(s)"] for row in scaling_rows(medians)] == [1.0, 3.0]
    assert [r.total[AGGREGATE] for r in median_runs(rounds[:2])] == [2000.0, 4200.0]   # even: the lower middle


def test_bench_gpu_counts_take_turns_over_rounds_and_scale_their_medians(monkeypatch, capsys):
    monkeypatch.setattr("graphsdg.render.gpu_assignment._query_nvidia_smi", lambda: SMI)
    monkeypatch.setattr("graphsdg.render.gpu_assignment.check_egl_sees", lambda *args, **kwargs: None)
    monkeypatch.setattr("graphsdg.render.egl_device.egl_cuda_devices", lambda: [])
    monkeypatch.delenv("CUDA_VISIBLE_DEVICES", raising=False)
    assert main(["bench", "--gpus", "1", "2", "--rounds", "2", "--processes-per-gpu", "1", "--num-frames", "2",
                 "--resolution", "32", "24", "--asset-count", "1", "--skip-write", "--backend", "classic",
                 "--mps", "off", "--no-baseline"]) == 0     # no NVIDIA GPU here: each process renders with Mesa
    out = capsys.readouterr().out
    for number in (1, 2):   # --bind-cores auto: one GPU's process on every core, two GPUs' on their shares
        assert f"#### 1 GPU(s), 1 processes, round {number}" in out
        assert re.search(rf"#### 2 GPU\(s\), 2 processes, each GPU's processes on its \d+ cores, round {number}", out)
    assert "#### Rounds" in out and "x 1 GPU(s) with 2" in out
    assert "#### Scaling (each count's median round)" in out


def test_bind_cores_binds_several_gpus_by_default_and_one_gpu_only_when_asked():
    from graphsdg.jobs.cli import bound_cores, build_parser

    shares = {0: [0, 1], 1: [2, 3], 2: [4, 5], 3: [6, 7]}
    assert [bound_cores("auto", n, shares) for n in (1, 2, 4)] == [None, shares, shares]
    assert [bound_cores("on", n, shares) for n in (1, 4)] == [shares, shares]
    assert [bound_cores("off", n, shares) for n in (1, 4)] == [None, None]
    parse = lambda *a: build_parser().parse_args(["bench", *a]).bind_cores   # noqa: E731
    assert (parse(), parse("--bind-cores"), parse("--bind-cores", "off")) == ("auto", "on", "off")


def test_a_gpu_shared_under_mps_gets_sixteen_processes_by_default():
    from graphsdg.jobs.scaleout import default_workers
    from graphsdg.render import cuda_mps

    assert [default_processes_per_gpu(g, 64, mps=True) for g in (1, 2, 4, 8)] == [16, 16, 16, 8]
    assert default_processes_per_gpu(4, 16, mps=True) == 4 and default_workers(4, 64, mps=True) == 64
    assert cuda_mps.would_share("on") and not cuda_mps.would_share("off")
    assert cuda_mps.would_share("auto", control="/bin/true")
    with pytest.raises(ValueError, match="sometimes"):
        cuda_mps.would_share("sometimes")


def test_a_ray_worker_given_one_gpu_of_several_runs_on_that_gpus_cores(monkeypatch):
    from graphsdg.jobs import scaleout
    from graphsdg.render.gpu_cores import assigned_share

    host = [GpuInfo(i) for i in range(4)]
    assert assigned_share(["1"], host, range(8)) == [2, 3]
    assert assigned_share([1], host, range(8), local=lambda g: {0, 1, 2, 3} if g.index < 2 else {4, 5, 6, 7}) \
        == [2, 3]
    assert assigned_share(["0", "1"], host, range(8)) is None          # a worker over two GPUs: every core
    assert assigned_share(["0"], host[:1], range(8)) is None           # one GPU: every core
    assert assigned_share(["GPU-abc"], host, range(8)) is None and assigned_share(["7"], host, range(8)) is None
    ours = os.sched_getaffinity(0)
    monkeypatch.setattr(scaleout, "host_gpus", lambda: host[:2])
    monkeypatch.setattr(scaleout, "usable_core_set", lambda: set(sorted(ours)[:2]) if len(ours) > 1 else ours)
    try:
        cores = scaleout.bind_to_assigned_gpu(["1"])
        assert os.sched_getaffinity(0) == {sorted(ours)[1 if len(ours) > 1 else 0]}
        assert cores == str(sorted(os.sched_getaffinity(0))[0])
    finally:
        os.sched_setaffinity(0, ours)
    monkeypatch.setattr(scaleout, "host_gpus", lambda: [])
    assert scaleout.bind_to_assigned_gpu(["0"]) is None and os.sched_getaffinity(0) == ours
