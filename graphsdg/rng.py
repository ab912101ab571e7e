"""Seeds and random streams.

Every random choice graphsdg makes derives from the global seed
(:func:`set_global_seed`) and a stable key, so the same script with the same seed
samples the same values, and one node's stream never shifts because another node
was added.

Example:
    >>> import graphsdg as rep
    >>> rep.set_global_seed(7)
    >>> a = rep.rng.ReplicatorRNG(seed=42).generator.uniform()
    >>> b = rep.rng.ReplicatorRNG(seed=42).generator.uniform()
    >>> a == b
    True
"""
from __future__ import annotations

import hashlib
import weakref
from typing import Hashable

import numpy as np

from graphsdg.base import settings_store as settings

_DEFAULT_SEED = 0
_live_rngs: "weakref.WeakSet[ReplicatorRNG]" = weakref.WeakSet()


def set_global_seed(seed: int) -> None:
    """Set the seed every distribution and seedless :class:`ReplicatorRNG` derives from."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"global seed must be a non-negative integer, got {seed!r}")
    settings.set("/omni/replicator/globalSeed", int(seed))
    for rng in list(_live_rngs):
        rng.reset()


def get_global_seed() -> int:
    """Return the global seed (0 unless :func:`set_global_seed` was called)."""
    seed = settings.get("/omni/replicator/globalSeed")
    return _DEFAULT_SEED if seed is None else int(seed)


def stable_key(*parts: Hashable) -> int:
    """Hash ``parts`` into a 64-bit integer that is the same in every process.

    Python's ``hash()`` of strings is salted per process, so it cannot key seeds.
    """
    h = hashlib.blake2b(repr(parts).encode(), digest_size=8)
    return int.from_bytes(h.digest(), "little")


def stream(*key: Hashable) -> np.random.Generator:
    """A counter-based generator keyed on (global seed, *key*).

    Uses Philox, so any ``(node, execution)`` stream can be recreated on its own:
    frame N of a dataset can be regenerated without replaying frames 0..N-1.
    """
    seq = np.random.SeedSequence([get_global_seed(), stable_key(*key)])
    return np.random.Generator(np.random.Philox(seq))


class ReplicatorRNG:
    """Replicator's RNG object: ``.generator`` is a :class:`numpy.random.Generator`.

    ``seed=None`` derives the stream from the global seed and ``node`` (any
    hashable, stable id), so two identical scripts produce identical streams.
    """

    def __init__(self, seed: int | None = None, node: Hashable = None) -> None:
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer))
                                 or seed < 0):
            raise ValueError(f"ReplicatorRNG seed must be a non-negative integer or None, got {seed!r}")
        self._seed = None if seed is None else int(seed)
        self._node = node
        self.generator: np.random.Generator
        self.reset()
        _live_rngs.add(self)

    @property
    def seed(self) -> int | None:
        return self._seed

    @seed.setter
    def seed(self, value: int | None) -> None:
        self._seed = None if value is None else int(value)
        self.reset()

    def reset(self) -> None:
        """Restart the stream from its seed (called when the global seed changes)."""
        if self._seed is not None:
            self.generator = np.random.default_rng(np.random.SeedSequence(self._seed))
        else:
            self.generator = np.random.default_rng(
                np.random.SeedSequence([get_global_seed(), stable_key("ReplicatorRNG", self._node)]))


_functional_rng: "ReplicatorRNG | None" = None


def as_generator(rng: "ReplicatorRNG | np.random.Generator | None", *key: Hashable) -> np.random.Generator:
    """Accept what Replicator's functional API accepts as ``rng`` and return a Generator."""
    if rng is None:
        global _functional_rng
        if _functional_rng is None:
            _functional_rng = ReplicatorRNG(node=("functional",) + key)
        return _functional_rng.generator
    if isinstance(rng, ReplicatorRNG):
        return rng.generator
    if isinstance(rng, np.random.Generator):
        return rng
    raise TypeError(f"rng must be a ReplicatorRNG, a numpy Generator or None, got {type(rng).__name__}")
