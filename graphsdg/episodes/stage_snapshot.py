"""A USD copy of the stage next to recorded sessions. ``stage_snapshot.usd``, and a JSON note describing it.

Sessions in one folder share one snapshot; a session opened where the snapshot
already exists names it in its ``stage_snapshot`` root attribute, so a replay
can find the stage the episodes were recorded on.

Example:
    >>> import json, os, tempfile
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.cube(name="Cube")
    >>> folder = tempfile.mkdtemp()
    >>> path = export_stage_snapshot(folder)
    >>> os.path.basename(path), sorted(os.listdir(folder))
    ('stage_snapshot.usd', ['stage_snapshot.sidecar.json', 'stage_snapshot.usd'])
    >>> json.load(open(os.path.join(folder, "stage_snapshot.sidecar.json")))["stage_snapshot_flattened"]
    True
"""
from __future__ import annotations

import json
import logging
import os
from datetime import datetime, timezone

from graphsdg.stage.context import get_stage

STAGE_SNAPSHOT_BASENAME = "stage_snapshot"
SIDECAR_FORMAT_VERSION = 1
log = logging.getLogger("graphsdg.episodes")


def export_stage_snapshot(output_dir: str, *, basename: str = STAGE_SNAPSHOT_BASENAME, flatten: bool = True,
                          include_sidecar: bool = True) -> str:
    """Write the current stage to ``<output_dir>/<basename>.usd`` (flattened: self-contained; else the root
    layer only) and, with ``include_sidecar``, ``<basename>.sidecar.json``; returns the USD file's absolute path."""
    stage = get_stage()
    if stage is None:
        raise RuntimeError("export_stage_snapshot: there is no stage to export")
    folder = os.path.abspath(os.path.expanduser(str(output_dir)))
    os.makedirs(folder, exist_ok=True)
    usd_path = os.path.join(folder, f"{basename}.usd")
    layer = stage.Flatten() if flatten else stage.GetRootLayer()
    if not layer.Export(usd_path):
        raise RuntimeError(f"export_stage_snapshot: USD could not write {usd_path}")
    if include_sidecar:
        note = {"format_version": SIDECAR_FORMAT_VERSION, "stage_snapshot": os.path.basename(usd_path),
                "stage_snapshot_flattened": bool(flatten), "created_at": datetime.now(timezone.utc).isoformat()}
        sidecar = os.path.join(folder, f"{basename}.sidecar.json")
        try:
            with open(sidecar, "w", encoding="utf-8") as f:
                json.dump(note, f, indent=2, sort_keys=True)
        except OSError as exc:
            log.warning("export_stage_snapshot: could not write %s: %s", sidecar, exc)
    return usd_path
