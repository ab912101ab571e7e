"""Which EGL device renders: the one of the GPU a scheduler (Ray) assigned to this process.

MuJoCo picks its EGL device by ``MUJOCO_EGL_DEVICE_ID``, an index into
``eglQueryDevicesEXT``'s list, whose order need not match CUDA's, and NVIDIA's EGL
lists only the GPUs that ``CUDA_VISIBLE_DEVICES`` leaves visible. Ray restricts
``CUDA_VISIBLE_DEVICES`` to the assigned GPUs, so the assigned GPU is CUDA device 0
here; :func:`follow_assigned_gpu` finds the EGL device whose ``EGL_CUDA_DEVICE_NV``
attribute is that CUDA device and sets ``MUJOCO_EGL_DEVICE_ID`` to its index
(before the first GL context is made).
"""
from __future__ import annotations

import ctypes
import ctypes.util
import logging
import os
from typing import Sequence

log = logging.getLogger("graphsdg.render")
EGL_CUDA_DEVICE_NV = 0x323A


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


def follow_assigned_gpu(gpu_ids: Sequence) -> str | None:
    """Set ``MUJOCO_EGL_DEVICE_ID`` to the EGL device of the first assigned GPU; return the value set.

    Leaves a value the user set alone, and does nothing without assigned GPUs
    (rendering then uses whatever EGL offers, e.g. Mesa's llvmpipe).
    """
    if os.environ.get("MUJOCO_EGL_DEVICE_ID"):
        return os.environ["MUJOCO_EGL_DEVICE_ID"]
    if not gpu_ids:
        return None
    visible = [v for v in os.environ.get("CUDA_VISIBLE_DEVICES", "").split(",") if v.strip()]
    cuda_index = visible.index(str(gpu_ids[0])) if str(gpu_ids[0]) in visible else 0
    try:
        cuda_of = egl_cuda_devices()
    except OSError as exc:   # no usable libEGL
        log.warning("cannot list EGL devices (%s); rendering on EGL's default device", exc)
        return None
    if cuda_index in cuda_of:
        os.environ["MUJOCO_EGL_DEVICE_ID"] = str(cuda_of.index(cuda_index))
        return os.environ["MUJOCO_EGL_DEVICE_ID"]
    log.warning("no EGL device reports CUDA device %d (EGL devices: %s); rendering on EGL's default device",
                cuda_index, cuda_of)
    return None
