"""Merging the shards of a sharded run (``graphsdg run --workers K``) into one dataset.

Shards write their per-frame files straight into the writers' output folders,
named by the global frame index, so those need no merging. What each shard keeps
on its own is the writers' dataset-wide files, under
``<output_dir>/.graphsdg-shards/shard-<i>/``; this module combines them:

* CocoWriter: one ``coco_annotations_<id>.json``: images by id (``frame * products
  + product``), annotations ordered by image and numbered 1, 2, ...; categories
  numbered in first-seen order over the merged frames (as one process numbers
  them), with the panoptic images of a shard recoloured where its numbering differed.
* every other file a shard kept is moved into place (identical copies collapse).

Finally the shard folders are removed and ``graphsdg_index.json`` is written at the job's root. Output
folders and the root are local folders or ``s3://`` prefixes alike (:mod:`graphsdg.io.location`): a
sharded run on nodes that share no filesystem merges in the bucket.

Example:
    >>> doc, remaps = merge_coco_documents(
    ...     [{"images": [{"id": 1}], "annotations": [{"id": 1, "image_id": 1, "category_id": 1}],
    ...       "categories": [{"id": 1, "name": "a"}]},
    ...      {"images": [{"id": 0}], "annotations": [{"id": 1, "image_id": 0, "category_id": 1}],
    ...       "categories": [{"id": 1, "name": "b"}]}], auto_categories=True)
    >>> [(c["id"], c["name"]) for c in doc["categories"]], [(a["id"], a["image_id"]) for a in doc["annotations"]]
    ([(1, 'b'), (2, 'a')], [(1, 0), (2, 1)])
    >>> remaps
    [{1: 2}, {1: 1}]
"""
from __future__ import annotations

import io
import json
import os
import posixpath
from typing import Any

import numpy as np
from PIL import Image

from graphsdg.annotate.ids import color_of
from graphsdg.io.frame_plan import SHARD_FOLDER
from graphsdg.io import encode
from graphsdg.io.location import Location, open_location
from graphsdg.io.writers.coco import renumber_annotations

INDEX_FILE = "graphsdg_index.json"


class MergeError(RuntimeError):
    """Shards that cannot be combined into one dataset."""


def merge_coco_documents(docs: list[dict], auto_categories: bool) -> tuple[dict, list[dict[int, int]]]:
    """One COCO document from the shards' documents, and per shard its category id remap (old -> new)."""
    if not docs:
        raise MergeError("no COCO document to merge")
    merged: dict[str, Any] = {k: v for k, v in docs[0].items() if k not in ("images", "annotations", "categories")}
    images: dict[int, tuple[int, dict]] = {}
    for shard, doc in enumerate(docs):
        for image in doc.get("images", []):
            if int(image["id"]) in images and images[int(image["id"])][1] != image:
                raise MergeError(f"two shards wrote different COCO images with id {image['id']}")
            images.setdefault(int(image["id"]), (shard, image))
    owner = {i: shard for i, (shard, _) in images.items()}
    annotations = [(owner.get(int(a["image_id"]), shard), a) for shard, doc in enumerate(docs)
                   for a in doc.get("annotations", []) if owner.get(int(a["image_id"])) == shard]
    annotations.sort(key=lambda sa: int(sa[1]["image_id"]))        # stable: keeps each image's order
    names = [{int(c["id"]): c for c in doc.get("categories", [])} for doc in docs]
    remaps: list[dict[int, int]] = [{} for _ in docs]
    categories: dict[int, dict] = {}
    if auto_categories:   # first-seen order over the merged frames, as one process assigns them
        new_ids: dict[str, int] = {}
        order = [(shard, int(a["category_id"])) for shard, a in annotations]
        order += [(shard, cid) for shard in range(len(docs)) for cid in sorted(names[shard])]
        for shard, cid in order:
            cat = names[shard].get(cid)
            if cat is None:
                raise MergeError(f"shard {shard} annotates category {cid}, which its categories lack")
            new = new_ids.setdefault(cat["name"], len(new_ids) + 1)
            remaps[shard][cid] = new
            if new not in categories:
                categories[new] = {**cat, "id": new, "color": list(color_of(new + 2)[:3])}
    else:
        for shard, table in enumerate(names):
            for cid, cat in table.items():
                if cid in categories and categories[cid]["name"] != cat["name"]:
                    raise MergeError(f"shards disagree on COCO category {cid}: {categories[cid]['name']!r} "
                                     f"vs {cat['name']!r}")
                categories.setdefault(cid, cat)
                remaps[shard][cid] = cid
    merged["images"] = [images[i][1] for i in sorted(images)]
    merged["annotations"] = renumber_annotations(
        [{**a, "category_id": remaps[shard][int(a["category_id"])]} for shard, a in annotations])
    merged["categories"] = [categories[k] for k in sorted(categories)]
    return merged, remaps


def _recolour_panoptic(folder: Location, rel: str, remap: dict[int, int]) -> None:
    """Rewrite a panoptic PNG whose category colours follow a shard's numbering."""
    if not rel.endswith(".png"):
        raise MergeError(f"cannot recolour {folder.path_of(rel)}: shards numbered COCO categories differently and "
                         f"the panoptic image is not lossless; pass coco_categories to CocoWriter")
    image = np.array(Image.open(io.BytesIO(folder.read(rel))).convert("RGB"))
    out = np.zeros_like(image)
    for old, new in remap.items():
        out[np.all(image == color_of(old + 2)[:3], axis=-1)] = color_of(new + 2)[:3]
    folder.write(rel, encode.encode_image(out, ".png"))


def _merge_coco(folder: Location, records: list[dict]) -> list[str]:
    final = next(iter(records[0]["aggregates"]))
    docs = []
    for rec in records:
        if folder.exists(rec["aggregates"][final]):
            docs.append(json.loads(folder.read(rec["aggregates"][final])))
    if folder.exists(final):   # a resumed sharded run: frames merged before stay
        docs.insert(0, json.loads(folder.read(final)))
    merged, remaps = merge_coco_documents(docs, bool(records[0]["info"].get("auto_categories")))
    if records[0]["info"].get("panoptic"):
        owner = {}
        for shard, doc in enumerate(docs):
            for image in doc.get("images", []):
                owner.setdefault(int(image["id"]), shard)
        for image in merged["images"]:
            remap = remaps[owner[int(image["id"])]]
            if any(k != v for k, v in remap.items()):
                path, name = posixpath.split(image["file_name"].replace(os.sep, "/"))
                _recolour_panoptic(folder, posixpath.join(path, "panoptic_" + name[len("rgb_"):]), remap)
    folder.write(final, encode.encode_json(merged, indent=2))
    return [final]


MERGERS = {"CocoWriter": _merge_coco}


def _move_rest(folder: Location) -> None:
    """Move every file left in the shard folders into place; identical copies collapse."""
    for rel in folder.files(SHARD_FOLDER):
        # <SHARD_FOLDER>/shard-<i>/<path> -> <path>
        dst = rel.split("/", 2)[2] if rel.count("/") >= 2 else None
        if dst is None:
            continue
        if folder.exists(dst):
            if folder.read(rel) != folder.read(dst):
                raise MergeError(f"shards wrote different {dst} in {folder.url}")
            continue
        folder.move(rel, dst)
    folder.remove_tree(SHARD_FOLDER)


def merge_shards(shard_results: list[dict]) -> list[dict]:
    """Combine the writers' shard files of a sharded run; return one entry per output folder.

    Each output folder is a local folder or an ``s3://`` prefix (:mod:`graphsdg.io.location`).
    """
    by_dir: dict[str, list[dict]] = {}
    for result in shard_results:
        for rec in result.get("writers", []):
            by_dir.setdefault(rec["output_dir"], []).append(rec)
    datasets = []
    for output_dir, recs in sorted(by_dir.items()):
        kinds = {r["writer"] for r in recs}
        if len(kinds) > 1:
            raise MergeError(f"several writer types ({sorted(kinds)}) share the output folder {output_dir}")
        kind = kinds.pop()
        folder = open_location(output_dir)
        merger = MERGERS.get(kind)
        if merger is not None and any(r["aggregates"] for r in recs):
            merger(folder, recs)
            for rec in recs:
                for shard_path in rec["aggregates"].values():
                    folder.delete(shard_path)
        _move_rest(folder)
        folder.remove_leftovers()     # interrupted writes of an earlier, resumed attempt
        datasets.append({"writer": kind, "output_dir": output_dir})
    return datasets


def write_index(root: str, job: dict, datasets: list[dict]) -> str:
    """``graphsdg_index.json`` at ``root`` (a folder or an ``s3://`` prefix): the job and, per writer folder,
    its files with their sizes. Returns the index's path or URL."""
    top = open_location(root)
    entries = []
    for ds in datasets:
        folder = open_location(ds["output_dir"])
        files = {rel: size for rel, size in folder.files().items()
                 if not any(part.startswith(".") for part in rel.split("/"))}   # shard folders, temporaries
        entries.append({"writer": ds["writer"], "output_dir": folder.relative_to(top), "files": len(files),
                        "bytes": sum(files.values()), "sizes": files})
    top.write(INDEX_FILE, encode.encode_json({"job": job, "datasets": entries}, indent=2))
    return top.path_of(INDEX_FILE)
