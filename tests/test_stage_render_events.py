"""Kit's stage rendering events in compat mode: the viewport's frame on app updates while someone observes
NEW_FRAME, a capture's products otherwise; and rep.orchestrator.draw, the render behind the viewport frame."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import UsdGeom

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.render.render_product import registry


@pytest.fixture
def compat():
    isaac.install()
    import omni.usd
    omni.usd.get_context().new_stage()   # the USD context authors Kit's viewport cameras
    yield
    rep.timeline.get_timeline_interface().stop()
    isaac.uninstall()


def _observe_new_frames(seen: list):
    import carb.eventdispatcher
    import omni.usd
    ctx = omni.usd.get_context()
    kind = omni.usd.StageRenderingEventType.NEW_FRAME
    d = carb.eventdispatcher.get_eventdispatcher()
    return [d.observe_event(event_name=ctx.stage_rendering_event_name(kind, immediate),
                            on_event=lambda e, immediate=immediate: seen.append((immediate, e["render_products"])))
            for immediate in (True, False)]


def test_observed_app_updates_draw_the_viewport_and_send_new_frame(compat):
    import omni.kit.app
    from omni.kit.viewport.utility import get_active_viewport
    app = omni.kit.app.get_app()
    app.update()
    assert not [p for p in registry if p.name == "Viewport"]      # unobserved: nothing drawn, no product made
    seen = []
    guards = _observe_new_frames(seen)
    rep.timeline.get_timeline_interface().play()
    for _ in range(3):
        app.update()
    viewport_path = get_active_viewport().render_product_path
    assert seen == [(True, [viewport_path]), (False, [viewport_path])] * 3
    rep.timeline.get_timeline_interface().stop()
    app.update()                                                   # Kit draws its viewport while stopped too
    assert len(seen) == 8
    for guard in guards:
        guard.reset()
    app.update()
    assert len(seen) == 8


def test_a_capture_sends_its_products_and_no_extra_viewport_frame(compat):
    import omni.kit.app
    cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (16, 16))
    rgb = rep.annotators.get("rgb").attach(rp)
    seen = []
    guards = _observe_new_frames(seen)
    rep.timeline.get_timeline_interface().play()       # capture on play: each app update captures rp
    omni.kit.app.get_app().update()
    assert seen == [(True, [rp.path]), (False, [rp.path])]
    rgb.detach()
    del guards


def test_draw_renders_what_a_capture_renders():
    rep.functional.create.dome_light(intensity=600)
    cube = rep.functional.create.cube(position=(0, 0, 0))
    UsdGeom.Gprim(cube).CreateDisplayColorAttr([(0.8, 0.2, 0.1)])
    cam = rep.functional.create.camera(position=(0, -4, 0), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (32, 24))
    heard = []
    from graphsdg.engine.runtime import runtime
    runtime().render_observers.append(heard.append)
    try:
        captured = rep.orchestrator.frames_captured()
        drawn = rep.orchestrator.draw([rp])[0].get("color")
        assert rep.orchestrator.frames_captured() == captured       # a draw is not a captured frame
        rgb = rep.annotators.get("rgb").attach(rp)
        rep.orchestrator.step(delta_time=0.0)
        assert np.array_equal(drawn, rgb.get_data())
        assert (drawn[..., 0] > drawn[..., 2] + 50).any()            # the red cube is in the picture
        assert heard == [[rp.path], [rp.path]]
        assert rep.orchestrator.frames_captured() == captured + 1
        rgb.detach()
    finally:
        runtime().render_observers.remove(heard.append)
