"""What a compiled model carries for renderers, and a gprim's visibility.

MuJoCo's visual options (offscreen framebuffer size, shadow-map size, MSAA
samples, the shadow depth range), the geom groups renderers skip (hidden prims,
proxy collision shapes), the camera the pbr backend poses at each render
product, and the live sync of ``visibility`` / ``purpose`` edits into a geom's
group.
"""
from __future__ import annotations

import mujoco
import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.base import settings_store as settings
from graphsdg.sim.compiled_scene import GeomBinding

HIDDEN_GROUP = 5            # geoms in this group are not drawn (invisible prims)
COLLISION_ONLY_GROUP = 4    # proxy collision shapes (not drawn)
UNDRAWN_GROUPS = (COLLISION_ONLY_GROUP, HIDDEN_GROUP)
PBR_CAMERA = "graphsdg:pbr_camera"   # the camera the PBR backend renders from (render products' poses)


def pbr_camera_name(index: int) -> str:
    """The name of the PBR backend's camera ``index`` (0: :data:`PBR_CAMERA`; one per render product it draws
    in one launch)."""
    return PBR_CAMERA if index == 0 else f"{PBR_CAMERA}_{index}"


def drawn_geom_mask(model: mujoco.MjModel) -> np.ndarray:
    """Which geoms renders draw: those in MuJoCo's groups 0-5 other than :data:`UNDRAWN_GROUPS`."""
    group = model.geom_group
    drawn = (group >= 0) & (group < mujoco.mjNGROUP)
    for g in UNDRAWN_GROUPS:
        drawn &= group != g
    return drawn


_quality: list = [None, None]   # (settings generation, largest image) and the answer for them


def render_quality(largest_image: int = 4096) -> tuple[int, int]:
    """(shadow map size, MSAA samples) for the current settings.

    ``/rtx/rendermode = PathTracing`` (Isaac's highest-quality mode) maps to the
    rasteriser's best: 8x multisampling and shadow maps of 8 texels per pixel of
    the largest image (``largest_image``, its longer edge), up to 4096 px, never
    below ``/graphsdg/render/shadowSize``.
    """
    key = (settings.generation(), largest_image)
    if _quality[0] == key:          # every render asks; the settings rarely change
        return _quality[1]
    shadow = int(settings.get("/graphsdg/render/shadowSize", 1024))
    samples = int(settings.get("/graphsdg/render/msaaSamples", 4))
    if str(settings.get("/rtx/rendermode", "")).lower() == "pathtracing":
        shadow, samples = max(shadow, min(4096, 8 * int(largest_image))), max(samples, 8)
    _quality[:] = [key, (shadow, samples)]
    return shadow, samples


def configure_visual(spec: mujoco.MjSpec, offscreen: tuple[int, int]) -> None:
    """Set ``spec``'s offscreen framebuffer to ``offscreen`` and its shadow / MSAA quality from the settings."""
    vis = spec.visual
    vis.global_.offwidth, vis.global_.offheight = offscreen
    vis.quality.shadowsize, vis.quality.offsamples = render_quality(max(offscreen))
    # Cameras get their own near/far from USD; these two (relative to the model extent)
    # only bound MuJoCo's shadow-map depth range, so they are kept tight for precision.
    vis.map.znear = 0.01
    vis.map.zfar = 8.0


def add_pbr_cameras(spec: mujoco.MjSpec, count: int = 1) -> None:
    """``count`` MuJoCo cameras for the PBR backend to pose at render products' USD cameras, one per product
    drawn in the same launch (their rays are per pixel, so no field of view is needed)."""
    if count < 1:
        raise ValueError(f"the pbr backend needs at least one camera, got count={count}")
    for index in range(count):
        spec.worldbody.add_camera(name=pbr_camera_name(index))


def sync_visibility(model: mujoco.MjModel, prim: Usd.Prim, g: GeomBinding) -> None:
    """A visibility edit: the geom of ``prim`` moves into or out of :data:`HIDDEN_GROUP`."""
    visible = UsdGeom.Imageable(prim).ComputeVisibility(Usd.TimeCode.Default()) != UsdGeom.Tokens.invisible
    model.geom_group[g.geom_id] = 0 if visible else HIDDEN_GROUP
    g.visible = visible
