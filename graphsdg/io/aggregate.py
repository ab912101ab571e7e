"""Files that a writer rewrites whole as its dataset grows (COCO json, BOP scene json).

Each rewrite is scheduled on the write queue with a snapshot of the data; the
queue runs several workers, so two rewrites of one file can finish out of
order. :class:`AggregateFile` numbers the snapshots and never lets an older one
replace a newer one, and every rewrite is atomic (the backend's ``write_blob``).

Example:
    >>> import graphsdg as rep, tempfile, json, os
    >>> backend = rep.backends.get("DiskBackend", init_params={"output_dir": tempfile.mkdtemp()})
    >>> doc = AggregateFile(backend, "all.json")
    >>> doc.schedule({"frames": [0]}); doc.schedule({"frames": [0, 1]})
    >>> rep.orchestrator.wait_until_complete()
    >>> json.load(open(os.path.join(backend.output_dir, "all.json")))
    {'frames': [0, 1]}
"""
from __future__ import annotations

import threading
from typing import Any, Callable

from graphsdg.io import encode


class AggregateFile:
    """One file of ``backend`` at ``path`` that is rewritten whole; the newest snapshot wins."""

    def __init__(self, backend: Any, path: str,
                 encoder: Callable[[Any], bytes] = lambda data: encode.encode_json(data, indent=2)) -> None:
        self.backend = backend
        self.path = path
        self._encoder = encoder
        self._lock = threading.Lock()
        self._scheduled = 0
        self._written = 0

    def schedule(self, snapshot: Any) -> None:
        """Queue a rewrite with ``snapshot`` (the caller must not mutate it afterwards)."""
        self._scheduled += 1
        self.backend.schedule(self._rewrite, version=self._scheduled, snapshot=snapshot)

    def _rewrite(self, version: int, snapshot: Any, backend_instance: Any) -> None:
        with self._lock:
            if version < self._written:
                return          # a newer snapshot is already on disk
            backend_instance.write_blob(self.path, self._encoder(snapshot))
            self._written = version
