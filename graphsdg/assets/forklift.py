"""Stand-in for Isaac Sim's forklift prop (``/Isaac/Props/Forklift/forklift.usd``).

A counterbalance forklift at real size, built from boxes and wheels: body and
counterweight, overhead guard on four posts, seat and steering wheel, a mast
with the fork carriage and two forks, two drive wheels under the mast and two
steer wheels under the counterweight.

Conventions the SDG examples rely on: metres, Z up, origin on the floor under
the middle of the wheelbase (roughly under the driver), the forks pointing
along -Y (scene-based SDG puts the pallet 1.2 to 1.8 m along the forklift's
-Y and a driver camera 1.9 m above its origin). The forks reach 1.95 m ahead of
the origin, the counterweight 1.25 m behind it, the overhead guard stands
2.15 m tall. Each part is a mesh child of the default prim with its own
material; the prop has no physics and no labels (scripts label it
``forklift`` themselves).

Example:
    >>> FORKLIFT_SIZE
    (1.16, 3.2, 2.15)
"""
from __future__ import annotations

import numpy as np

from graphsdg.assets import authoring, geometry
from graphsdg.assets.entries import UsdAsset
from graphsdg.assets.props import Part, write_prop

FORKLIFT_PATH = "/Isaac/Props/Forklift/forklift.usd"
FORKLIFT_SIZE = (1.16, 3.2, 2.15)
FORK_TIP_Y = -1.95        # the forks' tips, along -Y from the origin
REAR_Y = 1.25             # the counterweight's back face
WIDTH = 1.16              # across the drive wheels
GUARD_TOP = 2.15

YELLOW, DARK, BLACK, STEEL = (0.93, 0.66, 0.06), (0.18, 0.18, 0.19), (0.04, 0.04, 0.04), (0.35, 0.35, 0.36)


def _wheel(x: float, y: float, radius: float, width: float) -> geometry.MeshData:
    """A tyre with its axle along X, standing on the floor at (x, y)."""
    w = width / 2
    tyre = geometry.lathe([(0.0, -w), (radius * 0.92, -w), (radius, -w * 0.6), (radius, w * 0.6),
                           (radius * 0.92, w), (0.0, w)], segments=12)
    to_x = np.array([[0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [x, y, radius, 1]], dtype=float)
    return geometry.transformed(tyre, to_x)


def forklift_parts() -> list[Part]:
    """The forklift's parts (see the module docstring for the frame)."""
    hw = WIDTH / 2
    uv = geometry.planar_uv(0.5)
    body = geometry.merge([
        geometry.box((-0.50, -0.62, 0.18), (0.50, 0.70, 0.95), uv),        # chassis and hood
        geometry.box((-0.50, -0.62, 0.95), (-0.30, 0.30, 1.10), uv),       # left side step / cowl
        geometry.box((0.30, -0.62, 0.95), (0.50, 0.30, 1.10), uv),         # right cowl
    ])
    counterweight = geometry.box((-0.54, 0.70, 0.12), (0.54, REAR_Y, 1.12), uv)
    posts = [geometry.box((sx * 0.46 - 0.035, y - 0.035, 0.95), (sx * 0.46 + 0.035, y + 0.035, GUARD_TOP - 0.05), uv)
             for sx in (-1, 1) for y in (-0.55, 0.62)]
    roof = geometry.merge([geometry.box((-0.50, -0.62, GUARD_TOP - 0.05), (0.50, 0.68, GUARD_TOP - 0.02), uv)] + [
        geometry.box((-0.50, y - 0.03, GUARD_TOP - 0.02), (0.50, y + 0.03, GUARD_TOP), uv)
        for y in np.linspace(-0.55, 0.60, 5)])
    seat = geometry.merge([geometry.box((-0.25, 0.05, 1.10), (0.25, 0.50, 1.20), uv),
                           geometry.box((-0.25, 0.42, 1.20), (0.25, 0.52, 1.62), uv)])
    column = geometry.box((-0.04, -0.45, 0.95), (0.04, -0.37, 1.45), uv)
    ring = geometry.lathe([(0.13, -0.015), (0.16, -0.015), (0.16, 0.015), (0.13, 0.015), (0.13, -0.015)], segments=10)
    tilt = np.radians(-35.0)
    wheel_tf = np.array([[1, 0, 0, 0], [0, np.cos(tilt), np.sin(tilt), 0], [0, -np.sin(tilt), np.cos(tilt), 0],
                         [0.0, -0.40, 1.48, 1]], dtype=float)
    steering = geometry.merge([column, geometry.transformed(ring, wheel_tf)])
    mast = geometry.merge([geometry.box((sx * 0.36 - 0.05, -0.80, 0.08), (sx * 0.36 + 0.05, -0.68, 2.05), uv)
                           for sx in (-1, 1)] + [geometry.box((-0.36, -0.80, 1.95), (0.36, -0.70, 2.05), uv)])
    carriage = geometry.merge([geometry.box((-0.48, -0.86, 0.12), (0.48, -0.80, 0.24), uv),
                               geometry.box((-0.48, -0.86, 0.60), (0.48, -0.80, 0.70), uv)]
                              + [geometry.box((x - 0.015, -0.86, 0.24), (x + 0.015, -0.82, 1.25), uv)
                                 for x in np.linspace(-0.45, 0.45, 6)])
    forks = geometry.merge([m for x in (-0.30, 0.30) for m in (
        geometry.box((x - 0.06, -0.90, 0.05), (x + 0.06, -0.86, 0.62), uv),          # shank
        geometry.box((x - 0.06, FORK_TIP_Y, 0.05), (x + 0.06, -0.86, 0.095), uv))])  # blade
    wheels = geometry.merge([_wheel(sx * (hw - 0.12), -0.45, 0.30, 0.24) for sx in (-1, 1)]
                            + [_wheel(sx * (hw - 0.16), 0.85, 0.22, 0.18) for sx in (-1, 1)])
    return [Part("Body", body, YELLOW, 0.45), Part("Counterweight", counterweight, YELLOW, 0.5),
            Part("OverheadGuard", geometry.merge(posts + [roof]), DARK, 0.5), Part("Seat", seat, BLACK, 0.8),
            Part("Steering", steering, BLACK, 0.5), Part("Mast", mast, DARK, 0.4),
            Part("Carriage", carriage, DARK, 0.4), Part("Forks", forks, STEEL, 0.35),
            Part("Wheels", wheels, BLACK, 0.9)]


def build_forklift(root: str) -> list[str]:
    """Write ``forklift.usd`` and its part textures."""
    stage, _, written = write_prop(root, FORKLIFT_PATH, "Forklift", forklift_parts(), texture_dir="Textures",
                                   texture_prefix="forklift", seed=921, decimals=authoring.COMPACT_DECIMALS)
    authoring.save(stage)
    return [FORKLIFT_PATH, *written]


ASSETS: list[UsdAsset] = [
    UsdAsset("forklift", FORKLIFT_PATH, FORKLIFT_SIZE,
             "counterbalance forklift: body, counterweight, overhead guard, seat, mast, carriage, forks along -Y "
             "(tips 1.95 m ahead of the origin), wheels; origin on the floor mid-wheelbase", build_forklift),
]
