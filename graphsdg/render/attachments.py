"""What is attached to render products: the annotators and writers a capture feeds.

An :class:`~graphsdg.annotate.annotator.Annotator` or a
:class:`~graphsdg.io.writer.Writer` enters :data:`attachments` when it attaches
to a render product and leaves when it detaches; the runtime and the
orchestrator read the registry to know what to render, annotate and write. It
sits below both annotate/ and io/ so that neither reaches up into the runtime.

A ``step(wait_for_render=False)`` leaves its annotate-and-write work here
(:attr:`Attachments.pending_capture`): attaching, detaching or reading an
annotator's data first completes it (:meth:`Attachments.complete_capture`).

Attachments belong to the stage's session: when the stage is replaced, the
render products are destroyed and every writer and annotator detaches.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0))
    >>> rp = rep.create.render_product(cam, (64, 48))
    >>> rgb = rep.annotators.get("rgb").attach(rp)
    >>> rgb in attachments.annotators
    True
    >>> _ = rep.stage.new_stage()      # a new stage releases every attachment
    >>> rgb in attachments.annotators, rp.destroyed
    (False, True)
"""
from __future__ import annotations

from typing import Any, Callable, Generic, Iterator, TypeVar

from pxr import Usd

from graphsdg.errors import RenderProductDestroyedError

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


class Attachments:
    """The attached annotators and writers, and the capture a pipelined step left pending."""

    def __init__(self) -> None:
        self.annotators: OrderedSet[Any] = OrderedSet()
        self.writers: OrderedSet[Any] = OrderedSet()
        # a step(wait_for_render=False) whose annotators and writers have not run yet
        self.pending_capture: Callable[[], None] | None = None

    def complete_capture(self) -> None:
        """Annotate and write the capture a ``step(wait_for_render=False)`` left pending, if any."""
        finish, self.pending_capture = self.pending_capture, None
        if finish is not None:
            finish()

    def check_live(self) -> None:
        """Raise if an attached annotator or writer still points at a destroyed render product."""
        for owner in list(self.writers) + list(self.annotators):
            for rp in owner.render_products:
                if rp.destroyed:
                    kind = "writer" if owner in self.writers else "annotator"
                    name = type(owner).__name__ if kind == "writer" else owner.name
                    raise RenderProductDestroyedError(
                        f"render product {rp.name!r} ({rp.path}) was destroyed but {kind} {name!r} is still "
                        f"attached to it; call detach() before destroy(), or attach to a live render product")

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """Detach every writer, then every annotator (the stage was replaced; the session destroyed the render
        products first and resets the runtime after, so the writers write what they still hold for the old
        stage)."""
        for w in list(self.writers):
            w.detach()
        for a in list(self.annotators):
            a.detach()


#: The process's attachments (held by the session, :mod:`graphsdg.engine.session`).
attachments = Attachments()
