"""Node types written as OmniGraph Python nodes: an ``.ogn`` definition plus a class with ``compute(db)``.

A Kit extension ships a node type as two files in its ``nodes`` folder:
``OgnFoo.ogn`` (JSON: the type's name, description, ``inputs`` / ``outputs`` /
``state`` attributes with their ``type`` and ``default``) and ``OgnFoo.py``
defining class ``OgnFoo`` whose static ``compute(db)`` reads ``db.inputs.<name>``,
writes ``db.outputs.<name>`` and returns True on success (optionally
``internal_state()``, the per-node object ``db.per_instance_state`` /
``db.internal_state``; a state with a ``node`` attribute left None gets the
node, as Kit's ``init_instance`` hooks give it). :func:`load_folder` turns each
pair into a graphsdg node type: its ports are the definition's attributes, its
compute builds a :class:`Database` and calls the class's. A type named without dots
(``"OgnFoo"``) is registered as ``<extension>.OgnFoo``, as Kit does.

Values a compute reads: ``target`` attributes give the prims' paths
(``Sdf.Path``), arrays give numpy arrays, a distribution's samples the array of
its draws. Execution attributes: a node whose ``execIn`` is fed by other nodes'
``execOut`` (any number of them) runs only when one of them ran in the same
evaluation and set its ``execOut`` to anything but
:attr:`ExecutionState.DISABLED`; a compute that leaves ``execOut`` unset enables
it when it returns True.

Example:
    >>> import json, pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "OgnTwice.ogn").write_text(json.dumps({"OgnTwice": {"description": "Doubles x.",
    ...     "inputs": {"x": {"type": "float", "default": 1.0}}, "outputs": {"y": {"type": "float"}}}}))
    >>> _ = (folder / "OgnTwice.py").write_text(
    ...     "class OgnTwice:\\n    @staticmethod\\n    def compute(db):\\n        db.outputs.y = 2 * db.inputs.x\\n"
    ...     "        return True\\n")
    >>> [cls.type_name for cls in load_folder(folder, "my.ext")]
    ['my.ext.OgnTwice']
"""
from __future__ import annotations

import enum
import importlib.util
import json
import logging
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from graphsdg.graph.attributes import EXEC_IN, readable
from graphsdg.graph.node import ExecContext, Node, Port, flatten_prims
from graphsdg.graph.registry import NodeRegistry

log = logging.getLogger("graphsdg.ogn")


class ExecutionState(enum.IntEnum):
    """The value of an execution attribute (OmniGraph's ``ExecutionAttributeState``)."""

    DISABLED = 0
    ENABLED = 1
    ENABLED_AND_PUSH = 2
    LATENT_PUSH = 3
    LATENT_FINISH = 4


# OGN base types -> (numpy dtype, value when no default is given)
_BASE_TYPES: dict[str, tuple[Any, Any]] = {
    "bool": (np.bool_, False), "int": (np.int32, 0), "uint": (np.uint32, 0), "int64": (np.int64, 0),
    "uint64": (np.uint64, 0), "uchar": (np.uint8, 0), "float": (np.float32, 0.0), "double": (np.float64, 0.0),
    "half": (np.float16, 0.0), "timecode": (np.float64, 0.0), "token": (object, ""), "string": (object, ""),
    "path": (object, ""), "target": (object, []), "execution": (None, ExecutionState.DISABLED),
    "any": (None, None), "objectId": (np.uint64, 0),
}
_ROLE_TYPES = ("colorf", "colord", "colorh", "normalf", "normald", "normalh", "pointf", "pointd", "pointh",
               "vectorf", "vectord", "vectorh", "quatf", "quatd", "quath", "texcoordf", "texcoordd", "texcoordh",
               "matrixd", "frame")


@dataclass(frozen=True)
class AttributeType:
    """A parsed OGN type string: base type, tuple count (``float[3]``: 3) and array depth (``[]``: 1)."""

    base: str
    tuple_count: int = 1
    array_depth: int = 0

    @classmethod
    def parse(cls, text: Any, where: str) -> "AttributeType":
        if isinstance(text, list):       # a union: values keep whatever type they are given
            return cls("any")
        raw = str(text).strip()
        depth = 0
        while raw.endswith("[]"):
            raw, depth = raw[:-2], depth + 1
        count = 1
        if raw.endswith("]") and "[" in raw:
            raw, _, n = raw[:-1].partition("[")
            count = int(n)
        base = raw
        for role in _ROLE_TYPES:       # role types are tuples of a float kind: colorf[3] and the like
            if base == role:
                base = {"f": "float", "d": "double", "h": "half"}.get(role[-1], "double")
                if role in ("matrixd", "frame"):   # matrixd[4] is a 4 x 4 matrix: 16 values
                    count = count * count if count > 1 else 16
                else:
                    count = count if count > 1 else (4 if role.startswith("quat") else 3)
        if base not in _BASE_TYPES:
            raise ValueError(f"{where}: attribute type {text!r} is not one graphsdg reads; known base types: "
                             f"{sorted(_BASE_TYPES)} (with [n] tuples and [] arrays)")
        return cls(base, count, depth)

    def default(self) -> Any:
        if self.array_depth or self.base == "target":
            return []
        if self.tuple_count > 1:
            return np.zeros(self.tuple_count, dtype=_BASE_TYPES[self.base][0])
        return _BASE_TYPES[self.base][1]


@dataclass
class Definition:
    """One node type of an ``.ogn`` file."""

    type_name: str
    description: str
    inputs: dict[str, tuple[AttributeType, Any]] = field(default_factory=dict)
    outputs: dict[str, tuple[AttributeType, Any]] = field(default_factory=dict)
    state: dict[str, tuple[AttributeType, Any]] = field(default_factory=dict)


def _attributes(section: dict, where: str) -> dict[str, tuple[AttributeType, Any]]:
    out = {}
    for name, spec in (section or {}).items():
        t = AttributeType.parse(spec.get("type", "any"), f"{where} {name}")
        out[name] = (t, spec.get("default", t.default()))
    return out


def definition_from_spec(type_name: str, spec: dict, where: str = "") -> Definition:
    """The :class:`Definition` of node type ``type_name`` from its OGN JSON ``spec`` (one entry of an
    ``.ogn`` file: ``description``, ``inputs`` / ``outputs`` / ``state`` with ``type`` and ``default``)."""
    where = where or type_name
    text = spec.get("description", "")
    description = " ".join(text) if isinstance(text, list) else str(text)
    return Definition(type_name, description, _attributes(spec.get("inputs"), f"{where}: input"),
                      _attributes(spec.get("outputs"), f"{where}: output"),
                      _attributes(spec.get("state"), f"{where}: state"))


def parse_definition(path: Path, extension: str) -> list[Definition]:
    """The node types defined in ``.ogn`` file ``path`` (names without a dot get ``extension.`` in front)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: not valid OGN JSON ({exc})") from None
    return [definition_from_spec(key if "." in key else f"{extension}.{key}", spec, str(path))
            for key, spec in data.items()]


class _Values:
    """``db.inputs`` / ``db.outputs`` / ``db.state``: attribute values by name."""

    def __init__(self, names: dict[str, Any], read, write=None) -> None:
        object.__setattr__(self, "_names", names)
        object.__setattr__(self, "_read", read)
        object.__setattr__(self, "_write", write)

    def __getattr__(self, name: str) -> Any:
        if name not in self._names:
            raise AttributeError(f"no attribute {name!r}; this node has {sorted(self._names)}")
        return self._read(name)

    def __setattr__(self, name: str, value: Any) -> None:
        if self._write is None:
            raise AttributeError(f"inputs are read-only in compute; cannot set {name!r}")
        if name not in self._names:
            raise AttributeError(f"no attribute {name!r}; this node has {sorted(self._names)}")
        self._write(name, value)


class Database:
    """What an OmniGraph Python node's ``compute(db)`` sees (see the module docstring)."""

    def __init__(self, node: "OgnNode", ctx: ExecContext) -> None:
        self.node = node
        self.ctx = ctx
        self.written: dict[str, Any] = {}
        self.inputs = _Values(node.definition.inputs, self._input)
        self.outputs = _Values(node.definition.outputs, self._output, self._set_output)
        self.state = _Values(node.definition.state, node.state_values.get, node.state_values.__setitem__)

    @property
    def per_instance_state(self) -> Any:
        return self.node.instance_state

    @property
    def internal_state(self) -> Any:
        return self.node.instance_state

    def _input(self, name: str) -> Any:
        t, _ = self.node.definition.inputs[name]
        if t.base == "execution":
            return self.node.exec_input_state(self.ctx.frame)
        value = readable(self.ctx.value(name))
        if t.base == "target":
            return [p.GetPath() for p in flatten_prims(value, f"{self.node.type_name} inputs:{name}")]
        return _typed(value, t)

    def _output(self, name: str) -> Any:
        return self.written.get(name, self.node.output_values.get(name))

    def _set_output(self, name: str, value: Any) -> None:
        self.written[name] = value

    def log_error(self, message: str, *args: Any) -> None:
        """Record an error of this compute (logged and kept in ``node.errors``)."""
        log.error("%s: %s", self.node.name, message)
        self.node.errors.append(str(message))

    def log_warning(self, message: str, *args: Any) -> None:
        log.warning("%s: %s", self.node.name, message)
        self.node.warnings.append(str(message))

    def log_warn(self, message: str, *args: Any) -> None:
        self.log_warning(message)


def _typed(value: Any, t: AttributeType) -> Any:
    """``value`` as the attribute type reads (arrays and tuples as numpy arrays)."""
    if value is None or t.base == "any":
        return value
    dtype = _BASE_TYPES[t.base][0]
    if t.array_depth or t.tuple_count > 1:
        if dtype is object:
            return list(value)
        arr = np.asarray(value, dtype=dtype)
        return arr.reshape(-1, t.tuple_count) if t.array_depth and t.tuple_count > 1 else arr
    if dtype is object:
        return value if t.base != "path" else str(value)
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.reshape(-1)[0]
    return np.asarray(value, dtype=dtype).item() if dtype is not np.bool_ else bool(value)


class OgnNode(Node):
    """Base of node types made from ``.ogn`` definitions (see the module docstring)."""

    family = "randomizer"
    definition: ClassVar[Definition]
    implementation: ClassVar[type]
    omnigraph_type: ClassVar[str] = ""

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        make_state = getattr(self.implementation, "internal_state", None)
        self.instance_state = make_state() if callable(make_state) else None
        if getattr(self.instance_state, "node", False) is None:
            self.instance_state.node = self     # what a node's init_instance(node, ...) gives its state in Kit
        self.state_values: dict[str, Any] = {n: d for n, (_, d) in self.definition.state.items()}
        self.output_values = {n: d for n, (_, d) in self.definition.outputs.items()}
        self.errors: list[str] = []
        self.warnings: list[str] = []

    def exec_input_state(self, frame: int) -> ExecutionState:
        """ENABLED when nothing but triggers feeds ``execIn``, or when one of the execution outputs feeding it ran
        on ``frame`` and is not disabled."""
        sources = [(up, port) for up, port in self.input_sources(EXEC_IN) if up.family != "trigger"]
        if not sources or any(up.last_frame == frame and up.output_values.get(port) != ExecutionState.DISABLED
                              for up, port in sources):
            return ExecutionState.ENABLED
        return ExecutionState.DISABLED

    def compute(self, ctx: ExecContext) -> dict[str, Any] | None:
        exec_outputs = [n for n, (t, _) in self.definition.outputs.items() if t.base == "execution"]
        if self.exec_input_state(ctx.frame) == ExecutionState.DISABLED:
            return {n: ExecutionState.DISABLED for n in exec_outputs}
        db = Database(self, ctx)
        ok = self.implementation.compute(db)
        out = dict(db.written)
        for n in exec_outputs:
            state = out.get(n, ExecutionState.ENABLED if ok else ExecutionState.DISABLED)
            out[n] = ExecutionState(int(state))
        return out


def node_class(definition: Definition, implementation: type) -> type[OgnNode]:
    """A registered graphsdg node type for ``definition`` computed by ``implementation.compute(db)``."""
    if not callable(getattr(implementation, "compute", None)):
        raise TypeError(f"{definition.type_name}: {implementation!r} has no compute(db)")
    ports_in = {n: Port(t.base, default=d) for n, (t, d) in definition.inputs.items()}
    ports_out = {n: Port(t.base) for n, (t, _) in definition.outputs.items()}
    cls = type(implementation.__name__, (OgnNode,), {
        "type_name": definition.type_name, "omnigraph_type": definition.type_name, "inputs": ports_in,
        "outputs": ports_out, "definition": definition, "implementation": implementation,
        "__doc__": definition.description or f"OmniGraph Python node {definition.type_name}.",
        "__module__": __name__})
    return NodeRegistry.register(cls)


def _import_implementation(py_path: Path, extension: str) -> Any:
    name = f"graphsdg_ogn.{extension}.{py_path.stem}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, py_path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load the node implementation {py_path}")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def load_file(ogn_path: Path, extension: str) -> list[type[OgnNode]]:
    """Register the node types of ``ogn_path``, computed by the class named after the file in the ``.py`` beside it."""
    ogn_path = Path(ogn_path)
    py_path = ogn_path.with_suffix(".py")
    if not py_path.is_file():
        raise FileNotFoundError(f"{ogn_path}: no Python implementation {py_path.name} beside it (graphsdg runs "
                                f"Python OmniGraph nodes only)")
    module = _import_implementation(py_path, extension)
    implementation = getattr(module, ogn_path.stem, None)
    if implementation is None:
        raise ImportError(f"{py_path} defines no class {ogn_path.stem!r} (the node's compute(db))")
    return [node_class(d, implementation) for d in parse_definition(ogn_path, extension)]


def load_folder(folder: Path, extension: str) -> list[type[OgnNode]]:
    """Register every node type of the ``.ogn`` files in ``folder`` (and its subfolders), in name order."""
    out: list[type[OgnNode]] = []
    for ogn_path in sorted(Path(folder).rglob("*.ogn")):
        out += load_file(ogn_path, extension)
    return out


def definition_types(ogn_path: Path, extension: str) -> list[str]:
    """The type names ``.ogn`` file ``ogn_path`` defines (without loading its implementation)."""
    return [d.type_name for d in parse_definition(ogn_path, extension)]


__all__ = ["ExecutionState", "AttributeType", "Definition", "Database", "OgnNode", "node_class", "load_file",
           "load_folder", "parse_definition", "definition_from_spec", "definition_types"]
