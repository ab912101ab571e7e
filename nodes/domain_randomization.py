"""Physics domain-randomization nodes: the RL-frame trigger, its environment gates, and the view writers.

``graphsdg.domain_randomization`` builds them (Isaac's
``isaacsim.replicator.experimental.domain_randomization``)::

    with dr.on_rl_frame(num_envs=4):              # trigger.on_rl_frame: fired by step_randomization()
        with dr.on_interval(interval=20):         # gate.environments: rows whose frame is a multiple of 20
            dr.randomize_rigid_body_view("objects", mass=rep.distribution.uniform(0.5, 2.0))
        with dr.on_env_reset():                   # gate.environments: the rows being reset
            ...

A writer takes one sample per picked environment from its ``values`` (a
distribution, or a plain value for every row) and hands them to
:func:`graphsdg.physics.domain_randomization.write_samples`.
"""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from graphsdg.graph.node import ExecContext, Node, Port, TriggerNode
from graphsdg.graph.registry import register_node
from graphsdg.graph.samples import Samples
from graphsdg.physics.domain_randomization import (EnvironmentFrames, check_attribute, interval_rows,
                                                   randomization_targets, write_samples)


@register_node
class OnRLFrame(TriggerNode):
    """Fire once per ``step_randomization(reset_inds)`` call of an RL loop, never on orchestrator steps.

    Keeps one frame counter per environment; outputs ``frame_num`` (every environment's frame, resets at 0)
    and ``reset_inds`` (the environments being reset) for its gates.
    """

    type_name = "trigger.on_rl_frame"
    inputs = {"num_envs": Port(int, required=True)}
    outputs = {"execs": Port(int), "reset_inds": Port("indices"), "frame_num": Port("indices")}
    counts_toward_completion = False

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        self.frames = EnvironmentFrames(self.value_of("num_envs"))
        self.output_values = {"execs": 0, "reset_inds": np.zeros(0, dtype=np.int64),
                              "frame_num": np.zeros(0, dtype=np.int64)}

    def poll(self, frame: int, sim_time: float, events: set[str]) -> bool:
        return False

    def prepare(self, reset_inds: Any) -> None:
        """Take one RL frame: reset ``reset_inds``' counters and publish every environment's frame."""
        resets = np.asarray([] if reset_inds is None else reset_inds, dtype=np.int64).reshape(-1)
        frames = self.frames.advance(resets)
        self.output_values = {**self.output_values, "reset_inds": resets, "frame_num": frames}


@register_node
class EnvironmentGate(Node):
    """Pick the environments the writers of its block randomize: those whose frame is a positive multiple of
    ``interval``, or (``on_reset``) those being reset."""

    type_name = "gate.environments"
    family = "gate"
    inputs = {"frame_num": Port("indices", required=True), "reset_inds": Port("indices", required=True),
              "interval": Port(int), "on_reset": Port(bool, False)}
    outputs = {"indices": Port("indices"), "on_reset": Port(bool)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        if not self.value_of("on_reset"):
            interval_rows(np.zeros(0), self.value_of("interval"))     # raises naming a bad interval

    def compute(self, ctx: ExecContext) -> dict[str, Any]:
        on_reset = bool(self.value_of("on_reset"))
        if on_reset:
            rows = np.asarray(ctx.value("reset_inds"), dtype=np.int64).reshape(-1)
        else:
            rows = interval_rows(np.asarray(ctx.value("frame_num")), int(self.value_of("interval")))
        ctx.record("indices", rows)
        return {"indices": rows, "on_reset": on_reset}


class ViewWriter(Node):
    """Base of the writers: randomize one attribute of a registered view for the gate's environments."""

    family = "randomizer"
    kind: ClassVar[str] = ""
    inputs = {"view": Port(str), "attribute": Port(str, required=True), "operation": Port(str, "direct"),
              "values": Port("samples", required=True), "indices": Port("indices", required=True),
              "on_reset": Port(bool, False), "num_buckets": Port(int),
              "bucket_lower": Port("number|tuple"), "bucket_upper": Port("number|tuple")}
    outputs = {"values": Port("array")}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        check_attribute(self.kind, self.value_of("attribute"), self.value_of("operation"))
        buckets = self.value_of("num_buckets")
        if buckets and (isinstance(buckets, bool) or not isinstance(buckets, int) or buckets < 1):
            raise ValueError(f"num_buckets must be a positive integer, got {buckets!r}")

    def _samples(self, ctx: ExecContext, n: int) -> np.ndarray:
        value = ctx.value("values")
        if isinstance(value, Samples):
            return np.asarray(value.take(n), dtype=np.float64).reshape(n, -1)
        row = np.asarray(value, dtype=np.float64).reshape(1, -1)
        return np.repeat(row, n, axis=0)

    def _buckets(self) -> tuple[np.ndarray, np.ndarray, int] | None:
        """(lower, upper, count) of material buckets: the ``bucket_lower`` / ``bucket_upper`` given, else the bounds
        of the distribution feeding ``values``."""
        count = self.value_of("num_buckets")
        if not count:
            return None
        if self.value_of("bucket_lower") is not None and self.value_of("bucket_upper") is not None:
            return (np.asarray(self.value_of("bucket_lower"), dtype=np.float64),
                    np.asarray(self.value_of("bucket_upper"), dtype=np.float64), int(count))
        source = getattr(self.values.get("values"), "node", None)
        kind = getattr(source, "type_name", "")
        if kind in ("distribution.uniform", "distribution.log_uniform"):
            lower, upper = source.value_of("lower"), source.value_of("upper")
        elif kind == "distribution.normal":     # two standard deviations either side of the mean
            mean, std = np.asarray(source.value_of("mean"), float), np.asarray(source.value_of("std"), float)
            lower, upper = mean - 2 * std, mean + 2 * std
        else:
            raise ValueError(f"num_buckets needs the values from a uniform, log-uniform or normal distribution "
                             f"(its bounds give the buckets), got {kind or type(self.values.get('values')).__name__}")
        return np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64), int(count)

    def compute(self, ctx: ExecContext) -> dict[str, Any] | None:
        indices = ctx.value("indices")
        rows = np.asarray([] if indices is None else indices, dtype=np.int64).reshape(-1)
        if rows.size == 0:
            return None
        target = randomization_targets().get(self.value_of("view") or "", self.kind)
        samples = self._samples(ctx, rows.size)
        if self.kind == "simulation":     # one gravity for every environment: the first sample
            samples, rows = samples[:1], np.zeros(1, dtype=np.int64)
        written = write_samples(target, self.value_of("attribute"), self.value_of("operation"), samples, rows,
                                bool(ctx.value("on_reset")), self._buckets())
        ctx.record("indices", rows)
        ctx.record(self.value_of("attribute"), written)
        return {"values": written}


@register_node
class WriteRigidBodyView(ViewWriter):
    """Randomize one attribute of a registered rigid-body view (Isaac's ``randomize_rigid_prim_view``)."""

    type_name = "randomizer.write_rigid_body_view"
    kind = "rigid_body"


@register_node
class WriteArticulationView(ViewWriter):
    """Randomize one attribute of a registered articulation view (Isaac's ``randomize_articulation_view``)."""

    type_name = "randomizer.write_articulation_view"
    kind = "articulation"


@register_node
class WriteSimulation(ViewWriter):
    """Randomize the simulation's gravity (Isaac's ``randomize_simulation_context``; the first picked
    environment's sample: gravity is one for all)."""

    type_name = "randomizer.write_simulation"
    kind = "simulation"
