"""Props built from coloured parts: the shared authoring of the YCB, packing-table and SimReady stand-ins.

A :class:`Part` is one mesh with a base colour; :func:`write_prop` writes a USD
file whose default prim holds one ``UsdGeom.Mesh`` per part, each bound to a
``UsdPreviewSurface`` material that reads a small procedural texture (the colour
with faint mottling, so the surface is not flat). :func:`fit` scales a set of
parts to an object's real outer size. :func:`apply_rigid_body` and
:func:`apply_colliders` author the ``UsdPhysics`` schemas the physics variants of
these assets carry.

Example:
    >>> from graphsdg.assets import geometry
    >>> parts = fit([Part("Body", geometry.box((0, 0, 0), (1, 1, 1)), (0.8, 0.1, 0.1))], (0.1, 0.2, 0.3))
    >>> [round(float(x), 3) for x in parts[0].mesh.bounds()[1] - parts[0].mesh.bounds()[0]]
    [0.1, 0.2, 0.3]
"""
from __future__ import annotations

import os
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np
from pxr import Kind, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.noise import fbm

RGB = tuple[float, float, float]
PART_TEXTURE_SIZE = (32, 32)   # the parts' colour is flat but for a faint mottle: 32 px keeps the pack small


@dataclass(frozen=True)
class Part:
    """One mesh of a prop and its base colour (linear RGB in [0, 1])."""

    name: str
    mesh: geometry.MeshData
    color: RGB
    roughness: float = 0.6


def fit(parts: Sequence[Part], size: Sequence[float], origin: str = "center") -> list[Part]:
    """``parts`` scaled together so their joint bounds measure ``size`` (x, y, z metres).

    ``origin``: ``"center"`` puts the bounds' centre at the origin, ``"bottom"``
    the centre of the bottom face.
    """
    if origin not in ("center", "bottom"):
        raise ValueError(f"origin must be 'center' or 'bottom', got {origin!r}")
    target = np.asarray(size, dtype=np.float64)
    if target.shape != (3,) or np.any(target <= 0):
        raise ValueError(f"size must be three positive lengths (x, y, z), got {size!r}")
    lo = np.min([p.mesh.bounds()[0] for p in parts], axis=0)
    hi = np.max([p.mesh.bounds()[1] for p in parts], axis=0)
    scale = target / (hi - lo)
    shift = -(lo + hi) / 2 * scale
    if origin == "bottom":
        shift[2] = -lo[2] * scale[2]
    matrix = np.diag([*scale, 1.0])
    matrix[3, :3] = shift
    return [replace(p, mesh=geometry.transformed(p.mesh, matrix)) for p in parts]


def part_texture(color: RGB, seed: int) -> np.ndarray:
    """The small tileable texture of a part: ``color`` with a +/- 4 % mottle."""
    mottle = fbm(PART_TEXTURE_SIZE, period=(4, 4), octaves=3, seed=seed)
    return np.clip(np.asarray(color)[None, None, :] * (0.96 + 0.08 * mottle[..., None]), 0.0, 1.0)


def write_prop(root: str, rel: str, prim_name: str, parts: Sequence[Part], *, texture_dir: str,
               texture_prefix: str, seed: int, meters_per_unit: float | None = 1.0,
               unit_scale: float = 1.0, decimals: tuple[int, int] | None = None
               ) -> tuple[Usd.Stage, Usd.Prim, list[str]]:
    """Write ``parts`` as the prop file ``rel`` (under ``root``) with default prim ``/prim_name``.

    Each part is the mesh ``/prim_name/<part.name>`` bound to
    ``/prim_name/Looks/<part.name>``, whose texture is
    ``<texture_dir>/<texture_prefix>_<part.name>.png`` (a path relative to the
    file's folder). Geometry is multiplied by ``unit_scale`` (100 for an asset
    authored in centimetres). ``meters_per_unit`` None leaves the metadata
    unauthored (USD's fallback is centimetres). ``decimals`` rounds the meshes'
    values (:func:`graphsdg.assets.authoring.define_mesh`). Returns the open stage, the root
    prim and the relative paths written (textures; the caller saves the stage).
    """
    path = os.path.join(root, rel.lstrip("/"))
    stage, prim = authoring.new_asset_stage(path, prim_name, kind=Kind.Tokens.component)
    if meters_per_unit is None:
        stage.GetRootLayer().pseudoRoot.ClearInfo("metersPerUnit")
    else:
        UsdGeom.SetStageMetersPerUnit(stage, meters_per_unit)
    written = []
    folder = os.path.dirname(rel)
    for k, part in enumerate(parts):
        tex_rel = f"{folder}/{texture_dir}/{texture_prefix}_{part.name}.png"
        if tex_rel not in written:
            textures.write_png(os.path.join(root, tex_rel.lstrip("/")), part_texture(part.color, seed * 31 + k))
            written.append(tex_rel)
        material = authoring.define_textured_material(stage, f"/{prim_name}/Looks/{part.name}",
                                                      f"./{texture_dir}/{texture_prefix}_{part.name}.png",
                                                      roughness=part.roughness)
        mesh = part.mesh
        if unit_scale != 1.0:
            mesh = geometry.transformed(mesh, np.diag([unit_scale] * 3 + [1.0]))
        geom = authoring.define_mesh(stage, f"/{prim_name}/{part.name}", mesh, decimals)
        authoring.bind_material(geom.GetPrim(), material)
    return stage, prim, written


def mesh_prims(prim: Usd.Prim) -> list[Usd.Prim]:
    """The ``UsdGeom.Mesh`` prims at and below ``prim``."""
    return [p for p in Usd.PrimRange(prim) if p.IsA(UsdGeom.Mesh)]


def apply_colliders(prim: Usd.Prim, approximation: str = "convexHull") -> None:
    """``CollisionAPI`` and ``MeshCollisionAPI`` (``approximation``) on every mesh at and below ``prim``."""
    for mesh in mesh_prims(prim):
        UsdPhysics.CollisionAPI.Apply(mesh)
        UsdPhysics.MeshCollisionAPI.Apply(mesh).CreateApproximationAttr().Set(approximation)


def apply_rigid_body(prim: Usd.Prim, mass: float) -> None:
    """``RigidBodyAPI`` and ``MassAPI`` (``mass`` in kg) on ``prim``."""
    if mass <= 0:
        raise ValueError(f"mass must be > 0 kg, got {mass!r}")
    UsdPhysics.RigidBodyAPI.Apply(prim)
    UsdPhysics.MassAPI.Apply(prim).CreateMassAttr().Set(float(mass))


def apply_legacy_semantics(prim: Usd.Prim, label: str, sem_type: str = "class", instance: str = "Semantics") -> None:
    """Isaac Sim's older ``Semantics.SemanticsAPI`` labels (``semantic:<instance>:params:semanticType`` and
    ``semanticData``), as SimReady assets carry them; authored as plain properties and the API schema token,
    since usd-core has no ``Semantics`` schema plugin."""
    schemas = prim.GetMetadata("apiSchemas") or Sdf.TokenListOp()
    token = f"SemanticsAPI:{instance}"
    items = list(schemas.prependedItems)
    if token not in items:
        schemas.prependedItems = items + [token]
        prim.SetMetadata("apiSchemas", schemas)
    prim.CreateAttribute(f"semantic:{instance}:params:semanticType", Sdf.ValueTypeNames.String).Set(sem_type)
    prim.CreateAttribute(f"semantic:{instance}:params:semanticData", Sdf.ValueTypeNames.String).Set(label)
