"""The single-sample framebuffer that id passes draw into: id colours and float depth, no stencil.

Ids and depth must be exact at pixel centres, so they are drawn with one sample
per pixel. MuJoCo turns multisampling off for its id colours, which Mesa
honours; NVIDIA's driver still resolves the multisampled id colours, blending
neighbouring ids into the colour of a third geom. So id passes draw into a
framebuffer of their own.

It is graphsdg's, not MuJoCo's, because of its depth format. MuJoCo's buffers
hold depth as DEPTH32F_STENCIL8 (stencil for mirror reflections, which graphsdg
never compiles), which NVIDIA's driver unpacks on the GPU to read depth alone.
Here depth is DEPTH_COMPONENT32F: read as stored, 4 bytes a pixel, in one copy.

Its colour holds only the bytes of id colour the codes need (:func:`colour_format`):
one (R8) for scenes of fewer than 255 geoms, so reading the codes back is a plain
copy of one byte a pixel, where the red byte of RGBA8 would make the GPU repack
every pixel. docs/performance.md ("The id framebuffer's formats") has the
measurements behind these choices.

Example (inside a current GL context)::

    ids = IdFramebuffer(512, 512, code_bits=8)
    with ids.bound(mjr_context):      # mjr_render now draws into it, single-sample
        mujoco.mjr_render(rect, scene, mjr_context)
    ids.free()
"""
from __future__ import annotations

import mujoco
from OpenGL import GL

from graphsdg.render.readback import restore_offscreen_bindings


_COLOUR_FORMATS = {8: GL.GL_R8, 16: GL.GL_RG8, 24: GL.GL_RGBA8}


def colour_format(code_bits: int):
    """The colour storage for id codes of ``code_bits`` bits (8, 16 or 24: see ``readback.code_bits``)."""
    if code_bits not in _COLOUR_FORMATS:
        raise ValueError(f"id codes are 8, 16 or 24 bits, got {code_bits!r}")
    return _COLOUR_FORMATS[code_bits]


class IdFramebuffer:
    """A framebuffer of ``width`` x ``height`` for id codes of ``code_bits`` bits, with DEPTH_COMPONENT32F
    depth, in the current GL context."""

    def __init__(self, width: int, height: int, code_bits: int = 24) -> None:
        if width < 1 or height < 1:
            raise ValueError(f"id framebuffer size must be positive, got {width}x{height}")
        colour = colour_format(code_bits)
        self.width, self.height, self.code_bits = int(width), int(height), code_bits
        self.fbo = int(GL.glGenFramebuffers(1))
        self._renderbuffers = [int(b) for b in GL.glGenRenderbuffers(2)]
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self.fbo)
        for rb, fmt, attachment in zip(self._renderbuffers, (colour, GL.GL_DEPTH_COMPONENT32F),
                                       (GL.GL_COLOR_ATTACHMENT0, GL.GL_DEPTH_ATTACHMENT)):
            GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, rb)
            GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, fmt, self.width, self.height)
            GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, attachment, GL.GL_RENDERBUFFER, rb)
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, 0)
        status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
        if status != GL.GL_FRAMEBUFFER_COMPLETE:
            self.free()
            raise RuntimeError(f"the GL driver cannot make a {code_bits}-bit id + DEPTH_COMPONENT32F "
                               f"framebuffer of {width}x{height} (status 0x{int(status):x})")

    def bound(self, ctx: mujoco.MjrContext) -> "_Bound":
        """Make MuJoCo's offscreen framebuffer this one (single-sample) for the ``with`` block."""
        return _Bound(self.fbo, ctx)

    def free(self) -> None:
        """Delete the framebuffer and its storage (the context must be current)."""
        if self.fbo:
            GL.glDeleteFramebuffers(1, [self.fbo])
            GL.glDeleteRenderbuffers(len(self._renderbuffers), self._renderbuffers)
            self.fbo, self._renderbuffers = 0, []


class _Bound:
    """:meth:`IdFramebuffer.bound`'s block (a class: a generator context manager costs several times as
    much to enter and leave, once a frame)."""

    __slots__ = ("fbo", "ctx", "saved")

    def __init__(self, fbo: int, ctx: mujoco.MjrContext) -> None:
        self.fbo, self.ctx = fbo, ctx

    def __enter__(self) -> None:
        ctx = self.ctx
        self.saved = ctx.offFBO, ctx.offSamples
        ctx.offFBO, ctx.offSamples = self.fbo, 0
        restore_offscreen_bindings(ctx)   # binds it for drawing and reading

    def __exit__(self, *exc: object) -> bool:
        ctx = self.ctx
        ctx.offFBO, ctx.offSamples = self.saved
        restore_offscreen_bindings(ctx)
        return False
