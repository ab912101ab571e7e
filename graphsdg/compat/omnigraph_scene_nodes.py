"""Isaac compat area: the scene-reading nodes of ``omni.graph.nodes`` that robot action graphs use.

* ``GetPrimLocalToWorldTransform``: the world transform of a prim (``inputs:prim``
  target, or ``inputs:primPath`` when ``inputs:usePath``, the default) as a 4 x 4
  matrix in USD's row-vector convention (translation in the last row);
* ``GetMatrix4Quaternion`` / ``GetMatrix4Translation``: the rotation (quaternion
  ``(x, y, z, w)``, scale and shear removed) and the translation of such a matrix
  or of an array of them;
* ``ReadPrimAttribute``: the value of attribute ``inputs:name`` of a prim
  (``inputs:prim`` target, or ``inputs:primPath`` when ``inputs:usePath``) at
  ``inputs:usdTimecode`` (NaN: the default time), as
  :func:`graphsdg.compat.omnigraph_usd.usd_value` reads USD values.

The stage is the current one; a missing prim or attribute fails the compute,
naming it (the action graph logs it and goes on, as Kit does).

Example:
    >>> import numpy as np
    >>> from pxr import Gf
    >>> m = Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(0, 0, 1), 90)).SetTranslateOnly(Gf.Vec3d(1, 2, 3))
    >>> np.round(matrix_quaternion(np.array(m)), 4).tolist(), matrix_translation(np.array(m)).tolist()
    ([0.0, 0.0, 0.7071, 0.7071], [1.0, 2.0, 3.0])
"""
from __future__ import annotations

import math
import types
from typing import Any

import numpy as np
from pxr import Gf, Usd, UsdGeom

from graphsdg.compat.modules import CompatModule
from graphsdg.compat.omnigraph_action import register_node_types
from graphsdg.compat.omnigraph_usd import usd_value
from graphsdg.graph import ogn
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import resolve_prim

EXTENSIONS = {"omni.graph.nodes": ("omni.graph.nodes",)}
_MATRICES = ["matrixd[4]", "matrixd[4][]"]


def _prim(db: ogn.Database) -> Usd.Prim:
    """The prim a node reads: ``inputs:primPath`` when ``inputs:usePath``, else the ``inputs:prim`` target."""
    if db.inputs.usePath:
        return resolve_prim(str(db.inputs.primPath), get_stage())
    targets = db.inputs.prim
    if not targets:
        raise ValueError(f"{db.node.get_prim_path()}: inputs:prim names no prim (and inputs:usePath is off)")
    return resolve_prim(targets[0], get_stage())


def matrix_quaternion(matrix: np.ndarray) -> np.ndarray:
    """The rotation of a 4 x 4 row-vector transform as a quaternion ``(x, y, z, w)`` (``(N, 4)`` for N of them)."""
    m = np.asarray(matrix, dtype=np.float64)
    if m.ndim == 3:
        return np.array([matrix_quaternion(one) for one in m])
    q = Gf.Matrix4d(m.reshape(4, 4).tolist()).RemoveScaleShear().ExtractRotationQuat()
    return np.array([*q.GetImaginary(), q.GetReal()], dtype=np.float64)


def matrix_translation(matrix: np.ndarray) -> np.ndarray:
    """The translation of a 4 x 4 row-vector transform (``(N, 3)`` for N of them)."""
    m = np.asarray(matrix, dtype=np.float64)
    return m[..., 3, :3].copy() if m.ndim == 3 else m.reshape(4, 4)[3, :3].copy()


class GetPrimLocalToWorldTransform:
    """``omni.graph.nodes.GetPrimLocalToWorldTransform``: a prim's local-to-world matrix."""

    spec = {"description": "The matrix that takes a prim's local frame to the world frame.",
            "inputs": {"prim": {"type": "target"}, "primPath": {"type": "token"},
                       "usePath": {"type": "bool", "default": True}},
            "outputs": {"localToWorldTransform": {"type": "matrixd[4]"}}}

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        matrix = UsdGeom.Xformable(_prim(db)).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
        db.outputs.localToWorldTransform = np.array(matrix, dtype=np.float64)
        return True


class GetMatrix4Quaternion:
    """``omni.graph.nodes.GetMatrix4Quaternion``: the rotation of a transform matrix as a quaternion."""

    spec = {"description": "The rotation of a transform matrix as a quaternion (x, y, z, w).",
            "inputs": {"matrix": {"type": _MATRICES}},
            "outputs": {"quaternion": {"type": ["quatd[4]", "quatd[4][]"]}}}

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        db.outputs.quaternion = matrix_quaternion(db.inputs.matrix)
        return True


class GetMatrix4Translation:
    """``omni.graph.nodes.GetMatrix4Translation``: the translation of a transform matrix."""

    spec = {"description": "The translation of a transform matrix.",
            "inputs": {"matrix": {"type": _MATRICES}},
            "outputs": {"translation": {"type": ["vectord[3]", "vectord[3][]"]}}}

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        db.outputs.translation = matrix_translation(db.inputs.matrix)
        return True


class ReadPrimAttribute:
    """``omni.graph.nodes.ReadPrimAttribute``: the value of one attribute of a prim."""

    spec = {"description": "The value of a prim's attribute at a time (NaN: the default time).",
            "inputs": {"name": {"type": "token"}, "prim": {"type": "target"}, "primPath": {"type": "token"},
                       "usePath": {"type": "bool", "default": False},
                       "usdTimecode": {"type": "timecode", "default": math.nan}},
            "outputs": {"value": {"type": "any"}}}

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        prim = _prim(db)
        attr = prim.GetAttribute(str(db.inputs.name))
        if not attr:
            raise ValueError(f"prim {prim.GetPath()} has no attribute {str(db.inputs.name)!r}")
        time = float(db.inputs.usdTimecode)
        db.outputs.value = usd_value(attr.Get(Usd.TimeCode.Default() if math.isnan(time) else Usd.TimeCode(time)))
        return True


NODE_TYPES: dict[str, Any] = {f"omni.graph.nodes.{cls.__name__}": cls for cls in
                              (GetPrimLocalToWorldTransform, GetMatrix4Quaternion, GetMatrix4Translation,
                               ReadPrimAttribute)}


def modules() -> list[types.ModuleType]:
    """The node types (registered) and the ``omni.graph.nodes`` module name."""
    register_node_types(NODE_TYPES)
    return [CompatModule("omni.graph.nodes", hint="graphsdg runs the node types " + ", ".join(sorted(NODE_TYPES)))]
