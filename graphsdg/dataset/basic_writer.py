"""Reading a BasicWriter output directory back, frame by frame.

Replicator's BasicWriter names every file ``<stem>_<frame>.<ext>`` (with ``_labels``,
``_prim_paths``, ``_mapping`` ... companions). :class:`BasicWriterDataset`
finds the frames and loads what each holds, from a folder or an ``s3://bucket/prefix``.

Example:
    >>> ds = BasicWriterDataset("_out_demo")          # doctest: +SKIP
    >>> frame = ds.frame(ds.frame_ids[0])             # doctest: +SKIP
    >>> frame.boxes["x_min"]                          # doctest: +SKIP
"""
from __future__ import annotations

import io
import json
import posixpath
import re
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable

import numpy as np
from PIL import Image

from graphsdg.dataset.label_images import colour_ids, decode_image, png_colour_ids
from graphsdg.dataset.npy_bytes import array_from_npy
from graphsdg.io.basic_writer_layout import FLAGS, json_companions
from graphsdg.io.location import Location, open_location

# file stem -> the JSON companion files BasicWriter writes with it (from the writer's layout table)
COMPANIONS = {stem: suffixes for stem in sorted({stem for _, stem in FLAGS.values()})
              if (suffixes := json_companions(stem))}
# point clouds (PLY, PCD) of sensors written beside the images share the frame numbering
_MAIN = re.compile(r"^(?P<stem>[a-z0-9_]+?)_(?P<frame>(?:\d+_)*\d+)\.(?P<ext>png|jpg|jpeg|npy|json|ply|pcd)$")
_COMPANION_SUFFIXES = tuple(sorted({suffix for suffixes in COMPANIONS.values() for suffix in suffixes}))


def _parse(name: str) -> tuple[str, str, str] | None:
    m = _MAIN.match(name)
    if not m:
        return None
    stem = m.group("stem")
    for suffix in _COMPANION_SUFFIXES:
        if stem.endswith(suffix) and stem[: -len(suffix)] in COMPANIONS:
            return None
    return stem, m.group("frame"), m.group("ext")


def _color_key(key: str) -> tuple[int, ...] | None:
    if key.startswith("(") and key.endswith(")"):
        return tuple(int(v) for v in key.strip("()").split(","))
    return None


def _colorized(mapping: dict, keys: list[str], shift: bool, keep: Callable[[object], bool] | None,
               value_of: Callable[[object, int], int] | None) -> tuple[list, list | None, int, dict]:
    """(colours, per-colour values, value of a colour not listed, value -> mapping entry) of a colorized
    segmentation's mapping, as :meth:`Frame.segmentation` documents them."""
    colours = [_color_key(k) for k in keys]
    if value_of is not None:
        return colours, [value_of(mapping[k], i) for i, k in enumerate(keys)], 0, \
            dict(enumerate(mapping[k] for k in keys))
    values = [i + 1 if keep is None or keep(mapping[k]) else 0 for i, k in enumerate(keys)] if shift else None
    return colours, values, 0 if shift else -1, {i + shift: mapping[k] for i, k in enumerate(keys)}


@dataclass
class Frame:
    """The files of one frame in one BasicWriter folder (``folder``: ``/``-separated, relative to the dataset)."""

    location: Location
    folder: str
    frame_id: str
    files: dict[str, str] = field(default_factory=dict)   # stem -> main file name

    def path(self, name: str) -> str:
        """``name`` relative to the dataset."""
        return posixpath.join(self.folder, name) if self.folder else name

    def read(self, name: str) -> bytes:
        return self.location.read(self.path(name))

    def _json(self, name: str):
        return json.loads(self.read(name))

    def companion(self, stem: str, suffix: str) -> str:
        return f"{stem}{suffix}_{self.frame_id}.json"

    def expected_files(self) -> list[str]:
        out = []
        for stem, name in self.files.items():
            out.append(name)
            out += [self.companion(stem, s) for s in COMPANIONS.get(stem, ())]
        return out

    @cached_property
    def rgb(self) -> np.ndarray | None:
        name = self.files.get("rgb")
        return np.array(Image.open(io.BytesIO(self.read(name))).convert("RGB")) if name else None

    def boxes(self, kind: str = "bounding_box_2d_tight",
              paths: bool = True) -> tuple[np.ndarray, dict, list[str]] | None:
        """(rows, idToLabels, primPaths) of a box annotator (the rows a read-only structured array), or None if not
        written (``paths=False``: the prim paths file is not read and the list is empty)."""
        name = self.files.get(kind)
        if not name:
            return None
        rows = array_from_npy(self.read(name))
        return rows, self._json(self.companion(kind, "_labels")), \
            self._json(self.companion(kind, "_prim_paths")) if paths else []

    def segmentation(self, kind: str, shift: bool = False, keep: Callable[[object], bool] | None = None,
                     value_of: Callable[[object, int], int] | None = None) -> tuple[np.ndarray, dict] | None:
        """(ids (H, W) int, id -> value mapping) for semantic/instance segmentation, colorized or not.

        Colorized images give each pixel the index of its colour among the mapping's ``"(r, g, b, a)"`` keys
        (-1 for a colour the mapping lacks). ``shift``: ids + 1 instead, 0 for a colour the mapping lacks and
        for a mapping value ``keep`` rejects (background, unlabelled), so that 0 means nothing. ``value_of``:
        each pixel holds ``value_of(mapping value, id)`` instead (0 for a colour the mapping lacks), the mapping
        still keyed by the ids.
        """
        name = self.files.get(kind)
        if not name:
            return None
        suffix = "_labels" if kind == "semantic_segmentation" else "_mapping"
        mapping = self._json(self.companion(kind, suffix))
        data = self.read(name)
        keys = [k for k in mapping if _color_key(k) is not None]
        colorized = _colorized(mapping, keys, shift, keep, value_of) if keys else None
        if colorized is not None:   # graphsdg's own PNGs are read run by run, straight to the values
            ids = png_colour_ids(data, *colorized[:3])
            if ids is not None:
                return ids, colorized[3]
        img = decode_image(data, rgb_order=False)
        if img.ndim == 3:   # colorized: pixel colours index the mapping's "(r, g, b, a)" keys
            colours, values, missing, names = colorized or _colorized(mapping, keys, shift, keep, value_of)
            return colour_ids(img, colours, bgr=True, values=values, missing=missing), names
        ids = img.astype(np.int64)
        mapping = {int(k): v for k, v in mapping.items()}
        if not shift and value_of is None:
            return ids, mapping
        lut = np.zeros(max([int(ids.max(initial=0)), *mapping]) + 1, dtype=np.int64)
        for k, v in mapping.items():
            lut[k] = value_of(v, k) if value_of is not None else k + 1 if keep is None or keep(v) else 0
        if value_of is not None:
            return lut[ids], mapping
        return lut[ids], {k + 1: v for k, v in mapping.items()}

    def semantics_of_instances(self) -> dict[int, object] | None:
        """Instance segmentation's id -> semantic labels (its ``_semantics_mapping`` file), ids as
        :meth:`segmentation` gives them (unshifted); None if not written."""
        if "instance_segmentation" not in self.files:
            return None
        try:
            semantics = self._json(self.companion("instance_segmentation", "_semantics_mapping"))
        except FileNotFoundError:
            return None
        mapping = self._json(self.companion("instance_segmentation", "_mapping"))
        keys = [k for k in mapping if _color_key(k) is not None]
        if keys:   # colorized: both files are keyed by colour; ids are the colour's place in the mapping
            return {i: semantics[k] for i, k in enumerate(keys) if k in semantics}
        return {int(k): v for k, v in semantics.items()}

    def semantic_labels(self) -> dict[int, object]:
        """semanticId -> labels, from every ``_labels`` file of this frame's box annotators (the ids the
        point cloud's ``pointcloud_semantic`` holds too)."""
        out: dict[int, object] = {}
        for kind in ("bounding_box_2d_tight", "bounding_box_2d_loose", "bounding_box_3d"):
            if kind in self.files:
                out.update({int(k): v for k, v in self._json(self.companion(kind, "_labels")).items()})
        return out

    def camera_params(self) -> dict | None:
        """The ``camera_params`` annotator's output of this frame, or None if not written."""
        name = self.files.get("camera_params")
        return self._json(name) if name else None

    def pointcloud(self) -> dict[str, np.ndarray] | None:
        """The ``pointcloud`` annotator's arrays (``data`` and whichever of ``rgb``, ``normals``, ``semantic``,
        ``instance`` were written), or None."""
        name = self.files.get("pointcloud")
        if not name:
            return None
        out = {"data": np.load(io.BytesIO(self.read(name)))}
        for part in ("rgb", "normals", "semantic", "instance"):
            if f"pointcloud_{part}" in self.files:
                out[part] = np.load(io.BytesIO(self.read(self.files[f"pointcloud_{part}"])))
        return out

    def depth(self, kind: str = "distance_to_image_plane") -> np.ndarray | None:
        """The frame's depth of ``kind`` (a read-only array), or None where it was not written."""
        name = self.files.get(kind)
        return array_from_npy(self.read(name)) if name else None


class BasicWriterDataset:
    """All frames of a BasicWriter output directory (and of its per-render-product folders).

    ``root``: a folder or an ``s3://bucket/prefix`` (:mod:`graphsdg.io.location`); it is listed once, unless
    ``listing`` (its :meth:`~graphsdg.io.location.Location.files`, listed by the caller) is given.
    """

    def __init__(self, root: str | Location, listing: dict[str, int] | None = None) -> None:
        self.location = open_location(root)
        if not self.location.is_folder():
            raise NotADirectoryError(f"dataset directory {self.location.url!r} does not exist")
        self.root = self.location.url
        self.frames: dict[tuple[str, str], Frame] = {}
        self.stray: list[str] = []                 # relative paths of temporary and hidden files
        self.listing = self.location.files() if listing is None else listing   # relative path -> size
        for rel in self.listing:
            folder, name = posixpath.split(rel)
            if name.endswith(".tmp") or name.startswith("."):
                self.stray.append(rel)
                continue
            parsed = _parse(name)
            if parsed is None:
                continue
            stem, frame_id, _ = parsed
            key = (folder, frame_id)
            self.frames.setdefault(key, Frame(self.location, folder, frame_id)).files[stem] = name

    def exists(self, rel: str) -> bool:
        """Whether the dataset holds file ``rel`` (from the listing)."""
        return rel in self.listing

    @property
    def frame_ids(self) -> list[tuple[str, str]]:
        return sorted(self.frames)

    def frame(self, key: tuple[str, str]) -> Frame:
        return self.frames[key]

    def __len__(self) -> int:
        return len(self.frames)

    def stems(self) -> set[str]:
        return {s for f in self.frames.values() for s in f.files}
