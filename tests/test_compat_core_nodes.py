"""Isaac compat: isaacsim.core.nodes' Python names (reset-on-stop node state, queued writer attachment, helpers)."""
from __future__ import annotations

import os

import pytest

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.io.writer import WriterRegistry
from graphsdg.engine.runtime import runtime


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def test_reset_node_resets_on_stop(compat):
    from isaacsim.core.nodes import BaseResetNode

    class Counter(BaseResetNode):
        resets = 0

        def custom_reset(self):
            Counter.resets += 1

    node = Counter(initialize=True)
    timeline = runtime().timeline
    timeline.play()
    timeline.stop()
    assert Counter.resets == 1 and node.initialized is False
    node.reset()
    timeline.play()
    timeline.stop()
    assert Counter.resets == 1 and node.initialized is None


def test_writer_node_attaches_a_copy_at_the_next_app_update_and_detaches_on_stop(compat, tmp_path):
    import omni.kit.app
    from isaacsim.core.nodes import BaseWriterNode
    rep.stage.new_stage()
    rep.functional.create.cube(semantics=[("class", "cube")])
    camera = rep.functional.create.camera(position=(0, 0, 5), look_at=(0, 0, 0))
    rp = rep.create.render_product(camera, (32, 24))
    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir=str(tmp_path), rgb=True)
    attached = []

    class Node(BaseWriterNode):
        def post_attach(self, w, render_product):
            attached.append((type(w).__name__, render_product))

    node = Node()
    node.attach_writer(writer, rp.path)
    assert WriterRegistry.get_attached_writers() == []          # queued until the next app update
    omni.kit.app.get_app().update()
    (copy,) = WriterRegistry.get_attached_writers()
    assert copy is not writer and attached == [("BasicWriter", rp.path)]
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    assert "rgb_0000.png" in os.listdir(tmp_path)
    timeline = runtime().timeline
    timeline.play()
    timeline.stop()                                             # stop queues the detach
    omni.kit.app.get_app().update()
    assert WriterRegistry.get_attached_writers() == []
    node.reset()


def test_registrations_need_omnigraph_and_target_prims(compat):
    from isaacsim.core.nodes import register_annotator_from_node_with_telemetry, register_node_writer_with_telemetry
    from isaacsim.core.nodes.scripts.utils import set_target_prims
    with pytest.raises(Exception, match="register_node_writer"):
        register_node_writer_with_telemetry(name="MyNodeWriter", node_type_id="x.Y", annotators=[])
    assert "MyNodeWriter" not in WriterRegistry._default_writers
    with pytest.raises(NotImplementedError, match="register_annotator_from_function"):
        register_annotator_from_node_with_telemetry(name="MyAnnot", input_rendervars=[], node_type_id="x.Y")
    stage = rep.stage.new_stage()
    rep.functional.create.xform(name="Node")
    rep.functional.create.cube(name="A")
    set_target_prims("/Node", ["/A"], "inputs:targetPrim")
    assert [str(p) for p in stage.GetPrimAtPath("/Node").GetRelationship("inputs:targetPrim").GetTargets()] == ["/A"]
    with pytest.raises(ValueError, match="no prim at '/Missing'"):
        set_target_prims("/Missing", ["/A"])
