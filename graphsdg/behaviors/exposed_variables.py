"""A behavior's settings as USD attributes on its prim (``exposedVar:<behavior>:<name>``), and script plumbing.

Each behavior declares the variables it exposes (name, Sdf type, default, documentation); attaching it creates
them on the prim (an attribute that exists already keeps its value), scripts read them when the timeline
plays, and detaching a behavior removes them. :func:`add_behavior_script_with_parameters_async` attaches a
script and sets its variables once the script has created them; :func:`publish_event_and_wait_for_completion_async`
sends a control event and waits (app update by app update) for the reply a behavior publishes.

Example:
    >>> import graphsdg as rep
    >>> from pxr import Sdf
    >>> _ = rep.stage.new_stage()
    >>> prim = rep.functional.create.xform(name="Holder")
    >>> create_exposed_variables(prim, EXPOSED_ATTR_NS, "demo", [
    ...     {"attr_name": "interval", "attr_type": Sdf.ValueTypeNames.UInt, "default_value": 3}])
    >>> get_exposed_variable(prim, "exposedVar:demo:interval")
    3
"""
from __future__ import annotations

import logging
from typing import Any, Iterable, Mapping

from pxr import Sdf, Usd

from graphsdg.behaviors import host
from graphsdg.behaviors.script_runtime import SCRIPTS_ATTR, attach_script

EXTENSION_NAME = "isaacsim.replicator.behavior"
EXPOSED_ATTR_NS = "exposedVar"
SCOPE_NAME = "/Behaviors"
EXPOSED_VARS_CHANGED_EVENT = f"{EXTENSION_NAME}.EXPOSED_VARS_CHANGED"
log = logging.getLogger("graphsdg.behaviors")


def _valid(prim: Usd.Prim | None) -> bool:
    return prim is not None and prim.IsValid()


def create_exposed_variable(prim: Usd.Prim, full_attr_name: str, attr_type: Sdf.ValueTypeName, default_value: Any,
                            doc: str | None = None) -> Usd.Attribute:
    """The attribute ``full_attr_name`` of ``prim``, created with ``default_value`` if it is not there."""
    attr = prim.GetAttribute(full_attr_name)
    if attr:
        return attr
    attr = prim.CreateAttribute(full_attr_name, attr_type)
    attr.Set(default_value)
    if doc:
        attr.SetDocumentation(doc)
    return attr


def create_exposed_variables(prim: Usd.Prim, exposed_attr_ns: str, behavior_ns: str,
                             variables_to_expose: Iterable[Mapping[str, Any]]) -> None:
    """Create a behavior's exposed variables on ``prim`` and announce it (``EXPOSED_VARS_CHANGED_EVENT``)."""
    for var in variables_to_expose:
        create_exposed_variable(prim, f"{exposed_attr_ns}:{behavior_ns}:{var['attr_name']}", var["attr_type"],
                                var["default_value"], var.get("doc"))
    host.event_bus().dispatch_event(EXPOSED_VARS_CHANGED_EVENT, payload={})


def check_if_exposed_variables_should_be_removed(prim: Usd.Prim, script_file_path: str) -> bool:
    """Whether ``script_file_path`` is no longer among the prim's scripts (so its variables can go)."""
    if not _valid(prim):
        return False
    attr = prim.GetAttribute(SCRIPTS_ATTR)
    scripts = attr.Get() if attr else None
    return not scripts or not any(script_file_path == a.path for a in scripts)


def remove_exposed_variable(prim: Usd.Prim, full_attr_name: str) -> None:
    """Remove one exposed variable from ``prim`` (a missing one is logged)."""
    if not _valid(prim):
        log.warning("cannot remove %s: the prim is not valid", full_attr_name)
        return
    if prim.GetAttribute(full_attr_name):
        prim.RemoveProperty(full_attr_name)
    else:
        log.warning("%s has no attribute %s", prim.GetPath(), full_attr_name)


def remove_exposed_variables(prim: Usd.Prim, exposed_attr_ns: str, behavior_ns: str,
                             variables_to_expose: Iterable[Mapping[str, Any]]) -> None:
    """Remove a behavior's exposed variables from ``prim`` and announce it."""
    for var in variables_to_expose:
        remove_exposed_variable(prim, f"{exposed_attr_ns}:{behavior_ns}:{var['attr_name']}")
    host.event_bus().dispatch_event(EXPOSED_VARS_CHANGED_EVENT, payload={})


def get_exposed_variable(prim: Usd.Prim, full_attr_name: str) -> Any:
    """The value of ``full_attr_name`` on ``prim`` (None when the prim or attribute is missing)."""
    if not _valid(prim):
        log.warning("cannot read %s: the prim is not valid", full_attr_name)
        return None
    attr = prim.GetAttribute(full_attr_name)
    return attr.Get() if attr else None


def set_exposed_variables(prim: Usd.Prim, exposed_variables: Mapping[str, Any]) -> None:
    """Set each ``{full_attr_name: value}`` on ``prim`` (a name the prim does not have is logged and skipped)."""
    if not _valid(prim):
        log.warning("cannot set exposed variables: the prim is not valid")
        return
    for name, value in exposed_variables.items():
        attr = prim.GetAttribute(name)
        if attr:
            attr.Set(value)
        else:
            log.warning("%s has no attribute %s; it was not set", prim.GetPath(), name)


def remove_empty_scopes(prim: Usd.Prim, stage: Usd.Stage) -> None:
    """Remove, children first, typeless and Scope prims below (and including) ``prim`` that hold nothing."""
    if not _valid(prim):
        return
    for child in prim.GetChildren():
        remove_empty_scopes(child, stage)
    if prim.GetTypeName() in ("", "Scope") and not any(c.IsValid() for c in prim.GetChildren()):
        stage.RemovePrim(prim.GetPath())


def add_behavior_script(prim: Usd.Prim, script_path: str, allow_duplicates: bool = False) -> None:
    """Attach the behavior script ``script_path`` to ``prim`` (once, unless ``allow_duplicates``)."""
    if not _valid(prim):
        log.warning("cannot add a behavior script: the prim is not valid")
        return
    attach_script(prim, script_path, allow_duplicates=allow_duplicates)


async def add_behavior_script_with_parameters_async(prim: Usd.Prim, script_path: str,
                                                    exposed_variables: Mapping[str, Any] | None = None,
                                                    allow_duplicates: bool = False) -> None:
    """Attach a behavior script, wait for it to create its variables (three app updates), then set them."""
    if not _valid(prim):
        log.warning("cannot add a behavior script: the prim is not valid")
        return
    add_behavior_script(prim, script_path, allow_duplicates=allow_duplicates)
    for _ in range(3):
        await host.next_update()
    set_exposed_variables(prim, exposed_variables or {})


async def publish_event_and_wait_for_completion_async(publish_payload: dict, expected_payload: dict,
                                                      publish_event_name: str, subscribe_event_name: str,
                                                      max_wait_updates: int, verbose: bool = True) -> bool:
    """Dispatch ``publish_payload`` as ``publish_event_name`` and wait up to ``max_wait_updates`` app updates
    for a ``subscribe_event_name`` event whose payload holds every item of ``expected_payload``; whether it came."""
    done = False

    def on_reply(event: Any) -> None:
        nonlocal done
        if all(item in dict(event.payload).items() for item in expected_payload.items()):
            done = True
        if verbose:
            log.info("reply %s: %s", "matches" if done else "does not match yet", dict(event.payload))

    bus = host.event_bus()
    observation = bus.observe_event(event_name=subscribe_event_name, on_event=on_reply,
                                    observer_name="behaviors.publish_event_and_wait")
    try:
        bus.dispatch_event(publish_event_name, payload=publish_payload)
        for _ in range(int(max_wait_updates)):
            if done:
                break
            await host.next_update()
        if not done and verbose:
            log.info("no matching %s reply after %d updates", subscribe_event_name, max_wait_updates)
    finally:
        observation.reset()
    return done
