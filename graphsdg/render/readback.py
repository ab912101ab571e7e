"""Asynchronous reads of MuJoCo's offscreen framebuffer through pixel-buffer objects.

``glReadPixels`` into client memory stalls the CPU until the GPU has drawn the
frame and copied it over. Reading into a pixel-buffer object (PBO) instead only
queues the copy; mapping the PBO later returns the pixels, waiting only if the
GPU has not finished by then. The orchestrator uses that to overlap a frame's
rendering and transfer with the script's next randomization
(``step(wait_for_render=False)``). Colour is read as RGBA, the format GL drivers
copy without repacking (MuJoCo's ``mjr_readPixels`` reads RGB), and depth as the
buffer stores it.

Mapping a buffer the GPU is still copying into makes NVIDIA's driver spin on
the CPU until it is done. With many processes sharing one GPU each such wait
is long (other contexts' work runs first; docs/performance.md, "Waiting for the
GPU without spinning"). So each read is followed by a fence, and a map first waits for the fence by polling it
and sleeping in between (:func:`wait_for_fence`), which leaves the core to
other processes and the interpreter lock to the writer threads.

Example (inside a current GL context, after ``mjr_render``)::

    reads = PixelReads(gl_context.make_current)
    pending = reads.read_color(mjr_context, 512, 512)
    ...                                      # other work while the GPU copies
    rgba = pending.result()                  # uint8 (512, 512, 4), top row first
"""
from __future__ import annotations

import ctypes
from typing import Callable

import mujoco
import numpy as np
from OpenGL import GL
from OpenGL.raw.GL.VERSION.GL_1_0 import glReadPixels as raw_read_pixels   # no client-array wrapping: a PBO offset
from OpenGL.raw.GL.VERSION.GL_3_0 import glBlitFramebuffer as raw_blit_framebuffer   # no error check of its own

from graphsdg.base import profiling
from graphsdg.render import gl_direct as gld
from graphsdg.render.polling import wait_until

_FORMATS = {  # kind -> (GL format, GL type, numpy dtype, channels)
    "rgba": (GL.GL_RGBA, GL.GL_UNSIGNED_BYTE, np.uint8, 4),
    # id colours of fewer than 2^8 / 2^16 codes: only the red / red and green bytes carry them
    # (the driver drops the rest on the GPU; two bytes read as one little-endian uint16)
    "red": (GL.GL_RED, GL.GL_UNSIGNED_BYTE, np.uint8, 1),
    "red_green": (GL.GL_RG, GL.GL_UNSIGNED_BYTE, np.uint16, 1),
    "depth": (GL.GL_DEPTH_COMPONENT, GL.GL_FLOAT, np.float32, 1),
    # MuJoCo's depth buffers are DEPTH32F_STENCIL8: read as stored (float depth, then stencil in the
    # second word), a plain copy; asking for depth alone makes NVIDIA's driver unpack it on the GPU
    # first (measured: 0.30 ms of GPU time per 512x512 frame, a quarter of the frame's)
    "depth_stencil": (GL.GL_DEPTH_STENCIL, GL.GL_FLOAT_32_UNSIGNED_INT_24_8_REV, np.float32, 2),
}


def _copy(pixels: np.ndarray) -> np.ndarray:
    return pixels.copy()


_ALPHA_BITS = np.array([0, 0, 0, 255], dtype=np.uint8).view(np.uint32)[0]   # alpha of one RGBA pixel as a word


def _opaque_copy(rgba: np.ndarray) -> np.ndarray:
    """A copy of RGBA pixels with alpha 255, in the one pass of the copy (each pixel ORed as a 32-bit word)."""
    out = np.empty(rgba.shape, dtype=np.uint8)
    np.bitwise_or(rgba.view(np.uint32), _ALPHA_BITS, out=out.view(np.uint32))
    return out


class PendingPixels:
    """One queued read; :meth:`result` maps it (once) and hands its buffer back to the pool.

    ``decode`` turns the mapped pixels (a view of the buffer, top row first) into
    the result, which must not share the buffer's memory; by default a copy.
    Decoding straight from the mapping (depth linearised, say) saves a copy.
    """

    def __init__(self, reads: "PixelReads", pbo: int, nbytes: int, shape: tuple[int, ...], dtype,
                 decode: Callable[[np.ndarray], np.ndarray] = _copy, fence=None) -> None:
        self._reads, self._pbo, self._nbytes, self._fence = reads, pbo, nbytes, fence
        self._shape, self._dtype, self._decode = shape, dtype, decode
        self._array: np.ndarray | None = None

    def result(self) -> np.ndarray:
        """The decoded pixels, top row first (GL's rows run bottom-up: flipped as they are decoded
        out of the buffer); waits for the GPU if it is still copying."""
        if self._array is None:
            with profiling.timed("readback:map"):
                self._array = self._map()
        return self._array

    def _map(self) -> np.ndarray:
        self._reads.make_current()
        if self._fence is not None:
            fence, self._fence = self._fence, None
            try:
                wait_for_fence(fence)
            finally:
                gld.glDeleteSync(fence)
        # binds and the map of a buffer whose copy is done keep the interpreter lock (gl_direct)
        gld.glBindBuffer(GL.GL_PIXEL_PACK_BUFFER, self._pbo)
        pointer = gld.glMapBufferRange(GL.GL_PIXEL_PACK_BUFFER, 0, self._nbytes, GL.GL_MAP_READ_BIT)
        if not pointer:
            gld.glBindBuffer(GL.GL_PIXEL_PACK_BUFFER, 0)
            error = gld.glGetError()
            raise RuntimeError(f"could not map a {self._nbytes}-byte pixel buffer for reading (GL error "
                               f"0x{error:04x})")
        try:
            mapped = np.frombuffer((ctypes.c_ubyte * self._nbytes).from_address(pointer), dtype=self._dtype)
            out = self._decode(mapped.reshape(self._shape)[::-1])
        finally:
            gld.glUnmapBuffer(GL.GL_PIXEL_PACK_BUFFER)
            gld.glBindBuffer(GL.GL_PIXEL_PACK_BUFFER, 0)
            self._reads.release(self._pbo, self._nbytes)
        gld.check("mapping a pixel buffer")
        return out


def restore_offscreen_bindings(ctx: mujoco.MjrContext) -> None:
    """What ``mujoco.mjr_setBuffer(mjFB_OFFSCREEN, ctx)`` binds in a context without a window (its offscreen
    framebuffer for drawing and reading, colour attachment 0 both ways), through calls that keep the
    interpreter lock: the binding's own call releases it, ~8 us a read on a GPU host, three reads a frame."""
    gld.glBindFramebuffer(GL.GL_FRAMEBUFFER, ctx.offFBO)
    gld.glReadBuffer(GL.GL_COLOR_ATTACHMENT0)
    gld.glDrawBuffer(GL.GL_COLOR_ATTACHMENT0)


class PixelReads:
    """A pool of pixel-buffer objects for one GL context, and the reads that use them.

    ``make_current`` is the context's own make-current (a no-op when it is
    current already); buffers are reused by size, so a steady stream of frames
    allocates none after the first two.
    """

    def __init__(self, make_current) -> None:
        self.make_current = make_current
        self._free: dict[int, list[int]] = {}
        self._all: list[int] = []
        self._packed_depth: dict[int, bool] = {}   # framebuffer -> its depth is DEPTH32F_STENCIL8 (asked once)
        self._fences: bool | None = None         # the context has fences (GL 3.2 / ARB_sync; asked once)

    def read_color(self, ctx: mujoco.MjrContext, width: int, height: int, opaque: bool = False) -> PendingPixels:
        """Queue a read of the offscreen colour buffer as RGBA (resolving multisamples first).

        ``opaque`` sets alpha to 255 (MuJoCo's blending leaves other values there)
        as the pixels are copied out of the buffer, at no extra pass. (Clearing
        alpha on the GPU instead cost 4 ms per 1280x720 frame on Mesa's llvmpipe.)
        """
        return self._read(ctx, width, height, "rgba", _opaque_copy if opaque else _copy)

    def read_codes(self, ctx: mujoco.MjrContext, width: int, height: int, size: int) -> PendingPixels:
        """Queue a read of MuJoCo's id colours (``mjRND_IDCOLOR``: segid + 1 in red, green, blue) as
        codes below ``size``: uint8 or uint16 when they fit (one or two bytes a pixel cross the bus),
        else uint32 from the whole colour, clipped below ``size``."""
        bits = code_bits(size)
        if bits == 8:
            return self._read(ctx, width, height, "red")
        if bits == 16:
            return self._read(ctx, width, height, "red_green")
        return self._read(ctx, width, height, "rgba", codes_from_rgba(size))

    def read_depth(self, ctx: mujoco.MjrContext, width: int, height: int,
                   decode: Callable[[np.ndarray], np.ndarray] = _copy) -> PendingPixels:
        """Queue a read of the offscreen depth buffer (window depth; single-sample buffers only);
        ``decode`` gets the float32 (H, W) window depths, top row first."""
        if ctx.offSamples:
            raise ValueError("depth is read from a single-sample buffer; render it into one "
                             "(graphsdg.render.id_framebuffer.IdFramebuffer)")
        packed = self._packed_depth.get(ctx.offFBO)
        if packed is None:
            packed = self._packed_depth[ctx.offFBO] = _is_depth32f_stencil8(ctx.offFBO)
        if not packed:
            return self._read(ctx, width, height, "depth", decode)
        return self._read(ctx, width, height, "depth_stencil", lambda packed: decode(packed[..., 0]))

    def _read(self, ctx: mujoco.MjrContext, width: int, height: int, kind: str,
              decode: Callable[[np.ndarray], np.ndarray] = _copy) -> PendingPixels:
        fmt, gltype, dtype, channels = _FORMATS[kind]
        nbytes = width * height * channels * np.dtype(dtype).itemsize
        source = ctx.offFBO
        if ctx.offSamples and kind == "rgba":
            # what mjr_readPixels does: resolve the multisampled buffer into the single-sample one (the blit
            # releases the interpreter lock: on Mesa it is the resolve's work; errors are checked below)
            gld.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, ctx.offFBO)
            gld.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, ctx.offFBO_r)
            raw_blit_framebuffer(0, 0, width, height, 0, 0, width, height, GL.GL_COLOR_BUFFER_BIT, GL.GL_NEAREST)
            source = ctx.offFBO_r
        # the short calls keep the interpreter lock (gl_direct); the read itself (on Mesa it renders the
        # frame) and the blit release it
        gld.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, source)
        gld.glReadBuffer(GL.GL_COLOR_ATTACHMENT0)
        pbo = self._acquire(nbytes)
        gld.glBindBuffer(GL.GL_PIXEL_PACK_BUFFER, pbo)
        gld.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
        raw_read_pixels(0, 0, width, height, fmt, gltype, ctypes.c_void_p(0))
        if self._fences is None:
            self._fences = bool(GL.glFenceSync)
        fence = gld.glFenceSync(GL.GL_SYNC_GPU_COMMANDS_COMPLETE, 0) if self._fences else None
        gld.glBindBuffer(GL.GL_PIXEL_PACK_BUFFER, 0)
        restore_offscreen_bindings(ctx)   # MuJoCo's own bindings back
        gld.check(f"queuing a read of {kind} pixels")
        shape = (height, width, channels) if channels > 1 else (height, width)
        return PendingPixels(self, pbo, nbytes, shape, dtype, decode, fence)

    def _acquire(self, nbytes: int) -> int:
        free = self._free.get(nbytes)
        if free:
            return free.pop()
        pbo = int(GL.glGenBuffers(1))
        GL.glBindBuffer(GL.GL_PIXEL_PACK_BUFFER, pbo)
        GL.glBufferData(GL.GL_PIXEL_PACK_BUFFER, nbytes, None, GL.GL_STREAM_READ)
        GL.glBindBuffer(GL.GL_PIXEL_PACK_BUFFER, 0)
        self._all.append(pbo)
        return pbo

    def release(self, pbo: int, nbytes: int) -> None:
        self._free.setdefault(nbytes, []).append(pbo)

    def forget_framebuffers(self) -> None:
        """Drop what was learnt about framebuffers (call when they are remade: GL reuses their names)."""
        self._packed_depth.clear()

    def free(self) -> None:
        """Delete every buffer (the context must be current)."""
        if self._all:
            GL.glDeleteBuffers(len(self._all), np.array(self._all, dtype=np.uint32))
        self._all.clear()
        self._free.clear()


_SIGNALED = (GL.GL_ALREADY_SIGNALED, GL.GL_CONDITION_SATISFIED)


def wait_for_fence(fence) -> None:
    """Return once the GPU has passed ``fence`` (a ``glFenceSync`` of the current context), polling
    without blocking in the driver (:func:`graphsdg.render.polling.wait_until`)."""
    flags = [GL.GL_SYNC_FLUSH_COMMANDS_BIT]   # the first poll also submits the queued commands

    def passed() -> bool:
        status = gld.glClientWaitSync(fence, flags[0], 0)   # never blocks (timeout 0): keeps the interpreter lock
        if status == GL.GL_WAIT_FAILED:
            raise RuntimeError("glClientWaitSync failed while waiting for a pixel read to finish")
        flags[0] = 0
        return status in _SIGNALED

    wait_until(passed)


def codes_from_rgba(size: int) -> Callable[[np.ndarray], np.ndarray]:
    """The decoder of 24-bit id colours read as RGBA words: uint32 codes, any code at or above ``size``
    (nothing drawn has one; a driver that blends id colours can make one) clipped to ``size - 1``, which
    the code -> geom table keeps for the background, so every code indexes the table."""
    top = np.uint32(size - 1)
    return lambda rgba: np.minimum(rgba.view(np.uint32)[..., 0] & np.uint32(0xFFFFFF), top)


def code_bits(size: int) -> int:
    """The bits of id colour a read must keep for codes below ``size``: 8, 16, or 24 (all of RGB)."""
    return next(b for b in (8, 16) if size <= 1 << b) if size <= 1 << 16 else 24


def _is_depth32f_stencil8(fbo: int) -> bool:
    """Whether framebuffer ``fbo``'s depth attachment is 32-bit float depth with 8-bit stencil."""
    GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, fbo)
    ask = lambda p: int(GL.glGetFramebufferAttachmentParameteriv(  # noqa: E731
        GL.GL_READ_FRAMEBUFFER, GL.GL_DEPTH_ATTACHMENT, p))
    return (ask(GL.GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE) == 32 and
            ask(GL.GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE) == 8 and
            ask(GL.GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE) == GL.GL_FLOAT)
