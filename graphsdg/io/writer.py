"""The Writer base class and the writer registry.

A writer declares ``annotators`` (names or :class:`Annotator` objects) and a
``data_structure``; after ``attach(render_products)`` it receives one ``data``
dict per captured frame in :meth:`Writer.write`, shaped as in Replicator:

* ``"legacy"``: ``{anno: data}`` (one product) or ``{"anno-rp_name": data}``;
* ``"annotator"``: ``{"annotators": {anno: {rp_name: {"data": ..., **info}}}}``;
* ``"renderProduct"``: ``{"renderProducts": {rp_name: {"camera", "resolution", anno: {...}}}}``;

each also with ``trigger_outputs`` and ``reference_time``.

Example:
    >>> import graphsdg as rep
    >>> class CountingWriter(rep.Writer):
    ...     def __init__(self):
    ...         self.annotators = ["rgb"]
    ...         self.frames = 0
    ...     def write(self, data):
    ...         self.frames += 1
    >>> rep.WriterRegistry.register(CountingWriter)
    >>> rep.writers.get("CountingWriter").__class__.__name__
    'CountingWriter'
"""
from __future__ import annotations

import inspect
from typing import Any, Iterable

from graphsdg import rng
from graphsdg.annotate.annotator import Annotator, AnnotatorRegistry, shape_output
from graphsdg.errors import closest, unknown_name
from graphsdg.io.io_functions import write_json
from graphsdg.render.attachments import attachments
from graphsdg.render.render_product import RenderProduct, registry as rp_registry

DATA_STRUCTURES = ("legacy", "annotator", "renderProduct")
ON_FRAME = "omni.replicator.core.OgnOnFrame"


class Writer:
    """Base class of dataset writers (``rep.Writer``)."""

    backend: Any = None
    version: str = "0.0.0"
    annotators: list = []
    num_written: int = 0
    data_structure: str = "legacy"
    #: True for writers that name a frame's files by ``data["frame_index"]`` when it is given (sharded and
    #: resumed runs pass it); only such writers can be sharded or resumed.
    frame_indexed: bool = False

    def __new__(cls, *args: Any, **kwargs: Any) -> "Writer":
        # Per-instance defaults (Replicator seeds them in __new__ too), so a subclass
        # __init__ that appends to self.annotators never touches a shared list.
        instance = super().__new__(cls)
        instance.annotators = []
        instance.num_written = 0
        return instance

    def write(self, data: dict) -> None:
        """Called once per captured frame."""
        raise NotImplementedError(f"{type(self).__name__} must implement write(self, data)")

    def initialize(self, **kwargs: Any) -> None:
        """Construct the writer with ``kwargs`` (``WriterRegistry.get(name).initialize(...)``)."""
        sig = inspect.signature(type(self).__init__)
        params = sig.parameters
        if not any(p.kind == p.VAR_KEYWORD for p in params.values()):
            unknown = [k for k in kwargs if k not in params]
            if unknown:
                known = [k for k in params if k != "self"]
                hints = "".join(closest(k, known) for k in unknown)
                raise TypeError(f"{type(self).__name__}.initialize() got unknown parameter(s) {unknown}{hints}; "
                                f"known: {known}")
        self.__init__(**kwargs)  # type: ignore[misc]
        self._initialized = True
        self._needs_initialize = False

    # ---- attachment ----------------------------------------------------
    def _annotator_objects(self) -> list[Annotator]:
        objs = getattr(self, "_annotator_objs", None)
        if objs is None:
            objs = []
            for entry in self.annotators or []:
                if isinstance(entry, Annotator):
                    objs.append(entry)
                elif isinstance(entry, str):
                    objs.append(AnnotatorRegistry.get_annotator(entry))
                else:
                    raise TypeError(f"{type(self).__name__}.annotators holds {entry!r}; expected annotator "
                                    f"names or rep.annotators.get(...) objects")
            self._annotator_objs = objs
        return objs

    def get_annotators(self) -> dict[str, Annotator]:
        """The writer's annotators by name (their keys in ``data``)."""
        return {a.name: a for a in self._annotator_objects()}

    def get_annotator(self, name: str) -> Annotator | None:
        """The writer's annotator called ``name``, or None."""
        return self.get_annotators().get(name)

    def add_annotator(self, annotator: "Annotator | str", name: str | None = None) -> None:
        """Add ``annotator`` (an object or a name); one of the same name is replaced, as in Replicator.

        ``name`` renames the annotator (its key in ``data``).
        """
        if isinstance(annotator, str):
            annotator = AnnotatorRegistry.get_annotator(annotator)
        if not isinstance(annotator, Annotator):
            raise TypeError(f"{type(self).__name__}.add_annotator expects an annotator or an annotator name, got "
                            f"{type(annotator).__name__} {annotator!r}")
        if name:
            annotator.name = name
        annotators = self.get_annotators()
        annotators[annotator.name] = annotator
        self.annotators = list(annotators.values())
        self._annotator_objs = None

    def augment_annotator(self, annotator_name: str, augmentation: Any, **kwargs: Any) -> None:
        """Augment the writer's annotator ``annotator_name`` (its data keeps that name); ``augmentation`` as
        for ``Annotator.augment``, ``kwargs`` its parameters."""
        annotators = self.get_annotators()
        if annotator_name not in annotators:
            raise ValueError(f"{type(self).__name__} has no annotator {annotator_name!r} to augment"
                             f"{closest(str(annotator_name), annotators)}; its annotators: {sorted(annotators)}")
        annotators[annotator_name].augment(augmentation, **kwargs)
        self.annotators = list(annotators.values())
        self._annotator_objs = None

    @property
    def render_products(self) -> list[RenderProduct]:
        return list(getattr(self, "_render_products", []))

    def attach(self, render_products: "RenderProduct | str | Iterable[RenderProduct | str]",
               trigger: Any = ON_FRAME) -> None:
        """Attach to render products; frames are written when ``trigger`` fires (every step by default)."""
        if render_products is None or (isinstance(render_products, (list, tuple)) and not render_products):
            raise ValueError(f"{type(self).__name__}.attach() needs at least one render product, got "
                             f"{render_products!r}")
        if self.data_structure not in DATA_STRUCTURES:
            raise ValueError(f"{type(self).__name__}.data_structure is {self.data_structure!r}; expected one of "
                             f"{DATA_STRUCTURES}")
        items = render_products if isinstance(render_products, (list, tuple)) else [render_products]
        rps = [rp_registry.find(item) for item in items]
        annotators = self._annotator_objects()
        if not annotators:
            if getattr(self, "_needs_initialize", False):
                raise ValueError(f"{type(self).__name__}.attach() before initialize(): call "
                                 f"writer.initialize(...) first (BasicWriter: e.g. output_dir='_out', rgb=True)")
            raise ValueError(f"{type(self).__name__} has no annotators to write; set self.annotators "
                             f"(e.g. rgb=True for BasicWriter)")
        self._render_products = rps
        self.num_written = 0
        self._trigger = trigger
        self._manual_requests = 0
        for a in annotators:
            a.attach(rps)
        attachments.writers.add(self)

    def attach_async(self, render_products, trigger: Any = ON_FRAME):
        async def _attach():
            self.attach(render_products, trigger)
        return _attach()

    def detach(self) -> None:
        """Stop receiving frames (aggregate files are flushed first); the writer's annotators detach."""
        if self in attachments.writers:
            attachments.complete_capture()   # the frame a pipelined step left pending is this writer's too
            self.flush()
        for a in self._annotator_objects():
            a.detach(self.render_products) if self.render_products else None
        self._render_products = []
        attachments.writers.discard(self)

    def schedule_write(self) -> None:
        """With ``attach(..., trigger=None)``: write the next captured frame."""
        self._manual_requests = getattr(self, "_manual_requests", 0) + 1

    def wants_frame(self, fired_triggers: set) -> bool:
        trigger = getattr(self, "_trigger", ON_FRAME)
        if trigger is None:
            if getattr(self, "_manual_requests", 0) > 0:
                self._manual_requests -= 1
                return True
            return False
        if trigger == ON_FRAME or isinstance(trigger, str):
            return True
        if callable(trigger) and not hasattr(trigger, "node"):
            return bool(trigger())
        return trigger in fired_triggers

    def on_final_frame(self) -> None:
        """Called when generation stops (``orchestrator.stop()``, the end of ``run()``)."""

    def flush(self) -> None:
        """Schedule the current state of aggregate files (a dataset-wide json, an open shard).

        Writers that keep such files override this; ``orchestrator.wait_until_complete()``
        and :meth:`detach` call it, so the files on disk are complete after either.
        """

    def frame_complete(self, frame_index: int) -> bool:
        """Whether every file of frame ``frame_index`` is on disk (``--resume`` skips such frames)."""
        return False

    def shard_info(self) -> dict:
        """What the merge step of a sharded run needs: ``{"aggregates": {final path: shard path}, ...}``."""
        return {}

    def get_metadata(self) -> dict:
        """The writer's metadata: name, version and the global seed."""
        self.metadata = {"name": type(self).__name__, "version": self.version,
                         "replicator_global_seed:": rng.get_global_seed()}
        return self.metadata

    def write_metadata(self) -> None:
        """Schedule ``metadata.txt`` (Replicator's JSON, stray colon in the seed key included).

        Called before the first frame a writer writes; a writer without a backend writes none.
        """
        if self.backend is None:
            return
        self.backend.schedule(write_json, data=self.get_metadata(), path="metadata.txt")
        self._is_metadata_written = True

    def _write(self, data: dict) -> None:
        """What the orchestrator calls per captured frame: metadata first, then :meth:`write`."""
        if not getattr(self, "_is_metadata_written", False):
            self.write_metadata()
        self.write(data)
        self.num_written = (self.num_written or 0) + 1

    # ---- data assembly -------------------------------------------------
    def build_payload(self, outputs: dict[tuple[int, str], dict], trigger_outputs: dict,
                      reference_time: tuple[int, int], extra: dict | None = None) -> dict:
        """Shape per-(annotator, render product) outputs into this writer's ``data_structure``."""
        annotators = self._annotator_objects()
        rps = self.render_products
        data: dict[str, Any]
        if self.data_structure == "legacy":
            data = {}
            for a in annotators:
                for rp in rps:
                    out = outputs.get((id(a), rp.path))
                    if out is None:
                        continue
                    key = a.name if len(rps) == 1 else f"{a.name}-{rp.name}"
                    data[key] = shape_output(out, legacy=True)
        elif self.data_structure == "annotator":
            data = {"annotators": {}}
            for a in annotators:
                per_rp = {}
                for rp in rps:
                    out = outputs.get((id(a), rp.path))
                    if out is not None:
                        per_rp[rp.name] = shape_output(out, legacy=False)
                data["annotators"][a.name] = per_rp
        else:
            data = {"renderProducts": {}}
            for rp in rps:
                entry: dict[str, Any] = {"camera": rp.camera, "resolution": [rp.width, rp.height]}
                for a in annotators:
                    out = outputs.get((id(a), rp.path))
                    if out is not None:
                        entry[a.name] = shape_output(out, legacy=False)
                data["renderProducts"][rp.name] = entry
        data["trigger_outputs"] = dict(trigger_outputs)
        data["reference_time"] = reference_time
        if extra:
            data.update(extra)
        return data


class WriterRegistry:
    """Registry of writer classes (``rep.WriterRegistry``)."""

    _writers: dict[str, tuple[type[Writer], str | None]] = {}
    #: names of the writers graphsdg ships (those registered in the "default" category); Replicator keeps this
    #: list for its telemetry and extensions append their writers to it
    _default_writers: list[str] = []

    @classmethod
    def register(cls, writer_cls: type[Writer], category: str | None = None) -> None:
        """Register a :class:`Writer` subclass under its class name."""
        if not (inspect.isclass(writer_cls) and issubclass(writer_cls, Writer)):
            raise TypeError(f"WriterRegistry.register expects a rep.Writer subclass, got {writer_cls!r}")
        cls._writers[writer_cls.__name__] = (writer_cls, category)
        if category == "default" and writer_cls.__name__ not in cls._default_writers:
            cls._default_writers.append(writer_cls.__name__)

    @classmethod
    def unregister(cls, name: str) -> None:
        """Remove writer ``name``; its attached instances detach first. An unknown name raises, listing the known."""
        if name not in cls._writers:
            raise unknown_name("writer", name, cls._writers)
        for writer in [w for w in attachments.writers if type(w).__name__ == name]:
            writer.detach()
        del cls._writers[name]

    unregister_writer = unregister   # Replicator's other name for it

    @classmethod
    def register_node_writer(cls, name: str, node_type_id: str, annotators: list, category: str | None = None,
                             **kwargs: Any) -> None:
        """Replicator registers writers implemented as OmniGraph nodes (ROS 2 publishers, ...); graphsdg has none."""
        raise NotImplementedError(
            f"register_node_writer({name!r}, node_type_id={node_type_id!r}, ...) registers a writer implemented as "
            f"an OmniGraph node, and graphsdg has no OmniGraph nodes. Subclass rep.Writer (write(data) receives the "
            f"annotators' data each frame) and register it with rep.writers.register_writer(cls)")

    @classmethod
    def get(cls, name: str, init_params: dict | None = None, render_products=None,
            trigger: Any = ON_FRAME) -> Writer:
        """A new writer of type ``name``; initialized and attached if those arguments are given."""
        entry = cls._writers.get(name)
        if entry is None:
            raise unknown_name("writer", name, cls._writers)
        writer_cls = entry[0]
        writer = writer_cls.__new__(writer_cls)
        writer._needs_initialize = True      # made without __init__: initialize() constructs it
        if init_params is not None:
            writer.initialize(**init_params)
        if render_products is not None:
            writer.attach(render_products, trigger=trigger)
        return writer

    @classmethod
    def get_writers(cls, category: str | None = None) -> dict[str, type[Writer]]:
        return {n: c for n, (c, cat) in cls._writers.items() if category is None or cat == category}

    @classmethod
    def get_attached_writers(cls) -> list[Writer]:
        return list(attachments.writers)

    @classmethod
    def detach_all(cls) -> None:
        for w in cls.get_attached_writers():
            w.detach()
