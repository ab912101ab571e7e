"""The result of one compile: MuJoCo's model and data plus the prim <-> element maps.

:func:`graphsdg.sim.compiler.compile_stage` fills a :class:`CompiledScene`; it
remembers which MuJoCo elements each prim drives (its geoms, bodies, joints,
lights and materials) so live sync can write attribute edits straight into the
model.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np


@dataclass
class GeomBinding:
    """What one gprim drives in the compiled model."""

    path: str
    type_name: str
    geom_id: int
    body_id: int
    mocap_id: int                    # >= 0 when the gprim owns a mocap body
    rigid_root: str | None           # path of the rigid body the geom belongs to
    scale: np.ndarray                # world scale baked into size or vertices
    material: str | None             # bound material path
    visible: bool = True
    relative: np.ndarray | None = None   # pose in its rigid body's frame (row-vector 4x4)
    parts: tuple[int, ...] = ()          # drawn per-subset part geoms (the geom itself is then not drawn)


@dataclass
class BodyBinding:
    """A rigid body (UsdPhysics.RigidBodyAPI) in the compiled model."""

    path: str
    body_id: int
    mocap_id: int                    # kinematic bodies are mocap bodies
    qpos_adr: int = -1               # free joint address (dynamic bodies)
    qvel_adr: int = -1
    kinematic: bool = False
    articulated: bool = False        # moved by a joint to a parent body (a link of a kinematic tree)


@dataclass
class JointBinding:
    """A UsdPhysics joint in the compiled model (see :mod:`graphsdg.sim.joints`)."""

    path: str
    kind: str                        # revolute, prismatic, spherical, fixed
    body0: str
    body1: str
    joint_id: int = -1               # MuJoCo joint (-1: fixed, or a weld)
    qpos_adr: int = -1
    dof_adr: int = -1
    actuator_id: int = -1            # the drive, if any
    eq_id: int = -1                  # weld constraint (fixed joints outside the tree)
    articulation: str = ""           # articulation root (or tree root body) the joint belongs to
    reversed: bool = False           # the tree hangs USD body0 from body1


@dataclass
class LightBinding:
    """A UsdLux light in the compiled model: its MuJoCo lights (none while it is hidden)."""

    path: str
    kind: str
    light_ids: list[int]


@dataclass
class CompiledScene:
    """A compiled MuJoCo model plus the prim <-> element maps."""

    model: mujoco.MjModel
    data: mujoco.MjData
    geoms: dict[str, GeomBinding] = field(default_factory=dict)
    geom_paths: list[str] = field(default_factory=list)      # geom id -> gprim path ("" if none)
    bodies: dict[str, BodyBinding] = field(default_factory=dict)
    joints: dict[str, JointBinding] = field(default_factory=dict)
    lights: dict[str, LightBinding] = field(default_factory=dict)
    materials: dict[str, int] = field(default_factory=dict)
    sky_texture_id: int = -1
    has_scene_lights: bool = False
    compile_seconds: float = 0.0
    collider_owner: dict[int, str] = field(default_factory=dict)   # colliding geom id -> body or prim path
    collider_prim: dict[int, str] = field(default_factory=dict)    # colliding geom id -> collider prim path
    collider_paths: set[str] = field(default_factory=set)          # gprims that collide (own geom or proxies)
    probe_box: int = -1              # geom ids of the query probes
    probe_sphere: int = -1
    deformables: list = field(default_factory=list)   # graphsdg.sim.deformables.FlexBinding per deformable
