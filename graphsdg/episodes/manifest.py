"""A session file's manifest: its recordables' bindings, session metadata, sampling and conventions.

The manifest is what a replayer needs to rebuild a session without the script
that recorded it. It is stored as four JSON strings under ``/manifest`` of the
HDF5 file (``tracks``: one entry per recordable; ``session``; ``sampling``;
``coord_conventions``), and the file's root attribute ``schema_version`` says
which layout the file has (:data:`SCHEMA_VERSION`).
"""
from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field, is_dataclass
from typing import Any

import numpy as np

SCHEMA_VERSION = 2
MANIFEST_GROUP = "manifest"
MANIFEST_PARTS = ("tracks", "session", "sampling", "coord_conventions")


def _default_conventions() -> dict[str, Any]:
    return {"quaternion_order": "wxyz", "position_units": "meters", "angle_units": "radians"}


@dataclass
class SessionManifest:
    """The manifest of one session (see the module docstring)."""

    tracks: list[dict[str, Any]] = field(default_factory=list)
    session: dict[str, Any] = field(default_factory=dict)
    sampling: dict[str, Any] = field(default_factory=dict)
    coord_conventions: dict[str, Any] = field(default_factory=_default_conventions)

    def track_groups(self) -> list[str]:
        """The HDF5 group of every track, in recording order."""
        return [entry["group"] for entry in self.tracks]


def _check(manifest: SessionManifest) -> None:
    groups: set[str] = set()
    for i, entry in enumerate(manifest.tracks):
        for key in ("type", "group"):
            if key not in entry:
                raise ValueError(f"manifest track {i} ({entry!r}) has no {key!r}")
        if entry["group"] in groups:
            raise ValueError(f"manifest has two tracks for group {entry['group']!r}")
        groups.add(entry["group"])


def build_manifest(recordable_entries: Iterable[dict[str, Any]], *, sampling: dict[str, Any] | None = None,
                   session_metadata: dict[str, Any] | None = None,
                   coord_conventions: dict[str, Any] | None = None) -> SessionManifest:
    """A checked manifest of these track entries, sampling fields, session metadata and conventions."""
    manifest = SessionManifest(tracks=list(recordable_entries), session=dict(session_metadata or {}),
                               sampling=dict(sampling or {}))
    if coord_conventions is not None:
        manifest.coord_conventions = dict(coord_conventions)
    _check(manifest)
    return manifest


def _json_value(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if is_dataclass(obj) and not isinstance(obj, type):
        return asdict(obj)
    raise TypeError(f"manifest value {obj!r} of type {type(obj).__name__} cannot be written as JSON")


def write_manifest(h5_file: Any, manifest: SessionManifest) -> None:
    """Write ``manifest`` under ``/manifest`` of an open HDF5 file (replacing one there) and stamp the schema."""
    _check(manifest)
    h5_file.attrs["schema_version"] = SCHEMA_VERSION
    group = h5_file.require_group(MANIFEST_GROUP)
    for part in MANIFEST_PARTS:
        if part in group:
            del group[part]
        group.create_dataset(part, data=json.dumps(getattr(manifest, part), sort_keys=True, default=_json_value))


def read_manifest(h5_file: Any) -> SessionManifest:
    """The manifest of an open session file (ValueError for another schema or a missing part)."""
    version = int(h5_file.attrs.get("schema_version", 0))
    if version != SCHEMA_VERSION:
        raise ValueError(f"{getattr(h5_file, 'filename', 'the HDF5 file')} has schema_version {version}; episode "
                         f"sessions of schema {SCHEMA_VERSION} are read (earlier recorder files are not)")
    if MANIFEST_GROUP not in h5_file:
        raise ValueError(f"{getattr(h5_file, 'filename', 'the HDF5 file')} has no /{MANIFEST_GROUP} group")
    group = h5_file[MANIFEST_GROUP]
    missing = [part for part in MANIFEST_PARTS if part not in group]
    if missing:
        raise ValueError(f"{getattr(h5_file, 'filename', 'the HDF5 file')} lacks /{MANIFEST_GROUP}/{missing[0]}")

    def load(part: str) -> Any:
        raw = group[part][()]
        return json.loads(raw.decode("utf-8") if isinstance(raw, bytes) else raw)

    return SessionManifest(**{part: load(part) for part in MANIFEST_PARTS})
