"""The PBR backend: mujoco-warp-pbr draws render products on an NVIDIA GPU.

:class:`PbrRenderer` is a :class:`~graphsdg.render.backend.RenderBackend`: it
renders graphsdg's compiled model (the classic path's model and state) with
mujoco-warp-pbr and returns :class:`~graphsdg.render.rasterizer.RenderOutputs` in
the classic layout, so annotators and writers do not know which backend drew.

* **Same state.** Each render writes the simulation's geom, light and camera poses
  (``geom_xpos``/``geom_xmat`` as MuJoCo computed them on the CPU: mocap poses,
  physics, randomizers) straight into the renderer's data and refits the scene
  BVH; no kinematics run on the GPU. Colours, material bindings, sizes and light
  colours go into the renderer's model when they differ from the last upload
  (per-world arrays: nothing recompiles); meshes rescaled in place are traced through
  their rescale folded into the geom frame (no BVH refit), meshes deformed otherwise get
  their BVHs refit (:mod:`graphsdg.render.pbr_meshes`).
  A new model, resolution, or a geom shown or hidden builds a new render context.
* **Same camera.** The model carries one camera (``graphsdg:pbr_camera``, added by
  the compiler where this backend draws); each render poses it at the USD camera
  and renders per-pixel rays (:func:`graphsdg.render.pbr_scene.camera_rays`), so
  aperture fit, offsets and clipping are the classic path's exactly; new
  intrinsics give new rays without recompiling.
* **Labels from the same rays.** Depth (planar z, ``inf`` background) and geom ids
  (-1 background) come from the colour render's primary rays, converted to the
  classic layout on the GPU (:mod:`graphsdg.render.pbr_outputs`).
  ``render_isolated`` (unoccluded footprints for occlusion and loose boxes) is
  drawn by the classic rasteriser, which samples the same pixel centres.
* **Tiers.** ``RaytracedLighting``: the real-time tier; ``rt_subframes`` N gives
  ceil(sqrt(N))^2 stratified samples per pixel (anti-aliasing, as on the
  rasteriser). ``PathTracing``: the path tier with the settings' samples and
  denoiser; subframes beyond one launch's samples are further launches, averaged.
* **Motion blur.** The mean display colour of renders at the shutter's sub-frames
  (:mod:`graphsdg.render.motion_blur`); labels from the capture's instant.

Imports Warp, mujoco_warp and mujoco_warp_pbr on construction (``graphsdg[gpu]``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np
from pxr import Usd, UsdGeom, UsdShade

from graphsdg import settings_store as settings
from graphsdg.benchmark import profiling
from graphsdg.imaging import environment_map
from graphsdg.render import mesh_folds, pbr_scene
from graphsdg.render.backend import PbrUnavailableError, pbr_missing, requested_backend
from graphsdg.render.camera import CameraView
from graphsdg.maths.rotations import decompose
from graphsdg.render.rasterizer import PASSES, Rasterizer, RenderOutputs
from graphsdg.sim import lights as lightmap
from graphsdg.sim.scene import SimScene
from graphsdg.sim.visual import PBR_CAMERA, UNDRAWN_GROUPS, drawn_geom_mask
from graphsdg.stage.xform import world_matrix

ENABLED_GROUPS = tuple(g for g in range(mujoco.mjNGROUP) if g not in UNDRAWN_GROUPS)


@dataclass
class _Context:
    """One render context: a model's geometry at one resolution and tier."""

    key: tuple
    model: Any          # mujoco_warp Model
    data: Any           # mujoco_warp Data (nworld 1)
    rc: Any             # mujoco_warp_pbr PbrRenderContext
    camera: int         # the PBR camera's id
    rgb: Any            # wp.array (1, H, W) vec3 (path-tier accumulation)
    env_yaw: float
    layout: Any         # pbr_outputs.ClassicLayout: device-side conversion and host buffers
    rays_key: tuple     # the camera intrinsics the rays were made from
    meshes: "_MeshState"     # how the device's mesh BVHs relate to the model's current vertices
    uploaded: dict = field(default_factory=dict)   # field name -> host copy last uploaded


@dataclass
class _MeshState:
    """The context's mesh BVHs against the simulation's meshes (:mod:`graphsdg.render.pbr_meshes`)."""

    geom_mesh: np.ndarray      # (ngeom,) each geom's mesh id, -1 for other geom types
    built_maps: np.ndarray     # (nmesh, 3, 3) SimScene.mesh_maps (identity where none) the BVHs' vertices had
    half_extents: np.ndarray   # (nmesh, 3) the scene BVH's mesh bounds for those vertices
    reshapes: np.ndarray       # SimScene.mesh_reshapes when the BVHs last took new vertices
    stamps: np.ndarray         # SimScene.mesh_stamps when the traced frames below were computed
    mirror_vert: np.ndarray    # host copies of the device's mesh vertices and normals
    mirror_normal: np.ndarray
    relative: np.ndarray       # (nmesh, 3, 3) built vertices -> current ones
    moved: np.ndarray          # (nmesh,) meshes whose relative map is not the identity
    bounds: np.ndarray | None = None   # the mesh bounds last uploaded


class PbrRenderer:
    """Renders :class:`SimScene` views with mujoco-warp-pbr (see the module docstring)."""

    def __init__(self, device: str | None = None) -> None:
        lacks = pbr_missing()
        if lacks and device != "cpu":
            raise PbrUnavailableError("the pbr backend needs " + "; and ".join(lacks))
        import mujoco_warp as mjw
        import mujoco_warp_pbr as mjpbr
        import warp as wp

        from graphsdg.render import backend, pbr_meshes, pbr_outputs
        backend.pbr_in_use = True
        self._wp, self._mjw, self._mjpbr = wp, mjw, mjpbr
        self._outputs, self._meshes = pbr_outputs, pbr_meshes
        self._device = device or "cuda:0"
        self._contexts: dict[tuple, _Context] = {}
        self._renders: dict[str, int] = {}       # per camera path: the seed of its next path-traced launch
        self._isolated = None                    # classic rasteriser for render_isolated footprints
        self.stats: dict[str, int] = {"color": 0, "contexts": 0}

    # ---- contexts ------------------------------------------------------
    def _key(self, sim: SimScene, view: CameraView, subframes: int) -> tuple:
        request = requested_backend()
        model = sim.model
        drawn = drawn_geom_mask(model)
        per_axis = math.ceil(math.sqrt(subframes)) if request.tier == "realtime" else 1
        return (id(model), sim.model_version, view.width, view.height, request.tier, request.path_samples,
                request.denoise, per_axis, drawn.tobytes(), float(settings.get("/graphsdg/render/exposure", 1.0)))

    def _context(self, sim: SimScene, view: CameraView, subframes: int) -> _Context:
        if mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_CAMERA, PBR_CAMERA) < 0:
            sim.recompile(keep_state=True)   # compiled while the classic backend drew: add the PBR camera
        key = self._key(sim, view, subframes)
        ctx = self._contexts.get(key)
        if ctx is not None:
            return ctx
        self._contexts.clear()      # one live context (device memory); products at several sizes rebuild
        with profiling.timed("render:pbr_context"):
            ctx = self._build(sim, view, key)
        self._contexts[key] = ctx
        self.stats["contexts"] += 1
        return ctx

    def _build(self, sim: SimScene, view: CameraView, key: tuple) -> _Context:
        wp, mjw, mjpbr = self._wp, self._mjw, self._mjpbr
        model = sim.model
        camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, PBR_CAMERA)
        request = requested_backend()
        exposure_setting = float(settings.get("/graphsdg/render/exposure", 1.0))
        env, yaw = self._environment(sim)
        path = request.tier == "path"
        cam_active = [i == camera for i in range(model.ncam)]
        with wp.ScopedDevice(self._device):
            m = mjw.put_model(model)
            d = mjw.put_data(model, sim.data, nworld=1)
            rc = mjpbr.create_render_context(
                model, nworld=1, cam_res=[(view.width, view.height)], render_rgb=True, render_depth=True,
                render_seg=True, enabled_geom_groups=ENABLED_GROUPS, cam_active=cam_active,
                light_model=mjpbr.LightModel.PHYSICAL, tone_mapper=mjpbr.ToneMapper.CLAMP,
                ev100=pbr_scene.ev100(exposure_setting), samples_per_pixel=key[7],
                envmap=env, envmap_intensity=1.0 if env is not None else None, envmap_rotation=math.degrees(yaw),
                use_skybox=env is None, mesh_bvh_frame="mujoco",
                tier=mjpbr.Tier.PATH if path else mjpbr.Tier.REALTIME, path_samples=request.path_samples,
                denoise=path and request.denoise, camera_rays=pbr_scene.camera_rays(view)[None])
            rgb = wp.zeros((1, view.height, view.width), dtype=wp.vec3)
        layout = self._outputs.ClassicLayout(view.width, view.height, pbr_scene.ray_cosines(view), view.near,
                                             view.far, self._device)
        return _Context(key=key, model=m, data=d, rc=rc, camera=camera, rgb=rgb, env_yaw=yaw, layout=layout,
                        rays_key=_rays_key(view), meshes=self._mesh_state(sim, rc))

    def _mesh_state(self, sim: SimScene, rc) -> _MeshState:
        """The context was built from the model's current vertices: every mesh's BVH is up to date."""
        model, nmesh = sim.model, sim.model.nmesh
        geom_mesh = np.where(model.geom_type == mujoco.mjtGeom.mjGEOM_MESH, model.geom_dataid, -1).astype(np.int64)
        half = rc.base.mesh_bounds_size.numpy().astype(np.float64) if nmesh else np.zeros((0, 3))
        return _MeshState(geom_mesh=geom_mesh, built_maps=mesh_folds.current_maps(sim.mesh_maps, nmesh),
                          half_extents=half, reshapes=_counts(sim.mesh_reshapes, nmesh),
                          stamps=_counts(sim.mesh_stamps, nmesh),
                          mirror_vert=np.array(model.mesh_vert, dtype=np.float32),
                          mirror_normal=np.array(model.mesh_normal, dtype=np.float32),
                          relative=np.tile(np.eye(3), (nmesh, 1, 1)), moved=np.zeros(nmesh, dtype=bool))

    def _environment(self, sim: SimScene) -> tuple[np.ndarray | None, float]:
        """The stage's dome lights as one environment map in nits, and its yaw (0 when resampled)."""
        stage = sim.stage
        domes = [p for p in stage.Traverse() if p.GetTypeName() == "DomeLight"
                 and UsdGeom.Imageable(p).ComputeVisibility(Usd.TimeCode.Default()) != UsdGeom.Tokens.invisible]
        if not domes:
            return None, 0.0
        total, yaw = None, 0.0
        for prim in domes:
            _, rotation, scale = decompose(world_matrix(prim))
            params = lightmap.light_params(prim, scale)
            # light_params scaled to display units; undo it for nits
            nits = params.color * lightmap.REFERENCE_IRRADIANCE / float(settings.get("/graphsdg/render/exposure", 1.0))
            nits = nits / math.pi      # dome "power" was radiance x pi (horizontal irradiance)
            radiance = environment_map.load(params.texture).radiance if params.texture else None
            turn = pbr_scene.dome_yaw(rotation) if len(domes) == 1 else None
            env = pbr_scene.dome_environment(radiance, rotation, nits, resample=turn is None)
            if turn is not None:
                yaw = turn
            total = env if total is None else total + env
        return total, yaw

    # ---- one render ----------------------------------------------------
    def render(self, sim: SimScene, view: CameraView, passes: set[str], subframes: int = 1,
               defer: bool = False, motion=None) -> RenderOutputs:
        """Render ``passes`` of ``view``: colour, depth and ids from the same rays (see the module docstring)."""
        unknown = set(passes) - set(PASSES)
        if unknown:
            raise ValueError(f"unknown render passes {sorted(unknown)}; known: {PASSES}")
        if subframes < 1:
            raise ValueError(f"subframes must be >= 1, got {subframes}")
        wp = self._wp
        ctx = self._context(sim, view, subframes)
        with wp.ScopedDevice(self._device):
            with profiling.timed("render:pbr_upload"):
                self._upload_state(sim, view, ctx)
            path = requested_backend().tier == "path"
            launches = max(1, math.ceil(subframes / max(1, ctx.rc.path_samples))) if path else 1
            acc = self._motion_blur(sim, ctx, motion, launches) if motion is not None else None
            if acc is not None:
                self._upload_state(sim, view, ctx)     # labels from the capture's own instant
                launches = 1
            with profiling.timed("render:pbr"):
                for _ in range(launches):
                    seed = self._renders.get(view.path, 0)
                    self._renders[view.path] = seed + 1
                    self._mjpbr.render(ctx.model, ctx.data, ctx.rc, seed=seed)
                    self.stats["color"] += 1
                    if motion is None and launches > 1:   # several path launches: average their display colours
                        acc = self._colour(ctx) if acc is None else acc + self._colour(ctx)
                if acc is not None and motion is None:
                    acc = acc / launches
                ctx.layout.convert(ctx.rc.base, 0)
            with profiling.timed("readback:pbr"):
                want_ids = "segmentation" in passes or "depth" in passes
                host = ctx.layout.read(colour=acc is None and bool({"color", "hdr"} & passes),
                                       depth="depth" in passes, ids=want_ids)
        out = RenderOutputs()
        if acc is not None:
            colour = np.clip(acc, 0.0, 1.0).astype(np.float32)
            rgba = np.full((view.height, view.width, 4), 255, dtype=np.uint8)
            rgba[..., :3] = np.rint(colour * 255.0)
        else:
            rgba = host.rgba
        if "color" in passes:
            out.put("color", rgba)
        if "hdr" in passes:
            out.put("hdr", colour if acc is not None else rgba[..., :3].astype(np.float32) / 255.0)
        if "depth" in passes:
            out.put("depth", host.depth)
        if "segmentation" in passes:
            codes, lut = id_codes(host.geom_ids, sim.model.ngeom)
            out.put("id_codes", codes)
            out.id_lut = lut
            out.put("geom_ids", host.geom_ids)
        out.render_isolated = lambda geoms, crop: self._classic().render_isolated(sim, view, geoms, crop)
        return out

    def _colour(self, ctx: _Context) -> np.ndarray:
        """The last launch's display colour, (H, W, 3) float in [0, 1]."""
        self._mjpbr.get_rgb(ctx.rc, 0, ctx.rgb)
        return ctx.rgb.numpy()[0]

    def _motion_blur(self, sim: SimScene, ctx: _Context, motion, launches: int) -> np.ndarray:
        """Mean display colour of renders at the motion-blur sub-frames (:mod:`graphsdg.render.motion_blur`):
        each sub-frame's geometry, lights and camera, and the next seed (its own soft-shadow and path samples)."""
        acc = None
        with profiling.timed("render:pbr_motion"):
            for i in range(motion.count):
                posed, seen = motion.pose(i)
                self._upload_state(sim, seen, ctx, data=posed)
                for _ in range(launches):
                    seed = self._renders.get(seen.path, 0)
                    self._renders[seen.path] = seed + 1
                    self._mjpbr.render(ctx.model, ctx.data, ctx.rc, seed=seed)
                    self.stats["color"] += 1
                    acc = self._colour(ctx) if acc is None else acc + self._colour(ctx)
        return acc / (motion.count * launches)

    def _upload_state(self, sim: SimScene, view: CameraView, ctx: _Context, data=None) -> None:
        """The simulation's poses and randomized model fields into the renderer (no recompile).

        Poses change every frame and always go up; model fields that randomizers may write (colours,
        material bindings, sizes, light colours) go up only when they differ from the last upload."""
        model, m, d, rc = sim.model, ctx.model, ctx.data, ctx.rc
        data = sim.data if data is None else data
        d.geom_xpos.assign(np.asarray(data.geom_xpos, dtype=np.float32)[None])
        xmat = self._traced_frames(sim, ctx, np.asarray(data.geom_xmat).reshape(-1, 3, 3))
        d.geom_xmat.assign(np.asarray(xmat, dtype=np.float32)[None])
        if model.nlight:
            d.light_xpos.assign(np.asarray(data.light_xpos, dtype=np.float32)[None])
            d.light_xdir.assign(np.asarray(data.light_xdir, dtype=np.float32)[None])
        if model.nflex:     # deformables: their vertices as physics left them (refit_bvh refits the flex BVHs)
            d.flexvert_xpos.assign(np.asarray(data.flexvert_xpos, dtype=np.float32)[None])
        self._pose_camera(view, ctx)
        changed = self._upload_changed(ctx, [
            (m.geom_rgba, "geom_rgba", model.geom_rgba, np.float32),
            (m.geom_matid, "geom_matid", model.geom_matid, np.int32),
            (m.geom_size, "geom_size", model.geom_size, np.float32),
            (m.mat_rgba, "mat_rgba", model.mat_rgba if model.nmat else None, np.float32),
            (m.light_diffuse, "light_diffuse", model.light_diffuse if model.nlight else None, np.float32)])
        if changed & {"geom_matid", "light_diffuse"} or "surfaces" not in ctx.uploaded:
            exposure = float(settings.get("/graphsdg/render/exposure", 1.0))
            world = pbr_scene.world_arrays(model, self._surfaces(sim), exposure)
            rc.geom_metallic.assign(world.geom_metallic[None])
            rc.geom_roughness.assign(world.geom_roughness[None])
            rc.geom_reflectance.assign(world.geom_reflectance[None])
            if model.nlight:
                rc.light_intensity.assign(world.light_intensity[None])
            ctx.uploaded["surfaces"] = True
        self._mjw.refit_bvh(m, d, rc.base)

    def _traced_frames(self, sim: SimScene, ctx: _Context, xmat: np.ndarray) -> np.ndarray:
        """Geom frames for the tracer: rescaled meshes folded in, other vertex changes refit into their BVHs
        (:mod:`graphsdg.render.pbr_meshes`); the scene BVH's mesh bounds follow."""
        model, state, meshes, folds = sim.model, ctx.meshes, self._meshes, mesh_folds
        if not model.nmesh:
            return xmat
        stamps = _counts(sim.mesh_stamps, model.nmesh)
        if not np.array_equal(stamps, state.stamps):
            now = folds.current_maps(sim.mesh_maps, model.nmesh)
            reshapes = _counts(sim.mesh_reshapes, model.nmesh)
            reshaped = meshes.changed(state.reshapes, reshapes)
            if reshaped.size:      # vertices no map describes (deformables): new vertices into the BVHs
                with profiling.timed("render:pbr_mesh_refit"):
                    meshes.refit(model, ctx.model, ctx.rc, reshaped, state.mirror_vert, state.mirror_normal)
                state.built_maps[reshaped] = now[reshaped]
                state.half_extents[reshaped] = folds.vertex_extents(model)[reshaped]
                state.reshapes = reshapes
                state.bounds = None
            state.relative = folds.relative_maps(now, state.built_maps)
            state.moved = ~np.all(np.abs(state.relative - np.eye(3)) <= 0.0, axis=(1, 2))
            state.stamps = stamps
            bounds = folds.folded_bounds(state.relative, state.half_extents).astype(np.float32)
            if state.bounds is None or not np.array_equal(bounds, state.bounds):
                ctx.rc.base.mesh_bounds_size.assign(bounds)
                state.bounds = bounds
        return folds.traced_frames(xmat, state.geom_mesh, state.relative, state.moved)

    @staticmethod
    def _upload_changed(ctx: _Context, fields: list) -> set[str]:
        """Assign each ``(device array, name, host array, dtype)`` whose host array differs from its last upload;
        returns the names assigned."""
        changed = set()
        for device_array, name, host, dtype in fields:
            if host is None:
                continue
            last = ctx.uploaded.get(name)
            if last is not None and np.array_equal(last, host):
                continue
            copy = np.array(host, dtype=dtype)
            device_array.assign(copy[None])
            ctx.uploaded[name] = copy
            changed.add(name)
        return changed

    def _pose_camera(self, view: CameraView, ctx: _Context) -> None:
        """Place the PBR camera at the USD camera; new intrinsics (focal length, apertures, clipping) give new
        rays, copied to the renderer without recompiling."""
        position, xmat = pbr_scene.camera_pose(view)
        cam_xpos = np.zeros((1, ctx.model.ncam, 3), dtype=np.float32)
        cam_xmat = np.tile(np.eye(3, dtype=np.float32), (1, ctx.model.ncam, 1, 1))
        cam_xpos[0, ctx.camera], cam_xmat[0, ctx.camera] = position, xmat
        ctx.data.cam_xpos.assign(cam_xpos)
        ctx.data.cam_xmat.assign(cam_xmat)
        key = _rays_key(view)
        if key != ctx.rays_key:
            self._mjpbr.set_camera_rays(ctx.rc, pbr_scene.camera_rays(view)[None])
            ctx.layout = self._outputs.ClassicLayout(view.width, view.height, pbr_scene.ray_cosines(view), view.near,
                                                     view.far, self._device)
            ctx.rays_key = key

    def _surfaces(self, sim: SimScene) -> dict[int, pbr_scene.SurfaceFields]:
        compiled = sim.ensure_compiled()
        cache = getattr(self, "_surface_cache", None)
        if cache is None or cache[0] != (id(compiled), sim.model_version):
            stage = sim.stage
            fields = {}
            for path, mid in compiled.materials.items():
                prim = stage.GetPrimAtPath(path)
                if prim and mid >= 0:
                    fields[mid] = pbr_scene.surface_fields(UsdShade.Material(prim))
            cache = ((id(compiled), sim.model_version), fields)
            self._surface_cache = cache
        return cache[1]

    def _classic(self):
        if self._isolated is None:
            self._isolated = Rasterizer()
        return self._isolated

    def close(self) -> None:
        self._contexts.clear()
        if self._isolated is not None:
            self._isolated.close()
            self._isolated = None


def _counts(stamps: np.ndarray, n: int) -> np.ndarray:
    """A copy of per-mesh counts, zeros when they were not sized for this model yet."""
    return stamps.copy() if stamps.shape[0] == n else np.zeros(n, dtype=np.int64)


def _rays_key(view: CameraView) -> tuple:
    """What a view's camera rays and depth conversion depend on besides its pose."""
    return (view.projection, view.width, view.height, view.fx, view.fy, view.cx, view.cy, view.near, view.far)


def id_codes(geom_ids: np.ndarray, ngeom: int) -> tuple[np.ndarray, np.ndarray]:
    """Codes (geom id + 1, 0 background) and their ``code -> geom id`` table, as the classic path reports them:
    uint8-sized tables are 256 long, uint16 ones 65536 (every code indexes the table)."""
    bits = 8 if ngeom + 1 < (1 << 8) else 16 if ngeom + 1 < (1 << 16) else 32
    size = 1 << bits if bits < 32 else ngeom + 2
    lut = np.full(size, -1, dtype=np.int32)
    lut[1:ngeom + 1] = np.arange(ngeom, dtype=np.int32)
    dtype = np.uint8 if bits == 8 else np.uint16 if bits == 16 else np.uint32
    return (geom_ids + 1).astype(dtype), lut
