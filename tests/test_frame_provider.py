"""The engine asks the graph through one typed provider: what it answers, and a capture without a graph."""
from __future__ import annotations

import dataclasses

import pytest

import graphsdg as rep
from graphsdg.engine import capture
from graphsdg.engine.frame_provider import NO_GRAPH, GraphStep
from graphsdg.engine.runtime import runtime
from graphsdg.graph.frame_provider import GRAPH_FRAMES
from graphsdg.graph.node import ReplicatorItem


def _light_intensity():
    prim = rep.stage.get_stage().GetPrimAtPath("/Replicator/SphereLight_Xform/SphereLight")
    return prim.GetAttribute("inputs:intensity").Get()


def test_the_graph_is_the_runtimes_provider_and_a_step_is_typed():
    assert runtime().frame_provider is GRAPH_FRAMES
    with rep.trigger.on_frame(interval=2, max_execs=3, rt_subframes=4) as trig:
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(100.0, 200.0))
    provider = runtime().frame_provider
    steps = [provider.step(0.0) for _ in range(3)]
    assert all(isinstance(s, GraphStep) for s in steps)
    # fires on frames 0 and 2: the fired trigger is the item writers gated on it compare with
    assert [s.fired for s in steps] == [frozenset({ReplicatorItem(trig.node)}), frozenset(),
                                        frozenset({ReplicatorItem(trig.node)})]
    assert [s.trigger_outputs for s in steps] == [{"on_frame": 1}, {"on_frame": 1}, {"on_frame": 2}]
    assert [s.rt_subframes for s in steps] == [4, 0, 4]
    assert [s.provenance["frame"] for s in steps] == [0, 1, 2]
    assert steps[2].provenance["fired"] == ["on_frame"]
    light = steps[2].provenance["nodes"]["light"]
    assert (light["frame"], light["execution"]) == (2, 1)
    assert light["values"]["intensity"] == [pytest.approx(_light_intensity(), rel=1e-6)]   # as authored (float)
    with pytest.raises(dataclasses.FrozenInstanceError):
        steps[0].rt_subframes = 1


def test_the_provider_answers_the_run_loops_questions():
    provider = runtime().frame_provider
    assert provider.frame() is None and not provider.counts_frames() and provider.planned_length() is None
    with rep.trigger.on_frame(interval=3, max_execs=4):
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    assert provider.frame() == 0 and provider.counts_frames() and provider.unlimited_triggers() == []
    assert provider.planned_length() == (4 - 1) * 3 + 1      # the frame of the last execution, plus one
    for _ in range(9):
        assert not provider.exhausted()
        provider.step(0.0)
    assert not provider.exhausted()                          # three executions, on frames 0, 3, 6
    provider.step(0.0)                                       # frame 9: the fourth
    assert provider.exhausted() and provider.frame() == 10


def test_seek_and_preview_through_the_provider_give_an_uninterrupted_runs_values():
    with rep.trigger.on_frame():
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    provider = runtime().frame_provider
    values = []
    for _ in range(5):
        provider.step(0.0)
        values.append(_light_intensity())
    provider.seek(3)
    assert provider.frame() == 3 and _light_intensity() == values[2]    # the stage as frame 2 left it
    provider.step(0.0)
    assert _light_intensity() == values[3]
    provider.preview()                                       # frame 4's values, counters put back
    assert provider.frame() == 4 and _light_intensity() == values[4]
    provider.step(0.0)
    assert _light_intensity() == values[4]


def test_without_a_graph_a_step_captures_with_nothing_fired(monkeypatch):
    seen = []
    monkeypatch.setattr(runtime(), "frame_provider", NO_GRAPH)
    monkeypatch.setattr(capture, "_capture", lambda subframes, graph, defer=False: seen.append((subframes, graph)))
    rep.orchestrator.step()
    assert seen == [(1, GraphStep())] and seen[0][1].provenance == {} and not seen[0][1].fired


def test_a_subframe_request_holds_for_the_next_capture_only(monkeypatch):
    seen = []
    monkeypatch.setattr(capture, "_capture", lambda subframes, graph, defer=False: seen.append(subframes))
    capture.request_next_subframes(3)
    capture.request_next_subframes(2, minimum=True)          # at least 2: 3 stays
    rep.orchestrator.step()
    capture.request_next_subframes(6)
    capture.withdraw_subframe_request()
    rep.orchestrator.step()
    assert seen == [3, 1]
    for bad in (0, -2, True, 1.5):
        with pytest.raises(ValueError, match="positive integer"):
            capture.request_next_subframes(bad)
