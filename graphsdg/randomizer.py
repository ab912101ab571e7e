"""``rep.randomizer``: graph-API randomizers and user-registered randomizer functions.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cubes = rep.create.cube(count=3)
    >>> with rep.trigger.on_frame():
    ...     with cubes:
    ...         _ = rep.randomizer.rotation()
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.builder import add_node, targets_value
from graphsdg.graph.node import ReplicatorItem
from graphsdg.graph.registration import register_function
from graphsdg.graph.registry import NodeRegistry


def color(colors: Any, per_sub_mesh: bool = False, seed: int | None = None, input_prims: Any = None
          ) -> ReplicatorItem:
    """Give each prim its own material with a diffuse colour from ``colors`` (usually a distribution)."""
    return add_node(NodeRegistry.create("randomizer.color", input_prims=targets_value(input_prims,
                                                                                      "rep.randomizer.color"),
                                        colors=colors, per_sub_mesh=per_sub_mesh, seed=seed))


def materials(materials: Any, seed: int | None = None, max_cached_materials: int = 0, input_prims: Any = None,
              name: str | None = None) -> ReplicatorItem:
    """Bind each prim a material drawn from ``materials`` (a material_omnipbr item, prims or paths)."""
    return add_node(NodeRegistry.create(
        "randomizer.materials", name=name, input_prims=targets_value(input_prims, "rep.randomizer.materials"),
        materials=materials, seed=seed, max_cached_materials=max_cached_materials))


def texture(textures: Any, texture_scale: Any = None, texture_rotate: Any = None, per_sub_mesh: bool = False,
            project_uvw: bool = False, seed: int | None = None, input_prims: Any = None) -> ReplicatorItem:
    """Give each prim a material textured with a file drawn from ``textures``; UV scale and rotation (degrees)."""
    return add_node(NodeRegistry.create(
        "randomizer.texture", input_prims=targets_value(input_prims, "rep.randomizer.texture"), textures=textures,
        texture_scale=texture_scale, texture_rotate=texture_rotate, per_sub_mesh=per_sub_mesh,
        project_uvw=project_uvw, seed=seed))


def rotation(min_angle: Any = (-180.0, -180.0, -180.0), max_angle: Any = (180.0, 180.0, 180.0),
             seed: int | None = None, input_prims: Any = None) -> ReplicatorItem:
    """Rotate each prim uniformly on SO(3) (within XYZ Euler limits in degrees)."""
    return add_node(NodeRegistry.create(
        "randomizer.rotation", input_prims=targets_value(input_prims, "rep.randomizer.rotation"),
        min_angle=min_angle, max_angle=max_angle, seed=seed))


def scatter_2d(surface_prims: Any, no_coll_prims: Any = None, min_samp: Any = (None, None, None),
               max_samp: Any = (None, None, None), seed: int | None = None, offset: float = 0,
               check_for_collisions: bool = False, input_prims: Any = None, name: str | None = None
               ) -> ReplicatorItem:
    """Place the prims on ``surface_prims`` (``graphsdg.functional.randomizer.scatter_2d``)."""
    return add_node(NodeRegistry.create(
        "randomizer.scatter_2d", name=name, input_prims=targets_value(input_prims, "rep.randomizer.scatter_2d"),
        surface_prims=surface_prims, no_coll_prims=no_coll_prims, min_samp=min_samp, max_samp=max_samp,
        seed=seed, offset=offset, check_for_collisions=check_for_collisions))


def scatter_3d(volume_prims: Any = None, no_coll_prims: Any = None, volume_excl_prims: Any = None,
               min_samp: Any = (None, None, None), max_samp: Any = (None, None, None), resolution_scaling: float = 1.0,
               voxel_size: float = 0.0, check_for_collisions: bool = False, prevent_vol_overlap: bool = True,
               viz_sampled_voxels: bool = False, seed: int | None = None, input_prims: Any = None,
               name: str | None = None) -> ReplicatorItem:
    """Place the prims inside ``volume_prims`` (``graphsdg.functional.randomizer.scatter_3d``)."""
    return add_node(NodeRegistry.create(
        "randomizer.scatter_3d", name=name, input_prims=targets_value(input_prims, "rep.randomizer.scatter_3d"),
        volume_prims=volume_prims, no_coll_prims=no_coll_prims, volume_excl_prims=volume_excl_prims,
        min_samp=min_samp, max_samp=max_samp, resolution_scaling=resolution_scaling, voxel_size=voxel_size,
        check_for_collisions=check_for_collisions, prevent_vol_overlap=prevent_vol_overlap,
        viz_sampled_voxels=viz_sampled_voxels, seed=seed))


def instantiate(paths: Any, size: int, weights: Any = None, mode: str = "scene_instance",
                with_replacements: bool = True, seed: int | None = None, name: str | None = None,
                use_cache: bool = True, semantics: Any = None) -> ReplicatorItem:
    """``size`` instances under ``/Replicator``, each referencing a USD file drawn from ``paths``."""
    return add_node(NodeRegistry.create(
        "randomizer.instantiate", name=name, paths=list(paths) if not isinstance(paths, str) else paths,
        size=size, weights=weights, mode=mode, with_replacements=with_replacements, seed=seed,
        use_cache=use_cache, semantics=semantics))


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.randomizer.<fn_name>``; calling it builds the nodes ``fn`` builds.

    ``fn`` must return what it built (an item or ``item.node``).
    """
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = ["color", "materials", "texture", "rotation", "scatter_2d", "scatter_3d", "instantiate", "register"]
