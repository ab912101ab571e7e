"""Which EGL device renders: the GPU a scheduler gave this process. The scheduler is Ray or ``graphsdg bench
--gpus``.

MuJoCo picks its EGL device by ``MUJOCO_EGL_DEVICE_ID``: older releases as an index into
``eglQueryDevicesEXT``'s list, whose order need not match CUDA's, MuJoCo 4 as a position among the GPUs that
``CUDA_VISIBLE_DEVICES`` shows. A scheduler restricts ``CUDA_VISIBLE_DEVICES`` to the GPU it gives a process
(Ray for its actors, ``graphsdg bench --gpus`` for its processes), so that GPU is CUDA device 0 there;
:func:`bind_visible_gpu` finds the EGL device that is that GPU (by the ``EGL_CUDA_DEVICE_NV`` attribute) and
sets ``MUJOCO_EGL_DEVICE_ID`` as the installed MuJoCo reads it, before the first GL context is made:
:func:`follow_assigned_gpu` in a Ray actor, :func:`bind_requested_gpu` at import in a process started with
:data:`BIND_ENV`. A GPU that EGL cannot see is an error (:class:`EglDeviceError`), not a silent fall back to
another device or to Mesa's software rasteriser.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import logging
import os
from typing import Sequence

log = logging.getLogger("graphsdg.render")
EGL_CUDA_DEVICE_NV = 0x323A
#: set by a parent process with ``CUDA_VISIBLE_DEVICES`` (``graphsdg bench --gpus``): the GPU, by its nvidia-smi
#: index, that this process renders on; read at import by :func:`bind_requested_gpu`
BIND_ENV = "GRAPHSDG_GPU"


def egl_cuda_devices() -> list[int | None]:
    """For each EGL device (in ``eglQueryDevicesEXT`` order) its CUDA device index, or None (not NVIDIA)."""
    name = ctypes.util.find_library("EGL")
    if name is None:
        return []
    egl = ctypes.CDLL(name)
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    query_ptr = egl.eglGetProcAddress(b"eglQueryDevicesEXT")
    attrib_ptr = egl.eglGetProcAddress(b"eglQueryDeviceAttribEXT")
    if not query_ptr:
        return []
    query = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_int, ctypes.POINTER(ctypes.c_void_p),
                             ctypes.POINTER(ctypes.c_int))(query_ptr)
    attrib = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_void_p, ctypes.c_int,
                              ctypes.POINTER(ctypes.c_long))(attrib_ptr) if attrib_ptr else None
    devices = (ctypes.c_void_p * 32)()
    count = ctypes.c_int(0)
    if not query(32, devices, ctypes.byref(count)):
        return []
    out: list[int | None] = []
    for i in range(count.value):
        value = ctypes.c_long(-1)
        ok = attrib is not None and attrib(devices[i], EGL_CUDA_DEVICE_NV, ctypes.byref(value))
        out.append(int(value.value) if ok and value.value >= 0 else None)
    return out


class EglDeviceError(RuntimeError):
    """The GPU a process was given is not among EGL's devices (the message names both counts)."""


def egl_index_of(cuda_ids: Sequence[int | None], physical: int) -> int | None:
    """The position in EGL's device list of physical GPU ``physical`` when ``CUDA_VISIBLE_DEVICES`` shows it
    alone; ``cuda_ids`` is :func:`egl_cuda_devices`. None when no device is it.

    NVIDIA's EGL reports each device's CUDA number; drivers differ in whether that number counts all GPUs
    (then GPU ``physical`` reports ``physical``) or only the ones this process's ``CUDA_VISIBLE_DEVICES``
    shows (then it reports 0, and the hidden ones report none). The first reading is tried first, as
    MuJoCo 4 does.

    Example:
        >>> egl_index_of([0, 1, 2, 3], 2), egl_index_of([None, None, 0, None], 2), egl_index_of([None], 1)
        (2, 2, None)
    """
    if physical in cuda_ids:
        return list(cuda_ids).index(physical)
    if 0 in cuda_ids:
        return list(cuda_ids).index(0)
    return None


def _mujoco_counts_visible_devices() -> bool:
    """Whether the installed MuJoCo reads ``MUJOCO_EGL_DEVICE_ID`` as a position among the GPUs
    ``CUDA_VISIBLE_DEVICES`` shows (MuJoCo 4) rather than in EGL's own list; told from its source, since
    importing ``mujoco.egl`` may already open a display (older releases did)."""
    import importlib.util
    try:
        spec = importlib.util.find_spec("mujoco.egl")
    except ImportError:
        return False
    if spec is None or not spec.origin:
        return False
    try:
        with open(spec.origin, encoding="utf-8") as f:
            return "_select_egl_device" in f.read()
    except OSError:
        return False


def bind_visible_gpu(physical: int, environ=os.environ, cuda_ids: Sequence[int | None] | None = None,
                     host_has_gpu: bool | None = None) -> str | None:
    """Point MuJoCo's EGL at physical GPU ``physical``, the one ``CUDA_VISIBLE_DEVICES`` shows this
    process, before the first GL context: set ``MUJOCO_EGL_DEVICE_ID`` as the installed MuJoCo reads it
    (MuJoCo 4: 0, the first GPU CUDA shows; older: the position in EGL's list); return the value set.

    A ``MUJOCO_EGL_DEVICE_ID`` already set is kept. On a machine without an NVIDIA GPU (Ray's GPUs can be
    logical ones, as in tests) it logs and leaves EGL's default device.

    Raises:
        EglDeviceError: the machine has NVIDIA GPUs but none of EGL's devices is GPU ``physical``.
    """
    if environ.get("MUJOCO_EGL_DEVICE_ID"):
        return environ["MUJOCO_EGL_DEVICE_ID"]
    if cuda_ids is None:
        try:
            cuda_ids = egl_cuda_devices()
        except OSError as exc:   # no usable libEGL: the first GL context will say so
            log.warning("cannot list EGL devices (%s); rendering on EGL's default device", exc)
            return None
    index = egl_index_of(cuda_ids, physical)
    if index is None:
        if host_has_gpu is None:
            host_has_gpu = any(os.path.exists(f"/dev/nvidia{i}") for i in range(64))
        if not host_has_gpu and not any(c is not None for c in cuda_ids):
            log.warning("GPU %s was assigned but this machine has no NVIDIA GPU; rendering on EGL's default "
                        "device", physical)
            return None
        nvidia = sum(c is not None for c in cuda_ids)
        raise EglDeviceError(
            f"GPU {physical} (CUDA_VISIBLE_DEVICES={environ.get('CUDA_VISIBLE_DEVICES')!r}) is not among EGL's "
            f"{len(cuda_ids)} device(s), of which {nvidia} NVIDIA (their CUDA devices: {list(cuda_ids)}); the "
            f"classic rasteriser cannot draw on it: check the NVIDIA EGL vendor library "
            f"(__EGL_VENDOR_LIBRARY_FILENAMES)")
    value = "0" if _mujoco_counts_visible_devices() else str(index)
    environ["MUJOCO_EGL_DEVICE_ID"] = value
    return value


def bind_requested_gpu(environ=os.environ) -> str | None:
    """At import: :func:`bind_visible_gpu` for the GPU a parent process named in ``GRAPHSDG_GPU``
    (:data:`BIND_ENV`, set with ``CUDA_VISIBLE_DEVICES`` by ``graphsdg bench --gpus``); nothing without it or
    off EGL."""
    requested = environ.get(BIND_ENV, "").strip()
    if not requested or environ.get("MUJOCO_GL", "egl").lower() != "egl":
        return None
    if not requested.isdigit():
        raise EglDeviceError(f"{BIND_ENV}={requested!r} must be a GPU's index (as nvidia-smi numbers them)")
    return bind_visible_gpu(int(requested), environ)


def follow_assigned_gpu(gpu_ids: Sequence) -> str | None:
    """Point EGL at the first GPU a scheduler (Ray) assigned and showed through ``CUDA_VISIBLE_DEVICES``;
    return the ``MUJOCO_EGL_DEVICE_ID`` set (None without assigned GPUs: EGL's default device, e.g. Mesa's
    llvmpipe). See :func:`bind_visible_gpu`."""
    if os.environ.get("MUJOCO_EGL_DEVICE_ID"):
        return os.environ["MUJOCO_EGL_DEVICE_ID"]
    if not gpu_ids:
        return None
    first = str(gpu_ids[0])
    if not first.isdigit():
        log.warning("assigned GPU %r is not an index; rendering on EGL's default device", first)
        return None
    return bind_visible_gpu(int(first))
