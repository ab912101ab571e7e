"""Which frames of a dataset are complete on disk: the run-state file ``graphsdg_run.json``.

While a writer with an output folder has frames that are not yet known to be
complete, ``<output_dir>/graphsdg_run.json`` says which are (format documented in
``docs/reproducibility.md``). It appears with the first frame and is rewritten
atomically about once a second and at every flush point (``wait_until_complete()``,
``stop()``, the end of ``run()``, an interrupt, interpreter exit). When
``wait_until_complete()``, ``stop()`` or the end of ``run()`` finds every frame
complete, the file is removed: a finished dataset holds exactly the writer's own
files, byte-identical to an uninterrupted run's. A folder *with* the file was
interrupted (status ``"interrupted"``), failed (``"failed"``), was flushed only by
the exit hook (``"exited"``) or is still being written (``"writing"``, also what a
killed process leaves).

A frame is *complete* once every file the writer scheduled for it is on disk under
its final name; for writers that keep dataset-wide files (COCO json, BOP scene json,
WebDataset shards: writers that override ``Writer.flush``) once those were flushed
too, at a flush point. The file lags the disk by at most a second and never lists a
frame whose files are not all there. A frame that is not listed may have some of
its files on disk (each of them whole: writes are atomic); a resumed run writes it
again.

Example:
    >>> import graphsdg as rep, tempfile, os
    >>> out = tempfile.mkdtemp()
    >>> _ = rep.stage.new_stage()
    >>> cam = rep.functional.create.camera(position=(0, -3, 0), look_at=(0, 0, 0))
    >>> rp = rep.create.render_product(cam, (16, 16))
    >>> writer = rep.writers.get("BasicWriter")
    >>> writer.initialize(output_dir=out, rgb=True)
    >>> writer.attach(rp)
    >>> for _ in range(3):
    ...     rep.orchestrator.step()
    >>> read(out)["writers"]["BasicWriter"]["status"]       # written with the first frame
    'writing'
    >>> rep.orchestrator.wait_until_complete()   # every frame complete: the file goes
    >>> read(out) is None, sorted(os.listdir(out))[:2]
    (True, ['metadata.txt', 'rgb_0000.png'])
    >>> writer.detach(); rp.destroy()
"""
from __future__ import annotations

import contextlib
import json
import logging
import os
import threading
import time
import weakref
from typing import Any

from graphsdg.base import settings_store as settings
from graphsdg.io.location import open_location
from graphsdg.render.attachments import attachments
from graphsdg.rng import get_global_seed
from graphsdg.io.write_queue import get_write_queue
from graphsdg.errors import unknown_name
from graphsdg.io.writer import Writer

FILE_NAME = "graphsdg_run.json"
FORMAT = "graphsdg.run_state"
VERSION = 1
CHECKPOINT_EVERY_S = 1.0
STATUSES = ("writing", "flushed", "finished", "interrupted", "failed", "exited")
_CLEAN = ("flushed", "finished")     # statuses after which a complete folder needs no file
log = logging.getLogger("graphsdg.io")


class _FrameSet:
    """Frame numbers as a done prefix plus the few done beyond it (bounded memory over long runs)."""

    def __init__(self) -> None:
        self.prefix = 0            # every frame < prefix is in the set
        self.extra: set[int] = set()

    def add(self, frame: int) -> None:
        if frame < self.prefix:
            return
        self.extra.add(frame)
        while self.prefix in self.extra:
            self.extra.discard(self.prefix)
            self.prefix += 1

    def __contains__(self, frame: int) -> bool:
        return frame < self.prefix or frame in self.extra

    def ranges(self, upto: int | None = None) -> list[list[int]]:
        """Inclusive ``[first, last]`` runs, optionally only of frames <= ``upto``."""
        frames = sorted(self.extra)
        out: list[list[int]] = [[0, self.prefix - 1]] if self.prefix else []
        for f in frames:
            if out and out[-1][1] == f - 1:
                out[-1][1] = f
            else:
                out.append([f, f])
        if upto is not None:
            out = [[a, min(b, upto)] for a, b in out if a <= upto]
        return out


class FrameLedger:
    """One writer's frames in one output folder: handed to ``write()``, on disk, complete."""

    def __init__(self, writer: Any, output_dir: str) -> None:
        self.writer_ref = weakref.ref(writer)
        self.name = type(writer).__name__
        self.output_dir = output_dir
        self.aggregate = type(writer).flush is not Writer.flush
        self.global_seed = get_global_seed()
        self._lock = threading.Lock()
        self.next_frame = 0                   # one past the highest frame number handed to the writer
        self.begun = 0                        # frames handed to the writer by this process
        self.finished = 0                     # of those, frames whose tasks all succeeded
        self.done = _FrameSet()
        self.restored = _FrameSet()           # complete frames of the run this one resumes
        self.failed: set[int] = set()
        self.last_begun = -1
        self.flushed_upto = -1                # aggregate writers: frames <= this had their shared files flushed
        self.steps: list[list[int]] = []      # [first_frame, first_step, count] runs
        self.status = "writing"
        self.changed = True

    def begin(self, step: int, frame: int | None = None) -> int:
        """Register a frame captured by orchestrator step ``step``; return its number.

        ``frame`` is the frame's number in the whole dataset when the run says
        (sharded and resumed runs); otherwise frames are numbered in order.
        """
        with self._lock:
            frame = self.next_frame if frame is None else int(frame)
            self.next_frame = max(self.next_frame, frame + 1)
            self.begun += 1
            self.last_begun = frame
            last = self.steps[-1] if self.steps else None
            if last is not None and last[0] + last[2] == frame and last[1] + last[2] == step:
                last[2] += 1
            else:
                self.steps.append([frame, step, 1])
            self.status = "writing"
            self.changed = True
            return frame

    def files_done(self, frame: int, ok: bool) -> None:
        """Every task scheduled for ``frame`` finished (``ok``: none failed). Runs on a writer thread."""
        with self._lock:
            if ok:
                self.done.add(frame)
                self.finished += 1
            else:
                self.failed.add(frame)
            self.changed = True

    def drained(self, status: str) -> None:
        """Writers flushed and the queue empty: every written frame's shared files are on disk."""
        with self._lock:
            self.flushed_upto = self.last_begun
            self.status = status
            self.changed = True

    def restore(self, entry: dict) -> None:
        """Continue an earlier run's entry (``read(dir)["writers"][name]``): its complete frames stay listed,
        and frames are numbered on from the first one that is not complete."""
        with self._lock:
            for first, last in entry.get("complete", []):
                for f in range(int(first), int(last) + 1):
                    self.restored.add(f)
            self.next_frame = self.restored.prefix
            earlier = [[r[0], r[1], min(r[2], self.next_frame - r[0])] for r in entry.get("steps", [])
                       if r[0] < self.next_frame]
            self.steps = earlier + self.steps
            self.changed = True

    def complete(self) -> _FrameSet:
        out = _FrameSet()
        out.prefix, out.extra = self.restored.prefix, set(self.restored.extra)
        upto = self.flushed_upto if self.aggregate else None
        for first, last in self.done.ranges(upto):
            for f in range(first, last + 1):
                out.add(f)
        return out

    def entry(self) -> dict:
        with self._lock:
            complete = self.complete()
            return {"writer": self.name, "status": self.status, "global_seed": self.global_seed,
                    "next_frame": self.next_frame, "complete": complete.ranges(),
                    "failed": sorted(f for f in self.failed if f not in complete),
                    "steps": [list(r) for r in self.steps], "aggregate_files": self.aggregate}

    def all_complete(self) -> bool:
        """Every frame this process handed to the writer is complete (shared files flushed too)."""
        with self._lock:
            return not self.failed and self.finished == self.begun and \
                (not self.aggregate or self.flushed_upto >= self.last_begun)

    def writer_gone(self) -> bool:
        writer = self.writer_ref()
        return writer is None or writer not in attachments.writers


def enabled() -> bool:
    return bool(settings.get("/graphsdg/io/runState", True))


def _output_dir(writer: Any) -> str | None:
    out = getattr(getattr(writer, "backend", None), "output_dir", None)
    return out if isinstance(out, str) and out else None


def _read_quietly(output_dir: str) -> dict | None:
    try:
        return read(output_dir)
    except ValueError as exc:
        log.warning("graphsdg: ignoring the run-state file in %s: %s", output_dir, exc)
        return None


def file_name() -> str:
    """``graphsdg_run.json``, or ``graphsdg_run.shard-<i>-of-<k>.json`` in shard ``i`` of a ``k``-way sharded
    run (``/graphsdg/run/shardIndex`` / ``shardCount``), whose processes share output folders."""
    count = settings.get("/graphsdg/run/shardCount", 1) or 1
    if int(count) <= 1:
        return FILE_NAME
    return f"{FILE_NAME[:-5]}.shard-{int(settings.get('/graphsdg/run/shardIndex', 0) or 0)}-of-{int(count)}.json"


class RunLedgers:
    """The ledger of every writer's output folder, and which folders' run-state files this process wrote."""

    def __init__(self) -> None:
        self._ledgers: dict[tuple[int, str], FrameLedger] = {}
        self._present: set[str] = set()   # output folders whose run-state file this process wrote or resumed from
        self._lock = threading.Lock()
        self._last_save = 0.0

    def ledger_for(self, writer: Any, create: bool = True) -> FrameLedger | None:
        """The ledger of ``writer``'s current output folder (``None`` for writers without one)."""
        out = _output_dir(writer)
        if out is None or not enabled():
            return None
        key = (id(writer), out)
        with self._lock:
            ledger = self._ledgers.get(key)
            if ledger is not None and ledger.writer_ref() is not writer:   # an id reused by a new object
                ledger = None
            if ledger is None and create:
                ledger = self._ledgers[key] = FrameLedger(writer, out)
                if settings.get("/graphsdg/run/resume", False):     # graphsdg run --resume: keep what was complete
                    earlier = _read_quietly(out)
                    if earlier is not None:
                        self._present.add(out)    # the earlier run's file goes when this run completes the folder
                    if earlier is not None and ledger.name in earlier["writers"]:
                        ledger.restore(earlier["writers"][ledger.name])
            return ledger

    def frame(self, writer: Any, step: int, frame_index: int | None = None) -> contextlib.AbstractContextManager:
        """A ``with`` block around one ``writer._write(data)``: the tasks it schedules make up one frame (the
        frame is registered as the block is made, which ``with`` does at once).

        ``frame_index``: the frame's number in the whole dataset, when the run assigns
        one (sharded and resumed runs pass ``data["frame_index"]``).
        """
        ledger = self.ledger_for(writer)
        if ledger is None:
            return contextlib.nullcontext()
        first = ledger.status != "writing" or ledger.begun == 0
        number = ledger.begin(step, frame_index)
        if first:     # the file exists whenever frames are in flight, so a killed run always leaves one
            self._save_quietly()
        return get_write_queue().group(lambda ok: ledger.files_done(number, ok))

    def _save_dir(self, output_dir: str, ledgers: list[FrameLedger]) -> None:
        location = open_location(output_dir)      # a folder, or an s3:// prefix
        writers: dict[str, dict] = {}
        for ledger in ledgers:
            name = ledger.name
            i = 2
            while name in writers:
                name, i = f"{ledger.name}#{i}", i + 1
            writers[name] = ledger.entry()
        if all(ledger.all_complete() and ledger.status in _CLEAN for ledger in ledgers):
            if output_dir in self._present:   # only a file this process wrote or found (no request for others: S3)
                location.delete(file_name())
                self._present.discard(output_dir)
            return
        lines = [f' "format": {json.dumps(FORMAT)},', f' "version": {VERSION},', ' "writers": {']
        lines += [f'  {json.dumps(name)}: {json.dumps(entry)}{"," if i < len(writers) - 1 else ""}'
                  for i, (name, entry) in enumerate(writers.items())]
        location.write(file_name(), ("{\n" + "\n".join(lines) + "\n }\n}\n").encode(), count=False)
        self._present.add(output_dir)

    def save(self, force: bool = False) -> None:
        """Write the run-state file of every folder whose frames changed (``force``: every folder)."""
        with self._lock:
            ledgers = list(self._ledgers.values())
        by_dir: dict[str, list[FrameLedger]] = {}
        for ledger in ledgers:
            by_dir.setdefault(ledger.output_dir, []).append(ledger)
        for output_dir, group in by_dir.items():
            if force or any(ledger.changed for ledger in group):
                for ledger in group:
                    ledger.changed = False
                self._save_dir(output_dir, group)
        self._last_save = time.monotonic()

    def _save_quietly(self) -> None:
        """Save during capture: a failure (a full disk) is logged, and the frames' own writes report it."""
        try:
            self.save()
        except Exception as exc:  # noqa: BLE001 - bookkeeping must not stop the capture
            log.error("graphsdg: could not update the run-state file: %s", exc)

    def checkpoint(self) -> None:
        """Called after each captured frame: save at most about once a second."""
        if self._ledgers and time.monotonic() - self._last_save >= CHECKPOINT_EVERY_S:
            self._save_quietly()

    def drained(self, status: str = "flushed", only_writing: bool = False) -> None:
        """Every attached writer was flushed and the write queue is empty: record ``status``, save (or remove
        the files of folders that are complete), forget detached writers.

        ``only_writing`` leaves entries whose status is already final (used at interpreter exit).
        """
        if status not in STATUSES:
            raise ValueError(f"run-state status must be one of {STATUSES}, got {status!r}")
        with self._lock:
            ledgers = list(self._ledgers.values())
        for ledger in ledgers:
            if not only_writing or ledger.status == "writing":
                ledger.drained(status)
        self.save()
        with self._lock:
            for key, ledger in list(self._ledgers.items()):
                if ledger.writer_gone():
                    del self._ledgers[key]

    def mark_failed(self) -> None:
        """A write failed: record it in every open entry (the failed frames are already left out of
        ``complete``).

        Never raises (it runs while another error is on its way to the script); a run-state
        file that cannot be written is logged.
        """
        with self._lock:
            ledgers = list(self._ledgers.values())
        for ledger in ledgers:
            if ledger.status == "writing":
                with ledger._lock:
                    ledger.status = "failed"
                    ledger.changed = True
        self._save_quietly()

    def summary(self) -> list[str]:
        """One line per tracked writer whose frames are not all complete (for error messages)."""
        out = []
        with self._lock:
            ledgers = list(self._ledgers.values())
        for ledger in ledgers:
            if not ledger.all_complete():
                entry = ledger.entry()
                ranges = ", ".join(f"{a}-{b}" if a != b else f"{a}" for a, b in entry["complete"]) or "none"
                failed = f", failed {entry['failed']}" if entry["failed"] else ""
                out.append(f"{ledger.output_dir}: {ledger.name} was given frames up to {entry['next_frame'] - 1}, "
                           f"complete {ranges}{failed} (see {file_name()} there)")
        return out

    def open_ledgers(self) -> int:
        """How many writers' entries are being tracked (for leak checks)."""
        return len(self._ledgers)


#: The process's ledgers (held by the session, :mod:`graphsdg.engine.session`).
ledgers = RunLedgers()

ledger_for = ledgers.ledger_for
frame = ledgers.frame
save = ledgers.save
checkpoint = ledgers.checkpoint
drained = ledgers.drained
mark_failed = ledgers.mark_failed
summary = ledgers.summary
open_ledgers = ledgers.open_ledgers


def read(output_dir: str | os.PathLike) -> dict | None:
    """The parsed run-state file of ``output_dir``, or ``None`` when there is none.

    ``None`` means every frame graphsdg wrote to the folder is complete (or none was
    written). Raises ``ValueError`` for a file that is not a graphsdg run-state file
    of a version this graphsdg reads.
    """
    location = open_location(output_dir)      # a folder, or an s3:// prefix
    path = location.path_of(file_name())
    try:
        raw = location.read(file_name())
    except FileNotFoundError:
        return None
    try:
        doc = json.loads(raw)
    except ValueError:
        doc = None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT or doc.get("version") != VERSION:
        found = (doc.get("format"), doc.get("version")) if isinstance(doc, dict) else "not a JSON object"
        raise ValueError(f"{path!r} is not a {FORMAT} file of version {VERSION} (found {found!r})")
    return doc


def complete_frames(output_dir: str | os.PathLike, writer: str | None = None) -> list[int] | None:
    """Frame numbers whose files are all on disk, from the run-state file; ``None`` when the folder has
    no run-state file (every frame complete). ``writer``: the entry's name (default: the only entry)."""
    doc = read(output_dir)
    if doc is None:
        return None
    writers = doc["writers"]
    if writer is None:
        if len(writers) != 1:
            raise ValueError(f"{os.fspath(output_dir)!r} holds run state of several writers {sorted(writers)}; "
                             f"pass writer=")
        writer = next(iter(writers))
    if writer not in writers:
        raise unknown_name("writer entry", writer, writers)
    return [f for first, last in writers[writer]["complete"] for f in range(first, last + 1)]


__all__ = ["FILE_NAME", "FORMAT", "VERSION", "FrameLedger", "frame", "checkpoint", "drained", "save", "read",
           "complete_frames", "ledger_for", "mark_failed"]
