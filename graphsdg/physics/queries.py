"""Scene queries against the colliders of the simulation (PhysX's scene-query interface).

* :func:`overlap_box` / :func:`overlap_sphere`: which colliders a box or sphere
  touches; each hit goes to a callback that returns ``True`` to continue and
  ``False`` to stop the query (the palletizing seed's ``overlap_box``).
* :func:`raycast_closest` / :func:`raycast_all`: where a ray meets colliders.
* :func:`get_contacts`: the contacts a body has after the last physics step.

A hit names the collider prim (``collision``) and the rigid body it belongs to
(``rigid_body``: the body prim for dynamic and kinematic bodies, the collider
prim itself for static colliders, as PhysX reports them). Only prims with
``UsdPhysics.CollisionAPI`` take part; collider approximations are honoured.
Quaternions follow PhysX here: ``(x, y, z, w)``.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.physics import queries
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(position=(0, 0, 0.5), name="Crate")
    >>> rep.functional.physics.apply_collider(cube)
    >>> hits = []
    >>> queries.overlap_box((0.2, 0.2, 0.2), (0.0, 0.0, 1.1), (0, 0, 0, 1), lambda h: hits.append(h) or True)
    1
    >>> hits[0].rigid_body
    '/Crate'
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import mujoco
import numpy as np

from graphsdg.maths.rotations import quat_wxyz_to_matrix
from graphsdg.engine.runtime import runtime
from graphsdg.sim.compiled_scene import CompiledScene
from graphsdg.sim.rigid_bodies import rigid_root
from graphsdg.stage.prims import PrimLike, resolve_prim

NO_PROTO = 0xFFFFFFFF


@dataclass
class OverlapHit:
    """One collider touched by an overlap query."""

    rigid_body: str
    collision: str
    protoIndex: int = NO_PROTO


@dataclass
class RaycastHit:
    """Where a ray met a collider."""

    rigid_body: str
    collision: str
    position: np.ndarray
    normal: np.ndarray
    distance: float

    def as_dict(self) -> dict[str, Any]:
        """The hit in PhysX's ``raycast_closest`` dict form."""
        return {"hit": True, "position": tuple(self.position.tolist()), "normal": tuple(self.normal.tolist()),
                "distance": self.distance, "faceIndex": 0, "collision": self.collision,
                "rigidBody": self.rigid_body, "material": ""}


@dataclass
class Contact:
    """One contact between the queried body and another collider, from the last physics step.

    ``normal`` points from the other collider towards the queried body;
    ``separation`` is negative when they interpenetrate; ``normal_force`` is in
    newtons.
    """

    rigid_body: str
    collision: str
    other_rigid_body: str
    other_collision: str
    position: np.ndarray
    normal: np.ndarray
    separation: float
    normal_force: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)


def _vec(value: Any, n: int, what: str) -> np.ndarray:
    if all(hasattr(value, a) for a in "xyzw"[:n]):
        value = [getattr(value, a) for a in "xyzw"[:n]]
    try:
        arr = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be {n} finite numbers, got {value!r}")
    return arr


def _rotation_xyzw(rotation: Any) -> np.ndarray:
    q = _vec(rotation, 4, "rotation (quaternion x, y, z, w)")
    norm = np.linalg.norm(q)
    if norm < 1e-12:
        raise ValueError(f"rotation quaternion (x, y, z, w) must be non-zero, got {rotation!r}")
    return quat_wxyz_to_matrix(q[[3, 0, 1, 2]])


def _scene() -> CompiledScene:
    sim = runtime().sim
    sim.sync_dirty_prims()
    return sim.ensure_compiled()


def _collider_ids(c: CompiledScene) -> np.ndarray:
    return np.array(sorted(c.collider_owner), dtype=np.int64)


def _world_aabbs(c: CompiledScene, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World (centre, half extent) of each geom's bounding box."""
    m, d = c.model, c.data
    mats = d.geom_xmat[ids].reshape(-1, 3, 3)
    local_c, local_h = m.geom_aabb[ids, :3], m.geom_aabb[ids, 3:]
    centers = d.geom_xpos[ids] + np.einsum("nij,nj->ni", mats, local_c)
    halves = np.einsum("nij,nj->ni", np.abs(mats), local_h)
    return centers, halves


def _overlap(probe: int, size: np.ndarray, rbound: float, half: np.ndarray, position: np.ndarray,
             rot: np.ndarray, callback: Callable[[OverlapHit], bool] | None, any_hit: bool) -> int:
    c = _scene()
    m, d = c.model, c.data
    saved = (m.geom_size[probe].copy(), float(m.geom_rbound[probe]), m.geom_aabb[probe].copy(),
             d.geom_xpos[probe].copy(), d.geom_xmat[probe].copy())
    m.geom_size[probe] = size
    m.geom_rbound[probe] = rbound
    m.geom_aabb[probe] = np.concatenate([np.zeros(3), half])
    d.geom_xpos[probe] = position
    d.geom_xmat[probe] = rot.ravel()
    try:
        return _report_overlaps(c, probe, half, position, rot, callback, any_hit)
    finally:
        # a query leaves no trace in the simulation: the next physics step sees the model it saw before
        m.geom_size[probe], m.geom_rbound[probe], m.geom_aabb[probe] = saved[0], saved[1], saved[2]
        d.geom_xpos[probe], d.geom_xmat[probe] = saved[3], saved[4]


def _report_overlaps(c: CompiledScene, probe: int, half: np.ndarray, position: np.ndarray, rot: np.ndarray,
                     callback: Callable[[OverlapHit], bool] | None, any_hit: bool) -> int:
    m, d = c.model, c.data
    ids = _collider_ids(c)
    if len(ids) == 0:
        return 0
    centers, halves = _world_aabbs(c, ids)
    probe_half = np.abs(rot) @ half
    near = np.all(np.abs(centers - position) <= halves + probe_half + 1e-9, axis=1)
    reported: set[str] = set()
    count = 0
    for gid in ids[near]:
        collision = c.collider_prim[int(gid)]
        if collision in reported:
            continue     # several proxy shapes of one collider report once
        if mujoco.mj_geomDistance(m, d, probe, int(gid), 1e-6, None) > 1e-9:
            continue
        reported.add(collision)
        count += 1
        hit = OverlapHit(rigid_body=c.collider_owner[int(gid)], collision=collision)
        keep_going = callback(hit) if callback is not None else True
        if any_hit or keep_going is False:
            break
    return count


def overlap_box(half_extent: Sequence[float], position: Sequence[float], rotation: Sequence[float],
                callback: Callable[[OverlapHit], bool] | None = None, any_hit: bool = False) -> int:
    """Report every collider the box touches; return how many were reported.

    ``half_extent`` (3 positive numbers), ``position`` (world centre) and
    ``rotation`` (quaternion ``x, y, z, w``, PhysX's order) place the box.
    ``callback(hit)`` receives an :class:`OverlapHit`; returning ``False`` stops
    the query. ``any_hit=True`` stops after the first hit.
    """
    half = _vec(half_extent, 3, "half_extent")
    if np.any(half <= 0):
        raise ValueError(f"overlap_box half_extent must be 3 positive numbers, got {tuple(half.tolist())}")
    c = _scene()
    return _overlap(c.probe_box, half, float(np.linalg.norm(half)), half, _vec(position, 3, "position"),
                    _rotation_xyzw(rotation), callback, any_hit)


def overlap_sphere(radius: float, position: Sequence[float], callback: Callable[[OverlapHit], bool] | None = None,
                   any_hit: bool = False) -> int:
    """Like :func:`overlap_box` for a sphere of ``radius`` at ``position``."""
    if isinstance(radius, bool) or not isinstance(radius, (int, float)) or not radius > 0:
        raise ValueError(f"overlap_sphere radius must be a positive number, got {radius!r}")
    c = _scene()
    r = float(radius)
    return _overlap(c.probe_sphere, np.array([r, 0, 0]), r, np.full(3, r), _vec(position, 3, "position"),
                    np.eye(3), callback, any_hit)


def _ray_hits(origin: Sequence[float], direction: Sequence[float], distance: float) -> list[RaycastHit]:
    o = _vec(origin, 3, "origin")
    v = _vec(direction, 3, "direction")
    n = np.linalg.norm(v)
    if n < 1e-12:
        raise ValueError(f"ray direction must be non-zero, got {direction!r}")
    if isinstance(distance, bool) or not isinstance(distance, (int, float)) or not distance > 0:
        raise ValueError(f"ray distance must be a positive number, got {distance!r}")
    v = v / n
    c = _scene()
    m, d = c.model, c.data
    ids = _collider_ids(c)
    if len(ids) == 0:
        return []
    centers, halves = _world_aabbs(c, ids)
    with np.errstate(divide="ignore", invalid="ignore"):   # slab test: axis-parallel rays divide by zero
        inv = 1.0 / v
        t0 = (centers - halves - o) * inv
        t1 = (centers + halves - o) * inv
    tmin = np.nanmax(np.minimum(t0, t1), axis=1)
    tmax = np.nanmin(np.maximum(t0, t1), axis=1)
    near = (tmax >= np.maximum(tmin, 0.0)) & (tmin <= distance)
    hits = []
    normal = np.zeros(3)
    for gid in ids[near]:
        gid = int(gid)
        if m.geom_type[gid] == mujoco.mjtGeom.mjGEOM_MESH:
            t = mujoco.mj_rayMesh(m, d, gid, o, v, normal)
        else:
            t = mujoco.mju_rayGeom(d.geom_xpos[gid], d.geom_xmat[gid], m.geom_size[gid], o, v,
                                   int(m.geom_type[gid]), normal)
        if 0 <= t <= distance:
            hits.append(RaycastHit(rigid_body=c.collider_owner[gid], collision=c.collider_prim[gid],
                                   position=o + t * v, normal=normal.copy(), distance=float(t)))
    hits.sort(key=lambda h: h.distance)
    return hits


def raycast_closest(origin: Sequence[float], direction: Sequence[float], distance: float) -> dict[str, Any]:
    """The nearest collider along the ray, as PhysX's dict (``{"hit": False}`` when none)."""
    hits = _ray_hits(origin, direction, distance)
    return hits[0].as_dict() if hits else {"hit": False}


def raycast_all(origin: Sequence[float], direction: Sequence[float], distance: float,
                callback: Callable[[RaycastHit], bool] | None = None) -> int:
    """Report every collider along the ray, nearest first; ``callback`` returning ``False`` stops."""
    count = 0
    seen: set[str] = set()
    for hit in _ray_hits(origin, direction, distance):
        if hit.collision in seen:
            continue
        seen.add(hit.collision)
        count += 1
        if callback is not None and callback(hit) is False:
            break
    return count


def get_contacts(prim: PrimLike) -> list[Contact]:
    """Contacts of the rigid body (or static collider) ``prim`` in the current simulation state."""
    p = resolve_prim(prim)
    root = rigid_root(p)
    owner = str(root.GetPath()) if root is not None else str(p.GetPath())
    c = _scene()
    m, d = c.model, c.data
    mujoco.mj_forward(m, d)
    mine = {gid for gid, o in c.collider_owner.items() if o == owner}
    if not mine:
        raise ValueError(f"prim {p.GetPath()} has no colliders in the simulation; apply "
                         f"rep.functional.physics.apply_collider (or apply_rigid_body(with_collider=True))")
    out = []
    force = np.zeros(6)
    for i in range(d.ncon):
        con = d.contact[i]
        g1, g2 = int(con.geom1), int(con.geom2)
        if g1 not in mine and g2 not in mine:
            continue
        mujoco.mj_contactForce(m, d, i, force)
        normal = np.array(con.frame[:3])          # MuJoCo: from geom1 towards geom2
        own, other = (g1, g2) if g1 in mine else (g2, g1)
        if own == g1:
            normal = -normal
        out.append(Contact(rigid_body=owner, collision=c.collider_prim.get(own, ""),
                           other_rigid_body=c.collider_owner.get(other, ""),
                           other_collision=c.collider_prim.get(other, ""), position=np.array(con.pos),
                           normal=normal, separation=float(con.dist), normal_force=float(force[0])))
    return out
