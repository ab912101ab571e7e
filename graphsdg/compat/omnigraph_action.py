"""Isaac compat area: OmniGraph action graphs (``omni.graph.action``): event nodes and the runner that ticks them.

Action graphs are graphs of the ``execution`` evaluator
(:class:`graphsdg.graph.action_graph.ActionGraph`), made with
``og.Controller.edit({"graph_path": ..., "evaluator_name": "execution"}, ...)`` or
authored on the stage as ``OmniGraph`` prims (read when the timeline plays,
:mod:`graphsdg.compat.omnigraph_usd`). While compat mode is installed, the runner
evaluates every action graph:

* on each timeline tick (after its physics step, before the script's
  ``CURRENT_TIME_TICKED`` subscribers): ``omni.graph.action.OnPlaybackTick``
  fires (``outputs:tick``) with the timeline's ``time``, ``deltaSeconds`` and
  ``frame``;
* on each app update (``simulation_app.update()``, ``omni.kit.app``'s update):
  ``omni.graph.action.OnTick`` fires every ``framePeriod + 1`` updates, only
  while the timeline plays unless ``onlyPlayback`` is off;
* when the timeline stops, nodes with per-instance state reset it (Isaac's
  ``BaseResetNode`` behaviour);
* when the timeline plays, action graphs authored on the stage that are not
  loaded yet are loaded, and those whose prim went away are dropped.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.graph.core as og, omni.timeline, omni.usd
    >>> _ = omni.usd.get_context().new_stage()
    >>> graph, (tick,), _, _ = og.Controller.edit({"graph_path": "/Tick", "evaluator_name": "execution"},
    ...     {og.Controller.Keys.CREATE_NODES: [("OnPlaybackTick", "omni.graph.action.OnPlaybackTick")]})
    >>> timeline = omni.timeline.get_timeline_interface()
    >>> timeline.play()
    >>> for _ in range(3):
    ...     omni.kit.app.get_app().update()
    >>> timeline.stop()
    >>> round(og.Controller.get(tick.get_attribute("outputs:frame")))
    3
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Any

from graphsdg.compat import kit, omnigraph, omnigraph_usd
from graphsdg.compat.modules import CompatModule
from graphsdg.engine.runtime import runtime
from graphsdg.graph import action_graph, ogn
from graphsdg.graph.action_graph import ActionGraph, Tick
from graphsdg.graph.ogn import ExecutionState
from graphsdg.sim.timeline import TimelineEventType
from graphsdg.stage.context import stage_context

EXTENSIONS = {"omni.graph.action": ("omni.graph.action",), "omni.graph.action_nodes": ("omni.graph.action",),
              "omni.graph.action_core": ("omni.graph.action",)}


class OnPlaybackTick:
    """``omni.graph.action.OnPlaybackTick``: an execution pulse on every timeline tick while it plays."""

    event = "playback_tick"
    spec = {"description": "An execution pulse on each timeline tick during playback, with the playback time.",
            "outputs": {"tick": {"type": "execution"}, "time": {"type": "double"},
                        "deltaSeconds": {"type": "double"}, "frame": {"type": "double"}}}

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        tick: Tick = db.node.graph.tick
        db.outputs.time = tick.time
        db.outputs.deltaSeconds = tick.delta_seconds
        db.outputs.frame = tick.frame
        db.outputs.tick = ExecutionState.ENABLED if tick.playing else ExecutionState.DISABLED
        return True


class _UpdateCount:
    """OnTick's state: updates seen since the last pulse, and the time accumulated since then."""

    def __init__(self) -> None:
        self.updates = 0
        self.since_pulse = 0.0
        self.elapsed = 0.0

    def reset(self) -> None:
        self.updates = 0
        self.since_pulse = 0.0


class OnTick:
    """``omni.graph.action.OnTick``: an execution pulse every ``framePeriod + 1`` app updates (only while playing
    unless ``onlyPlayback`` is off)."""

    event = "app_update"
    spec = {"description": "An execution pulse at a regular multiple of the app's updates.",
            "inputs": {"framePeriod": {"type": "uint", "default": 0}, "onlyPlayback": {"type": "bool",
                                                                                       "default": True}},
            "outputs": {"tick": {"type": "execution"}, "isPlaying": {"type": "bool"},
                        "deltaSeconds": {"type": "double"}, "time": {"type": "double"}, "frame": {"type": "double"},
                        "timeSinceStart": {"type": "double"}, "absoluteSimTime": {"type": "double"}}}

    @staticmethod
    def internal_state() -> _UpdateCount:
        return _UpdateCount()

    @staticmethod
    def compute(db: ogn.Database) -> bool:
        tick: Tick = db.node.graph.tick
        state: _UpdateCount = db.per_instance_state
        state.elapsed += tick.delta_seconds
        db.outputs.isPlaying = tick.playing
        db.outputs.time, db.outputs.frame = tick.time, tick.frame
        db.outputs.timeSinceStart = db.outputs.absoluteSimTime = state.elapsed
        if db.inputs.onlyPlayback and not tick.playing:
            db.outputs.tick = ExecutionState.DISABLED
            return True
        state.since_pulse += tick.delta_seconds
        state.updates += 1
        if (state.updates - 1) % (int(db.inputs.framePeriod) + 1):
            db.outputs.tick = ExecutionState.DISABLED
            return True
        db.outputs.deltaSeconds, state.since_pulse = state.since_pulse, 0.0
        db.outputs.tick = ExecutionState.ENABLED
        return True


NODE_TYPES = {"omni.graph.action.OnPlaybackTick": OnPlaybackTick, "omni.graph.action.OnTick": OnTick}


def register_node_types(types_: dict[str, type]) -> None:
    """Register OmniGraph node types, each an implementation class with its OGN ``spec`` and ``compute(db)``."""
    for type_name, implementation in types_.items():
        ogn.node_class(ogn.definition_from_spec(type_name, implementation.spec), implementation)


# ---- the runner ---------------------------------------------------------------------------------------------
def action_graphs() -> list[ActionGraph]:
    """Every action graph compat mode knows (made by ``og.Controller`` or read from the stage)."""
    return [g for g in omnigraph.made_graphs().values() if isinstance(g, ActionGraph)]


def _answers(graph: ActionGraph, event: str) -> bool:
    return any(action_graph.event_of(n) == event for n in graph)


class ActionGraphRunner:
    """Evaluates the action graphs on timeline ticks and app updates (see the module docstring)."""

    def __init__(self) -> None:
        self._subscriptions: list[Any] = []

    def start(self) -> None:
        """Listen to the timeline and the app's updates."""
        if self._subscriptions:
            return
        timeline = runtime().timeline
        self._subscriptions = [
            timeline.subscribe(self._on_tick, TimelineEventType.CURRENT_TIME_TICKED_PERMANENT),
            timeline.subscribe(self._on_play, TimelineEventType.PLAY),
            timeline.subscribe(self._on_stop, TimelineEventType.STOP),
            kit.get_app().get_update_event_stream().create_subscription_to_pop(self._on_update)]

    def stop(self) -> None:
        """Stop listening."""
        for sub in self._subscriptions:
            sub.unsubscribe()
        self._subscriptions = []

    @staticmethod
    def _evaluate_all(event: str, time: float, dt: float, playing: bool) -> None:
        fps = runtime().timeline.get_time_codes_per_seconds()
        for graph in action_graphs():
            if _answers(graph, event):
                action_graph.evaluate(graph, Tick(time, dt, time * fps, playing, event))

    def _on_tick(self, event: Any) -> None:
        self._evaluate_all("playback_tick", float(event.payload["currentTime"]), float(event.payload["dt"]), True)

    def _on_update(self, event: Any) -> None:
        timeline = runtime().timeline
        payload = getattr(event, "payload", {}) or {}
        self._evaluate_all("app_update", timeline.get_current_time(), float(payload.get("dt", 0.0)),
                           timeline.is_playing())

    @staticmethod
    def _on_play(event: Any) -> None:
        omnigraph_usd.sync_stage_graphs(stage_context.get_stage())

    @staticmethod
    def _on_stop(event: Any) -> None:
        for graph in action_graphs():
            action_graph.reset(graph)


_runner = ActionGraphRunner()


class OmniGraphTestCase(kit.AsyncTestCase):
    """``omni.graph.core.tests.OmniGraphTestCase``: an async test case that starts and ends on a new stage with a
    stopped timeline (the base of Isaac's OmniGraph node tests)."""

    async def setUp(self) -> None:
        await kit.get_context().new_stage_async()

    async def tearDown(self) -> None:
        runtime().timeline.stop()
        await kit.get_context().new_stage_async()


def install() -> None:
    """Start evaluating action graphs (compat mode was installed)."""
    _runner.start()


def uninstall() -> None:
    """Stop evaluating action graphs."""
    _runner.stop()


def modules() -> list[types.ModuleType]:
    """``omni.graph.action``'s node types (registered) and the module's name."""
    register_node_types(NODE_TYPES)
    return [CompatModule("omni.graph.action", hint="graphsdg runs the action graphs' event nodes OnPlaybackTick "
                                                   "and OnTick; make graphs with omni.graph.core.Controller.edit"),
            CompatModule("omni.graph.core.tests", OmniGraphTestCase=OmniGraphTestCase)]
