"""CosmosWriter: clips of the control videos NVIDIA Cosmos Transfer takes as input.

Layout (Replicator's ``CosmosWriter``)::

    <output_dir>/clip_<c>/<modality>/<modality>_<n>.png     one image per captured frame
    <output_dir>/clip_<c>/<modality>.mp4                    the clip's frames as a video

for the five modalities ``rgb``, ``shaded_seg``, ``segmentation``, ``depth`` and
``edges`` (see :mod:`graphsdg.io.cosmos_controls` for how each is made). ``<c>`` and
``<n>`` have four digits; ``<n>`` restarts at 0 in every clip. The videos play at the
stage's time codes per second (the timeline rate, 60 by default) and are encoded from
the clip's PNG files when the clip ends: on ``orchestrator.wait_until_complete()``,
``detach()``, ``next_clip()`` or the end of a run. Frames captured after that are
added to the same clip, and its videos encoded again, until the next clip starts.

A new clip starts with :meth:`CosmosWriter.next_clip`, or, when the writer's frames
come from a ``trigger.on_time`` trigger, each time that trigger's count goes up
(its count is the clip index), as in Replicator.

Segmentation: with ``segmentation_mapping`` (semantic label -> RGB(A) colour) every
instance whose label is in the mapping gets that colour and the others a pastel
colour fixed by their id; without it each instance (``use_instance_id=True``: each
rendered prim, labelled or not) gets its pastel colour. Background is black.

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("CosmosWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), segmentation_mapping={"cube": [255, 0, 0, 255]})
"""
from __future__ import annotations

import numbers
from typing import Any, Mapping

import cv2
import numpy as np
from pxr import UsdGeom

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io import cosmos_controls, io_functions as iof, video
from graphsdg.io.backends import BaseBackend, writes_discarded
from graphsdg.io.write_queue import get_write_queue
from graphsdg.io.writer import ON_FRAME
from graphsdg.io.writers.format_writer import FormatWriter
from graphsdg.stage import get_stage

MODALITIES = ("rgb", "shaded_seg", "segmentation", "depth", "edges")
ON_TIME = "on_time"


def _color(writer: str, label: str, value: Any) -> tuple[int, int, int]:
    """An RGB triple from a mapping value of 3 or 4 integers 0..255 (alpha is dropped: the videos have none)."""
    ok = isinstance(value, (list, tuple, np.ndarray)) and len(value) in (3, 4) and all(
        isinstance(c, numbers.Integral) and not isinstance(c, bool) and 0 <= c <= 255 for c in value)
    if not ok:
        raise ValueError(f"{writer}: segmentation_mapping[{label!r}] must be an RGB or RGBA colour of integers "
                         f"0..255 such as [255, 0, 0, 255], got {value!r}")
    return int(value[0]), int(value[1]), int(value[2])


def clip_folder(clip: int) -> str:
    """The folder of clip ``clip``: ``clip_0003``."""
    return f"clip_{clip:04d}"


def frame_path(clip: int, modality: str, frame: int) -> str:
    """Where frame ``frame`` of ``modality`` in clip ``clip`` is written, relative to the output folder."""
    return f"{clip_folder(clip)}/{modality}/{modality}_{frame:04d}.png"


def video_path(clip: int, modality: str) -> str:
    """Where the video of ``modality`` in clip ``clip`` is written, relative to the output folder."""
    return f"{clip_folder(clip)}/{modality}.mp4"


def encode_clip_video(backend: BaseBackend, clip: int, modality: str, frames: int, fps: float) -> None:
    """Encode frames ``0 .. frames-1`` of ``modality`` in clip ``clip`` (read back from ``backend``) to its MP4."""
    def images():
        for n in range(frames):
            raw = np.frombuffer(backend.read_blob(frame_path(clip, modality, n)), np.uint8)
            img = cv2.imdecode(raw, cv2.IMREAD_COLOR)
            if img is None:
                raise ValueError(f"{frame_path(clip, modality, n)} does not decode as an image")
            yield cv2.cvtColor(img, cv2.COLOR_BGR2RGB)
    backend.write_blob(video_path(clip, modality), video.encode_mp4(images(), fps))


class CosmosWriter(FormatWriter):
    """Replicator's CosmosWriter: rgb, shaded_seg, segmentation, depth and edges clips (see the module docstring).

    Args:
        output_dir: folder to write to (or pass ``backend``).
        backend: a backend from ``rep.backends.get(...)``; it must read back what it wrote
            (a disk backend does), since the videos are encoded from the PNG files.
        segmentation_mapping: semantic label -> RGB(A) colour of the segmentation images.
        use_instance_id: colour every rendered prim (labelled or not) rather than every
            labelled instance; ignored when ``segmentation_mapping`` is given.
        canny_threshold_low, canny_threshold_high: the hysteresis thresholds of the edges.
    """

    def __init__(self, output_dir: str | None = None, backend: BaseBackend | None = None,
                 segmentation_mapping: Mapping[str, Any] | None = None, use_instance_id: bool = True,
                 canny_threshold_low: float = 10, canny_threshold_high: float = 100) -> None:
        super().__init__(output_dir, backend, version="0.1.0")
        name = type(self).__name__
        if segmentation_mapping is not None and not isinstance(segmentation_mapping, Mapping):
            raise ValueError(f"{name}: segmentation_mapping must be a dict of semantic label -> RGBA colour, got "
                             f"{segmentation_mapping!r}")
        self._mapping = {str(k): _color(name, k, v) for k, v in (segmentation_mapping or {}).items()}
        if not isinstance(use_instance_id, (bool, np.bool_)):
            raise ValueError(f"{name}: use_instance_id must be True or False, got {use_instance_id!r}")
        for key, value in (("canny_threshold_low", canny_threshold_low),
                           ("canny_threshold_high", canny_threshold_high)):
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not 0 <= value:
                raise ValueError(f"{name}: {key} must be a number >= 0, got {value!r}")
        if canny_threshold_low > canny_threshold_high:
            raise ValueError(f"{name}: canny_threshold_low ({canny_threshold_low!r}) must not exceed "
                             f"canny_threshold_high ({canny_threshold_high!r})")
        self._canny = (float(canny_threshold_low), float(canny_threshold_high))
        # Semantic instances carry the labels a mapping colours; instance ids cover every prim.
        self._seg = "instance_id_segmentation_fast" if use_instance_id and not self._mapping \
            else "instance_segmentation_fast"
        self.annotators = [AnnotatorRegistry.get_annotator("rgb"),
                           AnnotatorRegistry.get_annotator("distance_to_camera_fast"),
                           AnnotatorRegistry.get_annotator("normals_fast"),
                           AnnotatorRegistry.get_annotator(self._seg)]
        self._clip = 0
        self._frame_id = 0
        self._encoded = 0          # frames of the current clip already in its videos
        self._fps: float | None = None
        self._up = (0.0, 0.0, 1.0)

    # ---- attachment ----------------------------------------------------------------------------
    def attach(self, render_products: Any, trigger: Any = ON_FRAME) -> None:
        """Attach to one render product (one camera's clips; use one CosmosWriter per camera)."""
        items = render_products if isinstance(render_products, (list, tuple)) else [render_products]
        if len(items) != 1:
            raise ValueError(f"{type(self).__name__} writes the clips of one camera; attach exactly one render "
                             f"product (one writer per camera), got {len(items)}")
        super().attach(render_products, trigger)

    # ---- frames --------------------------------------------------------------------------------
    def write(self, data: dict) -> None:
        for trigger_name, count in data.get("trigger_outputs", {}).items():
            if ON_TIME in trigger_name and int(count) > self._clip:
                self.next_clip()
        if self._fps is None:
            stage = get_stage()
            self._fps = float(stage.GetTimeCodesPerSecond())
            # shading light from straight above, whichever axis is up
            self._up = (0.0, 1.0, 0.0) if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y else (0.0, 0.0, 1.0)
        rp = next(iter(data["renderProducts"].values()))
        seg = rp[self._seg]
        segmentation = cosmos_controls.segmentation_image(seg["data"], self._id_colors(seg))
        shaded = cosmos_controls.shaded_segmentation(segmentation, rp["normals_fast"]["data"], self._up)
        images = {
            "rgb": rp["rgb"]["data"],
            "shaded_seg": shaded,
            "segmentation": segmentation,
            "depth": cosmos_controls.depth_image(rp["distance_to_camera_fast"]["data"]),
            "edges": cosmos_controls.edge_image(shaded, *self._canny),
        }
        for modality in MODALITIES:
            self.backend.schedule(iof.write_image, data=images[modality],
                                  path=frame_path(self._clip, modality, self._frame_id))
        self._frame_id += 1

    def _id_colors(self, seg: dict) -> dict[int, tuple[int, int, int]]:
        """Mapping colours of this frame's instance ids (by any of their semantic labels)."""
        if not self._mapping:
            return {}
        colors = {}
        for key, semantics in (seg.get("idToSemantics") or {}).items():
            labels = [label.strip() for value in (semantics or {}).values() for label in str(value).split(",")]
            hit = next((self._mapping[label] for label in labels if label in self._mapping), None)
            if hit is not None:
                colors[int(key)] = hit
        return colors

    # ---- clips ---------------------------------------------------------------------------------
    def flush(self) -> None:
        """Encode the current clip's videos from its PNG files (once its PNG writes are done)."""
        if self._frame_id <= self._encoded or writes_discarded():
            return
        queue = get_write_queue()
        queue.wait_until_done()     # the videos read the PNG files back
        for modality in MODALITIES:
            queue.schedule(encode_clip_video, self.backend, self._clip, modality, self._frame_id, self._fps)
        self._encoded = self._frame_id

    def on_final_frame(self) -> None:
        self.flush()

    def next_clip(self) -> None:
        """Finish the current clip (its videos are encoded) and write the next frames to a new one."""
        self.flush()
        self._clip += 1
        self._frame_id = 0
        self._encoded = 0
