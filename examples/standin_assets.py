"""Procedural stand-ins for the Isaac assets the SDG workflows reference.

The workflows load a pallet, card boxes, two environments and indoor sky HDRs
from Isaac's asset server. When ``graphsdg.assets.get_assets_root_path()`` is
available it is used; otherwise :func:`assets_root_path` writes small stand-ins
at the same relative paths into a folder and returns that folder, so the
scripts stay the seeds' scripts.

Each stand-in is a real USD file whose default prim is an Xform with ``Mesh``
children (the workflows walk those meshes to apply colliders):

* ``SM_PaletteA_01.usd``: a 1.2 x 0.8 x 0.14 m pallet (a deck on three runners),
  origin at the centre of its bottom;
* ``SM_CardBoxC_01.usd``, ``SM_CardBoxD_01.usd``, ``SM_CardBoxD_04.usd``: card
  boxes, origin at the centre of their bottom;
* ``Grid/default_environment.usd`` and ``Simple_Warehouse/warehouse.usd``: a
  ground plane with a collider (the warehouse adds walls);
* ``NVIDIA/Assets/Skies/Indoor/*.hdr``: small Radiance HDR gradients.
"""
from __future__ import annotations

import os
import tempfile

import numpy as np
from pxr import Gf, Usd, UsdGeom, UsdPhysics, Vt

PROPS = "/Isaac/Environments/Simple_Warehouse/Props"
PALLET_SIZE = (1.2, 0.8, 0.14)
BOX_SIZES = {
    "SM_CardBoxC_01": (0.40, 0.30, 0.25),
    "SM_CardBoxD_01": (0.30, 0.30, 0.30),
    "SM_CardBoxD_04": (0.25, 0.20, 0.15),
}
SKIES = ("autoshop_01_4k", "carpentry_shop_01_4k", "wooden_lounge_4k")


def box_mesh_arrays(lo, hi):
    """Points, face counts and indices of an axis-aligned box mesh (outward quads)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    pts = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                    [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], dtype=np.float32)
    faces = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
    return pts, np.full(6, 4), faces.ravel()


def define_box_mesh(stage, path, boxes, color):
    """A Mesh at ``path`` made of the axis-aligned ``boxes`` ((lo, hi) pairs), each its own part."""
    all_pts, counts, idx = [], [], []
    for lo, hi in boxes:
        p, c, i = box_mesh_arrays(lo, hi)
        idx.append(i + sum(len(q) for q in all_pts))
        all_pts.append(p)
        counts.append(c)
    pts = np.vstack(all_pts)
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pts))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.concatenate(counts).astype(np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.concatenate(idx).astype(np.int32)))
    mesh.CreateExtentAttr(Vt.Vec3fArray([Gf.Vec3f(*pts.min(0).tolist()), Gf.Vec3f(*pts.max(0).tolist())]))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateDisplayColorAttr(Vt.Vec3fArray([Gf.Vec3f(*color)]))
    return mesh.GetPrim()


def _new_asset(path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetTimeCodesPerSecond(60.0)        # Kit's rate: one timeline frame per 1/60 s
    root = UsdGeom.Xform.Define(stage, "/Root").GetPrim()
    stage.SetDefaultPrim(root)
    return stage


def write_pallet(path):
    sx, sy, sz = PALLET_SIZE
    deck = 0.04
    stage = _new_asset(path)
    boxes = [((-sx / 2, -sy / 2, sz - deck), (sx / 2, sy / 2, sz))]
    for y in (-sy / 2 + 0.05, 0.0, sy / 2 - 0.05):
        boxes.append(((-sx / 2, y - 0.05, 0.0), (sx / 2, y + 0.05, sz - deck)))
    define_box_mesh(stage, "/Root/SM_PaletteA_01", boxes, (0.62, 0.45, 0.25))
    stage.Save()


def write_box(path, name, size):
    sx, sy, sz = size
    stage = _new_asset(path)
    define_box_mesh(stage, f"/Root/{name}", [((-sx / 2, -sy / 2, 0.0), (sx / 2, sy / 2, sz))], (0.72, 0.55, 0.35))
    stage.Save()


def write_environment(path, walls=False):
    stage = _new_asset(path)
    ground = UsdGeom.Plane.Define(stage, "/Root/GroundPlane")
    ground.CreateWidthAttr(40.0)
    ground.CreateLengthAttr(40.0)
    ground.CreateAxisAttr(UsdGeom.Tokens.z)
    ground.CreateDisplayColorAttr(Vt.Vec3fArray([Gf.Vec3f(0.45, 0.45, 0.45)]))
    UsdPhysics.CollisionAPI.Apply(ground.GetPrim())
    if walls:
        boxes = [((-10, -10.2, 0), (10, -10, 4)), ((-10, 10, 0), (10, 10.2, 4)),
                 ((-10.2, -10, 0), (-10, 10, 4)), ((10, -10, 0), (10.2, 10, 4))]
        walls_prim = define_box_mesh(stage, "/Root/Walls", boxes, (0.8, 0.8, 0.75))
        UsdPhysics.CollisionAPI.Apply(walls_prim)
    stage.Save()


def write_sky(path, top, bottom):
    import cv2
    os.makedirs(os.path.dirname(path), exist_ok=True)
    t = np.linspace(0.0, 1.0, 16, dtype=np.float32)[:, None, None]
    img = (1 - t) * np.array(top, np.float32) + t * np.array(bottom, np.float32)
    cv2.imwrite(path, np.repeat(img, 32, axis=1)[..., ::-1].copy())


def build_standin_assets(root):
    """Write every stand-in under ``root`` (Isaac's relative layout) and return ``root``."""
    write_pallet(os.path.join(root, PROPS.lstrip("/"), "SM_PaletteA_01.usd"))
    for name, size in BOX_SIZES.items():
        write_box(os.path.join(root, PROPS.lstrip("/"), f"{name}.usd"), name, size)
    write_environment(os.path.join(root, "Isaac/Environments/Grid/default_environment.usd"))
    write_environment(os.path.join(root, "Isaac/Environments/Simple_Warehouse/warehouse.usd"), walls=True)
    tints = ((1.2, 1.1, 0.9), (0.9, 1.0, 1.2), (1.1, 0.95, 0.8))
    for name, tint in zip(SKIES, tints):
        write_sky(os.path.join(root, "NVIDIA/Assets/Skies/Indoor", f"{name}.hdr"), tint, (0.3, 0.3, 0.3))
    return root


def assets_root_path():
    """graphsdg's built-in asset pack if this install has one, else freshly written stand-ins."""
    try:
        from graphsdg.assets import get_assets_root_path
    except ImportError:
        get_assets_root_path = None
    if get_assets_root_path is not None:
        root = get_assets_root_path()
        if root is not None:
            return root
    return build_standin_assets(tempfile.mkdtemp(prefix="graphsdg_standins_"))
