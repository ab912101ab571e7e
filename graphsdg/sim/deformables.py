"""Deformable bodies (Isaac's volume and surface deformables) as MuJoCo flexes.

Isaac Sim 6 marks a deformable with ``OmniPhysicsDeformableBodyAPI`` on its root
prim and simulates a mesh found below it (or the root itself): a tetrahedral
``TetMesh`` with ``OmniPhysicsVolumeDeformableSimAPI`` (volume) or a triangle
``Mesh`` with ``OmniPhysicsSurfaceDeformableSimAPI`` (surface, e.g. cloth). The
render meshes are embedded in the simulation mesh and follow it.

Here (see docs/physics.md, "Deformable bodies"):

* each simulation node is a MuJoCo body with three slide joints (named
  ``<sim mesh path>#<i>:x|y|z``, so state carries over a recompile) at the
  node's rest position; the mesh becomes one flex of dimension 3 (tetrahedra)
  or 2 (triangles) whose linear FEM elasticity takes the bound deformable
  material's Young's modulus, Poisson's ratio and damping; the mass (density x
  volume, or x area x thickness for a surface) is lumped onto the nodes;
* flexes collide with every colliding geom (not with themselves);
* the render meshes stay ordinary mesh geoms (drawn, shaded, labelled like any
  prim); after each physics step :func:`follow` moves their vertices with the
  nodes (barycentric weights in the enclosing tetrahedron), re-uploads them to
  the renderer and writes the deformed points back to the USD meshes;
* MuJoCo integrates flex elasticity only with its ``discrete`` integrator, so a
  stage holding deformables is compiled with it.

:func:`cook_volume` builds the simulation tetrahedra for a volume deformable
the way PhysX's hexahedral simulation mesh does: the render meshes' bounding
box is cut into cubes (``resolution`` along the longest side), the cubes the
surface passes through and those it encloses are kept, and each is split into
six tetrahedra along its main diagonal (neighbouring cubes share faces, so the
mesh is conforming).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, Vt

from graphsdg.stage.xform import world_matrix

DEFORMABLE_BODY_API = "OmniPhysicsDeformableBodyAPI"
VOLUME_SIM_API = "OmniPhysicsVolumeDeformableSimAPI"
SURFACE_SIM_API = "OmniPhysicsSurfaceDeformableSimAPI"
DEFORMABLE_MATERIAL_API = "OmniPhysicsDeformableMaterialAPI"
SURFACE_MATERIAL_API = "OmniPhysicsSurfaceDeformableMaterialAPI"
REST_POINTS = "graphsdg:restPoints"            # a render mesh's points when its deformable was set up
SIMULATION_MESH = "simulation_mesh"            # the TetMesh cook_volume creates under the root
DEFAULT_RESOLUTION = 4                         # cubes along the longest side of a cooked volume
DEFAULT_DENSITY = 1000.0                       # kg/m³
DEFAULT_YOUNG = 1.0e6                          # Pa, PhysX's default deformable material
DEFAULT_POISSON = 0.45
DEFAULT_THICKNESS = 0.001                      # m, a surface deformable's shell
NODE_INERTIA = 1e-9                            # nodes are points: three slide joints, no rotation
# the six tetrahedra of a cube around its 0-7 diagonal (corner bits: x = 1, y = 2, z = 4)
_CUBE_TETS = np.array([(0, 1, 3, 7), (0, 1, 5, 7), (0, 2, 3, 7), (0, 2, 6, 7), (0, 4, 5, 7), (0, 4, 6, 7)])


class DeformableError(ValueError):
    """A deformable body that cannot be set up or simulated as asked."""


def has_api(prim: Usd.Prim, name: str) -> bool:
    """Whether ``prim`` lists the applied API schema ``name`` (known to USD here or not)."""
    # GetAppliedSchemas() drops schemas USD has no definition for; the type info keeps every token
    return name in prim.GetPrimTypeInfo().GetAppliedAPISchemas()


def add_api(prim: Usd.Prim, name: str) -> None:
    """Apply the API schema ``name`` by its token (Isaac's deformable schemas are not in usd-core)."""
    if not has_api(prim, name):
        prim.AddAppliedSchema(name)


def is_deformable_root(prim: Usd.Prim) -> bool:
    """An enabled deformable body root (``omniphysics:deformableBodyEnabled`` not False)."""
    if not has_api(prim, DEFORMABLE_BODY_API):
        return False
    enabled = prim.GetAttribute("omniphysics:deformableBodyEnabled")
    return not (enabled and enabled.HasAuthoredValue() and enabled.Get() is False)


def simulation_mesh(root: Usd.Prim) -> tuple[Usd.Prim, str]:
    """The simulation mesh of a deformable root and its kind (``"volume"`` or ``"surface"``)."""
    for prim in Usd.PrimRange(root):
        if has_api(prim, VOLUME_SIM_API):
            return prim, "volume"
        if has_api(prim, SURFACE_SIM_API):
            return prim, "surface"
    raise DeformableError(f"deformable body {root.GetPath()} has no simulation mesh below it (a TetMesh with "
                          f"{VOLUME_SIM_API} or a Mesh with {SURFACE_SIM_API})")


def render_meshes(root: Usd.Prim) -> list[Usd.Prim]:
    """The Mesh prims at or below ``root`` that are drawn (the simulation TetMesh is not a Mesh)."""
    return [p for p in Usd.PrimRange(root) if p.IsA(UsdGeom.Mesh)
            and UsdGeom.Imageable(p).ComputePurpose() in (UsdGeom.Tokens.default_, UsdGeom.Tokens.render)]


def rest_points(mesh: Usd.Prim) -> np.ndarray:
    """A mesh's rest points (local frame): the ones saved when its deformable was set up, else its points."""
    attr = mesh.GetAttribute(REST_POINTS)
    value = attr.Get() if attr and attr.HasAuthoredValue() else None
    if value is None:
        value = UsdGeom.Mesh(mesh).GetPointsAttr().Get()
    return np.asarray(value if value is not None else [], dtype=np.float64).reshape(-1, 3)


def save_rest_points(mesh: Usd.Prim) -> None:
    """Keep a render mesh's current points as its rest shape (the simulation writes ``points`` back)."""
    if mesh.GetAttribute(REST_POINTS).HasAuthoredValue():
        return
    points = UsdGeom.Mesh(mesh).GetPointsAttr().Get()
    mesh.CreateAttribute(REST_POINTS, Sdf.ValueTypeNames.Point3fArray, custom=True).Set(
        points if points is not None else Vt.Vec3fArray())


def triangles(mesh: Usd.Prim) -> np.ndarray:
    """The faces of a Mesh as triangles (polygons fanned), (k, 3) point indices."""
    m = UsdGeom.Mesh(mesh)
    counts = np.asarray(m.GetFaceVertexCountsAttr().Get() or [], dtype=np.int64)
    indices = np.asarray(m.GetFaceVertexIndicesAttr().Get() or [], dtype=np.int64)
    tris, start = [], 0
    for n in counts.tolist():
        tris.extend((indices[start], indices[start + i], indices[start + i + 1]) for i in range(1, n - 1))
        start += n
    return np.asarray(tris, dtype=np.int64).reshape(-1, 3)


def _to(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Row-vector points through a USD (row-vector) 4x4 matrix."""
    return points @ matrix[:3, :3] + matrix[3, :3]


# ---- cooking: the hexahedral simulation mesh ------------------------------------------
def cook_volume(root: Usd.Prim, resolution: int = DEFAULT_RESOLUTION) -> Usd.Prim:
    """Create ``<root>/simulation_mesh``, a TetMesh of conforming cube tetrahedra around the render meshes.

    The TetMesh is in the root's frame and a ``guide`` (not drawn); the render
    meshes' rest points are saved (:data:`REST_POINTS`).
    """
    if int(resolution) < 1:
        raise DeformableError(f"simulation resolution of {root.GetPath()} is {resolution!r}; expected a "
                              f"positive number of cubes along the longest side")
    meshes = render_meshes(root)
    if not meshes:
        raise DeformableError(f"cannot make a volume deformable of {root.GetPath()}: no Mesh below it")
    root_inv = np.linalg.inv(world_matrix(root))
    surface = []
    for mesh in meshes:
        save_rest_points(mesh)
        to_root = world_matrix(mesh) @ root_inv
        pts = _to(to_root, rest_points(mesh))
        tris = triangles(mesh)
        surface.append((pts, tris))
    nodes, tets = _hex_tets(surface, int(resolution))
    sim = UsdGeom.TetMesh.Define(root.GetStage(), root.GetPath().AppendChild(SIMULATION_MESH))
    sim.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(nodes.astype(np.float32)))
    sim.CreateTetVertexIndicesAttr(Vt.Vec4iArray.FromNumpy(tets.astype(np.int32)))
    sim.CreatePurposeAttr(UsdGeom.Tokens.guide)
    add_api(sim.GetPrim(), VOLUME_SIM_API)
    return sim.GetPrim()


def _hex_tets(surface: list[tuple[np.ndarray, np.ndarray]], resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and tetrahedra of the cubes that the triangle soups ``surface`` pass through or enclose."""
    allpts = np.concatenate([p for p, _ in surface])
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    h = max(float((hi - lo).max()), 1e-9) / resolution
    dims = np.maximum(np.ceil((hi - lo) / h - 1e-9).astype(int), 1)
    lo = (lo + hi) / 2 - dims * h / 2        # centre the grid on the box
    occupied = np.zeros(dims + 2, dtype=bool)  # a free border for the outside flood fill
    for pts, tris in surface:
        samples = [pts]
        if len(tris):
            a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
            longest = np.max([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                              np.linalg.norm(a - c, axis=1)], axis=0)
            steps = int(min(64, max(1, np.ceil(longest.max() / (0.25 * h)))))
            for i in range(steps + 1):
                for j in range(steps + 1 - i):
                    u, v = i / steps, j / steps
                    samples.append(a + u * (b - a) + v * (c - a))
        cells = np.clip(np.floor((np.concatenate(samples) - lo) / h).astype(int), 0, dims - 1) + 1
        occupied[cells[:, 0], cells[:, 1], cells[:, 2]] = True
    outside = _flood_outside(occupied)
    keep = ~outside[1:-1, 1:-1, 1:-1]
    cells = np.argwhere(keep)
    corners = np.array([[(c >> 0) & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)])
    corner_ids = (cells[:, None, :] + corners[None, :, :]).reshape(-1, 3)
    unique, inverse = np.unique(corner_ids, axis=0, return_inverse=True)
    inverse = inverse.reshape(len(cells), 8)
    tets = inverse[:, _CUBE_TETS].reshape(-1, 4)
    nodes = lo + unique * h
    return nodes, _positive(nodes, tets)


def _flood_outside(occupied: np.ndarray) -> np.ndarray:
    """Cells reachable from the grid's border through unoccupied cells (6-connected)."""
    outside = np.zeros_like(occupied)
    outside[0, :, :] = outside[-1, :, :] = outside[:, 0, :] = outside[:, -1, :] = True
    outside[:, :, 0] = outside[:, :, -1] = True
    outside &= ~occupied
    while True:
        grown = outside.copy()
        grown[1:] |= outside[:-1]
        grown[:-1] |= outside[1:]
        grown[:, 1:] |= outside[:, :-1]
        grown[:, :-1] |= outside[:, 1:]
        grown[:, :, 1:] |= outside[:, :, :-1]
        grown[:, :, :-1] |= outside[:, :, 1:]
        grown &= ~occupied
        if (grown == outside).all():
            return outside
        outside = grown


def _positive(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Tetrahedra ordered to have positive volume."""
    tets = tets.copy()
    flip = _signed_volumes(nodes, tets) < 0
    tets[flip, 2], tets[flip, 3] = tets[flip, 3], tets[flip, 2].copy()
    return tets


def _signed_volumes(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    a, b, c, d = (nodes[tets[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0


# ---- materials ---------------------------------------------------------------------
@dataclass
class DeformableMaterial:
    """The elastic properties a flex takes from a deformable's bound physics material."""

    young: float = DEFAULT_YOUNG
    poisson: float = DEFAULT_POISSON
    density: float = DEFAULT_DENSITY
    damping: float = 0.0
    friction: float = 0.5
    thickness: float = DEFAULT_THICKNESS


def _attr(prim: Usd.Prim, name: str, default: float) -> float:
    attr = prim.GetAttribute(name)
    value = attr.Get() if attr and attr.HasAuthoredValue() else None
    return float(default if value is None else value)


def bound_material(prim: Usd.Prim) -> DeformableMaterial:
    """The deformable material bound to ``prim`` (or an ancestor) for physics; PhysX's defaults if none."""
    result = DeformableMaterial()
    material = None
    q = prim
    while q and material is None:
        rel = UsdShade.MaterialBindingAPI(q).GetDirectBinding("physics").GetMaterial()
        material = rel if rel else None
        q = q.GetParent()
    if material is None:
        return result
    m = material.GetPrim()
    result.young = _attr(m, "omniphysics:youngsModulus", result.young)
    result.poisson = _attr(m, "omniphysics:poissonsRatio", result.poisson)
    result.density = _attr(m, "omniphysics:density", 0.0) or DEFAULT_DENSITY   # 0: PhysX's "default"
    result.damping = _attr(m, "physxDeformableMaterial:elasticityDamping", result.damping)
    result.friction = _attr(m, "omniphysics:dynamicFriction", result.friction)
    result.thickness = _attr(m, "omniphysics:surfaceThickness", result.thickness)
    if not (result.young >= 0 and 0 <= result.poisson < 0.5 + 1e-9 and result.density > 0):
        raise DeformableError(f"deformable material {m.GetPath()}: Young's modulus {result.young}, Poisson's ratio "
                              f"{result.poisson}, density {result.density}; expected E >= 0, 0 <= nu <= 0.5, "
                              f"density > 0")
    # MuJoCo's linear FEM divides by (1 - 2 nu): an incompressible 0.5 is taken as 0.49
    result.poisson = min(result.poisson, 0.49)
    return result


# ---- compile ---------------------------------------------------------------------------
@dataclass
class FlexPlan:
    """One deformable added to the spec, to bind once the model is compiled."""

    root: str
    sim_path: str
    kind: str                         # "volume" or "surface"
    rest_world: np.ndarray            # (n, 3) node rest positions, world
    elements: np.ndarray              # (k, 4) tets or (k, 3) triangles
    meshes: list[str] = field(default_factory=list)


@dataclass
class EmbeddedMesh:
    """A render mesh moved by a flex: each point is a weighted sum of nodes."""

    path: str
    geom_id: int
    mesh_id: int
    point_nodes: np.ndarray           # (p, m) node indices per USD point
    point_weights: np.ndarray         # (p, m)
    vert_points: np.ndarray           # MuJoCo mesh vertex -> USD point index
    world_to_local: np.ndarray        # the prim's inverse world matrix (row-vector)


@dataclass
class FlexBinding:
    """A compiled deformable: its flex and node dofs, and the meshes it moves."""

    root: str
    sim_path: str
    kind: str
    flex_id: int
    node_bodies: np.ndarray           # body id per node
    qpos_adr: np.ndarray              # (n, 3) slide-joint qpos addresses per node
    qvel_adr: np.ndarray              # (n, 3)
    rest_world: np.ndarray
    elements: np.ndarray
    meshes: list[EmbeddedMesh] = field(default_factory=list)


def find(stage_prims: list[Usd.Prim]) -> list[Usd.Prim]:
    """The deformable body roots among ``stage_prims``."""
    return [p for p in stage_prims if is_deformable_root(p)]


def add_to_spec(spec: mujoco.MjSpec, stage_prims: list[Usd.Prim], cache: UsdGeom.XformCache) -> list[FlexPlan]:
    """Add a flex (and its node bodies) for every deformable root among ``stage_prims``."""
    plans = []
    for root in find(stage_prims):
        sim, kind = simulation_mesh(root)
        to_world = world_matrix(sim, cache)
        if kind == "volume":
            tm = UsdGeom.TetMesh(sim)
            pts = np.asarray(tm.GetPointsAttr().Get() or [], dtype=np.float64).reshape(-1, 3)
            elements = np.asarray(tm.GetTetVertexIndicesAttr().Get() or [], dtype=np.int64).reshape(-1, 4)
            meshes = render_meshes(root)
        else:
            pts, elements, meshes = rest_points(sim), triangles(sim), [sim]
        if not len(pts) or not len(elements):
            raise DeformableError(f"simulation mesh {sim.GetPath()} of deformable {root.GetPath()} is empty")
        if elements.min() < 0 or elements.max() >= len(pts):
            raise DeformableError(f"simulation mesh {sim.GetPath()} indexes point {int(elements.max())} of "
                                  f"{len(pts)}")
        rest = _to(to_world, pts)
        material = bound_material(root if kind == "volume" else sim)
        _add_flex(spec, str(sim.GetPath()), kind, rest, elements, material)
        for mesh in meshes:   # a render mesh is drawn, never a collider of its own flex
            geom = spec.geom(str(mesh.GetPath()))
            if geom is not None:
                geom.contype = geom.conaffinity = 0
        plans.append(FlexPlan(root=str(root.GetPath()), sim_path=str(sim.GetPath()), kind=kind, rest_world=rest,
                              elements=elements, meshes=[str(m.GetPath()) for m in meshes]))
    if plans:
        # MuJoCo integrates flex elasticity only with its discrete integrator (stable at any stiffness)
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_DISCRETE
    return plans


def _add_flex(spec: mujoco.MjSpec, name: str, kind: str, rest: np.ndarray, elements: np.ndarray,
              material: DeformableMaterial) -> None:
    if kind == "volume":
        sizes = np.abs(_signed_volumes(rest, elements))
        mass = material.density * sizes
    else:
        a, b, c = (rest[elements[:, i]] for i in range(3))
        sizes = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        mass = material.density * material.thickness * sizes
    node_mass = np.zeros(len(rest))
    np.add.at(node_mass, elements.ravel(), np.repeat(mass / elements.shape[1], elements.shape[1]))
    node_mass = np.maximum(node_mass, 1e-6)
    names = []
    for i, (p, m) in enumerate(zip(rest, node_mass)):
        body = spec.worldbody.add_body(name=f"{name}#{i}", pos=p.tolist())
        body.explicitinertial = True
        body.mass = float(m)
        body.inertia = [NODE_INERTIA] * 3
        for axis, vec in (("x", (1, 0, 0)), ("y", (0, 1, 0)), ("z", (0, 0, 1))):
            body.add_joint(name=f"{name}#{i}:{axis}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=list(vec))
        names.append(body.name)
    flex = spec.add_flex()
    flex.name = name
    flex.dim = 3 if kind == "volume" else 2
    flex.vertbody = names
    flex.elem = elements.ravel().astype(int).tolist()
    flex.young = float(material.young)
    flex.poisson = float(material.poisson)
    flex.damping = float(material.damping)
    if kind == "surface":
        flex.thickness = float(material.thickness)
        flex.elastic2d = 3          # stretching and bending
    edge = float(np.median(np.linalg.norm(rest[elements[:, 0]] - rest[elements[:, 1]], axis=1)))
    flex.radius = float(min(0.005, 0.1 * edge))
    flex.selfcollide = mujoco.mjtFlexSelf.mjFLEXSELF_NONE
    flex.friction = [float(material.friction), 0.005, 0.0001]
    flex.group = 5                  # the flex itself is not drawn: its render meshes are
    flex.rgba = [0, 0, 0, 0]


def bind(plans: list[FlexPlan], model: mujoco.MjModel, data: mujoco.MjData, geoms: dict,
         stage: Usd.Stage) -> list[FlexBinding]:
    """Bind compiled flexes to their nodes' dofs and the render meshes to embedding weights."""
    bindings = []
    for plan in plans:
        fid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_FLEX, plan.sim_path)
        n = len(plan.rest_world)
        bodies = np.array([mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"{plan.sim_path}#{i}")
                           for i in range(n)])
        qadr = np.zeros((n, 3), dtype=np.int64)
        vadr = np.zeros((n, 3), dtype=np.int64)
        for i in range(n):
            for k, axis in enumerate("xyz"):
                jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{plan.sim_path}#{i}:{axis}")
                qadr[i, k], vadr[i, k] = model.jnt_qposadr[jid], model.jnt_dofadr[jid]
        b = FlexBinding(root=plan.root, sim_path=plan.sim_path, kind=plan.kind, flex_id=fid, node_bodies=bodies,
                        qpos_adr=qadr, qvel_adr=vadr, rest_world=plan.rest_world, elements=plan.elements)
        for path in plan.meshes:
            g = geoms.get(path)
            prim = stage.GetPrimAtPath(path)
            if g is None or not prim or int(model.geom_dataid[g.geom_id]) < 0:
                continue
            b.meshes.append(_embed(plan, prim, g.geom_id, model, data))
        bindings.append(b)
    return bindings


def _embed(plan: FlexPlan, prim: Usd.Prim, geom_id: int, model: mujoco.MjModel,
           data: mujoco.MjData) -> EmbeddedMesh:
    to_world = world_matrix(prim)
    rest = _to(to_world, rest_points(prim))
    if plan.kind == "surface":
        nodes, weights = np.arange(len(rest))[:, None], np.ones((len(rest), 1))
    else:
        nodes, weights = _barycentric(plan.rest_world, plan.elements, rest)
    # MuJoCo's vertices of the mesh (its own frame) -> the USD points they were compiled from
    mesh_id = int(model.geom_dataid[geom_id])
    v0, nv = int(model.mesh_vertadr[mesh_id]), int(model.mesh_vertnum[mesh_id])
    mujoco.mj_kinematics(model, data)
    verts = model.mesh_vert[v0:v0 + nv].astype(np.float64) @ data.geom_xmat[geom_id].reshape(3, 3).T \
        + data.geom_xpos[geom_id]
    current = _to(to_world, np.asarray(UsdGeom.Mesh(prim).GetPointsAttr().Get() or [], dtype=np.float64)
                  .reshape(-1, 3))
    return EmbeddedMesh(path=str(prim.GetPath()), geom_id=geom_id, mesh_id=mesh_id, point_nodes=nodes,
                        point_weights=weights, vert_points=_nearest(verts, current),
                        world_to_local=np.linalg.inv(to_world))


def _nearest(queries: np.ndarray, points: np.ndarray, chunk: int = 2048) -> np.ndarray:
    """Index of the nearest of ``points`` to each query (exact: chunked brute force)."""
    out = np.empty(len(queries), dtype=np.int64)
    for s in range(0, len(queries), chunk):
        q = queries[s:s + chunk]
        out[s:s + chunk] = np.argmin(((q[:, None, :] - points[None, :, :]) ** 2).sum(-1), axis=1)
    return out


def _barycentric(nodes: np.ndarray, tets: np.ndarray, points: np.ndarray,
                 chunk: int = 256) -> tuple[np.ndarray, np.ndarray]:
    """For each point, the tetrahedron that contains it best (largest smallest coordinate) and its
    barycentric coordinates there (a point just outside the mesh extrapolates from the nearest one)."""
    a = nodes[tets[:, 0]]
    basis = np.stack([nodes[tets[:, i]] - a for i in (1, 2, 3)], axis=2)    # (k, 3, 3) columns
    inv = np.linalg.inv(basis)
    best_t = np.zeros(len(points), dtype=np.int64)
    best_w = np.zeros((len(points), 4))
    for s in range(0, len(points), chunk):
        p = points[s:s + chunk]
        local = np.einsum("kij,pkj->pki", inv, p[:, None, :] - a[None, :, :])     # (p, k, 3)
        w = np.concatenate([1.0 - local.sum(-1, keepdims=True), local], axis=2)   # (p, k, 4)
        t = np.argmax(w.min(axis=2), axis=1)
        best_t[s:s + chunk] = t
        best_w[s:s + chunk] = w[np.arange(len(p)), t]
    return tets[best_t], best_w


# ---- runtime ----------------------------------------------------------------------------
def node_positions(b: FlexBinding, data: mujoco.MjData) -> np.ndarray:
    """World positions of a deformable's simulation nodes, (n, 3)."""
    return b.rest_world + data.qpos[b.qpos_adr]


def set_node_positions(b: FlexBinding, data: mujoco.MjData, positions: np.ndarray) -> None:
    data.qpos[b.qpos_adr] = np.asarray(positions, dtype=np.float64) - b.rest_world


def node_velocities(b: FlexBinding, data: mujoco.MjData) -> np.ndarray:
    return data.qvel[b.qvel_adr].copy()


def set_node_velocities(b: FlexBinding, data: mujoco.MjData, velocities: np.ndarray) -> None:
    data.qvel[b.qvel_adr] = np.asarray(velocities, dtype=np.float64)


def follow(bindings: list[FlexBinding], model: mujoco.MjModel, data: mujoco.MjData, stage: Usd.Stage,
           moved: set[int]) -> None:
    """Move every embedded render mesh with its flex: MuJoCo's vertices (the meshes' ids added to ``moved``,
    for the renderers' copies) and the USD points (authored; the caller mutes change tracking)."""
    with Sdf.ChangeBlock():
        for b in bindings:
            nodes = node_positions(b, data)
            for e in b.meshes:
                world = np.einsum("pm,pmk->pk", e.point_weights, nodes[e.point_nodes])
                _write_vertices(model, data, e, world[e.vert_points])
                moved.add(e.mesh_id)
                prim = stage.GetPrimAtPath(e.path)
                if prim:
                    local = _to(e.world_to_local, world).astype(np.float32)
                    UsdGeom.Mesh(prim).GetPointsAttr().Set(Vt.Vec3fArray.FromNumpy(local))


def _write_vertices(model: mujoco.MjModel, data: mujoco.MjData, e: EmbeddedMesh, world: np.ndarray) -> None:
    """World positions -> the mesh's vertices in its geom's frame, with normals and bounds to match."""
    g = e.geom_id
    rot = data.geom_xmat[g].reshape(3, 3)
    local = (world - data.geom_xpos[g]) @ rot
    v0, nv = int(model.mesh_vertadr[e.mesh_id]), int(model.mesh_vertnum[e.mesh_id])
    model.mesh_vert[v0:v0 + nv] = local
    f0, nf = int(model.mesh_faceadr[e.mesh_id]), int(model.mesh_facenum[e.mesh_id])
    faces = model.mesh_face[f0:f0 + nf]
    fn = np.cross(local[faces[:, 1]] - local[faces[:, 0]], local[faces[:, 2]] - local[faces[:, 0]])
    n0, nn = int(model.mesh_normaladr[e.mesh_id]), int(model.mesh_normalnum[e.mesh_id])
    normals = np.zeros((nn, 3))
    for k in range(3):   # area-weighted face normals summed at each corner's normal
        np.add.at(normals, model.mesh_facenormal[f0:f0 + nf, k], fn)
    norms = np.linalg.norm(normals, axis=1, keepdims=True)
    model.mesh_normal[n0:n0 + nn] = normals / np.where(norms > 0, norms, 1.0)
    lo, hi = local.min(axis=0), local.max(axis=0)
    model.geom_aabb[g] = np.concatenate([(lo + hi) / 2, (hi - lo) / 2])
    model.geom_rbound[g] = float(np.linalg.norm(local, axis=1).max())


def edits_touch(bindings: list[FlexBinding], edited: dict) -> bool:
    """Whether stage edits (path -> property names) move a deformable: a transform of its root, of an
    ancestor or of a prim below it, or new points (the nodes are placed when the stage is compiled)."""
    if not bindings:
        return False
    roots = [Sdf.Path(b.root) for b in bindings]
    for path, names in edited.items():
        if not any(n.startswith("xformOp") or n in ("points", REST_POINTS) for n in names):
            continue   # material inputs, labels, visibility: drawn as for any prim
        p = Sdf.Path(str(path))
        if any(root.HasPrefix(p) or p.HasPrefix(root) for root in roots):
            return True
    return False
