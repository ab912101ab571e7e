"""carb.eventdispatcher, the Kit events bridged to it, omni.physics.core step events, timeline looping."""
from __future__ import annotations

import asyncio
import gc

import pytest

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError, CompatImportError


@pytest.fixture
def compat():
    """The Isaac module names, for one test, on a fresh stage with a stopped, reset timeline."""
    isaac.install()
    rep.stage.new_stage()
    tl = rep.timeline.get_timeline_interface()
    yield
    tl.stop()
    tl.set_looping(False)
    tl.end_time = None   # no end time (the default): later tests play without bound
    tl.set_start_time(0.0)
    tl.set_ticks_per_frame(1)
    tl.set_time_codes_per_second(60)
    isaac.uninstall()


def _dispatcher():
    import carb.eventdispatcher
    return carb.eventdispatcher.get_eventdispatcher()


# ---- the dispatcher ------------------------------------------------------------------
def test_observers_run_by_order_then_registration_and_get_the_payload(compat):
    d = _dispatcher()
    calls = []
    guards = [d.observe_event(event_name="t:e", order=order, observer_name=tag,
                              on_event=lambda e, tag=tag: calls.append((tag, e.event_name, e["x"], e.payload)))
              for order, tag in ((10, "late"), (-5, "first"), (0, "a"), (0, "b"))]
    assert d.dispatch_event("t:e", payload={"x": 3}) == 4
    assert [c[0] for c in calls] == ["first", "a", "b", "late"]
    assert all(c[1:] == ("t:e", 3, {"x": 3}) for c in calls)
    assert [g.name for g in d.get_observers(["t:e"])] == ["first", "a", "b", "late"]
    del guards


def test_event_item_access_follows_carb(compat):
    d = _dispatcher()
    got = []
    guard = d.observe_event(event_name="t:item", on_event=got.append)
    d.dispatch_event("t:item", {"a": 1, "b": "two"})
    event = got[0]
    assert event["a"] == 1 and event.get("b") == "two"
    assert event["missing"] is None                    # carb: a missing key reads as None
    assert "a" in event and event.has_key("b") and not event.has_key("c") and len(event) == 2
    with pytest.raises(CompatError, match="carb.eventdispatcher.Event.type"):
        event.type   # noqa: B018 - an IEvent attribute the new Event does not have
    guard.reset()


def test_reset_and_dropping_the_guard_end_the_observation(compat):
    d = _dispatcher()
    calls = []
    guard = d.observe_event(event_name="t:drop", on_event=lambda e: calls.append(1))
    assert d.dispatch_event("t:drop") == 1
    guard.reset()
    guard.reset()   # a second reset does nothing
    assert d.dispatch_event("t:drop") == 0
    d.observe_event(event_name="t:drop", on_event=lambda e: calls.append(2))   # guard dropped at once
    gc.collect()
    assert d.dispatch_event("t:drop") == 0 and not d.has_observers("t:drop")
    assert calls == [1]


def test_reset_during_dispatch_and_observers_added_during_dispatch(compat):
    d = _dispatcher()
    calls = []
    guards = {}

    def first(e):
        calls.append("first")
        guards["second"].reset()                      # not called for this event any more
        guards["added"] = d.observe_event(event_name="t:during", order=100, on_event=lambda e: calls.append("added"))

    guards["first"] = d.observe_event(event_name="t:during", order=0, on_event=first)
    guards["second"] = d.observe_event(event_name="t:during", order=1, on_event=lambda e: calls.append("second"))
    assert d.dispatch_event("t:during") == 1
    assert calls == ["first"]                          # the observer added mid-dispatch waits for the next one
    guards["first"].reset()
    assert d.dispatch_event("t:during") == 1 and calls == ["first", "added"]


def test_filters_select_dispatches_by_payload(compat):
    d = _dispatcher()
    calls = []
    g1 = d.observe_event(event_name="t:win", filter={"WindowID": 1}, on_event=lambda e: calls.append(("w1", e["n"])))
    g2 = d.observe_event(event_name="t:win", on_event=lambda e: calls.append(("all", e["n"])))
    assert d.dispatch_event("t:win", {"WindowID": 2, "n": 0}) == 1
    assert d.dispatch_event("t:win", {"WindowID": 1, "n": 1}) == 2
    assert d.dispatch_event("t:win", {"n": 2}) == 1
    assert calls == [("all", 0), ("w1", 1), ("all", 1), ("all", 2)]
    assert d.has_observers("t:win", {"WindowID": 1}) and not d.has_observers("t:other")
    g1.enabled = False
    assert d.dispatch_event("t:win", {"WindowID": 1, "n": 3}) == 1
    assert d.remove_all_observers_for("t:win") == 2 and d.dispatch_event("t:win", {"n": 4}) == 0
    del g2


def test_an_observer_error_is_logged_and_the_dispatch_goes_on(compat, caplog):
    d = _dispatcher()
    calls = []
    g1 = d.observe_event(event_name="t:err", order=0, on_event=lambda e: 1 / 0, observer_name="boom")
    g2 = d.observe_event(event_name="t:err", order=1, on_event=lambda e: calls.append("after"))
    with caplog.at_level("ERROR", logger="carb"):
        assert d.dispatch_event("t:err") == 2
    assert calls == ["after"] and "boom" in caplog.text and "ZeroDivisionError" in caplog.text
    del g1, g2


def test_bad_arguments_name_themselves(compat):
    d = _dispatcher()
    with pytest.raises(TypeError, match="on_event"):
        d.observe_event(event_name="t:x", on_event=None)
    with pytest.raises(TypeError, match="event_name"):
        d.observe_event(on_event=print)
    with pytest.raises(TypeError, match="order must be an int, got 'soon'"):
        d.observe_event(event_name="t:x", on_event=print, order="soon")
    with pytest.raises(TypeError, match="payload must be a dict"):
        d.dispatch_event("t:x", payload=[1, 2])
    with pytest.raises(CompatImportError, match="carb.eventdispatcher.missing"):
        from carb.eventdispatcher import missing  # noqa: F401


def test_next_event_waits_for_the_next_dispatch(compat):
    d = _dispatcher()

    async def main():
        waiter = asyncio.ensure_future(d.next_event("t:next", filter={"k": 2}))
        await asyncio.sleep(0)
        d.dispatch_event("t:next", {"k": 1})
        await asyncio.sleep(0)
        assert not waiter.done()
        d.dispatch_event("t:next", {"k": 2, "v": "yes"})
        return await waiter

    event = asyncio.run(main())
    assert event["v"] == "yes" and not d.has_observers("t:next")


# ---- Kit's events, bridged ------------------------------------------------------------
def test_timeline_events_reach_observers_with_their_payload(compat):
    import omni.timeline
    d = _dispatcher()
    seen = []
    names = ("GLOBAL_EVENT_PLAY", "GLOBAL_EVENT_PAUSE", "GLOBAL_EVENT_STOP", "GLOBAL_EVENT_CURRENT_TIME_TICKED",
             "GLOBAL_EVENT_LOOP_MODE_CHANGED", "GLOBAL_EVENT_END_TIME_CHANGED")
    guards = [d.observe_event(event_name=getattr(omni.timeline, n), on_event=lambda e, n=n: seen.append((n, e)))
              for n in names]
    tl = omni.timeline.get_timeline_interface()
    tl.set_time_codes_per_second(60)
    tl.play()
    rep.orchestrator.update()
    rep.orchestrator.update()
    tl.pause()
    tl.set_looping(True)
    tl.set_end_time(5.0)
    tl.stop()
    kinds = [n for n, _ in seen]
    assert kinds == ["GLOBAL_EVENT_PLAY", "GLOBAL_EVENT_CURRENT_TIME_TICKED", "GLOBAL_EVENT_CURRENT_TIME_TICKED",
                     "GLOBAL_EVENT_PAUSE", "GLOBAL_EVENT_LOOP_MODE_CHANGED", "GLOBAL_EVENT_END_TIME_CHANGED",
                     "GLOBAL_EVENT_STOP"]
    ticks = [e for n, e in seen if n == "GLOBAL_EVENT_CURRENT_TIME_TICKED"]
    assert [round(e["currentTime"] * 60, 9) for e in ticks] == [1, 2] and ticks[0]["dt"] == pytest.approx(1 / 60)
    assert seen[4][1]["looping"] is True and seen[5][1]["endTime"] == 5.0
    del guards


def test_app_update_events_fire_once_per_update(compat):
    import omni.kit.app
    import omni.timeline
    d = _dispatcher()
    seen = []
    g1 = d.observe_event(event_name=omni.kit.app.GLOBAL_EVENT_UPDATE, on_event=lambda e: seen.append(e.event_name))
    g2 = d.observe_event(event_name=omni.kit.app.GLOBAL_EVENT_POST_UPDATE, on_event=lambda e: seen.append("post"))
    g3 = d.observe_event(event_name=omni.kit.app.GLOBAL_EVENT_PRE_UPDATE, on_event=lambda e: seen.append(
        ("pre", round(tl.get_current_time() * 60))))
    tick = d.observe_event(event_name=omni.timeline.GLOBAL_EVENT_CURRENT_TIME_TICKED, on_event=lambda e: seen.append(
        "tick"))
    tl = omni.timeline.get_timeline_interface()
    tl.play()
    app = omni.kit.app.get_app()
    for _ in range(2):
        app.update()
    # pre-update before the timeline moves, update and post-update after its tick
    assert seen == [("pre", 0), "tick", omni.kit.app.GLOBAL_EVENT_UPDATE, "post",
                    ("pre", 1), "tick", omni.kit.app.GLOBAL_EVENT_UPDATE, "post"]
    g1.reset()
    del g3, tick
    app.update()
    assert seen[8:] == ["post"]
    del g2


def test_stage_events_by_name(compat):
    import omni.usd
    ctx = omni.usd.get_context()
    d = _dispatcher()
    seen = []
    guards = [d.observe_event(event_name=ctx.stage_event_name(t), on_event=lambda e, t=t: seen.append(t))
              for t in (omni.usd.StageEventType.CLOSING, omni.usd.StageEventType.OPENED)]
    ctx.new_stage()
    assert seen == [omni.usd.StageEventType.CLOSING, omni.usd.StageEventType.OPENED]
    assert ctx.stage_event_type(ctx.stage_event_name(omni.usd.StageEventType.SAVED)) == omni.usd.StageEventType.SAVED
    with pytest.raises(ValueError, match="99 is not a omni.usd.StageEventType"):
        ctx.stage_event_name(99)
    del guards


def test_new_frame_events_fire_per_capture_not_per_update(compat):
    import omni.usd
    ctx = omni.usd.get_context()
    kind = omni.usd.StageRenderingEventType.NEW_FRAME
    d = _dispatcher()
    seen = []
    g1 = d.observe_event(event_name=ctx.stage_rendering_event_name(kind, True), on_event=lambda e: seen.append("imm"))
    g2 = d.observe_event(event_name=ctx.stage_rendering_event_name(kind), on_event=lambda e: seen.append(
        e["render_products"]))
    cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (32, 32))
    annot = rep.AnnotatorRegistry.get_annotator("distance_to_camera")
    rep.orchestrator.update()                          # stopped timeline, nothing renders
    assert seen == []
    annot.attach(rp)
    rep.orchestrator.step(delta_time=0.0)
    assert seen == ["imm", [rp.path]]
    assert ctx.stage_rendering_event_type(ctx.stage_rendering_event_name(kind, True)) == kind
    annot.detach()
    del g1, g2


def test_physics_step_events_before_and_after_each_step_in_order(compat):
    import omni.physics.core
    sim = omni.physics.core.get_physics_simulation_interface()
    seen = []
    post = sim.subscribe_physics_on_step_events(pre_step=False, order=0, on_update=lambda dt, c: seen.append(
        ("post", round(dt, 9), c.pre_step)))
    pre_late = sim.subscribe_physics_on_step_events(pre_step=True, order=5, on_update=lambda dt, c: seen.append(
        ("pre5", round(dt, 9), c.pre_step)))
    pre = sim.subscribe_physics_on_step_events(pre_step=True, order=-1, on_update=lambda dt, c: seen.append(
        ("pre", round(dt, 9), c.pre_step)))
    cube = rep.functional.create.cube(position=(0, 0, 2))
    rep.functional.physics.apply_rigid_body(cube)
    tl = rep.timeline.get_timeline_interface()
    tl.play()
    rep.orchestrator.update()                         # one 60 Hz frame = two 120 Hz MuJoCo steps
    step = round(1 / 120, 9)
    assert seen == [("pre", step, True), ("pre5", step, True), ("post", step, False)] * 2
    post.unsubscribe()
    del pre_late
    gc.collect()
    rep.orchestrator.update()
    assert seen[6:] == [("pre", step, True)] * 2
    pre.unsubscribe()


# ---- the timeline's bounds, looping and ticks --------------------------------------------
def test_looping_wraps_time_to_the_start_and_physics_goes_on(compat):
    import omni.timeline
    tl = omni.timeline.get_timeline_interface()
    cube = rep.functional.create.cube(position=(0, 0, 50))
    rep.functional.physics.apply_rigid_body(cube)
    tl.set_time_codes_per_second(10)
    tl.set_start_time(0.2)
    tl.set_end_time(0.5)
    tl.set_looping(True)
    assert tl.is_looping() and tl.get_end_time() == 0.5 and tl.get_current_time() == 0.2   # stopped: at the start
    tl.play()
    times, heights = [], []
    for _ in range(5):
        rep.orchestrator.update()
        times.append(round(tl.get_current_time(), 9))
        heights.append(float(cube.GetAttribute("xformOp:translate").Get()[2]))
    assert times == [0.3, 0.4, 0.2, 0.3, 0.4]        # 0.5 s is the end: it wraps to 0.2 s
    assert all(b < a for a, b in zip(heights, heights[1:]))   # the fall carries on through the wrap
    tl.stop()
    assert tl.get_current_time() == 0.2


def test_without_looping_the_timeline_pauses_at_the_end(compat):
    import omni.timeline
    tl = omni.timeline.get_timeline_interface()
    tl.set_time_codes_per_second(10)
    tl.set_end_time(0.25)
    tl.play()
    times = []
    for _ in range(4):
        rep.orchestrator.update()
        times.append(round(tl.get_current_time(), 9))
    assert times == [0.1, 0.2, 0.25, 0.25] and not tl.is_playing() and not tl.is_stopped()


def test_ticks_per_frame_split_each_frame(compat):
    import omni.timeline
    tl = omni.timeline.get_timeline_interface()
    d = _dispatcher()
    dts = []
    guard = d.observe_event(event_name=omni.timeline.GLOBAL_EVENT_CURRENT_TIME_TICKED,
                            on_event=lambda e: dts.append(round(e["dt"], 9)))
    tl.set_time_codes_per_second(30)
    tl.set_ticks_per_frame(3)
    tl.play()
    rep.orchestrator.update()
    assert dts == [round(1 / 90, 9)] * 3 and tl.get_current_time() == pytest.approx(1 / 30)
    import carb.settings                               # Kit: the same as the timeline's sub-stepping setting
    assert carb.settings.get_settings().get("/app/player/timelineSubsampleRate") == 3
    carb.settings.get_settings().set("/app/player/timelineSubsampleRate", 2)
    dts.clear()
    rep.orchestrator.update()
    assert tl.get_ticks_per_frame() == 2 and dts == [round(1 / 60, 9)] * 2
    with pytest.raises(ValueError, match="timelineSubsampleRate"):
        carb.settings.get_settings().set("/app/player/timelineSubsampleRate", 0)
    del guard


def test_timeline_rate_is_the_stage_rate_and_bad_bounds_raise(compat):
    import omni.timeline
    import omni.usd
    tl = omni.timeline.get_timeline_interface()
    tl.set_time_codes_per_second(100)
    assert omni.usd.get_context().get_stage().GetTimeCodesPerSecond() == 100
    tl.play()
    rep.orchestrator.update()
    assert tl.get_current_time() == pytest.approx(0.01)
    with pytest.raises(ValueError, match="end time -1.0 s is before the start time"):
        tl.set_end_time(-1.0)
    with pytest.raises(ValueError, match="ticks per frame must be a positive integer, got 0"):
        tl.set_ticks_per_frame(0)
    with pytest.raises(TypeError, match="set_looping takes a bool, got 'yes'"):
        tl.set_looping("yes")
