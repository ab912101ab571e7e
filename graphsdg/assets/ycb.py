"""Stand-ins for the YCB objects Isaac Sim ships under ``/Isaac/Props/YCB``.

Each object is a cheap procedural shape (boxes, solids of revolution, swept
tubes) fitted to the real object's outer size from the YCB object set, with its
real mass and colours. Two files per object, as in Isaac:

* ``/Isaac/Props/YCB/Axis_Aligned/<id>.usd``: geometry and materials only;
* ``/Isaac/Props/YCB/Axis_Aligned_Physics/<id>.usd``: references the first and
  adds ``RigidBodyAPI`` + ``MassAPI`` on the default prim and ``CollisionAPI`` +
  ``MeshCollisionAPI`` (convex hull) on each mesh.

The default prim is an Xform named as in Isaac's files (``_11_banana`` for
``011_banana``) holding one mesh per part; the origin is the centre of the
object's bounds. Like Isaac's files, these carry no semantic labels: scripts
label what they load.

Example:
    >>> YCB_OBJECTS["011_banana"].size
    (0.036, 0.19, 0.036)
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Callable

import numpy as np
from pxr import Sdf

from graphsdg.assets import authoring, geometry
from graphsdg.assets.props import Part, apply_colliders, apply_rigid_body, fit, write_prop

YCB_DIR = "/Isaac/Props/YCB/Axis_Aligned"
YCB_PHYSICS_DIR = "/Isaac/Props/YCB/Axis_Aligned_Physics"


@dataclass(frozen=True)
class YcbObject:
    """One YCB object: id (``011_banana``), outer size (m), mass (kg), class name and how to shape it."""

    id: str
    size: tuple[float, float, float]
    mass: float
    label: str
    shape: Callable[[], list[Part]]

    @property
    def prim_name(self) -> str:
        """The default prim's name in Isaac's file: ``011_banana`` -> ``_11_banana``."""
        return "_" + self.id[1:]


def _cylinder(r: float = 1.0, h: float = 1.0, rim: float = 0.0) -> geometry.MeshData:
    """A can: a cylinder with a slightly narrower lid and base (``rim`` of the radius)."""
    inset = r * (1 - rim)
    return geometry.lathe([(0, 0), (inset, 0), (r, 0.03 * h), (r, 0.97 * h), (inset, h), (0, h)], segments=32)


def _box(color, name="Body", roughness=0.6) -> list[Part]:
    return [Part(name, geometry.box((-1, -1, -1), (1, 1, 1)), color, roughness)]


def _can(color, lid=(0.75, 0.75, 0.78)) -> list[Part]:
    body = geometry.lathe([(1.0, 0.06), (1.0, 0.94)], segments=32)
    ends = geometry.merge([geometry.lathe([(0, 0), (0.96, 0), (1.0, 0.06)], segments=32),
                           geometry.lathe([(1.0, 0.94), (0.96, 1.0), (0, 1.0)], segments=32)])
    return [Part("Label", body, color, 0.5), Part("Lid", ends, lid, 0.3)]


def _bottle(color, cap, neck=0.35, shoulder=0.75) -> list[Part]:
    body = geometry.lathe([(0, 0), (1.0, 0), (1.0, shoulder), (neck, 0.9)], segments=32)
    top = geometry.lathe([(neck, 0.9), (neck, 1.0), (0, 1.0)], segments=24)
    return [Part("Body", body, color, 0.4), Part("Cap", top, cap, 0.5)]


def banana_parts() -> list[Part]:
    """A banana: a tapering tube along a 100 degree arc, yellow peel (unit-less: fit it to a size)."""
    t = np.linspace(0.0, 1.0, 17)
    angle = (t - 0.5) * math.radians(100)          # a 100 degree arc
    line = np.c_[0.11 * (1 - np.cos(angle)), 0.11 * np.sin(angle), np.zeros_like(t)]
    radii = 0.018 * np.sqrt(np.clip(np.sin(np.pi * t), 0.08, 1.0))   # tapering to the stem and the tip
    return [Part("Peel", geometry.tube(line, radii, segments=12), (0.93, 0.78, 0.20), 0.55)]


def _marker() -> list[Part]:
    body = geometry.lathe([(0, 0), (1.0, 0), (1.0, 0.72)], segments=20)
    cap = geometry.lathe([(1.0, 0.72), (1.05, 0.72), (1.05, 0.97), (0.7, 1.0), (0, 1.0)], segments=20)
    lie = np.array([[0, 0, 1, 0], [0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1]], dtype=float)   # z -> x: lying down
    return [Part("Barrel", geometry.transformed(body, lie), (0.92, 0.92, 0.90), 0.5),
            Part("Cap", geometry.transformed(cap, lie), (0.10, 0.12, 0.14), 0.4)]


def _bowl(color) -> list[Part]:
    return [Part("Bowl", geometry.lathe([(0, 0), (0.55, 0), (0.9, 0.5), (1.0, 1.0), (0.94, 1.0), (0.84, 0.52),
                                         (0.5, 0.08), (0, 0.08)], segments=40), color, 0.35)]


def _mug() -> list[Part]:
    body = geometry.lathe([(0, 0), (1.0, 0), (1.0, 2.0), (0.9, 2.0), (0.9, 0.1), (0, 0.1)], segments=32)
    a = np.linspace(-math.pi / 2, math.pi / 2, 13)
    handle = geometry.tube(np.c_[1.0 + 0.45 * np.cos(a), np.zeros_like(a), 1.0 + 0.6 * np.sin(a)],
                           np.full(len(a), 0.1), segments=10)
    return [Part("Body", body, (0.80, 0.12, 0.10), 0.3), Part("Handle", handle, (0.80, 0.12, 0.10), 0.3)]


def _pitcher() -> list[Part]:
    body = geometry.lathe([(0, 0), (1.0, 0), (1.1, 1.2), (0.8, 2.0), (0.72, 2.0), (0, 0.1)], segments=32)
    a = np.linspace(-math.pi / 2, math.pi / 2, 13)
    handle = geometry.tube(np.c_[1.0 + 0.5 * np.cos(a), np.zeros_like(a), 1.1 + 0.6 * np.sin(a)],
                           np.full(len(a), 0.1), segments=10)
    return [Part("Body", body, (0.20, 0.45, 0.78), 0.35), Part("Handle", handle, (0.20, 0.45, 0.78), 0.35)]


def _drill() -> list[Part]:
    housing = geometry.box((-0.5, -0.15, 0.55), (0.45, 0.15, 1.0))
    grip = geometry.box((-0.35, -0.12, 0.15), (-0.1, 0.12, 0.6))
    battery = geometry.box((-0.5, -0.17, 0.0), (0.05, 0.17, 0.18))
    chuck = geometry.transformed(geometry.lathe([(0, 0), (0.1, 0), (0.08, 0.12), (0, 0.12)], segments=16),
                                 np.array([[0, 0, -1, 0], [0, 1, 0, 0], [1, 0, 0, 0], [0.45, 0, 0.78, 1]], float))
    return [Part("Housing", geometry.merge([housing, grip]), (0.10, 0.45, 0.55), 0.45),
            Part("Battery", battery, (0.12, 0.12, 0.12), 0.6), Part("Chuck", chuck, (0.55, 0.55, 0.57), 0.3)]


def _scissors() -> list[Part]:
    blades = geometry.merge([geometry.box((0.0, -0.06, 0.0), (1.0, 0.04, 0.35)),
                             geometry.box((0.0, -0.04, 0.4), (1.0, 0.06, 0.75))])
    rings = []
    for y, z in ((-0.22, 0.18), (0.22, 0.58)):
        a = np.linspace(0, 2 * math.pi, 17)
        rings.append(geometry.tube(np.c_[-0.3 + 0.25 * np.cos(a), y + 0.2 * np.sin(a), np.full_like(a, z)],
                                   np.full(len(a), 0.06), segments=8))
    return [Part("Blades", blades, (0.72, 0.72, 0.74), 0.25),
            Part("Handles", geometry.merge(rings), (0.10, 0.25, 0.75), 0.5)]


def _clamp(color) -> list[Part]:
    bar = geometry.box((0.0, -0.04, 0.0), (1.0, 0.04, 0.3))
    jaws = geometry.merge([geometry.box((0.0, 0.04, 0.0), (0.15, 0.5, 0.3)),
                           geometry.box((0.55, 0.04, 0.0), (0.7, 0.5, 0.3))])
    handle = geometry.box((0.55, -0.6, 0.02), (0.72, -0.04, 0.28))
    return [Part("Bar", bar, (0.25, 0.25, 0.27), 0.4), Part("Jaws", geometry.merge([jaws, handle]), color, 0.5)]


def _objects() -> list[YcbObject]:
    red, yellow = (0.78, 0.10, 0.08), (0.95, 0.80, 0.12)
    return [
        YcbObject("002_master_chef_can", (0.102, 0.102, 0.139), 0.414, "master_chef_can",
                  lambda: _can((0.12, 0.30, 0.62))),
        YcbObject("003_cracker_box", (0.158, 0.060, 0.210), 0.411, "cracker_box", lambda: _box(red)),
        YcbObject("004_sugar_box", (0.089, 0.038, 0.175), 0.514, "sugar_box", lambda: _box((0.95, 0.88, 0.35))),
        YcbObject("005_tomato_soup_can", (0.066, 0.066, 0.101), 0.349, "tomato_soup_can",
                  lambda: _can((0.80, 0.12, 0.10))),
        YcbObject("006_mustard_bottle", (0.085, 0.050, 0.175), 0.603, "mustard_bottle",
                  lambda: _bottle(yellow, (0.90, 0.45, 0.08))),
        YcbObject("007_tuna_fish_can", (0.085, 0.085, 0.033), 0.171, "tuna_fish_can",
                  lambda: _can((0.20, 0.35, 0.70))),
        YcbObject("008_pudding_box", (0.110, 0.035, 0.089), 0.187, "pudding_box", lambda: _box((0.55, 0.33, 0.18))),
        YcbObject("009_gelatin_box", (0.085, 0.028, 0.073), 0.097, "gelatin_box", lambda: _box((0.85, 0.20, 0.25))),
        YcbObject("010_potted_meat_can", (0.097, 0.050, 0.082), 0.370, "potted_meat_can",
                  lambda: _box((0.20, 0.30, 0.62), "Label", 0.4)),
        YcbObject("011_banana", (0.036, 0.190, 0.036), 0.066, "banana", banana_parts),
        YcbObject("019_pitcher_base", (0.188, 0.108, 0.242), 0.178, "pitcher_base", _pitcher),
        YcbObject("021_bleach_cleanser", (0.098, 0.065, 0.250), 1.131, "bleach_cleanser",
                  lambda: _bottle((0.93, 0.93, 0.90), (0.15, 0.35, 0.80), neck=0.3, shoulder=0.8)),
        YcbObject("024_bowl", (0.159, 0.159, 0.053), 0.147, "bowl", lambda: _bowl((0.80, 0.15, 0.12))),
        YcbObject("025_mug", (0.117, 0.080, 0.082), 0.118, "mug", _mug),
        YcbObject("035_power_drill", (0.184, 0.057, 0.187), 0.895, "power_drill", _drill),
        YcbObject("036_wood_block", (0.085, 0.085, 0.200), 0.729, "wood_block",
                  lambda: _box((0.78, 0.62, 0.40), roughness=0.8)),
        YcbObject("037_scissors", (0.200, 0.087, 0.014), 0.082, "scissors", _scissors),
        YcbObject("040_large_marker", (0.121, 0.018, 0.018), 0.016, "large_marker", _marker),
        YcbObject("051_large_clamp", (0.125, 0.165, 0.032), 0.125, "large_clamp", lambda: _clamp((0.10, 0.10, 0.10))),
        YcbObject("052_extra_large_clamp", (0.165, 0.213, 0.037), 0.202, "extra_large_clamp",
                  lambda: _clamp((0.95, 0.55, 0.08))),
        YcbObject("061_foam_brick", (0.050, 0.075, 0.050), 0.028, "foam_brick",
                  lambda: _box((0.85, 0.15, 0.12), roughness=0.9)),
    ]


YCB_OBJECTS: dict[str, YcbObject] = {o.id: o for o in _objects()}


def build_visual(obj: YcbObject, root: str) -> list[str]:
    """Write ``Axis_Aligned/<id>.usd`` and its textures; returns the relative paths written."""
    rel = f"{YCB_DIR}/{obj.id}.usd"
    parts = fit(obj.shape(), obj.size, origin="center")
    stage, prim, textures_written = write_prop(root, rel, obj.prim_name, parts, texture_dir="Textures",
                                               texture_prefix=obj.id, seed=int(obj.id[:3]))
    authoring.save(stage)
    return [rel, *textures_written]


def build_physics(obj: YcbObject, root: str) -> list[str]:
    """Write ``Axis_Aligned_Physics/<id>.usd``: a reference to the visual file plus rigid body and colliders."""
    rel = f"{YCB_PHYSICS_DIR}/{obj.id}.usd"
    stage, prim = authoring.new_asset_stage(os.path.join(root, rel.lstrip("/")), obj.prim_name)
    prim.GetReferences().AddReference(Sdf.Reference(f"../Axis_Aligned/{obj.id}.usd"))
    apply_rigid_body(prim, obj.mass)
    apply_colliders(prim, "convexHull")
    authoring.save(stage)
    return [rel]
