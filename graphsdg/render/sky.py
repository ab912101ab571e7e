"""A uniform sky drawn as a blend under the finished frame instead of MuJoCo's skybox.

MuJoCo draws its skybox as a textured cylinder around the camera after the
opaque geometry: on the H200 (whose GH100 die has few graphics units) that draw
was 0.14 of the 0.58 GPU milliseconds of a 512x512 4x-MSAA colour pass of the
benchmark scene. When the sky is one colour (an untextured dome light) the same
image comes from compositing that colour *under* the frame once it is resolved:
MuJoCo clears to transparent black and opaque geometry writes alpha 1, so after
the multisample resolve each pixel's alpha is the fraction of it the geometry
covers, and ``colour + (1 - alpha) * sky`` is what the skybox would have filled
in behind it (to a rounding step on anti-aliased edges). One single-sample
rectangle with blending does it.

That identity needs every drawn geom opaque (a transparent one blends over the
background and leaves alpha below its coverage) and no infinite plane (MuJoCo
draws its horizon haze with the skybox); :func:`composites_exactly` checks both,
and the renderer keeps MuJoCo's skybox otherwise.

Example (inside a current GL context, after ``mjr_render`` without the skybox
flag and a resolve into ``fbo``)::

    sky = uniform_sky(model)          # (r, g, b) in [0, 1], or None for a textured sky
    if sky is not None and composites_exactly(model):
        composite_under(fbo, 512, 512, sky)
"""
from __future__ import annotations

import mujoco
import numpy as np
from OpenGL import GL

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


def composites_exactly(model: mujoco.MjModel, undrawn_groups: tuple[int, ...] = ()) -> bool:
    """Whether compositing the sky under a frame of ``model`` gives MuJoCo's skybox image.

    Conservative, from the model's arrays (a few microseconds): no drawn geom
    (group not in ``undrawn_groups``, below MuJoCo's 6 groups) whose colour or
    material has an alpha below MuJoCo's opaque threshold, and no infinite plane.
    """
    group = np.asarray(model.geom_group)
    drawn = (group >= 0) & (group < mujoco.mjNGROUP) & ~np.isin(group, undrawn_groups)
    if not drawn.any():
        return True
    if (np.asarray(model.geom_rgba)[drawn, 3] < OPAQUE_ALPHA).any():
        return False
    matid = np.asarray(model.geom_matid)[drawn]
    matid = matid[matid >= 0]
    if matid.size and (np.asarray(model.mat_rgba)[matid, 3] < OPAQUE_ALPHA).any():
        return False
    size = np.asarray(model.geom_size)[drawn]
    plane = np.asarray(model.geom_type)[drawn] == int(mujoco.mjtGeom.mjGEOM_PLANE)
    return not (plane & (size[:, 0] == 0) & (size[:, 1] == 0)).any()


def composite_under(fbo: int, width: int, height: int, rgb: tuple[float, float, float]) -> None:
    """Blend ``rgb`` under the single-sample colour of framebuffer ``fbo`` by its alpha; alpha ends at 1.

    ``dst = dst + (1 - dst_alpha) * (rgb, 1)``. GL state is saved and restored.
    """
    GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, fbo)
    GL.glPushAttrib(GL.GL_ALL_ATTRIB_BITS)
    try:
        GL.glDrawBuffer(GL.GL_COLOR_ATTACHMENT0)
        GL.glViewport(0, 0, width, height)
        for cap in (GL.GL_DEPTH_TEST, GL.GL_LIGHTING, GL.GL_TEXTURE_2D, GL.GL_TEXTURE_CUBE_MAP, GL.GL_FOG,
                    GL.GL_CULL_FACE, GL.GL_SCISSOR_TEST, GL.GL_ALPHA_TEST, GL.GL_STENCIL_TEST):
            GL.glDisable(cap)
        GL.glPolygonMode(GL.GL_FRONT_AND_BACK, GL.GL_FILL)
        GL.glColorMask(GL.GL_TRUE, GL.GL_TRUE, GL.GL_TRUE, GL.GL_TRUE)
        GL.glEnable(GL.GL_BLEND)
        GL.glBlendFunc(GL.GL_ONE_MINUS_DST_ALPHA, GL.GL_ONE)
        GL.glMatrixMode(GL.GL_PROJECTION)
        GL.glPushMatrix()
        GL.glLoadIdentity()
        GL.glMatrixMode(GL.GL_MODELVIEW)
        GL.glPushMatrix()
        GL.glLoadIdentity()
        GL.glColor4f(rgb[0], rgb[1], rgb[2], 1.0)
        GL.glRectf(-1.0, -1.0, 1.0, 1.0)
        GL.glPopMatrix()
        GL.glMatrixMode(GL.GL_PROJECTION)
        GL.glPopMatrix()
        GL.glMatrixMode(GL.GL_MODELVIEW)
    finally:
        GL.glPopAttrib()
