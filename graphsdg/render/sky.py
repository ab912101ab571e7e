"""A one-colour sky drawn as one flat rectangle behind the geometry instead of MuJoCo's skybox.

MuJoCo draws its skybox as a textured cylinder around the camera after the
opaque geometry, a costly draw on GPUs with few graphics units (docs/performance.md,
"The one-colour sky"). When the sky is one colour (an untextured dome light) the same
samples come from one untextured rectangle drawn where the depth buffer still
holds its clear value, i.e. where no geometry was drawn, sample by sample, so
anti-aliased edges resolve exactly as they do over the skybox.

MuJoCo draws transparent geoms after the skybox, blended over it, and its
horizon haze with it; a fill after ``mjr_render`` would paint over the first
and miss the second, so :func:`fill_is_exact` requires every drawn geom opaque
and no infinite plane, and the renderer keeps MuJoCo's skybox otherwise.

Example (inside a current GL context, after ``mjr_render`` without the skybox flag)::

    sky = uniform_sky(model)          # (r, g, b) in [0, 1], or None for a textured sky
    if sky is not None and fill_is_exact(model, drawn_geom_mask(model)):   # graphsdg.sim.visual
        fill_background(512, 512, sky)
"""
from __future__ import annotations

import mujoco
import numpy as np
from OpenGL import GL

from graphsdg.render import gl_direct as gld

OPAQUE_ALPHA = 0.995   # MuJoCo draws geoms below this alpha in its transparent pass


def uniform_sky(model: mujoco.MjModel) -> tuple[float, float, float] | None:
    """The colour of the skybox MuJoCo would draw (its first skybox texture) when every texel has it.

    None when the model has no skybox or its texture varies (an environment map).
    The colour is the texel's bytes over 255, so it is drawn back to the same bytes.
    """
    skyboxes = np.flatnonzero(np.asarray(model.tex_type) == int(mujoco.mjtTexture.mjTEXTURE_SKYBOX))
    if skyboxes.size == 0:
        return None
    tid = int(skyboxes[0])
    channels = int(model.tex_nchannel[tid])
    if channels < 3:
        return None
    adr, count = int(model.tex_adr[tid]), int(model.tex_width[tid]) * int(model.tex_height[tid])
    texels = np.asarray(model.tex_data[adr:adr + count * channels]).reshape(count, channels)[:, :3]
    if not (texels == texels[0]).all():
        return None
    r, g, b = (float(v) / 255.0 for v in texels[0])
    return r, g, b


def fill_is_exact(model: mujoco.MjModel, drawn: np.ndarray) -> bool:
    """Whether filling the background of a frame of ``model`` after ``mjr_render`` gives MuJoCo's skybox image.

    Conservative, from the model's arrays (a few microseconds): no ``drawn`` geom
    (a mask over the geoms) whose colour or material has an alpha below MuJoCo's
    opaque threshold, and no infinite plane.
    """
    if not drawn.any():
        return True
    if (model.geom_rgba[drawn, 3] < OPAQUE_ALPHA).any():
        return False
    matid = model.geom_matid[drawn]
    if model.nmat and (model.mat_rgba[matid[matid >= 0], 3] < OPAQUE_ALPHA).any():
        return False
    infinite = (model.geom_type == int(mujoco.mjtGeom.mjGEOM_PLANE)) & (model.geom_size[:, 0] == 0) & \
        (model.geom_size[:, 1] == 0)
    return not (infinite & drawn).any()


def fill_background(width: int, height: int, rgb: tuple[float, float, float]) -> None:
    """Fill the pixels (samples) of the bound framebuffer that no geometry covered with ``rgb``.

    One rectangle at window depth 0 (MuJoCo's reversed-Z clear value, the far end)
    with MuJoCo's ``GL_GEQUAL`` depth test passes exactly where the depth buffer
    still holds the clear value, sample by sample. GL state is saved and restored. The ~30 calls keep the
    interpreter lock (:mod:`graphsdg.render.gl_direct`), with one error check at the end.
    """
    gld.glPushAttrib(GL.GL_ALL_ATTRIB_BITS)
    try:
        gld.glViewport(0, 0, width, height)
        gld.glDepthRange(0.0, 0.0)            # every fragment at window depth 0, whatever the clip convention
        gld.glEnable(GL.GL_DEPTH_TEST)
        gld.glDepthFunc(GL.GL_GEQUAL)
        gld.glDepthMask(GL.GL_FALSE)
        for cap in (GL.GL_LIGHTING, GL.GL_TEXTURE_2D, GL.GL_TEXTURE_CUBE_MAP, GL.GL_FOG, GL.GL_CULL_FACE,
                    GL.GL_SCISSOR_TEST, GL.GL_ALPHA_TEST, GL.GL_STENCIL_TEST, GL.GL_BLEND):
            gld.glDisable(cap)
        gld.glPolygonMode(GL.GL_FRONT_AND_BACK, GL.GL_FILL)
        gld.glColorMask(GL.GL_TRUE, GL.GL_TRUE, GL.GL_TRUE, GL.GL_TRUE)
        gld.glMatrixMode(GL.GL_PROJECTION)
        gld.glPushMatrix()
        gld.glLoadIdentity()
        gld.glMatrixMode(GL.GL_MODELVIEW)
        gld.glPushMatrix()
        gld.glLoadIdentity()
        gld.glColor4f(rgb[0], rgb[1], rgb[2], 1.0)
        gld.glRectf(-1.0, -1.0, 1.0, 1.0)
        gld.glPopMatrix()
        gld.glMatrixMode(GL.GL_PROJECTION)
        gld.glPopMatrix()
        gld.glMatrixMode(GL.GL_MODELVIEW)
    finally:
        gld.glPopAttrib()
    gld.check("filling the sky")
