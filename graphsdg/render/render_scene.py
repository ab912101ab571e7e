"""The render scene: what the renderers draw of one simulation, kept beside its MuJoCo model.

Both backends (the classic rasteriser, the pbr ray tracer) draw a :class:`RenderScene`: its
:attr:`~RenderScene.sim` gives the model and data; the scene itself keeps what renderers need that the
simulation does not:

* the offscreen framebuffer size and the pbr backend's camera count, which the next compile gives the model
  (:class:`~graphsdg.sim.render_link.DrawNeeds`). A renderer sizes the buffer to what it draws
  (:meth:`RenderScene.require_offscreen`), as MuJoCo's ``Renderer`` owns its width and height;
* the records of model data changed in place, so renderers keep their uploaded copies true without a
  re-upload: textures and meshes to upload again, each rescaled mesh's 3x3 map from its compiled vertices
  (:attr:`~RenderScene.mesh_maps`), and per-mesh change counts (:attr:`~RenderScene.mesh_stamps`,
  :attr:`~RenderScene.mesh_reshapes`) that the pbr backend and the ray-cast sensors compare;
* cameras posed with write-to-fabric (:class:`~graphsdg.sim.pose_writes.camera_poses.CameraPoses`) and
  values read from prims until the stage edits them (a camera's lens);
* :attr:`~RenderScene.version`, which changes whenever renderers must rebuild what they made from the model
  (a recompile, a larger offscreen buffer).

The scene attaches to its :class:`~graphsdg.sim.scene.SimScene` as its
:class:`~graphsdg.sim.render_link.RenderLink` (the simulation tells it of in-place changes and drained
stage edits) and hears of recompiles through :meth:`SimScene.subscribe_recompile`.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> _ = rep.stage.new_stage()
    >>> scene = runtime().render_scene
    >>> scene.require_offscreen(320, 240); scene.offscreen
    (320, 240)
    >>> scene.sim.model.vis.global_.offwidth
    320
"""
from __future__ import annotations

import itertools
from typing import Callable, Iterable

import numpy as np

from graphsdg.sim.compiled_scene import CompiledScene
from graphsdg.sim.mesh_scaling import MeshMaps
from graphsdg.sim.pose_writes.camera_poses import CameraPoses
from graphsdg.sim.render_link import DrawNeeds, RenderLink
from graphsdg.sim.scene import SimScene
from graphsdg.stage.changes import ChangeSet
from graphsdg.stage.read_cache import PrimReadCache

# one process-wide counter: a renderer keyed on (model, version) never mistakes a new scene for an old one
_versions = itertools.count()


class RenderScene(RenderLink):
    """What the renderers draw of one :class:`SimScene` (see the module docstring).

    ``pbr_draws``: asked at each compile, whether the pbr backend draws this process's models;
    ``render_products``: how many render products there are, so that a model compiled for the pbr backend has
    a camera for each when it draws them in one launch (no recompile in the middle of a step).
    """

    def __init__(self, sim: SimScene, pbr_draws: Callable[[], bool] = lambda: False,
                 render_products: Callable[[], int] = lambda: 1) -> None:
        self.sim = sim
        self._pbr_draws = pbr_draws
        self._render_products = render_products
        self.offscreen = (64, 64)
        self.pbr_cameras = 1                # cameras compiled for the pbr backend (render products per launch)
        self.version = next(_versions)
        self.textures_to_upload: set[int] = set()
        self.meshes_to_upload: set[int] = set()   # meshes whose vertices moved (deformables)
        # mesh id -> 3x3 map from the compiled vertices to the current ones, for meshes rescaled in
        # place since the compile; renderers draw the copy they uploaded through it (no re-upload)
        self.mesh_maps = MeshMaps()
        # per mesh: the count of vertex changes since the compile (rescales, deformables), so renderers that
        # keep their own copy (the pbr backend's BVHs) find the changed meshes with one comparison
        self.mesh_stamps = np.zeros(0, dtype=np.int64)
        # per mesh: the count of those changes that mesh_maps does not describe (deformables): a renderer
        # that draws its copy through the maps must take new vertices only for these
        self.mesh_reshapes = np.zeros(0, dtype=np.int64)
        self.camera_poses = CameraPoses(sim.world_transforms.parent_world)   # cameras posed with write-to-fabric
        self.prim_reads = PrimReadCache()   # values read from prims until the stage edits them
        sim.render_link = self
        sim.subscribe_recompile(self._recompiled)
        if sim.compiled is not None:
            self._recompiled(sim.compiled)

    # ---- sizes ---------------------------------------------------------
    def require_offscreen(self, width: int, height: int) -> None:
        """Make MuJoCo's offscreen buffer at least ``width`` x ``height`` (renderers rebuild their contexts if
        it grows)."""
        w, h = max(self.offscreen[0], width), max(self.offscreen[1], height)
        if (w, h) != self.offscreen:
            self.offscreen = (w, h)
            compiled = self.sim.compiled
            if compiled is not None:
                compiled.model.vis.global_.offwidth = w
                compiled.model.vis.global_.offheight = h
                self.version = next(_versions)

    def require_pbr_cameras(self, count: int) -> None:
        """Compile at least ``count`` cameras for the pbr backend, to draw that many render products in one
        launch (recompiles, keeping the state, if they grow and the model has them too few: only when products
        were created after the compile, since each compile gives every render product one)."""
        if count > self.pbr_cameras:
            self.pbr_cameras = count
            if self.sim.compiled is not None:
                self.sim.recompile(keep_state=True)

    # ---- what the simulation tells (RenderLink) ------------------------
    def draw_needs(self) -> DrawNeeds:
        pbr = self._pbr_draws()
        if pbr:
            self.pbr_cameras = max(self.pbr_cameras, int(self._render_products()))
        return DrawNeeds(self.offscreen, pbr, self.pbr_cameras)

    def _recompiled(self, compiled: CompiledScene) -> None:
        """A new model: renderers rebuild from it, and it holds no in-place changes yet."""
        self.version = next(_versions)
        self.textures_to_upload.clear()
        self.mesh_maps.clear()
        nmesh = compiled.model.nmesh
        self.mesh_stamps = np.zeros(nmesh, dtype=np.int64)
        self.mesh_reshapes = np.zeros(nmesh, dtype=np.int64)
        self.meshes_to_upload.clear()

    def stage_synced(self, changes: ChangeSet) -> None:
        self.camera_poses.forget_edited(changes)
        self.prim_reads.forget(changes)

    def meshes_rescaled(self, mesh_ids: np.ndarray, linears: np.ndarray, distinct: bool = False) -> None:
        self.mesh_maps.compose(mesh_ids, linears, distinct=distinct)
        self.stamp_meshes(mesh_ids, mapped=True, distinct=distinct)

    def meshes_reshaped(self, mesh_ids: set[int]) -> None:
        self.meshes_to_upload.update(mesh_ids)
        if self.meshes_to_upload:
            self.stamp_meshes(self.meshes_to_upload)

    def textures_changed(self, texture_ids: Iterable[int]) -> None:
        self.textures_to_upload.update(texture_ids)

    def stamp_meshes(self, mesh_ids, mapped: bool = False, distinct: bool = False) -> None:
        """Record that meshes ``mesh_ids``' vertices changed (see :attr:`mesh_stamps`); ``mapped``: by a linear
        map composed into :attr:`mesh_maps` (else :attr:`mesh_reshapes` counts the change too); ``distinct``:
        no id repeats (one indexed addition instead of ``np.add.at``)."""
        nmesh = self.sim.model.nmesh
        if self.mesh_stamps.shape[0] != nmesh:
            self.mesh_stamps = np.zeros(nmesh, dtype=np.int64)
        if self.mesh_reshapes.shape[0] != nmesh:
            self.mesh_reshapes = np.zeros(nmesh, dtype=np.int64)
        ids = np.asarray(list(mesh_ids) if isinstance(mesh_ids, set) else mesh_ids, dtype=np.int64)
        for counts in (self.mesh_stamps,) if mapped else (self.mesh_stamps, self.mesh_reshapes):
            if distinct:
                counts[ids] += 1
            else:
                np.add.at(counts, ids, 1)


def render_scene_of(sim: SimScene) -> RenderScene:
    """The render scene attached to ``sim`` (for readers that are handed the simulation: the ray-cast sensors)."""
    link = sim.render_link
    if not isinstance(link, RenderScene):
        raise RuntimeError("no render scene draws this simulation; make one with RenderScene(sim) "
                           "(graphsdg.engine.runtime.runtime().render_scene is the process's)")
    return link


__all__ = ["RenderScene", "render_scene_of"]
