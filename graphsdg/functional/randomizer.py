"""``rep.functional.randomizer``: randomize prims now, from an explicit ``rng``.

``display_color`` recolours; ``scatter_2d`` and ``scatter_3d`` place prims on
surfaces or in volumes, optionally without overlaps (the graph API's
``rep.randomizer.scatter_2d/3d`` nodes call these).

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cubes = rep.functional.create_batch.cube(count=2)
    >>> rep.functional.randomizer.display_color(cubes, rng=rep.rng.ReplicatorRNG(seed=1))
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from pxr import UsdGeom

from graphsdg.functional import modify
from graphsdg.rng import ReplicatorRNG, as_generator
from graphsdg.sim import bounds, placement, transforms
from graphsdg.stage.prims import resolve_prims
from graphsdg.stage.xform import set_local_pose, world_matrix


def display_color(prims: Any, rng: ReplicatorRNG | np.random.Generator | None = None,
                  min_value: Sequence[float] = (0.0, 0.0, 0.0), max_value: Sequence[float] = (1.0, 1.0, 1.0)
                  ) -> None:
    """Give each prim a uniform random ``primvars:displayColor`` in [min_value, max_value)."""
    targets = resolve_prims(prims)
    lo, hi = np.asarray(min_value, dtype=np.float64), np.asarray(max_value, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or np.any(lo > hi):
        raise ValueError(f"display_color range must be two RGB triples with min <= max, got {min_value}, {max_value}")
    gen = as_generator(rng, "display_color")
    modify.display_color(targets, gen.uniform(lo, hi, size=(len(targets), 3)))


def _bounds_offsets(targets: list, extents: Any) -> np.ndarray:
    """Each prim's box relative to its world origin, (N, 6): from ``extents`` or the prims' real bounds."""
    n = len(targets)
    if extents is not None:
        arr = np.asarray(extents, dtype=np.float64)
        if arr.ndim == 1:
            arr = np.tile(arr, (n, 1))
        if arr.ndim != 2 or arr.shape[0] != n or arr.shape[1] not in (3, 6) or not np.all(np.isfinite(arr)):
            raise ValueError(f"extents must be sizes (3,) / (N, 3) or bounds (xmin, ymin, zmin, xmax, ymax, zmax) "
                             f"(6,) / (N, 6) relative to each prim's origin, for N={n} prims; got shape "
                             f"{np.shape(extents)}")
        if arr.shape[1] == 3:
            if np.any(arr < 0):
                raise ValueError(f"extents sizes must be >= 0, got {arr.tolist()}")
            return np.c_[-arr / 2, arr / 2]
        if np.any(arr[:, 3:] < arr[:, :3]):
            raise ValueError(f"extents bounds need min <= max on every axis, got {arr.tolist()}")
        return arr
    cache = bounds.create_bbox_cache()
    out = np.zeros((n, 6))
    for i, prim in enumerate(targets):
        origin = transforms.get_world_position(prim)
        try:
            box = bounds.compute_aabb(prim, cache)
        except ValueError:
            continue                       # no geometry: a point at its origin
        out[i] = np.r_[box[:3] - origin, box[3:] - origin]
    return out


def _obstacles(no_collision_prims: Any) -> np.ndarray:
    if no_collision_prims is None:
        return np.zeros((0, 6))
    cache = bounds.create_bbox_cache()
    boxes = []
    for prim in resolve_prims(no_collision_prims):
        try:
            boxes.append(bounds.compute_aabb(prim, cache))
        except ValueError:
            continue
    return np.array(boxes).reshape(-1, 6)


def _move_to(targets: list, world_positions: np.ndarray) -> None:
    """Give each prim a local translation putting its origin at the world position (rotation kept)."""
    for prim, p in zip(targets, world_positions):
        parent = prim.GetParent()
        parent_m = world_matrix(parent) if parent and parent.IsA(UsdGeom.Xformable) else np.eye(4)
        local = np.append(p, 1.0) @ np.linalg.inv(parent_m)
        set_local_pose(prim, position=local[:3])


def _fail(kind: str, placed: int, targets: list, where: list, attempts: int, noun: str) -> ValueError:
    paths = ", ".join(str(p.GetPath()) for p in where)
    return ValueError(f"{kind} could fit only {placed} of {len(targets)} prims in {paths} without collisions: "
                      f"{targets[placed].GetPath()} found no free spot in {attempts} attempts; the stage was left "
                      f"unchanged (scatter fewer or smaller prims, or use a larger {noun})")


def scatter_2d(prims: Any, surface_prims: Any, no_collision_prims: Any = None, extents: Any = None,
               offset: float = 0.0, check_for_collisions: bool = False,
               rng: ReplicatorRNG | np.random.Generator | None = None) -> None:
    """Place each prim's origin at a point drawn uniformly by area on the surface prims.

    Surfaces are every Plane, Mesh or other shape at or below ``surface_prims``,
    hidden ones included; the origin goes ``offset`` along the surface normal
    there; rotations are kept. With ``check_for_collisions`` each prim's real
    world bounds (or ``extents``: sizes (N, 3) or bounds (N, 6) relative to the
    origin) may not overlap those already placed nor ``no_collision_prims``. A
    prim that finds no spot in 10 000 attempts raises ``ValueError`` saying how
    many fit; the stage is then left unchanged.

    Example:
        >>> import graphsdg as rep
        >>> _ = rep.stage.new_stage()
        >>> floor = rep.functional.create.plane(scale=(4, 4, 1), visible=False)
        >>> cubes = rep.functional.create_batch.cube(count=5, scale=0.3)
        >>> rep.functional.randomizer.scatter_2d(cubes, floor, offset=0.15, check_for_collisions=True,
        ...                                      rng=rep.rng.ReplicatorRNG(seed=3))
        >>> sorted({round(float(c.GetAttribute("xformOp:translate").Get()[2]), 2) for c in cubes})
        [0.15]
    """
    targets = resolve_prims(prims)
    surfaces = resolve_prims(surface_prims)
    if isinstance(offset, bool) or not isinstance(offset, (int, float, np.floating)) or not np.isfinite(offset):
        raise ValueError(f"offset must be a finite number, got {offset!r}")
    surface = placement.surface_of(surfaces)
    gen = as_generator(rng, "scatter_2d")
    offsets = _bounds_offsets(targets, extents)

    def propose(k: int) -> np.ndarray:
        points, normals = placement.sample_surface(surface, k, gen)
        return points + float(offset) * normals

    positions, placed, attempts = placement.place(len(targets), propose, offsets, _obstacles(no_collision_prims),
                                                  bool(check_for_collisions))
    if placed < len(targets):
        raise _fail("scatter_2d", placed, targets, surfaces, attempts, "surface")
    _move_to(targets, positions)


def scatter_3d(prims: Any, volume_prims: Any, no_collision_prims: Any = None, volume_excl_prims: Any = None,
               extents: Any = None, check_for_collisions: bool = False, prevent_vol_overlap: bool = True,
               viz_sampled_voxels: bool = False, resolution_scaling: float = 1.0, input_voxel_size: float = 0.0,
               rng: ReplicatorRNG | np.random.Generator | None = None) -> None:
    """Place each prim's origin at a point drawn uniformly by volume inside the volume prims.

    Volumes are the closed shapes at or below ``volume_prims`` (cubes, spheres,
    cylinders, cones, capsules exactly; meshes by winding number), minus those
    under ``volume_excl_prims``. With ``prevent_vol_overlap`` the prim's bounds
    must lie inside the volume and outside the excluded ones; collisions work as
    in :func:`scatter_2d`. Sampling is continuous, so Replicator's voxel settings
    (``resolution_scaling``, ``input_voxel_size``, ``viz_sampled_voxels``) are
    validated but change nothing.

    Example:
        >>> import graphsdg as rep
        >>> _ = rep.stage.new_stage()
        >>> box = rep.functional.create.cube(scale=2, visible=False)
        >>> balls = rep.functional.create_batch.sphere(count=4, scale=0.2)
        >>> rep.functional.randomizer.scatter_3d(balls, box, check_for_collisions=True,
        ...                                      rng=rep.rng.ReplicatorRNG(seed=1))
        >>> all(abs(v) <= 0.9 for b in balls for v in b.GetAttribute("xformOp:translate").Get())
        True
    """
    targets = resolve_prims(prims)
    volumes = [placement.Volume(p) for p in resolve_prims(volume_prims)]
    excluded = [placement.Volume(p) for p in resolve_prims(volume_excl_prims)] if volume_excl_prims is not None \
        else []
    for name, value in (("resolution_scaling", resolution_scaling), ("input_voxel_size", input_voxel_size)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value < 0 or \
                (name == "resolution_scaling" and value == 0):
            raise ValueError(f"{name} must be a {'positive' if name == 'resolution_scaling' else 'non-negative'} "
                             f"number, got {value!r}")
    gen = as_generator(rng, "scatter_3d")
    offsets = _bounds_offsets(targets, extents)
    signs = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=bool)

    def propose(k: int) -> np.ndarray:
        return placement.sample_volumes(volumes, k, gen, excluded)

    def accept(i: int, cand: np.ndarray) -> np.ndarray:
        if not prevent_vol_overlap or not np.any(offsets[i]):
            return np.ones(len(cand), dtype=bool)
        corner_offsets = np.where(signs, offsets[i, 3:], offsets[i, :3])          # (8, 3)
        corners = (cand[:, None, :] + corner_offsets[None]).reshape(-1, 3)
        inside = np.zeros(len(corners), dtype=bool)
        for vol in volumes:
            inside |= vol.contains(corners)
        for vol in excluded:
            inside &= ~vol.contains(corners)
        return inside.reshape(len(cand), 8).all(1)

    positions, placed, attempts = placement.place(len(targets), propose, offsets, _obstacles(no_collision_prims),
                                                  bool(check_for_collisions), accept)
    if placed < len(targets):
        raise _fail("scatter_3d", placed, targets, [v.prim for v in volumes], attempts, "volume")
    _move_to(targets, positions)
