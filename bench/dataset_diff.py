"""How two BasicWriter datasets of the same job differ: files, labels, boxes, depth, colour.

Used to measure what is reproducible across machines (docs/reproducibility.md):
write the same job with the same seed on two machines (or GL drivers), then

    python bench/dataset_diff.py DATASET_A DATASET_B

prints, per kind of file, how many are byte-identical, and at the pixel level:
segmentation pixels whose label differs, whether box rows are equal, depth
differences in metres, and rgb differences in 8-bit levels.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import re

import cv2
import numpy as np


def _digest(path: str) -> str:
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def _kind(name: str) -> str:
    return re.sub(r"_\d+(\.\w+)$", r"\1", name)


def compare(a: str, b: str) -> dict:
    """Per-kind counts and pixel-level differences between datasets ``a`` and ``b``."""
    names = sorted(os.listdir(a))
    if names != sorted(os.listdir(b)):
        raise ValueError(f"the datasets hold different files: {sorted(set(names) ^ set(os.listdir(b)))}")
    kinds: dict[str, list[int]] = {}
    report: dict = {"files": len(names), "identical": 0, "kinds": kinds, "segmentation_px": [], "boxes_equal": [],
                    "depth_max_m": [], "depth_median_m": [], "rgb_px_pct": [], "rgb_px_over8_pct": [],
                    "rgb_max": 0, "rgb_mean": []}
    for name in names:
        pa, pb = os.path.join(a, name), os.path.join(b, name)
        same = _digest(pa) == _digest(pb)
        report["identical"] += same
        kinds.setdefault(_kind(name), [0, 0])[0 if same else 1] += 1
        if name.startswith("rgb_"):
            x, y = cv2.imread(pa).astype(int), cv2.imread(pb).astype(int)
            d = np.abs(x - y).max(axis=2)
            report["rgb_px_pct"].append(100 * float((d > 0).mean()))
            report["rgb_px_over8_pct"].append(100 * float((d > 8).mean()))
            report["rgb_max"] = max(report["rgb_max"], int(d.max()))
            report["rgb_mean"].append(float(np.abs(x - y).mean()))
        elif name.startswith("semantic_segmentation_") and name.endswith(".png"):
            x, y = cv2.imread(pa, cv2.IMREAD_UNCHANGED), cv2.imread(pb, cv2.IMREAD_UNCHANGED)
            report["segmentation_px"].append(int(np.any(x != y, axis=-1).sum() if x.ndim == 3 else (x != y).sum()))
        elif name.startswith("distance_to") and name.endswith(".npy"):
            x, y = np.load(pa), np.load(pb)
            both = np.isfinite(x) & np.isfinite(y)
            d = np.abs(x[both] - y[both])
            report["depth_max_m"].append(float(d.max()) if d.size else 0.0)
            report["depth_median_m"].append(float(np.median(d)) if d.size else 0.0)
            report.setdefault("depth_inf_mismatch", 0)
            report["depth_inf_mismatch"] += int((np.isfinite(x) != np.isfinite(y)).sum())
        elif re.match(r"bounding_box_2d_\w+?_\d+\.npy$", name):
            report["boxes_equal"].append(bool(np.array_equal(np.load(pa), np.load(pb))))
    return report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("a")
    parser.add_argument("b")
    args = parser.parse_args()
    r = compare(args.a, args.b)
    print(f"{r['identical']}/{r['files']} files byte-identical")
    for kind, (same, diff) in sorted(r["kinds"].items()):
        print(f"  {kind}: {same} identical, {diff} different")
    if r["segmentation_px"]:
        print(f"semantic segmentation pixels with another label, per frame: {r['segmentation_px']}")
    if r["boxes_equal"]:
        print(f"2D box rows equal: {sum(r['boxes_equal'])}/{len(r['boxes_equal'])} frames")
    if r["depth_max_m"]:
        print(f"depth |difference|: median {max(r['depth_median_m']):.2g} m, max per frame "
              f"{[round(v, 4) for v in r['depth_max_m']]} m, background mismatches {r.get('depth_inf_mismatch', 0)}")
    if r["rgb_px_pct"]:
        print(f"rgb: pixels that differ {[round(v, 2) for v in r['rgb_px_pct']]} %, by more than 8 levels "
              f"{[round(v, 2) for v in r['rgb_px_over8_pct']]} %, largest {r['rgb_max']}, "
              f"mean |difference| {np.mean(r['rgb_mean']):.3f} levels")


if __name__ == "__main__":
    main()
