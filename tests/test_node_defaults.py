"""Each default is written once: a node's ports and the functional call it mirrors agree on every default."""
from __future__ import annotations

import doctest
import importlib
import inspect

import pytest

import graphsdg as rep
from graphsdg.functional import create as FC
from graphsdg.functional import create_batch as FB
from graphsdg.graph.registry import NodeRegistry
from graphsdg.nodes import mirrored_ports

FUNCTIONAL_FAMILIES = ("create", "get", "modify", "randomizer", "physics")
LIGHTS = [FC.cylinder_light, FC.disk_light, FC.distant_light, FC.dome_light, FC.rect_light, FC.sphere_light]
# node types whose functional call has another name
OTHER_NAMES = {"create.omni_lidar": ["graphsdg.functional.sensors.omni_lidar"],
               "create.omni_radar": ["graphsdg.functional.sensors.omni_radar"],
               "create.light": [f"graphsdg.functional.create.{fn.__name__}" for fn in LIGHTS]}
# ports that feed a parameter of another name
RENAMED = {("randomizer.scatter_3d", "voxel_size"): "input_voxel_size"}
# the same value spelled as two types, each as its Replicator API has it
TWO_SPELLINGS = {("randomizer.scatter_2d", "offset"): "Replicator's graph call takes the int 0, "
                                                      "rep.functional's the float 0.0"}
# where the functional call leaves an attribute unauthored (None) and the node authors Replicator's value
NODE_AUTHORS = {("create.light", "color"): "Replicator's rep.create.light authors white",
                ("create.light", "temperature"): "Replicator's rep.create.light enables 6500 K"}


def _function(dotted: str):
    module, name = dotted.rsplit(".", 1)
    return getattr(importlib.import_module(module), name)


def mirrored_pairs():
    """(node type, functional function) for every node type whose work a functional call does."""
    pairs = []
    for type_name in sorted(NodeRegistry.types()):
        family, call = type_name.split(".", 1)
        names = OTHER_NAMES.get(type_name)
        if names is None and family in FUNCTIONAL_FAMILIES:
            module = importlib.import_module(f"graphsdg.functional.{family}")
            names = [f"graphsdg.functional.{family}.{call}"] if callable(getattr(module, call, None)) else []
        pairs += [(type_name, _function(name)) for name in names or []]
    return pairs


def shared_defaults(type_name: str, fn) -> list[tuple[str, object, object]]:
    """(port, port default, parameter default) for each port of ``type_name`` that feeds a parameter of
    ``fn`` with a default, the port itself not required."""
    node_cls = NodeRegistry.get(type_name)
    params = inspect.signature(fn).parameters
    rows = []
    for port_name, port in node_cls.inputs.items():
        param = next((params[p] for p in (RENAMED.get((type_name, port_name)), port_name, f"{port_name}_value")
                      if p in params), None)
        if param is None or port.required or param.default is inspect.Parameter.empty:
            continue
        if (type_name, port_name) in NODE_AUTHORS:
            assert param.default is None, f"{type_name}.{port_name}: {fn.__name__} now has a default"
            continue
        rows.append((port_name, port.default, param.default))
    return rows


def test_every_mirroring_node_is_found():
    found = {t for t, _ in mirrored_pairs()}
    assert {"create.camera", "create.cube", "create.xform", "create.light", "get.prims", "modify.pose",
            "modify.semantics", "randomizer.rotation", "randomizer.scatter_2d", "randomizer.scatter_3d"} <= found


@pytest.mark.parametrize("type_name, fn", mirrored_pairs(), ids=lambda v: getattr(v, "__name__", v))
def test_port_defaults_equal_the_functional_defaults(type_name, fn):
    for port, port_default, fn_default in shared_defaults(type_name, fn):
        where = f"{type_name}.{port} vs {fn.__module__}.{fn.__name__}"
        assert port_default == fn_default, f"{where}: {port_default!r} != {fn_default!r}"
        if (type_name, port) not in TWO_SPELLINGS:
            assert type(port_default) is type(fn_default), f"{where}: {port_default!r} vs {fn_default!r}"


def test_the_comparison_covers_the_non_trivial_defaults():
    compared = {(t, port): d for t, fn in mirrored_pairs() for port, d, _ in shared_defaults(t, fn)
                if d is not None}
    assert compared[("create.camera", "focal_length")] == 24.0
    assert compared[("create.camera", "clipping_range")] == (0.01, 1000000.0)
    assert compared[("create.light", "intensity")] == 1000.0
    assert compared[("create.sphere", "visible")] is True and compared[("create.sphere", "as_mesh")] is False
    assert compared[("modify.pose", "rotation_order")] == "XYZ"
    assert compared[("randomizer.scatter_3d", "voxel_size")] == 0.0
    assert len(compared) >= 35


def test_a_changed_functional_default_moves_the_port_with_it():
    def lens(focal_length: float = 35.0, projection_type: str = "pinhole") -> None:
        """A stand-in functional call."""
    ports = mirrored_ports.mirrored_ports(lens, focal_length=float, projection_type=str)
    assert {k: (p.type, p.default) for k, p in ports.items()} == {"focal_length": (float, 35.0),
                                                                  "projection_type": (str, "pinhole")}
    with pytest.raises(TypeError, match=r"lens has no parameter 'f_stop' with a default"):
        mirrored_ports.mirrored_port(lens, "f_stop", float)


def test_graph_call_signatures_carry_the_functional_defaults():
    camera = inspect.signature(rep.create.camera).parameters
    for name, param in inspect.signature(FC.camera).parameters.items():
        if name in camera and name not in ("name", "parent"):
            assert camera[name].default == param.default, name
    assert inspect.signature(rep.modify.pose).parameters["rotation_order"].default == "XYZ"


@pytest.mark.parametrize("shape", ["camera", "cube", "sphere", "cylinder", "cone", "capsule", "plane", "disk",
                                   "torus"])
def test_batch_calls_take_the_single_calls_defaults(shape):
    batch = inspect.signature(getattr(FB, shape)).parameters
    single = inspect.signature(getattr(FC, shape)).parameters
    assert list(batch) == ["count", *[p for p in single if p != "as_mesh"]]
    assert batch["count"].default == 1
    for name in batch:
        if name != "count":
            assert batch[name].default == single[name].default, name


def test_batch_calls_bind_positional_and_bad_arguments_like_a_function():
    rep.stage.new_stage()
    cubes = FB.cube(2, [(0, 0, 0), (1, 0, 0)], name="Box")
    assert [str(c.GetPath()) for c in cubes] == ["/Box", "/Box_01"]
    assert [c.GetAttribute("xformOp:translate").Get()[0] for c in cubes] == [0.0, 1.0]
    cams = FB.camera(count=2, focal_length=50.0)
    assert [c.GetAttribute("focalLength").Get() for c in cams] == [50.0, 50.0]
    assert cams[0].GetAttribute("horizontalAperture").Get() == pytest.approx(20.955)
    with pytest.raises(TypeError, match=r"cube\(\) got an unexpected keyword argument 'as_mesh'"):
        FB.cube(count=1, as_mesh=True)
    with pytest.raises(ValueError, match="count must be a positive integer, got 0"):
        FB.camera(count=0)


@pytest.mark.parametrize("module", ["graphsdg.nodes.mirrored_ports", "graphsdg.functional.create_batch"])
def test_module_examples_run(module):
    assert doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS).failed == 0
