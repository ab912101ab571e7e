"""Reading a BasicWriter output directory back, frame by frame.

Replicator's BasicWriter names every file ``<stem>_<frame>.<ext>`` (with ``_labels``,
``_prim_paths``, ``_mapping`` ... companions). :class:`BasicWriterDataset`
finds the frames and loads what each holds.

Example:
    >>> ds = BasicWriterDataset("_out_demo")          # doctest: +SKIP
    >>> frame = ds.frame(ds.frame_ids[0])             # doctest: +SKIP
    >>> frame.boxes["x_min"]                          # doctest: +SKIP
"""
from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from PIL import Image

# file stem -> the companion files BasicWriter writes with it
COMPANIONS = {
    "bounding_box_2d_tight": ("_labels", "_prim_paths"),
    "bounding_box_2d_loose": ("_labels", "_prim_paths"),
    "bounding_box_3d": ("_labels", "_prim_paths"),
    "semantic_segmentation": ("_labels",),
    "instance_segmentation": ("_mapping", "_semantics_mapping"),
    "instance_id_segmentation": ("_mapping",),
}
_MAIN = re.compile(r"^(?P<stem>[a-z0-9_]+?)_(?P<frame>(?:\d+_)*\d+)\.(?P<ext>png|jpg|jpeg|npy|json)$")
_COMPANION_SUFFIXES = ("_labels", "_prim_paths", "_semantics_mapping", "_mapping")


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


@dataclass
class Frame:
    """The files of one frame in one BasicWriter folder."""

    folder: str
    frame_id: str
    files: dict[str, str] = field(default_factory=dict)   # stem -> main file name

    def path(self, name: str) -> str:
        return os.path.join(self.folder, name)

    def companion(self, stem: str, suffix: str) -> str:
        return self.path(f"{stem}{suffix}_{self.frame_id}.json")

    def expected_files(self) -> list[str]:
        out = []
        for stem, name in self.files.items():
            out.append(name)
            out += [os.path.basename(self.companion(stem, s)) for s in COMPANIONS.get(stem, ())]
        return out

    @cached_property
    def rgb(self) -> np.ndarray | None:
        name = self.files.get("rgb")
        return np.array(Image.open(self.path(name)).convert("RGB")) if name else None

    def boxes(self, kind: str = "bounding_box_2d_tight") -> tuple[np.ndarray, dict, list[str]] | None:
        """(rows, idToLabels, primPaths) of a box annotator, or None if not written."""
        name = self.files.get(kind)
        if not name:
            return None
        rows = np.load(self.path(name))
        with open(self.companion(kind, "_labels")) as f:
            labels = json.load(f)
        with open(self.companion(kind, "_prim_paths")) as f:
            paths = json.load(f)
        return rows, labels, paths

    def segmentation(self, kind: str) -> tuple[np.ndarray, dict] | None:
        """(ids (H, W) int64, id -> value mapping) for semantic/instance segmentation, colorized or not."""
        name = self.files.get(kind)
        if not name:
            return None
        suffix = "_labels" if kind == "semantic_segmentation" else "_mapping"
        with open(self.companion(kind, suffix)) as f:
            mapping = json.load(f)
        img = np.array(Image.open(self.path(name)))
        if img.ndim == 3:   # colorized: pixel colours index the mapping's "(r, g, b, a)" keys
            keys = [k for k in mapping if _color_key(k) is not None]
            ids = np.full(img.shape[:2], -1, dtype=np.int64)
            for i, key in enumerate(keys):
                color = _color_key(key)
                ids[np.all(img[..., : len(color)] == color, axis=-1)] = i
            return ids, {i: mapping[k] for i, k in enumerate(keys)}
        return img.astype(np.int64), {int(k): v for k, v in mapping.items()}

    def depth(self, kind: str = "distance_to_image_plane") -> np.ndarray | None:
        name = self.files.get(kind)
        return np.load(self.path(name)) if name else None


class BasicWriterDataset:
    """All frames of a BasicWriter output directory (and of its per-render-product folders)."""

    def __init__(self, root: str) -> None:
        if not os.path.isdir(root):
            raise NotADirectoryError(f"dataset directory {root!r} does not exist")
        self.root = os.path.abspath(root)
        self.frames: dict[tuple[str, str], Frame] = {}
        self.stray: list[str] = []
        for folder, _, names in os.walk(self.root):
            for name in sorted(names):
                if name.endswith(".tmp") or name.startswith("."):
                    self.stray.append(os.path.join(folder, name))
                    continue
                parsed = _parse(name)
                if parsed is None:
                    continue
                stem, frame_id, _ = parsed
                key = (folder, frame_id)
                self.frames.setdefault(key, Frame(folder, frame_id)).files[stem] = name

    @property
    def frame_ids(self) -> list[tuple[str, str]]:
        return sorted(self.frames)

    def frame(self, key: tuple[str, str]) -> Frame:
        return self.frames[key]

    def __len__(self) -> int:
        return len(self.frames)

    def stems(self) -> set[str]:
        return {s for f in self.frames.values() for s in f.files}
