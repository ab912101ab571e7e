"""Stand-ins for the Office and Hospital props Isaac's object-based SDG examples drop as distractors.

``/Isaac/Environments/Office/Props/<name>.usd`` (a whiteboard, two closed books,
an open book, a briefcase, a fire extinguisher) and
``/Isaac/Environments/Hospital/Props/<name>.usd`` (a gas-cylinder cart, a
medical bag, a first-aid box, a towel dispenser): visual props at real sizes,
built from boxes and solids of revolution with one coloured part per mesh, like
the pack's other props (metres, Z up, origin at the centre of the bottom face,
no physics, no labels: the examples add colliders and rigid bodies and clear
any labels on distractors themselves).

Example:
    >>> sorted(OFFICE_PROPS)[:2]
    ['SM_Board', 'SM_BookOpen_01']
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from graphsdg.assets import authoring, geometry
from graphsdg.assets.entries import UsdAsset
from graphsdg.assets.props import Part, fit, write_prop

OFFICE_DIR = "/Isaac/Environments/Office/Props"
HOSPITAL_DIR = "/Isaac/Environments/Hospital/Props"
WHITE, RED, BLACK, STEEL = (0.92, 0.92, 0.90), (0.78, 0.08, 0.07), (0.05, 0.05, 0.05), (0.55, 0.56, 0.58)


def _box(lo, hi) -> geometry.MeshData:
    return geometry.box(lo, hi, geometry.planar_uv(0.3))


def _cylinder_z(x: float, y: float, r: float, z0: float, z1: float, dome: bool = False, segments: int = 14):
    top = [(r * 0.7, z1 + r * 0.3), (0.0, z1 + r * 0.45)] if dome else [(0.0, z1)]
    mesh = geometry.lathe([(0.0, z0), (r, z0), (r, z1), *top], segments=segments)
    shift = np.eye(4)
    shift[3, :2] = (x, y)
    return geometry.transformed(mesh, shift)


def board() -> list[Part]:
    """A whiteboard: a white panel in an aluminium frame with a pen tray, standing on its bottom edge."""
    w, t, h = 1.2, 0.03, 0.9
    panel = _box((-w / 2 + 0.02, -t / 2, 0.02), (w / 2 - 0.02, t / 2, h - 0.02))
    frame = geometry.merge([_box((-w / 2, -t / 2 - 0.005, 0.0), (w / 2, t / 2 + 0.005, 0.02)),
                            _box((-w / 2, -t / 2 - 0.005, h - 0.02), (w / 2, t / 2 + 0.005, h)),
                            _box((-w / 2, -t / 2 - 0.005, 0.02), (-w / 2 + 0.02, t / 2 + 0.005, h - 0.02)),
                            _box((w / 2 - 0.02, -t / 2 - 0.005, 0.02), (w / 2, t / 2 + 0.005, h - 0.02)),
                            _box((-0.3, -t / 2 - 0.06, 0.0), (0.3, -t / 2 - 0.005, 0.025))])
    return [Part("Panel", panel, (0.96, 0.96, 0.95), 0.2), Part("Frame", frame, STEEL, 0.35)]


def book(w: float, d: float, h: float, cover) -> list[Part]:
    """A closed book lying flat: hard cover boards and spine round a block of pages."""
    c = 0.003
    covers = geometry.merge([_box((-w / 2, -d / 2, 0.0), (w / 2, d / 2, c)),
                             _box((-w / 2, -d / 2, h - c), (w / 2, d / 2, h)),
                             _box((-w / 2, -d / 2, c), (-w / 2 + c, d / 2, h - c))])
    pages = _box((-w / 2 + c, -d / 2 + 0.004, c), (w / 2 - 0.004, d / 2 - 0.004, h - c))
    return [Part("Cover", covers, cover, 0.6), Part("Pages", pages, (0.93, 0.90, 0.82), 0.8)]


def open_book() -> list[Part]:
    """An open book lying flat: two page blocks either side of the spine on the open cover."""
    w, d = 0.16, 0.23
    cover = _box((-w, -d / 2, 0.0), (w, d / 2, 0.003))
    pages = geometry.merge([_box((-w + 0.004, -d / 2 + 0.005, 0.003), (-0.002, d / 2 - 0.005, 0.016)),
                            _box((0.002, -d / 2 + 0.005, 0.003), (w - 0.004, d / 2 - 0.005, 0.016))])
    return [Part("Cover", cover, (0.15, 0.25, 0.45), 0.6), Part("Pages", pages, (0.94, 0.92, 0.85), 0.8)]


def briefcase() -> list[Part]:
    """A hard briefcase standing on its long edge, with a handle and two latches."""
    w, t, h = 0.45, 0.12, 0.34
    case = _box((-w / 2, -t / 2, 0.0), (w / 2, t / 2, h))
    handle = geometry.merge([_box((-0.08, -0.012, h), (-0.06, 0.012, h + 0.045)),
                             _box((0.06, -0.012, h), (0.08, 0.012, h + 0.045)),
                             _box((-0.08, -0.012, h + 0.035), (0.08, 0.012, h + 0.05))])
    latches = geometry.merge([_box((x - 0.02, -t / 2 - 0.004, h - 0.05), (x + 0.02, -t / 2, h - 0.02))
                              for x in (-0.14, 0.14)])
    return [Part("Case", case, (0.22, 0.13, 0.07), 0.5), Part("Handle", handle, BLACK, 0.5),
            Part("Latches", latches, (0.75, 0.68, 0.40), 0.3)]


def extinguisher() -> list[Part]:
    """A red fire extinguisher: the cylinder, the valve head and handle, a black hose and nozzle."""
    body = _cylinder_z(0.0, 0.0, 0.08, 0.0, 0.48, dome=True)
    head = geometry.merge([_cylinder_z(0.0, 0.0, 0.025, 0.50, 0.56, segments=10),
                           _box((-0.01, -0.02, 0.56), (0.10, 0.02, 0.58))])
    hose = geometry.tube([(0.02, 0.0, 0.54), (0.09, 0.0, 0.50), (0.11, 0.0, 0.35), (0.10, 0.0, 0.20)],
                         [0.012] * 4, segments=8)
    return [Part("Body", body, RED, 0.35), Part("Head", head, STEEL, 0.3), Part("Hose", hose, BLACK, 0.6)]


def gas_cart() -> list[Part]:
    """A two-cylinder gas cart: tubular frame, two wheels, two green cylinders."""
    frame = geometry.merge([
        geometry.tube([(-0.22, 0.15, 0.06), (-0.22, 0.15, 1.15), (0.22, 0.15, 1.15), (0.22, 0.15, 0.06)], [0.015] * 4,
                      segments=8),
        _box((-0.25, -0.22, 0.04), (0.25, 0.18, 0.07))])
    wheels = geometry.merge([geometry.transformed(
        geometry.lathe([(0.0, -0.02), (0.1, -0.02), (0.1, 0.02), (0.0, 0.02)], segments=12),
        np.array([[0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [x, 0.12, 0.1, 1]], dtype=float)) for x in (-0.23, 0.23)])
    cylinders = geometry.merge([_cylinder_z(x, -0.04, 0.09, 0.07, 0.95, dome=True) for x in (-0.11, 0.11)])
    valves = geometry.merge([_cylinder_z(x, -0.04, 0.02, 0.99, 1.06, segments=8) for x in (-0.11, 0.11)])
    return [Part("Frame", frame, STEEL, 0.4), Part("Wheels", wheels, BLACK, 0.9),
            Part("Cylinders", cylinders, (0.10, 0.45, 0.20), 0.35), Part("Valves", valves, (0.70, 0.60, 0.30), 0.3)]


def medical_bag() -> list[Part]:
    """A doctor's bag: a rounded body (a lathe about X), a frame clasp and a handle."""
    profile = [(0.0, -0.2), (0.09, -0.2), (0.13, -0.17), (0.14, -0.1), (0.14, 0.1), (0.13, 0.17), (0.09, 0.2),
               (0.0, 0.2)]
    body = geometry.lathe(profile, segments=14)
    lie = np.array([[0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 0.14, 1]], dtype=float)
    body = geometry.transformed(body, lie)
    squash = np.diag([1.0, 0.7, 1.0, 1.0])
    body = geometry.transformed(body, squash)
    clasp = _box((-0.2, -0.012, 0.27), (0.2, 0.012, 0.285))
    handle = geometry.tube([(-0.07, 0.0, 0.28), (-0.05, 0.0, 0.33), (0.05, 0.0, 0.33), (0.07, 0.0, 0.28)],
                           [0.01] * 4, segments=8)
    return [Part("Bag", body, (0.30, 0.10, 0.08), 0.6), Part("Clasp", clasp, (0.75, 0.68, 0.40), 0.3),
            Part("Handle", handle, (0.20, 0.07, 0.05), 0.6)]


def medical_box() -> list[Part]:
    """A white first-aid box with a red cross on its front and a handle on top."""
    w, t, h = 0.30, 0.12, 0.22
    box = _box((-w / 2, -t / 2, 0.0), (w / 2, t / 2, h))
    cross = geometry.merge([_box((-0.05, -t / 2 - 0.003, h / 2 - 0.017), (0.05, -t / 2, h / 2 + 0.017)),
                            _box((-0.017, -t / 2 - 0.003, h / 2 - 0.05), (0.017, -t / 2, h / 2 + 0.05))])
    handle = _box((-0.06, -0.01, h), (0.06, 0.01, h + 0.02))
    return [Part("Box", box, WHITE, 0.4), Part("Cross", cross, RED, 0.4), Part("Handle", handle, (0.6, 0.6, 0.6), 0.4)]


def towel_dispenser() -> list[Part]:
    """A wall towel dispenser: a housing with a slot and a towel hanging out of it (back against +Y)."""
    w, t, h = 0.28, 0.11, 0.36
    housing = _box((-w / 2, -t / 2, 0.04), (w / 2, t / 2, h))
    window = _box((-0.06, -t / 2 - 0.002, 0.2), (0.06, -t / 2, 0.26))
    towel = _box((-0.1, -t / 2 + 0.01, 0.0), (0.1, -t / 2 + 0.013, 0.045))
    return [Part("Housing", housing, (0.85, 0.86, 0.86), 0.3), Part("Window", window, (0.2, 0.25, 0.3), 0.1),
            Part("Towel", towel, (0.95, 0.95, 0.93), 0.9)]


@dataclass(frozen=True)
class InteriorProp:
    """One prop: its folder, name, the parts maker and the outer size (m) its parts are fitted to."""

    folder: str
    name: str
    parts: Callable[[], list[Part]]
    size: tuple[float, float, float]
    description: str


def _props() -> list[InteriorProp]:
    return [
        InteriorProp(OFFICE_DIR, "SM_Board", board, (1.2, 0.095, 0.9), "whiteboard 1.2 x 0.9 m in a frame, pen tray"),
        InteriorProp(OFFICE_DIR, "SM_Book_03", lambda: book(0.15, 0.23, 0.03, (0.55, 0.12, 0.10)), (0.15, 0.23, 0.03),
                     "closed hardback book lying flat, red cover"),
        InteriorProp(OFFICE_DIR, "SM_Book_34", lambda: book(0.17, 0.24, 0.04, (0.10, 0.30, 0.20)), (0.17, 0.24, 0.04),
                     "closed hardback book lying flat, green cover"),
        InteriorProp(OFFICE_DIR, "SM_BookOpen_01", open_book, (0.32, 0.23, 0.016), "open book lying flat"),
        InteriorProp(OFFICE_DIR, "SM_Briefcase", briefcase, (0.45, 0.124, 0.39), "hard brown briefcase, handle up"),
        InteriorProp(OFFICE_DIR, "SM_Extinguisher", extinguisher, (0.202, 0.156, 0.58),
                     "red fire extinguisher with valve head and hose"),
        InteriorProp(HOSPITAL_DIR, "SM_GasCart_01b", gas_cart, (0.5, 0.44, 1.156),
                     "gas-cylinder cart: tubular frame, two wheels, two green cylinders"),
        InteriorProp(HOSPITAL_DIR, "SM_MedicalBag_01a", medical_bag, (0.4, 0.191, 0.339), "doctor's bag with clasp"),
        InteriorProp(HOSPITAL_DIR, "SM_MedicalBox_01g", medical_box, (0.3, 0.123, 0.24),
                     "white first-aid box with a red cross"),
        InteriorProp(HOSPITAL_DIR, "SM_Toweldispenser_01a", towel_dispenser, (0.28, 0.112, 0.36),
                     "wall towel dispenser with a towel hanging out"),
    ]


INTERIOR_PROPS: dict[str, InteriorProp] = {p.name: p for p in _props()}
OFFICE_PROPS = {n: p for n, p in INTERIOR_PROPS.items() if p.folder == OFFICE_DIR}
HOSPITAL_PROPS = {n: p for n, p in INTERIOR_PROPS.items() if p.folder == HOSPITAL_DIR}


def build_prop(prop: InteriorProp, root: str) -> list[str]:
    """Write one prop's USD file and part textures (parts placed with the origin at the bottom centre)."""
    rel = f"{prop.folder}/{prop.name}.usd"
    parts = fit(prop.parts(), prop.size, origin="bottom")
    stage, _, written = write_prop(root, rel, prop.name, parts, texture_dir="Textures", texture_prefix=prop.name,
                                   seed=sum(map(ord, prop.name)), decimals=authoring.COMPACT_DECIMALS)
    authoring.save(stage)
    return [rel, *written]


ASSETS: list[UsdAsset] = [UsdAsset(p.name.lower(), f"{p.folder}/{p.name}.usd", p.size, p.description,
                                   lambda root, p=p: build_prop(p, root)) for p in INTERIOR_PROPS.values()]
