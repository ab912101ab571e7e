"""``rep.functional.randomizer``: randomize prims now, from an explicit ``rng``.

``scatter_2d`` and ``scatter_3d`` place prims on surfaces or in volumes,
optionally without overlaps.

These are also what the graph's randomizer nodes call (one implementation per
operation): a node passes its per-execution stream as ``rng``.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cubes = rep.functional.create_batch.cube(count=2)
    >>> rep.functional.randomizer.display_color(cubes, rng=rep.rng.ReplicatorRNG(seed=1))
"""
from __future__ import annotations

import math
import os
from typing import Any, Sequence

import numpy as np
from pxr import Sdf, Usd, UsdGeom, UsdShade

from graphsdg.assets.nucleus import is_nucleus_url, local_path
from graphsdg.functional import modify
from graphsdg.functional.per_prim import per_prim
from graphsdg.rng import ReplicatorRNG, as_generator
from graphsdg.sim import bounds, placement
from graphsdg.stage import materials as matlib
from graphsdg.stage import mdl_modules
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import resolve_prims, sanitize_name
from graphsdg.maths.rotations import matrix_to_euler_xyz, quat_wxyz_to_matrix
from graphsdg.stage.xform import parent_world_matrix, set_local_pose, world_matrix

LOOKS = "/Replicator/Looks"


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


def _own_material(prim: Usd.Prim, kind: str, looks: str) -> UsdShade.Material:
    """The material graphsdg made for ``prim`` (one per prim and kind), made and bound on first use."""
    stage = prim.GetStage()
    name = sanitize_name(f"{kind}_{str(prim.GetPath()).strip('/').replace('/', '_')}")
    path = Sdf.Path(looks).AppendChild(name)
    mat = UsdShade.Material(stage.GetPrimAtPath(path))
    if not mat:
        _ensure_scope(stage, Sdf.Path(looks))
        mat = matlib.define_preview_material(stage, path)
        mat.GetPrim().CreateAttribute("info:mdl:sourceAsset", Sdf.ValueTypeNames.Asset).Set(
            Sdf.AssetPath("OmniPBR.mdl"))
    bound = matlib.bound_material(prim)
    if bound is None or bound.GetPath() != path:
        matlib.bind(prim, mat)
    return mat


def _ensure_scope(stage: Usd.Stage, path: Sdf.Path) -> None:
    for prefix in path.GetPrefixes():
        if not stage.GetPrimAtPath(prefix).IsValid():
            UsdGeom.Scope.Define(stage, prefix) if prefix == path else UsdGeom.Xform.Define(stage, prefix)


def color(prims: Any, colors: Any = None, rng: ReplicatorRNG | np.random.Generator | None = None,
          looks: str = LOOKS) -> np.ndarray:
    """Bind each prim its own OmniPBR-style material and set its diffuse colour.

    ``colors``: one RGB for all, an ``(N, 3)`` array (one per prim), or None for a
    uniform random colour per prim from ``rng``. Returns the colours applied.
    The material is made once per prim; later calls only edit its colour.
    """
    targets = resolve_prims(prims)
    if colors is None:
        values = as_generator(rng, "color").uniform(0.0, 1.0, size=(len(targets), 3))
    else:
        arr = np.asarray(colors, dtype=np.float64)
        if arr.ndim == 1:
            arr = np.broadcast_to(arr, (len(targets), arr.shape[0]))
        if arr.ndim != 2 or arr.shape[0] != len(targets) or arr.shape[1] not in (3, 4):
            raise ValueError(f"colors must be one (r, g, b) or {len(targets)} rows of them, got shape "
                             f"{np.shape(colors)}")
        values = arr[:, :3]
    for prim, c in zip(targets, values):
        matlib.set_inputs(_own_material(prim, "Color", looks), diffuse=c)
    return np.asarray(values)


def is_mdl_url(value: Any) -> bool:
    """Whether ``value`` names an ``.mdl`` file (rather than a material prim)."""
    return isinstance(value, (str, os.PathLike)) and os.fspath(value).lower().endswith(".mdl")


def mdl_material(url: str, looks: str = LOOKS) -> Usd.Prim:
    """The material running the ``.mdl`` file ``url``, made once under ``looks`` (as Replicator does for MDL
    paths given to its material randomizer) and reused while that prim stands."""
    path = os.fspath(url)
    if is_nucleus_url(path):
        path = local_path(path)         # its local copy, or an error naming the URL and how to provide one
    if not os.path.isfile(path):
        raise FileNotFoundError(f"MDL material {path!r} does not exist")
    stage = get_stage()
    looks_prim = stage.GetPrimAtPath(looks)
    for child in looks_prim.GetChildren() if looks_prim else []:
        shader = UsdShade.Shader(child.GetChild("Shader"))
        asset = shader.GetSourceAsset("mdl") if shader else None
        if asset is not None and asset.path == path:
            return child
    name = mdl_modules.material_name(path)
    _ensure_scope(stage, Sdf.Path(looks))
    target = Sdf.Path(looks).AppendChild(sanitize_name(name))
    k = 1
    while stage.GetPrimAtPath(target):
        target = Sdf.Path(looks).AppendChild(sanitize_name(f"{name}_{k:02d}"))
        k += 1
    return matlib.define_mdl_material(stage, target, path, name).GetPrim()


def with_mdl_materials(value: Any, looks: str = LOOKS) -> Any:
    """``value`` (a material, path or list of them) with every ``.mdl`` file in it replaced by its material."""
    if is_mdl_url(value):
        return mdl_material(value, looks)
    if isinstance(value, (list, tuple)):
        return [with_mdl_materials(v, looks) for v in value]
    return value


def materials(prims: Any, materials: Any, rng: ReplicatorRNG | np.random.Generator | None = None) -> list[str]:
    """Bind each prim a material drawn uniformly from ``materials`` (prims, paths or ``.mdl`` files, whose
    materials are made once under ``/Replicator/Looks``); returns the paths bound."""
    mats = resolve_prims(with_mdl_materials(materials))
    if not mats:
        raise ValueError("materials() needs at least one material to choose from, got none")
    for m in mats:
        if not m.IsA(UsdShade.Material):
            raise TypeError(f"materials(): {m.GetPath()} is a {m.GetTypeName()!r} prim, not a Material")
    targets = resolve_prims(prims)
    picks = as_generator(rng, "materials").integers(0, len(mats), size=len(targets))
    chosen = []
    for prim, k in zip(targets, picks):
        matlib.bind(prim, UsdShade.Material(mats[int(k)]))
        chosen.append(str(mats[int(k)].GetPath()))
    return chosen


def texture(prims: Any, textures: Sequence[str], texture_scale: Any = None, texture_rotate: Any = None,
            rng: ReplicatorRNG | np.random.Generator | None = None, looks: str = LOOKS) -> list[str]:
    """Give each prim a material textured with a file drawn uniformly from ``textures``.

    ``texture_scale`` ((su, sv), or one row per prim) and ``texture_rotate``
    (degrees, or one per prim) set the UV transform. Returns the files applied.
    """
    files = [os.fspath(t) for t in ([textures] if isinstance(textures, (str, os.PathLike)) else textures)]
    if not files:
        raise ValueError("texture() needs at least one texture file, got none")
    missing = [f for f in files if not os.path.isfile(f)]
    if missing:
        raise FileNotFoundError(f"texture file(s) not found: {missing}")
    targets = resolve_prims(prims)
    picks = as_generator(rng, "texture").integers(0, len(files), size=len(targets))
    scales = per_prim(texture_scale, len(targets), "texture_scale", width=2, uniform=True)
    rotates = per_prim(texture_rotate, len(targets), "texture_rotate", width=1, uniform=True, uniform_per_prim=True)
    chosen = []
    for i, prim in enumerate(targets):
        mat = _own_material(prim, "Texture", looks)
        matlib.set_inputs(mat, diffuse_texture=files[int(picks[i])],
                          texture_scale=None if scales[i] is None else tuple(scales[i]),
                          texture_rotate=None if rotates[i] is None else float(rotates[i][0]))
        chosen.append(files[int(picks[i])])
    return chosen


def uniform_quaternions(gen: np.random.Generator, n: int) -> np.ndarray:
    """``n`` quaternions (w, x, y, z) uniform on SO(3) (Shoemake's method)."""
    u1, u2, u3 = gen.random((3, n))
    a, b = np.sqrt(1.0 - u1), np.sqrt(u1)
    q = np.stack([a * np.sin(2 * math.pi * u2), a * np.cos(2 * math.pi * u2),
                  b * np.sin(2 * math.pi * u3), b * np.cos(2 * math.pi * u3)], axis=1)   # (x, y, z, w)
    return q[:, [3, 0, 1, 2]]


def rotation(prims: Any, min_angle: Sequence[float] = (-180.0, -180.0, -180.0),
             max_angle: Sequence[float] = (180.0, 180.0, 180.0),
             rng: ReplicatorRNG | np.random.Generator | None = None, max_tries: int = 10000) -> np.ndarray:
    """Rotate each prim by a rotation uniform on SO(3) (restricted to XYZ Euler limits if given).

    With the default limits every orientation is equally likely (not uniform
    Euler angles, which crowd the poles). Narrower limits keep the uniform law
    restricted to the box, by rejection. Returns the Euler XYZ angles applied.
    """
    lo, hi = np.asarray(min_angle, dtype=np.float64), np.asarray(max_angle, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or np.any(lo > hi):
        raise ValueError(f"rotation limits must be two XYZ triples with min <= max, got {min_angle}, {max_angle}")
    targets = resolve_prims(prims)
    gen = as_generator(rng, "rotation")
    full = bool(np.all(lo <= -180.0) and np.all(hi >= 180.0))
    angles = np.zeros((len(targets), 3))
    for i in range(len(targets)):
        for _ in range(max_tries):
            e = np.array(matrix_to_euler_xyz(quat_wxyz_to_matrix(uniform_quaternions(gen, 1)[0])))
            if full or (np.all(e >= lo) and np.all(e <= hi)):
                angles[i] = e
                break
        else:
            raise ValueError(f"rotation limits {tuple(lo)}..{tuple(hi)} are too narrow: no uniform rotation "
                             f"fell inside them in {max_tries} tries")
    modify.pose(targets, rotation_value=angles)
    return angles


def _bounds_offsets(targets: list) -> np.ndarray:
    """Each prim's world box relative to its world origin, (N, 6) (a point for prims without geometry)."""
    cache = bounds.create_bbox_cache()
    out = np.zeros((len(targets), 6))
    for i, prim in enumerate(targets):
        origin = world_matrix(prim)[3, :3]   # targets are resolved prims
        try:
            box = bounds.compute_aabb(prim, cache)
        except ValueError:
            continue
        out[i] = np.r_[box[:3] - origin, box[3:] - origin]
    return out


def _sample_limits(extents: Any) -> tuple[np.ndarray, np.ndarray]:
    """World (min, max) corners that sampled origins must lie within (Replicator's min_samp / max_samp)."""
    lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
    if extents is None:
        return lo, hi
    try:
        pair = [None if e is None else list(e) for e in extents]
        ok = len(pair) == 2 and all(e is None or len(e) == 3 for e in pair)
    except TypeError:
        ok = False
    if not ok:
        raise ValueError(f"extents must be (min, max) world corners, each 3 numbers or None "
                         f"(None for an unbounded axis), got {extents!r}")
    for out, corner in ((lo, pair[0]), (hi, pair[1])):
        for axis, v in enumerate(corner or ()):
            if v is not None:
                out[axis] = float(v)
    if np.any(lo > hi):
        raise ValueError(f"extents need min <= max on every axis, got min {lo.tolist()} and max {hi.tolist()}")
    return lo, hi


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
        parent_m = parent_world_matrix(prim)
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
    there; rotations are kept. ``extents`` = (min, max) world corners (None or
    None entries: unbounded) limits where origins may land (Replicator's
    ``min_samp`` / ``max_samp``). With ``check_for_collisions`` each prim's real
    world bounds may not overlap those already placed nor ``no_collision_prims``.
    A prim that finds no spot in 10 000 attempts raises ``ValueError`` saying how
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
    lo, hi = _sample_limits(extents)
    if isinstance(offset, bool) or not isinstance(offset, (int, float, np.floating)) or not np.isfinite(offset):
        raise ValueError(f"offset must be a finite number, got {offset!r}")
    surface = placement.surface_of(surfaces)
    gen = as_generator(rng, "scatter_2d")
    offsets = _bounds_offsets(targets)

    def propose(k: int) -> np.ndarray:
        points, normals = placement.sample_surface(surface, k, gen)
        points = points + float(offset) * normals
        return points[np.all((points >= lo) & (points <= hi), axis=1)]

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
    in :func:`scatter_2d`, and so do ``extents``. Sampling is continuous, so Replicator's voxel settings
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
    lo, hi = _sample_limits(extents)
    gen = as_generator(rng, "scatter_3d")
    offsets = _bounds_offsets(targets)
    signs = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=bool)

    def propose(k: int) -> np.ndarray:
        points = placement.sample_volumes(volumes, k, gen, excluded)
        return points[np.all((points >= lo) & (points <= hi), axis=1)]

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


__all__ = ["display_color", "color", "is_mdl_url", "mdl_material", "with_mdl_materials", "materials", "texture", "rotation", "uniform_quaternions", "scatter_2d",
           "scatter_3d"]
