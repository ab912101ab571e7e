"""isaacsim.core / omni.physx helpers mapped onto graphsdg: bounds, rigid-body views, scene queries.

Isaac's experimental prim wrappers return warp arrays; graphsdg returns numpy
arrays that also answer ``.numpy()``, so ``poses[0].numpy()`` works unchanged.
"""
from __future__ import annotations

from typing import Any, Callable, Iterable, Sequence

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.compat.experimental_prims import RigidPrim, XformPrim  # noqa: F401 - re-exported
from graphsdg.compat.modules import CompatObject
from graphsdg.compat.warp_arrays import WarpLikeArray  # noqa: F401 - re-exported
from graphsdg.compat.warp_arrays import as_warp_like as _warp  # noqa: F401 - re-exported
from graphsdg.physics import queries
from graphsdg.sim import bounds
from graphsdg.stage import semantics as semlib
from graphsdg.stage.context import get_stage


# ---- bounds -----------------------------------------------------------------------
def create_bbox_cache(time: Usd.TimeCode = Usd.TimeCode.Default(), use_extents_hint: bool = True
                      ) -> UsdGeom.BBoxCache:
    return bounds.create_bbox_cache(time, use_extents_hint)


def compute_aabb(*args: Any, bbox_cache: UsdGeom.BBoxCache | None = None, prim: Any = None,
                 include_children: bool = False) -> np.ndarray:
    """``compute_aabb(bbox_cache, prim, ...)`` (isaacsim.core.utils.bounds) or
    ``compute_aabb(prim, bbox_cache=..., include_children=...)`` (the experimental utils)."""
    positional = list(args)
    if positional and isinstance(positional[0], UsdGeom.BBoxCache):
        bbox_cache = positional.pop(0)
    if positional:
        prim = positional.pop(0)
    if positional:
        bbox_cache = positional.pop(0)
    if prim is None:
        raise TypeError("compute_aabb needs a prim")
    return bounds.compute_aabb(prim, bbox_cache, include_children=include_children)


def compute_combined_aabb(bbox_cache: UsdGeom.BBoxCache, prim_paths: Iterable[str]) -> np.ndarray:
    return bounds.compute_combined_aabb(list(prim_paths), bbox_cache)


def compute_obb(bbox_cache: UsdGeom.BBoxCache, prim_path: str):
    return bounds.compute_obb(prim_path, bbox_cache)


# ---- stage and semantics utils ---------------------------------------------------------
def get_current_stage() -> Usd.Stage:
    return get_stage()


def add_labels(prim: Usd.Prim, labels: Sequence[str], instance_name: str = "class", overwrite: bool = True) -> None:
    """isaacsim.core.experimental.utils.semantics.add_labels."""
    semlib.apply(prim, {instance_name: list(labels)}, mode="replace" if overwrite else "add")


def get_labels(prim: Usd.Prim) -> dict[str, list[str]]:
    return semlib.direct_labels(prim)


def remove_labels(prim: Usd.Prim, instance_name: str | None = None) -> None:
    if instance_name is None:
        semlib.apply(prim, None, mode="clear")
    else:
        labels = {k: v for k, v in semlib.direct_labels(prim).items() if k != instance_name}
        semlib.apply(prim, labels, mode="clear")


# ---- omni.physx scene queries ------------------------------------------------------------
class SceneQueryInterface(CompatObject):
    """omni.physx's scene query interface; hits carry ``rigid_body`` / ``collision`` prim paths."""

    _compat_name = "omni.physx.IPhysxSceneQuery"

    def overlap_box(self, half_extent: Any, position: Any, rotation: Any,
                    report_fn: Callable[[Any], bool] | None = None, any_hit: bool = False) -> int:
        return queries.overlap_box(tuple(half_extent), tuple(position), tuple(rotation), report_fn, any_hit)

    def overlap_sphere(self, radius: float, position: Any, report_fn: Callable[[Any], bool] | None = None,
                       any_hit: bool = False) -> int:
        return queries.overlap_sphere(radius, tuple(position), report_fn, any_hit)

    def raycast_closest(self, origin: Any, direction: Any, distance: float) -> dict:
        return queries.raycast_closest(tuple(origin), tuple(direction), distance)

    def raycast_all(self, origin: Any, direction: Any, distance: float, report_fn: Callable | None = None):
        return queries.raycast_all(tuple(origin), tuple(direction), distance, report_fn)


_scene_query = SceneQueryInterface()


def get_physx_scene_query_interface() -> SceneQueryInterface:
    return _scene_query
