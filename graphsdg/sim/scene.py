"""The live MuJoCo side of the stage: compile once, then sync edits into it.

:class:`SimScene` owns the :class:`~graphsdg.sim.compiler.CompiledScene` of the
current stage. Each frame, :meth:`SimScene.sync_dirty_prims` consumes the change
tracker's :class:`~graphsdg.stage.changes.ChangeSet`:

* value edits (poses, sizes, colours, visibility, material inputs, lights) are
  written straight into ``MjModel``/``MjData`` fields, then kinematics are
  recomputed: no recompile;
* structural edits (prims added or removed, schemas applied, physics
  properties edited, a mesh rescaled, a shape moved inside its rigid body)
  recompile the stage, carrying the simulation state (time, rigid-body poses and
  velocities) over by prim path.

:meth:`SimScene.advance` steps physics and authors the rigid bodies' new poses
on the stage; :meth:`SimScene.body_pose` and :meth:`SimScene.body_velocity`
read a body's state; :meth:`SimScene.snapshot` / :meth:`SimScene.restore`
implement the timeline's stop (bodies return to where they were at play).
"""
from __future__ import annotations

import itertools
import math
import time
from typing import Callable

import mujoco
import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.sim import deformables, geom_subsets
from graphsdg.sim import lights as lightmap
from graphsdg.sim import joints as jointmap
from graphsdg.sim import physics_steps
from graphsdg.sim.compiler import (HIDDEN_GROUP, MUJOCO_DEFAULT_RGBA, VELOCITY_ATTRIBUTES, BodyBinding,
                                   CompiledScene, authored_velocity, compile_stage,
                                   display_rgba, light_dir_and_pos, place_directional_lights, primitive_size,
                                   rigid_root)
from graphsdg.sim.mesh_scaling import MeshMaps, rescale_mesh_geoms
from graphsdg.stage import materials as matlib
from graphsdg.stage.changes import ChangeSet, ChangeTracker
from graphsdg.stage.xform import (decompose, matrix_to_euler_xyz, matrix_to_quat_wxyz, quat_wxyz_to_matrix,
                                  set_local_pose, world_matrix)


class NeedsRecompile(Exception):
    """An edit that cannot be applied to compiled fields."""


ALL_ASPECTS = frozenset({"pose", "shape", "visibility", "material", "color"})
# Aspects an ancestor's edit passes down to the gprims below it.
INHERITED_ASPECTS = frozenset({"pose", "visibility", "material"})
_model_versions = itertools.count()

_SHAPE_ATTRS = {"size", "radius", "height", "width", "length", "axis", "points", "faceVertexCounts",
                "faceVertexIndices", "extent", "orientation", "primvars:st"}


def edit_aspects(names: set[str]) -> set[str]:
    """What a set of changed property names means for compiled geoms."""
    aspects: set[str] = set()
    for name in names:
        if name.startswith("xformOp") or name == "xformOpOrder":
            aspects.add("pose")
        elif name == "visibility" or name == "purpose":
            aspects.add("visibility")
        elif name.startswith("material:binding"):
            aspects.add("material")
        elif name in ("primvars:displayColor", "primvars:displayOpacity"):
            aspects.add("color")
        elif name in _SHAPE_ATTRS:
            aspects.add("shape")
        elif name.startswith("semantic"):
            continue   # labels are read by annotators, not compiled
        elif name in VELOCITY_ATTRIBUTES:
            continue   # simulation state, set on the body (SimScene._refresh_body_velocity)
        else:
            return set(ALL_ASPECTS)
    return aspects


class SimScene:
    """MuJoCo model and data of one stage, kept in step with it."""

    def __init__(self, stage: Usd.Stage, tracker: ChangeTracker) -> None:
        self.stage = stage
        self.tracker = tracker
        self.compiled: CompiledScene | None = None
        self.offscreen = (64, 64)
        # changes on every recompile (renderers rebuild contexts); drawn from one process-wide counter so
        # that (id(sim), model_version) keys stay unique when a freed scene's id is reused by a new one
        self.model_version = next(_model_versions)
        self.labels_version = 0             # bumps when semantic labels may have changed
        self.textures_to_upload: set[int] = set()
        self.meshes_to_upload: set[int] = set()   # meshes whose vertices moved (deformables), for renderers
        # mesh id -> 3x3 map from the compiled vertices to the current ones, for meshes rescaled in
        # place since the compile; renderers draw the copy they uploaded through it (no re-upload)
        self.mesh_maps = MeshMaps()
        # per mesh: the count of vertex changes since the compile (rescales, deformables), so renderers that
        # keep their own copy (the pbr backend's BVHs) find the meshes to refit with one comparison
        self.mesh_stamps = np.zeros(0, dtype=np.int64)
        self.stats = {"compiles": 0, "compile_s": 0.0, "syncs": 0, "sync_s": 0.0, "edited_prims": 0}
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

    def require_offscreen(self, width: int, height: int) -> None:
        """Make MuJoCo's offscreen buffer at least ``width`` x ``height`` (recompiles if it grows)."""
        w, h = max(self.offscreen[0], width), max(self.offscreen[1], height)
        if (w, h) != self.offscreen:
            self.offscreen = (w, h)
            if self.compiled is not None:
                self.compiled.model.vis.global_.offwidth = w
                self.compiled.model.vis.global_.offheight = h
                self.model_version = next(_model_versions)

    def rescale_mesh(self, geom_id: int, old_scale: np.ndarray, new_scale: np.ndarray) -> None:
        """Rescale visual mesh geom ``geom_id`` in place and record the map for renderers."""
        self.rescale_meshes(np.array([geom_id]), np.array([old_scale]), np.array([new_scale]))

    def rescale_meshes(self, geom_ids: np.ndarray, old_scales: np.ndarray, new_scales: np.ndarray) -> None:
        """:meth:`rescale_mesh` for many visual mesh geoms at once (their scales as (N, 3) arrays)."""
        mesh_ids, linears = rescale_mesh_geoms(self.model, geom_ids, old_scales, new_scales)
        self.mesh_maps.compose(mesh_ids, linears)
        self.stamp_meshes(mesh_ids)

    def stamp_meshes(self, mesh_ids) -> None:
        """Record that meshes ``mesh_ids``' vertices changed (see :attr:`mesh_stamps`)."""
        nmesh = self.model.nmesh
        if self.mesh_stamps.shape[0] != nmesh:
            self.mesh_stamps = np.zeros(nmesh, dtype=np.int64)
        np.add.at(self.mesh_stamps, np.asarray(list(mesh_ids) if isinstance(mesh_ids, set) else mesh_ids,
                                               dtype=np.int64), 1)

    def recompile(self, keep_state: bool = True) -> CompiledScene:
        """Compile the stage anew, keeping time and rigid-body state unless ``keep_state`` is False."""
        old = self.compiled
        start = time.perf_counter()
        new = compile_stage(self.stage, self.offscreen)
        if old is not None and keep_state:
            carry_state(old, new)
            mujoco.mj_forward(new.model, new.data)
        self.compiled = new
        self.model_version = next(_model_versions)
        self.labels_version += 1
        self.textures_to_upload.clear()
        self.mesh_maps.clear()
        self.mesh_stamps = np.zeros(new.model.nmesh, dtype=np.int64)
        self.meshes_to_upload.clear()
        self.follow_deformables()
        self.stats["compiles"] += 1
        self.stats["compile_s"] += time.perf_counter() - start
        for cb in list(self._on_recompile):
            cb(new)
        return new

    def subscribe_recompile(self, callback: Callable[[CompiledScene], None]) -> None:
        self._on_recompile.append(callback)

    # ---- sync ----------------------------------------------------------
    def sync_dirty_prims(self) -> None:
        """Bring MuJoCo up to date with every stage edit since the last sync."""
        changes = self.tracker.drain()
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
            self.recompile()
            return
        self.stats["syncs"] += 1
        self.stats["sync_s"] += time.perf_counter() - start

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
        c = self.compiled
        assert c is not None
        prim = self.stage.GetPrimAtPath(path)
        if not prim:
            raise NeedsRecompile
        b = c.bodies[path]
        if b.articulated:
            return      # links follow their joints; their authored poses are our own write-back
        t, r, _ = decompose(world_matrix(prim, cache))
        q = matrix_to_quat_wxyz(r)
        if b.mocap_id >= 0:
            c.data.mocap_pos[b.mocap_id] = t
            c.data.mocap_quat[b.mocap_id] = q
        elif b.qpos_adr >= 0:
            current = c.data.qpos[b.qpos_adr:b.qpos_adr + 7]
            if np.allclose(current[:3], t, atol=1e-9) and np.allclose(np.abs(np.dot(current[3:], q)), 1.0,
                                                                       atol=1e-12):
                return  # our own write-back of the simulated pose
            c.data.qpos[b.qpos_adr:b.qpos_adr + 3] = t
            c.data.qpos[b.qpos_adr + 3:b.qpos_adr + 7] = q
            c.data.qvel[b.qvel_adr:b.qvel_adr + 6] = 0.0   # a teleport, as in PhysX

    def _refresh_geom(self, path: str, cache: UsdGeom.XformCache, aspects: set[str] = ALL_ASPECTS) -> None:
        c = self.compiled
        assert c is not None
        prim = self.stage.GetPrimAtPath(path)
        if not prim:
            raise NeedsRecompile
        g = c.geoms[path]
        m, d = c.model, c.data
        if g.parts and (aspects - {"pose"} or (g.rigid_root is None and not np.allclose(
                decompose(world_matrix(prim, cache))[2], g.scale, rtol=1e-9, atol=1e-12))):
            raise NeedsRecompile   # a mesh drawn as GeomSubset parts: rebuild them (group, material, vertices)
        if aspects & {"pose", "shape"}:
            m_world = world_matrix(prim, cache)
            if g.rigid_root is None:
                t, r, scale = decompose(m_world)
                d.mocap_pos[g.mocap_id] = t
                d.mocap_quat[g.mocap_id] = matrix_to_quat_wxyz(r)
            else:
                root = self.stage.GetPrimAtPath(g.rigid_root)
                t_root, r_root, _ = decompose(world_matrix(root, cache))
                m_root = np.eye(4)
                m_root[:3, :3] = r_root.T
                m_root[3, :3] = t_root
                t, r, scale = decompose(m_world @ np.linalg.inv(m_root))
                relative = np.eye(4)
                relative[:3, :3] = r.T
                relative[3, :3] = t
                if g.relative is not None and not np.allclose(relative, g.relative, atol=1e-9):
                    raise NeedsRecompile   # a shape moved inside its rigid body: new mass distribution
            rescaled = not np.allclose(scale, g.scale, rtol=1e-9, atol=1e-12)
            if g.type_name in ("Mesh", "Cone") and g.rigid_root is None and "shape" not in aspects:
                if rescaled:
                    if np.any(np.abs(scale) < 1e-9) or path in c.collider_paths:
                        raise NeedsRecompile   # colliding meshes carry hulls and inertia
                    self.rescale_mesh(g.geom_id, g.scale, scale)
                    g.scale = scale
            elif g.type_name in ("Mesh", "Cone") or g.rigid_root is not None:
                if "shape" in aspects or rescaled:
                    raise NeedsRecompile   # vertices (or the body's inertia) change
            elif "shape" in aspects or not np.allclose(scale, g.scale, rtol=1e-9, atol=1e-12):
                self._resize(prim, g, scale)
        if "visibility" in aspects:
            visible = UsdGeom.Imageable(prim).ComputeVisibility(Usd.TimeCode.Default()) != UsdGeom.Tokens.invisible
            m.geom_group[g.geom_id] = 0 if visible else HIDDEN_GROUP
            g.visible = visible
        if aspects & {"material", "color"}:
            material = matlib.bound_material(prim) if "material" in aspects or g.material else None
            mat_path = str(material.GetPath()) if material is not None else None
            if mat_path is not None:
                if mat_path not in c.materials:
                    raise NeedsRecompile
                m.geom_matid[g.geom_id] = c.materials[mat_path]
                m.geom_rgba[g.geom_id] = MUJOCO_DEFAULT_RGBA
            else:
                m.geom_matid[g.geom_id] = -1
                m.geom_rgba[g.geom_id] = display_rgba(prim)
            g.material = mat_path

    def _refresh_drive(self, path: str, names: set[str]) -> None:
        """A drive's target edited on the stage: a write into ``ctrl`` / the actuator's bias."""
        c = self.compiled
        assert c is not None
        j = c.joints[path]
        if not all(n.startswith("drive:") and n.endswith(("targetPosition", "targetVelocity")) for n in names):
            raise NeedsRecompile     # stiffness, damping, limits...: rebuild the actuator
        if j.actuator_id < 0:
            raise NeedsRecompile     # a drive that did not exist at compile time
        prim = self.stage.GetPrimAtPath(path)
        drive = jointmap.read_joint(prim, rigid_root).drive
        if drive is None:
            raise NeedsRecompile
        c.data.ctrl[j.actuator_id] = drive.target_position
        c.model.actuator_biasprm[j.actuator_id, 0] = drive.damping * drive.target_velocity

    def _resize(self, prim: Usd.Prim, g, scale: np.ndarray) -> None:
        c = self.compiled
        assert c is not None
        m = c.model
        kind, size, _ = primitive_size(prim, scale)
        kind = int(kind)
        if kind != int(m.geom_type[g.geom_id]):
            raise NeedsRecompile   # e.g. a sphere scaled non-uniformly becomes an ellipsoid
        m.geom_size[g.geom_id] = size
        half = _aabb_half(kind, size)
        m.geom_rbound[g.geom_id] = float(np.linalg.norm(half))   # keeps view culling right
        m.geom_aabb[g.geom_id] = np.concatenate([np.zeros(3), half])
        g.scale = scale

    def _refresh_light(self, path: str, cache: UsdGeom.XformCache) -> None:
        c = self.compiled
        assert c is not None
        prim = self.stage.GetPrimAtPath(path)
        binding = c.lights[path]
        if not prim or not binding.light_ids:
            raise NeedsRecompile
        visible = UsdGeom.Imageable(prim).ComputeVisibility(Usd.TimeCode.Default()) != UsdGeom.Tokens.invisible
        if not visible:
            raise NeedsRecompile
        _, _, scale = decompose(world_matrix(prim, cache))
        params = lightmap.light_params(prim, scale)
        m = c.model
        if binding.kind == "dome":
            if params.texture is not None:
                raise NeedsRecompile
            # Only one dome is usual; when several exist the recompile path sums them.
            if sum(1 for lb in c.lights.values() if lb.kind == "dome") > 1:
                raise NeedsRecompile
            m.vis.headlight.ambient[:] = np.minimum(0.5 * params.color, 10.0)
            lid = binding.light_ids[0]
            m.light_diffuse[lid] = np.maximum(0.5 * params.color, 0)
            m.light_specular[lid] = np.minimum(0.5 * params.color * 0.3, 0.3)
            self._set_sky(np.clip(params.color, 0, 1))
            return
        pos, direction = light_dir_and_pos(prim, cache)
        lid = binding.light_ids[0]
        m.light_pos[lid] = pos
        m.light_dir[lid] = direction
        if binding.kind == "distant":
            place_directional_lights(m)
        m.light_diffuse[lid] = np.maximum(params.color, 0)
        m.light_specular[lid] = np.minimum(params.color * 0.3, 0.3)
        m.light_castshadow[lid] = params.cast_shadow

    def _set_sky(self, rgb: np.ndarray) -> None:
        c = self.compiled
        assert c is not None
        tid = c.sky_texture_id
        if tid < 0:
            raise NeedsRecompile
        m = c.model
        adr = m.tex_adr[tid]
        n = m.tex_width[tid] * m.tex_height[tid] * m.tex_nchannel[tid]
        pixel = np.round(rgb * 255).astype(np.uint8)
        m.tex_data[adr:adr + n] = np.tile(pixel, n // 3)
        self.textures_to_upload.add(int(tid))

    def _refresh_material(self, path: str) -> None:
        c = self.compiled
        assert c is not None
        prim = self.stage.GetPrimAtPath(path)
        if not prim:
            raise NeedsRecompile
        desc = matlib.describe(matlib.UsdShade.Material(prim))
        mid = c.materials[path]
        m = c.model
        has_tex = m.mat_texid[mid].max() >= 0
        if bool(desc.texture) != bool(has_tex) or desc.texture:
            raise NeedsRecompile   # texture swaps recompile (size is fixed at compile time)
        m.mat_rgba[mid] = desc.rgba
        m.mat_specular[mid] = 0.5 * (1.0 - desc.roughness)
        m.mat_shininess[mid] = max(0.0, 1.0 - desc.roughness)
        m.mat_emission[mid] = desc.emission

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
        c = self.compiled
        if c is None or not c.deformables:
            return
        with self.tracker.muted():
            deformables.follow(c.deformables, c.model, c.data, self.stage, self.meshes_to_upload)
        if self.meshes_to_upload:
            self.stamp_meshes(self.meshes_to_upload)

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
            _set_world_pose_sdf(self.stage.GetPrimAtPath(path), pos, quat, UsdGeom.XformCache(Usd.TimeCode.Default()))

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


_QPOS_SIZE = {int(mujoco.mjtJoint.mjJNT_FREE): 7, int(mujoco.mjtJoint.mjJNT_BALL): 4,
              int(mujoco.mjtJoint.mjJNT_SLIDE): 1, int(mujoco.mjtJoint.mjJNT_HINGE): 1}
_DOF_SIZE = {int(mujoco.mjtJoint.mjJNT_FREE): 6, int(mujoco.mjtJoint.mjJNT_BALL): 3,
             int(mujoco.mjtJoint.mjJNT_SLIDE): 1, int(mujoco.mjtJoint.mjJNT_HINGE): 1}


def carry_state(old: CompiledScene, new: CompiledScene) -> None:
    """Copy the simulation state of ``old`` into ``new`` by element name.

    Time, every joint's position, velocity and solver warm start (free joints of
    rigid bodies and the joints of kinematic trees) and every actuator's control,
    velocity target and activation carry over, so a model recompiled for a
    render-only edit (a light, a material, a texture) continues the simulation
    bit for bit. Weld constraints are compiled from the stage (whoever switches
    one authors ``physics:jointEnabled`` and the joint frames, see
    :func:`graphsdg.physics.articulations.set_fixed_joint`); elements new to ``new``
    keep what the stage says.
    """
    om, od, nm, nd = old.model, old.data, new.model, new.data
    nd.time = od.time
    for jid in range(nm.njnt):
        name = mujoco.mj_id2name(nm, mujoco.mjtObj.mjOBJ_JOINT, jid)
        oid = mujoco.mj_name2id(om, mujoco.mjtObj.mjOBJ_JOINT, name) if name else -1
        if oid < 0 or om.jnt_type[oid] != nm.jnt_type[jid]:
            continue
        kind = int(nm.jnt_type[jid])
        nq, nv = _QPOS_SIZE[kind], _DOF_SIZE[kind]
        qa, oqa = nm.jnt_qposadr[jid], om.jnt_qposadr[oid]
        va, ova = nm.jnt_dofadr[jid], om.jnt_dofadr[oid]
        nd.qpos[qa:qa + nq] = od.qpos[oqa:oqa + nq]
        nd.qvel[va:va + nv] = od.qvel[ova:ova + nv]
        nd.qacc_warmstart[va:va + nv] = od.qacc_warmstart[ova:ova + nv]
    for aid in range(nm.nu):
        name = mujoco.mj_id2name(nm, mujoco.mjtObj.mjOBJ_ACTUATOR, aid)
        oid = mujoco.mj_name2id(om, mujoco.mjtObj.mjOBJ_ACTUATOR, name) if name else -1
        if oid < 0:
            continue
        nd.ctrl[aid] = od.ctrl[oid]
        nm.actuator_biasprm[aid, 0] = om.actuator_biasprm[oid, 0]      # the drive's velocity target
        if nm.actuator_actnum[aid] and nm.actuator_actnum[aid] == om.actuator_actnum[oid]:
            na = nm.actuator_actnum[aid]
            nd.act[nm.actuator_actadr[aid]:nm.actuator_actadr[aid] + na] = \
                od.act[om.actuator_actadr[oid]:om.actuator_actadr[oid] + na]


def _aabb_half(kind: int, size: np.ndarray) -> np.ndarray:
    g = mujoco.mjtGeom
    if kind in (int(g.mjGEOM_BOX), int(g.mjGEOM_ELLIPSOID)):
        return np.asarray(size[:3], dtype=np.float64)
    if kind == int(g.mjGEOM_SPHERE):
        return np.full(3, size[0])
    if kind == int(g.mjGEOM_CYLINDER):
        return np.array([size[0], size[0], size[1]])
    if kind == int(g.mjGEOM_CAPSULE):
        return np.array([size[0], size[0], size[1] + size[0]])
    return np.asarray(size[:3], dtype=np.float64)


_IDENTITY = Gf.Matrix4d(1.0)


class PoseWriter:
    """Authors a rigid body's simulated world pose on its prim, once per step.

    The common case (a translate and an orient or rotateXYZ op, optionally a
    scale, under a parent without a transform) is written straight into the two
    attributes; anything else goes through the general path.
    """

    def __init__(self, prim: Usd.Prim) -> None:
        self.prim = prim
        self._order_attr = prim.GetAttribute("xformOpOrder")
        self._order: tuple[str, ...] | None = None
        self._last: np.ndarray | None = None
        self._last_velocity: np.ndarray | None = None
        self._velocity: Usd.Attribute | None = None
        self._angular: Usd.Attribute | None = None
        self._read_ops()

    def _read_ops(self) -> None:
        order = self._order_attr.Get() if self._order_attr else None
        self._order = tuple(order) if order is not None else ()
        self._translate = self._rotate = None
        self._rotate_kind = ""
        names = list(self._order)
        if names[-1:] == ["xformOp:scale"]:
            names = names[:-1]
        if len(names) == 2 and names[0] == "xformOp:translate" and names[1] in ("xformOp:orient",
                                                                                 "xformOp:rotateXYZ"):
            self._translate = self.prim.GetAttribute(names[0])
            self._rotate = self.prim.GetAttribute(names[1])
            type_name = str(self._rotate.GetTypeName())
            self._rotate_kind = {"quatd": "quatd", "quatf": "quatf", "double3": "eulerd",
                                 "float3": "eulerf"}.get(type_name, "")
            if str(self._translate.GetTypeName()) != "double3":
                self._rotate_kind = ""

    def write_velocity(self, linear: np.ndarray, angular: np.ndarray) -> None:
        """Author world-frame ``physics:velocity`` and ``physics:angularVelocity`` (given in rad/s,
        authored in degrees/s as UsdPhysics specifies)."""
        values = np.concatenate([linear, np.degrees(angular)]).astype(np.float32)
        if self._last_velocity is not None and np.array_equal(values, self._last_velocity):
            return
        self._last_velocity = values
        if self._velocity is None:
            body = UsdPhysics.RigidBodyAPI(self.prim)
            self._velocity, self._angular = body.CreateVelocityAttr(), body.CreateAngularVelocityAttr()
        self._velocity.Set(Gf.Vec3f(*(float(x) for x in values[:3])))
        self._angular.Set(Gf.Vec3f(*(float(x) for x in values[3:])))

    def write(self, qpos7: np.ndarray, cache: UsdGeom.XformCache) -> None:
        """Author ``qpos7`` (position, quaternion w, x, y, z) as the prim's world pose."""
        if self._last is not None and np.array_equal(qpos7, self._last):
            return      # unchanged since the last write (a body at rest)
        self._last = np.array(qpos7, dtype=np.float64)
        order = self._order_attr.Get() if self._order_attr else None
        if (tuple(order) if order is not None else ()) != self._order:
            self._read_ops()
        parent = self.prim.GetParent()
        parent_identity = not parent or not parent.IsA(UsdGeom.Xformable) or \
            cache.GetLocalToWorldTransform(parent) == _IDENTITY
        if not (parent_identity and self._rotate_kind):
            _set_world_pose_sdf(self.prim, qpos7[:3], qpos7[3:], cache)
            return
        x, y, z = (float(v) for v in qpos7[:3])
        self._translate.Set(Gf.Vec3d(x, y, z))
        w, qx, qy, qz = (float(v) for v in qpos7[3:])
        if self._rotate_kind == "quatd":
            self._rotate.Set(Gf.Quatd(w, qx, qy, qz))
        elif self._rotate_kind == "quatf":
            self._rotate.Set(Gf.Quatf(w, qx, qy, qz))
        else:
            euler = _quat_to_euler_xyz(w, qx, qy, qz)
            self._rotate.Set(Gf.Vec3d(*euler) if self._rotate_kind == "eulerd" else Gf.Vec3f(*euler))


def _quat_to_euler_xyz(w: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    """USD rotateXYZ angles (degrees) of a unit quaternion; same convention as ``matrix_to_euler_xyz``."""
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    r20 = 2 * (x * z - y * w)
    sy = -max(-1.0, min(1.0, r20))
    b = math.asin(sy)
    if abs(sy) < 1 - 1e-9:
        a = math.atan2(2 * (y * z + x * w), 1 - 2 * (x * x + y * y))
        c = math.atan2(2 * (x * y + z * w), 1 - 2 * (y * y + z * z))
    else:
        a = math.atan2(-2 * (y * z - x * w), 1 - 2 * (x * x + z * z))
        c = 0.0
    return (math.degrees(a), math.degrees(b), math.degrees(c))


def _set_world_pose_sdf(prim: Usd.Prim, pos: np.ndarray, quat_wxyz: np.ndarray,
                        cache: UsdGeom.XformCache) -> None:
    """Write a world pose as translate + orient ops, keeping the prim's scale."""
    parent = prim.GetParent()
    parent_m = world_matrix(parent, cache) if parent and parent.IsA(UsdGeom.Xformable) else np.eye(4)
    world = np.eye(4)
    world[:3, :3] = quat_wxyz_to_matrix(quat_wxyz).T
    world[3, :3] = pos
    local = world @ np.linalg.inv(parent_m)
    t, r, _ = decompose(local)
    xf = UsdGeom.Xformable(prim)
    ops = {op.GetOpName(): op for op in xf.GetOrderedXformOps()}
    translate = ops.get("xformOp:translate")
    if translate is not None:
        translate.Set(Gf.Vec3d(*t))
    orient = ops.get("xformOp:orient")
    if orient is not None:
        q = matrix_to_quat_wxyz(r)
        orient.Set(Gf.Quatd(*q) if orient.GetPrecision() == UsdGeom.XformOp.PrecisionDouble else Gf.Quatf(*q))
        return
    rot_ops = [n for n in ops if n.startswith("xformOp:rotate")]
    if rot_ops == ["xformOp:rotateXYZ"]:
        ops["xformOp:rotateXYZ"].Set(Gf.Vec3d(*matrix_to_euler_xyz(r)) if ops["xformOp:rotateXYZ"].GetPrecision()
                                     == UsdGeom.XformOp.PrecisionDouble else Gf.Vec3f(*matrix_to_euler_xyz(r)))
    else:
        set_local_pose(prim, position=t, rotation=matrix_to_quat_wxyz(r))
