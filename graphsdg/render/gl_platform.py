"""Choose MuJoCo's OpenGL platform before MuJoCo is imported.

MuJoCo reads ``MUJOCO_GL`` once, at import. graphsdg renders offscreen only, so
on Linux it defaults to EGL: Mesa's llvmpipe on CPU machines, the NVIDIA driver
on GPU machines (``MUJOCO_EGL_DEVICE_ID`` picks a GPU; a process started for one GPU, with
``GRAPHSDG_GPU``, is pointed at it here). A value the user set is kept.
"""
from __future__ import annotations

import os
import platform


def select_gl_platform() -> str:
    """Set ``MUJOCO_GL`` (and PyOpenGL's platform) for headless rendering; return the choice."""
    choice = os.environ.get("MUJOCO_GL", "").strip().lower()
    if not choice and platform.system() == "Linux":
        choice = "egl"
        os.environ["MUJOCO_GL"] = choice
    if choice in ("egl", "osmesa") and not os.environ.get("PYOPENGL_PLATFORM"):
        os.environ["PYOPENGL_PLATFORM"] = choice
    if choice == "egl" and os.environ.get("GRAPHSDG_GPU"):   # a parent gave this process one GPU (bench --gpus)
        from graphsdg.render.egl_device import bind_requested_gpu
        bind_requested_gpu()
    return choice or "default"
