"""GL and EGL entry points for short calls, called without releasing the interpreter lock.

PyOpenGL calls GL through ctypes, which releases the interpreter lock around every
call, then checks ``glGetError`` (a second call). For a call that returns at once
(a bind, a state change, a fence poll) the release is a hand-off, not a help: a
writer thread running Python takes the lock, and the render thread waits until
that thread gives it back, up to the interpreter's switch interval. A frame makes
dozens of such calls (readback, id framebuffer, one-colour sky); docs/performance.md
("Short GL calls and the interpreter lock") has the measurements.

The functions here are the same driver entry points (resolved from the library
PyOpenGL loaded), called through ``ctypes.PYFUNCTYPE``, which keeps the lock, and
without an error check per call: callers that need one call :func:`check` after a
sequence. Calls that make the driver work for long (``glReadPixels``, which renders
the frame on Mesa's llvmpipe; blits) stay on PyOpenGL and release the lock.

Example (inside a current GL context)::

    from graphsdg.render import gl_direct as gld
    gld.glBindBuffer(GL.GL_PIXEL_PACK_BUFFER, 0)
    gld.check("binding the pixel buffer")
"""
from __future__ import annotations

import ctypes
from typing import Any, Callable

from OpenGL import GL

_u, _i, _f, _d = ctypes.c_uint, ctypes.c_int, ctypes.c_float, ctypes.c_double
_b, _p, _sz, _u64 = ctypes.c_ubyte, ctypes.c_void_p, ctypes.c_ssize_t, ctypes.c_uint64

# name -> (result type, argument types); GLenum/GLbitfield/GLuint are unsigned int, GLboolean unsigned char
_SIGNATURES: dict[str, tuple[Any, tuple]] = {
    "glGetError": (_u, ()),
    "glBindFramebuffer": (None, (_u, _u)),
    "glBindBuffer": (None, (_u, _u)),
    "glReadBuffer": (None, (_u,)),
    "glDrawBuffer": (None, (_u,)),
    "glPixelStorei": (None, (_u, _i)),
    "glFenceSync": (_p, (_u, _u)),
    "glClientWaitSync": (_u, (_p, _u, _u64)),
    "glDeleteSync": (None, (_p,)),
    "glMapBufferRange": (_p, (_u, _sz, _sz, _u)),
    "glUnmapBuffer": (_b, (_u,)),
    "glPushAttrib": (None, (_u,)),
    "glPopAttrib": (None, ()),
    "glViewport": (None, (_i, _i, _i, _i)),
    "glDepthRange": (None, (_d, _d)),
    "glEnable": (None, (_u,)),
    "glDisable": (None, (_u,)),
    "glDepthFunc": (None, (_u,)),
    "glDepthMask": (None, (_b,)),
    "glPolygonMode": (None, (_u, _u)),
    "glColorMask": (None, (_b, _b, _b, _b)),
    "glMatrixMode": (None, (_u,)),
    "glPushMatrix": (None, ()),
    "glPopMatrix": (None, ()),
    "glLoadIdentity": (None, ()),
    "glColor4f": (None, (_f, _f, _f, _f)),
    "glRectf": (None, (_f, _f, _f, _f)),
}
_resolved: dict[str, Callable[..., Any]] = {}


def _address(name: str) -> int:
    """The entry point ``name`` of the GL library PyOpenGL uses (its export, else the platform's lookup)."""
    from OpenGL import platform
    library = platform.PLATFORM.GL
    try:
        return int(ctypes.cast(getattr(library, name), ctypes.c_void_p).value or 0)
    except AttributeError:
        pass
    pointer = platform.PLATFORM.getExtensionProcedure(name.encode())
    if not pointer:
        raise RuntimeError(f"the GL library has no entry point {name}")
    return int(pointer)


def _function(name: str) -> Callable[..., Any]:
    found = _resolved.get(name)
    if found is None:
        restype, argtypes = _SIGNATURES[name]
        found = _resolved[name] = ctypes.PYFUNCTYPE(restype, *argtypes)(_address(name))
        globals()[name] = found   # later ``gl_direct.<name>`` lookups find it without __getattr__
    return found


def __getattr__(name: str) -> Callable[..., Any]:
    """``gl_direct.glBindBuffer`` etc.: resolved on first use (a GL library must be loaded by then)."""
    if name in _SIGNATURES:
        return _function(name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}; direct entry points: "
                         f"{', '.join(sorted(_SIGNATURES))}")


def check(what: str) -> None:
    """Raise ``GL.GLError``-like ``RuntimeError`` naming ``what`` if GL recorded an error since the last check."""
    error = _function("glGetError")()
    if error != GL.GL_NO_ERROR:
        raise RuntimeError(f"GL error 0x{error:04x} while {what}")


_egl_current: Callable[[], int | None] | None = None


def egl_current_context() -> int | None:
    """The address of this thread's current EGL context (None when none), keeping the interpreter lock."""
    global _egl_current
    if _egl_current is None:
        from OpenGL import platform
        address = ctypes.cast(platform.PLATFORM.EGL.eglGetCurrentContext, ctypes.c_void_p).value
        _egl_current = ctypes.PYFUNCTYPE(ctypes.c_void_p)(address)
    return _egl_current()
