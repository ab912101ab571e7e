"""Procedural textures of the asset pack: wood, printed cardboard, concrete, paint, grid.

Every function returns a float ``(rows, cols, 3)`` RGB image in [0, 1] (display,
sRGB-encoded values, as a photo texture would hold) and is a pure function of its
arguments, built on :mod:`graphsdg.assets.noise`, so the pack regenerates to the
same pixels. :func:`write_png` stores one as an 8-bit PNG.

Conventions: row 0 is the top of the image (the ``v = 1`` edge of USD's ``st``);
wood grain runs along the columns (``u``).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass

import cv2
import numpy as np

from graphsdg.assets.noise import fbm, hash01, speckle, value_noise

RGB = tuple[float, float, float]


def _lerp(a: RGB, b: RGB, t: np.ndarray) -> np.ndarray:
    a_, b_ = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a_ + (b_ - a_) * t[..., None]


def _smoothstep(e0: float, e1: float, x: np.ndarray) -> np.ndarray:
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3 - 2 * t)


def to_uint8(rgb: np.ndarray) -> np.ndarray:
    """Float RGB in [0, 1] -> uint8 RGB (rounded, clipped)."""
    return np.clip(np.rint(np.asarray(rgb) * 255.0), 0, 255).astype(np.uint8)


def write_png(path: str, rgb: np.ndarray) -> None:
    """Write a float RGB image in [0, 1] as an 8-bit PNG (parent folders are created)."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    if not cv2.imwrite(path, cv2.cvtColor(to_uint8(rgb), cv2.COLOR_RGB2BGR)):
        raise OSError(f"could not write texture {path!r}")


# ---- wood -----------------------------------------------------------------
@dataclass(frozen=True)
class WoodStyle:
    """Look of one wood species: early/late wood colours and grain structure."""

    light: RGB
    dark: RGB
    rings: int            # growth rings across the image height (integer: the image tiles)
    warp: float           # how far (in rings) the grain meanders
    fibre: float          # strength of the fine fibre streaks
    seed: int
    knots: int = 0        # number of knots (timber)
    flecks: bool = False  # medullary ray flecks (oak)
    plies: int = 0        # glued veneer seams across the height (plywood face)


WOOD_STYLES: dict[str, WoodStyle] = {
    "Oak": WoodStyle(light=(0.70, 0.52, 0.31), dark=(0.42, 0.27, 0.13), rings=17, warp=1.8, fibre=0.10,
                     seed=11, flecks=True),
    "Ash": WoodStyle(light=(0.86, 0.77, 0.61), dark=(0.62, 0.49, 0.33), rings=12, warp=1.1, fibre=0.07, seed=23),
    "Plywood": WoodStyle(light=(0.89, 0.77, 0.57), dark=(0.70, 0.53, 0.33), rings=5, warp=3.2, fibre=0.05,
                         seed=37, plies=2),
    "Timber": WoodStyle(light=(0.80, 0.64, 0.43), dark=(0.55, 0.39, 0.22), rings=10, warp=1.5, fibre=0.12,
                        seed=41, knots=3),
    # sawn pallet pine: paler and greyer, with knots
    "PalletPine": WoodStyle(light=(0.80, 0.70, 0.53), dark=(0.50, 0.38, 0.23), rings=11, warp=1.3, fibre=0.16,
                            seed=53, knots=2),
}


def wood(size: tuple[int, int], style: WoodStyle) -> np.ndarray:
    """Tileable plank-wood texture of ``size`` (rows, cols); the grain runs along the columns."""
    rows, cols = size
    y = (np.arange(rows)[:, None] + 0.5) / rows * np.ones((1, cols))
    x = np.ones((rows, 1)) * ((np.arange(cols)[None, :] + 0.5) / cols)
    meander = fbm(size, period=(2, 2), octaves=4, seed=style.seed) - 0.5
    ring = style.rings * y + style.warp * meander
    knot_cores = np.zeros(size)
    for k in range(style.knots):
        # Knots pull the rings into tight loops around a dark core (periodic distance: still tiles).
        ky, kx = hash01(k, 1, style.seed), hash01(k, 2, style.seed)
        dy = (y - ky + 0.5) % 1.0 - 0.5
        dx = ((x - kx + 0.5) % 1.0 - 0.5) * 0.3      # knots are stretched along the grain
        d2 = (dx * dx + dy * dy) * (style.rings * 2.0) ** 2
        ring = ring + 1.2 * np.exp(-d2) * np.tanh(dy * style.rings * 6)
        knot_cores += np.exp(-(dx * dx + dy * dy) * (style.rings * 6.0) ** 2)
    frac = ring - np.floor(ring)
    # earlywood lightens slowly, latewood is a narrow dark band with a sharp outer edge
    latewood = frac ** 5
    fine = ring * 5.0
    fine_lines = (fine - np.floor(fine)) ** 8
    streaks = value_noise(size, period=(max(8, rows // 4), 4), seed=style.seed + 5)
    streaks2 = value_noise(size, period=(max(8, rows // 2), 8), seed=style.seed + 6)
    tone = fbm(size, period=(3, 1), octaves=3, seed=style.seed + 9)
    t = (0.8 * latewood + 0.12 * fine_lines + style.fibre * (streaks - 0.5) * 2.5
         + style.fibre * (streaks2 - 0.5) * 1.5 + 0.3 * (tone - 0.5))
    img = _lerp(style.light, style.dark, np.clip(t, 0.0, 1.0))
    img = img * (1.0 - 0.6 * np.clip(knot_cores, 0, 1)[..., None])
    if style.flecks:
        ray = value_noise(size, period=(rows // 4, 10), seed=style.seed + 17)
        img = img + 0.05 * _smoothstep(0.8, 0.92, ray)[..., None]
    if style.plies:
        seam = (y * style.plies) % 1.0
        dist = np.minimum(seam, 1 - seam) * rows / style.plies
        img = img * (1.0 - 0.22 * np.exp(-(dist / 1.2) ** 2))[..., None]
    return np.clip(img, 0.0, 1.0)


# ---- cardboard ------------------------------------------------------------
@dataclass(frozen=True)
class BoxPrint:
    """What is printed on a shipping box: ink colour, product code and markings."""

    code: str
    ink: RGB
    seed: int
    fragile: bool = True
    label: bool = True
    kraft: RGB = (0.70, 0.54, 0.36)


def dieline_layout(length: float, width: float, height: float) -> dict[str, tuple[float, float, float, float]]:
    """Regions of an unfolded regular slotted box, in metres: name -> (u0, v0, u1, v1).

    ``u`` runs around the box (front, right, back, left panels); ``v`` runs up
    (bottom flaps, panels, top flaps), so the dieline image is
    ``2 * (length + width)`` wide and ``height + width`` tall.
    """
    L, W, H = length, width, height
    x = [0.0, L, L + W, 2 * L + W, 2 * L + 2 * W]
    names = ("front", "right", "back", "left")
    regions: dict[str, tuple[float, float, float, float]] = {}
    for i, n in enumerate(names):
        regions[n] = (x[i], W / 2, x[i + 1], W / 2 + H)
        regions[f"{n}_top_flap"] = (x[i], W / 2 + H, x[i + 1], W + H)
        regions[f"{n}_bottom_flap"] = (x[i], 0.0, x[i + 1], W / 2)
    return regions


def _text(mask: np.ndarray, text: str, org: tuple[int, int], scale: float, thickness: int) -> None:
    cv2.putText(mask, text, org, cv2.FONT_HERSHEY_DUPLEX, scale, 255, thickness, cv2.LINE_AA)


def _fit_text(text: str, max_w: float, max_h: float) -> float:
    """The Hershey font scale at which ``text`` fits in ``max_w`` x ``max_h`` pixels."""
    (w, h), _ = cv2.getTextSize(text, cv2.FONT_HERSHEY_DUPLEX, 1.0, 2)
    return max(0.2, min(max_w / w, max_h / h))


def _arrow_pair(mask: np.ndarray, cx: int, cy: int, s: int) -> None:
    """The 'this side up' symbol: two upward arrows over a bar."""
    t = max(1, s // 7)
    for dx in (-s // 3, s // 3):
        x = cx + dx
        cv2.line(mask, (x, cy + s // 2), (x, cy - s // 3), 255, t, cv2.LINE_AA)
        pts = np.array([[x - s // 5, cy - s // 5], [x, cy - s // 2], [x + s // 5, cy - s // 5]], np.int32)
        cv2.polylines(mask, [pts], False, 255, t, cv2.LINE_AA)
    cv2.line(mask, (cx - s // 2, cy + s // 2 + t * 2), (cx + s // 2, cy + s // 2 + t * 2), 255, t, cv2.LINE_AA)


def _glass(mask: np.ndarray, cx: int, cy: int, s: int) -> None:
    """The 'fragile' symbol: a stemmed glass with a crack."""
    t = max(1, s // 9)
    bowl = np.array([[cx - s // 4, cy - s // 2], [cx + s // 4, cy - s // 2], [cx + s // 5, cy - s // 8],
                     [cx, cy], [cx - s // 5, cy - s // 8]], np.int32)
    cv2.polylines(mask, [bowl], True, 255, t, cv2.LINE_AA)
    cv2.line(mask, (cx, cy), (cx, cy + s // 3), 255, t, cv2.LINE_AA)
    cv2.line(mask, (cx - s // 5, cy + s // 3), (cx + s // 5, cy + s // 3), 255, t, cv2.LINE_AA)
    crack = np.array([[cx - s // 12, cy - s // 2], [cx + s // 20, cy - s // 3], [cx - s // 20, cy - s // 5]],
                     np.int32)
    cv2.polylines(mask, [crack], False, 255, max(1, t // 2), cv2.LINE_AA)


def _recycle(mask: np.ndarray, cx: int, cy: int, s: int) -> None:
    """A simplified recycling mark: three chasing arrows on a triangle."""
    t = max(1, s // 10)
    pts = [(cx + s / 2 * math.sin(a), cy - s / 2 * math.cos(a)) for a in (0.0, 2 * math.pi / 3, 4 * math.pi / 3)]
    for i in range(3):
        p, q = pts[i], pts[(i + 1) % 3]
        a = (int(p[0] + 0.12 * (q[0] - p[0])), int(p[1] + 0.12 * (q[1] - p[1])))
        b = (int(p[0] + 0.80 * (q[0] - p[0])), int(p[1] + 0.80 * (q[1] - p[1])))
        cv2.arrowedLine(mask, a, b, 255, t, cv2.LINE_AA, tipLength=0.35)


def _label(paper: np.ndarray, ink: np.ndarray, x0: int, y0: int, w: int, h: int, code: str, seed: int) -> None:
    """A white shipping label (into ``paper``) with a barcode and a line of text (into ``ink``)."""
    cv2.rectangle(paper, (x0, y0), (x0 + w, y0 + h), 255, -1)
    bars_top, bars_bottom = y0 + h // 8, y0 + int(h * 0.62)
    x, i = x0 + w // 10, 0
    while x < x0 + w - w // 10:
        bw = 1 + int(hash01(i, 7, seed) * 3)
        if hash01(i, 3, seed) > 0.45:
            cv2.rectangle(ink, (x, bars_top), (x + bw - 1, bars_bottom), 255, -1)
        x += bw
        i += 1
    _text(ink, code, (x0 + w // 10, y0 + int(h * 0.9)), max(0.25, h / 150.0), 1)


def _composite(img: np.ndarray, mask: np.ndarray, color: RGB, opacity: float) -> np.ndarray:
    a = (mask.astype(np.float64) / 255.0 * opacity)[..., None]
    return img * (1 - a) + np.asarray(color)[None, None, :] * a


def cardboard(length: float, width: float, height: float, print_: BoxPrint,
              px_per_m: float = 320.0) -> np.ndarray:
    """The printed dieline texture of a ``length`` x ``width`` x ``height`` m shipping box.

    Layout: :func:`dieline_layout`. Kraft board with fibre mottling, fold creases,
    a tape strip across the top seam, and the print of ``print_`` on the panels.
    """
    regions = dieline_layout(length, width, height)
    total_u, total_v = 2 * (length + width), height + width
    cols, rows = int(round(total_u * px_per_m)), int(round(total_v * px_per_m))
    size = (rows, cols)
    mottle = fbm(size, period=(max(2, rows // 60), max(2, cols // 60)), octaves=4, seed=print_.seed)
    fibres = value_noise(size, period=(rows // 3, cols // 3), seed=print_.seed + 1)
    flutes = 0.5 + 0.5 * np.sin(np.arange(cols) / max(1.0, px_per_m * 0.008) * 2 * math.pi)
    kraft = np.asarray(print_.kraft, dtype=np.float64)
    img = kraft[None, None, :] * (0.88 + 0.2 * mottle[..., None] + 0.05 * (fibres[..., None] - 0.5)
                                  + 0.012 * flutes[None, :, None])

    def px(u: float, v: float) -> tuple[int, int]:
        return int(round(u * px_per_m)), int(round((total_v - v) * px_per_m))   # row 0 is the top (v max)

    creases = np.zeros(size, np.uint8)
    for u0, v0, u1, v1 in regions.values():
        cv2.rectangle(creases, px(u0, v1), px(u1, v0), 255, 1, cv2.LINE_AA)
    img = _composite(img, creases, tuple(kraft * 0.72), 0.8)
    # the seam where the two major top flaps meet, covered by packing tape down onto the panels
    tape = np.zeros(size, np.uint8)
    tape_w = max(3, int(0.05 * px_per_m))
    for side in ("front", "back"):
        u0, _, u1, _ = regions[f"{side}_top_flap"]
        cx = (px(u0, 0)[0] + px(u1, 0)[0]) // 2
        cv2.rectangle(tape, (cx - tape_w // 2, px(0, width + height)[1]),
                      (cx + tape_w // 2, px(0, width / 2 + height - 0.06)[1]), 255, -1)
    img = _composite(img, tape, (0.80, 0.62, 0.38), 0.55)
    ink = np.zeros(size, np.uint8)
    paper = np.zeros(size, np.uint8)
    label_ink = np.zeros(size, np.uint8)
    for i, side in enumerate(("front", "back")):
        u0, v0, u1, v1 = regions[side]
        (x0, y1), (x1, y0) = px(u0, v0), px(u1, v1)
        w, h = x1 - x0, y1 - y0
        s = max(8, int(min(w, h) * 0.22))
        scale = _fit_text(print_.code, 0.58 * w, 0.22 * h)
        _text(ink, print_.code, (x0 + w // 14, y0 + int(h * 0.5)), scale, max(1, int(scale * 2.2)))
        _arrow_pair(ink, x1 - s, y0 + int(s * 0.9), s)
        if print_.fragile:
            _glass(ink, x1 - s, y1 - int(s * 0.9), s)
        _recycle(ink, x0 + int(s * 0.8), y1 - int(s * 0.8), int(s * 0.7))
        if i == 0:
            small = _fit_text("THIS SIDE UP", 0.4 * w, 0.1 * h)
            _text(ink, "THIS SIDE UP", (x0 + w // 14, y0 + int(h * 0.5) + int(h * 0.16)), small, 1)
    for i, side in enumerate(("right", "left")):
        u0, v0, u1, v1 = regions[side]
        (x0, y1), (x1, y0) = px(u0, v0), px(u1, v1)
        w, h = x1 - x0, y1 - y0
        s = max(8, int(min(w, h) * 0.2))
        if print_.label and i == 0:
            _label(paper, label_ink, x0 + w // 8, y0 + h // 6, int(w * 0.6), int(h * 0.33), print_.code,
                   print_.seed)
        _arrow_pair(ink, x0 + w // 2, y1 - s, s)
    wear = 0.75 + 0.25 * fbm(size, period=(max(2, rows // 30), max(2, cols // 30)), octaves=2, seed=print_.seed + 7)
    img = _composite(img, (ink * wear).astype(np.uint8), print_.ink, 0.92)
    img = _composite(img, paper, (0.94, 0.93, 0.89), 1.0)
    img = _composite(img, label_ink, (0.08, 0.08, 0.08), 1.0)
    return np.clip(img, 0.0, 1.0)


# ---- building surfaces ----------------------------------------------------
def concrete(size: tuple[int, int], seed: int, base: RGB = (0.56, 0.55, 0.52), joints: bool = True) -> np.ndarray:
    """Tileable polished warehouse concrete with stains, pits and saw-cut joints at the tile border."""
    rows, cols = size
    mottle = fbm(size, period=(3, 3), octaves=5, seed=seed)
    stains = _smoothstep(0.6, 0.85, fbm(size, period=(2, 2), octaves=3, seed=seed + 1))
    pits = speckle(size, seed + 2) > 0.998
    aggregate = value_noise(size, period=(rows // 3, cols // 3), seed=seed + 3)
    img = np.asarray(base)[None, None, :] * (0.86 + 0.24 * mottle[..., None] - 0.12 * stains[..., None]
                                             + 0.04 * (aggregate[..., None] - 0.5))
    img[pits] *= 0.55
    if joints:
        j = max(1, rows // 256)
        img[:j] *= 0.55
        img[:, :j] *= 0.55
    return np.clip(img, 0.0, 1.0)


def block_wall(size: tuple[int, int], seed: int, blocks: tuple[int, int] = (5, 5),
               paint: RGB = (0.78, 0.77, 0.72)) -> np.ndarray:
    """Tileable painted concrete-block wall: ``blocks`` = (rows, columns) of blocks per tile."""
    rows, cols = size
    img = np.asarray(paint)[None, None, :] * (0.93 + 0.1 * fbm(size, (4, 8), 4, seed)[..., None])
    by, bx = rows // blocks[0], cols // blocks[1]
    mortar = tuple(float(c) * 0.82 for c in paint)
    t = max(1, rows // 128)
    for r in range(blocks[0]):
        y = r * by
        img[y:y + t] = mortar
        offset = (bx // 2) * (r % 2)
        for c in range(blocks[1] + 1):
            x = (c * bx + offset) % cols
            img[y:y + by, x:x + t] = mortar
    return np.clip(img, 0.0, 1.0)


def painted_metal(size: tuple[int, int], seed: int, paint: RGB) -> np.ndarray:
    """Tileable powder-coated steel: a flat colour with faint orange peel and scuffs."""
    peel = fbm(size, period=(8, 8), octaves=3, seed=seed)
    scuff = _smoothstep(0.82, 0.95, fbm(size, period=(4, 16), octaves=3, seed=seed + 1))
    img = np.asarray(paint)[None, None, :] * (0.95 + 0.08 * peel[..., None])
    img = img * (1 - 0.25 * scuff[..., None]) + 0.25 * scuff[..., None] * 0.45
    return np.clip(img, 0.0, 1.0)


def safety_paint(size: tuple[int, int], seed: int, paint: RGB = (0.93, 0.74, 0.10)) -> np.ndarray:
    """Tileable worn floor-marking paint."""
    wear = _smoothstep(0.7, 0.9, fbm(size, period=(4, 4), octaves=4, seed=seed))
    img = _lerp(paint, (0.55, 0.53, 0.48), 0.6 * wear)
    return np.clip(img, 0.0, 1.0)


def grid(size: int, cells: int = 4, base: RGB = (0.62, 0.62, 0.64), line: RGB = (0.30, 0.30, 0.32),
         minor: RGB = (0.50, 0.50, 0.52)) -> np.ndarray:
    """One tile of a ground grid: a strong line on the tile border, ``cells`` lighter minor lines."""
    img = np.empty((size, size, 3), dtype=np.float64)
    img[:] = base
    step = size // cells
    t_minor = max(1, size // 256)
    t_major = max(2, size // 96)
    for k in range(1, cells):
        img[k * step:k * step + t_minor, :] = minor
        img[:, k * step:k * step + t_minor] = minor
    for sl in (slice(0, t_major // 2 + 1), slice(size - t_major // 2, size)):
        img[sl, :] = line
        img[:, sl] = line
    return img


def gravel(size: tuple[int, int], seed: int, base: RGB = (0.47, 0.45, 0.42), stones: int = 24) -> np.ndarray:
    """Tileable loose gravel: about ``stones`` pebbles across, each its own shade of ``base``, dark gaps between."""
    rows, cols = size
    cells = value_noise(size, period=(stones, stones * cols // rows), seed=seed)
    ridges = np.abs(fbm(size, period=(stones // 2, stones * cols // rows // 2), octaves=2, seed=seed + 1) - 0.5)
    gaps = _smoothstep(0.0, 0.06, ridges)                  # 0 in the cracks between pebbles
    grain = speckle(size, seed + 2)
    shade = 0.55 + 0.6 * cells + 0.08 * (grain - 0.5)
    hue = value_noise(size, period=(stones // 3 or 1, stones * cols // rows // 3 or 1), seed=seed + 3)
    img = np.asarray(base)[None, None, :] * shade[..., None] * (0.45 + 0.55 * gaps[..., None])
    img = img * (0.94 + 0.12 * np.stack([hue, 1 - hue, 0.5 + 0 * hue], -1))
    return np.clip(img, 0.0, 1.0)


def exposed_aggregate(size: tuple[int, int], seed: int) -> np.ndarray:
    """Tileable exposed-aggregate concrete: cement matrix with small pebbles showing through."""
    cement = concrete(size, seed, base=(0.62, 0.60, 0.56), joints=False)
    pebbles = gravel(size, seed + 10, base=(0.55, 0.50, 0.44), stones=40)
    mask = _smoothstep(0.45, 0.6, fbm(size, period=(24, 24), octaves=2, seed=seed + 20))[..., None]
    return np.clip(cement * (1 - mask) + pebbles * mask, 0.0, 1.0)


def roughness_map(size: tuple[int, int], seed: int, mean: float = 0.8, spread: float = 0.3) -> np.ndarray:
    """Tileable grey roughness in [0, 1] (the same value in R, G and B) around ``mean``."""
    r = np.clip(mean + spread * (fbm(size, period=(16, 16), octaves=4, seed=seed) - 0.5), 0.0, 1.0)
    return np.repeat(r[..., None], 3, axis=-1)


# ---- maps for physically based renderers -------------------------------------------------------------
_LUMA = np.array([0.2126, 0.7152, 0.0722])
MAP_SIZE = 256     # normal and ORM maps need less resolution than colour: at most this many pixels a side


def _map_source(rgb: np.ndarray) -> np.ndarray:
    """Luminance of ``rgb`` at most :data:`MAP_SIZE` a side (area-averaged: the image still tiles)."""
    lum = np.asarray(rgb, dtype=np.float64) @ _LUMA
    rows, cols = lum.shape
    k = max(rows, cols) / MAP_SIZE
    if k > 1:
        lum = cv2.resize(lum, (max(1, round(cols / k)), max(1, round(rows / k))), interpolation=cv2.INTER_AREA)
    return lum


def normal_map(rgb: np.ndarray, strength: float = 4.0) -> np.ndarray:
    """Tangent-space normal map (x along ``u``, y along ``v``, z out; stored as ``n * 0.5 + 0.5``) of the
    relief a colour texture suggests: darker is deeper (grain lines, joints, print, dents). Gradients wrap
    around the edges, so a tileable colour gives a tileable normal map."""
    h = _map_source(rgb) * strength
    du = (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) * 0.5
    d_row = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) * 0.5
    # row 0 is the v = 1 edge: along +v the row index falls
    n = np.stack([-du, d_row, np.ones_like(h)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return n * 0.5 + 0.5


def orm_map(rgb: np.ndarray, roughness: float, metallic: float = 0.0, roughness_spread: float = 0.2,
            occlusion_depth: float = 0.35) -> np.ndarray:
    """ORM map (R ambient occlusion, G perceptual roughness, B metallic) for a colour texture: cavities
    (darker than their surroundings) are occluded, and roughness varies around ``roughness`` with the colour
    (worn, lighter patches smoother)."""
    lum = _map_source(rgb)
    local = cv2.blur(np.pad(lum, 4, mode="wrap"), (9, 9))[4:-4, 4:-4]
    cavity = np.clip((local - lum) * 4.0, 0.0, 1.0)
    spread = lum - lum.mean()
    scale = max(float(np.abs(spread).max()), 1e-6)
    rough = np.clip(roughness - roughness_spread * spread / scale, 0.0, 1.0)
    return np.stack([1.0 - occlusion_depth * cavity, rough, np.full_like(lum, float(metallic))], axis=-1)


def write_pbr_maps(root: str, colour_rel: str, rgb: np.ndarray, roughness: float,
                   metallic: float = 0.0) -> tuple[str, str]:
    """Write the normal and ORM maps of the pack's colour texture ``colour_rel`` (``*_BaseColor.png`` ->
    ``*_Normal.png``, ``*_ORM.png`` beside it, under pack root ``root``); returns their pack-relative paths."""
    stem = colour_rel.rsplit("_BaseColor.png", 1)[0]
    normal_rel, orm_rel = f"{stem}_Normal.png", f"{stem}_ORM.png"
    write_png(os.path.join(root, normal_rel.lstrip("/")), normal_map(rgb))
    write_png(os.path.join(root, orm_rel.lstrip("/")), orm_map(rgb, roughness, metallic))
    return normal_rel, orm_rel


def write_jpg(path: str, rgb: np.ndarray, quality: int = 92) -> None:
    """Write a float RGB image in [0, 1] as a JPEG (parent folders are created)."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    if not cv2.imwrite(path, cv2.cvtColor(to_uint8(rgb), cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, quality]):
        raise OSError(f"could not write texture {path!r}")
