"""Physics domain randomization: registered views, their baseline values, and writing samples into them.

Isaac's ``isaacsim.replicator.experimental.domain_randomization`` randomizes the
physics of many cloned environments at once, one row of a physics view per
environment. This module holds what that needs below the node graph:

* :class:`RandomizationTargets`: the views registered by name (rigid bodies,
  articulations, the simulation's gravity), each with its *initial* values (read
  at registration) and *reset* values (the baseline of additive and scaling
  randomizations, moved by randomizations made on an environment reset);
* :func:`write_samples`: one randomization of one attribute for some rows:
  ``direct`` writes the samples, ``additive`` adds them to the reset values,
  ``scaling`` multiplies the reset values by them; on a reset the reset values
  of those rows become initial (+, x or =) samples first, and those are written;
* :class:`EnvironmentFrames`: the per-environment frame counters an RL loop
  advances (``step_randomization``), and which rows an interval gate picks.

Attributes and shapes (N rows, S shapes, D dofs, L links):

* rigid bodies: position (3), orientation (3: extrinsic X, Y, Z Euler angles in
  radians), linear_velocity (3), angular_velocity (3), velocity (6), force (3:
  applied for one physics step), mass (1), inertia (3: the diagonal),
  material_properties (S x 3), contact_offset (S), rest_offset (S);
* articulations: stiffness, damping, joint_friction, joint_positions,
  joint_velocities, lower_dof_limits, upper_dof_limits, max_efforts,
  joint_armatures, joint_max_velocities, joint_efforts (D each), position,
  orientation, linear_velocity, angular_velocity, velocity (root link),
  body_masses (L), body_inertias (L x 3), material_properties, contact_offset,
  rest_offset; fixed tendons are not compiled (there are none to randomize);
* the simulation: gravity (3).

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> from graphsdg.physics.rigid_body_tensor_view import RigidBodyTensorView
    >>> _ = rep.stage.new_stage()
    >>> box = rep.functional.create.cube(position=(0, 0, 1), name="Box")
    >>> rep.functional.physics.apply_collider(box); rep.functional.physics.apply_rigid_body(box)
    >>> targets = RandomizationTargets()
    >>> target = targets.register_rigid_bodies(RigidBodyTensorView("/Box"), "boxes")
    >>> write_samples(target, "mass", "scaling", np.array([[2.0]]), np.array([0])).tolist()
    [[2000.0]]
    >>> target.view.get_masses().tolist()
    [[2000.0]]
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pxr import Usd

from graphsdg.engine.session import session
from graphsdg.errors import unknown_name
from graphsdg.maths.rotations import euler_xyz_to_quat, quat_wxyz_to_euler_xyz
from graphsdg.physics import gravity as gravity_access
from graphsdg.physics.articulation_tensor_view import ArticulationTensorView
from graphsdg.physics.rigid_body_tensor_view import RigidBodyTensorView

SIMULATION_ATTRIBUTES = ("gravity",)
RIGID_BODY_ATTRIBUTES = ("angular_velocity", "linear_velocity", "velocity", "position", "orientation", "force",
                         "mass", "inertia", "material_properties", "contact_offset", "rest_offset")
TENDON_ATTRIBUTES = ("tendon_stiffnesses", "tendon_dampings", "tendon_limit_stiffnesses", "tendon_lower_limits",
                     "tendon_upper_limits", "tendon_rest_lengths", "tendon_offsets")
ARTICULATION_ATTRIBUTES = ("stiffness", "damping", "joint_friction", "position", "orientation", "linear_velocity",
                           "angular_velocity", "velocity", "joint_positions", "joint_velocities",
                           "lower_dof_limits", "upper_dof_limits", "max_efforts", "joint_armatures",
                           "joint_max_velocities", "joint_efforts", "body_masses", "body_inertias",
                           "material_properties", "contact_offset", "rest_offset") + TENDON_ATTRIBUTES
OPERATIONS = ("direct", "additive", "scaling")
KINDS = ("rigid_body", "articulation", "simulation")
ATTRIBUTES = {"rigid_body": RIGID_BODY_ATTRIBUTES, "articulation": ARTICULATION_ATTRIBUTES,
              "simulation": SIMULATION_ATTRIBUTES}
# attributes written for the selected rows only (the rest are written as the view's whole table)
ROW_ATTRIBUTES = frozenset({"position", "orientation", "linear_velocity", "angular_velocity", "velocity",
                            "joint_positions", "joint_velocities", "max_efforts"})


def euler_of_quats(quats_wxyz: np.ndarray) -> np.ndarray:
    """(N, 4) quaternions -> (N, 3) extrinsic X, Y, Z Euler angles in radians."""
    return np.radians(np.asarray(quat_wxyz_to_euler_xyz(np.asarray(quats_wxyz, dtype=np.float64))).reshape(-1, 3))


def quats_of_euler(angles_rad: np.ndarray) -> np.ndarray:
    """(N, 3) extrinsic X, Y, Z Euler angles in radians -> (N, 4) quaternions (w, x, y, z)."""
    return np.asarray(euler_xyz_to_quat(np.degrees(np.asarray(angles_rad, dtype=np.float64)))).reshape(-1, 4)


@dataclass
class Target:
    """One registered view: its kind, the view, and its initial and reset values by attribute."""

    name: str
    kind: str
    view: Any
    initial: dict[str, np.ndarray] = field(default_factory=dict)
    reset: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def rows(self) -> int:
        return 1 if self.kind == "simulation" else len(self.view)


def rigid_body_values(view: RigidBodyTensorView) -> dict[str, np.ndarray]:
    """The current value of every rigid-body attribute of ``view`` (rows x width tables)."""
    n = len(view)
    transforms, velocities = view.get_transforms(), view.get_velocities()
    return {"position": transforms[:, :3], "orientation": euler_of_quats(transforms[:, [6, 3, 4, 5]]),
            "linear_velocity": velocities[:, :3], "angular_velocity": velocities[:, 3:], "velocity": velocities,
            "force": np.zeros((n, 3)), "mass": view.get_masses().reshape(n, 1),
            "inertia": view.get_inertias()[:, [0, 4, 8]],
            "material_properties": view.get_material_properties().reshape(n, -1),
            "contact_offset": view.get_contact_offsets().reshape(n, -1),
            "rest_offset": view.get_rest_offsets().reshape(n, -1)}


def articulation_values(view: ArticulationTensorView) -> dict[str, np.ndarray]:
    """The current value of every articulation attribute of ``view`` (rows x width tables)."""
    n = len(view)
    root, root_velocity = view.get_root_transforms(), view.get_root_velocities()
    limits = view.get_dof_limits()
    return {"stiffness": view.get_dof_stiffnesses(), "damping": view.get_dof_dampings(),
            "joint_friction": view.get_dof_friction_coefficients(), "position": root[:, :3],
            "orientation": euler_of_quats(root[:, [6, 3, 4, 5]]), "linear_velocity": root_velocity[:, :3],
            "angular_velocity": root_velocity[:, 3:], "velocity": root_velocity,
            "joint_positions": view.get_dof_positions(), "joint_velocities": view.get_dof_velocities(),
            "lower_dof_limits": limits[..., 0], "upper_dof_limits": limits[..., 1],
            "max_efforts": view.get_dof_max_forces(), "joint_armatures": view.get_dof_armatures(),
            "joint_max_velocities": view.get_dof_max_velocities(),
            "joint_efforts": np.zeros((n, view.max_dofs)), "body_masses": view.get_masses(),
            "body_inertias": view.get_inertias()[..., [0, 4, 8]].reshape(n, -1),
            "material_properties": view.get_material_properties().reshape(n, -1),
            "contact_offset": view.get_contact_offsets().reshape(n, -1),
            "rest_offset": view.get_rest_offsets().reshape(n, -1)}


class RandomizationTargets:
    """Views registered for randomization, by name (see the module docstring)."""

    def __init__(self) -> None:
        self.targets: dict[str, Target] = {}
        self.simulation: Target | None = None

    def _register(self, target: Target) -> Target:
        target.reset = copy.deepcopy(target.initial)
        if target.kind == "simulation":
            self.simulation = target
        else:
            self.targets[target.name] = target
        return target

    def register_rigid_bodies(self, view: RigidBodyTensorView, name: str) -> Target:
        """Register ``view`` as ``name``, reading its initial values now."""
        return self._register(Target(_name(name), "rigid_body", view, rigid_body_values(view)))

    def register_articulations(self, view: ArticulationTensorView, name: str) -> Target:
        """Register ``view`` as ``name``, reading its initial values now."""
        return self._register(Target(_name(name), "articulation", view, articulation_values(view)))

    def register_simulation(self) -> Target:
        """Register the simulation's gravity (read now)."""
        return self._register(Target("simulation", "simulation", None,
                                     {"gravity": gravity_access.get_gravity().reshape(1, 3)}))

    def get(self, name: str, kind: str) -> Target:
        """The registered view ``name`` of ``kind`` (the simulation for kind ``"simulation"``)."""
        if kind == "simulation":
            if self.simulation is None:
                raise ValueError("no simulation is registered for randomization; call "
                                 "register_simulation_context() first")
            return self.simulation
        target = self.targets.get(name)
        if target is None or target.kind != kind:
            names = [n for n, t in self.targets.items() if t.kind == kind]
            raise unknown_name(f"registered {kind.replace('_', ' ')} view", name, names)
        return target

    def clear(self) -> None:
        """Forget every registered view and the simulation."""
        self.targets.clear()
        self.simulation = None

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """The views showed the old stage: forget them (as Isaac cleans up when the stage closes)."""
        self.clear()


def _name(name: Any) -> str:
    if not isinstance(name, str) or not name:
        raise ValueError(f"a randomized view needs a non-empty name, got {name!r}")
    return name


def check_attribute(kind: str, attribute: str, operation: str) -> None:
    """Raise ValueError naming a bad attribute or operation."""
    if kind not in KINDS:
        raise ValueError(f"unknown view kind {kind!r}; expected one of {KINDS}")
    if attribute not in ATTRIBUTES[kind]:
        raise ValueError(f"{attribute!r} is not a randomizable {kind.replace('_', ' ')} attribute; expected one "
                         f"of {list(ATTRIBUTES[kind])}")
    if operation not in OPERATIONS:
        raise ValueError(f"operation must be one of {OPERATIONS}, got {operation!r}")


def combine(base: np.ndarray, samples: np.ndarray, operation: str) -> np.ndarray:
    """``samples`` applied to ``base`` by ``operation``."""
    if operation == "additive":
        return base + samples
    if operation == "scaling":
        return base * samples
    return np.broadcast_to(samples, base.shape).copy() if base.shape != samples.shape else samples.copy()


def bucketed(values: np.ndarray, lower: np.ndarray, upper: np.ndarray, num_buckets: int) -> np.ndarray:
    """``values`` (rows x (S*3)) snapped down to ``num_buckets`` evenly spaced levels between ``lower`` and
    ``upper`` per material column (static friction, dynamic friction, restitution), as PhysX's material
    buckets limit how many distinct materials a scene has."""
    if num_buckets < 1:
        raise ValueError(f"num_buckets must be >= 1, got {num_buckets!r}")
    out = np.array(values, dtype=np.float64).reshape(values.shape[0], -1, 3)
    lo, hi = np.broadcast_to(np.asarray(lower, dtype=np.float64).reshape(-1)[:3], 3), \
        np.broadcast_to(np.asarray(upper, dtype=np.float64).reshape(-1)[:3], 3)
    for d in range(3):
        levels = lo[d] + (hi[d] - lo[d]) * np.arange(num_buckets) / num_buckets
        pick = np.clip(np.searchsorted(levels, out[..., d], side="right") - 1, 0, num_buckets - 1)
        out[..., d] = levels[pick]
    return out.reshape(values.shape)


def write_samples(target: Target, attribute: str, operation: str, samples: np.ndarray, indices: np.ndarray,
                  on_reset: bool = False, buckets: tuple[np.ndarray, np.ndarray, int] | None = None) -> np.ndarray:
    """Randomize ``attribute`` of rows ``indices`` of ``target`` with ``samples`` (one row per index); returns
    the values written for those rows. ``buckets``: (lower, upper, count) to snap material properties to."""
    check_attribute(target.kind, attribute, operation)
    idx = np.asarray(indices, dtype=np.int64).reshape(-1)
    if idx.size == 0:
        return np.zeros((0,))
    if np.any((idx < 0) | (idx >= target.rows)):
        raise IndexError(f"environment indices {idx.tolist()} out of range for {target.name!r} "
                         f"({target.rows} rows)")
    if attribute in TENDON_ATTRIBUTES:
        raise ValueError(f"cannot randomize {attribute!r} of {target.name!r}: graphsdg compiles no fixed tendons "
                         f"(the articulation has none)")
    initial, reset = target.initial[attribute], target.reset[attribute]
    width = initial.shape[1] if initial.ndim > 1 else 1
    rows = np.asarray(samples, dtype=np.float64).reshape(len(idx), -1)
    if rows.shape[1] != width and rows.shape[1] != 1:
        raise ValueError(f"{attribute} of {target.name!r} takes {width} value(s) per environment, got samples "
                         f"of shape {np.shape(samples)}")
    if on_reset:
        reset[idx] = combine(initial[idx], rows, operation)
        chosen = reset[idx].copy()
    else:
        chosen = combine(reset[idx], rows, operation)
    table = reset.copy()
    table[idx] = chosen
    if buckets is not None and attribute == "material_properties":
        table = bucketed(table, *buckets)
        chosen = table[idx]
    _apply(target, attribute, table, chosen, idx, rows)
    return chosen


def _apply(target: Target, attribute: str, table: np.ndarray, chosen: np.ndarray, idx: np.ndarray,
           samples: np.ndarray) -> None:
    """Write the randomized values into the view: ``chosen`` rows for row attributes, else the whole ``table``."""
    view = target.view
    if target.kind == "simulation":
        gravity_access.set_gravity(chosen[0])
        return
    if target.kind == "rigid_body":
        _apply_rigid(view, attribute, table, chosen, idx, samples)
    else:
        _apply_articulation(view, attribute, table, chosen, idx, samples)


def _apply_rigid(view: RigidBodyTensorView, attribute: str, table, chosen, idx, samples) -> None:
    n = len(view)
    if attribute in ("position", "orientation"):
        transforms = view.get_transforms()[idx]
        if attribute == "position":
            transforms[:, :3] = chosen
        else:
            transforms[:, 3:] = quats_of_euler(chosen)[:, [1, 2, 3, 0]]
        view.set_transforms(transforms, idx)
    elif attribute in ("linear_velocity", "angular_velocity", "velocity"):
        velocities = view.get_velocities()[idx]
        cols = {"linear_velocity": slice(0, 3), "angular_velocity": slice(3, 6), "velocity": slice(0, 6)}
        velocities[:, cols[attribute]] = chosen
        view.set_velocities(velocities, idx)
    elif attribute == "force":
        view.apply_forces(np.broadcast_to(samples, (len(idx), 3)), idx)
    elif attribute == "mass":
        view.set_masses(table.reshape(n, 1), idx)
    elif attribute == "inertia":
        inertias = np.zeros((n, 9))
        inertias[:, [0, 4, 8]] = table
        view.set_inertias(inertias, idx)
    elif attribute == "material_properties":
        view.set_material_properties(table.reshape(n, -1, 3), idx)
    elif attribute == "contact_offset":
        view.set_contact_offsets(table, idx)
    elif attribute == "rest_offset":
        view.set_rest_offsets(table, idx)


_ARTICULATION_TABLES = {"stiffness": "set_dof_stiffnesses", "damping": "set_dof_dampings",
                        "joint_friction": "set_dof_friction_coefficients", "joint_armatures": "set_dof_armatures",
                        "joint_max_velocities": "set_dof_max_velocities", "body_masses": "set_masses",
                        "contact_offset": "set_contact_offsets", "rest_offset": "set_rest_offsets"}


def _apply_articulation(view: ArticulationTensorView, attribute: str, table, chosen, idx, samples) -> None:
    n = len(view)
    if attribute in _ARTICULATION_TABLES:
        getattr(view, _ARTICULATION_TABLES[attribute])(table, idx)
    elif attribute in ("position", "orientation"):
        transforms = view.get_root_transforms()[idx]
        if attribute == "position":
            transforms[:, :3] = chosen
        else:
            transforms[:, 3:] = quats_of_euler(chosen)[:, [1, 2, 3, 0]]
        view.set_root_transforms(transforms, idx)
    elif attribute in ("linear_velocity", "angular_velocity", "velocity"):
        velocities = view.get_root_velocities()[idx]
        cols = {"linear_velocity": slice(0, 3), "angular_velocity": slice(3, 6), "velocity": slice(0, 6)}
        velocities[:, cols[attribute]] = chosen
        view.set_root_velocities(velocities, idx)
    elif attribute == "joint_positions":
        view.set_dof_positions(chosen, idx)
    elif attribute == "joint_velocities":
        view.set_dof_velocities(chosen, idx)
    elif attribute == "max_efforts":
        view.set_dof_max_forces(chosen, idx)
    elif attribute == "joint_efforts":
        view.set_dof_actuation_forces(np.broadcast_to(samples, (len(idx), view.max_dofs)), idx)
    elif attribute in ("lower_dof_limits", "upper_dof_limits"):
        limits = view.get_dof_limits()
        limits[..., 0 if attribute == "lower_dof_limits" else 1] = table
        view.set_dof_limits(limits, idx)
    elif attribute == "body_inertias":
        inertias = np.zeros((n, view.max_links, 9))
        inertias[..., [0, 4, 8]] = table.reshape(n, view.max_links, 3)
        view.set_inertias(inertias, idx)
    elif attribute == "material_properties":
        view.set_material_properties(table.reshape(n, -1, 3), idx)


class EnvironmentFrames:
    """Per-environment frame counters of an RL loop (Isaac's ``on_rl_frame`` trigger).

    Each :meth:`advance` is one randomization step: environments in ``reset_inds``
    restart at frame 0; the counters as they were (after the resets) are returned,
    then every counter moves on by one.
    """

    def __init__(self, num_envs: int) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
        self.num_envs = int(num_envs)
        self.counts = np.zeros(self.num_envs, dtype=np.int64)

    def advance(self, reset_inds: np.ndarray) -> np.ndarray:
        """Reset ``reset_inds``, return the frame of every environment, then count one frame more."""
        resets = np.asarray(reset_inds, dtype=np.int64).reshape(-1)
        if np.any((resets < 0) | (resets >= self.num_envs)):
            raise IndexError(f"reset indices {resets.tolist()} out of range for {self.num_envs} environments")
        self.counts[resets] = 0
        frames = self.counts.copy()
        self.counts += 1
        return frames


def interval_rows(frames: np.ndarray, interval: int) -> np.ndarray:
    """Environments whose frame is a positive multiple of ``interval`` (those an interval gate randomizes)."""
    if isinstance(interval, bool) or not isinstance(interval, (int, np.integer)) or interval < 1:
        raise ValueError(f"interval must be a positive integer, got {interval!r}")
    frames = np.asarray(frames, dtype=np.int64)
    return np.nonzero((frames % int(interval) == 0) & (frames > 0))[0]


#: The process's registered views (held by the session, :mod:`graphsdg.engine.session`).
_targets = session.adopt("randomization_targets", RandomizationTargets())


def randomization_targets() -> RandomizationTargets:
    """The process's registered views (emptied when the stage is replaced, as Isaac cleans up on close)."""
    return _targets
