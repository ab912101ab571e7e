"""``isaacsim.replicator.experimental.domain_randomization`` and the deprecated ``isaacsim.replicator.domain_randomization``.

Both map onto :mod:`graphsdg.domain_randomization` (views on the MuJoCo model,
an RL-frame trigger, environment gates and view writers in graphsdg's graph):

================================================  ==========================================================
``physics_view.register_simulation_context()``    the simulation's gravity (the deprecated one takes the World)
``physics_view.register_rigid_prim_view(v, name)`` the rigid bodies of ``v`` (a RigidPrim: its paths); the
                                                  deprecated one takes the view's ``name``
``physics_view.register_articulation_view(...)``  likewise for articulations
``trigger.on_rl_frame(num_envs)``                 the RL-frame trigger
``gate.on_interval(n)``, ``gate.on_env_reset()``  the environment gates
``physics_view.randomize_*``                      the view writers (``rigid_prim`` -> rigid body views)
``physics_view.step_randomization(reset_inds)``   fire the trigger now (one RL step)
================================================  ==========================================================

The writers' OmniGraph node types (``isaacsim.replicator.domain_randomization.OgnWritePhysics*``)
are graphsdg's writer nodes, so graphs built with ``og.Controller`` drive them too.
"""
from __future__ import annotations

import json
import types
from collections.abc import Mapping
from typing import Any, Iterator

import numpy as np

from graphsdg import domain_randomization as dr
from graphsdg.compat.modules import CompatModule
from graphsdg.graph import attributes
from graphsdg.physics import domain_randomization as engine
from graphsdg.physics import gravity
from graphsdg.stage.context import stage_context

EXPERIMENTAL = "isaacsim.replicator.experimental.domain_randomization"
DEPRECATED = "isaacsim.replicator.domain_randomization"
EXTENSIONS = {EXPERIMENTAL: (EXPERIMENTAL,), DEPRECATED: (DEPRECATED,)}

# the writer nodes' OmniGraph type names, their attribute names and the inputs OmniGraph makes them with
_WRITER_TYPES = {"OgnWritePhysicsRigidPrimView": ("randomizer.write_rigid_body_view", "position"),
                 "OgnWritePhysicsArticulationView": ("randomizer.write_articulation_view", "joint_positions"),
                 "OgnWritePhysicsSimulationContext": ("randomizer.write_simulation", "gravity")}
_WRITER_PORTS = {"prims": "view", "dist_param_1": "bucket_lower", "dist_param_2": "bucket_upper"}

_originals: dict[str, Any] = {}          # the view objects scripts registered, by name


def _on_stage_replaced(stage: object) -> None:
    _originals.clear()


stage_context.subscribe_replaced(_on_stage_replaced)


class _Registered(Mapping):
    """A read-only live view of the registered views (Isaac's ``physics_view._rigid_prim_views`` and the like)."""

    def __init__(self, kind: str, what: str) -> None:
        self.kind, self.what = kind, what

    def _targets(self) -> dict[str, engine.Target]:
        return {n: t for n, t in engine.randomization_targets().targets.items() if t.kind == self.kind}

    def __getitem__(self, name: str) -> Any:
        target = self._targets()[name]
        if self.what == "view":
            return _originals.get(name, target.view)
        return getattr(target, self.what)

    def __iter__(self) -> Iterator[str]:
        return iter(self._targets())

    def __len__(self) -> int:
        return len(self._targets())


class _PhysicsViewModule(CompatModule):
    """``physics_view``: assigning an empty dict to one of its registries (Isaac's tests reset module state
    that way) forgets the registered views of that kind; the registries stay live views."""

    def __setattr__(self, name: str, value: Any) -> None:
        current = self.__dict__.get(name)
        if isinstance(current, _Registered) and not isinstance(value, _Registered):
            if value:
                raise ValueError(f"physics_view.{name} is graphsdg's live registry; register views with "
                                 f"register_*_view instead of assigning {value!r}")
            targets = engine.randomization_targets().targets
            for view_name in [n for n, t in targets.items() if t.kind == current.kind]:
                del targets[view_name]
                _originals.pop(view_name, None)
            return
        super().__setattr__(name, value)


# ---- physics_view -----------------------------------------------------------------------------------------
def register_simulation_context(simulation_context: Any = None) -> None:
    """Register the simulation's gravity (``simulation_context``: SimulationManager or a World; its physics is
    graphsdg's one simulation either way)."""
    dr.register_simulation_context()


def register_rigid_prim_view(rigid_prim_view: Any, name: str | None = None) -> None:
    """Register the rigid bodies of ``rigid_prim_view`` as ``name`` (the deprecated form: the view's ``name``)."""
    name = name if name is not None else getattr(rigid_prim_view, "name", None)
    dr.register_rigid_body_view(rigid_prim_view, name)
    _originals[name] = rigid_prim_view


def register_articulation_view(articulation_view: Any, name: str | None = None) -> None:
    """Register the articulations of ``articulation_view`` as ``name`` (deprecated form: the view's ``name``)."""
    name = name if name is not None else getattr(articulation_view, "name", None)
    dr.register_articulation_view(articulation_view, name)
    _originals[name] = articulation_view


def step_randomization(reset_inds: Any = None) -> None:
    """One RL step: reset ``reset_inds``' frame counters and run the randomizations now."""
    if reset_inds is not None and hasattr(reset_inds, "cpu"):      # a torch tensor
        reset_inds = reset_inds.cpu().numpy()
    dr.step_randomization(reset_inds)


def randomize_rigid_prim_view(view_name: str, operation: str = "direct", num_buckets: int | None = None,
                              **attributes: Any) -> None:
    """Randomize attributes of registered rigid-prim view ``view_name`` for the enclosing gate's environments."""
    dr.randomize_rigid_body_view(view_name, operation, num_buckets, **attributes)


def randomize_articulation_view(view_name: str, operation: str = "direct", num_buckets: int | None = None,
                                **attributes: Any) -> None:
    """Randomize attributes of registered articulation view ``view_name`` for the enclosing gate's environments."""
    dr.randomize_articulation_view(view_name, operation, num_buckets, **attributes)


def randomize_simulation_context(operation: str = "direct", gravity: Any = None) -> None:
    """Randomize the simulation's gravity."""
    dr.randomize_simulation_context(operation, gravity)


def resolve_rigid_prim_view(view_name: str) -> Any:
    """The rigid-prim view registered as ``view_name`` (None if none)."""
    return _Registered("rigid_body", "view").get(view_name)


def resolve_articulation_view(view_name: str) -> Any:
    """The articulation view registered as ``view_name`` (None if none)."""
    return _Registered("articulation", "view").get(view_name)


class SimulationView:
    """The registered simulation as PhysX's simulation view: its gravity."""

    def get_gravity(self) -> np.ndarray:
        return gravity.get_gravity()

    def set_gravity(self, value: Any) -> None:
        gravity.set_gravity([value[0], value[1], value[2]])


def resolve_physics_sim_view() -> SimulationView | None:
    """The registered simulation (None before ``register_simulation_context``)."""
    return SimulationView() if engine.randomization_targets().simulation is not None else None


def cleanup() -> None:
    """Forget every registered view (Isaac does this when the stage closes; graphsdg too)."""
    engine.randomization_targets().clear()
    _originals.clear()


# ---- context ----------------------------------------------------------------------------------------------
def get_reset_inds() -> np.ndarray | None:
    """The environments reset by the last ``step_randomization`` (None before the first)."""
    triggers = dr.rl_triggers()
    return triggers[0].output_values.get("reset_inds") if triggers and triggers[0].exec_count else None


# ---- utils ------------------------------------------------------------------------------------------------
def set_distribution_params(distribution: Any, parameters: dict) -> None:
    """Set inputs of a distribution item by name (``{"lower": ..., "upper": ...}``)."""
    node = distribution.node
    for parameter, value in parameters.items():
        if not node.get_attribute_exists("inputs:" + parameter):
            raise ValueError(f"This distribution does not have a parameter: `{parameter}`")
        node.get_attribute("inputs:" + parameter).set(value)


def get_distribution_params(distribution: Any, parameters: list[str]) -> list:
    """The distribution item's inputs ``parameters``, as arrays."""
    node = distribution.node
    out = []
    for parameter in parameters:
        if not node.get_attribute_exists("inputs:" + parameter):
            raise ValueError(f"This distribution does not have a parameter: `{parameter}`")
        out.append(np.asarray(node.get_attribute("inputs:" + parameter).get()))
    return out


def get_image_space_points(points: Any, view_proj_matrix: Any) -> np.ndarray:
    """(N, 3) world points projected by a row-vector view-projection matrix into image space ([0, 1] x, y; depth)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    clip = np.concatenate([pts, np.ones((len(pts), 1))], axis=1) @ np.asarray(view_proj_matrix, dtype=np.float64)
    ndc = clip[:, :3] / clip[:, 3:4]
    ndc[:, :2] = (ndc[:, :2] + 1.0) / 2.0
    return ndc


def calculate_truncation_ratio_simple(corners: Any, img_width: float, img_height: float) -> float:
    """The fraction of the projected corners' bounding box outside the image (1: fully outside)."""
    pts = np.asarray(corners, dtype=np.float64).reshape(-1, 2)
    (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
    area = (x1 - x0) * (y1 - y0)
    if area <= 0:
        return 1.0
    cx0, cy0 = np.clip(x0, 0, img_width), np.clip(y0, 0, img_height)
    cx1, cy1 = np.clip(x1, 0, img_width), np.clip(y1, 0, img_height)
    return float(1.0 - max(cx1 - cx0, 0.0) * max(cy1 - cy0, 0.0) / area)


class NumpyEncoder(json.JSONEncoder):
    """A JSON encoder that writes numpy arrays as lists."""

    def default(self, obj: Any) -> Any:
        if isinstance(obj, np.ndarray):
            return obj.tolist()
        return super().default(obj)


# ---- modules ----------------------------------------------------------------------------------------------
def _package(root: str) -> list[types.ModuleType]:
    constants = {"ARTICULATION_ATTRIBUTES": list(engine.ARTICULATION_ATTRIBUTES),
                 "RIGID_PRIM_ATTRIBUTES": list(engine.RIGID_BODY_ATTRIBUTES),
                 "SIMULATION_CONTEXT_ATTRIBUTES": list(engine.SIMULATION_ATTRIBUTES),
                 "TENDON_ATTRIBUTES": list(engine.TENDON_ATTRIBUTES)}
    physics_view = _PhysicsViewModule(
        f"{root}.physics_view", register_simulation_context=register_simulation_context,
        register_rigid_prim_view=register_rigid_prim_view, register_articulation_view=register_articulation_view,
        step_randomization=step_randomization, randomize_rigid_prim_view=randomize_rigid_prim_view,
        randomize_articulation_view=randomize_articulation_view,
        randomize_simulation_context=randomize_simulation_context, resolve_rigid_prim_view=resolve_rigid_prim_view,
        resolve_articulation_view=resolve_articulation_view, resolve_physics_sim_view=resolve_physics_sim_view,
        cleanup=cleanup,
        _rigid_prim_views=_Registered("rigid_body", "view"),
        _rigid_prim_views_initial_values=_Registered("rigid_body", "initial"),
        _rigid_prim_views_reset_values=_Registered("rigid_body", "reset"),
        _articulation_views=_Registered("articulation", "view"),
        _articulation_views_initial_values=_Registered("articulation", "initial"),
        _articulation_views_reset_values=_Registered("articulation", "reset"))
    trigger = CompatModule(f"{root}.trigger", on_rl_frame=dr.on_rl_frame)
    gate = CompatModule(f"{root}.gate", on_interval=dr.on_interval, on_env_reset=dr.on_env_reset)
    context = CompatModule(f"{root}.context", get_reset_inds=get_reset_inds, trigger_randomization=step_randomization)
    utils = CompatModule(f"{root}.utils", set_distribution_params=set_distribution_params,
                         get_distribution_params=get_distribution_params,
                         get_image_space_points=get_image_space_points,
                         calculate_truncation_ratio_simple=calculate_truncation_ratio_simple, NumpyEncoder=NumpyEncoder)
    attributes_module = CompatModule(f"{root}.attributes", **constants)
    parts = {"physics_view": physics_view, "trigger": trigger, "gate": gate, "context": context, "utils": utils}
    scripts = CompatModule(f"{root}.scripts", attributes=attributes_module, **parts)
    package = CompatModule(root, scripts=scripts, **parts, **constants)
    return [package, scripts, attributes_module, *parts.values()]


def modules() -> list[types.ModuleType]:
    """Both domain-randomization packages, and the writer nodes' OmniGraph type names."""
    for og_name, (type_name, attribute) in _WRITER_TYPES.items():
        attributes.register_type_name(f"{DEPRECATED}.{og_name}", type_name, _WRITER_PORTS,
                                      {"attribute": attribute, "values": 0.0, "indices": []})
    return _package(EXPERIMENTAL) + _package(DEPRECATED)
