"""Live sync of a gprim's pose and scale into its compiled geom.

A gprim with its own mocap body moves by a write into ``mocap_pos`` /
``mocap_quat``; a scale edit resizes an implicit primitive in place
(:func:`graphsdg.sim.gprims.resize_primitive`) or rescales a visual mesh's
vertices in place (:mod:`graphsdg.sim.mesh_scaling`). A shape moved or rescaled
inside its rigid body, or a colliding mesh rescaled, changes the body's mass
distribution or collision hulls: :class:`NeedsRecompile`.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.sim.compiled_scene import CompiledScene, GeomBinding
from graphsdg.sim.gprims import resize_primitive
from graphsdg.sim.needs_recompile import NeedsRecompile
from graphsdg.stage.xform import world_matrix
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz


def sync_geom_pose(c: CompiledScene, stage: Usd.Stage, prim: Usd.Prim, g: GeomBinding, cache: UsdGeom.XformCache,
                   aspects: set[str], rescale_mesh: Callable[[int, np.ndarray, np.ndarray], None]) -> None:
    """A pose, scale or shape edit of gprim ``prim`` written into its geom ``g``.

    ``rescale_mesh(geom_id, old_scale, new_scale)`` rescales a visual mesh in place
    (:meth:`graphsdg.sim.scene.SimScene.rescale_mesh`, which tells renderers).
    """
    d = c.data
    m_world = world_matrix(prim, cache)
    if g.rigid_root is None:
        t, r, scale = decompose(m_world)
        d.mocap_pos[g.mocap_id] = t
        d.mocap_quat[g.mocap_id] = matrix_to_quat_wxyz(r)
    else:
        root = stage.GetPrimAtPath(g.rigid_root)
        t_root, r_root, _ = decompose(world_matrix(root, cache))
        m_root = np.eye(4)
        m_root[:3, :3] = r_root.T
        m_root[3, :3] = t_root
        t, r, scale = decompose(m_world @ np.linalg.inv(m_root))
        relative = np.eye(4)
        relative[:3, :3] = r.T
        relative[3, :3] = t
        if g.relative is not None and not np.allclose(relative, g.relative, atol=1e-9):
            raise NeedsRecompile   # a shape moved inside its rigid body: new mass distribution
    rescaled = not np.allclose(scale, g.scale, rtol=1e-9, atol=1e-12)
    if g.type_name in ("Mesh", "Cone") and g.rigid_root is None and "shape" not in aspects:
        if rescaled:
            if np.any(np.abs(scale) < 1e-9) or g.path in c.collider_paths:
                raise NeedsRecompile   # colliding meshes carry hulls and inertia
            rescale_mesh(g.geom_id, g.scale, scale)
            g.scale = scale
    elif g.type_name in ("Mesh", "Cone") or g.rigid_root is not None:
        if "shape" in aspects or rescaled:
            raise NeedsRecompile   # vertices (or the body's inertia) change
    elif "shape" in aspects or not np.allclose(scale, g.scale, rtol=1e-9, atol=1e-12):
        resize_primitive(c.model, prim, g, scale)
