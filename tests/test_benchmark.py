"""The benchmark's own arithmetic (its runs are measured in bench/, not timed here)."""
from __future__ import annotations

import math

from graphsdg.benchmark import _steady_rate


def _process(start: float, period: float, frames: int) -> dict:
    ends = [start + period * (i + 1) for i in range(frames)]
    return {"start": start, "wall": ends[-1] - start, "frames": frames, "frame_ends": ends}


def test_steady_rate_counts_only_frames_while_every_process_runs():
    # A: 10 frames/s from t=0 for 10 s; B: 20 frames/s from t=2 for 5 s. Both run from 2 to 7.
    a, b = _process(0.0, 0.1, 100), _process(2.0, 0.05, 100)
    assert math.isclose(_steady_rate([a, b]), 30.0, rel_tol=0.02)
    assert math.isclose(_steady_rate([a]), 10.0, rel_tol=1e-9)


def test_steady_rate_is_undefined_when_the_processes_never_overlap():
    assert math.isnan(_steady_rate([_process(0.0, 0.1, 10), _process(5.0, 0.1, 10)]))
