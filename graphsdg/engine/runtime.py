"""The process-wide capture runtime: stage, simulation, renderer, timeline.

One :class:`Runtime` ties together what a capture needs: the current stage, its
:class:`~graphsdg.sim.scene.SimScene` and the :class:`~graphsdg.render.render_scene.RenderScene`
the renderers draw of it, the :class:`Rasterizer` (which owns the GL context and so
lives on the thread that captures), the timeline, and the label tables. The
annotators and writers attached to render products are held in
:data:`graphsdg.render.attachments.attachments`, which the runtime reads. The
orchestrator drives it.
"""
from __future__ import annotations

from typing import Callable

from pxr import Usd

from graphsdg.annotate.frame import SceneLabels
from graphsdg.annotate.ids import IdTables
from graphsdg.engine.frame_provider import NO_GRAPH, FrameProvider
from graphsdg.engine.session import session
from graphsdg.io.write_queue import current_write_queue
from graphsdg.render import render_product
from graphsdg.render.attachments import OrderedSet, attachments
from graphsdg.render.backend import RenderBackend, pbr_draws, resolve_backend
from graphsdg.render.rasterizer import Rasterizer
from graphsdg.render.render_scene import RenderScene
from graphsdg.sim.scene import SimScene
from graphsdg.sim.timeline import Timeline
from graphsdg.stage.context import stage_context


class Runtime:
    """Everything a capture step touches (see the module docstring)."""

    def __init__(self) -> None:
        self._sim: SimScene | None = None
        self._render_scene: RenderScene | None = None
        self._sim_stage: Usd.Stage | None = None
        self.rasterizer = Rasterizer()    # the classic backend (always there: tests and tools read its stats)
        self._pbr = None                   # graphsdg.render.pbr.PbrRenderer, made on first use
        self.timeline = Timeline(simulation=lambda: self.sim)
        self.ids = IdTables()
        self.labels = SceneLabels(self.ids)
        self.frame_provider: FrameProvider = NO_GRAPH   # the graph installs its scheduler here
        # called with the render product paths of every capture that rendered (Kit's new-frame events)
        self.render_observers: list[Callable[[list[str]], None]] = []

    @property
    def annotators(self) -> OrderedSet:
        """The attached annotators (:data:`graphsdg.render.attachments.attachments`)."""
        return attachments.annotators

    @property
    def writers(self) -> OrderedSet:
        """The attached writers (:data:`graphsdg.render.attachments.attachments`)."""
        return attachments.writers

    @property
    def pending_capture(self) -> Callable[[], None] | None:
        """The annotate-and-write work a ``step(wait_for_render=False)`` left pending, if any."""
        return attachments.pending_capture

    @pending_capture.setter
    def pending_capture(self, finish: Callable[[], None] | None) -> None:
        attachments.pending_capture = finish

    def complete_capture(self) -> None:
        """Annotate and write the capture a ``step(wait_for_render=False)`` left pending, if any."""
        attachments.complete_capture()

    @property
    def renderer(self) -> RenderBackend:
        """The render backend the settings choose now (:mod:`graphsdg.render.backend`): the classic
        rasteriser or the PBR renderer (made on first use)."""
        if resolve_backend() == "classic":
            return self.rasterizer
        if self._pbr is None:
            from graphsdg.render.backend import pbr_device
            from graphsdg.render.pbr import PbrRenderer   # imports Warp: only where pbr was chosen
            self._pbr = PbrRenderer(pbr_device(), wait_for_release=_wait_for_a_write)
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
            self._render_scene = RenderScene(self._sim, pbr_draws=pbr_draws,
                                             render_products=lambda: len(render_product.registry))
            self._sim_stage = stage
            self.timeline.set_time_codes_per_second(stage.GetTimeCodesPerSecond() or 60.0)
        return self._sim

    @property
    def render_scene(self) -> RenderScene:
        """What the renderers draw of :attr:`sim` (:mod:`graphsdg.render.render_scene`)."""
        self.sim   # made with the simulation of the current stage
        assert self._render_scene is not None
        return self._render_scene

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """Forget the old stage's simulation, render scene and label tables (the session detached the
        writers and annotators first, so they wrote what they held with these)."""
        self._sim = None
        self._render_scene = None
        self._sim_stage = None
        self.ids.clear()
        self.labels = SceneLabels(self.ids)
        self.timeline.forget_simulation_state()

    def check_attachments(self) -> None:
        """Raise if an attached annotator or writer still points at a destroyed render product."""
        attachments.check_live()


def runtime() -> Runtime:
    """The process's :class:`Runtime` (created on first use, held by the session)."""
    rt = session.runtime
    if rt is None:
        rt = session.adopt("runtime", Runtime())
    return rt


def _wait_for_a_write() -> bool:
    """Wait until a queued write finishes (False at once when none is queued): a frame read while every
    page-locked host buffer is still lent waits on this for the writes holding them instead of being copied."""
    queue = current_write_queue()
    return queue is not None and queue.wait_for_progress()
