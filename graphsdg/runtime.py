"""The process-wide capture runtime: stage, simulation, renderer, attachments.

One :class:`Runtime` ties together what a capture needs: the current stage and
its :class:`~graphsdg.sim.scene.SimScene`, the :class:`Rasterizer` (which owns
the GL context and so lives on the thread that captures), the timeline, and the
annotators and writers attached to render products. The orchestrator drives it.
"""
from __future__ import annotations

from typing import Callable, Generic, Iterator, TypeVar

from pxr import Usd

from graphsdg.annotate.frame import SceneLabels
from graphsdg.annotate.ids import IdTables
from graphsdg.render.backend import RenderBackend, resolve_backend
from graphsdg.render.rasterizer import Rasterizer
from graphsdg.errors import RenderProductDestroyedError
from graphsdg.render.render_product import registry as rp_registry
from graphsdg.sim.scene import SimScene
from graphsdg.sim.timeline import Timeline
from graphsdg.stage.context import stage_context

T = TypeVar("T")


class OrderedSet(Generic[T]):
    """Insertion-ordered set (attachment order decides evaluation order, deterministically)."""

    def __init__(self) -> None:
        self._items: dict[int, T] = {}

    def add(self, item: T) -> None:
        self._items.setdefault(id(item), item)

    def discard(self, item: T) -> None:
        self._items.pop(id(item), None)

    def __iter__(self) -> Iterator[T]:
        return iter(list(self._items.values()))

    def __len__(self) -> int:
        return len(self._items)

    def __contains__(self, item: object) -> bool:
        return id(item) in self._items

    def clear(self) -> None:
        self._items.clear()


class Runtime:
    """Everything a capture step touches (see the module docstring)."""

    def __init__(self) -> None:
        self._sim: SimScene | None = None
        self._sim_stage: Usd.Stage | None = None
        self.rasterizer = Rasterizer()    # the classic backend (always there: tests and tools read its stats)
        self._pbr = None                   # graphsdg.render.pbr.PbrRenderer, made on first use
        self.timeline = Timeline(simulation=lambda: self.sim)
        self.annotators: OrderedSet = OrderedSet()
        self.writers: OrderedSet = OrderedSet()
        self.ids = IdTables()
        self.labels = SceneLabels(self.ids)
        self.graph_hooks: list[Callable[..., object]] = []
        # called with the render product paths of every capture that rendered (Kit's new-frame events)
        self.render_observers: list[Callable[[list[str]], None]] = []
        # a step(wait_for_render=False) whose annotators and writers have not run yet
        self.pending_capture: Callable[[], None] | None = None
        stage_context.subscribe_replaced(self._on_stage_replaced)

    def complete_capture(self) -> None:
        """Annotate and write the capture a ``step(wait_for_render=False)`` left pending, if any."""
        finish, self.pending_capture = self.pending_capture, None
        if finish is not None:
            finish()

    @property
    def renderer(self) -> RenderBackend:
        """The render backend the settings choose now (:mod:`graphsdg.render.backend`): the classic
        rasteriser or the PBR renderer (made on first use)."""
        if resolve_backend() == "classic":
            return self.rasterizer
        if self._pbr is None:
            from graphsdg.render.backend import pbr_device
            from graphsdg.render.pbr import PbrRenderer   # imports Warp: only where pbr was chosen
            self._pbr = PbrRenderer(pbr_device())
        return self._pbr

    @property
    def stage(self) -> Usd.Stage:
        return stage_context.get_stage()

    @property
    def sim(self) -> SimScene:
        stage = self.stage
        if self._sim is None or self._sim_stage is not stage:
            assert stage_context.tracker is not None
            self._sim = SimScene(stage, stage_context.tracker)
            self._sim_stage = stage
            self.timeline.set_time_codes_per_second(stage.GetTimeCodesPerSecond() or 60.0)
        return self._sim

    def _on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        # Render products, annotators and writers belong to the old stage's session.
        rp_registry.clear()
        for w in list(self.writers):
            w.detach()
        for a in list(self.annotators):
            a.detach()
        self._sim = None
        self._sim_stage = None
        self.ids.clear()
        self.labels = SceneLabels(self.ids)
        self.timeline.forget_simulation_state()

    def check_attachments(self) -> None:
        """Raise if an attached annotator or writer still points at a destroyed render product."""
        for owner in list(self.writers) + list(self.annotators):
            for rp in owner.render_products:
                if rp.destroyed:
                    kind = "writer" if owner in self.writers else "annotator"
                    name = type(owner).__name__ if kind == "writer" else owner.name
                    raise RenderProductDestroyedError(
                        f"render product {rp.name!r} ({rp.path}) was destroyed but {kind} {name!r} is still "
                        f"attached to it; call detach() before destroy(), or attach to a live render product")


_runtime: Runtime | None = None


def runtime() -> Runtime:
    """The process's :class:`Runtime` (created on first use)."""
    global _runtime
    if _runtime is None:
        _runtime = Runtime()
    return _runtime
