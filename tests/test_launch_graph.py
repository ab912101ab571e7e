"""LaunchGraph: a fixed sequence of Warp launches run plainly, then recorded and replayed, on Warp's CPU device."""
from __future__ import annotations

import numpy as np
import pytest

wp = pytest.importorskip("warp")

from graphsdg.render.launch_graph import LaunchGraph  # noqa: E402


@wp.kernel(enable_backward=False)
def _scale_add(values: wp.array[wp.float32], scale: float, offset: wp.array[wp.float32]):
    i = wp.tid()
    values[i] = values[i] * scale + offset[0]


def test_replays_do_what_plain_runs_do_and_read_the_arrays_current_contents():
    plain = wp.array(np.arange(5, dtype=np.float32), device="cpu")
    graphed = wp.array(np.arange(5, dtype=np.float32), device="cpu")
    offset = wp.zeros(1, dtype=wp.float32, device="cpu")
    calls = []

    def launches():
        calls.append(1)
        wp.launch(_scale_add, dim=5, inputs=[graphed, 2.0, offset], device="cpu")

    graph = LaunchGraph("cpu", launches)
    for step in range(5):
        offset.fill_(float(step))                 # an input's contents change between runs: replays read them
        wp.launch(_scale_add, dim=5, inputs=[plain, 2.0, offset], device="cpu")
        graph.run()
        assert np.array_equal(graphed.numpy(), plain.numpy())
    assert graph.recorded and len(calls) == 2     # run once plainly, once while recording; replayed after


def test_a_sequence_that_cannot_be_recorded_runs_plainly_every_time():
    values = wp.zeros(3, dtype=wp.float32, device="cpu")
    runs = []

    def launches():
        runs.append(1)
        values.fill_(float(len(runs)))
        if len(runs) == 2:                        # the second run is the recording: fail it as Warp would
            raise RuntimeError("operation not permitted when stream is capturing")

    graph = LaunchGraph("cpu", launches)
    graph.run()
    graph.run()                                   # recording fails: this run's launches then run plainly
    graph.run()
    assert not graph.recorded and len(runs) == 4 and np.all(values.numpy() == 4.0)
