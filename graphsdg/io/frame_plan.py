"""Which frames of an ``orchestrator.run(num_frames)`` this process captures: shards and resumed runs.

A plain run captures frames ``0 .. num_frames-1`` one after the other. With a
plan (``graphsdg run --workers K`` / ``--resume``) the run instead visits the
frames it owns: shard ``i`` of ``K`` owns the frames ``i, i + K, i + 2K, ...``;
a resumed run skips the frames its writers already find complete on disk. Before
each frame that does not directly follow the previous one, the graph scheduler
seeks to it (``graphsdg.graph.seek``), so the frame holds the same random values
as in one uninterrupted run; writers receive the frame's global number as
``data["frame_index"]`` and name their files by it.

The plan lives in settings, so ``graphsdg run`` sets it before the script runs:

* ``/graphsdg/run/shardIndex``, ``/graphsdg/run/shardCount`` (default 0 of 1),
* ``/graphsdg/run/resume`` (default False).

Example:
    >>> from graphsdg import settings
    >>> from graphsdg.io import frame_plan
    >>> settings.set("/graphsdg/run/shardIndex", 1); settings.set("/graphsdg/run/shardCount", 3)
    >>> [f for f in range(8) if frame_plan.current().owns(f)]
    [1, 4, 7]
    >>> settings.set("/graphsdg/run/shardIndex", 0); settings.set("/graphsdg/run/shardCount", 1)
    >>> frame_plan.current() is None
    True
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

from graphsdg.base import settings_store as settings
from graphsdg.io.object_store import is_s3_url

SHARD_FOLDER = ".graphsdg-shards"   # per-shard aggregate files, inside a writer's output folder


@dataclass(frozen=True)
class FramePlan:
    """Shard ``shard_index`` of ``shard_count``; ``resume`` skips frames complete on disk."""

    shard_index: int = 0
    shard_count: int = 1
    resume: bool = False

    def __post_init__(self) -> None:
        if not (isinstance(self.shard_count, int) and self.shard_count >= 1):
            raise ValueError(f"shard count must be a positive integer, got {self.shard_count!r}")
        if not (isinstance(self.shard_index, int) and 0 <= self.shard_index < self.shard_count):
            raise ValueError(f"shard index must be in 0..{self.shard_count - 1}, got {self.shard_index!r}")

    @property
    def sharded(self) -> bool:
        return self.shard_count > 1

    def owns(self, frame: int) -> bool:
        """Whether this shard captures global frame ``frame``."""
        return frame % self.shard_count == self.shard_index


def current() -> FramePlan | None:
    """The plan set in settings, or None for a plain run."""
    plan = FramePlan(int(settings.get("/graphsdg/run/shardIndex", 0) or 0),
                     int(settings.get("/graphsdg/run/shardCount", 1) or 1),
                     bool(settings.get("/graphsdg/run/resume", False)))
    return plan if plan.sharded or plan.resume else None


def set_plan(plan: FramePlan | None) -> None:
    """Install ``plan`` (None: plain runs)."""
    plan = plan or FramePlan()
    settings.set("/graphsdg/run/shardIndex", plan.shard_index)
    settings.set("/graphsdg/run/shardCount", plan.shard_count)
    settings.set("/graphsdg/run/resume", plan.resume)


def resuming() -> bool:
    """True in a resumed run (writers adopt what is on disk instead of starting over)."""
    return bool(settings.get("/graphsdg/run/resume", False))


def aggregate_path(path: str) -> str:
    """Where a writer keeps an aggregate file (a dataset-wide json) in this process.

    In a sharded run each shard keeps its own under ``.graphsdg-shards/shard-<i>/``;
    the merge step combines them into ``path``. Otherwise ``path`` itself.
    """
    plan = current()
    if plan is None or not plan.sharded:
        return path
    return f"{SHARD_FOLDER}/shard-{plan.shard_index:04d}/{path}"


@dataclass
class WriterRecord:
    """What the merge step needs to know about one writer of one shard."""

    writer: str
    output_dir: str
    aggregates: dict[str, str] = field(default_factory=dict)   # final path -> this shard's path (relative)
    info: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"writer": self.writer, "output_dir": self.output_dir, "aggregates": dict(self.aggregates),
                "info": dict(self.info)}


class WriterRecords:
    """The writers of this process's planned runs, by writer (what a shard returns to the merge step)."""

    def __init__(self) -> None:
        self._records: dict[int, WriterRecord] = {}

    def record_writer(self, writer) -> None:
        """Remember an attached writer of a planned run (the shard returns these to the merge step)."""
        output_dir = getattr(writer, "output_dir", None) or getattr(getattr(writer, "backend", None), "output_dir",
                                                                    None)
        if output_dir is None:
            return
        info = writer.shard_info() if hasattr(writer, "shard_info") else {}
        folder = output_dir if is_s3_url(output_dir) else os.path.abspath(output_dir)   # a folder or an S3 prefix
        self._records[id(writer)] = WriterRecord(type(writer).__name__, folder,
                                                 dict(info.pop("aggregates", {})), info)

    def records(self) -> list[dict]:
        """Every writer recorded by this process's planned runs."""
        return [r.to_dict() for r in self._records.values()]

    def clear_records(self) -> None:
        """Forget the recorded writers (a new job starts)."""
        self._records.clear()


#: The process's writer records (held by the session, :mod:`graphsdg.engine.session`).
writer_records = WriterRecords()

record_writer = writer_records.record_writer
records = writer_records.records
clear_records = writer_records.clear_records
