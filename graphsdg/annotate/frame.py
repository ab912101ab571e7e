"""One render product's captured frame, as annotators see it.

A :class:`FrameView` holds the render passes of one product for one step and
derives, lazily and once, what several annotators share: which labelled prim
(the *semantic instance*) each pixel belongs to, their semantic and instance
ids, tight boxes, the unoccluded footprint of every instance in view (loose
boxes and occlusion ratios), world points and normals. Because every id
annotator reads these same tables, segmentation images, box rows and mapping
files always agree.

Semantic instances: a gprim belongs to its nearest ancestor-or-self that has
labels of its own, passes the semantic filter with its inherited labels, and
contributes at least one of the matching labels. Its labels are the matching
ones (Replicator's ``matchingLabels``), several per type kept as a list.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
from pxr import Usd

from graphsdg.annotate.ids import BACKGROUND_ID, UNLABELLED_ID, IdTables, color_of, labels_key, sorted_unique
from graphsdg.annotate.motion import PoseSnapshot, history
from graphsdg.annotate.semantic_filter import ALL_LABELS, SemanticFilter
from graphsdg.imaging.label_image import label_image
from graphsdg.render.camera import CameraView
from graphsdg.render.lookup import lookup
from graphsdg.render.backend import RenderOutputs
from graphsdg.render.raycast import surface_normals
from graphsdg.render.render_product import RenderProduct
from graphsdg.sim import geom_subsets
from graphsdg.sim.scene import SimScene
from graphsdg.sim.visual import drawn_geom_mask
from graphsdg.stage import semantics as semlib


@dataclass
class InstanceMap:
    """Semantic instances of the model for one semantic filter.

    ``geom_instance[g]`` is the index into ``paths`` of the instance that geom ``g``
    belongs to, or -1 if the geom belongs to no instance passing the filter.
    """

    paths: list[str]                       # labelled prim path per instance
    labels: list[dict[str, list[str]]]     # matching labels per instance
    instance_ids: np.ndarray               # uint32 stable id per instance
    semantic_ids: np.ndarray               # uint32 semantic id per instance
    geom_instance: np.ndarray              # int32 per geom
    semantic_labels: dict[int, dict[str, list[str]]]   # semantic id -> labels
    # values derived from the fields above (per-geom lookup tables...), kept as long as the map is: a map
    # is rebuilt when the labels or the model change, and the same one serves every frame until then
    _derived: dict = field(default_factory=dict, repr=False, compare=False)

    def geoms_of(self, index: int) -> np.ndarray:
        return np.nonzero(self.geom_instance == index)[0]

    def derived(self, key: object, build: Callable[[], Any]) -> Any:
        """``build()`` once for this map under ``key`` (a table every frame would otherwise rebuild)."""
        found = self._derived.get(key)
        if found is None:
            found = self._derived[key] = build()
        return found

    def id_lut(self, kind: str) -> np.ndarray:
        """geom index -> ``"semantic"`` or ``"instance"`` id (unlabelled geoms 1), with index -1 (the
        background) -> 0."""
        def build():
            per_instance = self.semantic_ids if kind == "semantic" else self.instance_ids
            lut = np.full(len(self.geom_instance) + 1, UNLABELLED_ID, dtype=np.uint32)
            labelled = self.geom_instance >= 0
            lut[:-1][labelled] = per_instance[self.geom_instance[labelled]]
            lut[-1] = BACKGROUND_ID
            lut.flags.writeable = False
            return lut
        return self.derived(("id_lut", kind), build)


@dataclass
class Footprints:
    """Unoccluded (isolated) renders of the instances of one filter, by instance index.

    ``counts[k]`` pixels of instance ``k`` in view with nothing in front;
    ``boxes[k]`` their inclusive pixel bounds (-1 when not in view).
    """

    counts: np.ndarray     # int64 (n,)
    boxes: np.ndarray      # int32 (n, 4) x_min y_min x_max y_max
    masks: dict = None     # k -> (x0, y0, x1, y1) crop and its bool mask (the full silhouette)


def id_palette(imap: InstanceMap, kind: str) -> np.ndarray:
    """Packed RGBA (uint32) of each geom index's ``"semantic"``/``"instance"`` id of ``imap``, coloured with
    :func:`graphsdg.annotate.ids.color_of`, the background's last (index -1): the colorized id image is this at
    each pixel's geom. Kept with the map, so it is the same array every frame until the labels change."""
    def build():
        ids = imap.id_lut(kind)
        # one colour per distinct id, spread over the geoms (a Python step per geom cost ~1 us each: 5 ms
        # a frame at 5,000 assets)
        distinct, slot = np.unique(ids, return_inverse=True)
        rgba = np.array([color_of(int(v)) for v in distinct.tolist()], dtype=np.uint8).reshape(-1, 4)[slot]
        packed = np.ascontiguousarray(rgba).view(np.uint32)[:, 0]
        packed.flags.writeable = False
        return packed
    return imap.derived(("palette", kind), build)


class SceneLabels:
    """Per-model cache of instance maps, rebuilt when the model or labels change."""

    def __init__(self, ids: IdTables) -> None:
        self.ids = ids
        self._key: tuple[int, int, bool] | None = None
        self._maps: dict[str, InstanceMap] = {}
        self._mesh_table: tuple[int, np.ndarray, dict[int, str]] | None = None

    def mesh_id_table(self, sim: SimScene) -> tuple[np.ndarray, dict[int, str]]:
        """(geom index -> mesh id, with index -1 -> background; mesh id -> gprim path) of the compiled model.

        Mesh ids are assigned once per prim path and never reused, so the table is
        built once per compile instead of once per frame (a Python step per geom).
        """
        key = sim.model_version
        if self._mesh_table is None or self._mesh_table[0] != key:
            paths = sim.ensure_compiled().geom_paths
            table = self.ids.mesh
            lut = np.array([table.id_of(p) if p else UNLABELLED_ID for p in paths] + [BACKGROUND_ID],
                           dtype=np.uint32)
            self._mesh_table = (key, lut, {table.id_of(p): p for p in paths if p})
        return self._mesh_table[1], self._mesh_table[2]

    def instance_map(self, sim: SimScene, stage: Usd.Stage, semantic_filter: SemanticFilter) -> InstanceMap:
        key = (sim.model_version, sim.labels_version, geom_subsets.per_subset_segmentation())
        if key != self._key:
            self._maps.clear()
            self._key = key
        found = self._maps.get(semantic_filter.text)
        if found is None:
            found = self._maps[semantic_filter.text] = self._build(sim, stage, semantic_filter)
        return found

    def _build(self, sim: SimScene, stage: Usd.Stage, semantic_filter: SemanticFilter) -> InstanceMap:
        compiled = sim.ensure_compiled()
        owners: dict[str, dict[str, list[str]]] = {}
        owner_of_prim: dict[str, str | None] = {}
        owner_of_geom: list[str | None] = []
        for path in compiled.geom_paths:
            prim = geom_subsets.segmentation_prim(stage.GetPrimAtPath(path)) if path else None
            owner = _owner(prim, semantic_filter, owner_of_prim, owners) if prim else None
            owner_of_geom.append(owner)
        paths = sorted(owners)
        index = {p: i for i, p in enumerate(paths)}
        labels = [owners[p] for p in paths]
        instance_ids = np.array([self.ids.instance.id_of(p) for p in paths], dtype=np.uint32)
        semantic_ids = np.array([self.ids.semantic.id_of(labels_key(lab)) for lab in labels], dtype=np.uint32)
        geom_instance = np.array([index[o] if o is not None else -1 for o in owner_of_geom], dtype=np.int32)
        sem_labels = {int(s): lab for s, lab in zip(semantic_ids, labels)}
        return InstanceMap(paths=paths, labels=labels, instance_ids=instance_ids, semantic_ids=semantic_ids,
                           geom_instance=geom_instance, semantic_labels=sem_labels)


def _owner(prim: Usd.Prim, semantic_filter: SemanticFilter, memo: dict[str, str | None],
           owners: dict[str, dict[str, list[str]]]) -> str | None:
    """Path of the semantic instance ``prim`` belongs to (see the module docstring), or None."""
    path = str(prim.GetPath())
    if path in memo:
        return memo[path]
    found: str | None = None
    direct = semlib.direct_labels(prim)
    if direct:
        matched = semantic_filter.match(semlib.labels(prim))
        if matched and any(v in matched.get(t, ()) for t, vals in direct.items() for v in vals):
            found = path
            owners[path] = matched
    if found is None:
        parent = prim.GetParent()
        found = _owner(parent, semantic_filter, memo, owners) if parent and not parent.IsPseudoRoot() else None
    memo[path] = found
    return found


class FrameView:
    """The passes of one render product at one step, plus shared derived maps."""

    def __init__(self, rp: RenderProduct, view: CameraView, outputs: RenderOutputs | None, sim: SimScene,
                 stage: Usd.Stage, labels: SceneLabels, frame_index: int, sim_time: float,
                 attached: frozenset[str] = frozenset()) -> None:
        self.render_product = rp
        self.attached = attached          # names of the annotator types computed for this product now
        self.camera = view
        self.outputs = outputs
        self.sim = sim
        self.stage = stage
        self.labels = labels
        self.frame_index = frame_index
        self.sim_time = sim_time
        self._cache: dict[object, object] = {}
        # The poses of this capture become the next capture's "previous" (motion vectors).
        self.poses = PoseSnapshot.capture(sim, view, frame_index)
        self.previous: PoseSnapshot | None = history.swap(rp, self.poses)

    @property
    def width(self) -> int:
        return self.camera.width

    @property
    def height(self) -> int:
        return self.camera.height

    def require(self, name: str) -> np.ndarray:
        value = getattr(self.outputs, name) if self.outputs is not None else None
        if value is None:
            raise RuntimeError(f"render pass {name!r} was not rendered for {self.render_product.name}; the "
                               f"annotator spec must list it in its passes")
        return value

    def ids_through(self, per_geom: np.ndarray) -> np.ndarray:
        """``per_geom[geom id]`` at every pixel (the background, id -1, reads the table's last entry).

        One lookup of the codes as read back, through ``per_geom`` composed with
        the code -> geom table, instead of a geom-id image and then a lookup.
        """
        coded = self._id_codes()
        if coded is None:
            return per_geom[self.require("geom_ids")]
        codes, code_to_geom = coded
        return lookup(per_geom[code_to_geom], codes)

    def _id_codes(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The id pass as read back: (codes, code -> geom table), or None when only geom ids exist."""
        if self.outputs is None or self.outputs.id_lut is None:
            return None
        codes = self.outputs.id_codes
        return None if codes is None else (codes, self.outputs.id_lut)

    def _code_boxes(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The renderer's pixel bounds of each id code and the code -> geom table, or None where it made none
        (:class:`~graphsdg.render.backend.RenderOutputs`)."""
        if self.outputs is None or self.outputs.id_lut is None:
            return None
        boxes = self.outputs.code_boxes
        return None if boxes is None else (boxes, self.outputs.id_lut)

    def cached(self, key: object, build):
        """Compute ``build()`` once per frame under ``key``."""
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    # ---- instances -----------------------------------------------------
    def instance_map(self, semantic_filter: SemanticFilter = ALL_LABELS) -> InstanceMap:
        """Labelled instances and their geoms, as of this capture (kept for the frame once looked up)."""
        return self.cached(("instance_map", semantic_filter.text),
                           lambda: self.labels.instance_map(self.sim, self.stage, semantic_filter))

    def instance_image(self, semantic_filter: SemanticFilter = ALL_LABELS) -> np.ndarray:
        """int32 (H, W): instance index into ``instance_map(f).paths`` per pixel, -1 if none."""
        def build():
            imap = self.instance_map(semantic_filter)
            return self.ids_through(np.append(imap.geom_instance, -1).astype(np.int32))   # index -1 -> -1
        return self.cached(("instance_image", semantic_filter.text), build)

    def semantic_image(self, semantic_filter: SemanticFilter = ALL_LABELS) -> np.ndarray:
        """uint32 (H, W): semantic id per pixel; 0 background, 1 unlabelled geometry."""
        return self.cached(("semantic_image", semantic_filter.text),
                           lambda: self._id_image(semantic_filter, "semantic"))

    def instance_id_image(self, semantic_filter: SemanticFilter = ALL_LABELS) -> np.ndarray:
        """uint32 (H, W): instance id per pixel; 0 background, 1 unlabelled geometry."""
        return self.cached(("instance_id_image", semantic_filter.text),
                           lambda: self._id_image(semantic_filter, "instance"))

    def colorized_id_image(self, kind: str, semantic_filter: SemanticFilter) -> np.ndarray:
        """uint8 (H, W, 4): the ``"semantic"``/``"instance"`` id image already coloured with
        :func:`graphsdg.annotate.ids.color_of`, in one lookup per pixel (geom -> packed RGBA) instead of ids
        then colours; a :class:`~graphsdg.imaging.label_image.LabelImage` (its PNG's rows stored unfiltered)."""
        palette = id_palette(self.instance_map(semantic_filter), kind)
        made = self.outputs.id_colours(palette) if self.outputs is not None else None
        if made is not None:       # coloured where the ids were drawn (the pbr backend's device PNGs)
            return made
        packed = self.ids_through(palette)
        return label_image(packed.view(np.uint8).reshape(*packed.shape, 4))

    def _id_image(self, semantic_filter: SemanticFilter, kind: str) -> np.ndarray:
        return self.ids_through(self.instance_map(semantic_filter).id_lut(kind))   # one lookup per pixel

    def present_geoms(self) -> np.ndarray:
        """Geom ids drawn in this frame (-1 included when background shows): from the renderer's code bounds
        where it made them, else from the runs, not every pixel."""
        def build():
            coded = self._code_boxes()
            if coded is None:
                return sorted_unique(self.runs()[2])
            boxes, code_to_geom = coded
            return sorted_unique(code_to_geom[np.flatnonzero(boxes[:, 2] >= 0)])
        return self.cached("present_geoms", build)

    def runs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Horizontal runs of equal geom id in the id image: (flat start, flat end inclusive, geom id)."""
        def build():
            coded = self._id_codes()
            if coded is None:
                return _runs(self.require("geom_ids"))
            codes, code_to_geom = coded
            starts, ends, run_codes = _runs(codes)   # runs of equal code are runs of equal geom
            return starts, ends, code_to_geom[run_codes]
        return self.cached("runs", build)

    def present_ids(self, kind: str, semantic_filter: SemanticFilter = ALL_LABELS) -> np.ndarray:
        """Sorted distinct ``"semantic"`` or ``"instance"`` ids in this frame, from the drawn geoms
        (one histogram of the id image shared by every id annotator, not one scan each)."""
        def build():
            return sorted_unique(self.instance_map(semantic_filter).id_lut(kind)[self.present_geoms()])
        return self.cached(("present_ids", kind, semantic_filter.text), build)

    # ---- boxes and occlusion -------------------------------------------
    def visible_counts(self, semantic_filter: SemanticFilter = ALL_LABELS) -> np.ndarray:
        """int64 (n,): visible pixels per instance."""
        def build():
            inst = self.instance_image(semantic_filter)
            n = len(self.instance_map(semantic_filter).paths)
            return np.bincount(inst.ravel() + 1, minlength=n + 1)[1:]   # slot 0 holds the -1 pixels
        return self.cached(("visible_counts", semantic_filter.text), build)

    def tight_boxes(self, semantic_filter: SemanticFilter = ALL_LABELS
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(instance indices, boxes (K, 4) inclusive x_min y_min x_max y_max, None) of visible instances."""
        def build():
            imap = self.instance_map(semantic_filter)
            n = len(imap.paths)
            # Boxes of each drawn geom straight from the id image (no per-pixel instance lookup),
            # then each instance's box is the union of its geoms' boxes.
            geom_boxes = self.geom_boxes()
            drawn = np.flatnonzero(geom_boxes[:, 2] >= 0)
            owner = imap.geom_instance[drawn] if drawn.size else np.zeros(0, dtype=np.int32)
            keep = owner >= 0
            drawn, owner = drawn[keep], owner[keep]
            if imap.derived("one_geom_each", lambda: bool((np.bincount(imap.geom_instance[imap.geom_instance >= 0],
                                                                        minlength=1) <= 1).all())):
                order = np.argsort(owner, kind="stable")   # an instance's box is its one geom's
                return owner[order].astype(np.intp), geom_boxes[drawn[order]].astype(np.int32, copy=False), None
            big = np.iinfo(np.int32).max
            lo = np.full((n, 2), big, dtype=np.int32)
            hi = np.full((n, 2), -1, dtype=np.int32)
            np.minimum.at(lo, owner, geom_boxes[drawn, :2])
            np.maximum.at(hi, owner, geom_boxes[drawn, 2:])
            present = np.flatnonzero(hi[:, 0] >= 0)
            boxes = np.concatenate([lo[present], hi[present]], axis=1)
            return present, boxes, None
        return self.cached(("tight_boxes", semantic_filter.text), build)

    def geom_boxes(self) -> np.ndarray:
        """(ngeom, 4) inclusive pixel bounds of every geom drawn in the id pass (-1 rows if not drawn)."""
        def build():
            ngeom = self.sim.model.ngeom
            coded = self._code_boxes()
            if coded is None:
                return _run_boxes(self.runs(), self.width, ngeom)
            return _geom_boxes_of_codes(*coded, ngeom)
        return self.cached("geom_boxes", build)

    def footprints(self, semantic_filter: SemanticFilter = ALL_LABELS) -> Footprints:
        """Unoccluded footprint of every instance in view, from isolated id renders.

        Each instance is drawn with every other geom hidden, cropped to a
        conservative pixel rectangle of its geoms' bounding spheres. Instances
        whose rectangles do not overlap share one render (their footprints cannot
        touch), so the number of renders is the number of overlap groups, not of
        instances. Instances whose rectangle misses the image are not in view.
        """
        def build():
            imap = self.instance_map(semantic_filter)
            n = len(imap.paths)
            counts = np.zeros(n, dtype=np.int64)
            boxes = np.full((n, 4), -1, dtype=np.int32)
            render = self.outputs.render_isolated if self.outputs is not None else None
            if render is None:
                raise RuntimeError("isolated renders need the segmentation pass")
            masks: dict[int, tuple[tuple[int, int, int, int], np.ndarray]] = {}
            shown = np.zeros(self.sim.model.ngeom, dtype=bool)
            shown[self.drawn_geoms()] = True
            rects = self._geom_rects()
            members: list[tuple[int, np.ndarray, tuple[int, int, int, int]]] = []
            for k in range(n):
                geoms = imap.geoms_of(k)
                geoms = geoms[shown[geoms]]
                crop = _union_crop(rects[geoms], self.width, self.height) if geoms.size else None
                if crop is not None:
                    members.append((k, geoms, crop))
            for group in _disjoint_groups(members):
                crops = np.array([c for _, _, c in group])
                x0, y0 = crops[:, :2].min(0)
                x1, y1 = crops[:, 2:].max(0)
                ids = render(np.concatenate([g for _, g, _ in group]), (int(x0), int(y0), int(x1), int(y1)))
                for k, geoms, crop in group:
                    part = ids[crop[1] - y0:crop[3] - y0, crop[0] - x0:crop[2] - x0]
                    mask = np.isin(part, geoms)
                    masks[k] = (tuple(int(c) for c in crop), mask)
                    counts[k] = int(mask.sum())
                    if counts[k]:
                        ys, xs = np.nonzero(mask)
                        boxes[k] = (xs.min() + crop[0], ys.min() + crop[1], xs.max() + crop[0], ys.max() + crop[1])
            # Guard against a pixel drawn in the full render but not the isolated one (the two
            # frusta differ in the last float bit): the footprint always covers the visible part.
            visible = self.visible_counts(semantic_filter)
            _, tight, _ = self.tight_boxes(semantic_filter)
            present = np.nonzero(visible)[0]
            counts = np.maximum(counts, visible)
            for k, box in zip(present, tight):
                if boxes[k, 0] < 0:
                    boxes[k] = box
                else:
                    boxes[k, :2] = np.minimum(boxes[k, :2], box[:2])
                    boxes[k, 2:] = np.maximum(boxes[k, 2:], box[2:])
            return Footprints(counts=counts, boxes=boxes, masks=masks)
        return self.cached(("footprints", semantic_filter.text), build)

    def occlusion_ratios(self, semantic_filter: SemanticFilter = ALL_LABELS) -> np.ndarray:
        """float32 (n,): occluded / unoccluded pixels per instance in view; NaN when not in view."""
        def build():
            fp = self.footprints(semantic_filter)
            visible = self.visible_counts(semantic_filter)
            ratio = np.full(len(fp.counts), np.nan, dtype=np.float64)
            inview = fp.counts > 0
            ratio[inview] = 1.0 - visible[inview] / fp.counts[inview]
            return np.clip(ratio, 0.0, 1.0).astype(np.float32)
        return self.cached(("occlusion", semantic_filter.text), build)

    def drawn_geoms(self) -> np.ndarray:
        """Ids of the geoms the rasteriser draws (not hidden, not collision-only)."""
        return np.flatnonzero(drawn_geom_mask(self.sim.model))

    def _geom_rects(self) -> np.ndarray:
        """(ngeom, 4) conservative pixel rectangles of every geom's bounding sphere (NaN: behind)."""
        def build():
            m, d = self.sim.model, self.sim.data
            radii = np.asarray(m.geom_rbound, dtype=np.float64).copy()
            rects = self.camera.sphere_pixel_bounds(d.geom_xpos, radii)
            rects[radii <= 0] = (0, 0, self.width, self.height)   # rbound 0: unbounded geom
            return rects
        return self.cached("geom_rects", build)

    # ---- geometry ------------------------------------------------------
    def world_points(self) -> np.ndarray:
        """float64 (H, W, 3): world position of each pixel centre's surface (inf on background)."""
        return self.cached("world_points", lambda: self.camera.unproject(self.require("depth")))

    def normals(self) -> np.ndarray:
        """float32 (H, W, 3): world-space unit surface normals facing the camera; 0 on background."""
        return self.cached("normals", lambda: surface_normals(self.sim, self.camera, self.require("geom_ids")))


def _runs(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Horizontal runs of equal label in a (H, W) label image: flat start, flat end (inclusive), label."""
    h, w = labels.shape
    if h == 0 or w == 0:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, empty.astype(labels.dtype)
    # run starts: every row's first pixel, and where the label changes along a row
    change = np.empty((h, w), dtype=bool)
    change[:, 0] = True
    np.not_equal(labels[:, 1:], labels[:, :-1], out=change[:, 1:])
    starts = np.flatnonzero(change)
    ends = np.empty_like(starts)
    ends[:-1] = starts[1:] - 1   # a run ends where the next one starts
    ends[-1] = h * w - 1
    return starts, ends, labels.ravel()[starts]


def _run_boxes(runs: tuple[np.ndarray, np.ndarray, np.ndarray], w: int, n: int) -> np.ndarray:
    """(n, 4) inclusive pixel bounds of each label >= 0 of an image of width ``w``, from its runs.

    Only the ends of horizontal runs can be extreme: the left end of every run gives
    x_min (and every row a label touches has one, so y_min / y_max), the right end
    gives x_max. Scanning run ends instead of every labelled pixel makes the
    scatter-min/max work proportional to the objects' outlines, not their areas.
    """
    boxes = np.full((n, 4), -1, dtype=np.int32)
    starts, ends, labels = runs
    if n == 0 or not labels.size:
        return boxes
    sy, sx = np.divmod(starts, w)
    # slot 0 collects the unlabelled runs (label -1), so no run is filtered out first (four one-dimensional
    # scatters: NumPy's fast path; a scatter of (x, y) rows is ~10 times slower)
    slot = labels + 1
    big = np.iinfo(np.int64).max
    lo_x, lo_y = np.full(n + 1, big), np.full(n + 1, big)
    hi_x, hi_y = np.full(n + 1, -1), np.full(n + 1, -1)
    np.minimum.at(lo_x, slot, sx)
    np.minimum.at(lo_y, slot, sy)
    np.maximum.at(hi_y, slot, sy)
    np.maximum.at(hi_x, slot, ends % w)
    present = hi_x[1:] >= 0
    boxes[present] = np.stack([lo_x[1:], lo_y[1:], hi_x[1:], hi_y[1:]], 1)[present]
    return boxes


def _geom_boxes_of_codes(code_boxes: np.ndarray, code_to_geom: np.ndarray, ngeom: int) -> np.ndarray:
    """(ngeom, 4) inclusive pixel bounds of each geom (-1 rows: not drawn) from its id code's bounds."""
    boxes = np.full((ngeom, 4), -1, dtype=np.int32)
    drawn = np.flatnonzero(code_boxes[:, 2] >= 0)
    geoms = code_to_geom[drawn]
    keep = geoms >= 0
    boxes[geoms[keep]] = code_boxes[drawn[keep]]
    return boxes


def _disjoint_groups(members: list) -> list[list]:
    """Greedy packing of ``(index, geoms, crop)`` members into groups of pairwise disjoint crops."""
    groups: list[list] = []
    for member in members:
        x0, y0, x1, y1 = member[2]
        for group in groups:
            if all(x1 <= c[0] or c[2] <= x0 or y1 <= c[1] or c[3] <= y0 for _, _, c in group):
                group.append(member)
                break
        else:
            groups.append([member])
    return groups


def _union_crop(rects: np.ndarray, width: int, height: int) -> tuple[int, int, int, int] | None:
    """Integer pixel rectangle covering ``rects`` (float x0 y0 x1 y1), clipped to the image; None if empty."""
    rects = rects[~np.isnan(rects).any(axis=1)]
    if rects.size == 0:
        return None
    x0 = max(int(np.floor(rects[:, 0].min())), 0)
    y0 = max(int(np.floor(rects[:, 1].min())), 0)
    x1 = min(int(np.ceil(rects[:, 2].max())) + 1, width)
    y1 = min(int(np.ceil(rects[:, 3].max())) + 1, height)
    if x0 >= x1 or y0 >= y1:
        return None
    return x0, y0, x1, y1
