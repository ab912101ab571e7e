"""Isaac compat area: ``isaacsim.test.utils.image_comparison`` and ``image_io``, image tests' numbers and files.

Comparison (``image_comparison``) follows Isaac Sim's contracts:

* ``compute_difference_metrics(golden, test, *, percentiles, allclose_rtol, allclose_atol,
  ignore_blank_pixels)``: ``allclose``, ``rtol``, ``atol``, ``mean_abs``, ``max_abs``,
  ``rmse``, ``percentiles`` (:func:`graphsdg.imaging.image_difference.difference_metrics`);
* ``compare_arrays_within_tolerances(golden, test, allclose_rtol, allclose_atol,
  mean_tolerance, max_tolerance, absolute_tolerance, percentile_tolerance, rmse_tolerance,
  print_all_stats)``: ``{"passed", "criteria", "metrics", "thresholds"}``; the test array is
  cast to the golden's dtype first; ``allclose`` is a criterion unless both tolerances
  are None; ``percentile_tolerance`` is ``(percentile, tolerance)``;
* ``compare_images_within_tolerances(golden_file_path, test_file_path, ...)``: the same on
  two image files (a single channel squeezed; RGB against RGBA compares RGB);
* ``compare_images_in_directories(golden_dir, test_dir, path_pattern, ...)``: every file
  name (matching the regular expression) present in both folders, with
  ``all_passed`` only when every pair passed and both folders hold the same names.

Files (``image_io``): ``save_rgb_image`` (a PNG is written RGBA, alpha 255 added to RGB;
RGBA to JPEG raises ``ValueError``), ``save_depth_image`` (``.tif``/``.tiff``: float32,
exact; other formats: 8-bit grey, values in [0, 1] scaled by 255 or, with
``normalize``, the finite range stretched to 0-255), ``save_annotator_data``,
``read_image_as_array``. A golden image that is a Git LFS pointer raises ``OSError``
naming it.

Example:
    >>> import numpy as np
    >>> result = compare_arrays_within_tolerances(np.zeros((2, 2), np.uint8), np.ones((2, 2), np.uint8),
    ...                                           mean_tolerance=1.0)
    >>> result["passed"], result["criteria"]
    (False, {'allclose': False, 'mean': True})
"""
from __future__ import annotations

import json
import os
import re
import types
from typing import Any

import numpy as np
from PIL import Image

from graphsdg.compat.modules import CompatModule
from graphsdg.imaging.image_difference import difference_metrics
from graphsdg.imaging.image_files import read_image_array

DEFAULT_PERCENTILES = (50, 75, 90, 95, 99)


# ---- comparison ---------------------------------------------------------------------------------
def compute_difference_metrics(golden_array: np.ndarray, test_array: np.ndarray, *,
                               percentiles: list[float] | tuple[float, ...] = DEFAULT_PERCENTILES,
                               allclose_rtol: float = 1e-05, allclose_atol: float = 1e-08,
                               ignore_blank_pixels: bool = False) -> dict[str, object]:
    """Difference metrics of two arrays of one shape (``ValueError`` when the shapes differ)."""
    return difference_metrics(golden_array, test_array, percentiles=percentiles, allclose_rtol=allclose_rtol,
                              allclose_atol=allclose_atol, ignore_blank_pixels=ignore_blank_pixels)


def print_difference_statistics(metrics: dict[str, object]) -> None:
    """Print the metrics of :func:`compute_difference_metrics`."""
    header = "=== All metrics ==="
    print(f"\n{header}")
    print(f"Allclose (rtol={metrics['rtol']}, atol={metrics['atol']}): {'PASS' if metrics['allclose'] else 'FAIL'}")
    print(f"Mean absolute difference: {metrics['mean_abs']:.3f}")
    print(f"Max absolute difference: {metrics['max_abs']:.3f}")
    print(f"Root Mean Square Error (RMSE): {metrics['rmse']:.3f}")
    for p, value in sorted(dict(metrics.get("percentiles", {})).items()):
        print(f"{int(p)}th percentile of differences: {value:.3f}")
    print("=" * len(header) + "\n")


def _percentile_tolerance(value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    if isinstance(value, (tuple, list)) and len(value) == 2:
        return float(value[0]), float(value[1])
    raise ValueError(f"percentile_tolerance must be a tuple of (percentile, tolerance), got {value!r}")


def compare_arrays_within_tolerances(golden_array: np.ndarray, test_array: np.ndarray,
                                     allclose_rtol: float | None = 1e-05, allclose_atol: float | None = 1e-08,
                                     mean_tolerance: float | None = None, max_tolerance: float | None = None,
                                     absolute_tolerance: float | None = None,
                                     percentile_tolerance: tuple | None = None, rmse_tolerance: float | None = None,
                                     print_all_stats: bool = False) -> dict[str, object]:
    """Whether two arrays agree by every criterion asked for: ``{"passed", "criteria", "metrics", "thresholds"}``.

    Raises:
        ValueError: the shapes differ, or ``percentile_tolerance`` is not a pair.
    """
    golden_array, test_array = np.asarray(golden_array), np.asarray(test_array)
    if golden_array.shape != test_array.shape:
        raise ValueError(f"Image shapes do not match: golden {golden_array.shape} vs test {test_array.shape}")
    if golden_array.dtype != test_array.dtype:
        test_array = test_array.astype(golden_array.dtype)
    percentile = _percentile_tolerance(percentile_tolerance)
    rtol = 1e-05 if allclose_rtol is None else allclose_rtol
    atol = 1e-08 if allclose_atol is None else allclose_atol
    wanted = sorted(set(DEFAULT_PERCENTILES) | ({percentile[0]} if percentile else set()))
    metrics = compute_difference_metrics(golden_array, test_array, percentiles=wanted, allclose_rtol=rtol,
                                         allclose_atol=atol)
    criteria: dict[str, bool] = {}
    thresholds: dict[str, object] = {"rtol": float(rtol), "atol": float(atol)}
    if not (allclose_rtol is None and allclose_atol is None):
        criteria["allclose"] = bool(metrics["allclose"])
    for name, tolerance, value in (("mean", mean_tolerance, metrics["mean_abs"]),
                                   ("max", max_tolerance, metrics["max_abs"]),
                                   ("absolute", absolute_tolerance, metrics["max_abs"])):
        if tolerance is not None:
            criteria[name] = float(value) <= float(tolerance)
            thresholds[f"{name}_tolerance"] = float(tolerance)
    if percentile is not None:
        criteria[f"percentile_{int(percentile[0])}"] = float(metrics["percentiles"][percentile[0]]) <= percentile[1]
        thresholds["percentile_tolerance"] = percentile
    if rmse_tolerance is not None:
        criteria["rmse"] = float(metrics["rmse"]) <= float(rmse_tolerance)
        thresholds["rmse_tolerance"] = float(rmse_tolerance)
    if print_all_stats:
        print_difference_statistics(metrics)
    return {"passed": all(criteria.values()), "criteria": criteria, "metrics": metrics, "thresholds": thresholds}


def _comparable(golden: np.ndarray, test: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """RGB against RGBA of the same size: drop the alpha channel."""
    if golden.ndim == test.ndim == 3 and golden.shape[:2] == test.shape[:2] \
            and {golden.shape[2], test.shape[2]} == {3, 4}:
        return golden[:, :, :3], test[:, :, :3]
    return golden, test


def compare_images_within_tolerances(golden_file_path: str, test_file_path: str,
                                     allclose_rtol: float | None = 1e-05, allclose_atol: float | None = 1e-08,
                                     mean_tolerance: float | None = None, max_tolerance: float | None = None,
                                     absolute_tolerance: float | None = None,
                                     percentile_tolerance: tuple | None = None, rmse_tolerance: float | None = None,
                                     print_all_stats: bool = False) -> dict[str, object]:
    """:func:`compare_arrays_within_tolerances` on two image files.

    Raises:
        FileNotFoundError: a file is missing.
        OSError: a file is not an image (a Git LFS pointer says so).
    """
    for path, role in ((golden_file_path, "Golden"), (test_file_path, "Test")):
        if not os.path.exists(path):
            raise FileNotFoundError(f"{role} image file not found: {path}")
    golden, test = _comparable(read_image_array(golden_file_path), read_image_array(test_file_path))
    return compare_arrays_within_tolerances(golden, test, allclose_rtol, allclose_atol, mean_tolerance,
                                            max_tolerance, absolute_tolerance, percentile_tolerance,
                                            rmse_tolerance, print_all_stats)


def _describe_tolerances(**tolerances: Any) -> str:
    named = [f"{k}={v}" for k, v in tolerances.items() if v is not None and k not in ("rtol", "atol")]
    if not named and tolerances["rtol"] is not None and tolerances["atol"] is not None:
        named = [f"rtol={tolerances['rtol']}, atol={tolerances['atol']}"]
    return ", ".join(named) or "default allclose"


def compare_images_in_directories(golden_dir: str, test_dir: str, path_pattern: str | None = None,
                                  allclose_rtol: float | None = 1e-05, allclose_atol: float | None = 1e-08,
                                  mean_tolerance: float | None = None, max_tolerance: float | None = None,
                                  absolute_tolerance: float | None = None, percentile_tolerance: tuple | None = None,
                                  rmse_tolerance: float | None = None, print_all_stats: bool = False,
                                  print_per_file_results: bool = True) -> dict[str, object]:
    """Compare the same-named files of two folders (names matching ``path_pattern``, a regular expression).

    Returns ``all_passed``, ``file_results``, ``passed_count``, ``failed_count``, ``golden_files``,
    ``test_files``, ``file_list_match``, ``golden_only_files``, ``test_only_files``.

    Raises:
        FileNotFoundError: a folder is missing.
    """
    for folder, role in ((golden_dir, "Golden"), (test_dir, "Test")):
        if not os.path.exists(folder):
            raise FileNotFoundError(f"{role} directory not found: {folder}")
    pattern = re.compile(path_pattern) if path_pattern is not None else None
    golden_files = sorted(f for f in os.listdir(golden_dir) if pattern is None or pattern.search(f))
    test_files = sorted(f for f in os.listdir(test_dir) if pattern is None or pattern.search(f))
    golden_only, test_only = sorted(set(golden_files) - set(test_files)), sorted(set(test_files) - set(golden_files))
    which = f"pattern '{path_pattern}'" if path_pattern is not None else "all files"
    if golden_files != test_files:
        print(f"WARNING: File lists do not match for {which}: only in golden {golden_only}, only in test {test_only}")
    common = sorted(set(golden_files) & set(test_files))
    summary: dict[str, object] = {"all_passed": False, "file_results": {}, "passed_count": 0, "failed_count": 0,
                                  "golden_files": golden_files, "test_files": test_files,
                                  "file_list_match": golden_files == test_files, "golden_only_files": golden_only,
                                  "test_only_files": test_only}
    if not common:
        print(f"No common files found matching {which} in both directories.")
        return summary
    if print_per_file_results:
        print(f"Comparing images matching {which} with " + _describe_tolerances(
            mean_tolerance=mean_tolerance, max_tolerance=max_tolerance, absolute_tolerance=absolute_tolerance,
            percentile_tolerance=percentile_tolerance, rmse_tolerance=rmse_tolerance, rtol=allclose_rtol,
            atol=allclose_atol) + f"\n  Golden dir: {golden_dir}\n  Test dir:   {test_dir}")
    results: dict[str, dict[str, object]] = {}
    for name in common:
        result = compare_images_within_tolerances(os.path.join(golden_dir, name), os.path.join(test_dir, name),
                                                  allclose_rtol, allclose_atol, mean_tolerance, max_tolerance,
                                                  absolute_tolerance, percentile_tolerance, rmse_tolerance,
                                                  print_all_stats)
        results[name] = result
        if print_per_file_results:
            m = result["metrics"]
            print(f"\t'{name}': {'PASSED' if result['passed'] else 'FAILED'} (mean_diff={m['mean_abs']:.3f}, "
                  f"max_diff={m['max_abs']:.3f}, rmse={m['rmse']:.3f})")
    passed = sum(1 for r in results.values() if r["passed"])
    summary.update(file_results=results, passed_count=passed, failed_count=len(results) - passed,
                   all_passed=passed == len(results) and bool(summary["file_list_match"]))
    return summary


# ---- files --------------------------------------------------------------------------------------
def save_rgb_image(rgb_data: np.ndarray, out_dir: str, file_name: str) -> None:
    """Write RGB(A) pixels to ``out_dir/file_name`` (a PNG always RGBA).

    Raises:
        ValueError: RGBA pixels to a JPEG file.
    """
    os.makedirs(out_dir, exist_ok=True)
    rgb_data = np.asarray(rgb_data)
    has_alpha = rgb_data.ndim == 3 and rgb_data.shape[2] == 4
    ext = os.path.splitext(file_name)[1].lower()
    if has_alpha and ext in (".jpg", ".jpeg"):
        raise ValueError(f"Cannot save RGBA data (4 channels) as {ext.upper()}: JPEG format doesn't support "
                         f"transparency. Use PNG format instead.")
    image = Image.fromarray(rgb_data, mode="RGBA") if has_alpha else Image.fromarray(rgb_data)
    if not has_alpha and ext == ".png":
        image = image.convert("RGBA")
    path = os.path.join(out_dir, file_name)
    image.save(path)
    print(f"Saved image to {path} with shape {rgb_data.shape}")


def _depth_to_grey(depth: np.ndarray, normalize: bool) -> np.ndarray:
    if not normalize:
        if depth.dtype in (np.float32, np.float64):
            return (np.clip(depth, 0, 1) * 255).astype(np.uint8)
        return depth.astype(np.uint8)
    valid = np.isfinite(depth)
    if not valid.any():
        return np.full(depth.shape, 128, np.uint8)
    low, high = float(depth[valid].min()), float(depth[valid].max())
    if high <= low:
        return np.full(depth.shape, 128, np.uint8)
    clean = np.where(valid, depth, low)
    return ((clean - low) / (high - low) * 255).astype(np.uint8)


def save_depth_image(depth_data: np.ndarray, out_dir: str, file_name: str, normalize: bool = False) -> None:
    """Write depth as float32 TIFF (``.tif``/``.tiff``, exact, NaN and inf kept) or as an 8-bit grey image.

    Raises:
        ValueError: depth is not H x W or H x W x 1.
    """
    depth = np.asarray(depth_data)
    if depth.ndim == 3 and depth.shape[2] == 1:
        depth = depth[:, :, 0]
    elif depth.ndim != 2:
        raise ValueError(f"Expected depth data with shape (H, W) or (H, W, 1), got {depth.shape}")
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, file_name)
    if os.path.splitext(file_name)[1].lower() in (".tif", ".tiff"):
        if normalize:
            print("Warning: TIFF format requested with normalize=True; TIFF keeps metric float32 depth, so "
                  "normalize is ignored.")
        image = Image.fromarray(depth.astype(np.float32), mode="F")
        try:
            image.save(path, compression="tiff_deflate")
        except (OSError, ValueError):   # PIL built without libtiff's deflate: uncompressed, still exact
            image.save(path)
        print(f"Saved metric depth (float32 TIFF) to {path}")
        return
    Image.fromarray(_depth_to_grey(depth, normalize), mode="L").save(path)
    print(f"Saved image as grayscale depth to {path}")


def save_annotator_data(data: Any, output_path: str) -> None:
    """Write an annotator's output: ``{"data": array, ...}`` and arrays as ``.npy`` (an array to a ``.png`` path
    as an image), other dictionaries as JSON of their values' reprs (``.json`` beside ``output_path``)."""
    folder = os.path.dirname(output_path) or "."
    os.makedirs(folder, exist_ok=True)
    if isinstance(data, dict):
        if hasattr(data.get("data"), "shape"):
            np.save(output_path, data["data"])
            print(f"Saved data['data'] array: {output_path} (shape: {data['data'].shape})")
        else:
            json_path = os.path.splitext(output_path)[0] + ".json"
            with open(json_path, "w", encoding="utf-8") as f:
                json.dump({k: repr(v) for k, v in data.items()}, f, indent=2)
            print(f"Saved dict data: {json_path}")
    elif hasattr(data, "shape"):
        if output_path.endswith(".png"):
            save_rgb_image(data, folder, os.path.basename(output_path))
        else:
            np.save(output_path, data)
            print(f"Saved array: {output_path} (shape: {data.shape}, dtype: {data.dtype})")
    else:
        print(f"Annotator returned: {type(data).__name__}: {repr(data)[:200]}")


def read_image_as_array(file_path: str, squeeze_singleton_channel: bool = True) -> np.ndarray:
    """The image at ``file_path`` as an array (``FileNotFoundError`` / ``OSError`` when it cannot be read)."""
    return read_image_array(file_path, squeeze_singleton_channel)


def modules() -> list[types.ModuleType]:
    """``isaacsim.test.utils.image_comparison`` and ``image_io``, and their names on ``isaacsim.test.utils``."""
    comparison = dict(compute_difference_metrics=compute_difference_metrics,
                      print_difference_statistics=print_difference_statistics,
                      compare_arrays_within_tolerances=compare_arrays_within_tolerances,
                      compare_images_within_tolerances=compare_images_within_tolerances,
                      compare_images_in_directories=compare_images_in_directories)
    files = dict(save_rgb_image=save_rgb_image, save_depth_image=save_depth_image,
                 save_annotator_data=save_annotator_data, read_image_as_array=read_image_as_array)
    return [CompatModule("isaacsim.test.utils.image_comparison", **comparison),
            CompatModule("isaacsim.test.utils.image_io", **files),
            CompatModule("isaacsim.test.utils", **comparison, **files)]
