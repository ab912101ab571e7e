"""MuJoCo's OpenGL rasteriser, driven by USD cameras.

One :class:`Rasterizer` per process owns the GL context (EGL when headless) and
an ``MjrContext`` for the current model. The USD camera's pose and pinhole
projection are written into the scene's ``mjvGLCamera`` directly, so render
products need no MuJoCo camera and any aspect ratio, clipping range or aperture
offset is honoured exactly.

Passes:

* ``color`` + ``depth``: one ``mjr_render``, one ``mjr_readPixels`` of both
  buffers; depth is linearised to planar z in stage units (background ``inf``).
* ``segmentation``: a second render with MuJoCo's id colours, decoded to geom
  ids (background -1). MSAA does not blend ids.

``subframes`` > 1 renders the colour that many times with sub-pixel jitter
(a Halton(2, 3) pattern) and averages: anti-aliasing on a rasteriser, which is
what Replicator's ``rt_subframes`` buys. Depth and ids come from the unjittered
sample so labels stay crisp.
"""
from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from graphsdg.render.camera import CameraView
from graphsdg.sim.compiler import COLLISION_ONLY_GROUP, HIDDEN_GROUP
from graphsdg.sim.scene import SimScene

PASSES = ("color", "depth", "segmentation")
SKY_FAR_FACTOR = 2.0


@dataclass
class RenderOutputs:
    """What one render of one camera produced (each ``None`` if not requested)."""

    color: np.ndarray | None = None          # uint8 (H, W, 3)
    depth: np.ndarray | None = None          # float32 (H, W), planar z, inf on background
    geom_ids: np.ndarray | None = None       # int32 (H, W), -1 on background


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
    """Renders a :class:`SimScene` from :class:`CameraView` s."""

    def __init__(self) -> None:
        self._gl = None
        self._mjr: mujoco.MjrContext | None = None
        self._scene: mujoco.MjvScene | None = None
        self._option = mujoco.MjvOption()
        self._option.geomgroup[HIDDEN_GROUP] = 0
        self._option.geomgroup[COLLISION_ONLY_GROUP] = 0
        self._camera = mujoco.MjvCamera()
        self._camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        self._version = -1
        self._model: mujoco.MjModel | None = None

    # ---- contexts ------------------------------------------------------
    def _ensure_gl(self) -> None:
        if self._gl is None:
            from mujoco.rendering.classic import gl_context
            if gl_context.GLContext is None:
                raise RuntimeError("MuJoCo has no OpenGL platform; set MUJOCO_GL=egl (needs libEGL) "
                                   "before importing graphsdg")
            self._gl = gl_context.GLContext(64, 64)
        self._gl.make_current()

    def bind(self, sim: SimScene) -> None:
        """Make the GL contexts match the scene's current model."""
        self._ensure_gl()
        model = sim.model
        if self._version != sim.model_version or self._model is not model:
            if self._mjr is not None:
                self._mjr.free()
            self._mjr = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._mjr)
            self._mjr.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR
            self._scene = mujoco.MjvScene(model, maxgeom=max(1000, 2 * model.ngeom + 100))
            self._version = sim.model_version
            self._model = model
        if sim.textures_to_upload:
            for tid in sorted(sim.textures_to_upload):
                mujoco.mjr_uploadTexture(model, self._mjr, tid)
            sim.textures_to_upload.clear()
        if sim.meshes_to_upload:
            for mid in sorted(sim.meshes_to_upload):
                mujoco.mjr_uploadMesh(model, self._mjr, mid)
            sim.meshes_to_upload.clear()

    def close(self) -> None:
        if self._mjr is not None:
            if self._gl is not None:
                self._gl.make_current()
            self._mjr.free()
            self._mjr = None
        if self._gl is not None:
            self._gl.free()
            self._gl = None

    # ---- one render ----------------------------------------------------
    def _update_scene(self, sim: SimScene, view: CameraView, jitter: tuple[float, float]) -> None:
        scene = self._scene
        assert scene is not None
        far = effective_far(sim.model, view)
        mujoco.mjv_updateScene(sim.model, sim.data, self._option, None, self._camera,
                               mujoco.mjtCatBit.mjCAT_STATIC | mujoco.mjtCatBit.mjCAT_DYNAMIC, scene)
        near = view.near
        half_w = near * view.horizontal_aperture / (2 * view.focal_length)
        half_h = half_w * view.height / view.width
        # Aperture offsets move the principal point; jitter moves it by a sub-pixel.
        cx_shift = near * view.horizontal_aperture_offset / view.focal_length + jitter[0] * 2 * half_w / view.width
        cy_shift = near * view.vertical_aperture_offset / view.focal_length - jitter[1] * 2 * half_h / view.height
        forward = -view.rotation[:, 2]
        up = view.rotation[:, 1]
        for i in range(2):
            cam = scene.camera[i]
            cam.pos[:] = view.position
            cam.forward[:] = forward
            cam.up[:] = up
            cam.frustum_center = cx_shift
            cam.frustum_width = half_w
            cam.frustum_bottom = cy_shift - half_h
            cam.frustum_top = cy_shift + half_h
            cam.frustum_near = near
            cam.frustum_far = SKY_FAR_FACTOR * far
            cam.orthographic = 1 if view.projection == "orthographic" else 0
        scene.enabletransform = 0

    def render(self, sim: SimScene, view: CameraView, passes: set[str], subframes: int = 1) -> RenderOutputs:
        """Render the requested ``passes`` of ``view``."""
        unknown = set(passes) - set(PASSES)
        if unknown:
            raise ValueError(f"unknown render passes {sorted(unknown)}; known: {PASSES}")
        if subframes < 1:
            raise ValueError(f"subframes must be >= 1, got {subframes}")
        self.bind(sim)
        model = sim.model
        if view.width > model.vis.global_.offwidth or view.height > model.vis.global_.offheight:
            raise ValueError(f"resolution {view.width}x{view.height} exceeds the offscreen buffer "
                             f"{model.vis.global_.offwidth}x{model.vis.global_.offheight}")
        assert self._scene is not None and self._mjr is not None
        scene, ctx = self._scene, self._mjr
        w, h = view.width, view.height
        rect = mujoco.MjrRect(0, 0, w, h)
        out = RenderOutputs()
        flags = scene.flags
        if "color" in passes or "depth" in passes:
            flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 0
            flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 0
            flags[mujoco.mjtRndFlag.mjRND_SKYBOX] = 1
            flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 1
            rgb = np.empty((h, w, 3), dtype=np.uint8)
            depth = np.empty((h, w), dtype=np.float32)
            self._update_scene(sim, view, (0.0, 0.0))
            mujoco.mjr_render(rect, scene, ctx)
            mujoco.mjr_readPixels(rgb, depth, rect, ctx)
            if "color" in passes:
                if subframes > 1:
                    acc = rgb.astype(np.float32)
                    for jit in jitter_offsets(subframes)[1:]:
                        self._update_scene(sim, view, jit)
                        mujoco.mjr_render(rect, scene, ctx)
                        mujoco.mjr_readPixels(rgb, None, rect, ctx)
                        acc += rgb
                    rgb = np.rint(acc / subframes).astype(np.uint8)
                out.color = np.ascontiguousarray(rgb[::-1])
            if "depth" in passes:
                far = effective_far(model, view)
                out.depth = _linearize_depth(depth[::-1], view.near, SKY_FAR_FACTOR * far, far)
        if "segmentation" in passes:
            flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 1
            flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 1
            flags[mujoco.mjtRndFlag.mjRND_SKYBOX] = 0
            flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
            self._update_scene(sim, view, (0.0, 0.0))
            mujoco.mjr_render(rect, scene, ctx)
            ids = np.empty((h, w, 3), dtype=np.uint8)
            mujoco.mjr_readPixels(ids, None, rect, ctx)
            out.geom_ids = _decode_segmentation(ids[::-1], scene)
            flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 0
            flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 0
        return out


def effective_far(model: mujoco.MjModel, view: CameraView) -> float:
    """The far plane actually used: the camera's, tightened to just beyond the scene.

    MuJoCo fits directional shadow maps to the view frustum and draws the skybox at
    ~0.6-0.7 of the far plane. A tight far plane (the scene's bounding sphere plus
    margin) keeps shadows sharp; rendering to twice it keeps the sky behind all geometry.
    """
    reach = float(np.linalg.norm(view.position - model.stat.center)) + 4.0 * float(model.stat.extent)
    return max(min(view.far, reach), view.near * 10)


def _linearize_depth(raw: np.ndarray, near: float, far: float, clip: float) -> np.ndarray:
    """Reversed-Z window depth -> planar z (the algebra of ``mujoco.Renderer``); beyond ``clip`` -> inf."""
    zfar, znear = np.float32(far), np.float32(near)
    c = -(zfar + znear) / (zfar - znear)
    d = -(np.float32(2) * zfar * znear) / (zfar - znear)
    c = np.float32(-0.5) * c - np.float32(0.5)
    d = np.float32(-0.5) * d
    z = raw.astype(np.float64)
    with np.errstate(divide="ignore"):
        lin = d / (z + c)
    lin = lin.astype(np.float32)
    lin[(raw <= 0.0) | (lin > clip)] = np.inf   # nothing drawn, or the sky
    return lin


def _decode_segmentation(rgb: np.ndarray, scene: mujoco.MjvScene) -> np.ndarray:
    segid = rgb[..., 0].astype(np.int32) | (rgb[..., 1].astype(np.int32) << 8) | \
        (rgb[..., 2].astype(np.int32) << 16)
    lut = np.full(scene.ngeom + 2, -1, dtype=np.int32)
    for g in scene.geoms[:scene.ngeom]:
        if g.segid >= 0 and g.objtype == mujoco.mjtObj.mjOBJ_GEOM:
            lut[g.segid + 1] = g.objid
    segid = np.clip(segid, 0, len(lut) - 1)
    return lut[segid]
