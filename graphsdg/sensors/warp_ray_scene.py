"""A MuJoCo scene on a GPU, in world coordinates, for casting rays.

MuJoCo Warp's ``rays`` walks a BVH of geoms and, for each mesh geom whose box a ray crosses, a second BVH of
that mesh's triangles in the mesh's own frame. Where many mesh assets overlap (a pile of thousands), a ray
crosses dozens of mesh boxes before it finds its first surface, and each costs a whole mesh query. This scene
keeps every held mesh geom's triangles in world coordinates under one BVH of triangle boxes (refit when geoms
move) and the other geoms (boxes, spheres, capsules, cylinders, ellipsoids) in a BVH of their bounding
spheres, intersected with MuJoCo Warp's own analytic primitive tests; planes are tested directly. Hits follow
``mj_ray``'s rules: a mesh triangle counts only from its front (a back face, or the back of a two-sided
surface, is looked through), geoms not enabled are skipped, and a hit farther than the cutoff is a miss.

Models with height fields, SDF geoms or flexes are not covered (:func:`covers` says so); the caster uses
MuJoCo Warp's ``rays`` for them.

Example:
    >>> scene = WorldRayScene(model, held, "cuda:0")                  # doctest: +SKIP
    >>> scene.pose(model, data.geom_xpos, data.geom_xmat)             # doctest: +SKIP
    >>> scene.enable(flags)                                           # doctest: +SKIP
    >>> dist, geom, normal = scene.cast(origins, directions, cutoff)  # doctest: +SKIP
"""
from __future__ import annotations

import mujoco
import numpy as np
import warp as wp
from mujoco_warp._src.ray import ray_geom   # MuJoCo Warp's analytic primitive tests (pinned in the gpu extra)

MESH = int(mujoco.mjtGeom.mjGEOM_MESH)
PLANE = int(mujoco.mjtGeom.mjGEOM_PLANE)
UNCOVERED_TYPES = (int(mujoco.mjtGeom.mjGEOM_HFIELD), int(mujoco.mjtGeom.mjGEOM_SDF))
TRIANGLE_BVH = "sah"           # built once a model (the best tree to walk), refit as geoms move


def covers(model: mujoco.MjModel, drawn: np.ndarray) -> bool:
    """Whether the geoms of ``drawn`` (a boolean per geom) are all primitives or meshes, and no flex is drawn."""
    types = np.asarray(model.geom_type)[drawn]
    return not np.isin(types, UNCOVERED_TYPES).any() and model.nflex == 0


@wp.kernel
def _world_vertices(local: wp.array(dtype=wp.vec3), vert_geom: wp.array(dtype=wp.int32),
                    xpos: wp.array(dtype=wp.vec3), xmat: wp.array(dtype=wp.mat33), world: wp.array(dtype=wp.vec3)):
    i = wp.tid()
    g = vert_geom[i]
    world[i] = xpos[g] + xmat[g] @ local[i]


@wp.kernel
def _sphere_bounds(geoms: wp.array(dtype=wp.int32), xpos: wp.array(dtype=wp.vec3), rbound: wp.array(dtype=float),
                   lower: wp.array(dtype=wp.vec3), upper: wp.array(dtype=wp.vec3)):
    i = wp.tid()
    g = geoms[i]
    r = rbound[g]
    lower[i] = xpos[g] - wp.vec3(r, r, r)
    upper[i] = xpos[g] + wp.vec3(r, r, r)


@wp.kernel
def _triangle_bounds(world: wp.array(dtype=wp.vec3), faces: wp.array(dtype=wp.vec3i),
                     lower: wp.array(dtype=wp.vec3), upper: wp.array(dtype=wp.vec3)):
    f = wp.tid()
    face = faces[f]
    a, b, c = world[face[0]], world[face[1]], world[face[2]]
    lower[f] = wp.min(a, wp.min(b, c))
    upper[f] = wp.max(a, wp.max(b, c))


@wp.func
def _front_face_hit(a: wp.vec3, b: wp.vec3, c: wp.vec3, pnt: wp.vec3, vec: wp.vec3):
    """(distance, unit normal) where the ray meets triangle abc from its front (counter-clockwise side), else
    distance -1 (Moller-Trumbore with the back faces culled)."""
    e1 = b - a
    e2 = c - a
    pvec = wp.cross(vec, e2)
    det = wp.dot(e1, pvec)          # -dot(vec, e1 x e2): positive when the ray meets the front
    if det <= 0.0:
        return float(-1.0), wp.vec3()
    inv = 1.0 / det
    tvec = pnt - a
    u = wp.dot(tvec, pvec) * inv
    if u < 0.0 or u > 1.0:
        return float(-1.0), wp.vec3()
    qvec = wp.cross(tvec, e1)
    v = wp.dot(vec, qvec) * inv
    if v < 0.0 or u + v > 1.0:
        return float(-1.0), wp.vec3()
    t = wp.dot(e2, qvec) * inv
    if t < 0.0:
        return float(-1.0), wp.vec3()
    return t, wp.normalize(wp.cross(e1, e2))


@wp.func
def _primitive_hit(g: int, enabled: wp.array(dtype=wp.int32), geom_type: wp.array(dtype=wp.int32),
                   geom_size: wp.array(dtype=wp.vec3), xpos: wp.array(dtype=wp.vec3), xmat: wp.array(dtype=wp.mat33),
                   pnt: wp.vec3, vec: wp.vec3):
    """(distance, normal) where the ray meets primitive geom ``g`` (MuJoCo Warp's test), distance -1 if it misses
    or ``g`` is not enabled."""
    if enabled[g] == 0:
        return float(-1.0), wp.vec3()
    return ray_geom(xpos[g], xmat[g], geom_size[g], pnt, vec, geom_type[g])


@wp.kernel
def _cast(tris: wp.uint64, has_tris: int, world: wp.array(dtype=wp.vec3), faces: wp.array(dtype=wp.vec3i),
          face_geom: wp.array(dtype=wp.int32),
          bvh: wp.uint64, has_bvh: int, bvh_geoms: wp.array(dtype=wp.int32), planes: wp.array(dtype=wp.int32),
          geom_type: wp.array(dtype=wp.int32), geom_size: wp.array(dtype=wp.vec3), xpos: wp.array(dtype=wp.vec3),
          xmat: wp.array(dtype=wp.mat33), enabled: wp.array(dtype=wp.int32),
          pnt: wp.array(dtype=wp.vec3), vec: wp.array(dtype=wp.vec3), cutoff: float,
          dist_out: wp.array(dtype=float), geom_out: wp.array(dtype=wp.int32), normal_out: wp.array(dtype=wp.vec3)):
    i = wp.tid()
    p = pnt[i]
    d = vec[i]
    best = cutoff
    best_geom = int(-1)
    best_normal = wp.vec3()
    # planes and primitives first: their cheap tests often shorten the ray before the triangles are walked
    for k in range(planes.shape[0]):
        g = planes[k]
        t, n = _primitive_hit(g, enabled, geom_type, geom_size, xpos, xmat, p, d)
        if t >= 0.0 and t < best:
            best = t
            best_geom = g
            best_normal = n
    if has_bvh != 0:
        query = wp.bvh_query_ray(bvh, p, d)
        item = int(0)
        while wp.bvh_query_next(query, item, best):
            g = bvh_geoms[item]
            t, n = _primitive_hit(g, enabled, geom_type, geom_size, xpos, xmat, p, d)
            if t >= 0.0 and t < best:
                best = t
                best_geom = g
                best_normal = n
    if has_tris != 0:
        query = wp.bvh_query_ray(tris, p, d)
        f = int(0)
        while wp.bvh_query_next(query, f, best):
            g = face_geom[f]
            if enabled[g] != 0:
                face = faces[f]
                t, n = _front_face_hit(world[face[0]], world[face[1]], world[face[2]], p, d)
                if t >= 0.0 and t < best:
                    best = t
                    best_geom = g
                    best_normal = n
    if best_geom < 0:
        dist_out[i] = -1.0
    else:
        dist_out[i] = best
    geom_out[i] = best_geom
    normal_out[i] = best_normal


class WorldRayScene:
    """The drawn geoms of one compiled model on a Warp device, posed for casting (module docstring)."""

    def __init__(self, model: mujoco.MjModel, drawn: np.ndarray, device: str) -> None:
        """Hold the geoms flagged in ``drawn`` (one flag per geom) of ``model`` on ``device``."""
        self.device = device
        self.held = np.asarray(drawn, dtype=bool)     # the geoms this scene can hit
        geoms = np.flatnonzero(drawn)
        types = np.asarray(model.geom_type)[geoms]
        meshes = geoms[types == MESH]
        self._planes = geoms[types == PLANE].astype(np.int32)
        self._primitives = geoms[(types != MESH) & (types != PLANE)].astype(np.int32)
        self._vert_src, vert_geom, faces, face_geom = self._triangles(model, meshes)
        self._poses: tuple[np.ndarray, np.ndarray] | None = None
        self._sizes: np.ndarray | None = None
        self._enabled: np.ndarray | None = None
        with wp.ScopedDevice(device):
            ngeom = max(model.ngeom, 1)
            self._type = wp.array(np.asarray(model.geom_type, dtype=np.int32), dtype=wp.int32)
            self._size = wp.zeros(ngeom, dtype=wp.vec3)
            self._rbound = wp.zeros(ngeom, dtype=float)
            self._xpos = wp.zeros(ngeom, dtype=wp.vec3)
            self._xmat = wp.zeros(ngeom, dtype=wp.mat33)
            self._enabled_dev = wp.zeros(ngeom, dtype=wp.int32)
            self._plane_dev = wp.array(self._planes, dtype=wp.int32)
            self._bvh_geoms = wp.array(self._primitives if len(self._primitives) else np.zeros(1, np.int32),
                                       dtype=wp.int32)
            self._vert_geom = wp.array(vert_geom, dtype=wp.int32)
            self._face_geom = wp.array(face_geom if len(face_geom) else np.zeros(1, np.int32), dtype=wp.int32)
            self._local = wp.array(self._local_vertices(model), dtype=wp.vec3)
            self._tris = self._bvh = None
            self._faces = faces
            nface = max(len(faces), 1)
            self._face_dev = wp.array(faces if len(faces) else np.zeros((1, 3), np.int32), dtype=wp.vec3i)
            self._world = wp.zeros(max(len(self._vert_src), 1), dtype=wp.vec3)
            self._tri_lower = wp.zeros(nface, dtype=wp.vec3)
            self._tri_upper = wp.zeros(nface, dtype=wp.vec3)
            self._lower = wp.zeros(max(len(self._primitives), 1), dtype=wp.vec3)
            self._upper = wp.zeros(max(len(self._primitives), 1), dtype=wp.vec3)

    @staticmethod
    def _triangles(model: mujoco.MjModel, meshes: np.ndarray):
        """(source vertex of each world vertex, its geom, the world faces, each face's geom) of ``meshes``."""
        vert_src, vert_geom, faces, face_geom, base = [], [], [], [], 0
        for g in meshes.tolist():
            mesh = int(model.geom_dataid[g])
            v0, nv = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
            f0, nf = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
            if not nv or not nf:
                continue
            vert_src.append(np.arange(v0, v0 + nv))
            vert_geom.append(np.full(nv, g, dtype=np.int32))
            faces.append(np.asarray(model.mesh_face[f0:f0 + nf], dtype=np.int32) + base)
            face_geom.append(np.full(nf, g, dtype=np.int32))
            base += nv
        if not faces:
            empty = np.zeros(0, dtype=np.int32)
            return np.zeros(0, dtype=np.int64), empty, np.zeros((0, 3), np.int32), empty
        return (np.concatenate(vert_src), np.concatenate(vert_geom), np.concatenate(faces),
                np.concatenate(face_geom))

    def _local_vertices(self, model: mujoco.MjModel) -> np.ndarray:
        return np.asarray(model.mesh_vert, dtype=np.float32)[self._vert_src].reshape(-1, 3)

    def remesh(self, model: mujoco.MjModel) -> None:
        """Take the meshes' vertices anew (meshes rescaled in place); the next :meth:`pose` refits."""
        with wp.ScopedDevice(self.device):
            self._local.assign(self._local_vertices(model))
        self._poses = None

    def pose(self, model: mujoco.MjModel, xpos: np.ndarray, xmat: np.ndarray) -> None:
        """Place the geoms at ``xpos`` / ``xmat`` (per geom, MuJoCo's layout) with the model's current sizes;
        rebuilds nothing when nothing moved."""
        sizes = np.asarray(model.geom_size, dtype=np.float32)
        size_changed = self._sizes is None or not np.array_equal(sizes, self._sizes)
        poses = (np.asarray(xpos, dtype=np.float32), np.asarray(xmat, dtype=np.float32).reshape(-1, 3, 3))
        moved = self._poses is None or not (np.array_equal(poses[0], self._poses[0])
                                            and np.array_equal(poses[1], self._poses[1]))
        if not (moved or size_changed):
            return
        with wp.ScopedDevice(self.device):
            if size_changed:
                self._size.assign(sizes)
                self._rbound.assign(np.asarray(model.geom_rbound, dtype=np.float32))
                self._sizes = sizes
            self._xpos.assign(poses[0])
            self._xmat.assign(poses[1])
            self._place_meshes()
            self._place_primitives()
        self._poses = poses

    def _place_meshes(self) -> None:
        if not len(self._faces):
            return
        wp.launch(_world_vertices, dim=len(self._vert_src),
                  inputs=[self._local, self._vert_geom, self._xpos, self._xmat, self._world])
        wp.launch(_triangle_bounds, dim=len(self._faces),
                  inputs=[self._world, self._face_dev, self._tri_lower, self._tri_upper])
        if self._tris is None:
            self._tris = wp.Bvh(self._tri_lower, self._tri_upper, constructor=TRIANGLE_BVH)
        else:
            self._tris.refit()

    def _place_primitives(self) -> None:
        if not len(self._primitives):
            return
        wp.launch(_sphere_bounds, dim=len(self._primitives),
                  inputs=[self._bvh_geoms, self._xpos, self._rbound, self._lower, self._upper])
        if self._bvh is None:
            self._bvh = wp.Bvh(self._lower, self._upper)
        else:
            self._bvh.refit()

    def enable(self, enabled: np.ndarray) -> None:
        """Cast against the geoms ``enabled`` (one flag per geom) from now on."""
        flags = np.asarray(enabled, dtype=np.int32)
        if self._enabled is None or not np.array_equal(flags, self._enabled):
            with wp.ScopedDevice(self.device):
                self._enabled_dev.assign(flags)
            self._enabled = flags

    def cast(self, origins: np.ndarray, directions: np.ndarray,
             cutoff: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(distance or -1, geom or -1, unit normal) of each ray from ``origins`` along unit ``directions``
        against the enabled geoms, no farther than ``cutoff``."""
        count = len(directions)
        with wp.ScopedDevice(self.device):
            pnt = wp.array(np.asarray(origins, dtype=np.float32), dtype=wp.vec3)
            vec = wp.array(np.asarray(directions, dtype=np.float32), dtype=wp.vec3)
            dist = wp.empty(count, dtype=float)
            geom = wp.empty(count, dtype=wp.int32)
            normal = wp.empty(count, dtype=wp.vec3)
            self.launch(pnt, vec, cutoff, dist, geom, normal)
            return dist.numpy(), geom.numpy(), normal.numpy()

    def launch(self, pnt, vec, cutoff: float, dist, geom, normal) -> None:
        """The cast kernel over device arrays (for callers that keep their rays on the device)."""
        tris_id = self._tris.id if self._tris is not None else wp.uint64(0)
        bvh_id = self._bvh.id if self._bvh is not None else wp.uint64(0)
        wp.launch(_cast, dim=pnt.shape[0],
                  inputs=[tris_id, int(self._tris is not None), self._world, self._face_dev, self._face_geom,
                          bvh_id, int(self._bvh is not None),
                          self._bvh_geoms, self._plane_dev, self._type, self._size, self._xpos, self._xmat,
                          self._enabled_dev, pnt, vec, float(cutoff)],
                  outputs=[dist, geom, normal])
