"""What an edit of a prim's properties means for its compiled geoms. The aspects to sync live.

A changed property maps to one aspect (``pose``, ``shape``, ``visibility``,
``material``, ``color``); semantic labels and rigid-body velocities need no geom
sync; anything else is treated as touching every aspect. Edits of an ancestor
pass ``pose``, ``visibility`` and ``material`` down to the gprims below it.
"""
from __future__ import annotations

from graphsdg.sim.rigid_bodies import VELOCITY_ATTRIBUTES

ALL_ASPECTS = frozenset({"pose", "shape", "visibility", "material", "color"})
# Aspects an ancestor's edit passes down to the gprims below it.
INHERITED_ASPECTS = frozenset({"pose", "visibility", "material"})
_SHAPE_ATTRS = {"size", "radius", "height", "width", "length", "axis", "points", "faceVertexCounts",
                "faceVertexIndices", "extent", "orientation", "primvars:st"}


def edit_aspects(names: set[str]) -> set[str]:
    """What a set of changed property names means for compiled geoms."""
    aspects: set[str] = set()
    for name in names:
        if name.startswith("xformOp") or name == "xformOpOrder":
            aspects.add("pose")
        elif name == "visibility" or name == "purpose":
            aspects.add("visibility")
        elif name.startswith("material:binding"):
            aspects.add("material")
        elif name in ("primvars:displayColor", "primvars:displayOpacity"):
            aspects.add("color")
        elif name in _SHAPE_ATTRS:
            aspects.add("shape")
        elif name.startswith("semantic"):
            continue   # labels are read by annotators, not compiled
        elif name in VELOCITY_ATTRIBUTES:
            continue   # simulation state, set on the body (SimScene._refresh_body_velocity)
        else:
            return set(ALL_ASPECTS)
    return aspects
