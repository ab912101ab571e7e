"""Isaac compat area: ``isaacsim.benchmark.services.validation.Validator``, benchmark images against golden ones.

A ``Validator`` captures one RGB frame of every render product with a writer
(``BasicWriter``), puts each product's files under the product's camera path
(``Replicator/cam_0_Xform/cam_0/rgb/rgb_0000.png``), and compares them with the
golden images of the same relative paths: both blurred with a Gaussian of
``blur_kernel`` pixels, then the mean absolute difference (0-255) against
``tolerance``. Failing images get a red difference overlay in a temporary
folder, named in the printout.

Differences: graphsdg's render products are not prims, so the products captured
are the live ones of the process (``root_prim_path`` is not searched) plus the
active viewport's, as Kit's viewport texture is always among Isaac's. Golden
images rendered by RTX differ from graphsdg's rasterised ones in shading
(docs/porting.md, Renderer), so the mean difference is the figure to report, not
the pass. A golden image that is a Git LFS pointer cannot be compared: the
validation raises ``OSError`` naming it. ``CoordinateValidator`` and the validator's timestamp matching
(``validate_frames_by_timestamp``) are not provided.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> from isaacsim.core.utils.extensions import enable_extension
    >>> enable_extension("isaacsim.benchmark.services")
    True
    >>> from isaacsim.benchmark.services.validation import Validator
    >>> Validator(tolerance=2.5).tolerance
    2.5
    >>> isaac.uninstall()
"""
from __future__ import annotations

import os
import re
import shutil
import tempfile
import types
from datetime import datetime
from typing import Any

import cv2

import graphsdg as rep
from graphsdg.compat import viewport
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.imaging.image_difference import blurred_mean_difference, difference_overlay
from graphsdg.imaging.image_files import read_image_array
from graphsdg.render.render_product import registry as render_products

DEFAULT_BLUR = 3
DEFAULT_TOLERANCE = 5.0
DEFAULT_TIMESTAMP_TOLERANCE_SEC = 0.01
TIMESTAMP_DECIMAL_PLACES = 6
_INDEX_NAME = re.compile(r"^(\w+)_(\d+)\.png$", re.IGNORECASE)
_TIMESTAMP_NAME = re.compile(r"^(\w+)_(\d+\.\d+)\.png$", re.IGNORECASE)


def _pngs(root: str) -> list[str]:
    return sorted(os.path.relpath(os.path.join(folder, f), root)
                  for folder, _, files in os.walk(root) for f in files if f.endswith(".png"))


class Validator(CompatObject):
    """Captures each render product's RGB image and compares it with golden images (module docstring)."""

    _compat_name = "isaacsim.benchmark.services.validation.Validator"

    def __init__(self, *, tolerance: float = DEFAULT_TOLERANCE, blur_kernel: int = DEFAULT_BLUR,
                 regenerate_golden: bool = False, output_root: str = "captures", golden_root: str = "golden_data",
                 auto_cleanup: bool = True) -> None:
        self.tolerance = float(tolerance)
        self.blur_kernel = int(blur_kernel)
        self.regenerate_golden = bool(regenerate_golden)
        self.output_root = os.fspath(output_root)
        self.golden_root = os.fspath(golden_root)
        self.auto_cleanup = bool(auto_cleanup)
        self.render_product_map: dict[str, str] = {}
        self._last_capture_path: str | None = None
        self._last_benchmark_name: str | None = None
        self._folders: dict[str, str] = {}   # render product path -> the writer's folder name for it

    def build_render_product_map(self, stage: Any, root_prim_path: str = "/Render/OmniverseKit/HydraTextures"
                                 ) -> dict[str, str]:
        """Render product path -> its camera's path without the leading ``/`` (``_1``, ``_2``... for repeats),
        for the active viewport's product and every live one."""
        viewport.get_active_viewport().render_product_path   # Kit's viewport texture is always there
        self.render_product_map.clear()
        self._folders.clear()
        for rp in render_products:
            if rp.destroyed:
                continue
            name = base = str(rp.camera).lstrip("/")
            index = 1
            while name in self.render_product_map.values():
                name, index = f"{base}_{index}", index + 1
            self.render_product_map[rp.path] = name
            self._folders[rp.path] = rp.name
        return self.render_product_map

    def rename_writer_folders(self, output_dir: str) -> None:
        """Move each product's writer folder (its render product's name) to its camera path."""
        for path, nice in self.render_product_map.items():
            old = os.path.join(output_dir, self._folders.get(path, path.rsplit("/", 1)[-1]))
            if os.path.isdir(old):
                new = os.path.join(output_dir, nice)
                os.makedirs(os.path.dirname(new), exist_ok=True)
                shutil.move(old, new)

    def capture_images(self, stage: Any, *, benchmark_name: str, output_root: str | None = None,
                       golden_root: str | None = None, writer_name: str = "BasicWriter") -> str:
        """Write one RGB frame of every mapped product (into the golden folder when regenerating); returns the
        folder."""
        if not self.render_product_map:
            self.build_render_product_map(stage)
        if output_root is not None:
            self.output_root = os.fspath(output_root)
        if golden_root is not None:
            self.golden_root = os.fspath(golden_root)
        if self.regenerate_golden:
            location = os.path.join(self.golden_root, benchmark_name)
            shutil.rmtree(location, ignore_errors=True)
        else:
            location = os.path.join(self.output_root, f"{benchmark_name}_{datetime.now():%Y%m%d_%H%M%S}")
        os.makedirs(location, exist_ok=True)
        writer = rep.WriterRegistry.get(writer_name)
        writer.initialize(output_dir=location, rgb=True)
        paths = list(self.render_product_map)
        writer.attach(paths)
        rep.orchestrator.step()
        writer.detach()
        rep.orchestrator.wait_until_complete()
        if len(paths) == 1:   # one product: the writer puts its folders at the top; give them the product's folder
            folder = os.path.join(location, self._folders.get(paths[0], "rp"))
            os.makedirs(folder, exist_ok=True)
            for entry in os.listdir(location):
                if entry != os.path.basename(folder) and os.path.isdir(os.path.join(location, entry)):
                    shutil.move(os.path.join(location, entry), folder)
        self.rename_writer_folders(location)
        if self.regenerate_golden:
            print(f"\nGolden images regenerated - check them by eye:\n{location}")
        self._last_capture_path, self._last_benchmark_name = location, benchmark_name
        return location

    def _compare(self, captured: str, golden: str) -> tuple[bool, float | None, str]:
        """(passed, mean difference or None, reason) for one pair of image files."""
        cap, gold = read_image_array(captured, False), read_image_array(golden, False)
        if cap.shape != gold.shape:
            return False, None, f"shape mismatch {cap.shape} vs {gold.shape}"
        mean, diff = blurred_mean_difference(cap, gold, self.blur_kernel)
        if mean <= self.tolerance:
            return True, mean, ""
        out = os.path.join(tempfile.mkdtemp(prefix="diff_"), f"diff_{os.path.basename(captured)}")
        cv2.imwrite(out, cv2.cvtColor(difference_overlay(cap, diff), cv2.COLOR_RGB2BGR))
        return False, mean, f"mean_diff={mean:.2f} (tolerance={self.tolerance}) diff image: {out}"

    def validate_images(self, captured_dir: str | None = None, golden_dir: str | None = None) -> bool:
        """Compare the capture's images with the golden ones of the same relative paths; True when every image
        of every product is within tolerance.

        Raises:
            ValueError: no capture was made and none is given.
            OSError: an image cannot be read (a Git LFS pointer, a broken file).
        """
        captured_dir = captured_dir or self._last_capture_path
        if captured_dir is None:
            raise ValueError("captured_dir not specified and no capture has been performed yet")
        self._last_capture_path = captured_dir
        if golden_dir is None:
            golden_dir = os.path.join(self.golden_root, self._last_benchmark_name or "")
        print("\nValidating Images\n" + "-" * 40)
        passed = True
        for nice in self.render_product_map.values():
            cap_root, gold_root = os.path.join(captured_dir, nice), os.path.join(golden_dir, nice)
            if not (os.path.isdir(cap_root) and os.path.isdir(gold_root)):
                print(f"Missing directories for render product '{nice}'\nCapture dir: {cap_root}\n"
                      f"Golden dir:  {gold_root}")
                passed = False
                continue
            common = sorted(set(_pngs(cap_root)) & set(_pngs(gold_root)))
            if not common:
                print(f"No common PNG files for render product {nice}; skipping")
            for rel in common:
                ok, mean, reason = self._compare(os.path.join(cap_root, rel), os.path.join(gold_root, rel))
                print(f"[{'PASS' if ok else 'FAIL'}] {nice}/{rel}: "
                      f"{reason or f'mean_diff={mean:.2f} (tolerance={self.tolerance})'}")
                passed = passed and ok
        print(f"\nValidation {'passed for all images' if passed else 'failed for some images'}.\n")
        if self.auto_cleanup:
            self.clear_last_capture()
        return passed

    def _product_names(self, *roots: str) -> list[str]:
        if self.render_product_map:
            return [n for n in sorted(self.render_product_map.values())
                    if all(os.path.isdir(os.path.join(r, n)) for r in roots)]
        common = None
        for root in roots:
            found = {d for d in os.listdir(root) if os.path.isdir(os.path.join(root, d))}
            common = found if common is None else common & found
        return sorted(common or ())

    def validate_frames(self, captured_run_dir: str, golden_benchmark_dir: str) -> dict:
        """Compare every frame of every product present in both folders: ``{"render_products": {name: {"passed",
        "total_files", "failures", "frame_results"}}, "total", "passed", "failed"}`` (products)."""
        for folder in (captured_run_dir, golden_benchmark_dir):
            if not os.path.isdir(folder):
                raise ValueError(f"directory does not exist: {folder}")
        results = {}
        for name in self._product_names(captured_run_dir, golden_benchmark_dir):
            cap_root, gold_root = os.path.join(captured_run_dir, name), os.path.join(golden_benchmark_dir, name)
            common = sorted(set(_pngs(cap_root)) & set(_pngs(gold_root)))
            if not common:
                results[name] = {"passed": False, "reason": "no_common_files", "failures": []}
                continue
            frames, failures = [], []
            for rel in common:
                ok, mean, reason = self._compare(os.path.join(cap_root, rel), os.path.join(gold_root, rel))
                frame: dict[str, Any] = {"file": rel, "passed": ok}
                frame.update({"mean_diff": mean} if mean is not None else {"reason": reason})
                frames.append(frame)
                if not ok:
                    failures.append(f"{rel}: {reason}")
            results[name] = {"passed": not failures, "total_files": len(common), "failures": failures,
                             "frame_results": frames}
        passed = sum(1 for r in results.values() if r["passed"])
        return {"render_products": results, "total": len(results), "passed": passed, "failed": len(results) - passed}

    def clear_last_capture(self) -> None:
        """Delete the last capture folder."""
        if self._last_capture_path and os.path.isdir(self._last_capture_path):
            shutil.rmtree(self._last_capture_path)
        self._last_capture_path = None

    @staticmethod
    def parse_timestamp_from_basename(basename: str) -> float | None:
        """The simulation time in a name like ``rgb_12.500000.png``, or None."""
        match = _TIMESTAMP_NAME.match(basename)
        return float(match.group(2)) if match else None

    def rename_captured_frames_to_timestamps(self, run_dir: str, frame_timestamps: list[float]) -> None:
        """Rename ``<prefix>_<index>.png`` files under ``run_dir`` to ``<prefix>_<time>.png`` (six decimals)."""
        for folder, _, files in os.walk(run_dir, topdown=False):
            for name in files:
                match = _INDEX_NAME.match(name)
                if match is None or not 0 <= int(match.group(2)) < len(frame_timestamps):
                    continue
                stamp = frame_timestamps[int(match.group(2))]
                os.rename(os.path.join(folder, name),
                          os.path.join(folder, f"{match.group(1)}_{stamp:.{TIMESTAMP_DECIMAL_PLACES}f}.png"))

    def run(self, stage: Any, *, benchmark_name: str) -> bool:
        """Map the products, capture, and validate (True when regenerating the golden images)."""
        self.build_render_product_map(stage)
        self.capture_images(stage, benchmark_name=benchmark_name)
        return True if self.regenerate_golden else self.validate_images()

    @classmethod
    def from_cli_args(cls, args: Any, *, auto_cleanup: bool | None = None) -> "Validator":
        """A validator from an argparse namespace's ``tolerance``, ``blur_kernel``, ``regenerate_golden``,
        ``output_dir`` and ``golden_dir`` (relative folders from the working folder)."""
        out_dir = os.path.abspath(getattr(args, "output_dir", "captures"))
        gold_dir = os.path.abspath(getattr(args, "golden_dir", "golden_data"))
        return cls(tolerance=getattr(args, "tolerance", DEFAULT_TOLERANCE),
                   blur_kernel=getattr(args, "blur_kernel", DEFAULT_BLUR),
                   regenerate_golden=getattr(args, "regenerate_golden", False), output_root=out_dir,
                   golden_root=gold_dir, auto_cleanup=True if auto_cleanup is None else auto_cleanup)


def modules() -> list[types.ModuleType]:
    """``isaacsim.benchmark.services.validation``."""
    return [CompatModule("isaacsim.benchmark.services.validation", Validator=Validator, DEFAULT_BLUR=DEFAULT_BLUR,
                         DEFAULT_TOLERANCE=DEFAULT_TOLERANCE,
                         DEFAULT_TIMESTAMP_TOLERANCE_SEC=DEFAULT_TIMESTAMP_TOLERANCE_SEC,
                         TIMESTAMP_DECIMAL_PLACES=TIMESTAMP_DECIMAL_PLACES,
                         hint="CoordinateValidator (robot pose statistics against historical runs) is not provided.")]
