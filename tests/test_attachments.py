"""The attachment registry: annotators and writers enter and leave it, the runtime reads it."""
from __future__ import annotations

import doctest
import importlib

import pytest

import graphsdg as rep
from graphsdg.render.attachments import attachments
from graphsdg.engine.runtime import runtime


class _Counting(rep.Writer):
    def __init__(self):
        self.annotators = ["rgb"]
        self.frames = 0

    def write(self, data):
        self.frames += 1


def _product():
    rep.stage.new_stage()
    cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0))
    return rep.create.render_product(cam, (32, 24))


def test_attach_and_detach_go_through_the_registry_the_runtime_reads():
    rp = _product()
    writer = _Counting()
    writer.attach(rp)
    assert writer in attachments.writers and writer in runtime().writers
    assert [a.name for a in attachments.annotators] == ["rgb"]
    assert rep.WriterRegistry.get_attached_writers() == [writer]
    rep.orchestrator.step()
    assert writer.frames == 1
    writer.detach()
    assert writer not in attachments.writers and len(attachments.annotators) == 0


def test_a_pipelined_capture_waits_in_the_registry():
    rp = _product()
    rgb = rep.annotators.get("rgb").attach(rp)
    rep.orchestrator.step(wait_for_render=False)
    assert attachments.pending_capture is not None and runtime().pending_capture is attachments.pending_capture
    assert rgb.get_data().shape == (24, 32, 4)     # reading the data completes the capture
    assert attachments.pending_capture is None
    rgb.detach()


def test_a_new_stage_releases_every_attachment():
    rp = _product()
    writer = _Counting()
    writer.attach(rp)
    rep.stage.new_stage()
    assert rp.destroyed
    assert writer not in attachments.writers and len(attachments.annotators) == 0


@pytest.mark.parametrize("name", ["graphsdg.render.attachments", "graphsdg.physics.timeline",
                                  "graphsdg.physics.world_pose", "graphsdg.physics.bodies",
                                  "graphsdg.physics.queries", "graphsdg.sim.transforms"])
def test_docstring_examples(name):
    rep.stage.new_stage()
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
