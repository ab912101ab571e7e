"""Stage-wide metadata that changes how the scene is read: the up axis and unit.

Both are authored on the root layer (as Replicator does, so they survive a save)
and make the next simulation update recompile the MuJoCo model, whose gravity,
default look-at up vector and shape axes follow them.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.stage import metadata
    >>> _ = rep.stage.new_stage()
    >>> metadata.set_up_axis("y")
    >>> metadata.up_axis()
    'Y'
    >>> metadata.set_meters_per_unit(0.01)
    >>> metadata.meters_per_unit()
    0.01
"""
from __future__ import annotations

import math
import numbers

from pxr import Usd, UsdGeom

from graphsdg.stage import context

UP_AXES = ("Y", "Z")


def up_axis() -> str:
    """The current stage's up axis, ``"Y"`` or ``"Z"``."""
    return str(UsdGeom.GetStageUpAxis(context.get_stage()))


def set_up_axis(axis: str) -> None:
    """Author ``upAxis`` (``"Y"`` or ``"Z"``, any case) on the current stage's root layer.

    Raises ``ValueError`` naming the value for anything else.
    """
    if not isinstance(axis, str) or axis.upper() not in UP_AXES:
        raise ValueError(f"stage up axis must be one of {list(UP_AXES)}, got {axis!r}")
    stage = context.get_stage()
    with Usd.EditContext(stage, stage.GetRootLayer()):
        UsdGeom.SetStageUpAxis(stage, axis.upper())
    # Layer metadata is not a prim edit, so no change notice reaches the tracker: say it here.
    context.tracker().mark_structural()


def meters_per_unit() -> float:
    """Metres per stage unit of the current stage."""
    return float(UsdGeom.GetStageMetersPerUnit(context.get_stage()))


def set_meters_per_unit(value: float) -> None:
    """Author ``metersPerUnit`` (a finite number > 0) on the current stage's root layer."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"stage meters per unit must be a finite number > 0, got {value!r}")
    stage = context.get_stage()
    with Usd.EditContext(stage, stage.GetRootLayer()):
        UsdGeom.SetStageMetersPerUnit(stage, float(value))
    context.tracker().mark_structural()
