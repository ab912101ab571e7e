"""The pack's block pallet (``SM_PaletteA_01``): its measurements and boards.

Shared by the pallet asset itself and by the warehouse racks, which stock a
single-mesh copy of it (:mod:`graphsdg.assets.warehouse_stages`).

Example:
    >>> len(pallet_parts()), PALLET_HEIGHT
    (20, 0.14)
"""
from __future__ import annotations

PALLET_LENGTH, PALLET_WIDTH, PALLET_HEIGHT = 1.2, 0.8, 0.14
BOARD_T = 0.022          # deck and bottom board thickness
BLOCK_H = 0.074          # block height: 0.022 + 0.022 + 0.074 + 0.022 = 0.14
BLOCK_W = 0.145


def pallet_parts() -> list[tuple[str, tuple[float, float, float], tuple[float, float, float], int]]:
    """(name, lo, hi, grain axis) of every board and block of the pallet, origin at the bottom centre.

    A block pallet after the EUR pattern: three bottom boards along X, nine blocks,
    three cross boards along Y, and five top deck boards along X (wide at the
    edges and centre, narrow between).
    """
    L, W = PALLET_LENGTH, PALLET_WIDTH
    xs = (-L / 2 + BLOCK_W / 2, 0.0, L / 2 - BLOCK_W / 2)
    ys = (-W / 2 + BLOCK_W / 2, 0.0, W / 2 - BLOCK_W / 2)
    parts = []
    z0 = 0.0
    for i, y in enumerate(ys):
        parts.append((f"BottomBoard_{i:02d}", (-L / 2, y - BLOCK_W / 2, z0), (L / 2, y + BLOCK_W / 2, z0 + BOARD_T), 0))
    z1 = z0 + BOARD_T
    k = 0
    for x in xs:
        for y in ys:
            parts.append((f"Block_{k:02d}", (x - BLOCK_W / 2, y - BLOCK_W / 2, z1),
                          (x + BLOCK_W / 2, y + BLOCK_W / 2, z1 + BLOCK_H), 2))
            k += 1
    z2 = z1 + BLOCK_H
    for i, x in enumerate(xs):
        parts.append((f"CrossBoard_{i:02d}", (x - BLOCK_W / 2, -W / 2, z2), (x + BLOCK_W / 2, W / 2, z2 + BOARD_T), 1))
    z3 = z2 + BOARD_T
    widths = (0.145, 0.100, 0.145, 0.100, 0.145)
    gap = (W - sum(widths)) / (len(widths) - 1)
    y = -W / 2
    for i, w in enumerate(widths):
        parts.append((f"DeckBoard_{i:02d}", (-L / 2, y, z3), (L / 2, y + w, z3 + BOARD_T), 0))
        y += w + gap
    return parts
