"""Annotators Isaac Sim's extensions register on top of Replicator's: ``StableIdMap``, ``IsaacNoop``,
``IsaacReadSimulationTime`` and ``IsaacReadSystemTime``.

``StableIdMap`` maps the stable id of every gprim drawn by the scene to its prim path, in the RTX
renderer's byte layout: one 24-byte entry per gprim (the id as 128 bits, little endian, then the
path's byte length and byte offset as ``uint32``), the UTF-8 paths, and the entry count as a
``uint32`` in the last 4 bytes. The ids are those of ``instance_id_segmentation`` (one per rendered
gprim, stable for the run), so its images and the map agree.

Example:
    >>> import graphsdg as rep
    >>> "StableIdMap" in rep.annotators.get_registered_annotators()
    True
"""
from __future__ import annotations

import time

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry, AnnotatorSpec
from graphsdg.annotate.frame import FrameView

STABLE_ID_ENTRY = np.dtype([("stable_id", "<u4", (4,)), ("label_length", "<u4"), ("label_offset", "<u4")])


def encode_stable_id_map(mapping: dict[int, str]) -> np.ndarray:
    """``{stable id: prim path}`` as the StableIdMap byte buffer (uint8), ids in ascending order."""
    ids = sorted(mapping)
    labels = [mapping[i].encode("utf-8") for i in ids]
    entries = np.zeros(len(ids), dtype=STABLE_ID_ENTRY)
    offset = len(ids) * STABLE_ID_ENTRY.itemsize
    for row, (stable_id, label) in enumerate(zip(ids, labels)):
        entries[row]["stable_id"] = [(stable_id >> (32 * k)) & 0xFFFFFFFF for k in range(4)]
        entries[row]["label_length"] = len(label)
        entries[row]["label_offset"] = offset
        offset += len(label)
    buffer = entries.tobytes() + b"".join(labels) + np.uint32(len(ids)).tobytes()
    return np.frombuffer(buffer, dtype=np.uint8).copy()


def decode_stable_id_map(buffer: np.ndarray | bytes) -> dict[int, str]:
    """The inverse of :func:`encode_stable_id_map` (what Isaac's ``parse_stable_id_map_data`` reads)."""
    raw = bytes(buffer) if not isinstance(buffer, np.ndarray) else buffer.tobytes()
    count = int(np.frombuffer(raw[-4:], dtype="<u4")[0])
    entries = np.frombuffer(raw[:count * STABLE_ID_ENTRY.itemsize], dtype=STABLE_ID_ENTRY)
    out = {}
    for entry in entries:
        stable_id = sum(int(word) << (32 * k) for k, word in enumerate(entry["stable_id"]))
        start = int(entry["label_offset"])
        out[stable_id] = raw[start:start + int(entry["label_length"])].decode("utf-8")
    return out


def stable_id_map(frame: FrameView, params: dict) -> dict:
    """uint8 byte buffer: stable id (``instance_id_segmentation``'s per-gprim id) -> prim path of every drawn
    gprim, in the RTX StableIdMap layout (module doc)."""
    _, paths = frame.labels.mesh_id_table(frame.sim)
    return {"data": encode_stable_id_map(paths)}


def noop(frame: FrameView, params: dict) -> dict:
    """Nothing: Isaac's ``IsaacNoop`` only keeps a writer's graph ticking each frame."""
    return {"info": {}}


def read_simulation_time(frame: FrameView, params: dict) -> dict:
    """``simulationTime``: the simulated seconds of the captured frame (0 again after the timeline stops)."""
    return {"info": {"simulationTime": float(frame.sim_time)}}


def _validate_reset_on_stop(params: dict) -> None:
    if not params.get("resetOnStop", True):
        raise ValueError("IsaacReadSimulationTime(resetOnStop=False) asks for a simulation time that keeps rising "
                         "across timeline stops; graphsdg's simulation clock restarts at each stop and keeps no "
                         "such total. Use resetOnStop=True (the time since play)")


def read_system_time(frame: FrameView, params: dict) -> dict:
    """``systemTime``: the wall-clock seconds (Unix time) when the frame's annotators ran."""
    return {"info": {"systemTime": time.time()}}


AnnotatorRegistry.register_spec(AnnotatorSpec(name="StableIdMap", passes=frozenset(), compute=stable_id_map,
                                              doc=stable_id_map.__doc__))
AnnotatorRegistry.register_spec(AnnotatorSpec(name="IsaacNoop", passes=frozenset(), compute=noop, doc=noop.__doc__))
AnnotatorRegistry.register_spec(AnnotatorSpec(name="IsaacReadSimulationTime", passes=frozenset(),
                                              compute=read_simulation_time, defaults={"resetOnStop": True},
                                              validate=_validate_reset_on_stop, doc=read_simulation_time.__doc__,
                                              pixels_only=True))
AnnotatorRegistry.register_spec(AnnotatorSpec(name="IsaacReadSystemTime", passes=frozenset(),
                                              compute=read_system_time, doc=read_system_time.__doc__))
