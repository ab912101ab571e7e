"""The share of a machine's CPU time its host took (graphsdg/benchmark/host_steal.py): /proc/stat's steal."""
from __future__ import annotations

import os
import time

from graphsdg.benchmark.gpu_sampler import parse_samples, summarize
from graphsdg.benchmark.host_steal import CpuTimesSampler, parse_cpu_times, read_cpu_times, steal_percent


def test_cpu_times_are_the_aggregate_lines_first_eight_fields():
    times = parse_cpu_times("cpu  10 1 5 80 2 0 1 7 3 0", stamp=4.0)
    assert (times.stamp, times.total, times.steal) == (4.0, 106, 7)     # guest (3) is inside user already
    for other in ("cpu0 10 1 5 80 2 0 1 7 3 0", "intr 1 2 3", "cpu 1 2 3", "cpu a b c d e f g h", ""):
        assert parse_cpu_times(other, 0.0) is None


def test_steal_is_the_stolen_share_between_the_windows_first_and_last_samples():
    line = "cpu  {user} 0 0 {idle} 0 0 0 {steal} 0 0"
    samples = [parse_cpu_times(line.format(user=u, idle=i, steal=st), stamp=t)
               for t, u, i, st in [(0.0, 0, 0, 0), (1.0, 100, 100, 0), (2.0, 200, 150, 50), (3.0, 350, 150, 300)]]
    assert steal_percent(samples, 1.0, 3.0) == 50.0      # (300 - 0) of (800 - 200)
    assert steal_percent(samples, 0.5, 2.5) == 25.0      # (50 - 0) of (400 - 200)
    assert steal_percent(samples, 2.5, 9.0) is None      # one sample only
    assert steal_percent([], 0.0, 1.0) is None


def test_the_sampler_reads_the_file_as_it_changes(tmp_path):
    stat = tmp_path / "stat"
    stat.write_text("cpu  100 0 0 900 0 0 0 0 0 0\ncpu0 1 2 3 4 5 6 7 8 9 10\n")
    with CpuTimesSampler(interval=0.02, path=str(stat)) as sampler:
        time.sleep(0.1)
        start = time.time()
        time.sleep(0.3)                                              # samples of the first counts in the window
        stat.write_text("cpu  400 0 0 1200 0 0 0 400 0 0\n")       # 300 busy, 300 idle, 400 stolen
        time.sleep(0.3)
    assert steal_percent(sampler.samples, start - 0.01, time.time()) == 40.0
    assert sampler.samples[-1].steal == 400


def test_a_machine_without_proc_stat_gives_no_samples(tmp_path):
    absent = str(tmp_path / "absent")
    assert read_cpu_times(absent) is None
    with CpuTimesSampler(interval=0.01, path=absent) as sampler:
        time.sleep(0.05)
    assert sampler.samples == []
    if os.path.exists("/proc/stat"):                      # Linux: this machine's own counters move forward
        first = read_cpu_times()
        time.sleep(0.05)
        assert read_cpu_times().total >= first.total > 0


def test_gpu_samples_carry_the_sm_clock():
    samples = parse_samples(["0, 50, 100, 1500", "0, 70, 120, 1700", "1, [N/A], 5, 900", "2, 10, 20"], stamp=1.0)
    assert [(s.index, s.sm_clock_mhz) for s in samples] == [(0, 1500.0), (0, 1700.0)]
    assert summarize(samples, 0.0, 2.0) == {0: (60.0, 120.0, 1600.0)}
