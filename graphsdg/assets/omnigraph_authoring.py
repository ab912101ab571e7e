"""Writing OmniGraph graphs into asset files the way Kit saves them: ``OmniGraph`` and ``OmniGraphNode`` prims.

A graph is a prim of type ``OmniGraph`` (``evaluator:type``, e.g. ``execution``
for an action graph); each node a child ``OmniGraphNode`` prim with ``node:type``
and ``node:typeVersion``. An input is a custom ``inputs:<name>`` attribute of the
USD type Kit uses for its OGN type (``double`` -> ``double``, ``vectord[3]`` ->
``vector3d``, ``quatd[4]`` -> ``quatd``, ``token[]`` -> ``token[]``, ...);
execution pins are ``uint`` attributes marked ``isExecution`` in their custom data;
a connection is the input's ``.connect`` to the upstream node's output attribute;
``target`` inputs are relationships, so they follow the asset wherever it is
referenced. graphsdg reads such graphs back in compat mode
(:mod:`graphsdg.compat.omnigraph_usd`).

Quaternion values are given as OmniGraph writes them, ``(x, y, z, w)``.

Example:
    >>> from pxr import Usd
    >>> stage = Usd.Stage.CreateInMemory()
    >>> graph = define_graph(stage, "/Graph")
    >>> tick = define_node(stage, graph, "tick", "omni.graph.action.OnPlaybackTick")
    >>> drive = define_node(stage, graph, "drive", "isaacsim.robot.wheeled_robots.DifferentialController")
    >>> set_input(drive, "wheelRadius", "double", 0.14)
    >>> connect(tick, "tick", drive, "execIn", "execution")
    >>> [str(p) for p in drive.GetAttribute("inputs:execIn").GetConnections()]
    ['/Graph/tick.outputs:tick']
"""
from __future__ import annotations

from typing import Any, Iterable

from pxr import Gf, Sdf, Usd

# OGN attribute types -> the USD value types Kit saves them as
USD_TYPES: dict[str, Sdf.ValueTypeName] = {
    "bool": Sdf.ValueTypeNames.Bool, "int": Sdf.ValueTypeNames.Int, "uint": Sdf.ValueTypeNames.UInt,
    "int64": Sdf.ValueTypeNames.Int64, "double": Sdf.ValueTypeNames.Double, "float": Sdf.ValueTypeNames.Float,
    "token": Sdf.ValueTypeNames.Token, "string": Sdf.ValueTypeNames.String, "timecode": Sdf.ValueTypeNames.TimeCode,
    "double[2]": Sdf.ValueTypeNames.Double2, "double[3]": Sdf.ValueTypeNames.Double3,
    "vectord[3]": Sdf.ValueTypeNames.Vector3d, "pointd[3]": Sdf.ValueTypeNames.Point3d,
    "quatd[4]": Sdf.ValueTypeNames.Quatd, "matrixd[4]": Sdf.ValueTypeNames.Matrix4d,
    "bool[]": Sdf.ValueTypeNames.BoolArray, "int[]": Sdf.ValueTypeNames.IntArray,
    "double[]": Sdf.ValueTypeNames.DoubleArray, "token[]": Sdf.ValueTypeNames.TokenArray,
    "execution": Sdf.ValueTypeNames.UInt,
}


def _usd_type(ogn_type: str) -> Sdf.ValueTypeName:
    try:
        return USD_TYPES[ogn_type]
    except KeyError:
        raise ValueError(f"OGN type {ogn_type!r} has no USD type here; known: {sorted(USD_TYPES)}") from None


def define_graph(stage: Usd.Stage, path: str, evaluator: str = "execution") -> Usd.Prim:
    """An ``OmniGraph`` prim at ``path`` run by ``evaluator`` (``execution``: an action graph)."""
    prim = stage.DefinePrim(path, "OmniGraph")
    prim.CreateAttribute("evaluator:type", Sdf.ValueTypeNames.Token).Set(evaluator)
    prim.CreateAttribute("evaluationMode", Sdf.ValueTypeNames.Token).Set("Automatic")
    prim.CreateAttribute("fileFormatVersion", Sdf.ValueTypeNames.Int2).Set(Gf.Vec2i(1, 9))
    prim.CreateAttribute("pipelineStage", Sdf.ValueTypeNames.Token).Set("pipelineStageSimulation")
    return prim


def define_node(stage: Usd.Stage, graph: Usd.Prim, name: str, node_type: str, version: int = 1) -> Usd.Prim:
    """An ``OmniGraphNode`` prim ``name`` of type ``node_type`` in ``graph``."""
    prim = stage.DefinePrim(graph.GetPath().AppendChild(name), "OmniGraphNode")
    prim.CreateAttribute("node:type", Sdf.ValueTypeNames.Token).Set(node_type)
    prim.CreateAttribute("node:typeVersion", Sdf.ValueTypeNames.Int).Set(int(version))
    return prim


def _value(ogn_type: str, value: Any) -> Any:
    """``value`` as the USD type of ``ogn_type`` takes it (quaternions given as x, y, z, w)."""
    if ogn_type == "quatd[4]":
        x, y, z, w = (float(v) for v in value)
        return Gf.Quatd(w, x, y, z)
    if ogn_type == "matrixd[4]":
        return Gf.Matrix4d(*[float(v) for row in value for v in row])
    return value


def _attribute(node: Usd.Prim, name: str, ogn_type: str) -> Usd.Attribute:
    attr = node.CreateAttribute(name, _usd_type(ogn_type), custom=True)
    if ogn_type == "execution":
        attr.SetCustomDataByKey("isExecution", True)
    return attr


def set_input(node: Usd.Prim, name: str, ogn_type: str, value: Any) -> None:
    """Author input ``inputs:<name>`` (OGN type ``ogn_type``) of ``node`` with ``value``."""
    _attribute(node, f"inputs:{name}", ogn_type).Set(_value(ogn_type, value))


def set_targets(node: Usd.Prim, name: str, targets: Iterable[str | Sdf.Path]) -> None:
    """Point ``target`` input ``inputs:<name>`` of ``node`` at the prims ``targets``."""
    rel = node.CreateRelationship(f"inputs:{name}", custom=True)
    rel.SetCustomDataByKey("omni", {"graph": {"relType": "target"}})
    rel.SetTargets([Sdf.Path(str(t)) for t in targets])


def connect(source: Usd.Prim, output: str, dest: Usd.Prim, input_: str, ogn_type: str) -> None:
    """Feed ``dest``'s ``inputs:<input_>`` from ``source``'s ``outputs:<output>`` (both of OGN type ``ogn_type``)."""
    out = _attribute(source, f"outputs:{output}", ogn_type)
    _attribute(dest, f"inputs:{input_}", ogn_type).AddConnection(out.GetPath())


__all__ = ["USD_TYPES", "connect", "define_graph", "define_node", "set_input", "set_targets"]
