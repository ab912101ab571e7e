"""Trigger timing, custom events, run/stop/pause, writers gated by triggers, and build errors."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.engine import capture
from graphsdg.graph import GraphBuildError

from conftest import unit_cube_scene


def _intensity(item):
    return [p.GetAttribute("inputs:intensity").Get() for p in item.get_output_prims()["prims"]]


def _changes(item, frames):
    """Frames on which the light's sampled intensity changed (frame 0: changed from its default)."""
    out, last = [], _intensity(item)
    for f in range(frames):
        rep.orchestrator.step()
        now = _intensity(item)
        if now != last:
            out.append(f)
        last = now
    return out


@pytest.mark.parametrize("interval", [1, 3, 4])
def test_on_frame_interval_fires_on_multiples_over_20_frames(interval):
    with rep.trigger.on_frame(interval=interval):
        light = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    assert _changes(light, 20) == list(range(0, 20, interval))


def test_max_execs_stops_firing_and_trigger_outputs_count():
    with rep.trigger.on_frame(interval=3, max_execs=4) as trig:
        light = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    assert _changes(light, 20) == [0, 3, 6, 9]
    assert trig.node.exec_count == 4 and trig.node.exhausted()


def test_two_triggers_at_different_rates_in_one_graph():
    with rep.trigger.on_frame():
        fast = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    with rep.trigger.on_frame(interval=4):
        slow = rep.create.light(light_type="Disk", intensity=rep.distribution.uniform(1.0, 2.0))
    seen_fast, seen_slow = [], []
    for _ in range(10):
        rep.orchestrator.step()
        seen_fast.append(_intensity(fast)[0])
        seen_slow.append(_intensity(slow)[0])
    assert len(set(seen_fast)) == 10
    assert [i for i in range(1, 10) if seen_slow[i] != seen_slow[i - 1]] == [4, 8]


def test_on_time_fires_on_simulated_time():
    with rep.trigger.on_time(interval=1.0) as trig:
        light = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    rep.orchestrator.set_capture_on_play(False)
    fired = []
    for f in range(10):
        before = trig.node.exec_count
        rep.orchestrator.step(delta_time=0.25)
        if trig.node.exec_count > before:
            fired.append(f)
    assert fired == [0, 4, 8]
    assert abs(rep.runtime.runtime().timeline.get_current_time() - 2.5) < 1e-9
    assert _intensity(light)


def test_custom_event_fires_only_on_the_next_step():
    with rep.trigger.on_custom_event(event_name="recolor"):
        dome = rep.create.light(light_type="Dome", color=rep.distribution.uniform((0, 0, 0), (1, 1, 1)))
    colors = []
    for i in range(6):
        if i in (2, 3):
            rep.utils.send_og_event(event_name="recolor")
        rep.orchestrator.step()
        colors.append(tuple(dome.get_output_prims()["prims"][0].GetAttribute("inputs:color").Get()))
    assert colors[0] == colors[1] == (1.0, 1.0, 1.0)
    assert colors[2] != colors[1] and colors[3] != colors[2] and colors[3] == colors[4] == colors[5]


def test_unknown_event_warns_naming_known_events():
    with rep.trigger.on_custom_event(event_name="randomize_dome_light_color"):
        rep.create.light(light_type="Dome", color=rep.distribution.uniform((0, 0, 0), (1, 1, 1)))
    with pytest.warns(UserWarning, match=r"no trigger listens to event 'randomize_dome_light'.*"
                                         r"randomize_dome_light_color"):
        rep.utils.send_og_event(event_name="randomize_dome_light")


class CountingWriter(rep.Writer):
    def __init__(self):
        self.annotators = ["distance_to_image_plane"]
        self.frames = []
        self.finals = 0

    def write(self, data):
        self.frames.append((dict(data["trigger_outputs"]), data.get("provenance")))

    def on_final_frame(self):
        self.finals += 1


@pytest.fixture(autouse=True, scope="module")
def counting_writer():
    """CountingWriter registered for this module's tests only (other modules list the registry's writers)."""
    rep.WriterRegistry.register(CountingWriter)
    yield
    rep.WriterRegistry.unregister("CountingWriter")


def test_run_stops_when_every_trigger_reached_max_execs_and_calls_on_final_frame():
    _, _, rp = unit_cube_scene(resolution=(16, 12))
    with rep.trigger.on_frame(max_execs=5):
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    with rep.trigger.on_frame(interval=2, max_execs=2):
        rep.create.light(light_type="Disk", intensity=rep.distribution.uniform(1.0, 2.0))
    writer = rep.writers.get("CountingWriter")
    writer.initialize()
    writer.attach(rp)
    rep.orchestrator.run()
    assert len(writer.frames) == 5 and writer.finals == 1
    assert writer.frames[-1][0] == {"on_frame": 5, "on_frame_01": 2}
    assert rep.orchestrator.get_status() == rep.orchestrator.Status.STOPPED


def test_run_num_frames_pause_resume_and_unbounded_error():
    _, _, rp = unit_cube_scene(resolution=(16, 12))
    with rep.trigger.on_frame():
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    with pytest.raises(rep.orchestrator.OrchestratorError, match=r"\['on_frame'\] have no max_execs"):
        rep.orchestrator.run()
    writer = rep.writers.get("CountingWriter")
    writer.initialize()
    writer.attach(rp)
    handle = rep.orchestrator.register_status_callback(
        lambda s: rep.orchestrator.pause() if s == rep.orchestrator.Status.STEPPED and len(writer.frames) == 2
        else None)
    rep.orchestrator.run(num_frames=5)
    assert rep.orchestrator.get_is_paused() and len(writer.frames) == 2
    rep.orchestrator.unregister_status_callback(handle)
    rep.orchestrator.resume()
    assert len(writer.frames) == 5 and writer.finals == 1 and rep.orchestrator.get_is_stopped()


def test_writer_attached_with_a_trigger_writes_only_when_it_fires():
    _, _, rp = unit_cube_scene(resolution=(16, 12))
    trig = rep.trigger.on_frame(interval=3)
    with trig:
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    writer = rep.writers.get("CountingWriter")
    writer.initialize()
    writer.attach(rp, trigger=trig)
    for _ in range(7):
        rep.orchestrator.step()
    assert [f[0]["on_frame"] for f in writer.frames] == [1, 2, 3]


def test_step_uses_the_fired_triggers_rt_subframes(monkeypatch):
    with rep.trigger.on_frame(interval=2, rt_subframes=7):
        rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    seen = []
    monkeypatch.setattr(capture, "_capture", lambda subframes, *a, **k: seen.append(subframes))
    for _ in range(3):
        rep.orchestrator.step()
    assert seen == [7, 1, 7]


def test_preview_runs_the_graph_without_writing_and_keeps_frame_zero():
    _, _, rp = unit_cube_scene(resolution=(16, 12))
    with rep.trigger.on_frame():
        light = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1.0, 2.0))
    writer = rep.writers.get("CountingWriter")
    writer.initialize()
    writer.attach(rp)
    rep.orchestrator.preview()
    previewed = _intensity(light)
    assert previewed != [1.0] and writer.frames == []
    rep.orchestrator.step()
    assert _intensity(light) == previewed and len(writer.frames) == 1


# ---- build errors ------------------------------------------------------------
def test_on_frame_interval_zero_raises():
    with pytest.raises(ValueError, match="on_frame interval must be an integer >= 1, got 0"):
        rep.trigger.on_frame(interval=0)


def test_nested_trigger_raises_naming_both():
    with rep.trigger.on_frame(name="outer"):
        with pytest.raises(GraphBuildError, match="nested in trigger 'outer'"):
            rep.trigger.on_frame(interval=2)


def test_modify_without_target_raises():
    with pytest.raises(GraphBuildError, match=r"rep.modify.pose\(\) has no target"):
        rep.modify.pose(position=(0, 0, 1))
    with rep.trigger.on_frame():
        with pytest.raises(GraphBuildError, match=r"rep.randomizer.color\(\) has no target"):
            rep.randomizer.color(colors=rep.distribution.uniform((0, 0, 0), (1, 1, 1)))


def test_registered_randomizer_returning_a_non_item_raises():
    # returning nothing is Replicator's common form (tests/test_replicator_value_shapes.py); a stray value is not
    def confused():
        rep.create.light(light_type="Sphere")
        return 42

    rep.randomizer.register(confused)
    with pytest.raises(GraphBuildError, match="registered randomizer 'confused' returned 42"):
        rep.randomizer.confused()


def test_no_warning_for_a_listened_event():
    with rep.trigger.on_custom_event(event_name="go"):
        rep.create.light(light_type="Dome", intensity=rep.distribution.uniform(1, 2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rep.utils.send_og_event(event_name="go")
    assert np.isfinite(1.0)
