"""Physics domain randomization of cloned environments for RL loops (Isaac's ``domain_randomization`` extension).

Register views of the environments' rigid bodies and articulations (one row
per environment), build a randomization graph under an RL-frame trigger, and
call :func:`step_randomization` once per RL step; the randomized values go
straight into MuJoCo's ``MjModel`` / ``MjData``
(:mod:`graphsdg.physics.domain_randomization` lists the attributes)::

    import graphsdg as rep
    import graphsdg.domain_randomization as dr

    dr.register_simulation_context()
    dr.register_rigid_body_view("/World/envs/.*/object", name="objects")
    with dr.on_rl_frame(num_envs=4):
        with dr.on_interval(interval=20):
            dr.randomize_simulation_context(operation="scaling",
                                            gravity=rep.distribution.uniform((1, 1, 0.5), (1, 1, 2)))
        with dr.on_env_reset():
            dr.randomize_rigid_body_view("objects", operation="additive",
                                         position=rep.distribution.normal((0, 0, 0), (0.2, 0.2, 0)))
    for frame in range(200):
        dr.step_randomization([0, 1, 2, 3] if frame % 50 == 0 else [])
        rep.orchestrator.step()

Operations: ``direct`` writes the samples, ``additive`` / ``scaling`` add them
to / multiply them with each environment's reset values (the registered values,
moved by what an ``on_env_reset`` block writes). Environment ``k`` in an
``on_interval(n)`` block is randomized when its frame count (reset to 0 on its
resets) is a positive multiple of ``n``.
"""
from __future__ import annotations

from typing import Any, Iterable, Sequence

import numpy as np

from graphsdg.errors import GraphBuildError
from graphsdg.graph import scheduler
from graphsdg.graph.builder import add_node
from graphsdg.graph.node import Node, ReplicatorItem
from graphsdg.graph.registry import NodeRegistry
from graphsdg.graph.scopes import current_trigger, implicit_targets
from graphsdg.physics.articulation_tensor_view import ArticulationTensorView
from graphsdg.physics.domain_randomization import (ARTICULATION_ATTRIBUTES, OPERATIONS, RIGID_BODY_ATTRIBUTES,
                                                   SIMULATION_ATTRIBUTES, TENDON_ATTRIBUTES, Target,
                                                   randomization_targets)
from graphsdg.physics.rigid_body_tensor_view import RigidBodyTensorView


def _paths_of(view: Any) -> Any:
    """Prim paths (or a path expression) of ``view``: a path, a list of them, or an object listing its paths."""
    for attr in ("paths", "prim_paths"):
        value = getattr(view, attr, None)
        if value is not None and not callable(value):
            return list(value)
    return view


def register_simulation_context() -> Target:
    """Register the simulation (its gravity) for :func:`randomize_simulation_context`."""
    return randomization_targets().register_simulation()


def register_rigid_body_view(view: Any, name: str) -> Target:
    """Register the rigid bodies ``view`` names (paths, a regular expression, a view) as ``name``."""
    tensor_view = view if isinstance(view, RigidBodyTensorView) else RigidBodyTensorView(_paths_of(view))
    return randomization_targets().register_rigid_bodies(tensor_view, name)


def register_articulation_view(view: Any, name: str) -> Target:
    """Register the articulations ``view`` names (paths, a regular expression, a view) as ``name``."""
    tensor_view = view if isinstance(view, ArticulationTensorView) else ArticulationTensorView(_paths_of(view))
    return randomization_targets().register_articulations(tensor_view, name)


def on_rl_frame(num_envs: int) -> ReplicatorItem:
    """The trigger of an RL loop's randomizations: ``with on_rl_frame(num_envs):`` gates the gates built in it;
    it fires once per :func:`step_randomization` call."""
    if current_trigger() is not None:
        raise GraphBuildError(f"on_rl_frame(num_envs={num_envs!r}) is nested in trigger "
                              f"{current_trigger().name!r}; triggers cannot be nested")
    return add_node(NodeRegistry.create("trigger.on_rl_frame", name="on_rl_frame", num_envs=num_envs),
                    gated=False)


def _rl_trigger(call: str) -> Node:
    trigger = current_trigger()
    if trigger is None or trigger.type_name != "trigger.on_rl_frame":
        raise GraphBuildError(f"{call} must be called inside 'with on_rl_frame(num_envs):' (it gates by the "
                              f"environments' RL frames), not "
                              f"{'outside any trigger' if trigger is None else 'in ' + repr(trigger.name)}")
    return trigger


def _gate(call: str, **values: Any) -> ReplicatorItem:
    trigger = _rl_trigger(call)
    return add_node(NodeRegistry.create("gate.environments", frame_num=ReplicatorItem(trigger, "frame_num"),
                                        reset_inds=ReplicatorItem(trigger, "reset_inds"), **values))


def on_interval(interval: int) -> ReplicatorItem:
    """A gate: the writers in its block randomize the environments whose RL frame is a positive multiple of
    ``interval``."""
    return _gate(f"on_interval(interval={interval!r})", interval=interval)


def on_env_reset() -> ReplicatorItem:
    """A gate: the writers in its block randomize the environments being reset (and move their reset values)."""
    return _gate("on_env_reset()", on_reset=True)


def _current_gate(call: str) -> Node:
    item = implicit_targets()
    if item is None or item.node.type_name != "gate.environments":
        raise GraphBuildError(f"{call}() must be called inside an 'on_interval' or 'on_env_reset' block (the gate "
                              f"picks the environments it randomizes)")
    return item.node


def _writers(call: str, type_name: str, allowed: Sequence[str], view: str, operation: str,
             num_buckets: int | None, attributes: dict[str, Any]) -> list[ReplicatorItem]:
    gate = _current_gate(call)
    if operation not in OPERATIONS:
        raise ValueError(f"{call}: operation must be one of {OPERATIONS}, got {operation!r}")
    unknown = sorted(set(attributes) - set(allowed))
    if unknown:
        raise TypeError(f"{call}() got unknown attribute(s) {unknown}; randomizable attributes: {list(allowed)}")
    tendons = sorted(a for a in TENDON_ATTRIBUTES if attributes.get(a) is not None)
    if tendons:
        raise ValueError(f"{call}(): cannot randomize {tendons} of {view!r}: graphsdg compiles no fixed tendons "
                         f"(MuJoCo's model of the articulation has none)")
    items = []
    for attribute in allowed:          # Isaac's order, whatever the keyword order
        value = attributes.get(attribute)
        if value is None:
            continue
        items.append(add_node(NodeRegistry.create(
            type_name, name=f"{view or 'simulation'}_{attribute}", view=view, attribute=attribute,
            operation=operation, values=value, indices=ReplicatorItem(gate, "indices"),
            on_reset=ReplicatorItem(gate, "on_reset"),
            num_buckets=num_buckets if attribute == "material_properties" else None)))
    return items


def randomize_rigid_body_view(view_name: str, operation: str = "direct", num_buckets: int | None = None,
                              **attributes: Any) -> list[ReplicatorItem]:
    """Randomize attributes (keyword: distribution or plain value per environment) of registered rigid-body
    view ``view_name`` for the enclosing gate's environments."""
    randomization_targets().get(view_name, "rigid_body")
    return _writers("randomize_rigid_body_view", "randomizer.write_rigid_body_view", RIGID_BODY_ATTRIBUTES,
                    view_name, operation, num_buckets, attributes)


def randomize_articulation_view(view_name: str, operation: str = "direct", num_buckets: int | None = None,
                                **attributes: Any) -> list[ReplicatorItem]:
    """Randomize attributes of registered articulation view ``view_name`` for the enclosing gate's
    environments."""
    randomization_targets().get(view_name, "articulation")
    return _writers("randomize_articulation_view", "randomizer.write_articulation_view", ARTICULATION_ATTRIBUTES,
                    view_name, operation, num_buckets, attributes)


def randomize_simulation_context(operation: str = "direct", gravity: Any = None) -> list[ReplicatorItem]:
    """Randomize the simulation's gravity when the enclosing gate picks any environment."""
    randomization_targets().get("simulation", "simulation")
    return _writers("randomize_simulation_context", "randomizer.write_simulation", SIMULATION_ATTRIBUTES, "",
                    operation, None, {"gravity": gravity})


def rl_triggers() -> list[Node]:
    """The RL-frame triggers of the current graph."""
    graph = scheduler.active_graph()
    if graph is None:
        return []
    return [t for t in graph.triggers if t.type_name == "trigger.on_rl_frame"]


def step_randomization(reset_inds: Iterable[int] | np.ndarray | None = None) -> list[Node]:
    """One RL step: environments ``reset_inds`` restart at frame 0, every RL-frame trigger fires and its gates'
    writers randomize now; returns the nodes run."""
    triggers = rl_triggers()
    if not triggers:
        raise GraphBuildError("step_randomization(): the graph has no on_rl_frame trigger; build the "
                              "randomizations inside 'with on_rl_frame(num_envs):' first")
    resets = np.asarray([] if reset_inds is None else list(np.asarray(reset_inds).reshape(-1)), dtype=np.int64)
    for trigger in triggers:
        trigger.prepare(resets)
    return scheduler.fire_now(triggers)


__all__ = ["register_simulation_context", "register_rigid_body_view", "register_articulation_view",
           "on_rl_frame", "on_interval", "on_env_reset", "randomize_rigid_body_view",
           "randomize_articulation_view", "randomize_simulation_context", "step_randomization", "rl_triggers",
           "RIGID_BODY_ATTRIBUTES", "ARTICULATION_ATTRIBUTES", "SIMULATION_ATTRIBUTES"]
