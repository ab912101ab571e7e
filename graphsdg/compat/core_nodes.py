"""Isaac compat area: the Python names of ``isaacsim.core.nodes`` (its OmniGraph node bases and helpers).

* ``BaseResetNode``: a node state object whose ``custom_reset()`` runs when the timeline stops (Kit's
  ``omni.timeline`` stop event through ``carb.eventdispatcher``), after which it is uninitialized;
* ``BaseWriterNode`` (and ``WriterRequest``): queues writer attach / detach requests and carries them out at
  the next app update, attaching Isaac's ``IsaacNoop`` annotator too (as Isaac does to keep the capture graph
  alive); stopping the timeline detaches its writers;
* ``register_node_writer_with_telemetry`` / ``register_annotator_from_node_with_telemetry``: Replicator's
  node-based registrations plus the telemetry lists; graphsdg has no OmniGraph node types to build writers or
  annotators from, so they raise Replicator's registration error naming the Python alternatives;
* ``scripts.utils.set_target_prims``: points a prim's relationship at target prims.

Of the extension's OmniGraph node types, ``IsaacArticulationController`` and ``IsaacComputeOdometry`` run in
action graphs (:mod:`graphsdg.compat.core_node_types`); the others (``IsaacCreateRenderProduct``, ...) raise
``CompatError`` naming them.
"""
from __future__ import annotations

import copy
import logging
import types
from typing import Any

from pxr import Usd

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.compat.event_dispatch import get_eventdispatcher
from graphsdg.compat.event_names import APP_UPDATE, TIMELINE_EVENT_NAMES
from graphsdg.compat.modules import CompatModule
from graphsdg.io.writer import WriterRegistry
from graphsdg.sim.timeline import TimelineEventType
from graphsdg.stage.context import get_stage

NAME = "isaacsim.core.nodes"
EXTENSIONS = {NAME: (NAME,)}
STOP_EVENT = TIMELINE_EVENT_NAMES[TimelineEventType.STOP][1]
log = logging.getLogger("carb")


class BaseResetNode:
    """A node's state that resets itself when the timeline stops (``custom_reset``, then uninitialized)."""

    def __init__(self, initialize: bool = False) -> None:
        self.initialized = initialize
        self.timeline_event_sub = get_eventdispatcher().observe_event(
            event_name=STOP_EVENT, on_event=self.on_stop_play, observer_name=f"{NAME}.BaseResetNode.on_stop_play")

    def on_stop_play(self, event: Any) -> None:
        """The timeline stopped: reset."""
        self.custom_reset()
        self.initialized = False

    def custom_reset(self) -> None:
        """What a subclass resets when the timeline stops."""

    def reset(self) -> None:
        """Stop listening to the timeline and forget the initialization state."""
        if self.timeline_event_sub is not None:
            self.timeline_event_sub.reset()
        self.timeline_event_sub = None
        self.initialized = None


class WriterRequest:
    """A queued attach (``activate``) or detach of ``writer`` on ``render_product_path``."""

    def __init__(self, writer: Any, render_product_path: str | list[str] | None, activate: bool = True) -> None:
        self.writer = writer
        self.render_product_path = render_product_path
        self.activate = activate

    def __repr__(self) -> str:
        annotators = "".join(f"\t\t{a}\n" for a in getattr(self.writer, "annotators", []))
        return f"{type(self.writer).__name__}\n\t{self.render_product_path}\n\tAnnotators:\n{annotators}"


class BaseWriterNode(BaseResetNode):
    """A node that attaches copies of writers to render products at the next app update (see module docstring)."""

    def __init__(self, initialize: bool = False) -> None:
        self._writers: list[Any] = []
        self._requests: list[WriterRequest] = []
        self._event_stream: Any = None
        super().__init__(initialize=False)

    def custom_reset(self) -> None:
        for writer in self._writers:
            self._append_request(WriterRequest(writer, None, False))
        self._writers = []
        self.initialized = False

    def append_writer(self, writer: Any) -> None:
        """Keep a copy of ``writer`` for :meth:`attach_writers`."""
        self._writers.append(copy.deepcopy(writer))

    def attach_writers(self, render_product_path: str | list[str]) -> None:
        """Queue attaching every kept writer to ``render_product_path``."""
        for writer in self._writers:
            self._append_request(WriterRequest(writer, render_product_path, True))

    def attach_writer(self, writer: Any, render_product_path: str | list[str]) -> None:
        """Keep a copy of ``writer`` and queue attaching it to ``render_product_path``."""
        self._writers.append(copy.deepcopy(writer))
        self._append_request(WriterRequest(self._writers[-1], render_product_path, True))

    def _append_request(self, request: WriterRequest) -> None:
        self._requests.append(request)
        if self._event_stream is None:
            self._event_stream = get_eventdispatcher().observe_event(
                event_name=APP_UPDATE, on_event=self._process_activation_requests,
                observer_name="BaseWriterNode._process_activation_requests")

    def _process_activation_requests(self, event: Any) -> None:
        stage = get_stage()
        guard, self._event_stream = self._event_stream, None
        if guard is not None:
            guard.reset()
        if stage is None:
            return
        requests, self._requests = self._requests, []
        with Usd.EditContext(stage, stage.GetSessionLayer()):
            for request in requests:
                try:
                    if request.activate:
                        request.writer.attach(request.render_product_path)
                        self.post_attach(request.writer, request.render_product_path)
                        AnnotatorRegistry.get_annotator("IsaacNoop").attach(request.render_product_path)
                    else:
                        request.writer.detach()
                except Exception as exc:  # noqa: BLE001 - Kit logs a failed request and goes on
                    log.error("could not process writer request %r: %s", request, exc)

    def post_attach(self, writer: Any, render_product: str | list[str]) -> None:
        """Called after ``writer`` is attached to ``render_product`` (subclasses add to it)."""


def register_node_writer_with_telemetry(*args: Any, **kwargs: Any) -> None:
    """Replicator's ``register_node_writer`` plus the telemetry list (it raises here: no OmniGraph node types)."""
    WriterRegistry.register_node_writer(*args, **kwargs)
    if kwargs["name"] not in WriterRegistry._default_writers:
        WriterRegistry._default_writers.append(kwargs["name"])


def register_annotator_from_node_with_telemetry(*args: Any, **kwargs: Any) -> None:
    """Replicator's ``register_annotator_from_node`` plus the telemetry list (it raises here, naming the
    Python alternatives)."""
    AnnotatorRegistry.register_annotator_from_node(*args, **kwargs)
    if kwargs["name"] not in AnnotatorRegistry._default_annotators:
        AnnotatorRegistry._default_annotators.append(kwargs["name"])


def set_target_prims(primPath: str, targetPrimPaths: list, inputName: str = "inputs:targetPrim") -> None:  # noqa: N803
    """Point the relationship ``inputName`` of the prim at ``primPath`` at ``targetPrimPaths``."""
    prim = get_stage().GetPrimAtPath(str(primPath))
    if not prim:
        raise ValueError(f"set_target_prims: no prim at {primPath!r}")
    prim.CreateRelationship(inputName).SetTargets([str(p) for p in targetPrimPaths])


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.nodes``, its ``impl`` and ``scripts.utils``."""
    bases = dict(BaseResetNode=BaseResetNode, BaseWriterNode=BaseWriterNode, WriterRequest=WriterRequest)
    registrations = dict(register_node_writer_with_telemetry=register_node_writer_with_telemetry,
                         register_annotator_from_node_with_telemetry=register_annotator_from_node_with_telemetry)
    utils = CompatModule(f"{NAME}.scripts.utils", set_target_prims=set_target_prims, **registrations)
    return [CompatModule(NAME, **bases, **registrations),
            CompatModule(f"{NAME}.impl", **bases),
            CompatModule(f"{NAME}.scripts", utils=utils), utils]
