"""Dry runs: sample the graph N times without rendering and report every sampled parameter.

The graph runs for real (so samples are exactly the ones a capture would use),
but its stage edits go to a throw-away layer that is removed afterwards, and the
scheduler's counters are restored: the stage and the next frame are unchanged.
On-frame triggers fire on their schedule; event and time triggers fire on every
dry frame, so their parameters are reported too.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame():
    ...     _ = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1e3, 2e3, name="power"))
    >>> report = rep.graph.dry_run(200)
    >>> lo, hi = report.parameters["power"].minimum[0], report.parameters["power"].maximum[0]
    >>> 1e3 <= lo < 1.1e3 and 1.9e3 < hi < 2e3
    True
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pxr import Sdf, Usd

from graphsdg.graph import scheduler
from graphsdg.graph.node import TriggerNode
from graphsdg.stage.context import get_stage, stage_context


@dataclass
class ParameterStats:
    """One sampled parameter over a dry run: per-component range, mean, histogram; or category counts."""

    name: str
    count: int
    minimum: list[float] = field(default_factory=list)
    maximum: list[float] = field(default_factory=list)
    mean: list[float] = field(default_factory=list)
    std: list[float] = field(default_factory=list)
    histograms: list[tuple[list[int], list[float]]] = field(default_factory=list)   # (counts, bin edges)
    categories: dict[str, int] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {k: v for k, v in self.__dict__.items() if v is not None}

    def __str__(self) -> str:
        if self.categories is not None:
            cats = ", ".join(f"{k}: {v}" for k, v in sorted(self.categories.items(), key=lambda kv: -kv[1])[:8])
            return f"{self.name:<32} n={self.count:<6} {cats}"
        rows = []
        for i, (lo, hi, mu) in enumerate(zip(self.minimum, self.maximum, self.mean)):
            counts = self.histograms[i][0]
            peak = max(counts) or 1
            bars = "".join(" .:-=+*#%@"[min(9, int(9 * c / peak + 0.999))] if c else " " for c in counts)
            label = self.name if i == 0 else ""
            rows.append(f"{label:<32} n={self.count:<6} [{i}] {lo:>11.4g} .. {hi:<11.4g} mean {mu:<11.4g} |{bars}|")
        return "\n".join(rows)


@dataclass
class DryRunReport:
    """What :func:`dry_run` sampled, by parameter (``node`` or ``node.port``)."""

    frames: int
    parameters: dict[str, ParameterStats]
    samples: dict[str, list] = field(repr=False, default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"frames": self.frames, "parameters": {k: v.to_dict() for k, v in self.parameters.items()}}

    def __str__(self) -> str:
        head = f"dry run: {self.frames} frames, {len(self.parameters)} sampled parameters"
        return "\n".join([head] + [str(p) for p in self.parameters.values()])


def _stats(name: str, values: list, bins: int) -> ParameterStats:
    try:
        rows = [np.asarray(v, dtype=np.float64) for v in values]
        width = max(int(np.prod(r.shape[1:])) if r.ndim > 1 else 1 for r in rows)
        arr = np.concatenate([r.reshape(-1, width) for r in rows], axis=0)
    except (TypeError, ValueError):
        flat = [str(x) for v in values for x in (v if isinstance(v, (list, tuple, np.ndarray)) else [v])]
        return ParameterStats(name, len(flat), categories=dict(Counter(flat)))
    hists = []
    for col in arr.T:
        counts, edges = np.histogram(col, bins=bins)
        hists.append((counts.tolist(), edges.tolist()))
    return ParameterStats(name, arr.shape[0], arr.min(0).tolist(), arr.max(0).tolist(), arr.mean(0).tolist(),
                          arr.std(0).tolist(), hists)


def dry_run(num_frames: int = 100, bins: int = 10) -> DryRunReport:
    """Run the current graph ``num_frames`` times without rendering or keeping its edits; report the samples."""
    if isinstance(num_frames, bool) or not isinstance(num_frames, int) or num_frames < 1:
        raise ValueError(f"dry_run num_frames must be a positive integer, got {num_frames!r}")
    graph = scheduler.active_graph()
    if graph is None:
        raise ValueError("dry_run: there is no graph to sample; build one with rep.create/rep.trigger/... first")
    stage = get_stage()
    tracker = stage_context.tracker
    snap = scheduler.snapshot(graph)
    layer = Sdf.Layer.CreateAnonymous("graphsdg_dry_run")
    session = stage.GetSessionLayer()
    collected: dict[str, list] = {}
    muted = tracker.muted() if tracker is not None else None
    try:
        if muted is not None:
            muted.__enter__()
        session.subLayerPaths.insert(0, layer.identifier)
        with Usd.EditContext(stage, layer):
            for _ in range(num_frames):
                fired = []
                for t in graph.triggers:
                    if not isinstance(t, TriggerNode):
                        continue
                    frame_driven = t.execs_before(0) is not None
                    if (t.poll(graph.frame, 0.0, set()) if frame_driven else not t.exhausted()):
                        t.exec_count += 1
                        fired.append(t)
                for node in scheduler.run_subgraphs(graph, fired, graph.frame, dry=True):
                    for key, value in node.record.items():
                        collected.setdefault(node.name if key == "value" else f"{node.name}.{key}", []).append(
                            scheduler.jsonable(value))
                graph.frame += 1
    finally:
        if layer.identifier in list(session.subLayerPaths):
            session.subLayerPaths.remove(layer.identifier)
        if muted is not None:
            muted.__exit__(None, None, None)
        scheduler.restore(graph, snap)
    return DryRunReport(num_frames, {k: _stats(k, v, bins) for k, v in collected.items()}, collected)
