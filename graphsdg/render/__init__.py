"""Rendering: headless GL platform choice, cameras, render products, render passes.

This package's ``__init__`` imports nothing heavy: :mod:`gl_platform` must run
before the first ``import mujoco`` so MuJoCo picks EGL on headless machines.
"""
