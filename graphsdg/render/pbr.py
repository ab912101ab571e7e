"""The PBR backend: mujoco-warp-pbr draws render products on an NVIDIA GPU.

:class:`PbrRenderer` is a :class:`~graphsdg.render.backend.RenderBackend`: it
renders graphsdg's compiled model (the classic path's model and state) with
mujoco-warp-pbr and returns :class:`~graphsdg.render.backend.RenderOutputs` in
the classic layout, so annotators and writers do not know which backend drew.

* **Same state.** Each render writes the simulation's geom, light and camera poses
  (``geom_xpos``/``geom_xmat`` as MuJoCo computed them on the CPU: mocap poses,
  physics, randomizers) straight into the renderer's data and rebuilds the scene
  BVH from them (:mod:`graphsdg.render.pbr_scene_bvh`: each frame traced through the tree of its
  own boxes, whatever frame the context was built at); no kinematics run on the GPU.
  Colours, material bindings, sizes and light
  colours go into the renderer's model when they differ from the last upload
  (per-world arrays: nothing recompiles); meshes rescaled in place are traced through
  their rescale folded into the geom frame (no BVH refit), meshes deformed otherwise get
  their BVHs refit (:mod:`graphsdg.render.pbr_meshes`).
  A new model, resolution, or a geom shown or hidden builds a new render context.
* **Same camera.** The model carries cameras for this backend (``graphsdg:pbr_camera``,
  ``graphsdg:pbr_camera_1``, ...: added by the compiler where this backend draws, one per
  render product drawn in one launch); each render poses them at the USD cameras and
  renders per-pixel rays (:func:`graphsdg.render.pbr_scene.camera_rays`), so aperture
  fit, offsets and clipping are the classic path's exactly; new intrinsics give new
  rays without recompiling.
* **Products in one launch.** :meth:`PbrRenderer.render_batch` draws a step's render
  products as the cameras of one launch while their pixels add up to at most
  ``/graphsdg/render/pbrBatchPixels`` (:func:`graphsdg.render.backend.launch_groups`;
  ``bench/pbr_products.py`` measured where it pays), each at its own resolution.
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
import zlib
from dataclasses import dataclass, field
from typing import Any, Callable

import mujoco
import numpy as np
from pxr import Usd, UsdGeom, UsdShade

from graphsdg.base import settings_store as settings
from graphsdg.base import profiling
from graphsdg.imaging import environment_map
from graphsdg.render import mesh_folds, pbr_kernel, pbr_scene
from graphsdg.render.backend import (PNG_ON_DEVICE_KEY, BackendRequest, PbrUnavailableError, RenderOutputs,
                                     RenderRequest, launch_groups, pbr_missing, requested_backend)
from graphsdg.render.camera import CameraView
from graphsdg.render.lookup import lookup
from graphsdg.maths.rotations import decompose
from graphsdg.render.rasterizer import PASSES, Rasterizer
from graphsdg.render.render_scene import RenderScene
from graphsdg.sim import lights as lightmap
from graphsdg.sim.visual import UNDRAWN_GROUPS, drawn_geom_mask, pbr_camera_name
from graphsdg.stage.xform import world_matrix

ENABLED_GROUPS = tuple(g for g in range(mujoco.mjNGROUP) if g not in UNDRAWN_GROUPS)
LAUNCHES_A_FRAME = 4096     # seeds of one frame's launches (path launches times motion sub-frames) stay apart


def launch_seed(frame: int, products: tuple[str, ...], launch: int) -> int:
    """The seed of a frame's ``launch``-th render launch of render products ``products`` (their paths): a
    function of those alone, so a frame draws the same samples in a one-process run, a shard and a resumed
    run, and different products' launches draw different ones.

    Example:
        >>> rp = ("/Render/rp",)
        >>> launch_seed(7, rp, 0) == launch_seed(7, rp, 0) != launch_seed(8, rp, 0) != launch_seed(7, rp, 1)
        True
    """
    products_code = zlib.crc32("\n".join(products).encode())
    return (products_code + (int(frame) * LAUNCHES_A_FRAME + int(launch))) % (2 ** 31)


@dataclass
class _Context:
    """One render context: a model's geometry, with one camera per render product it draws in one launch, at
    those products' resolutions and one tier."""

    key: tuple
    model: Any          # mujoco_warp Model
    data: Any           # mujoco_warp Data (nworld 1)
    rc: Any             # mujoco_warp_pbr PbrRenderContext
    cameras: list[int]  # the PBR cameras' ids, one per render product (the renderer's camera order)
    env_yaw: float
    layouts: list       # pbr_outputs.ClassicLayout per camera: device-side conversion and host buffers
    rays_keys: list     # per camera: the intrinsics its rays were made from
    meshes: "_MeshState"     # how the device's mesh BVHs relate to the model's current vertices
    uploads: Any        # pbr_uploads.PinnedUploads: the per-frame copies' page-locked buffers
    uploaded: dict = field(default_factory=dict)   # field name -> host copy last uploaded
    tree: Any = None    # pbr_scene_bvh.SceneTree: the scene BVH and the boxes it was last built from
    rgb: dict = field(default_factory=dict)        # camera index -> wp.array (1, H, W) vec3 (colour accumulation)
    conversions: dict = field(default_factory=dict)   # (ids per camera, layouts) -> LaunchGraph of the conversion
    draw: Any = None    # megakernel_launch.MegakernelLaunch: the megakernel's launch, replayed with each seed


@dataclass
class _MeshState:
    """The context's mesh BVHs against the simulation's meshes (:mod:`graphsdg.render.pbr_meshes`)."""

    geom_mesh: np.ndarray      # (ngeom,) each geom's mesh id, -1 for other geom types
    mesh_rows: np.ndarray      # the mesh geoms (geom_mesh >= 0)
    built_maps: np.ndarray     # (nmesh, 3, 3) RenderScene.mesh_maps (identity where none) the BVHs' vertices had
    built_inverse: np.ndarray  # their inverses
    half_extents: np.ndarray   # (nmesh, 3) the scene BVH's mesh bounds for those vertices
    reshapes: np.ndarray       # RenderScene.mesh_reshapes when the BVHs last took new vertices
    stamps: np.ndarray         # RenderScene.mesh_stamps when the traced frames below were computed
    mirror_vert: np.ndarray    # host copies of the device's mesh vertices and normals
    mirror_normal: np.ndarray
    relative: np.ndarray       # (nmesh, 3, 3) built vertices -> current ones
    moved: np.ndarray          # (nmesh,) meshes whose relative map is not the identity
    bounds: np.ndarray | None = None   # the mesh bounds last uploaded


@dataclass
class _LaunchSeeds:
    """The seeds of one render's launches: :func:`launch_seed` of its frame, products and launch count."""

    frame: int
    products: tuple[str, ...]
    launches: int = 0

    def next(self) -> int:
        seed = launch_seed(self.frame, self.products, self.launches)
        self.launches += 1
        return seed


class PbrRenderer:
    """Renders :class:`~graphsdg.render.render_scene.RenderScene` views with mujoco-warp-pbr (see the module
    docstring)."""

    MAX_CONTEXTS = 4    # live render contexts (device memory): a step's batch, plus products drawn alone
    MAX_CONVERSIONS = 4     # conversion graphs kept a context (passes asked for, layouts)
    #: the mujoco-warp Data and Model arrays a frame uploads (PbrRenderer._upload_state), sent in one copy
    FRAME_DATA = ("geom_xpos", "geom_xmat", "light_xpos", "light_xdir", "cam_xpos", "cam_xmat")
    FRAME_MODEL = ("geom_rgba", "geom_matid", "geom_size", "mat_rgba", "light_diffuse")
    #: the Warp modules every first frame launches whatever the scene (the megakernel is the scene's own):
    #: compiled side by side when the renderer starts (kernel_cache.compile_in_background)
    FIRST_FRAME_MODULES = ("mujoco_warp._src.render_util", "mujoco_warp._src.bvh", "mujoco_warp_pbr._src.envmap",
                           "mujoco_warp_pbr._src.ibl", "mujoco_warp_pbr._src.rays", "graphsdg.render.pbr_scene_bvh",
                           "graphsdg.render.pbr_outputs")

    def __init__(self, device: str | None = None, wait_for_release: Callable[[], bool] | None = None) -> None:
        """``device``: the Warp device drawn on (default ``cuda:0``); ``wait_for_release``: what a frame's read
        waits on while every page-locked host buffer is still lent (:class:`~graphsdg.render.pbr_outputs.HostBuffers`:
        the write queue's progress, so a frame waits for the writes behind it instead of being copied)."""
        lacks = pbr_missing()
        if lacks and device != "cpu":
            raise PbrUnavailableError("the pbr backend needs " + "; and ".join(lacks))
        from graphsdg.render import kernel_cache
        kernel_cache.configure_warp()   # the node's kernel cache, each kernel compiled once (before Warp compiles any)
        import mujoco_warp as mjw
        import mujoco_warp_pbr as mjpbr
        import warp as wp

        from graphsdg.render import (backend, launch_graph, megakernel_launch, pbr_meshes, pbr_outputs, pbr_scene_bvh,
                                     pbr_uploads)
        if wp.get_device(device or "cuda:0").is_cuda:
            kernel_cache.compile_in_background(self.FIRST_FRAME_MODULES, device or "cuda:0")
        backend.pbr_in_use = True
        self._wp, self._mjw, self._mjpbr = wp, mjw, mjpbr
        self._outputs, self._meshes, self._uploads = pbr_outputs, pbr_meshes, pbr_uploads
        self._scene_bvh, self._launch_graph, self._megakernel = pbr_scene_bvh, launch_graph, megakernel_launch
        self._device = device or "cuda:0"
        self._wait_for_release = wait_for_release
        self._contexts: dict[tuple, _Context] = {}
        self._isolated = None                    # classic rasteriser for render_isolated footprints
        self.stats: dict[str, int] = {"color": 0, "contexts": 0, "products": 0, "scene_trees": 0}
        self._queued: list = []                  # pbr_outputs.QueuedReads of deferred renders not yet taken

    # ---- contexts ------------------------------------------------------
    def _key(self, scene: RenderScene, views: list[CameraView], subframes: int) -> tuple:
        request = requested_backend()
        model = scene.sim.model
        drawn = drawn_geom_mask(model)
        per_axis = math.ceil(math.sqrt(subframes)) if request.tier == "realtime" else 1
        sizes = tuple((v.width, v.height) for v in views)
        return (id(model), scene.version, sizes, request.tier, request.path_samples, request.denoise, per_axis,
                drawn.tobytes(), float(settings.get("/graphsdg/render/exposure", 1.0)), pbr_kernel.requested_kind())

    def _context(self, scene: RenderScene, views: list[CameraView], subframes: int) -> _Context:
        sim = scene.sim
        scene.require_pbr_cameras(len(views))
        if mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_CAMERA, pbr_camera_name(len(views) - 1)) < 0:
            sim.recompile(keep_state=True)   # compiled while the classic backend drew: add the PBR cameras
        key = self._key(scene, views, subframes)
        ctx = self._contexts.pop(key, None)
        if ctx is None:
            for stale in [k for k in self._contexts if k[:2] != key[:2]]:   # built for another model
                del self._contexts[stale]
            while len(self._contexts) >= self.MAX_CONTEXTS:   # the least recently used goes
                del self._contexts[next(iter(self._contexts))]
            with profiling.timed("render:pbr_context"):
                ctx = self._build(scene, views, key)
            self.stats["contexts"] += 1
        self._contexts[key] = ctx    # (re)inserted last: the most recently used
        return ctx

    def _build(self, scene: RenderScene, views: list[CameraView], key: tuple) -> _Context:
        wp, mjw, mjpbr = self._wp, self._mjw, self._mjpbr
        sim = scene.sim
        model = sim.model
        cameras = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, pbr_camera_name(i)) for i in range(len(views))]
        request = requested_backend()
        exposure_setting = float(settings.get("/graphsdg/render/exposure", 1.0))
        env, yaw = self._environment(sim.stage)
        path = request.tier == "path"
        cam_active = [i in cameras for i in range(model.ncam)]
        with wp.ScopedDevice(self._device):
            m = mjw.put_model(model)
            d = mjw.put_data(model, sim.data, nworld=1)
            rc = mjpbr.create_render_context(
                model, nworld=1, cam_res=[(v.width, v.height) for v in views], render_rgb=True, render_depth=True,
                render_seg=True, enabled_geom_groups=ENABLED_GROUPS, cam_active=cam_active,
                light_model=mjpbr.LightModel.PHYSICAL, tone_mapper=mjpbr.ToneMapper.CLAMP,
                ev100=pbr_scene.ev100(exposure_setting), samples_per_pixel=key[6],
                envmap=env, envmap_intensity=1.0 if env is not None else None, envmap_rotation=math.degrees(yaw),
                use_skybox=env is None, mesh_bvh_frame="mujoco",
                tier=mjpbr.Tier.PATH if path else mjpbr.Tier.REALTIME, path_samples=request.path_samples,
                denoise=path and request.denoise, camera_rays=[pbr_scene.camera_rays(v) for v in views])
            rc.baked = pbr_kernel.baked_groups(key[-1], rc.baked)
        layouts = [self._layout(v, model.ngeom) for v in views]
        return _Context(key=key, model=m, data=d, rc=rc, cameras=cameras, env_yaw=yaw, layouts=layouts,
                        rays_keys=[_rays_key(v) for v in views], meshes=self._mesh_state(scene, rc),
                        uploads=self._gathered_uploads(m, d))

    def _gathered_uploads(self, m, d):
        """The context's :class:`~graphsdg.render.pbr_uploads.PinnedUploads`, with the arrays a frame sends
        (poses, and the model fields randomizers change) gathered into one allocation: one copy a frame."""
        uploads = self._uploads.PinnedUploads(self._device)
        owners = {name: d for name in self.FRAME_DATA} | {name: m for name in self.FRAME_MODEL}
        moved = uploads.gather({name: getattr(owner, name) for name, owner in owners.items()})
        for name, view in moved.items():
            setattr(owners[name], name, view)
        return uploads

    def _layout(self, view: CameraView, ngeom: int, masks: int = 0):
        return self._outputs.ClassicLayout(view.width, view.height, pbr_scene.ray_cosines(view), view.near,
                                           view.far, self._device, ngeom, self._wait_for_release,
                                           png=bool(settings.get(PNG_ON_DEVICE_KEY, False)), masks=masks)

    def _device_masks(self, ctx: _Context, requests: list[RenderRequest], acc) -> tuple[int, ...]:
        """How many class masks each camera of ``ctx`` colours on the device this frame (its request's
        palettes, where PNGs are made on the device and the ids are drawn), with each layout made room for
        and given its palettes."""
        if acc is not None or not settings.get(PNG_ON_DEVICE_KEY, False):
            return (0,) * len(requests)
        counts = tuple(len(r.palettes) if "segmentation" in r.passes else 0 for r in requests)
        for index, (count, request) in enumerate(zip(counts, requests)):
            layout = ctx.layouts[index]
            if count > layout.masks:
                layout = ctx.layouts[index] = self._layout(request.view, layout.ngeom, count)
            layout.set_palettes(request.palettes[:count])
        return counts

    def _mesh_state(self, scene: RenderScene, rc) -> _MeshState:
        """The context was built from the model's current vertices: every mesh's BVH is up to date."""
        model, nmesh = scene.sim.model, scene.sim.model.nmesh
        geom_mesh = np.where(model.geom_type == mujoco.mjtGeom.mjGEOM_MESH, model.geom_dataid, -1).astype(np.int64)
        half = rc.base.mesh_bounds_size.numpy().astype(np.float64) if nmesh else np.zeros((0, 3))
        built = mesh_folds.current_maps(scene.mesh_maps, nmesh)
        return _MeshState(geom_mesh=geom_mesh, mesh_rows=np.flatnonzero(geom_mesh >= 0), built_maps=built,
                          built_inverse=np.linalg.inv(built), half_extents=half,
                          reshapes=_counts(scene.mesh_reshapes, nmesh),
                          stamps=_counts(scene.mesh_stamps, nmesh),
                          mirror_vert=np.array(model.mesh_vert, dtype=np.float32),
                          mirror_normal=np.array(model.mesh_normal, dtype=np.float32),
                          relative=np.tile(np.eye(3), (nmesh, 1, 1)), moved=np.zeros(nmesh, dtype=bool))

    def _environment(self, stage: Usd.Stage) -> tuple[np.ndarray | None, float]:
        """The stage's dome lights as one environment map in nits, and its yaw (0 when resampled)."""
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

    # ---- renders -------------------------------------------------------
    def render(self, scene: RenderScene, view: CameraView, passes: set[str], subframes: int = 1,
               defer: bool = False, motion=None, frame: int = 0) -> RenderOutputs:
        """Render ``passes`` of ``view``: colour, depth and ids from the same rays (see the module docstring);
        ``frame`` seeds the random samples (:func:`launch_seed`)."""
        scene.require_offscreen(view.width, view.height)   # the classic footprints of render_isolated draw there
        return self._render_launch(scene, [RenderRequest(view, passes, subframes, defer, motion, frame)])[0]

    def render_batch(self, scene: RenderScene, requests: list[RenderRequest]) -> list[RenderOutputs]:
        """Render a step's products: those one launch can draw together (no motion blur, one launch of samples,
        :func:`~graphsdg.render.backend.launch_groups`'s pixel limit) as cameras of one launch, the rest alone.
        A product's pixels do not depend on which products share its launch, except the soft-shadow and path
        samples' seed (:func:`launch_seed` of the frame and the launch's products)."""
        for r in requests:   # the classic footprints of render_isolated draw in the offscreen buffer
            scene.require_offscreen(r.view.width, r.view.height)
        outputs: list[RenderOutputs | None] = [None] * len(requests)
        tier = requested_backend()
        together = [i for i, r in enumerate(requests)
                    if self._one_launch(r, tier) and r.subframes == requests[0].subframes]
        for group in launch_groups([requests[i].view.width * requests[i].view.height for i in together]):
            chosen = [together[j] for j in group]
            for i, out in zip(chosen, self._render_launch(scene, [requests[i] for i in chosen])):
                outputs[i] = out
        for i, r in enumerate(requests):
            if outputs[i] is None:
                outputs[i] = self._render_launch(scene, [r])[0]
        return outputs

    @staticmethod
    def _one_launch(request: RenderRequest, tier: BackendRequest) -> bool:
        """Whether ``request`` is drawn by one launch under ``tier`` (a :class:`BackendRequest`): no motion blur,
        no path samples beyond one launch's."""
        return request.motion is None and (tier.tier == "realtime" or request.subframes <= max(1, tier.path_samples))

    def _render_launch(self, scene: RenderScene, requests: list[RenderRequest]) -> list[RenderOutputs]:
        """Render ``requests`` (several only when each takes one launch: :meth:`_one_launch`) as the cameras of
        one render context."""
        for r in requests:
            unknown = set(r.passes) - set(PASSES)
            if unknown:
                raise ValueError(f"unknown render passes {sorted(unknown)}; known: {PASSES}")
            if r.subframes < 1:
                raise ValueError(f"subframes must be >= 1, got {r.subframes}")
        self._take_queued(keep=1)
        views = [r.view for r in requests]
        wp, first = self._wp, requests[0]
        ctx = self._context(scene, views, first.subframes)
        seeds = _LaunchSeeds(first.frame, tuple(v.path for v in views))
        with wp.ScopedDevice(self._device):
            with profiling.timed("render:pbr_upload"):
                self._upload_state(scene, views, ctx)
            path = requested_backend().tier == "path"
            launches = max(1, math.ceil(first.subframes / max(1, ctx.rc.path_samples))) if path else 1
            acc = self._motion_blur(scene, ctx, first.motion, launches, seeds) if first.motion is not None else None
            if acc is not None:
                self._upload_state(scene, views, ctx)     # labels from the capture's own instant
                launches = 1
            with profiling.timed("render:pbr"):
                for _ in range(launches):
                    self._launch(ctx, seeds)
                    if first.motion is None and launches > 1:   # several path launches: average their colours
                        acc = self._colour(ctx) if acc is None else acc + self._colour(ctx)
                if acc is not None and first.motion is None:
                    acc = acc / launches
                ids = tuple(bool({"segmentation", "depth"} & r.passes) for r in requests)
                pngs = tuple(acc is None and "color" in r.passes for r in requests)
                masks = self._device_masks(ctx, requests, acc)
                self._conversion(ctx, ids, pngs, masks).run()
            with profiling.timed("readback:pbr"):
                queued = self._outputs.queue_reads([
                    (layout, acc is None and bool({"color", "hdr"} & r.passes), "depth" in r.passes, read_ids, png,
                     count) for layout, r, read_ids, png, count in zip(ctx.layouts, requests, ids, pngs, masks)])
                if all(r.defer for r in requests):   # pipelined: the copies finish while the script goes on
                    self._queued.append(queued)
                else:
                    queued.hosts()
        self.stats["products"] += len(requests)
        return [self._outputs_of(scene, r, _host_of(queued, i), layout.table, acc, r.palettes[:count])
                for i, (r, layout, count) in enumerate(zip(requests, ctx.layouts, masks))]

    def _conversion(self, ctx: _Context, ids: tuple[bool, ...], pngs: tuple[bool, ...], masks: tuple[int, ...]):
        """The :class:`~graphsdg.render.launch_graph.LaunchGraph` converting each camera's pixels of ``ctx``
        to the classic layout, with their codes' pixel bounds where ``ids`` asks, their colour's PNG rows
        compressed where ``pngs`` asks and the layout does that, and ``masks`` class masks (one of each per
        camera)."""
        key = (ids, pngs, masks, tuple(id(layout) for layout in ctx.layouts))
        graph = ctx.conversions.get(key)
        if graph is None:
            if len(ctx.conversions) >= self.MAX_CONVERSIONS:   # new intrinsics every frame make new layouts
                ctx.conversions.clear()
            base, layouts = ctx.rc.base, list(ctx.layouts)

            def launches() -> None:
                for index, (layout, boxes, png, count) in enumerate(zip(layouts, ids, pngs, masks)):
                    layout.convert(base, index, boxes=boxes, png=png, masks=count)
            graph = ctx.conversions[key] = self._launch_graph.LaunchGraph(self._device, launches)
        return graph

    def _take_queued(self, keep: int = 0) -> None:
        """Take the deferred renders' pixels still in page-locked buffers but the newest ``keep`` (a pipelined
        step's frame, finished after the next frame's render): at most one frame copies while another renders."""
        queued = [reads for reads in self._queued if not reads.taken]
        while len(queued) > keep:
            queued.pop(0).hosts()
        self._queued = queued

    def _launch(self, ctx: _Context, seeds: _LaunchSeeds) -> None:
        """One launch of every camera of ``ctx``, with the frame's next seed for these products."""
        if ctx.draw is None:
            ctx.draw = self._megakernel.MegakernelLaunch()
        with pbr_kernel.building(ctx.key[-1]):     # builds the megakernel on a context's first launch
            ctx.draw(ctx.model, ctx.data, ctx.rc, seeds.next())
        self.stats["color"] += 1

    def _outputs_of(self, scene: RenderScene, request: RenderRequest, host: Callable[[], Any], table: np.ndarray,
                    acc: np.ndarray | None, palettes: tuple = ()) -> RenderOutputs:
        """One product's :class:`RenderOutputs`, its passes taken from ``host()`` (its
        :class:`~graphsdg.render.pbr_outputs.HostFrame`, waited for on first use when the render was deferred);
        ``table`` its id codes' code -> geom table (``acc``: an averaged colour, if any); ``palettes`` those its
        class masks were coloured with on the device."""
        view, passes = request.view, request.passes
        out = RenderOutputs()
        if acc is not None:
            colour = np.clip(acc, 0.0, 1.0).astype(np.float32)
            rgba = np.full((view.height, view.width, 4), 255, dtype=np.uint8)
            rgba[..., :3] = np.rint(colour * 255.0)
            if "color" in passes:
                out.put("color", rgba)
            if "hdr" in passes:
                out.put("hdr", colour)
        else:
            if "color" in passes:
                out.put("color", lambda: host().rgba)
            if "hdr" in passes:
                out.put("hdr", lambda: np.asarray(host().rgba)[..., :3].astype(np.float32) / 255.0)
        if "depth" in passes:
            out.put("depth", lambda: host().depth)
        if "segmentation" in passes:
            out.put("id_codes", lambda: host().codes)
            out.put("code_boxes", lambda: host().code_boxes)
            out.id_lut = table
            out.derive("geom_ids", lambda done: lookup(table, done.id_codes))
            if palettes:
                out.put("id_colours", lambda: host().id_colours)
                out.palettes = palettes
        out.render_isolated = lambda geoms, crop: self._classic().render_isolated(scene, view, geoms, crop)
        return out

    def _colour(self, ctx: _Context, index: int = 0) -> np.ndarray:
        """The last launch's display colour of camera ``index``, (H, W, 3) float in [0, 1]."""
        rgb = ctx.rgb.get(index)
        if rgb is None:
            h, w = ctx.layouts[index].shape
            rgb = ctx.rgb[index] = self._wp.zeros((1, h, w), dtype=self._wp.vec3, device=self._device)
        self._mjpbr.get_rgb(ctx.rc, index, rgb)
        return rgb.numpy()[0]

    def _motion_blur(self, scene: RenderScene, ctx: _Context, motion, launches: int,
                     seeds: _LaunchSeeds) -> np.ndarray:
        """Mean display colour of renders at the motion-blur sub-frames (:mod:`graphsdg.render.motion_blur`):
        each sub-frame's geometry, lights and camera, and the next seed (its own soft-shadow and path samples)."""
        acc = None
        with profiling.timed("render:pbr_motion"):
            for i in range(motion.count):
                posed, seen = motion.pose(i)
                self._upload_state(scene, [seen], ctx, data=posed)
                for _ in range(launches):
                    self._launch(ctx, seeds)
                    acc = self._colour(ctx) if acc is None else acc + self._colour(ctx)
        return acc / (motion.count * launches)

    def _upload_state(self, scene: RenderScene, views: list[CameraView], ctx: _Context, data=None) -> None:
        """The simulation's poses and randomized model fields into the renderer (no recompile).

        Poses change every frame and always go up; model fields that randomizers may write (colours,
        material bindings, sizes, light colours) go up only when they differ from the last upload. Every copy
        goes through :class:`~graphsdg.render.pbr_uploads.PinnedUploads`."""
        sim = scene.sim
        model, m, d, rc, uploads = sim.model, ctx.model, ctx.data, ctx.rc, ctx.uploads
        data = sim.data if data is None else data
        uploads.begin()
        traced = self._traced_frames(scene, ctx, np.asarray(data.geom_xmat).reshape(-1, 3, 3))
        uploads.put("geom_xpos", d.geom_xpos, data.geom_xpos)
        uploads.put("geom_xmat", d.geom_xmat, traced)
        if model.nlight:
            uploads.put("light_xpos", d.light_xpos, data.light_xpos)
            uploads.put("light_xdir", d.light_xdir, data.light_xdir)
        if model.nflex:     # deformables: their vertices as physics left them (refit_bvh refits the flex BVHs)
            uploads.put("flexvert_xpos", d.flexvert_xpos, data.flexvert_xpos)
        self._pose_cameras(views, ctx)
        changed = self._upload_changed(ctx, [
            (m.geom_rgba, "geom_rgba", model.geom_rgba),
            (m.geom_matid, "geom_matid", model.geom_matid),
            (m.geom_size, "geom_size", model.geom_size),
            (m.mat_rgba, "mat_rgba", model.mat_rgba if model.nmat else None),
            (m.light_diffuse, "light_diffuse", model.light_diffuse if model.nlight else None)])
        uploads.end()
        if changed & {"geom_matid", "light_diffuse"} or "surfaces" not in ctx.uploaded:
            exposure = float(settings.get("/graphsdg/render/exposure", 1.0))
            world = pbr_scene.world_arrays(model, self._surfaces(scene), exposure)
            rc.geom_metallic.assign(world.geom_metallic[None])
            rc.geom_roughness.assign(world.geom_roughness[None])
            rc.geom_reflectance.assign(world.geom_reflectance[None])
            if model.nlight:
                rc.light_intensity.assign(world.light_intensity[None])
            ctx.uploaded["surfaces"] = True
        if ctx.tree is None:
            ctx.tree = self._scene_bvh.SceneTree()
        boxes_from = (data.geom_xpos, traced, model.geom_size, () if ctx.meshes.bounds is None else ctx.meshes.bounds)
        if ctx.tree.update(self._mjw, m, d, rc.base, boxes_from, always=bool(model.nflex)):   # the frame's own
            self.stats["scene_trees"] += 1                                                      # tree (pbr_scene_bvh)

    def _traced_frames(self, scene: RenderScene, ctx: _Context, xmat: np.ndarray) -> np.ndarray:
        """Geom frames for the tracer: rescaled meshes folded in, other vertex changes refit into their BVHs
        (:mod:`graphsdg.render.pbr_meshes`); the scene BVH's mesh bounds follow."""
        model, state, meshes, folds = scene.sim.model, ctx.meshes, self._meshes, mesh_folds
        if not model.nmesh:
            return xmat
        stamps = _counts(scene.mesh_stamps, model.nmesh)
        if not np.array_equal(stamps, state.stamps):
            now = folds.current_maps(scene.mesh_maps, model.nmesh)
            reshapes = _counts(scene.mesh_reshapes, model.nmesh)
            reshaped = meshes.changed(state.reshapes, reshapes)
            if reshaped.size:      # vertices no map describes (deformables): new vertices into the BVHs
                with profiling.timed("render:pbr_mesh_refit"):
                    meshes.refit(model, ctx.model, ctx.rc, reshaped, state.mirror_vert, state.mirror_normal)
                state.built_maps[reshaped] = now[reshaped]
                state.built_inverse = np.linalg.inv(state.built_maps)
                state.half_extents[reshaped] = folds.vertex_extents(model)[reshaped]
                state.reshapes = reshapes
                state.bounds = None
            state.relative = folds.relative_maps(now, state.built_maps, state.built_inverse)
            state.moved = folds.moved_maps(state.relative)
            state.stamps = stamps
            bounds = folds.folded_bounds(state.relative, state.half_extents).astype(np.float32)
            if state.bounds is None or not np.array_equal(bounds, state.bounds):
                # through the page-locked buffers: a pageable copy waits for the stream's earlier work
                ctx.uploads.put("mesh_bounds_size", ctx.rc.base.mesh_bounds_size, bounds)
                state.bounds = bounds
        return folds.traced_frames(xmat, state.geom_mesh, state.relative, state.moved, state.mesh_rows)

    @staticmethod
    def _upload_changed(ctx: _Context, fields: list) -> set[str]:
        """Upload each ``(device array, name, host array)`` whose host array differs from its last upload;
        returns the names uploaded."""
        changed = set()
        for device_array, name, host in fields:
            if host is None:
                continue
            last = ctx.uploaded.get(name)
            if last is not None and np.array_equal(last, host):
                continue
            copy = np.array(host)
            ctx.uploads.put(name, device_array, copy)
            ctx.uploaded[name] = copy
            changed.add(name)
        return changed

    def _pose_cameras(self, views: list[CameraView], ctx: _Context) -> None:
        """Place each PBR camera at its product's USD camera; new intrinsics (focal length, apertures,
        clipping) give new rays, copied to the renderer without recompiling."""
        ncam = ctx.model.ncam
        cam_xpos = np.zeros((ncam, 3), dtype=np.float32)
        cam_xmat = np.tile(np.eye(3, dtype=np.float32), (ncam, 1, 1))
        for camera, view in zip(ctx.cameras, views):
            cam_xpos[camera], cam_xmat[camera] = pbr_scene.camera_pose(view)
        ctx.uploads.put("cam_xpos", ctx.data.cam_xpos, cam_xpos)
        ctx.uploads.put("cam_xmat", ctx.data.cam_xmat, cam_xmat)
        keys = [_rays_key(v) for v in views]
        if keys != ctx.rays_keys:
            self._mjpbr.set_camera_rays(ctx.rc, [pbr_scene.camera_rays(v) for v in views])
            ctx.layouts = [layout if key == old else self._layout(view, layout.ngeom, layout.masks)
                           for layout, key, old, view in zip(ctx.layouts, keys, ctx.rays_keys, views)]
            ctx.rays_keys = keys

    def _surfaces(self, scene: RenderScene) -> dict[int, pbr_scene.SurfaceFields]:
        sim = scene.sim
        compiled = sim.ensure_compiled()
        cache = getattr(self, "_surface_cache", None)
        if cache is None or cache[0] != (id(compiled), scene.version):
            stage = sim.stage
            fields = {}
            for path, mid in compiled.materials.items():
                prim = stage.GetPrimAtPath(path)
                if prim and mid >= 0:
                    fields[mid] = pbr_scene.surface_fields(UsdShade.Material(prim))
            cache = ((id(compiled), scene.version), fields)
            self._surface_cache = cache
        return cache[1]

    def _classic(self):
        if self._isolated is None:
            self._isolated = Rasterizer()
        return self._isolated

    def close(self) -> None:
        self._take_queued()
        self._contexts.clear()
        if self._isolated is not None:
            self._isolated.close()
            self._isolated = None


def _host_of(queued, index: int) -> Callable[[], Any]:
    """The getter of product ``index``'s host arrays among a launch's queued reads."""
    return lambda: queued.hosts()[index]


def _counts(stamps: np.ndarray, n: int) -> np.ndarray:
    """A copy of per-mesh counts, zeros when they were not sized for this model yet."""
    return stamps.copy() if stamps.shape[0] == n else np.zeros(n, dtype=np.int64)


def _rays_key(view: CameraView) -> tuple:
    """What a view's camera rays and depth conversion depend on besides its pose."""
    return (view.projection, view.width, view.height, view.fx, view.fy, view.cx, view.cy, view.near, view.far)
