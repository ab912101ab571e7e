"""The live MuJoCo side of the stage: compile once, then sync edits into it.

:class:`SimScene` owns the :class:`~graphsdg.sim.compiled_scene.CompiledScene` of the
current stage. Each frame, :meth:`SimScene.sync_dirty_prims` consumes the change
tracker's :class:`~graphsdg.stage.changes.ChangeSet`:

* value edits (poses, sizes, colours, visibility, material inputs, lights) are
  written straight into ``MjModel``/``MjData`` fields, then kinematics are
  recomputed: no recompile. Which aspects an edit touches is
  :mod:`~graphsdg.sim.edit_aspects`; each aspect is synced by its module
  (:mod:`~graphsdg.sim.geom_poses`: pose, size and mesh rescales;
  :mod:`~graphsdg.sim.visual`: visibility; :mod:`~graphsdg.sim.materials`:
  material and colour; :mod:`~graphsdg.sim.lights`: lights and sky;
  :mod:`~graphsdg.sim.rigid_bodies`: rigid-body poses; :mod:`~graphsdg.sim.joints`:
  drive targets), which raises :class:`~graphsdg.sim.needs_recompile.NeedsRecompile`
  where it cannot;
* structural edits (prims added or removed, schemas applied, physics
  properties edited, a mesh rescaled, a shape moved inside its rigid body)
  recompile the stage, carrying the simulation state (time, rigid-body poses and
  velocities) over by prim path (:mod:`~graphsdg.sim.state_carry`).

:meth:`SimScene.advance` steps physics and authors the rigid bodies' new poses
on the stage (:mod:`~graphsdg.sim.pose_write_back`); :meth:`SimScene.body_pose` and :meth:`SimScene.body_velocity`
read a body's state; :meth:`SimScene.snapshot` / :meth:`SimScene.restore`
implement the timeline's stop (bodies return to where they were at play).

What renderers keep beside the model (offscreen sizes, uploads, mesh maps, camera poses) is the render
scene's (:mod:`graphsdg.render.render_scene`): the scene asks it what a compile must carry and tells it of
meshes and textures changed in place through its :attr:`SimScene.render_link`
(:mod:`~graphsdg.sim.render_link`); it hears of recompiles through :meth:`SimScene.subscribe_recompile`.
"""
from __future__ import annotations

import itertools
import time
from typing import Callable

import mujoco
import numpy as np
from pxr import Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.sim import deformables, geom_subsets
from graphsdg.sim import joints as jointmap
from graphsdg.sim import physics_steps
from graphsdg.stage.world_transforms import WorldTransforms
from graphsdg.sim.compiled_scene import BodyBinding, CompiledScene
from graphsdg.sim.compiler import compile_stage
from graphsdg.sim.edit_aspects import ALL_ASPECTS, INHERITED_ASPECTS, edit_aspects
from graphsdg.sim.geom_poses import sync_geom_pose
from graphsdg.sim.lights import sync_light
from graphsdg.sim.materials import sync_geom_material, sync_material
from graphsdg.sim.mesh_scaling import rescale_mesh_geoms
from graphsdg.sim.needs_recompile import NeedsRecompile
from graphsdg.sim.pose_write_back import PoseWriter, set_world_pose_sdf
from graphsdg.sim.render_link import RenderLink
from graphsdg.sim.rigid_bodies import VELOCITY_ATTRIBUTES, authored_velocity, rigid_root, sync_body_pose
from graphsdg.sim.state_carry import carry_state
from graphsdg.sim.visual import sync_visibility
from graphsdg.stage.changes import ChangeSet, ChangeTracker
from graphsdg.stage.xform import world_matrix
from graphsdg.maths.rotations import decompose, quat_wxyz_to_matrix

_model_versions = itertools.count()


class SimScene:
    """MuJoCo model and data of one stage, kept in step with it."""

    def __init__(self, stage: Usd.Stage, tracker: ChangeTracker) -> None:
        self.stage = stage
        self.tracker = tracker
        self.compiled: CompiledScene | None = None
        # the scene renderers draw of this simulation (graphsdg.render.render_scene attaches itself), asked what
        # a compile must carry and told of meshes and textures changed in place; this default: nothing draws it
        self.render_link = RenderLink()
        # changes on every recompile; drawn from one process-wide counter so that (id(sim), model_version)
        # keys stay unique when a freed scene's id is reused by a new one
        self.model_version = next(_model_versions)
        self.labels_version = 0             # bumps when semantic labels may have changed
        self.stats = {"compiles": 0, "compile_s": 0.0, "syncs": 0, "sync_s": 0.0, "edited_prims": 0}
        self.world_transforms = WorldTransforms(stage)   # read once until the stage changes
        self._on_recompile: list[Callable[[CompiledScene], None]] = []
        self._pose_writers: dict[str, PoseWriter] = {}
        self._physics_callbacks: dict[str, Callable[[float], None]] = {}

    # ---- compile -------------------------------------------------------
    @property
    def model(self) -> mujoco.MjModel:
        return self.ensure_compiled().model

    @property
    def data(self) -> mujoco.MjData:
        return self.ensure_compiled().data

    def ensure_compiled(self) -> CompiledScene:
        if self.compiled is None:
            self.tracker.drain()
            self.recompile()
        assert self.compiled is not None
        return self.compiled

    def rescale_mesh(self, geom_id: int, old_scale: np.ndarray, new_scale: np.ndarray) -> None:
        """Rescale visual mesh geom ``geom_id`` in place and tell the renderers' scene the map."""
        self.rescale_meshes(np.array([geom_id]), np.array([old_scale]), np.array([new_scale]))

    def rescale_meshes(self, geom_ids: np.ndarray, old_scales: np.ndarray, new_scales: np.ndarray) -> None:
        """:meth:`rescale_mesh` for many visual mesh geoms at once (their scales as (N, 3) arrays)."""
        mesh_ids, linears = rescale_mesh_geoms(self.model, geom_ids, old_scales, new_scales)
        self.render_link.meshes_rescaled(mesh_ids, linears)

    def recompile(self, keep_state: bool = True) -> CompiledScene:
        """Compile the stage anew, keeping time and rigid-body state unless ``keep_state`` is False."""
        old = self.compiled
        start = time.perf_counter()
        needs = self.render_link.draw_needs()
        new = compile_stage(self.stage, needs.offscreen, pbr=needs.pbr, pbr_cameras=needs.pbr_cameras)
        if old is not None and keep_state:
            carry_state(old, new)
            mujoco.mj_forward(new.model, new.data)
        self.compiled = new
        self.model_version = next(_model_versions)
        self.labels_version += 1
        moved = self._move_deformables()
        self.stats["compiles"] += 1
        self.stats["compile_s"] += time.perf_counter() - start
        for cb in list(self._on_recompile):
            cb(new)
        if moved is not None:   # after the hooks: the render scene's records start afresh for the new model there
            self.render_link.meshes_reshaped(moved)
        return new

    def subscribe_recompile(self, callback: Callable[[CompiledScene], None]) -> None:
        """Call ``callback(compiled)`` after every compile (the render scene, physics views' model overrides)."""
        self._on_recompile.append(callback)

    # ---- sync ----------------------------------------------------------
    def sync_dirty_prims(self) -> None:
        """Bring MuJoCo up to date with every stage edit since the last sync."""
        changes = self.tracker.drain()
        if changes:
            self.render_link.stage_synced(changes)
        if self.compiled is None:
            self.recompile()
            return
        if not changes:
            return
        if changes.semantics_changed:
            self.labels_version += 1
        start = time.perf_counter()
        try:
            if self._is_structural(changes):
                raise NeedsRecompile
            self._apply_edits(changes)
        except NeedsRecompile:
            self._move_bodies_before_recompile(changes)
            self.recompile()
            return
        self.stats["syncs"] += 1
        self.stats["sync_s"] += time.perf_counter() - start

    def _move_bodies_before_recompile(self, changes: ChangeSet) -> None:
        """Put the rigid bodies that the edits moved (a body's or an ancestor's transform) where the stage now
        says, so the state a recompile carries over has them there (a script that moves a prop and loads an
        environment in one go)."""
        c = self.compiled
        assert c is not None
        index = self._subtree_index()
        cache = UsdGeom.XformCache(Usd.TimeCode.Default())
        for path, names in changes.edited.items():
            if "pose" not in edit_aspects(names) & INHERITED_ASPECTS:
                continue
            for kind, bound in index.get(str(path), ()):
                prim = self.stage.GetPrimAtPath(bound)
                if kind == "b" and prim and prim.HasAPI(UsdPhysics.RigidBodyAPI):
                    try:
                        self._refresh_body(bound, cache)
                    except NeedsRecompile:
                        pass    # a body the recompile rebuilds from the stage anyway

    @staticmethod
    def _is_structural(changes: ChangeSet) -> bool:
        # Any prim added, removed, re-typed or given a new schema changes the model's shape.
        return bool(changes.structural)

    def _affected(self, edited: dict[Sdf.Path, set[str]]) -> tuple[dict, set[str], set[str], set[str]]:
        """Which bound elements the edits touch: geoms (with the aspects to refresh), lights,
        rigid bodies and materials."""
        c = self.compiled
        assert c is not None
        geoms: dict[str, set[str]] = {}
        lights, bodies, mats = set(), set(), set()
        index = self._subtree_index()
        for path, names in edited.items():
            p = str(path)
            if p in c.joints:
                self._refresh_drive(p, names)
                continue
            aspects = edit_aspects(names)
            inherited = aspects & INHERITED_ASPECTS
            for kind, bound in index.get(p, ()):
                own = bound == p
                if kind == "g" and (own or inherited):
                    geoms.setdefault(bound, set()).update(aspects if own else inherited)
                elif kind == "l" and (own or inherited):
                    lights.add(bound)
                elif kind == "b" and "pose" in inherited:
                    bodies.add(bound)
            q = path
            while q != Sdf.Path.absoluteRootPath and not q.isEmpty:
                if str(q) in c.materials:
                    mats.add(str(q))
                    break
                q = q.GetParentPath()
        return geoms, lights, bodies, mats

    def _subtree_index(self) -> dict[str, list[tuple[str, str]]]:
        """ancestor-or-self path -> bound elements below it (built lazily per compile)."""
        c = self.compiled
        assert c is not None
        cached = getattr(c, "_subtree_index", None)
        if cached is not None:
            return cached
        index: dict[str, list[tuple[str, str]]] = {}
        for kind, paths in (("g", c.geoms), ("l", c.lights), ("b", c.bodies)):
            for path in paths:
                q = Sdf.Path(path)
                while q != Sdf.Path.absoluteRootPath:
                    index.setdefault(str(q), []).append((kind, path))
                    q = q.GetParentPath()
        c._subtree_index = index  # type: ignore[attr-defined]
        return index

    def _apply_edits(self, changes: ChangeSet) -> None:
        c = self.compiled
        assert c is not None
        if deformables.edits_touch(c.deformables, changes.edited):
            raise NeedsRecompile   # a deformable's nodes are placed from its pose at compile time
        if geom_subsets.edits_touch(self.stage, changes.edited):
            raise NeedsRecompile   # face subsets decide a mesh's part geoms
        geoms, lights, bodies, mats = self._affected(changes.edited)
        for path, names in changes.edited.items():
            if names & VELOCITY_ATTRIBUTES and str(path) in c.bodies:
                self._refresh_body_velocity(str(path))
        cache = UsdGeom.XformCache(Usd.TimeCode.Default())
        for path in bodies:
            self._refresh_body(path, cache)
        for path, aspects in geoms.items():
            self._refresh_geom(path, cache, aspects)
        for path in lights:
            self._refresh_light(path, cache)
        for path in mats:
            self._refresh_material(path)
        self.stats["edited_prims"] += len(geoms) + len(lights) + len(bodies) + len(mats)
        mujoco.mj_kinematics(c.model, c.data)
        mujoco.mj_camlight(c.model, c.data)

    def _refresh_body_velocity(self, path: str) -> None:
        """A script authored a dynamic body's ``physics:velocity`` / ``physics:angularVelocity``."""
        b = self.compiled.bodies[path]
        if b.qvel_adr < 0:
            return
        linear, angular = authored_velocity(self.stage.GetPrimAtPath(path))
        self.set_body_velocity(path, linear, angular)

    def _refresh_body(self, path: str, cache: UsdGeom.XformCache) -> None:
        assert self.compiled is not None
        sync_body_pose(self.compiled, self.stage, path, cache)

    def _refresh_geom(self, path: str, cache: UsdGeom.XformCache, aspects: set[str] = ALL_ASPECTS) -> None:
        c = self.compiled
        assert c is not None
        prim = self.stage.GetPrimAtPath(path)
        if not prim:
            raise NeedsRecompile
        g = c.geoms[path]
        if g.parts and (aspects - {"pose"} or (g.rigid_root is None and not np.allclose(
                decompose(world_matrix(prim, cache))[2], g.scale, rtol=1e-9, atol=1e-12))):
            raise NeedsRecompile   # a mesh drawn as GeomSubset parts: rebuild them (group, material, vertices)
        if aspects & {"pose", "shape"}:
            sync_geom_pose(c, self.stage, prim, g, cache, aspects, self.rescale_mesh)
        if "visibility" in aspects:
            sync_visibility(c.model, prim, g)
        if aspects & {"material", "color"}:
            sync_geom_material(c, prim, g, aspects)

    def _refresh_drive(self, path: str, names: set[str]) -> None:
        """A drive's target edited on the stage: a write into ``ctrl`` / the actuator's bias."""
        assert self.compiled is not None
        jointmap.sync_drive(self.compiled, self.stage, path, names, rigid_root)

    def _refresh_light(self, path: str, cache: UsdGeom.XformCache) -> None:
        assert self.compiled is not None
        textures: set[int] = set()
        sync_light(self.compiled, self.stage, path, cache, textures)
        if textures:
            self.render_link.textures_changed(textures)

    def _refresh_material(self, path: str) -> None:
        assert self.compiled is not None
        sync_material(self.compiled, self.stage, path)

    # ---- physics -------------------------------------------------------
    def advance(self, seconds: float) -> None:
        """Simulate ``seconds`` of physics and write rigid-body poses back to the stage.

        Steps at the model's timestep until the simulated clock reaches its target,
        so ticks that are not a multiple of the timestep do not drift.
        """
        c = self.ensure_compiled()
        if seconds <= 0:
            return
        m, d = c.model, c.data
        target = d.time + seconds
        steps = 0
        while d.time < target - 0.5 * m.opt.timestep or steps == 0:
            for callback in list(self._physics_callbacks.values()):
                callback(float(m.opt.timestep))
            if self.compiled is not c:
                raise RuntimeError("a physics callback recompiled the stage in the middle of a physics step; "
                                   "physics callbacks may write simulation state (joint targets, constraints) "
                                   "but not edit the stage's structure")
            physics_steps.notify(True, float(m.opt.timestep))
            if m.nv == 0 and m.na == 0 and m.nplugin == 0:
                # nothing to integrate: a step only moves the clock (mj_Euler's own addition), and its forward
                # pass would be recomputed by the mj_forward below (the SDG scenes without rigid bodies)
                d.time += m.opt.timestep
            else:
                mujoco.mj_step(m, d)
            physics_steps.notify(False, float(m.opt.timestep))
            steps += 1
        # mj_step leaves positions-derived quantities one step behind; renders,
        # queries and contacts need them (and the contacts) for the new state.
        mujoco.mj_forward(m, d)
        self.write_back_rigid_bodies()
        self.follow_deformables()

    def add_physics_callback(self, name: str, callback: Callable[[float], None]) -> None:
        """Call ``callback(step_size)`` before every physics step (Isaac's ``World.add_physics_callback``).

        Controllers read and write simulation state here (joint targets through
        :class:`graphsdg.physics.articulations.ArticulationView`, weld constraints);
        the callback must not change the stage's structure.
        """
        if not callable(callback):
            raise TypeError(f"physics callback {name!r} must be callable, got {callback!r}")
        self._physics_callbacks[str(name)] = callback

    def remove_physics_callback(self, name: str) -> None:
        self._physics_callbacks.pop(str(name), None)

    def has_physics_callback(self, name: str) -> bool:
        return str(name) in self._physics_callbacks

    def follow_deformables(self) -> None:
        """Move deformables' render meshes with their flexes (MuJoCo vertices and USD points)."""
        moved = self._move_deformables()
        if moved is not None:
            self.render_link.meshes_reshaped(moved)

    def _move_deformables(self) -> set[int] | None:
        """:meth:`follow_deformables` without telling the renderers' scene; the ids of the meshes moved, None
        when the model has no deformables."""
        c = self.compiled
        if c is None or not c.deformables:
            return None
        moved: set[int] = set()
        with self.tracker.muted():
            deformables.follow(c.deformables, c.model, c.data, self.stage, moved)
        return moved

    def write_back_rigid_bodies(self) -> None:
        """Author simulated rigid-body poses on the stage (as PhysX does for USD readers)."""
        c = self.compiled
        if c is None or not c.bodies:
            return
        cache = UsdGeom.XformCache(Usd.TimeCode.Default())
        writers = self._pose_writers
        with self.tracker.muted(), Sdf.ChangeBlock():
            for path, b in c.bodies.items():
                if b.qpos_adr >= 0:
                    pose = c.data.qpos[b.qpos_adr:b.qpos_adr + 7]
                elif b.articulated:
                    pose = np.concatenate([c.data.xpos[b.body_id], c.data.xquat[b.body_id]])
                else:
                    continue
                writer = writers.get(path)
                if writer is None or not writer.prim:
                    prim = self.stage.GetPrimAtPath(path)
                    if not prim:
                        continue
                    writer = writers[path] = PoseWriter(prim)
                writer.write(pose, cache)
                if b.qvel_adr >= 0:   # PhysX writes world-frame velocities back too; scripts read them
                    v = c.data.qvel[b.qvel_adr:b.qvel_adr + 6]
                    writer.write_velocity(v[:3], quat_wxyz_to_matrix(pose[3:]) @ v[3:])

    # ---- rigid-body state ----------------------------------------------
    def body(self, path: str) -> BodyBinding:
        """The compiled rigid body of ``path`` (a prim with ``RigidBodyAPI``)."""
        self.sync_dirty_prims()
        c = self.ensure_compiled()
        binding = c.bodies.get(str(path))
        if binding is None:
            raise ValueError(f"prim {path} is not a simulated rigid body; apply "
                             f"rep.functional.physics.apply_rigid_body to it (with geometry under it) first")
        return binding

    def body_pose(self, path: str) -> tuple[np.ndarray, np.ndarray]:
        """World (position, quaternion w, x, y, z) of a rigid body's frame."""
        b = self.body(path)
        d = self.data
        if b.mocap_id >= 0:
            return d.mocap_pos[b.mocap_id].copy(), d.mocap_quat[b.mocap_id].copy()
        if b.qpos_adr < 0:       # a link of a kinematic tree (or a body fixed to the world)
            return d.xpos[b.body_id].copy(), d.xquat[b.body_id].copy()
        q = d.qpos[b.qpos_adr:b.qpos_adr + 7]
        return q[:3].copy(), q[3:].copy()

    def body_velocity(self, path: str) -> tuple[np.ndarray, np.ndarray]:
        """World-frame (linear m/s, angular rad/s) velocity of a rigid body's frame origin."""
        b = self.body(path)
        if b.articulated:
            vel = np.zeros(6)
            mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, b.body_id, vel, 0)
            return vel[3:].copy(), vel[:3].copy()      # MuJoCo: (angular, linear), world-aligned
        if b.qvel_adr < 0:
            return np.zeros(3), np.zeros(3)
        d = self.data
        v = d.qvel[b.qvel_adr:b.qvel_adr + 6]
        rot = quat_wxyz_to_matrix(d.qpos[b.qpos_adr + 3:b.qpos_adr + 7])
        return v[:3].copy(), rot @ v[3:]      # MuJoCo's free-joint angular velocity is body-local

    def set_body_pose(self, path: str, position: np.ndarray | None = None,
                      orientation: np.ndarray | None = None) -> None:
        """Move a rigid body to a world pose (quaternion w, x, y, z), keeping its velocity; authors the stage."""
        b = self.body(path)
        if b.articulated:
            raise ValueError(f"rigid body {path} hangs from a joint; move it through its joints "
                             f"(graphsdg.physics.articulations.ArticulationView.set_joint_positions)")
        c = self.ensure_compiled()
        d = c.data
        pos, quat = self.body_pose(path)
        if position is not None:
            pos = np.asarray(position, dtype=np.float64)
        if orientation is not None:
            quat = np.asarray(orientation, dtype=np.float64)
            quat = quat / np.linalg.norm(quat)
        if b.mocap_id >= 0:
            d.mocap_pos[b.mocap_id], d.mocap_quat[b.mocap_id] = pos, quat
        else:
            d.qpos[b.qpos_adr:b.qpos_adr + 3], d.qpos[b.qpos_adr + 3:b.qpos_adr + 7] = pos, quat
        mujoco.mj_forward(c.model, d)
        with self.tracker.muted(), Sdf.ChangeBlock():
            set_world_pose_sdf(self.stage.GetPrimAtPath(path), pos, quat, UsdGeom.XformCache(Usd.TimeCode.Default()))

    def set_body_velocity(self, path: str, linear: np.ndarray | None = None,
                          angular: np.ndarray | None = None) -> None:
        """Set a dynamic body's world-frame linear (m/s) and angular (rad/s) velocity."""
        b = self.body(path)
        if b.articulated:
            raise ValueError(f"rigid body {path} hangs from a joint; set its joints' velocities instead")
        if b.qvel_adr < 0:
            raise ValueError(f"rigid body {path} is kinematic; it has no simulated velocity to set")
        d = self.data
        if linear is not None:
            d.qvel[b.qvel_adr:b.qvel_adr + 3] = linear
        if angular is not None:
            rot = quat_wxyz_to_matrix(d.qpos[b.qpos_adr + 3:b.qpos_adr + 7])
            d.qvel[b.qvel_adr + 3:b.qvel_adr + 6] = rot.T @ np.asarray(angular, dtype=np.float64)

    def forward(self) -> None:
        """Recompute every derived quantity (contacts included) for the current state."""
        c = self.ensure_compiled()
        mujoco.mj_forward(c.model, c.data)

    # ---- play / stop ---------------------------------------------------
    def snapshot(self) -> dict[str, dict[str, object]]:
        """The authored xform values and velocities of every rigid body, to restore on stop
        (a velocity not authored at play is saved as None: cleared again on stop)."""
        self.sync_dirty_prims()
        saved: dict[str, dict[str, object]] = {}
        for path in self.ensure_compiled().bodies:
            prim = self.stage.GetPrimAtPath(path)
            if not prim:
                continue
            values: dict[str, object] = {name: None for name in VELOCITY_ATTRIBUTES}
            for attr in prim.GetAttributes():
                name = attr.GetName()
                if (name.startswith("xformOp") or name in VELOCITY_ATTRIBUTES) and attr.HasAuthoredValue():
                    values[name] = attr.Get()
            saved[path] = values
        return saved

    def restore(self, saved: dict[str, dict[str, object]]) -> None:
        """Put rigid bodies back where :meth:`snapshot` found them; time back to 0, at rest."""
        with Sdf.ChangeBlock():
            for path, values in saved.items():
                prim = self.stage.GetPrimAtPath(path)
                if not prim:
                    continue
                for name, value in values.items():
                    attr = prim.GetAttribute(name)
                    if attr and value is None:
                        attr.Clear()
                    elif attr:
                        attr.Set(value)
        self.tracker.drain()
        self._pose_writers.clear()   # their last-written values are no longer what the stage holds
        self.recompile(keep_state=False)
