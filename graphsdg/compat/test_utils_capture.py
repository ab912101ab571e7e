"""Isaac compat area: ``isaacsim.test.utils.image_capture``, ``timed_async_test`` and ``stage_utils``.

* ``capture_annotator_data_async(annotator_name, camera_position=(5, 5, 5), camera_look_at=(0, 0, 0),
  resolution=(1280, 720), camera_prim_path=None, render_product=None, do_array_copy=True)``:
  attaches the annotator to ``render_product`` (or to a temporary render product of
  ``camera_prim_path``, or of a temporary camera at ``camera_position`` looking at
  ``camera_look_at``), steps once, and returns its data; what it made is removed
  again. ``capture_rgb_data_async``, ``capture_depth_data_async`` (``distance_to_camera``
  or ``distance_to_image_plane``), ``capture_viewport_annotator_data_async`` and
  ``capture_viewport_screenshot_async`` (the active viewport's render product) build on it;
* ``capture_frame_sequence_async(output_dir, num_frames, updates_per_frame, mode, ...)`` in
  ``"viewport"`` and ``"replicator"`` modes (``"app"`` captures Kit's window, which graphsdg
  does not have: ``CompatError``, as ``capture_app_screenshot_async``);
* ``TimedAsyncTestCase``: an ``omni.kit.test.AsyncTestCase`` printing each test's time;
* ``poll_until``, ``wait_for_prim``, ``wait_for_stage_prims`` (and ``_async``): app updates
  until a condition holds.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> from isaacsim.core.utils.extensions import enable_extension
    >>> enable_extension("isaacsim.test.utils")
    True
    >>> from isaacsim.test.utils.stage_utils import poll_until
    >>> poll_until(lambda: True, timeout_frames=4, poll_steps=2)
    2
    >>> isaac.uninstall()
"""
from __future__ import annotations

import gc
import logging
import os
import time
import types
from typing import Any, Callable

import numpy as np

import graphsdg as rep
from graphsdg import assets
from graphsdg.compat import kit, viewport
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.compat.test_utils_images import save_rgb_image
from graphsdg.stage.context import get_stage

log = logging.getLogger("graphsdg.compat")

DEPTH_ANNOTATORS = ("distance_to_camera", "distance_to_image_plane")
NO_APP_WINDOW = ("graphsdg has no application window (Kit's swapchain capture): capture the viewport "
                 "(capture_viewport_screenshot_async) or a render product instead")


# ---- capture ------------------------------------------------------------------------------------
async def capture_annotator_data_async(annotator_name: str, camera_position: tuple[float, float, float] = (5, 5, 5),
                                       camera_look_at: tuple[float, float, float] = (0, 0, 0),
                                       resolution: tuple[int, int] = (1280, 720), camera_prim_path: str | None = None,
                                       render_product: Any = None, do_array_copy: bool = True) -> Any:
    """One step's data of ``annotator_name`` (see the module docstring for the camera it uses)."""
    temp_camera = None
    temp_product = None
    if render_product is None:
        camera_path = camera_prim_path
        if camera_path is None:
            temp_camera = rep.functional.create.camera(position=camera_position, look_at=camera_look_at)
            camera_path = str(temp_camera.GetPath())
        temp_product = rep.create.render_product(str(camera_path), tuple(resolution))
        render_product = temp_product
    annotator = rep.AnnotatorRegistry.get_annotator(annotator_name)
    annotator.attach(render_product)
    try:
        await rep.orchestrator.step_async()
        data = annotator.get_data(do_array_copy=do_array_copy)
    finally:
        annotator.detach()
        if temp_product is not None:
            temp_product.destroy()
        if temp_camera is not None:
            get_stage().RemovePrim(temp_camera.GetPath())
    return data


async def capture_rgb_data_async(camera_position: tuple[float, float, float] = (5, 5, 5),
                                 camera_look_at: tuple[float, float, float] = (0, 0, 0),
                                 resolution: tuple[int, int] = (1280, 720), camera_prim_path: str | None = None,
                                 render_product: Any = None) -> np.ndarray:
    """One step's RGBA image (H x W x 4, uint8)."""
    return await capture_annotator_data_async("rgb", camera_position, camera_look_at, resolution, camera_prim_path,
                                              render_product)


async def capture_depth_data_async(depth_type: str = "distance_to_camera",
                                   camera_position: tuple[float, float, float] = (5, 5, 5),
                                   camera_look_at: tuple[float, float, float] = (0, 0, 0),
                                   resolution: tuple[int, int] = (1280, 720), camera_prim_path: str | None = None,
                                   render_product: Any = None) -> np.ndarray:
    """One step's depth: distance to the camera's centre or to its image plane (float32).

    Raises:
        ValueError: ``depth_type`` is neither.
    """
    if depth_type not in DEPTH_ANNOTATORS:
        raise ValueError(f"Invalid depth_type {depth_type!r}; must be one of {list(DEPTH_ANNOTATORS)} "
                         f"('distance_to_camera': radial distance to the camera's centre, "
                         f"'distance_to_image_plane': depth along the view axis)")
    return await capture_annotator_data_async(depth_type, camera_position, camera_look_at, resolution,
                                              camera_prim_path, render_product)


async def capture_viewport_annotator_data_async(viewport_api: Any, annotator_name: str = "rgb") -> Any:
    """One step's data of ``annotator_name`` on the viewport's render product.

    Raises:
        ValueError: the viewport has no render product path.
    """
    path = viewport_api.render_product_path
    if not path:
        raise ValueError("viewport_api.render_product_path is None or empty")
    return await capture_annotator_data_async(annotator_name, render_product=path)


async def capture_viewport_screenshot_async(output_path: str, *, viewport_api: Any = None) -> bool:
    """Write the active (or given) viewport's RGB image to ``output_path``; True once the file exists."""
    viewport_api = viewport_api or viewport.get_active_viewport()
    rgb = await capture_viewport_annotator_data_async(viewport_api, annotator_name="rgb")
    save_rgb_image(rgb, os.path.dirname(output_path) or ".", os.path.basename(output_path))
    written = os.path.isfile(output_path)
    print(f"Viewport screenshot {'saved: ' + output_path if written else 'not created at ' + output_path}")
    return written


async def capture_app_screenshot_async(output_path: str, *, max_wait_frames: int = 20) -> bool:
    """Kit's whole-window screenshot: not available (``CompatError``)."""
    raise CompatError(f"isaacsim.test.utils.image_capture.capture_app_screenshot_async: {NO_APP_WINDOW}.")


def _save_frame(data: Any, output_dir: str, stem: str, as_image: bool) -> str:
    if as_image and isinstance(data, np.ndarray) and data.ndim >= 2:
        save_rgb_image(data, output_dir, f"{stem}.png")
        return os.path.join(output_dir, f"{stem}.png")
    path = os.path.join(output_dir, f"{stem}.npy")
    array = data["data"] if isinstance(data, dict) and isinstance(data.get("data"), np.ndarray) else data
    np.save(path, np.asarray(array))
    return path


async def capture_frame_sequence_async(output_dir: str, num_frames: int = 30, updates_per_frame: int = 2,
                                       mode: str = "app", *, prefix: str = "frame", start_index: int = 0,
                                       annotator_name: str = "rgb", resolution: tuple[int, int] | None = None,
                                       camera_prim_path: str | None = None, render_product: Any = None) -> list[str]:
    """Capture ``num_frames`` frames into ``output_dir`` as ``<prefix>_<index:04d>.png`` (images) or ``.npy``,
    with ``updates_per_frame`` app updates between captures; returns the files in order.

    Raises:
        CompatError: ``mode="app"`` (no application window here).
        ValueError: an unknown mode.
    """
    if mode == "app":
        raise CompatError(f"capture_frame_sequence_async(mode='app'): {NO_APP_WINDOW}; use mode='viewport' "
                          f"or mode='replicator'.")
    if mode not in ("viewport", "replicator"):
        raise ValueError(f"Unknown capture mode: {mode!r}. Use 'app', 'viewport', or 'replicator'.")
    os.makedirs(output_dir, exist_ok=True)
    app, paths = kit.get_app(), []
    if mode == "viewport":
        active = viewport.get_active_viewport()
        for index in range(start_index, start_index + num_frames):
            rgb = await capture_viewport_annotator_data_async(active, "rgb")
            paths.append(_save_frame(rgb, output_dir, f"{prefix}_{index:04d}", True))
            for _ in range(updates_per_frame):
                await app.next_update_async()
        return paths
    owned = render_product is None
    if owned:
        camera = camera_prim_path or str(viewport.get_active_viewport().camera_path)
        render_product = rep.create.render_product(camera, tuple(resolution or (1280, 720)))
    annotator = rep.AnnotatorRegistry.get_annotator(annotator_name)
    annotator.attach(render_product)
    as_image = annotator_name in ("rgb", "normals", "instance_segmentation_fast")
    try:
        for index in range(start_index, start_index + num_frames):
            await rep.orchestrator.step_async()
            paths.append(_save_frame(annotator.get_data(do_array_copy=True), output_dir, f"{prefix}_{index:04d}",
                                     as_image))
            for _ in range(updates_per_frame):
                await app.next_update_async()
    finally:
        annotator.detach()
        if owned:
            render_product.destroy()
    print(f"Captured {len(paths)} frames in {output_dir}")
    return paths


# ---- timed tests --------------------------------------------------------------------------------
class TimedAsyncTestCase(kit.AsyncTestCase):
    """An ``omni.kit.test.AsyncTestCase`` that prints ``[TEST TIMING] <test>: <seconds> seconds`` after each test."""

    async def setUp(self) -> None:
        """Start the test's clock."""
        await super().setUp()
        self._test_start_time = time.time()
        self._assets_root_path = assets.get_assets_root_path()

    async def tearDown(self) -> None:
        """Print the test's time."""
        if hasattr(self, "_test_start_time"):
            print(f"\n[TEST TIMING] {self._testMethodName}: {time.time() - self._test_start_time:.3f} seconds")
        await super().tearDown()
        gc.collect()


# ---- polling the stage --------------------------------------------------------------------------
def _polls(timeout_frames: int, poll_steps: int) -> int:
    if poll_steps < 1:
        raise ValueError(f"poll_steps must be a positive integer, got {poll_steps!r}")
    return max(0, timeout_frames // poll_steps)


def _report(label: str, elapsed: int | None, timeout_frames: int) -> int | None:
    if label:
        if elapsed is None:
            log.warning("%s not satisfied after %d frames", label, timeout_frames)
        else:
            log.info("%s satisfied after %d frames", label, elapsed)
    return elapsed


def poll_until(check_fn: Callable[[], object], timeout_frames: int = 1800, poll_steps: int = 30,
               label: str = "") -> int | None:
    """Run ``poll_steps`` app updates, then ask ``check_fn``; the frames run when it answers truthy, None when
    ``timeout_frames`` ran out."""
    for i in range(_polls(timeout_frames, poll_steps)):
        for _ in range(poll_steps):
            kit.get_app().update()
        if check_fn():
            return _report(label, (i + 1) * poll_steps, timeout_frames)
    return _report(label, None, timeout_frames)


async def poll_until_async(check_fn: Callable[[], object], timeout_frames: int = 1800, poll_steps: int = 30,
                           label: str = "") -> int | None:
    """:func:`poll_until` with awaited app updates."""
    for i in range(_polls(timeout_frames, poll_steps)):
        for _ in range(poll_steps):
            await kit.get_app().next_update_async()
        if check_fn():
            return _report(label, (i + 1) * poll_steps, timeout_frames)
    return _report(label, None, timeout_frames)


def _prim_exists(prim_path: str) -> Callable[[], bool]:
    return lambda: bool(get_stage().GetPrimAtPath(prim_path))


def _has_prims(min_prims: int) -> Callable[[], bool]:
    def check() -> bool:
        """Whether the stage holds ``min_prims`` prims."""
        for count, _ in enumerate(get_stage().Traverse(), start=1):
            if count >= min_prims:
                return True
        return False
    return check


def wait_for_prim(prim_path: str, timeout_frames: int = 1800, poll_steps: int = 30) -> bool:
    """Whether ``prim_path`` exists on the stage within ``timeout_frames`` app updates."""
    return poll_until(_prim_exists(prim_path), timeout_frames, poll_steps, label=prim_path) is not None


async def wait_for_prim_async(prim_path: str, timeout_frames: int = 1800, poll_steps: int = 30) -> bool:
    """:func:`wait_for_prim` with awaited app updates."""
    return await poll_until_async(_prim_exists(prim_path), timeout_frames, poll_steps, label=prim_path) is not None


def wait_for_stage_prims(min_prims: int = 20, timeout_frames: int = 1800, poll_steps: int = 30) -> bool:
    """Whether the stage holds ``min_prims`` prims within ``timeout_frames`` app updates."""
    return poll_until(_has_prims(min_prims), timeout_frames, poll_steps, label=f">={min_prims} prims") is not None


async def wait_for_stage_prims_async(min_prims: int = 20, timeout_frames: int = 1800, poll_steps: int = 30) -> bool:
    """:func:`wait_for_stage_prims` with awaited app updates."""
    return await poll_until_async(_has_prims(min_prims), timeout_frames, poll_steps,
                                  label=f">={min_prims} prims") is not None


def modules() -> list[types.ModuleType]:
    """``isaacsim.test.utils.image_capture``, ``timed_async_test`` and ``stage_utils``, and their names on
    ``isaacsim.test.utils``."""
    capture = dict(capture_annotator_data_async=capture_annotator_data_async,
                   capture_rgb_data_async=capture_rgb_data_async, capture_depth_data_async=capture_depth_data_async,
                   capture_viewport_annotator_data_async=capture_viewport_annotator_data_async,
                   capture_viewport_screenshot_async=capture_viewport_screenshot_async,
                   capture_app_screenshot_async=capture_app_screenshot_async,
                   capture_frame_sequence_async=capture_frame_sequence_async)
    stage = dict(poll_until=poll_until, poll_until_async=poll_until_async, wait_for_prim=wait_for_prim,
                 wait_for_prim_async=wait_for_prim_async, wait_for_stage_prims=wait_for_stage_prims,
                 wait_for_stage_prims_async=wait_for_stage_prims_async)
    return [CompatModule("isaacsim.test.utils.image_capture", **capture),
            CompatModule("isaacsim.test.utils.timed_async_test", TimedAsyncTestCase=TimedAsyncTestCase),
            CompatModule("isaacsim.test.utils.stage_utils", **stage),
            CompatModule("isaacsim.test.utils", **capture, **stage, TimedAsyncTestCase=TimedAsyncTestCase)]
