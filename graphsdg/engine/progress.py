"""Progress of long runs: a live bar, log lines, and a final summary. The bar shows on a terminal, periodic log
lines elsewhere.

Example:
    >>> with Progress(total=3, enabled=False) as bar:
    ...     for _ in range(3):
    ...         bar.advance()
    >>> bar.frames
    3
"""
from __future__ import annotations

import logging
import sys
import time

from graphsdg.io import backends
from graphsdg.io.write_queue import get_write_queue

log = logging.getLogger("graphsdg.engine.progress")
LOG_EVERY_S = 10.0


class Progress:
    """Frames done / total, frames per second, ETA and queued writes."""

    def __init__(self, total: int | None, description: str = "frames", enabled: bool | None = None) -> None:
        self.total = total
        self.frames = 0
        self.description = description
        self.enabled = sys.stderr.isatty() if enabled is None else enabled
        self._bar = None
        self._start = self._last_log = time.perf_counter()
        self._bytes0 = backends.bytes_written()
        self._files0 = backends.files_written()

    def __enter__(self) -> "Progress":
        if self.enabled:
            from tqdm import tqdm
            self._bar = tqdm(total=self.total, desc=self.description, unit="frame", dynamic_ncols=True)
        return self

    def set_total(self, total: int | None) -> None:
        """Change the number of frames expected (a resumed run learns it after checking the disk)."""
        self.total = total
        if self._bar is not None:
            self._bar.total = total
            self._bar.refresh()

    def advance(self, n: int = 1) -> None:
        self.frames += n
        pending = get_write_queue().pending()
        if self._bar is not None:
            self._bar.update(n)
            self._bar.set_postfix(queued_writes=pending, refresh=False)
            return
        now = time.perf_counter()
        if now - self._last_log >= LOG_EVERY_S:
            self._last_log = now
            fps = self.frames / max(now - self._start, 1e-9)
            eta = f", ETA {(self.total - self.frames) / fps:.0f} s" if self.total and fps > 0 else ""
            log.info("%s %d%s at %.1f frames/s%s, %d writes queued", self.description, self.frames,
                     f"/{self.total}" if self.total else "", fps, eta, pending)

    def __exit__(self, *exc) -> None:
        if self._bar is not None:
            self._bar.close()

    def summary(self) -> dict[str, float]:
        """Frames, files, bytes, wall time and frames/s since the start (writes counted when done)."""
        wall = time.perf_counter() - self._start
        return {"frames": self.frames, "files": backends.files_written() - self._files0,
                "bytes": backends.bytes_written() - self._bytes0, "seconds": round(wall, 3),
                "frames/s": round(self.frames / wall, 2) if wall > 0 else 0.0}
