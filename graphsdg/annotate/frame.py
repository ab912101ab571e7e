"""One render product's captured frame, as annotators see it.

A :class:`FrameView` holds the render passes of one product for one step and
derives, lazily and once, what several annotators share: which labelled prim
(the *semantic instance*) each pixel belongs to, their semantic and instance
ids. Because every id annotator reads these same tables, segmentation images,
box rows and mapping files always agree.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

import numpy as np
from pxr import Usd

from graphsdg.annotate.ids import BACKGROUND_ID, UNLABELLED_ID, IdTables, labels_key
from graphsdg.render.camera import CameraView
from graphsdg.render.rasterizer import RenderOutputs
from graphsdg.render.render_product import RenderProduct
from graphsdg.sim.scene import SimScene
from graphsdg.stage import semantics as semlib


@dataclass
class InstanceMap:
    """Semantic instances of the model for one semantic-type filter.

    ``geom_instance[g]`` is the index into ``paths`` of the instance that geom ``g``
    belongs to, or -1 if the geom has no label of the filtered types.
    """

    paths: list[str]                       # labelled prim path per instance
    labels: list[dict[str, list[str]]]     # filtered labels per instance
    instance_ids: np.ndarray               # uint32 stable id per instance
    semantic_ids: np.ndarray               # uint32 semantic id per instance
    geom_instance: np.ndarray              # int32 per geom
    semantic_labels: dict[int, dict[str, list[str]]]   # semantic id -> labels


def parse_semantic_types(types: Iterable[str] | None) -> tuple[str, ...] | None:
    """``None`` means every type."""
    if types is None:
        return None
    if isinstance(types, str):
        types = [types]
    out = tuple(str(t) for t in types)
    if not out or any(not t for t in out):
        raise ValueError(f"semanticTypes must be a non-empty list of type names, got {types!r}")
    return out


class SceneLabels:
    """Per-model cache of instance maps, rebuilt when the model or labels change."""

    def __init__(self, ids: IdTables) -> None:
        self.ids = ids
        self._key: tuple[int, int] | None = None
        self._maps: dict[tuple[str, ...] | None, InstanceMap] = {}

    def instance_map(self, sim: SimScene, stage: Usd.Stage, types: tuple[str, ...] | None) -> InstanceMap:
        key = (sim.model_version, sim.labels_version)
        if key != self._key:
            self._maps.clear()
            self._key = key
        found = self._maps.get(types)
        if found is None:
            found = self._maps[types] = self._build(sim, stage, types)
        return found

    def _build(self, sim: SimScene, stage: Usd.Stage, types: tuple[str, ...] | None) -> InstanceMap:
        compiled = sim.ensure_compiled()
        owner_of_geom: list[str | None] = []
        owners: dict[str, dict[str, list[str]]] = {}
        for path in compiled.geom_paths:
            prim = stage.GetPrimAtPath(path) if path else None
            owner = semlib.labelled_ancestor(prim, types) if prim else None
            if owner is None:
                owner_of_geom.append(None)
                continue
            opath = str(owner.GetPath())
            if opath not in owners:
                labels = semlib.labels(owner)
                owners[opath] = {t: v for t, v in labels.items() if types is None or t in types}
            owner_of_geom.append(opath)
        paths = sorted(owners)
        index = {p: i for i, p in enumerate(paths)}
        labels = [owners[p] for p in paths]
        instance_ids = np.array([self.ids.instance.id_of(p) for p in paths], dtype=np.uint32)
        semantic_ids = np.array([self.ids.semantic.id_of(labels_key(lab)) for lab in labels], dtype=np.uint32)
        geom_instance = np.array([index[o] if o is not None else -1 for o in owner_of_geom], dtype=np.int32)
        sem_labels = {int(s): lab for s, lab in zip(semantic_ids, labels)}
        return InstanceMap(paths=paths, labels=labels, instance_ids=instance_ids, semantic_ids=semantic_ids,
                           geom_instance=geom_instance, semantic_labels=sem_labels)


class FrameView:
    """The passes of one render product at one step, plus shared derived maps."""

    def __init__(self, rp: RenderProduct, view: CameraView, outputs: RenderOutputs, sim: SimScene,
                 stage: Usd.Stage, labels: SceneLabels, frame_index: int, sim_time: float) -> None:
        self.render_product = rp
        self.camera = view
        self.outputs = outputs
        self.sim = sim
        self.stage = stage
        self.labels = labels
        self.frame_index = frame_index
        self.sim_time = sim_time
        self._cache: dict[object, object] = {}

    @property
    def width(self) -> int:
        return self.camera.width

    @property
    def height(self) -> int:
        return self.camera.height

    def require(self, name: str) -> np.ndarray:
        value = getattr(self.outputs, name)
        if value is None:
            raise RuntimeError(f"render pass {name!r} was not rendered for {self.render_product.name}")
        return value

    def cached(self, key: object, build):
        """Compute ``build()`` once per frame under ``key``."""
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    def instance_map(self, types: tuple[str, ...] | None) -> InstanceMap:
        return self.labels.instance_map(self.sim, self.stage, types)

    def instance_image(self, types: tuple[str, ...] | None) -> np.ndarray:
        """int32 (H, W): instance index into ``instance_map(types).paths`` per pixel, -1 if none."""
        def build():
            geom_ids = self.require("geom_ids")
            imap = self.instance_map(types)
            lut = np.append(imap.geom_instance, -1).astype(np.int32)   # index -1 -> -1
            return lut[geom_ids]
        return self.cached(("instance_image", types), build)

    def semantic_image(self, types: tuple[str, ...] | None) -> np.ndarray:
        """uint32 (H, W): semantic id per pixel; 0 background, 1 unlabelled geometry."""
        def build():
            geom_ids = self.require("geom_ids")
            imap = self.instance_map(types)
            inst = self.instance_image(types)
            sem = np.where(geom_ids < 0, BACKGROUND_ID, UNLABELLED_ID).astype(np.uint32)
            has = inst >= 0
            sem[has] = imap.semantic_ids[inst[has]]
            return sem
        return self.cached(("semantic_image", types), build)

    def tight_boxes(self, types: tuple[str, ...] | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(instance indices, boxes (K, 4) inclusive x_min y_min x_max y_max, pixel counts) of visible instances."""
        def build():
            inst = self.instance_image(types)
            flat = inst.ravel()
            sel = np.nonzero(flat >= 0)[0]
            if sel.size == 0:
                return np.zeros(0, np.int64), np.zeros((0, 4), np.int32), np.zeros(0, np.int64)
            k = flat[sel]
            ys, xs = np.divmod(sel, self.width)
            n = len(self.instance_map(types).paths)
            xmin = np.full(n, np.iinfo(np.int64).max)
            ymin = np.full(n, np.iinfo(np.int64).max)
            xmax = np.full(n, -1)
            ymax = np.full(n, -1)
            np.minimum.at(xmin, k, xs)
            np.minimum.at(ymin, k, ys)
            np.maximum.at(xmax, k, xs)
            np.maximum.at(ymax, k, ys)
            counts = np.bincount(k, minlength=n)
            present = np.nonzero(counts)[0]
            boxes = np.stack([xmin[present], ymin[present], xmax[present], ymax[present]], 1).astype(np.int32)
            return present, boxes, counts[present]
        return self.cached(("tight_boxes", types), build)
