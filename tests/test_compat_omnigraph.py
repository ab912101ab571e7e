"""Isaac compat: omni.graph.core and Replicator's OmniGraph plumbing on graphsdg's node graph."""
from __future__ import annotations

import json
import math
import sys
import textwrap

import mujoco
import numpy as np
import pytest
from pxr import Gf, UsdGeom

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError
from graphsdg.engine.runtime import runtime

# A Python OmniGraph node as a Kit extension ships it: it puts each target prim at (radius * k, 0, 0), k = 1, 2, ...
_OGN = {"OgnLineUp": {"version": 1, "language": "Python", "description": "Lines prims up along X.",
                      "inputs": {"prims": {"type": "target", "default": []},
                                 "execIn": {"type": "execution"},
                                 "spacing": {"type": "float", "default": 1.0},
                                 "offset": {"type": "double[3]", "default": [0.0, 0.0, 0.0]}},
                      "outputs": {"execOut": {"type": "execution"}, "count": {"type": "int"}},
                      "state": {}}}
_PY = '''
import numpy as np
import omni.graph.core as og
import omni.usd
from pxr import Gf, UsdGeom


class OgnLineUpInternalState:
    def __init__(self):
        self.runs = 0


class OgnLineUp:
    @staticmethod
    def internal_state():
        return OgnLineUpInternalState()

    @staticmethod
    def compute(db):
        paths = db.inputs.prims
        if len(paths) == 0:
            db.outputs.execOut = og.ExecutionAttributeState.DISABLED
            return False
        db.per_instance_state.runs += 1
        stage = omni.usd.get_context().get_stage()
        offset = np.asarray(db.inputs.offset)
        for k, path in enumerate(paths):
            prim = stage.GetPrimAtPath(str(path))
            xf = UsdGeom.Xformable(prim)
            op = prim.GetAttribute("xformOp:translate")
            value = Gf.Vec3d(*(offset + [db.inputs.spacing * (k + 1) * db.per_instance_state.runs, 0.0, 0.0]))
            (op.Set(value) if op else xf.AddTranslateOp().Set(value))
        db.outputs.count = len(paths)
        db.outputs.execOut = og.ExecutionAttributeState.ENABLED
        return True
'''
_BUILDER = '''
from omni.replicator.core.utils import ReplicatorItem, ReplicatorWrapper, create_node, set_target_prims


@ReplicatorWrapper
def line_up(spacing=1.0, input_prims=None):
    node = create_node("my.line_up_ext.OgnLineUp", spacing=spacing)
    if input_prims:
        set_target_prims(node, "inputs:prims", input_prims)
    return node
'''


@pytest.fixture
def compat():
    isaac.install()
    rep.stage.new_stage()
    yield
    isaac.uninstall()


@pytest.fixture
def extension(tmp_path):
    """A Kit extension folder with one Python OmniGraph node and a module that builds it with Replicator."""
    root = tmp_path / "my.line_up_ext"
    (root / "config").mkdir(parents=True)
    (root / "config" / "extension.toml").write_text('[package]\nversion = "1.0.0"\n\n[[python.module]]\n'
                                                    'name = "my.line_up_ext"\n')
    nodes = root / "python" / "nodes"
    nodes.mkdir(parents=True)
    (nodes / "OgnLineUp.ogn").write_text(json.dumps(_OGN))
    (nodes / "OgnLineUp.py").write_text(textwrap.dedent(_PY))
    (root / "python" / "line_up_builder.py").write_text(_BUILDER)
    sys.path.insert(0, str(root / "python"))
    yield root
    sys.path.remove(str(root / "python"))
    sys.modules.pop("line_up_builder", None)


def _translate(path: str) -> tuple[float, ...]:
    return tuple(rep.stage.get_stage().GetPrimAtPath(path).GetAttribute("xformOp:translate").Get())


def test_a_python_ogn_node_of_an_extension_runs_in_the_frame_schedule(compat, extension):
    import omni.replicator.core as rep_core
    from line_up_builder import line_up        # lives in the extension: its nodes folder is searched

    cubes = rep_core.create.cube(count=3)
    with rep_core.trigger.on_frame(interval=2):
        with cubes:
            item = line_up(0.5)
    node = item.node
    assert node.get_node_type().get_node_type() == "my.line_up_ext.OgnLineUp"
    assert node.trigger is not None and node.trigger.name == "on_frame"
    paths = [str(p.GetPath()) for p in cubes.get_output_prims()["prims"]]
    for step in range(4):
        rep_core.orchestrator.step()
        runs = node.instance_state.runs
        assert runs == step // 2 + 1                        # frames 0 and 2 fire
        assert [_translate(p) for p in paths] == [(0.5 * (k + 1) * runs, 0.0, 0.0) for k in range(3)]
    assert node.get_attribute("outputs:count").get() == 3
    # the simulation saw the edits: each cube's geom is where its prim was put (runs == 2 after frame 2)
    sim = runtime().sim
    sim.sync_dirty_prims()
    c = sim.ensure_compiled()
    assert [c.data.geom_xpos[c.geoms[p].geom_id][0] for p in paths] == pytest.approx([1.0, 2.0, 3.0])


def test_disabled_exec_out_stops_the_nodes_it_feeds(compat, extension):
    import omni.graph.core as og
    og.register_ogn_nodes(str(extension / "python" / "nodes"), "my.line_up_ext")
    stage = rep.stage.get_stage()
    for name in ("A", "B"):
        UsdGeom.Xform.Define(stage, f"/{name}").AddTranslateOp().Set(Gf.Vec3d(9, 9, 9))
    controller = og.Controller()
    graph = controller.create_graph("/World/PushGraph")
    first = controller.create_node(("first", graph), "my.line_up_ext.OgnLineUp")
    second = controller.create_node(("second", graph), "my.line_up_ext.OgnLineUp")
    second.get_attribute("inputs:prims").set(["/B"])
    controller.connect(first.get_attribute("outputs:execOut"), second.get_attribute("inputs:execIn"))
    controller.evaluate_sync(graph)                   # first has no prims: execOut disabled, second skipped
    assert first.get_attribute("outputs:execOut").get() == og.ExecutionAttributeState.DISABLED
    assert _translate("/B") == (9.0, 9.0, 9.0)
    first.get_attribute("inputs:prims").set(["/A"])
    controller.evaluate_sync(graph)
    assert _translate("/A") == (1.0, 0.0, 0.0) and _translate("/B") == (1.0, 0.0, 0.0)


def test_controller_edit_builds_a_push_graph_of_replicator_nodes_and_dr_writers(compat):
    import isaacsim.replicator.experimental.domain_randomization as dr
    import omni.graph.core as og
    from isaacsim.core.experimental.prims import RigidPrim
    ball = rep.functional.create.sphere(position=(0, 0, 1), scale=0.2, name="Ball")
    rep.functional.physics.apply_collider(ball)
    rep.functional.physics.apply_rigid_body(ball)
    dr.physics_view.register_rigid_prim_view(RigidPrim("/Ball"), name="ball")
    assert dr.physics_view._rigid_prim_views_initial_values["ball"]["mass"].shape == (1, 1)
    keys = og.Controller.Keys
    graph, nodes, _, _ = og.Controller.edit("/World/DRGraph", {
        keys.CREATE_NODES: [("uniform", "omni.replicator.core.OgnSampleUniform"),
                            ("write", "isaacsim.replicator.domain_randomization.OgnWritePhysicsRigidPrimView")],
        keys.SET_VALUES: [("uniform.inputs:numSamples", 1), ("uniform.inputs:lower", [[0.2, 0.3, 0.4]]),
                          ("uniform.inputs:upper", [[0.2, 0.3, 0.4]]), ("write.inputs:prims", "ball"),
                          ("write.inputs:attribute", "material_properties"), ("write.inputs:indices", [0]),
                          ("write.inputs:operation", "direct")],
        keys.CONNECT: [("uniform.outputs:samples", "write.inputs:values")]})
    assert [n.get_node_type().get_node_type() for n in nodes] == [
        "omni.replicator.core.OgnSampleUniform", "isaacsim.replicator.domain_randomization.OgnWritePhysicsRigidPrimView"]
    og.Controller.evaluate_sync(graph)
    model = runtime().sim.model
    g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "/Ball")
    assert model.geom_friction[g, 0] == pytest.approx(0.3)
    assert model.geom_solref[g, 1] == pytest.approx(-math.log(0.4) / math.sqrt(math.pi ** 2 + math.log(0.4) ** 2))
    # an attribute path reads back what the writer wrote
    assert np.allclose(og.Controller.get("/World/DRGraph/write.outputs:values"), [[0.2, 0.3, 0.4]])
    with pytest.raises(CompatError, match="omni.graph.action.OnKeyboardInput"):   # action graphs: test_action_graphs
        og.Controller.edit("/World/DRGraph", {keys.CREATE_NODES: [("key", "omni.graph.action.OnKeyboardInput")]})
    with pytest.raises(KeyError, match="has no attribute 'inputs:nope'"):
        nodes[0].get_attribute("inputs:nope")


def test_evaluate_sync_of_replicators_graph_runs_one_step_by_hand(compat):
    import omni.graph.core as og
    import omni.replicator.core as rep_core
    from omni.replicator.core.scripts.utils import utils
    cube = rep_core.create.cube(position=(0, 0, 0))
    with rep_core.trigger.on_frame():
        with cube:
            rep_core.modify.pose(position=rep_core.distribution.uniform((1, 1, 1), (2, 2, 2)))
    graph = og.Controller().graph(utils.GRAPH_PATH)
    prim = cube.get_output_prims()["prims"][0]
    before = tuple(prim.GetAttribute("xformOp:translate").Get())
    og.Controller.evaluate_sync(graph)
    moved = np.array(prim.GetAttribute("xformOp:translate").Get())
    assert before == (0.0, 0.0, 0.0) and np.all((moved >= 1) & (moved < 2))
    assert [n.get_prim_path() for n in graph.get_nodes()][0].startswith("/Replicator/SDGPipeline/")


def test_replicator_items_wrappers_and_attribute_connections(compat):
    from omni.replicator.core.scripts.utils import ReplicatorItem, create_node
    import omni.replicator.core as rep_core
    from omni.replicator.core.utils import ReplicatorWrapper

    dist = rep_core.distribution.uniform(0.0, 1.0)
    dist.node.get_attribute("inputs:lower").set(5.0)
    dist.node.get_attribute("inputs:upper").set(5.0)
    assert dist.node.get_attribute("inputs:upper").get() == 5.0
    assert dist.node.get_node_type().get_node_type() == "omni.replicator.core.OgnSampleUniform"
    made = ReplicatorItem(create_node, "omni.replicator.core.OgnSampleNormal", mean=2.0, std=0.0)
    assert isinstance(made, ReplicatorItem) and made.node.type_name == "distribution.normal"
    assert made.node.get_attribute("inputs:mean").get() == 2.0

    @ReplicatorWrapper
    def scaled(input_prims=None):
        return rep_core.modify.pose(scale=dist, input_prims=input_prims)

    cube = rep_core.create.cube()
    with rep_core.trigger.on_frame():
        with cube:
            assert ReplicatorItem._get_context() is cube.node
            scaled()
    rep_core.orchestrator.step()
    prim = cube.get_output_prims()["prims"][0]
    assert tuple(prim.GetAttribute("xformOp:scale").Get()) == (5.0, 5.0, 5.0)


@pytest.mark.parametrize("name", ["graphsdg.graph.attributes", "graphsdg.graph.ogn"])
def test_docstring_examples(name):
    import doctest
    import importlib
    rep.stage.new_stage()
    assert doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS).failed == 0
