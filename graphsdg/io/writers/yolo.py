"""YoloWriter: Ultralytics-style detection datasets.

Layout::

    <output_dir>/data.yaml
    <output_dir>/images/<split>/<name>.png
    <output_dir>/labels/<split>/<name>.txt      one line per object: "class cx cy w h"

``<name>`` is the frame number (``frame_padding`` digits), prefixed with
``<rp_name>_`` when the writer has several render products. Coordinates are
normalised to [0, 1] by the image size: ``cx = (x_min + x_max + 1) / 2 / W``,
``w = (x_max - x_min + 1) / W`` for the inclusive pixel bounds of the tight box
(or the loose box, ``bbox_type="loose"``). A frame without objects gets an
empty label file (a background image). Ultralytics finds each label by
replacing ``/images/`` with ``/labels/`` in the image path.

Classes are numbered from 0: the given ``classes`` (others are skipped), or
every label in first-seen order. ``data.yaml`` holds ``path`` (the output
directory), ``train``, ``val`` and ``names``; it is rewritten when a class is
added and on ``flush()``. ``min_visibility`` > 0 drops objects whose visible
fraction is lower (it attaches the ``occlusion`` annotator, which costs the
unoccluded renders). With ``val_every=N`` every N-th frame goes to the
``val`` split; otherwise ``val`` points at the training images.

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("YoloWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), classes=["pallet", "box"])
"""
from __future__ import annotations

import json
from typing import Sequence

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io import io_functions as iof
from graphsdg.io.aggregate import AggregateFile
from graphsdg.io.labels import ClassTable, class_name
from graphsdg.io.writers import arguments
from graphsdg.io.writers.format_writer import FormatWriter

BOX_TYPES = {"tight": "bounding_box_2d_tight_fast", "loose": "bounding_box_2d_loose_fast"}


def data_yaml(snapshot: dict) -> bytes:
    """Ultralytics' dataset YAML (strings written as JSON strings, which YAML reads as-is)."""
    lines = [f"path: {json.dumps(snapshot['path'])}", f"train: {json.dumps(snapshot['train'])}",
             f"val: {json.dumps(snapshot['val'])}", f"nc: {len(snapshot['names'])}", "names:"]
    lines += [f"  {i}: {json.dumps(n)}" for i, n in snapshot["names"].items()]
    return ("\n".join(lines) + "\n").encode()


class YoloWriter(FormatWriter):
    """YOLO (Ultralytics) detection labels (see the module docstring)."""

    def __init__(self, output_dir: str | None = None, classes: Sequence[str] | None = None,
                 semantic_types: Sequence[str] | None = None, semantic_filter_predicate: str | None = None,
                 split: str = "train", val_every: int = 0, bbox_type: str = "tight",
                 image_output_format: str = "png", frame_padding: int = 6, min_visibility: float = 0.0,
                 backend=None) -> None:
        super().__init__(output_dir, backend, version="0.1.0")
        name = type(self).__name__
        filter_text = self.semantic_filter(semantic_types, semantic_filter_predicate)
        if bbox_type not in BOX_TYPES:
            raise ValueError(f"{name}: bbox_type must be one of {sorted(BOX_TYPES)}, got {bbox_type!r}")
        if not isinstance(split, str) or not split or "/" in split:
            raise ValueError(f"{name}: split must be a folder name such as 'train', got {split!r}")
        if isinstance(val_every, bool) or not isinstance(val_every, int) or val_every < 0 or val_every == 1:
            raise ValueError(f"{name}: val_every must be 0 (no val split) or an integer >= 2, got {val_every!r}")
        if classes is not None and (isinstance(classes, str) or not all(isinstance(c, str) for c in classes)):
            raise ValueError(f"{name}: classes must be a list of class names, got {classes!r}")
        self.classes = ClassTable(classes, first_id=0, fixed=classes is not None)
        self._split, self._val_every = split, val_every
        self._box = BOX_TYPES[bbox_type]
        self._min_visibility = float(min_visibility)
        self._ext = arguments.image_extension(name, image_output_format)
        self._padding = arguments.frame_padding(name, frame_padding)
        self._frame_id = 0
        self._yaml = AggregateFile(self.backend, "data.yaml", encoder=data_yaml)
        self._dirty = True
        if isinstance(min_visibility, bool) or not isinstance(min_visibility, (int, float)) \
                or not 0.0 <= min_visibility <= 1.0:
            raise ValueError(f"{name}: min_visibility must be in [0, 1], got {min_visibility!r}")
        self.annotators = [AnnotatorRegistry.get_annotator("rgb"),
                           AnnotatorRegistry.get_annotator(self._box, init_params={"semanticFilter": filter_text})]
        if self._min_visibility > 0:
            # tight boxes carry occlusion ratios only when an occlusion annotator pays for them
            self.annotators.append(AnnotatorRegistry.get_annotator("occlusion",
                                                                   init_params={"semanticFilter": filter_text}))

    def write(self, data: dict) -> None:
        products = data["renderProducts"]
        split = "val" if self._val_every and self._frame_id % self._val_every == self._val_every - 1 \
            else self._split
        for rp_name, rp in products.items():
            stem = f"{rp_name}_" if len(products) > 1 else ""
            stem += f"{self._frame_id:0{self._padding}d}"
            self.backend.schedule(iof.write_image, data=rp["rgb"]["data"], path=f"images/{split}/{stem}.{self._ext}")
            lines = self.label_lines(rp[self._box], *(int(v) for v in rp["resolution"]))
            self.backend.schedule(iof.write_blob, data="".join(f"{line}\n" for line in lines).encode(),
                                  path=f"labels/{split}/{stem}.txt")
        self._frame_id += 1
        if self._dirty:
            self.flush()

    def label_lines(self, boxes: dict, width: int, height: int) -> list[str]:
        lines = []
        for row in boxes["data"]:
            if self._min_visibility > 0 and 1.0 - float(row["occlusionRatio"]) < self._min_visibility:
                continue
            label = class_name(boxes["idToLabels"].get(str(int(row["semanticId"]))), self.semantic_types)
            if label is None:
                continue
            before = len(self.classes)
            class_id = self.classes.id_of(label)
            if class_id is None:
                continue
            self._dirty |= len(self.classes) != before
            x0, y0, x1, y1 = (int(row[k]) for k in ("x_min", "y_min", "x_max", "y_max"))
            cx, cy = (x0 + x1 + 1) / 2 / width, (y0 + y1 + 1) / 2 / height
            w, h = (x1 - x0 + 1) / width, (y1 - y0 + 1) / height
            lines.append(f"{class_id} {cx:.6f} {cy:.6f} {w:.6f} {h:.6f}")
        return lines

    def flush(self) -> None:
        """Schedule ``data.yaml`` with the classes known now."""
        if not self._dirty:
            return
        val = "images/val" if self._val_every else f"images/{self._split}"
        self._yaml.schedule({"path": self.output_dir or ".", "train": f"images/{self._split}", "val": val,
                             "names": self.classes.names()})
        self._dirty = False

    def on_final_frame(self) -> None:
        self.flush()
