"""Compile a ``Usd.Stage`` into a MuJoCo model through ``MjSpec``: the orchestration of one compile.

Mapping (USD -> MuJoCo), each schema's part in the module named:

* every renderable gprim (Cube, Sphere, Cylinder, Cone, Capsule, Plane, Mesh) is
  one geom (:mod:`~graphsdg.sim.gprims`). A gprim under a prim with
  ``UsdPhysics.RigidBodyAPI`` belongs to that rigid body; any other gprim gets
  its own mocap body at its world pose, so pose edits are a write into
  ``mocap_pos``/``mocap_quat`` with no recompile. The world scale of a gprim is
  baked into the geom size (primitives, editable live) or into the mesh vertices
  (meshes: a scale edit recompiles). A mesh with ``GeomSubset`` faces showing
  their own materials or labels is drawn as one part geom per subset
  (:mod:`~graphsdg.sim.geom_subsets`); its UV primvar becomes its texture
  coordinates (:mod:`~graphsdg.sim.texcoords`) and its authored normals its
  normals (:mod:`~graphsdg.sim.mesh_normals`).
* physics (``UsdPhysics``): rigid bodies (:mod:`~graphsdg.sim.rigid_bodies`: a
  free body, a mocap body when ``kinematicEnabled``; a rigid body nested in
  another moves with the outermost one); joints (:mod:`~graphsdg.sim.joints`:
  a kinematic tree of hinge / slide / ball joints, drives as actuators, weld
  constraints); ``CollisionAPI`` colliders and ``MeshCollisionAPI``
  approximations, physics-material friction (:mod:`~graphsdg.sim.colliders`);
  ``MassAPI`` masses and densities (:mod:`~graphsdg.sim.masses`);
  ``PhysicsScene`` gravity and step (:mod:`~graphsdg.sim.physics_scene`);
  PhysX attributes (:mod:`~graphsdg.sim.physx_attributes`); deformable bodies
  (:mod:`~graphsdg.sim.deformables`).
* ``UsdShade`` materials, their textures and ``primvars:displayColor``
  (:mod:`~graphsdg.sim.materials`).
* UsdLux lights, the dome's ambient light and skybox (:mod:`~graphsdg.sim.lights`).
* cameras are not compiled: render products read USD cameras directly. The
  visual options renderers read and the pbr backend's camera are set by
  :mod:`~graphsdg.sim.visual`.

The result, :class:`~graphsdg.sim.compiled_scene.CompiledScene`, remembers
which MuJoCo elements each prim drives so :mod:`graphsdg.sim.scene` can write
attribute edits straight into the model.
"""
from __future__ import annotations

import time
import warnings

import mujoco
import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.base import settings_store as settings
from graphsdg.sim import colliders, deformables, geom_subsets, physx_attributes
from graphsdg.sim import joints as jointmap
from graphsdg.sim import lights as lightmap
from graphsdg.sim.compile_error import CompileError
from graphsdg.sim.compiled_scene import CompiledScene, GeomBinding
from graphsdg.sim.gprims import GPRIM_TYPES, is_renderable, mesh_arrays, primitive_size
from graphsdg.sim.masses import apply_body_masses, assign_masses
from graphsdg.sim.materials import MUJOCO_DEFAULT_RGBA, SpecMaterials, display_rgba
from graphsdg.sim.mesh_normals import mesh_normals
from graphsdg.sim.mujoco_warnings import route_warnings
from graphsdg.sim.physics_scene import configure_physics
from graphsdg.sim.rigid_bodies import SpecBodies, in_body_frame, is_kinematic, rigid_root
from graphsdg.sim.visual import HIDDEN_GROUP, add_pbr_cameras, configure_visual
from graphsdg.stage.xform import world_matrix
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz

route_warnings()   # before the first compile: MuJoCo's warnings are logged, not written to MUJOCO_LOG.TXT

PROBE_BOX = "graphsdg:probe_box"          # collision-free shapes posed by scene queries
PROBE_SPHERE = "graphsdg:probe_sphere"


class _Builder:
    """One compile: walks the stage and fills an MjSpec, each schema through its module's part."""

    def __init__(self, stage: Usd.Stage, offscreen: tuple[int, int], pbr: bool, pbr_cameras: int = 1) -> None:
        self.stage = stage
        self.spec = mujoco.MjSpec()
        self.cache = UsdGeom.XformCache(Usd.TimeCode.Default())
        self.offscreen = offscreen
        self.geom_records: list[tuple[str, object, str | None, np.ndarray, str | None, bool]] = []
        self.mass_records: list[tuple] = []
        self.collider_records: list[tuple] = []
        self.pbr_maps = pbr                            # materials carry normal / ORM / ... maps for the pbr backend
        self.pbr_cameras = pbr_cameras
        self.materials = SpecMaterials(self.spec, self.pbr_maps)
        self.lights = lightmap.SpecLights(self.spec, stage, self.cache)
        self.bodies = SpecBodies(self.spec, stage, self.cache)
        self.part_records: dict[str, list[geom_subsets.PartGeom]] = {}   # mesh -> its GeomSubset part geoms
        self.mesh_count = 0

    def add_gprim(self, prim: Usd.Prim) -> None:
        """The geom of gprim ``prim`` (with its mesh, material, part geoms and collision shapes)."""
        path = str(prim.GetPath())
        m_world = world_matrix(prim, self.cache)
        root = rigid_root(prim)
        if root is not None:
            body = self.bodies.body_for(root)
            t, r, scale = decompose(in_body_frame(self.cache, prim, root))
        else:
            t, r, scale = decompose(m_world)
            body = self.spec.worldbody.add_body(name=path, pos=t.tolist(), quat=matrix_to_quat_wxyz(r).tolist(),
                                                mocap=True)
            t, r = np.zeros(3), np.eye(3)
        collides = colliders.collides(prim)
        dynamic = root is not None and not is_kinematic(root)
        visible = UsdGeom.Imageable(prim).ComputeVisibility(Usd.TimeCode.Default()) != UsdGeom.Tokens.invisible \
            and is_renderable(prim)
        material = self.materials.material(prim)
        type_name = prim.GetTypeName()
        mesh_data = None
        if type_name in ("Mesh", "Cone"):
            verts, tris = mesh_arrays(prim, scale)
            mesh_name = f"mesh:{path}"
            mesh = self.spec.add_mesh(name=mesh_name, uservert=(verts @ r.T + t).ravel().tolist(),
                                      userface=tris.ravel().tolist())
            uvs = self.materials.mesh_uvs(prim, material) if type_name == "Mesh" else None
            if uvs is not None and len(uvs.face_texcoord) == len(tris):
                mesh.usertexcoord = uvs.texcoord.ravel().tolist()
                mesh.userfacetexcoord = uvs.face_texcoord.ravel().tolist()
            normals = mesh_normals(prim, scale, r) if type_name == "Mesh" else None
            if normals is not None and len(normals.face_normal) == len(tris):
                mesh.usernormal = normals.normal.ravel().tolist()
                mesh.userfacenormal = normals.face_normal.ravel().tolist()
            mesh_data = (verts, tris, normals)
            solid = dynamic and collides and not colliders.is_flat(verts)
            mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX if solid else \
                mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
            geom = body.add_geom(name=path, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=mesh_name)
            self.mesh_count += 1
        else:
            kind, size, local_rot = primitive_size(prim, scale)
            geom = body.add_geom(name=path, type=kind, size=size.tolist(), pos=t.tolist(),
                                 quat=matrix_to_quat_wxyz(r @ local_rot).tolist())
        geom.group = 0 if visible else HIDDEN_GROUP
        if material is not None:
            geom.material = material
            geom.rgba = list(MUJOCO_DEFAULT_RGBA)
        else:
            geom.rgba = list(display_rgba(prim))
        if type_name == "Mesh":
            parts = geom_subsets.add_part_geoms(self.materials, prim, body, geom, *mesh_data, r, t,
                                                MUJOCO_DEFAULT_RGBA)
            if parts:
                geom.group = HIDDEN_GROUP      # it still collides and carries mass; its parts draw it
                self.part_records[path] = parts
        physical = [geom]
        if collides:
            physical = colliders.collision_shapes(self.spec, prim, body, geom, mesh_data, t, r, dynamic,
                                                  root is None)
        for part in physical:
            part.contype = part.conaffinity = 1 if collides else 0
        if physical and physical[0] is not geom:
            geom.contype = geom.conaffinity = 0
        self.mass_records.append((str(root.GetPath()) if root else None, prim, geom, physical, collides))
        relative = None
        if root is not None:
            relative = np.eye(4)
            relative[:3, :3] = r.T
            relative[3, :3] = t
        self.geom_records.append((path, geom, str(root.GetPath()) if root else None, scale, material, visible,
                                  relative))
        if collides:
            owner = str(root.GetPath()) if root is not None else path
            self.collider_records += [(part, owner, path) for part in physical]

    def add_probes(self) -> None:
        """Collision-free box and sphere that scene queries pose and size (never drawn)."""
        probe = self.spec.worldbody.add_body(name="graphsdg:probe", mocap=True)
        for name, kind in ((PROBE_BOX, mujoco.mjtGeom.mjGEOM_BOX), (PROBE_SPHERE, mujoco.mjtGeom.mjGEOM_SPHERE)):
            probe.add_geom(name=name, type=kind, size=[1e-3, 1e-3, 1e-3], contype=0, conaffinity=0,
                           group=HIDDEN_GROUP, density=0.0)

    def size_memory(self) -> None:
        """Skip contact detection when nothing collides; give big scenes a big enough arena.

        MuJoCo's broadphase scratch grows with the square of the body count, so
        thousands of visual-only bodies would overflow the default arena for nothing.
        """
        colliding = bool(self.collider_records)     # proxy shapes collide for their visual geoms
        if not colliding:
            self.spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
        nbody = len(self.geom_records) + len(self.bodies.records) + 1
        self.spec.memory = max(16 << 20, 16 * nbody * nbody + (8 << 20)) if colliding else -1

    # ---- top level -----------------------------------------------------
    def build(self) -> CompiledScene:
        configure_physics(self.spec, self.stage)
        configure_visual(self.spec, self.offscreen)
        predicate = Usd.TraverseInstanceProxies(Usd.PrimIsActive & Usd.PrimIsDefined & ~Usd.PrimIsAbstract)
        prims = list(Usd.PrimRange.Stage(self.stage, predicate))
        joint_prims = [p for p in prims if p.GetTypeName() in jointmap.JOINT_KINDS]
        if joint_prims:
            try:
                self.bodies.joint_plan = jointmap.plan(self.stage, joint_prims, rigid_root,
                                                       lambda path: is_kinematic(self.stage.GetPrimAtPath(path)))
            except jointmap.JointError as exc:
                raise CompileError(str(exc)) from None
        for prim in prims:
            type_name = prim.GetTypeName()
            if type_name in lightmap.LIGHT_KINDS:
                self.lights.add(prim)
            elif is_renderable(prim) or (prim.GetTypeName() in GPRIM_TYPES and colliders.collides(prim)):
                # a guide / proxy purpose collider is not drawn but collides (as in PhysX: addGroundPlane's plane)
                try:
                    self.add_gprim(prim)
                except CompileError:
                    raise
                except Exception as exc:  # pxr / mujoco errors: say which prim
                    raise CompileError(f"cannot compile prim {prim.GetPath()} ({type_name}): {exc}") from exc
        jointmap.add_joint_elements(self.spec, self.bodies.joint_plan, self.bodies.body_at)
        self.flex_plans = deformables.add_to_spec(self.spec, prims, self.cache)
        self.lights.finish()
        if self.pbr_maps:     # only where the pbr backend draws, so the classic model is unchanged
            add_pbr_cameras(self.spec, self.pbr_cameras)
        assign_masses(self.mass_records, self.bodies.body_mass)
        try:   # physxCollision offsets -> margins; authored PhysX attributes with no effect warn once
            physx_attributes.tune_colliders(self.stage, self.collider_records)
            physx_attributes.warn_unmapped(prims)
        except physx_attributes.PhysxAttributeError as exc:
            raise CompileError(str(exc)) from None
        self.add_probes()
        self.size_memory()
        try:
            with warnings.catch_warnings():
                # MuJoCo 4 says this of flexes whose elasticity its solver applies (tests/test_deformables.py
                # shows a softer material squashing more): a false alarm for every deformable, every compile
                warnings.filterwarnings("ignore", message=r"flex .* is not rigid and has no equality constraints "
                                                          r"or passive forces")
                model = self.spec.compile()
        except Exception as exc:
            raise CompileError(f"MuJoCo could not compile the stage: {exc}") from exc
        data = mujoco.MjData(model)
        return self._bind(model, data)

    def _bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> CompiledScene:
        scene = CompiledScene(model=model, data=data, has_scene_lights=self.lights.has_lights)
        scene.geom_paths = [""] * model.ngeom
        for path, geom, root, scale, material, visible, relative in self.geom_records:
            gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, path)
            bid = int(model.geom_bodyid[gid])
            mocap = int(model.body_mocapid[bid]) if root is None else -1
            scene.geoms[path] = GeomBinding(path=path, type_name=self.stage.GetPrimAtPath(path).GetTypeName(),
                                            geom_id=gid, body_id=bid, mocap_id=mocap, rigid_root=root,
                                            scale=scale, material=material, visible=visible,
                                            relative=relative)
            scene.geom_paths[gid] = path
        for path, parts in self.part_records.items():
            ids = tuple(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, part.name) for part in parts)
            for gid, part in zip(ids, parts):
                scene.geom_paths[gid] = part.label_path     # a labelled GeomSubset, or the mesh
            scene.geoms[path].parts = ids
        scene.bodies = self.bodies.bind(model)
        rescaled = apply_body_masses(model, scene.bodies, self.bodies.body_mass)
        for shape, owner, prim_path in self.collider_records:
            gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, shape.name)
            scene.collider_owner[gid] = owner
            scene.collider_prim[gid] = prim_path
            scene.collider_paths.add(prim_path)
        scene.probe_box = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, PROBE_BOX)
        scene.probe_sphere = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, PROBE_SPHERE)
        if rescaled:
            mujoco.mj_setConst(model, data)
        try:   # after the mass rescale: PhysX damping is per unit mass / inertia
            physx_attributes.apply_body_damping(model, self.stage, [(p, b.body_id, b.qvel_adr) for p, b
                                                                    in scene.bodies.items() if b.qvel_adr >= 0])
        except physx_attributes.PhysxAttributeError as exc:
            raise CompileError(str(exc)) from None
        scene.lights = self.lights.bind(model)
        scene.materials = self.materials.bind(model)
        lightmap.place_directional_lights(model)
        scene.sky_texture_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXTURE, lightmap.SKY_TEXTURE)
        # after mj_setConst, which uses the data as scratch: the current state
        self.bodies.set_free_states(scene)
        jointmap.bind_joints(scene, self.bodies.joint_plan, self.stage, self.cache)
        mujoco.mj_forward(model, data)
        scene.deformables = deformables.bind(self.flex_plans, model, data, scene.geoms, self.stage)
        return scene


def compile_stage(stage: Usd.Stage, offscreen: tuple[int, int] = (640, 480), pbr: bool = False,
                  pbr_cameras: int = 1) -> CompiledScene:
    """Compile ``stage`` into a :class:`CompiledScene` (model, data and prim maps).

    ``offscreen`` is the size of MuJoCo's offscreen framebuffer (the largest
    render product). ``pbr``: the pbr backend draws this model, so it gets that
    backend's cameras (``pbr_cameras``: how many render products it draws in one
    launch) and its materials their normal / ORM / ... maps (the classic model
    stays without them).

    Example:
        >>> from graphsdg import stage
        >>> from pxr import UsdGeom
        >>> s = stage.new_stage(); _ = UsdGeom.Cube.Define(s, "/Cube")
        >>> compile_stage(s).model.ngeom
        1
    """
    start = time.perf_counter()
    scene = _Builder(stage, offscreen, pbr, pbr_cameras).build()
    scene.compile_seconds = time.perf_counter() - start
    return scene
