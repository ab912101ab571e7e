"""``rep.functional.randomizer``: randomize prims now, from an explicit ``rng``.

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

from graphsdg.functional import modify
from graphsdg.rng import ReplicatorRNG, as_generator
from graphsdg.stage import materials as matlib
from graphsdg.stage.prims import resolve_prims, sanitize_name
from graphsdg.stage.xform import matrix_to_euler_xyz, quat_wxyz_to_matrix

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


def materials(prims: Any, materials: Any, rng: ReplicatorRNG | np.random.Generator | None = None) -> list[str]:
    """Bind each prim a material drawn uniformly from ``materials`` (prims or paths); returns the paths bound."""
    mats = resolve_prims(materials)
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
    scales = _per_prim_rows(texture_scale, len(targets), 2, "texture_scale")
    rotates = _per_prim_rows(texture_rotate, len(targets), 1, "texture_rotate")
    chosen = []
    for i, prim in enumerate(targets):
        mat = _own_material(prim, "Texture", looks)
        matlib.set_inputs(mat, diffuse_texture=files[int(picks[i])],
                          texture_scale=None if scales[i] is None else tuple(scales[i]),
                          texture_rotate=None if rotates[i] is None else float(rotates[i][0]))
        chosen.append(files[int(picks[i])])
    return chosen


def _per_prim_rows(value: Any, n: int, width: int, what: str) -> list:
    if value is None:
        return [None] * n
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0:
        return [np.full(width, float(arr))] * n
    if arr.ndim == 1 and arr.shape[0] == width:
        return [arr] * n
    if arr.ndim == 1 and width == 1 and arr.shape[0] == n:
        return [np.array([v]) for v in arr]
    if arr.ndim == 2 and arr.shape[0] == n and arr.shape[1] in (1, width):
        return [np.broadcast_to(row, (width,)) for row in arr]
    raise ValueError(f"{what} must be one value, one {width}-vector or one per prim ({n}), got shape {arr.shape}")


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


__all__ = ["display_color", "color", "materials", "texture", "rotation", "uniform_quaternions"]
