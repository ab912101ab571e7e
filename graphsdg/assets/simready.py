"""Stand-in SimReady assets (tables, dishes, fruit and vegetables) and the catalogue that finds them.

SimReady assets follow conventions that scripts rely on; these stand-ins keep
them:

* one file per asset, ``<SIMREADY_ROOT>/<name>/<name>.usd``, Z up, authored in
  metres (``metersPerUnit = 1``: scripts size things by ``BBox3d.GetRange()``,
  which is in the asset's own units), real-world size, origin at the centre of
  the bottom face, default prim ``/<name>`` of kind ``component``;
* semantic labels in Isaac's older ``Semantics.SemanticsAPI`` schema on the
  default prim (``semantic:Semantics:params:semanticType = "class"``,
  ``semanticData = <label>``), which scripts upgrade to ``UsdSemantics.LabelsAPI``
  with ``upgrade_prim_semantics_to_labels``;
* a ``PhysicsVariant`` variant set: ``None`` (the file's selection: geometry
  only) and ``RigidBody`` (``RigidBodyAPI`` + ``MassAPI`` on the default prim,
  ``CollisionAPI`` + convex-hull ``MeshCollisionAPI`` on every mesh).

The catalogue (:data:`SIMREADY_CATALOG`, JSON) lists each asset's name, file,
tags, labels, hierarchy, size and behaviours: it is what
``omni.simready.explorer.find_assets`` searches in compat mode.

Example:
    >>> sorted({a.label for a in SIMREADY_ASSETS.values() if "furniture" in a.tags})
    ['table']
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from typing import Callable

import numpy as np
from graphsdg.assets import authoring, geometry
from graphsdg.assets.ycb import banana_parts
from graphsdg.assets.props import (Part, apply_colliders, apply_legacy_semantics, apply_rigid_body, fit,
                                   write_prop)

SIMREADY_ROOT = "/NVIDIA/Assets/simready_content/common_assets/props"
SIMREADY_CATALOG = "/NVIDIA/Assets/simready_content/simready_catalog.json"
PHYSICS_VARIANT_SET = "PhysicsVariant"
PHYSICS_VARIANTS = ("None", "RigidBody")
METERS_PER_UNIT = 1.0


@dataclass(frozen=True)
class SimreadyEntry:
    """One stand-in SimReady asset: name, class label, search tags, hierarchy, size (m), mass (kg), shape."""

    name: str
    label: str
    tags: tuple[str, ...]
    hierarchy: tuple[str, ...]
    size: tuple[float, float, float]
    mass: float
    shape: Callable[[], list[Part]]

    @property
    def path(self) -> str:
        """The file, relative to the asset root."""
        return f"{SIMREADY_ROOT}/{self.name}/{self.name}.usd"


def _sphere_profile(n: int = 12, dimple: float = 0.0) -> list[tuple[float, float]]:
    """A unit-height spheroid profile from the bottom pole to the top pole (``dimple``: dip at the top)."""
    pts = []
    for k in range(n + 1):
        phi = math.pi * k / n
        r, z = math.sin(phi), (1 - math.cos(phi)) / 2
        pts.append((0.0 if k in (0, n) else r, z))
    if dimple:
        pts[-1] = (0.0, 1.0 - dimple)
    return pts


def _table(top_color, leg_color) -> list[Part]:
    top = geometry.box((-0.5, -0.5, 0.953), (0.5, 0.5, 1.0))
    legs = geometry.merge([geometry.box((sx * 0.46 - 0.03, sy * 0.44 - 0.03, 0.0), (sx * 0.46 + 0.03, sy * 0.44 + 0.03,
                                                                                 0.953))
                           for sx in (-1, 1) for sy in (-1, 1)])
    return [Part("Top", top, top_color, 0.55), Part("Legs", legs, leg_color, 0.6)]


def _round_table(color) -> list[Part]:
    top = geometry.lathe([(0, 0.94), (1.0, 0.94), (1.0, 1.0), (0, 1.0)], segments=40)
    stem = geometry.lathe([(0, 0.06), (0.08, 0.06), (0.08, 0.94), (0, 0.94)], segments=16)
    foot = geometry.lathe([(0, 0), (0.55, 0), (0.5, 0.06), (0, 0.06)], segments=32)
    return [Part("Top", top, color, 0.5), Part("Base", geometry.merge([stem, foot]), (0.15, 0.15, 0.16), 0.4)]


def _plate(color) -> list[Part]:
    return [Part("Plate", geometry.lathe([(0, 0), (0.6, 0), (0.72, 0.45), (1.0, 0.85), (1.0, 1.0), (0.97, 1.0),
                                          (0.7, 0.62), (0.6, 0.35), (0, 0.35)], segments=40), color, 0.25)]


def _bowl(color) -> list[Part]:
    return [Part("Bowl", geometry.lathe([(0, 0), (0.5, 0), (0.85, 0.45), (1.0, 1.0), (0.94, 1.0), (0.8, 0.5),
                                         (0.45, 0.08), (0, 0.08)], segments=40), color, 0.3)]


def _round_fruit(color, dimple=0.0, stem=None) -> list[Part]:
    parts = [Part("Skin", geometry.lathe(_sphere_profile(12, dimple), segments=24), color, 0.45)]
    if stem is not None:
        parts.append(Part("Stem", geometry.lathe([(0, 0.9), (0.04, 0.9), (0.03, 1.08), (0, 1.08)], segments=8),
                          stem, 0.7))
    return parts


def _lying_spheroid(color) -> list[Part]:
    lie = np.array([[0, 0, -1, 0], [0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1]], dtype=float)
    return [Part("Skin", geometry.transformed(geometry.lathe(_sphere_profile(12), segments=20), lie), color, 0.6)]


def _pear() -> list[Part]:
    profile = [(0, 0), (0.7, 0.05), (1.0, 0.25), (0.85, 0.55), (0.5, 0.8), (0.35, 0.95), (0, 1.0)]
    return [Part("Skin", geometry.lathe(profile, segments=24), (0.60, 0.72, 0.20), 0.5)]


def _onion() -> list[Part]:
    profile = [(0, 0), (0.5, 0.03), (0.95, 0.3), (0.9, 0.6), (0.4, 0.88), (0.08, 1.0), (0, 1.0)]
    return [Part("Skin", geometry.lathe(profile, segments=24), (0.72, 0.48, 0.22), 0.6)]


def _pepper() -> list[Part]:
    profile = [(0, 0.05), (0.6, 0), (0.95, 0.35), (1.0, 0.8), (0.6, 0.95), (0.12, 0.95), (0.1, 1.0), (0, 1.0)]
    return [Part("Skin", geometry.lathe(profile, segments=24), (0.15, 0.55, 0.12), 0.3)]


def _carrot() -> list[Part]:
    t = np.linspace(0.0, 1.0, 10)
    line = np.c_[t, np.zeros_like(t), np.zeros_like(t)]
    return [Part("Root", geometry.tube(line, 0.11 * (1.0 - 0.85 * t) + 0.005, segments=12), (0.93, 0.45, 0.08), 0.6)]


def _entries() -> list[SimreadyEntry]:
    oak, walnut, steel = (0.62, 0.45, 0.28), (0.36, 0.24, 0.15), (0.2, 0.2, 0.22)
    food = ("food",)
    return [
        SimreadyEntry("dining_table_a01", "table", ("table", "dining table", "furniture", "wood"),
                      ("furniture", "table"), (1.6, 0.9, 0.75), 28.0, lambda: _table(oak, oak)),
        SimreadyEntry("work_table_a02", "table", ("table", "work table", "furniture", "metal"),
                      ("furniture", "table"), (1.2, 0.7, 0.78), 22.0, lambda: _table((0.55, 0.57, 0.6), steel)),
        SimreadyEntry("cafe_table_round_a01", "table", ("table", "cafe table", "round table", "furniture"),
                      ("furniture", "table"), (0.7, 0.7, 0.74), 9.0, lambda: _round_table(walnut)),
        SimreadyEntry("plate_dinner_a01", "plate", ("plate", "dinner plate", "dish", "tableware", "ceramic"),
                      ("tableware", "dish", "plate"), (0.27, 0.27, 0.025), 0.55, lambda: _plate((0.93, 0.93, 0.9))),
        SimreadyEntry("plate_side_a02", "plate", ("plate", "side plate", "dish", "tableware", "ceramic"),
                      ("tableware", "dish", "plate"), (0.21, 0.21, 0.02), 0.32, lambda: _plate((0.25, 0.42, 0.62))),
        SimreadyEntry("bowl_cereal_a01", "bowl", ("bowl", "cereal bowl", "dish", "tableware", "ceramic"),
                      ("tableware", "dish", "bowl"), (0.16, 0.16, 0.07), 0.3, lambda: _bowl((0.9, 0.88, 0.82))),
        SimreadyEntry("bowl_serving_a02", "bowl", ("bowl", "serving bowl", "dish", "tableware", "ceramic"),
                      ("tableware", "dish", "bowl"), (0.24, 0.24, 0.09), 0.62, lambda: _bowl((0.7, 0.2, 0.15))),
        SimreadyEntry("apple_a01", "apple", ("apple", "fruit", *food), ("food", "fruit", "apple"),
                      (0.08, 0.08, 0.078), 0.18, lambda: _round_fruit((0.75, 0.1, 0.08), 0.08, (0.3, 0.2, 0.1))),
        SimreadyEntry("orange_a01", "orange", ("orange", "citrus", "fruit", *food), ("food", "fruit", "orange"),
                      (0.075, 0.075, 0.072), 0.14, lambda: _round_fruit((0.95, 0.5, 0.05))),
        SimreadyEntry("lemon_a01", "lemon", ("lemon", "citrus", "fruit", *food), ("food", "fruit", "lemon"),
                      (0.085, 0.06, 0.06), 0.1, lambda: _lying_spheroid((0.95, 0.85, 0.15))),
        SimreadyEntry("pear_a01", "pear", ("pear", "fruit", *food), ("food", "fruit", "pear"),
                      (0.07, 0.07, 0.1), 0.18, _pear),
        SimreadyEntry("banana_a01", "banana", ("banana", "fruit", *food), ("food", "fruit", "banana"),
                      (0.2, 0.09, 0.036), 0.12, banana_parts),
        SimreadyEntry("tomato_a01", "tomato", ("tomato", "vegetable", *food), ("food", "vegetable", "tomato"),
                      (0.065, 0.065, 0.05), 0.1, lambda: _round_fruit((0.85, 0.12, 0.08), 0.1, (0.2, 0.5, 0.1))),
        SimreadyEntry("onion_a01", "onion", ("onion", "vegetable", *food), ("food", "vegetable", "onion"),
                      (0.075, 0.075, 0.08), 0.15, _onion),
        SimreadyEntry("potato_a01", "potato", ("potato", "vegetable", *food), ("food", "vegetable", "potato"),
                      (0.09, 0.06, 0.05), 0.2, lambda: _lying_spheroid((0.72, 0.56, 0.36))),
        SimreadyEntry("carrot_a01", "carrot", ("carrot", "vegetable", *food), ("food", "vegetable", "carrot"),
                      (0.18, 0.03, 0.03), 0.07, _carrot),
        SimreadyEntry("bell_pepper_a01", "bell pepper", ("bell pepper", "pepper", "vegetable", *food),
                      ("food", "vegetable", "bell pepper"), (0.08, 0.08, 0.09), 0.16, _pepper),
    ]


SIMREADY_ASSETS: dict[str, SimreadyEntry] = {e.name: e for e in _entries()}


def build_asset(entry: SimreadyEntry, root: str) -> list[str]:
    """Write ``entry``'s file (metres, legacy semantics, PhysicsVariant) and textures."""
    parts = fit(entry.shape(), entry.size, origin="bottom")
    stage, prim, written = write_prop(root, entry.path, entry.name, parts, texture_dir="Textures",
                                      texture_prefix=entry.name, seed=sum(map(ord, entry.name)),
                                      meters_per_unit=METERS_PER_UNIT)
    apply_legacy_semantics(prim, entry.label)
    vset = prim.GetVariantSets().AddVariantSet(PHYSICS_VARIANT_SET)
    for name in PHYSICS_VARIANTS:
        vset.AddVariant(name)
    vset.SetVariantSelection("RigidBody")
    with vset.GetVariantEditContext():
        apply_rigid_body(prim, entry.mass)
        apply_colliders(prim, "convexHull")
    vset.SetVariantSelection("None")
    authoring.save(stage)
    return [entry.path, *written]


def catalog_records() -> list[dict]:
    """The catalogue's records: what ``find_assets`` searches and each asset object reports."""
    return [{"name": e.name, "url": e.path, "tags": list(e.tags), "labels": [e.label],
             "hierarchy": list(e.hierarchy), "extent_m": list(e.size), "mass_kg": e.mass,
             "behaviors": {PHYSICS_VARIANT_SET: list(PHYSICS_VARIANTS)}, "asset_type": "PROP"}
            for e in SIMREADY_ASSETS.values()]


def build_catalog(root: str) -> list[str]:
    """Write every SimReady stand-in and the JSON catalogue."""
    written = []
    for entry in SIMREADY_ASSETS.values():
        written += build_asset(entry, root)
    path = os.path.join(root, SIMREADY_CATALOG.lstrip("/"))
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"generator": authoring.GENERATOR_NOTE, "assets": catalog_records()}, f, indent=1)
        f.write("\n")
    return written + [SIMREADY_CATALOG]
