"""WebDatasetWriter: tar shards of per-frame samples, for streaming training at scale.

Layout (the WebDataset convention: a sample is the tar members that share a key)::

    <output_dir>/shard-000000.tar
        000000.png            the rgb image                     (rgb=True)
        000000.json           frame record: render product, camera, frame, sim time,
                              boxes [{label, prim_path, x_min, y_min, x_max, y_max, occlusion_ratio}]
                              (occlusion_ratio -1: not computed, as bounding_box_2d_tight reports it),
                              camera_params and id -> label maps of the id images
        000000.depth.npy      distance_to_image_plane, float32 (H, W)       (distance_to_image_plane=True)
        000000.semantic.png   16-bit semantic ids (map: json "semantic_labels")   (semantic_segmentation=True)
        000000.instance.png   16-bit instance ids (map: json "instance_labels")   (instance_segmentation=True)
        000001.png ...
    <output_dir>/shard-000001.tar ...

Keys are the frame number (6 digits), prefixed with ``<rp_name>_`` when the
writer has several render products. A shard holds at most ``maxcount`` samples
and about ``maxsize`` bytes; it is built in memory and written whole (through
the backend, atomically), so a shard on disk is always complete. ``flush()``
(``wait_until_complete()``, ``detach()``, the end of ``run()``) closes the open
shard; later frames go to the next one. Member metadata (mtime, owner, mode) is
fixed, so the same frames give the same bytes.

Read it with ``webdataset``::

    import webdataset as wds
    for sample in wds.WebDataset("out/shard-{000000..000001}.tar").decode("rgb8"):
        image, record = sample["png"], sample["json"]

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("WebDatasetWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), maxcount=100, distance_to_image_plane=True)
"""
from __future__ import annotations

import io
import tarfile
import threading
from typing import Any, Callable, Sequence

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io import encode
from graphsdg.io.labels import class_name
from graphsdg.io.writers import arguments
from graphsdg.io.writers.format_writer import FormatWriter


class _OrderedShards:
    """Appends encoded samples to tar shards in the order they were scheduled.

    Encoding runs in parallel on the write queue's workers; appending and closing
    take turns by sequence number (tasks leave the FIFO queue in order, so the
    task a worker waits for is already running on another worker).
    """

    def __init__(self, pattern: str, maxcount: int, maxsize: int) -> None:
        self.pattern, self.maxcount, self.maxsize = pattern, maxcount, maxsize
        self._cond = threading.Condition()
        self._scheduled = 0
        self._next = 0
        self._index = 0
        self._open: tuple[tarfile.TarFile, io.BytesIO] | None = None
        self._count = 0
        self.shards: list[str] = []

    def schedule(self, backend: Any, build: Callable[[], list[tuple[str, bytes]]] | None) -> None:
        """Queue one sample (``build`` returns its members) or, with ``None``, closing the open shard."""
        seq = self._scheduled
        self._scheduled += 1
        backend.schedule(self._run, seq=seq, build=build)

    def _run(self, seq: int, build, backend_instance: Any) -> None:
        error, members = None, None
        try:
            members = build() if build is not None else None
        except BaseException as exc:  # noqa: BLE001 - re-raised after this task's turn
            error = exc
        with self._cond:
            while self._next != seq:
                self._cond.wait()
            try:
                if error is None:
                    if members is None:
                        self._close(backend_instance)
                    else:
                        self._append(members, backend_instance)
            finally:
                self._next += 1
                self._cond.notify_all()
        if error is not None:
            raise error

    def _append(self, members: list[tuple[str, bytes]], backend: Any) -> None:
        if self._open is None:
            bio = io.BytesIO()
            self._open = (tarfile.open(fileobj=bio, mode="w", format=tarfile.USTAR_FORMAT), bio)
        tar, bio = self._open
        for name, data in members:
            info = tarfile.TarInfo(name)
            info.size, info.mtime, info.mode = len(data), 0, 0o444
            tar.addfile(info, io.BytesIO(data))
        self._count += 1
        if self._count >= self.maxcount or bio.tell() >= self.maxsize:
            self._close(backend)

    def _close(self, backend: Any) -> None:
        if self._open is None:
            return
        tar, bio = self._open
        tar.close()
        name = self.pattern % self._index
        backend.write_blob(name, bio.getvalue())
        self.shards.append(name)
        self._open, self._count = None, 0
        self._index += 1


class WebDatasetWriter(FormatWriter):
    """Tar shards of per-frame samples (see the module docstring)."""

    def __init__(self, output_dir: str | None = None, shard_pattern: str = "shard-%06d.tar", maxcount: int = 1000,
                 maxsize: int = 256 * 2 ** 20, rgb: bool = True, bounding_box_2d_tight: bool = True,
                 semantic_segmentation: bool = False, instance_segmentation: bool = False,
                 distance_to_image_plane: bool = False, camera_params: bool = True,
                 semantic_types: Sequence[str] | None = None, semantic_filter_predicate: str | None = None,
                 image_output_format: str = "png", frame_padding: int = 6, backend=None) -> None:
        super().__init__(output_dir, backend, version="0.1.0")
        name = type(self).__name__
        try:
            shard_pattern % 0
        except (TypeError, ValueError):
            raise ValueError(f"{name}: shard_pattern must hold one integer field such as 'shard-%06d.tar', got "
                             f"{shard_pattern!r}") from None
        for arg, value in (("maxcount", maxcount), ("maxsize", maxsize)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"{name}: {arg} must be a positive integer, got {value!r}")
        filter_text = self.semantic_filter(semantic_types, semantic_filter_predicate)
        self._ext = arguments.image_extension(name, image_output_format)
        self._padding = arguments.frame_padding(name, frame_padding)
        self._shards = _OrderedShards(shard_pattern, maxcount, maxsize)
        self._pending = False
        self._frame_id = 0
        sem = {"semanticFilter": filter_text}
        wanted = [("rgb", rgb, {}), ("bounding_box_2d_tight_fast", bounding_box_2d_tight, sem),
                  ("semantic_segmentation", semantic_segmentation, sem),
                  ("instance_segmentation_fast", instance_segmentation, sem),
                  ("distance_to_image_plane", distance_to_image_plane, {}), ("camera_params", camera_params, {})]
        self.annotators = [AnnotatorRegistry.get_annotator(a, init_params=p) for a, on, p in wanted if on]
        if not self.annotators:
            raise ValueError(f"{name}: nothing to write; enable at least one of rgb, bounding_box_2d_tight, "
                             f"semantic_segmentation, instance_segmentation, distance_to_image_plane, camera_params")

    @property
    def shards(self) -> list[str]:
        """Shard files written so far (paths relative to the output directory)."""
        return list(self._shards.shards)

    def write(self, data: dict) -> None:
        products = data["renderProducts"]
        for rp_name, rp in products.items():
            key = (f"{rp_name}_" if len(products) > 1 else "") + f"{self._frame_id:0{self._padding}d}"
            record = {"__key__": key, "render_product": rp_name, "camera": rp["camera"],
                      "resolution": list(rp["resolution"]), "frame": self._frame_id,
                      "reference_time": list(data.get("reference_time", (0, 1))),
                      "trigger_outputs": dict(data.get("trigger_outputs", {}))}
            self._shards.schedule(self.backend, _sample_builder(key, rp, record, self._ext, self.semantic_types))
            self._pending = True
        self._frame_id += 1

    def flush(self) -> None:
        """Close the open shard (later frames start a new one)."""
        if self._pending:
            self._shards.schedule(self.backend, None)
            self._pending = False

    def on_final_frame(self) -> None:
        self.flush()


def _sample_builder(key: str, rp: dict, record: dict, ext: str, semantic_types) -> Callable[[], list]:
    """A function (run on a worker) that encodes one sample's members."""
    def build() -> list[tuple[str, bytes]]:
        members = []
        if "rgb" in rp:
            members.append((f"{key}.{ext}", encode.encode_image(rp["rgb"]["data"], f".{ext}")))
        boxes = rp.get("bounding_box_2d_tight_fast")
        if boxes is not None:
            record["boxes"] = [
                {"label": class_name(boxes["idToLabels"].get(str(int(row["semanticId"]))), semantic_types),
                 "prim_path": path, "instance_id": int(iid),
                 **{k: int(row[k]) for k in ("x_min", "y_min", "x_max", "y_max")},
                 "occlusion_ratio": float(row["occlusionRatio"])}
                for row, path, iid in zip(boxes["data"], boxes["primPaths"], boxes["bboxIds"])]
        if "semantic_segmentation" in rp:
            members.append((f"{key}.semantic.png", encode.encode_image(rp["semantic_segmentation"]["data"])))
            record["semantic_labels"] = rp["semantic_segmentation"]["idToLabels"]
        if "instance_segmentation_fast" in rp:
            members.append((f"{key}.instance.png", encode.encode_image(rp["instance_segmentation_fast"]["data"])))
            record["instance_labels"] = rp["instance_segmentation_fast"]["idToLabels"]
        if "distance_to_image_plane" in rp:
            members.append((f"{key}.depth.npy",
                            encode.encode_npy(np.asarray(rp["distance_to_image_plane"]["data"], dtype=np.float32))))
        if "camera_params" in rp:
            record["camera_params"] = rp["camera_params"]
        members.append((f"{key}.json", encode.encode_json(record)))
        return members
    return build
