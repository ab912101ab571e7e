"""The live MuJoCo side of the stage: compile once, then sync edits into it.

:class:`SimScene` owns the :class:`~graphsdg.sim.compiler.CompiledScene` of the
current stage. Each frame, :meth:`SimScene.sync_dirty_prims` consumes the change
tracker's :class:`~graphsdg.stage.changes.ChangeSet`:

* value edits (poses, sizes, colours, visibility, material inputs, lights) are
  written straight into ``MjModel``/``MjData`` fields, then kinematics are
  recomputed: no recompile;
* structural edits (prims added or removed, schemas applied, a mesh rescaled)
  recompile the stage, carrying the simulation state (time, rigid-body poses and
  velocities) over by prim path.
"""
from __future__ import annotations

import time
from typing import Callable

import mujoco
import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom

from graphsdg.sim import lights as lightmap
from graphsdg.sim.compiler import (HIDDEN_GROUP, MUJOCO_DEFAULT_RGBA, CompiledScene, compile_stage,
                                   display_rgba, light_dir_and_pos, place_directional_lights, primitive_size)
from graphsdg.sim.mesh_scaling import rescale_mesh_geom
from graphsdg.stage import materials as matlib
from graphsdg.stage.changes import ChangeSet, ChangeTracker
from graphsdg.stage.xform import (decompose, matrix_to_euler_xyz, matrix_to_quat_wxyz, quat_wxyz_to_matrix,
                                  set_local_pose, world_matrix)


class NeedsRecompile(Exception):
    """An edit that cannot be applied to compiled fields."""


ALL_ASPECTS = frozenset({"pose", "shape", "visibility", "material", "color"})
# Aspects an ancestor's edit passes down to the gprims below it.
INHERITED_ASPECTS = frozenset({"pose", "visibility", "material"})
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
        self.model_version = 0              # bumps on every recompile (renderers rebuild contexts)
        self.labels_version = 0             # bumps when semantic labels may have changed
        self.textures_to_upload: set[int] = set()
        self.meshes_to_upload: set[int] = set()
        self.stats = {"compiles": 0, "compile_s": 0.0, "syncs": 0, "sync_s": 0.0, "edited_prims": 0}
        self._on_recompile: list[Callable[[CompiledScene], None]] = []

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
                self.model_version += 1

    def recompile(self) -> CompiledScene:
        """Compile the stage anew, keeping time and rigid-body state."""
        old = self.compiled
        start = time.perf_counter()
        new = compile_stage(self.stage, self.offscreen)
        if old is not None:
            new.data.time = old.data.time
            for path, body in new.bodies.items():
                prev = old.bodies.get(path)
                if prev is not None and prev.qpos_adr >= 0 and body.qpos_adr >= 0:
                    new.data.qpos[body.qpos_adr:body.qpos_adr + 7] = old.data.qpos[prev.qpos_adr:prev.qpos_adr + 7]
                    new.data.qvel[body.qvel_adr:body.qvel_adr + 6] = old.data.qvel[prev.qvel_adr:prev.qvel_adr + 6]
            mujoco.mj_forward(new.model, new.data)
        self.compiled = new
        self.model_version += 1
        self.labels_version += 1
        self.textures_to_upload.clear()
        self.meshes_to_upload.clear()
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
        geoms, lights, bodies, mats = self._affected(changes.edited)
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

    def _refresh_body(self, path: str, cache: UsdGeom.XformCache) -> None:
        c = self.compiled
        assert c is not None
        prim = self.stage.GetPrimAtPath(path)
        if not prim:
            raise NeedsRecompile
        b = c.bodies[path]
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
                if not np.allclose(t, self._geom_local_pos(g), atol=1e-9):
                    raise NeedsRecompile   # a geom moved inside its rigid body
            rescaled = not np.allclose(scale, g.scale, rtol=1e-9, atol=1e-12)
            if g.type_name in ("Mesh", "Cone") and g.rigid_root is None and "shape" not in aspects:
                if rescaled:
                    if np.any(np.abs(scale) < 1e-9) or m.geom_contype[g.geom_id] or m.geom_conaffinity[g.geom_id]:
                        raise NeedsRecompile   # colliding meshes carry hulls and inertia
                    self.meshes_to_upload.add(rescale_mesh_geom(m, g.geom_id, g.scale, scale))
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

    def _geom_local_pos(self, g) -> np.ndarray:
        c = self.compiled
        assert c is not None
        if g.type_name in ("Mesh", "Cone"):
            return np.zeros(3)   # mesh vertices carry the offset
        return np.asarray(c.model.geom_pos[g.geom_id])

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
        """Simulate ``seconds`` of physics and write rigid-body poses back to the stage."""
        c = self.ensure_compiled()
        if seconds <= 0:
            return
        n = max(1, int(round(seconds / c.model.opt.timestep)))
        for _ in range(n):
            mujoco.mj_step(c.model, c.data)
        self.write_back_rigid_bodies()

    def write_back_rigid_bodies(self) -> None:
        """Author simulated rigid-body poses on the stage (as PhysX does for USD readers)."""
        c = self.compiled
        if c is None or not c.bodies:
            return
        cache = UsdGeom.XformCache(Usd.TimeCode.Default())
        with self.tracker.muted(), Sdf.ChangeBlock():
            for path, b in c.bodies.items():
                if b.qpos_adr < 0:
                    continue
                prim = self.stage.GetPrimAtPath(path)
                if not prim:
                    continue
                pos = c.data.qpos[b.qpos_adr:b.qpos_adr + 3]
                quat = c.data.qpos[b.qpos_adr + 3:b.qpos_adr + 7]
                _set_world_pose_sdf(prim, pos, quat, cache)


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
