"""MuJoCo's OpenGL rasteriser, driven by USD cameras.

One :class:`Rasterizer` per process owns the GL context (EGL when headless) and
an ``MjrContext`` for the current model. The USD camera's pose and pinhole
projection are written into the scene's ``mjvGLCamera`` directly, so render
products need no MuJoCo camera and any aspect ratio, clipping range or aperture
offset is honoured exactly.

Passes:

* ``color`` (uint8) and ``hdr`` (the same colour as linear float, before 8-bit
  rounding): one lit, shadowed, multisampled ``mjr_render``.
* ``segmentation`` and ``depth``: one render with MuJoCo's id colours, read
  back with its depth buffer. It is drawn into a single-sample framebuffer of
  its own (:class:`~graphsdg.render.id_framebuffer.IdFramebuffer`), so ids and
  depth are both sampled exactly at pixel centres, on every GL driver, and
  agree with each other
  (a multisampled colour pass resolves depth from an off-centre sample, which
  is off by up to a quarter pixel of depth slope). Depth is linearised to
  planar z in stage units (background ``inf``); ids are geom ids (background -1).

``subframes`` > 1 renders the colour that many times with sub-pixel jitter
(a Halton(2, 3) pattern) and averages: anti-aliasing on a rasteriser, which is
what Replicator's ``rt_subframes`` buys. Depth and ids come from the unjittered
sample so labels stay crisp.

:meth:`Rasterizer.render_isolated` draws the ids of a chosen set of geoms
alone (every other geom hidden), cropped to a pixel rectangle of the same
image: the unoccluded footprint of an object, which exact occlusion ratios and
loose boxes are measured from.
"""
from __future__ import annotations

import os
from collections import Counter
from typing import Callable, Sequence

import cv2
import mujoco
import numpy as np

from graphsdg.base import profiling
from graphsdg.render import gl_direct, sky
from graphsdg.render.backend import Crop, RenderOutputs, RenderRequest
from graphsdg.render.camera import CameraView
from graphsdg.render.id_framebuffer import IdFramebuffer
from graphsdg.render.lookup import lookup
from graphsdg.render.motion_blur import MotionSamples
from graphsdg.render.readback import PixelReads, code_bits
from graphsdg.render.scene_geoms import geom_array
from graphsdg.render.render_scene import RenderScene
from graphsdg.sim.mesh_scaling import MeshMaps
from graphsdg.sim.visual import HIDDEN_GROUP, UNDRAWN_GROUPS, drawn_geom_mask, render_quality

PASSES = ("color", "hdr", "depth", "segmentation")
SKY_FAR_FACTOR = 2.0


def make_gl_context():
    """An offscreen GL context on the platform graphsdg chose (EGL when headless).

    Chosen here rather than through ``mujoco.rendering.classic.gl_context`` so a
    script that imported ``mujoco`` before ``graphsdg`` (which fixes MuJoCo's own
    choice at import) still renders headless.
    """
    platform = os.environ.get("MUJOCO_GL", "").strip().lower()
    if platform == "egl":
        from mujoco.egl import GLContext
    elif platform == "osmesa":
        from mujoco.osmesa import GLContext
    else:
        from mujoco.rendering.classic import gl_context
        GLContext = gl_context.GLContext
        if GLContext is None:
            raise RuntimeError("MuJoCo has no OpenGL platform; set MUJOCO_GL=egl (needs libEGL)")
    return GLContext(64, 64)


def _egl_context_address(gl) -> int | None:
    """The address of ``gl``'s EGL context (to compare with the current one), or None when it is not EGL's."""
    context = getattr(gl, "_context", None)
    if context is None or os.environ.get("MUJOCO_GL", "").lower() != "egl":
        return None
    import ctypes
    return ctypes.cast(context, ctypes.c_void_p).value


def halton(index: int, base: int) -> float:
    f, r = 1.0, 0.0
    while index > 0:
        f /= base
        r += f * (index % base)
        index //= base
    return r


def jitter_offsets(n: int) -> list[tuple[float, float]]:
    """``n`` sub-pixel offsets in [-0.5, 0.5)²; the first is the pixel centre."""
    return [(0.0, 0.0)] + [(halton(i, 2) - 0.5, halton(i, 3) - 0.5) for i in range(1, n)]


class Rasterizer:
    """Renders a :class:`~graphsdg.render.render_scene.RenderScene` from :class:`CameraView` s."""

    def __init__(self) -> None:
        self._gl = None
        self._gl_address: int | None = None   # its EGL context's address, when it is EGL's
        self._mjr: mujoco.MjrContext | None = None
        self._scene: mujoco.MjvScene | None = None
        self._option = mujoco.MjvOption()
        for group in UNDRAWN_GROUPS:
            self._option.geomgroup[group] = 0
        self._camera = mujoco.MjvCamera()
        self._camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        self._version = -1
        self._model: mujoco.MjModel | None = None
        # inverse of RenderScene.mesh_maps when the meshes were uploaded (a mesh absent: identity)
        self._uploaded_inverse: dict[int, np.ndarray] = {}
        self._undo = _undo_table({})   # the same by mesh id, as arrays
        self._reads: PixelReads | None = None
        self._flat_sky: tuple[float, float, float] | None = None   # the skybox's colour when uniform
        self._ids: IdFramebuffer | None = None   # where id passes draw (single-sample, float depth)
        self.stats: Counter = Counter()     # renders drawn, by kind (colour, ids, isolated)
        self.skies_filled = 0               # colour renders whose one-colour sky was a flat fill (no skybox draw)

    # ---- contexts ------------------------------------------------------
    def _ensure_gl(self) -> None:
        if self._gl is None:
            self._gl = make_gl_context()
            self._gl_address = _egl_context_address(self._gl)
            self._reads = PixelReads(self._ensure_gl)
        # re-binding a current context can flush the GL pipeline
        if self._gl_address is None or gl_direct.egl_current_context() != self._gl_address:
            self._gl.make_current()

    def bind(self, scene: RenderScene) -> None:
        """Make the GL contexts match the scene's current model."""
        with profiling.timed("render:bind+uploads"):
            self._bind(scene)

    def _bind(self, scene: RenderScene) -> None:
        self._ensure_gl()
        model = scene.sim.model
        quality = render_quality(max(int(model.vis.global_.offwidth), int(model.vis.global_.offheight)))
        if (int(model.vis.quality.shadowsize), int(model.vis.quality.offsamples)) != quality:
            # the render mode changed since the compile: takes effect now, no recompile needed
            model.vis.quality.shadowsize, model.vis.quality.offsamples = quality
            self._version = -1
        if self._version != scene.version or self._model is not model:
            if self._mjr is not None:
                self._mjr.free()
            self._mjr = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
            if self._ids is not None:
                self._ids.free()
                self._ids = None
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._mjr)
            self._mjr.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR
            self._scene = mujoco.MjvScene(model, maxgeom=max(1000, 2 * model.ngeom + 100))
            self._version = scene.version
            self._model = model
            self._uploaded_inverse = {mid: np.linalg.inv(m) for mid, m in scene.mesh_maps.items()}
            self._undo = _undo_table(self._uploaded_inverse)
            self._flat_sky = sky.uniform_sky(model)
        if scene.meshes_to_upload:   # deformables' meshes moved by physics
            for mid in sorted(scene.meshes_to_upload):
                mujoco.mjr_uploadMesh(model, self._mjr, mid)
            scene.meshes_to_upload.clear()
        if scene.textures_to_upload:
            for tid in sorted(scene.textures_to_upload):
                mujoco.mjr_uploadTexture(model, self._mjr, tid)
            scene.textures_to_upload.clear()
            self._flat_sky = sky.uniform_sky(model)

    def _id_framebuffer(self, bits: int) -> IdFramebuffer:
        """The id framebuffer for codes of ``bits`` bits at the model's offscreen size (made when either
        changes)."""
        assert self._model is not None and self._reads is not None
        size = (int(self._model.vis.global_.offwidth), int(self._model.vis.global_.offheight))
        ids = self._ids
        if ids is None or ids.code_bits != bits or (ids.width, ids.height) != size:
            if ids is not None:
                ids.free()
            self._ids = ids = IdFramebuffer(size[0], size[1], bits)
            self._reads.forget_framebuffers()   # GL may give the new one a freed framebuffer's name
        return ids

    def close(self) -> None:
        if self._gl is not None:
            self._gl.make_current()
            if self._reads is not None:
                self._reads.free()
                self._reads = None
            if self._ids is not None:
                self._ids.free()
                self._ids = None
        if self._mjr is not None:
            self._mjr.free()
            self._mjr = None
        if self._gl is not None:
            self._gl.free()
            self._gl = None

    # ---- one render ----------------------------------------------------
    def _update_scene(self, scene: RenderScene, view: CameraView, bounds: tuple[np.ndarray, float],
                      jitter: tuple[float, float], crop: Crop | None = None,
                      data: mujoco.MjData | None = None) -> float:
        """Fill the MuJoCo scene for one render of ``view`` with the geometry inside ``bounds`` (from
        :func:`geometry_bounds`), posed as in ``data`` (default: the simulation's); returns the far plane
        used (see :func:`effective_far`)."""
        mjv = self._scene
        assert mjv is not None and self._mjr is not None
        sim = scene.sim
        center, radius = bounds
        far = effective_far(center, radius, view)
        mujoco.mjv_updateScene(sim.model, sim.data if data is None else data, self._option, None, self._camera,
                               mujoco.mjtCatBit.mjCAT_STATIC | mujoco.mjtCatBit.mjCAT_DYNAMIC, mjv)
        if scene.mesh_maps:
            self._draw_rescaled_meshes(scene, mjv)
        if mjv.flags[mujoco.mjtRndFlag.mjRND_SHADOW]:
            self._fit_directional_shadows(mjv, center, radius)
        left, right, bottom, top = view.frustum_window(crop, jitter)
        forward = -view.rotation[:, 2]
        up = view.rotation[:, 1]
        for i in range(2):
            cam = mjv.camera[i]
            cam.pos[:] = view.position
            cam.forward[:] = forward
            cam.up[:] = up
            cam.frustum_center = 0.5 * (left + right)
            cam.frustum_width = 0.5 * (right - left)
            cam.frustum_bottom = bottom
            cam.frustum_top = top
            cam.frustum_near = view.near
            cam.frustum_far = SKY_FAR_FACTOR * far
            cam.orthographic = 1 if view.projection == "orthographic" else 0
        mjv.enabletransform = 0
        return far

    def _fit_directional_shadows(self, scene: mujoco.MjvScene, center: np.ndarray, radius: float) -> None:
        """Aim every shadow-casting directional light's shadow map at the geometry as it is now.

        MuJoCo draws a directional light's shadow map as a box of half-width
        ``MjrContext.shadowClip`` around the light's position, fixed when the context
        is made (from the model's extent at compile time); geometry that moved out
        of it since (randomized poses are written straight into MuJoCo) would cast
        no shadow. Each render puts the light up-light of the current bounding
        sphere and sizes the box to it.
        """
        assert self._mjr is not None
        directional = int(mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
        fitted = False
        for light in scene.lights[:scene.nlight]:
            if light.castshadow and int(light.type) == directional:
                d = np.asarray(light.dir, dtype=np.float64)
                light.pos[:] = center - 2.0 * radius * d / max(float(np.linalg.norm(d)), 1e-12)
                fitted = True
        if fitted:
            self._mjr.shadowClip = radius

    def _draw_rescaled_meshes(self, scene: RenderScene, mjv: mujoco.MjvScene) -> None:
        """Fold meshes rescaled since their upload into their scene geoms' matrices.

        The GPU holds each mesh as it was at upload; the model's vertices are that
        copy mapped by ``current @ inverse(uploaded)`` in the geom's frame, so the
        geom's rotation matrix times that map draws the current mesh (the fixed
        function pipeline transforms normals by the inverse transpose).
        """
        maps, uploaded_inverse = scene.mesh_maps, self._uploaded_inverse
        # ints, not the enums: comparing with a pybind11 enum costs microseconds per geom
        dataid = scene.sim.model.geom_dataid
        geom_obj, mesh = int(mujoco.mjtObj.mjOBJ_GEOM), int(mujoco.mjtGeom.mjGEOM_MESH)
        geoms = geom_array(mjv)
        if geoms is not None:
            _fold_mesh_maps(geoms, dataid, maps, self._undo, mesh, geom_obj)
            return
        for g in mjv.geoms[:mjv.ngeom]:
            if g.type != mesh or g.objtype != geom_obj:
                continue
            mid = int(dataid[g.objid])
            current = maps.get(mid)
            if current is not None:
                undo = uploaded_inverse.get(mid)
                g.mat[:] = g.mat @ (current if undo is None else current @ undo)

    def render_batch(self, scene: RenderScene, requests: list[RenderRequest]) -> list[RenderOutputs]:
        """:meth:`render` of each request in turn (the rasteriser draws one camera per pass), the offscreen
        buffer first made to hold them all."""
        for r in requests:
            scene.require_offscreen(r.view.width, r.view.height)
        return [self.render(scene, r.view, r.passes, r.subframes, defer=r.defer, motion=r.motion) for r in requests]

    def render(self, scene: RenderScene, view: CameraView, passes: set[str], subframes: int = 1,
               defer: bool = False, motion: MotionSamples | None = None) -> RenderOutputs:
        """Render the requested ``passes`` of ``view`` (only those: each pass costs a render).

        With ``defer`` the pixels are left copying off the GPU: each pass is
        finished (mapped, decoded) when first read from the outputs, so the
        caller can do other work meanwhile. Jittered subframes are always read
        at once (they are summed on the CPU). ``motion``: the colour is the mean of
        renders at these motion-blur sub-frames (:mod:`graphsdg.render.motion_blur`);
        depth and ids stay those of the simulation's current state. The scene's offscreen buffer grows to hold
        ``view`` if it must (the renderer owns its sizes, as MuJoCo's ``Renderer`` does).
        """
        unknown = set(passes) - set(PASSES)
        if unknown:
            raise ValueError(f"unknown render passes {sorted(unknown)}; known: {PASSES}")
        if subframes < 1:
            raise ValueError(f"subframes must be >= 1, got {subframes}")
        scene.require_offscreen(view.width, view.height)
        self.bind(scene)
        sim = scene.sim
        model = sim.model
        out = RenderOutputs()
        drawn = drawn_geom_mask(model)
        bounds = geometry_bounds(model, sim.data, drawn)   # one state for all of this render's passes
        colour = "color" in passes or "hdr" in passes
        # Without MSAA the colour pass's depth buffer is sampled at pixel centres, so colour and
        # depth come from one render; with MSAA it holds an off-centre sample, so depth is read
        # from the (single-sample) id render instead.
        depth_with_colour = colour and "depth" in passes and "segmentation" not in passes and \
            int(model.vis.quality.offsamples) == 0 and motion is None
        scene_far = None   # set while the scene holds this frame's unjittered geometry (reused by the id pass)
        if colour:
            scene_far = self._render_color(scene, view, bounds, subframes, out, want_color="color" in passes,
                                           want_linear="hdr" in passes, want_depth=depth_with_colour,
                                           motion=motion, drawn=drawn)
        if "segmentation" in passes or ("depth" in passes and not depth_with_colour):
            codes, lut, depth = self._render_ids(scene, view, bounds, None, with_depth="depth" in passes,
                                                 scene_far=scene_far)
            if "segmentation" in passes:
                out.put("id_codes", codes)
                out.id_lut = lut
                out.derive("geom_ids", lambda done: lookup(lut, done.id_codes))
            out.put("depth", depth)
        if not defer:
            out.finish()
        out.render_isolated = lambda geoms, crop: self.render_isolated(scene, view, geoms, crop)
        return out

    def _render_color(self, scene: RenderScene, view: CameraView, bounds: tuple[np.ndarray, float], subframes: int,
                      out: RenderOutputs, want_color: bool, want_linear: bool, want_depth: bool,
                      motion: MotionSamples | None = None, drawn: np.ndarray | None = None) -> float | None:
        """Draw and queue the colour pass; returns the far plane when the scene is left as updated for
        the unjittered view (one subframe), else None. ``drawn``: :func:`drawn_geom_mask` of the model, when
        the caller has it."""
        assert self._scene is not None and self._mjr is not None and self._reads is not None
        ctx, model = self._mjr, scene.sim.model
        w, h = view.width, view.height
        rect = mujoco.MjrRect(0, 0, w, h)
        flags = self._scene.flags
        flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 0
        flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 0
        # a one-colour sky is one flat rectangle behind the geometry, cheaper than MuJoCo's skybox draw
        background = self._flat_sky
        if background is not None:
            if not sky.fill_is_exact(model, drawn_geom_mask(model) if drawn is None else drawn):
                background = None
        flags[mujoco.mjtRndFlag.mjRND_SKYBOX] = background is None
        flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 1
        if background is not None:
            self.skies_filled += 1
        if motion is not None:   # motion blur: each render at its sub-frame's poses, with the next jitter
            n = max(subframes, motion.count)
            jitters = jitter_offsets(n)
            acc = np.zeros((h, w, 3), dtype=np.float32)
            for i in range(n):
                posed, seen = motion.pose(i * motion.count // n)
                self._update_scene(scene, seen, bounds, jitters[i], data=posed)
                with profiling.timed("render:color"):
                    self._draw_color(rect, background)
                acc += self._reads.read_color(ctx, w, h).result()[..., :3]
                self.stats["color"] += 1
            _put_average(out, acc / n, want_color, want_linear)
            return None
        far = self._update_scene(scene, view, bounds, (0.0, 0.0))
        with profiling.timed("render:color"):
            self._draw_color(rect, background)
        with profiling.timed("readback:color"):
            pixels = self._reads.read_color(ctx, w, h, opaque=subframes == 1)
            raw = self._reads.read_depth(ctx, w, h, _depth_decoder(far, view)) if want_depth else None
        self.stats["color"] += 1
        if raw is not None:
            out.put("depth", raw.result)
        if subframes == 1:
            if want_color:
                out.put("color", pixels.result)
            if want_linear:
                out.put("hdr", lambda: pixels.result()[..., :3].astype(np.float32) / np.float32(255))
            return far
        acc = pixels.result()[..., :3].astype(np.float32)
        for jit in jitter_offsets(subframes)[1:]:
            self._update_scene(scene, view, bounds, jit)
            self._draw_color(rect, background)
            acc += self._reads.read_color(ctx, w, h).result()[..., :3]
            self.stats["color"] += 1
        _put_average(out, acc / subframes, want_color, want_linear)
        return None

    def _draw_color(self, rect: mujoco.MjrRect, background: tuple[float, float, float] | None) -> None:
        """MuJoCo's colour render, then the one-colour sky behind the geometry when it is not drawn as a skybox."""
        mujoco.mjr_render(rect, self._scene, self._mjr)
        if background is not None:
            sky.fill_background(rect.width, rect.height, background)

    def _render_ids(self, scene: RenderScene, view: CameraView, bounds: tuple[np.ndarray, float], crop: Crop | None,
                    with_depth: bool, scene_far: float | None = None
                    ) -> tuple[Callable[[], np.ndarray], np.ndarray, Callable[[], np.ndarray] | None]:
        """Id codes (a finisher), their code -> geom id table, and a depth finisher, of the view or a
        crop of it, top row first.

        ``scene_far``: the scene already holds this view's geometry, uncropped and unjittered, with that
        far plane (the colour pass just updated it): drawn again as it is. The render flags are
        not inputs of ``mjv_updateScene``, and the shadow fit it skips only moves lights, which the
        id colours ignore.
        """
        assert self._scene is not None and self._mjr is not None and self._reads is not None
        mjv, ctx = self._scene, self._mjr
        x0, y0, x1, y1 = crop if crop is not None else (0, 0, view.width, view.height)
        w, h = x1 - x0, y1 - y0
        rect = mujoco.MjrRect(0, 0, w, h)
        flags = mjv.flags
        flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 1
        flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 1
        flags[mujoco.mjtRndFlag.mjRND_SKYBOX] = 0
        flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
        try:
            if scene_far is not None and crop is None:
                far = scene_far
            else:
                far = self._update_scene(scene, view, bounds, (0.0, 0.0), crop)
            kind = "ids" if crop is None else "isolated"
            lut = _segid_lut(mjv)   # the MuJoCo scene's segid -> geom id table of this render, taken now
            with self._id_framebuffer(code_bits(len(lut))).bound(ctx):
                with profiling.timed(f"render:{kind}"):
                    mujoco.mjr_render(rect, mjv, ctx)
                with profiling.timed(f"readback:{kind}"):
                    codes = self._reads.read_codes(ctx, w, h, len(lut))
                    raw = self._reads.read_depth(ctx, w, h, _depth_decoder(far, view)) if with_depth \
                        else None
        finally:
            flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 0
            flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 0
        self.stats[kind] += 1
        return codes.result, lut, (raw.result if raw is not None else None)

    def render_isolated(self, scene: RenderScene, view: CameraView, geoms: Sequence[int], crop: Crop) -> np.ndarray:
        """Geom ids (H', W') of the ``crop`` of ``view`` with only ``geoms`` drawn (-1 elsewhere).

        Every other geom is moved to the hidden group for this one render and put
        back afterwards, so the result is the unoccluded footprint of ``geoms``.
        """
        x0, y0, x1, y1 = (int(c) for c in crop)
        if not (0 <= x0 < x1 <= view.width and 0 <= y0 < y1 <= view.height):
            raise ValueError(f"crop {crop} is not a non-empty rectangle inside {view.width}x{view.height}")
        sim = scene.sim
        if self._model is not sim.model or self._version != scene.version:
            self.bind(scene)   # normally bound (and current) already: this follows render() of the same view
        model = sim.model
        group = model.geom_group
        saved = group.copy()
        keep = np.zeros(model.ngeom, dtype=bool)
        keep[np.asarray(list(geoms), dtype=np.int64)] = True
        try:
            group[~keep] = HIDDEN_GROUP
            codes, lut, _ = self._render_ids(scene, view, geometry_bounds(model, sim.data), (x0, y0, x1, y1),
                                             with_depth=False)
            return lookup(lut, codes())
        finally:
            group[:] = saved


def _put_average(out: RenderOutputs, mean: np.ndarray, want_color: bool, want_linear: bool) -> None:
    """The mean of several colour renders (jittered sub-frames, motion-blur samples) as the outputs."""
    if want_color:
        rgba = np.full((*mean.shape[:2], 4), 255, dtype=np.uint8)
        rgba[..., :3] = np.rint(mean)
        out.put("color", rgba)
    if want_linear:
        out.put("hdr", mean / np.float32(255))


def geometry_bounds(model: mujoco.MjModel, data: mujoco.MjData,
                    drawn: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """(centre, radius) of a sphere around every drawn, bounded geom where it is now (``drawn``:
    :func:`drawn_geom_mask` of the model, when the caller has it).

    Poses written since the compile (randomization, physics) move geoms away
    from the model's compile-time ``stat.center`` / ``stat.extent``, which are
    the fallback when no geom is bounded (planes alone).
    """
    radii = np.asarray(model.geom_rbound)
    bounded = (radii > 0) & (drawn_geom_mask(model) if drawn is None else drawn)
    if not bounded.any():
        return np.asarray(model.stat.center, dtype=np.float64), float(model.stat.extent)
    pos, r = np.asarray(data.geom_xpos)[bounded], radii[bounded][:, None]
    center = 0.5 * ((pos - r).min(axis=0) + (pos + r).max(axis=0))
    offsets = pos - center
    # np.linalg.norm's sum, bit for bit, without its dispatch (every render)
    return center, float((np.sqrt(np.add.reduce(offsets * offsets, axis=1)) + r[:, 0]).max())


def effective_far(center: np.ndarray, radius: float, view: CameraView) -> float:
    """The far plane actually used: the camera's, tightened to just beyond the geometry.

    MuJoCo's shadow maps take their depth range from the camera's frustum and its
    skybox is drawn at ~0.6-0.7 of the far plane. A tight far plane (the
    geometry's bounding sphere, from :func:`geometry_bounds`, plus margin) keeps
    shadows sharp; rendering to twice it keeps the sky behind all geometry.
    """
    reach = float(np.linalg.norm(view.position - center)) + 4.0 * float(radius)
    return max(min(view.far, reach), view.near * 10)


def _linearize_depth(raw: np.ndarray, near: float, far: float, clip: float,
                     orthographic: bool = False) -> np.ndarray:
    """Reversed-Z window depth -> planar z (the algebra of ``mujoco.Renderer``); beyond ``clip`` -> inf.

    A new array, computed in place after the first operation (``raw`` may be a
    strided view of a mapped pixel buffer: it is read once per operation).
    """
    if orthographic:   # window depth is linear: 1 at near, 0 at far
        lin = (far - raw.astype(np.float64) * (far - near)).astype(np.float32)
        lin[(raw <= 0.0) | (lin > clip)] = np.inf
        return lin
    # Reversed Z: window depth w = near * (far - z) / (z * (far - near)), so z = near * far / (w * (far - near) + near).
    # In float32 the relative error stays ~1e-7 (w itself is a float32 read from GL).
    lin = np.multiply(raw, np.float32(far - near))
    lin += np.float32(near)
    # Nothing drawn (w = 0 gives z = far, beyond clip) or the sky: z > clip, i.e. a denominator below
    # near * far / clip, is set to 0 so the division gives inf (one OpenCV pass instead of a mask and a put)
    cv2.threshold(lin, float(np.float32(near * far / clip)), 0.0, cv2.THRESH_TOZERO, dst=lin)
    with np.errstate(divide="ignore"):
        np.divide(np.float32(near * far), lin, out=lin)
    return lin


def _depth_decoder(far: float, view: CameraView) -> Callable[[np.ndarray], np.ndarray]:
    """Window depths (top row first) -> planar z, for a render of ``view`` with far plane ``far``."""
    near, orthographic = view.near, view.projection == "orthographic"
    return lambda raw: _linearize_depth(raw, near, SKY_FAR_FACTOR * far, far, orthographic=orthographic)


def _undo_table(uploaded_inverse: dict[int, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """``Rasterizer._uploaded_inverse`` as arrays by mesh id: (which meshes have one, (n, 3, 3) matrices)."""
    if not uploaded_inverse:
        return np.zeros(0, dtype=bool), np.zeros((0, 3, 3))
    size = max(uploaded_inverse) + 1
    has, undo = np.zeros(size, dtype=bool), np.zeros((size, 3, 3))
    ids = np.fromiter(uploaded_inverse.keys(), dtype=np.int64, count=len(uploaded_inverse))
    has[ids] = True
    undo[ids] = np.array(list(uploaded_inverse.values()), dtype=np.float64).reshape(-1, 3, 3)
    return has, undo


def _fold_mesh_maps(geoms: np.ndarray, dataid: np.ndarray, maps: MeshMaps | dict[int, np.ndarray],
                    uploaded_inverse: tuple[np.ndarray, np.ndarray], mesh: int, geom_obj: int) -> None:
    """:meth:`Rasterizer._draw_rescaled_meshes` over the MuJoCo scene's geoms as one array (``scene_geoms``);
    ``uploaded_inverse`` as :func:`_undo_table` gives it.

    The products are those of the per-geom loop, batched: for each drawn mesh geom
    ``current @ undo`` of its mesh, then the geom's float32 matrix times that in
    float64, rounded back to float32 as it is stored (the same numbers, bit for bit:
    tests compare both).
    """
    rows = np.flatnonzero((geoms["type"] == mesh) & (geoms["objtype"] == geom_obj))
    if not rows.size:
        return
    mids = np.asarray(dataid)[geoms["objid"][rows]]
    if isinstance(maps, MeshMaps):
        present, matrices = maps.present, maps.matrices
    else:
        ids = np.fromiter(maps.keys(), dtype=np.int64, count=len(maps))
        present = np.zeros(int(ids.max()) + 1 if ids.size else 0, dtype=bool)
        present[ids] = True
        matrices = np.zeros((present.size, 3, 3))
        matrices[ids] = np.array(list(maps.values()), dtype=np.float64).reshape(-1, 3, 3)
    keep = _flags_at(present, mids)
    if not keep.any():
        return
    rows, mids = rows[keep], mids[keep]
    folds = matrices[mids]                            # current maps, one per drawn mesh geom
    has_undo, undo = uploaded_inverse
    undone = _flags_at(has_undo, mids)                # meshes uploaded already rescaled
    if undone.any():
        folds[undone] = np.matmul(folds[undone], undo[mids[undone]])
    mats = geoms["mat"][rows].reshape(-1, 3, 3)
    geoms["mat"][rows] = np.matmul(mats, folds).reshape(-1, 9)


def _flags_at(flags: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """``flags[ids]`` with ids at or beyond the end of ``flags`` False."""
    if ids.size and int(ids.max()) < flags.size:
        return flags[ids]
    out = np.zeros(ids.shape, dtype=bool)
    inside = ids < flags.size
    out[inside] = flags[ids[inside]]
    return out


_GEOM_OBJ = int(mujoco.mjtObj.mjOBJ_GEOM)   # an int: comparing with the enum costs microseconds per geom
_UNSET_LUTS: dict[int, np.ndarray] = {}


def _unset_lut(size: int) -> np.ndarray:
    """A read-only int32 table of ``size`` -1s, copied for each render (cheaper than ``np.full`` each time)."""
    lut = _UNSET_LUTS.get(size)
    if lut is None:
        lut = _UNSET_LUTS[size] = np.full(size, -1, dtype=np.int32)
        lut.flags.writeable = False
    return lut


def _segid_lut(scene: mujoco.MjvScene) -> np.ndarray:
    """MuJoCo's id colours (segid + 1) -> geom id for the geoms of ``scene`` now; -1 for anything else.

    Sized 2^8 or 2^16 when the codes (1..ngeom, 0 the background) fit in those
    bits, so every code read back indexes it.
    """
    ngeom = scene.ngeom
    size = 1 << 8 if ngeom < 1 << 8 else 1 << 16 if ngeom < 1 << 16 else ngeom + 2
    lut = _unset_lut(size).copy()
    geom_obj = _GEOM_OBJ
    geoms = geom_array(scene)
    if geoms is not None:
        segid = geoms["segid"]
        drawn = (segid >= 0) & (geoms["objtype"] == geom_obj)
        lut[segid[drawn] + 1] = geoms["objid"][drawn]
        return lut
    for g in scene.geoms[:scene.ngeom]:
        if g.segid >= 0 and g.objtype == geom_obj:
            lut[g.segid + 1] = g.objid
    return lut
