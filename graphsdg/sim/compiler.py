"""Compile a ``Usd.Stage`` into a MuJoCo model through ``MjSpec``.

Mapping (USD -> MuJoCo):

* every renderable gprim (Cube, Sphere, Cylinder, Cone, Capsule, Plane, Mesh) is
  one geom. A gprim under a prim with ``UsdPhysics.RigidBodyAPI`` belongs to
  that rigid body (a free body, or a mocap body if kinematic); any other gprim
  gets its own mocap body at its world pose, so pose edits are a write into
  ``mocap_pos``/``mocap_quat`` with no recompile.
* the world scale of a gprim is baked into the geom size (primitives, editable
  live) or into the mesh vertices (meshes: a scale edit recompiles).
* physics (``UsdPhysics``): a prim with ``RigidBodyAPI`` is a free body (a
  mocap body when ``kinematicEnabled``); a rigid body nested in another moves
  with the outermost one (prim nesting is not a joint, as in PhysX); joints
  (revolute, prismatic, spherical, fixed) hang bodies in a kinematic tree with
  hinge / slide / ball joints, drives become actuators and fixed joints outside
  the tree become weld constraints (:mod:`graphsdg.sim.joints`);
  ``CollisionAPI`` makes a gprim collide, with
  ``MeshCollisionAPI`` approximations mapped by :mod:`graphsdg.sim.colliders`
  (proxy shapes in group :data:`COLLISION_ONLY_GROUP`, never drawn); a static
  or kinematic ``Plane`` collider is an infinite plane, as in PhysX;
  ``MassAPI`` mass and density set masses (colliders carry a body's mass, at
  1000 kg/m³ unless told otherwise); ``PhysicsScene`` sets gravity and
  ``physxScene:timeStepsPerSecond`` the physics step; a ``PhysicsMaterialAPI``
  bound with the ``physics`` purpose sets friction.
* ``UsdShade`` materials become MuJoCo materials; ``primvars:displayColor``
  becomes the geom colour when no material is bound. A ``UsdUVTexture`` on
  ``diffuseColor`` becomes a MuJoCo texture (decoded by
  :mod:`graphsdg.sim.texture_images`, shared by every material naming the same
  file), and a mesh's UV primvar becomes its texture coordinates
  (:mod:`graphsdg.sim.texcoords`).
* UsdLux lights become MuJoCo lights (see :mod:`graphsdg.sim.lights`); a dome
  light becomes ambient light plus a soft sky light, and a skybox. A dome
  texture (a lat-long HDR) is the skybox and sets the colour, strength and main
  direction of that light (:mod:`graphsdg.sim.environment_map`).
* cameras are not compiled: render products read USD cameras directly.

The result, :class:`CompiledScene`, remembers which MuJoCo elements each prim
drives so :mod:`graphsdg.sim.scene` can write attribute edits straight into the
model.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import mujoco
import numpy as np
from pxr import Usd, UsdGeom, UsdPhysics, UsdShade

from graphsdg import settings_store as settings
from graphsdg.sim import colliders, deformables, environment_map, geom_subsets
from graphsdg.sim import physx_attributes
from graphsdg.sim import joints as jointmap
from graphsdg.sim import lights as lightmap
from graphsdg.sim import texture_images
from graphsdg.sim.mesh_normals import mesh_normals
from graphsdg.sim.mujoco_warnings import route_warnings
from graphsdg.sim.texcoords import TexcoordError, UvTransform, mesh_texcoords
from graphsdg.stage import materials as matlib
from graphsdg.stage import shapes
from graphsdg.stage.changes import STATE_PROPERTIES
from graphsdg.stage.xform import decompose, matrix_to_quat_wxyz, quat_wxyz_to_matrix, up_axis_vector, world_matrix

route_warnings()   # before the first compile: MuJoCo's warnings are logged, not written to MUJOCO_LOG.TXT

HIDDEN_GROUP = 5            # geoms in this group are not drawn (invisible prims)
COLLISION_ONLY_GROUP = 4    # proxy collision shapes (not drawn)
UNDRAWN_GROUPS = (COLLISION_ONLY_GROUP, HIDDEN_GROUP)
PBR_CAMERA = "graphsdg:pbr_camera"
_ROLE = mujoco.mjtTextureRole


def _pbr_draws() -> bool:
    """Whether the pbr backend draws in this process (its camera and texture maps are compiled in)."""
    from graphsdg.render.backend import pbr_draws   # render/ sits above sim/: asked at compile time only
    return pbr_draws()


#: texture map roles (graphsdg.stage.materials.texture_maps) -> MuJoCo's texture roles, which the pbr backend reads
MAP_TEXTURE_ROLES = {"normal": _ROLE.mjTEXROLE_NORMAL, "orm": _ROLE.mjTEXROLE_ORM,
                     "occlusion": _ROLE.mjTEXROLE_OCCLUSION, "roughness": _ROLE.mjTEXROLE_ROUGHNESS,
                     "metallic": _ROLE.mjTEXROLE_METALLIC, "emissive": _ROLE.mjTEXROLE_EMISSIVE,
                     "opacity": _ROLE.mjTEXROLE_OPACITY}   # the camera the PBR backend renders from (render products' poses)
DEFAULT_RGBA = (0.7, 0.7, 0.7, 1.0)
MUJOCO_DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)   # geom rgba that lets a bound material show through
GPRIM_TYPES = ("Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane", "Mesh")
SKY_TEXTURE = "graphsdg:sky"
PROBE_BOX = "graphsdg:probe_box"          # collision-free shapes posed by scene queries
PROBE_SPHERE = "graphsdg:probe_sphere"
DEFAULT_DENSITY = 1000.0                 # kg/m³, PhysX's default
DEFAULT_FRICTION = 0.5                   # PhysX's default material (static = dynamic = 0.5)
# MuJoCo's soft contacts need a shorter step than PhysX's 60 Hz (whose solver iterates
# positions within a step) to keep dropped boxes within millimetres of each other and
# to calm a pile within the 75 frames the SDG workflows settle for: two physics steps
# per 60 Hz timeline frame, with elliptic friction cones (no creeping on slopes).
PHYSICS_STEPS_PER_SECOND = 120.0



class CompileError(ValueError):
    """The stage holds something that cannot become a MuJoCo model."""


@dataclass
class GeomBinding:
    """What one gprim drives in the compiled model."""

    path: str
    type_name: str
    geom_id: int
    body_id: int
    mocap_id: int                    # >= 0 when the gprim owns a mocap body
    rigid_root: str | None           # path of the rigid body the geom belongs to
    scale: np.ndarray                # world scale baked into size or vertices
    material: str | None             # bound material path
    visible: bool = True
    relative: np.ndarray | None = None   # pose in its rigid body's frame (row-vector 4x4)
    parts: tuple[int, ...] = ()          # drawn per-subset part geoms (the geom itself is then not drawn)


VELOCITY_ATTRIBUTES = STATE_PROPERTIES   # a rigid body's velocities: live state, not model structure


def authored_velocity(prim: Usd.Prim) -> tuple[np.ndarray, np.ndarray]:
    """A rigid body's authored world-frame (linear, angular rad/s) velocity; zeros where not authored.

    UsdPhysics gives ``physics:angularVelocity`` in degrees per second; PhysX reads
    both in world space unless ``physxRigidBody:localSpaceVelocities`` is set.
    """
    body = UsdPhysics.RigidBodyAPI(prim)
    linear, angular = body.GetVelocityAttr().Get(), body.GetAngularVelocityAttr().Get()
    return (np.array(linear if linear is not None else (0, 0, 0), dtype=np.float64),
            np.radians(np.array(angular if angular is not None else (0, 0, 0), dtype=np.float64)))


@dataclass
class BodyBinding:
    """A rigid body (UsdPhysics.RigidBodyAPI) in the compiled model."""

    path: str
    body_id: int
    mocap_id: int                    # kinematic bodies are mocap bodies
    qpos_adr: int = -1               # free joint address (dynamic bodies)
    qvel_adr: int = -1
    kinematic: bool = False
    articulated: bool = False        # moved by a joint to a parent body (a link of a kinematic tree)


@dataclass
class JointBinding:
    """A UsdPhysics joint in the compiled model (see :mod:`graphsdg.sim.joints`)."""

    path: str
    kind: str                        # revolute, prismatic, spherical, fixed
    body0: str
    body1: str
    joint_id: int = -1               # MuJoCo joint (-1: fixed, or a weld)
    qpos_adr: int = -1
    dof_adr: int = -1
    actuator_id: int = -1            # the drive, if any
    eq_id: int = -1                  # weld constraint (fixed joints outside the tree)
    articulation: str = ""           # articulation root (or tree root body) the joint belongs to
    reversed: bool = False           # the tree hangs USD body0 from body1


@dataclass
class LightBinding:
    path: str
    kind: str
    light_ids: list[int]


@dataclass
class CompiledScene:
    """A compiled MuJoCo model plus the prim <-> element maps."""

    model: mujoco.MjModel
    data: mujoco.MjData
    geoms: dict[str, GeomBinding] = field(default_factory=dict)
    geom_paths: list[str] = field(default_factory=list)      # geom id -> gprim path ("" if none)
    bodies: dict[str, BodyBinding] = field(default_factory=dict)
    joints: dict[str, JointBinding] = field(default_factory=dict)
    lights: dict[str, LightBinding] = field(default_factory=dict)
    materials: dict[str, int] = field(default_factory=dict)
    sky_texture_id: int = -1
    has_scene_lights: bool = False
    compile_seconds: float = 0.0
    collider_owner: dict[int, str] = field(default_factory=dict)   # colliding geom id -> body or prim path
    collider_prim: dict[int, str] = field(default_factory=dict)    # colliding geom id -> collider prim path
    collider_paths: set[str] = field(default_factory=set)          # gprims that collide (own geom or proxies)
    probe_box: int = -1              # geom ids of the query probes
    probe_sphere: int = -1
    deformables: list = field(default_factory=list)   # graphsdg.sim.deformables.FlexBinding per deformable


def clean_scale(scale: np.ndarray) -> np.ndarray:
    """A scale read off a rotated matrix, rounded to 12 significant digits.

    The row norms of ``R * s`` carry rounding noise that depends on the rotation;
    rounding it away makes a body's geometry, and so its inertia, identical
    however the body is turned when the stage is compiled.
    """
    return np.array([float(f"{v:.12g}") for v in np.asarray(scale, dtype=np.float64)])


def drawn_geom_mask(model: mujoco.MjModel) -> np.ndarray:
    """Which geoms renders draw: those in MuJoCo's groups 0-5 other than :data:`UNDRAWN_GROUPS`."""
    group = model.geom_group
    drawn = (group >= 0) & (group < mujoco.mjNGROUP)
    for g in UNDRAWN_GROUPS:
        drawn &= group != g
    return drawn


def render_quality(largest_image: int = 4096) -> tuple[int, int]:
    """(shadow map size, MSAA samples) for the current settings.

    ``/rtx/rendermode = PathTracing`` (Isaac's highest-quality mode) maps to the
    rasteriser's best: 8x multisampling and shadow maps of 8 texels per pixel of
    the largest image (``largest_image``, its longer edge), up to 4096 px, never
    below ``/graphsdg/render/shadowSize``.
    """
    shadow = int(settings.get("/graphsdg/render/shadowSize", 1024))
    samples = int(settings.get("/graphsdg/render/msaaSamples", 4))
    if str(settings.get("/rtx/rendermode", "")).lower() == "pathtracing":
        shadow, samples = max(shadow, min(4096, 8 * int(largest_image))), max(samples, 8)
    return shadow, samples


def _is_renderable(prim: Usd.Prim) -> bool:
    if prim.GetTypeName() not in GPRIM_TYPES:
        return False
    purpose = UsdGeom.Imageable(prim).ComputePurpose()
    return purpose in (UsdGeom.Tokens.default_, UsdGeom.Tokens.render)


def rigid_root(prim: Usd.Prim) -> Usd.Prim | None:
    """The outermost enabled ``RigidBodyAPI`` prim at or above ``prim`` (the body it moves with)."""
    found = None
    p = prim
    while p and not p.IsPseudoRoot():
        if p.HasAPI(UsdPhysics.RigidBodyAPI):
            enabled = UsdPhysics.RigidBodyAPI(p).GetRigidBodyEnabledAttr().Get()
            if enabled is None or enabled:
                found = p
        p = p.GetParent()
    return found


def _is_kinematic(root: Usd.Prim) -> bool:
    return bool(UsdPhysics.RigidBodyAPI(root).GetKinematicEnabledAttr().Get())


def _mass_api_values(prim: Usd.Prim) -> tuple[float, float]:
    """(mass, density) authored by ``MassAPI`` on ``prim`` (0 where unset); negative values raise."""
    if not prim.HasAPI(UsdPhysics.MassAPI):
        return 0.0, 0.0
    api = UsdPhysics.MassAPI(prim)
    values = []
    for name, attr in (("physics:mass", api.GetMassAttr()), ("physics:density", api.GetDensityAttr())):
        v = attr.Get() if attr else None
        v = 0.0 if v is None else float(v)
        if v < 0 or not np.isfinite(v):
            raise CompileError(f"{name} of {prim.GetPath()} is {v!r}; it must be >= 0 "
                               f"(0 means computed from the colliders' volume and density)")
        values.append(v)
    return values[0], values[1]


def _approximation(prim: Usd.Prim) -> str:
    attr = UsdPhysics.MeshCollisionAPI(prim).GetApproximationAttr() if prim.HasAPI(
        UsdPhysics.MeshCollisionAPI) else prim.GetAttribute("physics:approximation")
    value = attr.Get() if attr and attr.IsValid() else None
    if value is None:
        return "none"
    try:
        return colliders.check_approximation(str(value), f"{prim.GetPath()} (physics:approximation)")
    except colliders.ApproximationError as exc:
        raise CompileError(str(exc)) from None


def _friction(prim: Usd.Prim) -> tuple[float, int]:
    """(dynamic friction, contact priority) of the physics material bound to ``prim``.

    PhysX's 0.5 when none. MuJoCo takes the larger friction of two touching geoms
    unless one has a higher priority; a material whose
    ``physxMaterial:frictionCombineMode`` is ``min`` or ``multiply`` (PhysX: the
    smaller value wins) gets priority 1, so a slippery surface stays slippery.
    """
    binding = UsdShade.MaterialBindingAPI(prim)
    material, _ = binding.ComputeBoundMaterial("physics")
    if material and material.GetPrim().HasAPI(UsdPhysics.MaterialAPI):
        mat = material.GetPrim()
        combine = mat.GetAttribute("physxMaterial:frictionCombineMode")
        priority = 1 if combine and str(combine.Get()) in ("min", "multiply") else 0
        api = UsdPhysics.MaterialAPI(mat)
        for attr in (api.GetDynamicFrictionAttr(), api.GetStaticFrictionAttr()):
            v = attr.Get() if attr else None
            if v is not None:
                return max(float(v), 0.0), priority
        return DEFAULT_FRICTION, priority
    return DEFAULT_FRICTION, 0


def _collides(prim: Usd.Prim) -> bool:
    p = prim
    while p and not p.IsPseudoRoot():
        if p.HasAPI(UsdPhysics.CollisionAPI):
            enabled = UsdPhysics.CollisionAPI(p).GetCollisionEnabledAttr().Get()
            return enabled is None or bool(enabled)
        p = p.GetParent()
    return False


def display_rgba(prim: Usd.Prim) -> tuple[float, float, float, float]:
    """The gprim's ``primvars:displayColor`` (first value) and opacity, or graphsdg's grey."""
    gprim = UsdGeom.Gprim(prim)
    colors = gprim.GetDisplayColorAttr().Get() if gprim else None
    opacity = gprim.GetDisplayOpacityAttr().Get() if gprim else None
    rgb = tuple(float(c) for c in colors[0]) if colors is not None and len(colors) else DEFAULT_RGBA[:3]
    alpha = float(opacity[0]) if opacity is not None and len(opacity) else 1.0
    return (*rgb, alpha)


def _axis_rotation(axis: str) -> np.ndarray:
    """Rotation taking MuJoCo's +Z (its cylinder/capsule axis) onto USD ``axis``."""
    if axis == "X":
        return np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], dtype=np.float64)
    if axis == "Y":
        return np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=np.float64)
    return np.eye(3)


def _axis_index(axis: str) -> int:
    return "XYZ".index(axis)


def _extent(prim: Usd.Prim, name: str, value: object) -> float:
    """A size attribute of an implicit gprim; a CompileError naming the prim unless positive and finite."""
    v = float(value)  # type: ignore[arg-type]
    if not (v > 0 and np.isfinite(v)):
        raise CompileError(f"{prim.GetTypeName()} {prim.GetPath()} has {name} {v!r}; expected a positive "
                           f"number")
    return v


def primitive_size(prim: Usd.Prim, scale: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
    """(mjtGeom, size[3], local rotation) of an implicit gprim under world ``scale``."""
    s = np.abs(scale)
    t = prim.GetTypeName()
    if t == "Cube":
        a = _extent(prim, "size", UsdGeom.Cube(prim).GetSizeAttr().Get())
        return mujoco.mjtGeom.mjGEOM_BOX, a / 2 * s, np.eye(3)
    if t == "Sphere":
        r = _extent(prim, "radius", UsdGeom.Sphere(prim).GetRadiusAttr().Get())
        if np.allclose(s, s[0], rtol=1e-6):
            return mujoco.mjtGeom.mjGEOM_SPHERE, np.array([r * s[0], 0, 0]), np.eye(3)
        return mujoco.mjtGeom.mjGEOM_ELLIPSOID, r * s, np.eye(3)
    if t in ("Cylinder", "Capsule"):
        g = UsdGeom.Cylinder(prim) if t == "Cylinder" else UsdGeom.Capsule(prim)
        axis = str(g.GetAxisAttr().Get())
        i = _axis_index(axis)
        perp = max(s[j] for j in range(3) if j != i)
        r, h = _extent(prim, "radius", g.GetRadiusAttr().Get()), _extent(prim, "height", g.GetHeightAttr().Get())
        kind = mujoco.mjtGeom.mjGEOM_CYLINDER if t == "Cylinder" else mujoco.mjtGeom.mjGEOM_CAPSULE
        return kind, np.array([r * perp, h / 2 * s[i], 0]), _axis_rotation(axis)
    if t == "Plane":
        g = UsdGeom.Plane(prim)
        axis = str(g.GetAxisAttr().Get())
        w, length = _extent(prim, "width", g.GetWidthAttr().Get()), _extent(prim, "length", g.GetLengthAttr().Get())
        rot = _axis_rotation(axis)
        # USD Plane: width along the first in-plane axis, length along the second.
        in_plane = [j for j in range(3) if j != _axis_index(axis)]
        half = np.array([w / 2 * s[in_plane[0]], length / 2 * s[in_plane[1]], 1e-4])
        return mujoco.mjtGeom.mjGEOM_BOX, half, rot
    raise CompileError(f"{prim.GetPath()}: {t} is not an implicit primitive")


def mesh_arrays(prim: Usd.Prim, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (scaled, in the prim's frame) and triangles of a Mesh or Cone prim."""
    if prim.GetTypeName() == "Cone":
        g = UsdGeom.Cone(prim)
        verts, tris = shapes.cone_mesh(float(g.GetRadiusAttr().Get()), float(g.GetHeightAttr().Get()))
        verts = verts @ _axis_rotation(str(g.GetAxisAttr().Get())).T
        return verts * scale, tris
    mesh = UsdGeom.Mesh(prim)
    points = mesh.GetPointsAttr().Get()
    counts = mesh.GetFaceVertexCountsAttr().Get()
    indices = mesh.GetFaceVertexIndicesAttr().Get()
    if points is None or counts is None or indices is None or len(points) == 0:
        raise CompileError(f"mesh {prim.GetPath()} has no points or faces")
    verts = np.array(points, dtype=np.float64) * scale
    tris = shapes.triangulate(np.array(counts), np.array(indices))
    if tris.size and (tris.max() >= len(verts) or tris.min() < 0):
        raise CompileError(f"mesh {prim.GetPath()} has face indices outside its {len(verts)} points")
    if str(mesh.GetOrientationAttr().Get()) == UsdGeom.Tokens.leftHanded:
        tris = tris[:, ::-1]
    return verts, tris


class _Builder:
    """One compile: walks the stage and fills an MjSpec."""

    def __init__(self, stage: Usd.Stage, offscreen: tuple[int, int]) -> None:
        self.stage = stage
        self.spec = mujoco.MjSpec()
        self.cache = UsdGeom.XformCache(Usd.TimeCode.Default())
        self.offscreen = offscreen
        self.geom_records: list[tuple[str, object, str | None, np.ndarray, str | None, bool]] = []
        self.body_records: dict[str, object] = {}
        self.light_records: list[tuple[str, str, list[object]]] = []
        self.material_names: dict[str, str] = {}
        self.body_mass: dict[str, tuple[float, float]] = {}
        self.mass_records: list[tuple] = []
        self.collider_records: list[tuple] = []
        self.material_descs: dict[str, matlib.MaterialDesc] = {}
        self.texture_names: dict[str, str] = {}       # texture file -> MuJoCo texture name
        self.pbr_maps = _pbr_draws()                   # materials carry normal / ORM / ... maps for the pbr backend
        self.part_records: dict[str, list[geom_subsets.PartGeom]] = {}   # mesh -> its GeomSubset part geoms
        self.mesh_count = 0
        self.has_lights = False
        self.ambient = np.zeros(3)
        self.sky_rgb: np.ndarray | None = None
        self.sky_maps: list[tuple[environment_map.EnvironmentMap, np.ndarray, np.ndarray]] = []
        self.sky_flat = np.zeros(3)                      # untextured domes' share of the background
        self.joint_plan = jointmap.JointPlan()
        self.free_poses: dict[str, np.ndarray] = {}     # free body -> its current (position, quaternion)
        self.free_velocities: dict[str, tuple[np.ndarray, np.ndarray]] = {}   # world (linear, angular rad/s)

    # ---- options -------------------------------------------------------
    def configure(self) -> None:
        spec = self.spec
        spec.compiler.degree = False          # joint ranges are given in radians
        spec.compiler.boundmass = 1e-6
        spec.compiler.boundinertia = 1e-9
        spec.option.timestep = 1.0 / PHYSICS_STEPS_PER_SECOND
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
        spec.option.impratio = 10.0
        up = UsdGeom.GetStageUpAxis(self.stage)
        spec.option.gravity = [0, -9.81, 0] if up == UsdGeom.Tokens.y else [0, 0, -9.81]
        self.configure_physics_scene(up)
        vis = spec.visual
        vis.global_.offwidth, vis.global_.offheight = self.offscreen
        vis.quality.shadowsize, vis.quality.offsamples = render_quality(max(self.offscreen))
        # Cameras get their own near/far from USD; these two (relative to the model extent)
        # only bound MuJoCo's shadow-map depth range, so they are kept tight for precision.
        vis.map.znear = 0.01
        vis.map.zfar = 8.0

    def configure_physics_scene(self, up: str) -> None:
        """Gravity and physics step from the first ``UsdPhysics.Scene`` prim, if any."""
        spec = self.spec
        mpu = UsdGeom.GetStageMetersPerUnit(self.stage) or 1.0
        for prim in self.stage.Traverse():
            if not prim.IsA(UsdPhysics.Scene):
                continue
            scene = UsdPhysics.Scene(prim)
            direction = scene.GetGravityDirectionAttr().Get()
            magnitude = scene.GetGravityMagnitudeAttr().Get()
            # USD's fallback magnitude (-inf) means "earth gravity in stage units".
            g = 9.81 / mpu if magnitude is None or not np.isfinite(magnitude) or magnitude < 0 else float(magnitude)
            if direction is not None and np.linalg.norm(np.array(direction)) > 0:
                d = np.array(direction, dtype=np.float64)
                spec.option.gravity = (d / np.linalg.norm(d) * g).tolist()
            else:
                spec.option.gravity = [0, -g, 0] if up == UsdGeom.Tokens.y else [0, 0, -g]
            attr = prim.GetAttribute("physxScene:timeStepsPerSecond")
            tps = attr.Get() if attr and attr.IsValid() else None
            if tps is not None:
                if not np.isfinite(tps) or tps <= 0:
                    raise CompileError(f"physxScene:timeStepsPerSecond of {prim.GetPath()} is {tps!r}; "
                                       f"it must be a positive number of physics steps per second")
                spec.option.timestep = 1.0 / float(tps)
            return

    # ---- materials -----------------------------------------------------
    def material(self, prim: Usd.Prim) -> str | None:
        material = matlib.bound_material(prim)
        if material is None:
            return None
        path = str(material.GetPath())
        if path in self.material_names:
            return path
        desc = matlib.describe(material)
        m = self.spec.add_material(name=path)
        m.rgba = list(desc.rgba)
        m.specular = 0.5 * (1.0 - desc.roughness)
        m.shininess = max(0.0, 1.0 - desc.roughness)
        m.reflectance = 0.0
        m.emission = desc.emission
        if desc.texture:
            m.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = self.texture(desc.texture, path)
            m.texrepeat = [desc.texture_scale[0], desc.texture_scale[1]]
            m.texuniform = False
            if self.pbr_maps:     # the classic rasteriser reads only the colour role: the rest only where pbr draws
                for role, file in matlib.texture_maps(material).items():
                    if role in MAP_TEXTURE_ROLES:
                        m.textures[MAP_TEXTURE_ROLES[role]] = self.texture(file, path, linear=role != "emissive")
        self.material_names[path] = path
        self.material_descs[path] = desc
        return path

    def texture(self, file: str, material_path: str, linear: bool = False) -> str:
        """The MuJoCo texture holding image ``file`` (added once, however many materials use it); ``linear``:
        data, not colour (normal, occlusion / roughness / metallic, opacity maps), so never sRGB-decoded."""
        key = f"{file}#linear" if linear else file
        name = self.texture_names.get(key)
        if name is not None:
            return name
        try:
            rgb = texture_images.load_rgb(file)
        except texture_images.TextureFileError as exc:
            raise CompileError(f"material {material_path}: {exc}") from None
        name = f"tex:{key}"
        tex = self.spec.add_texture(name=name, type=mujoco.mjtTexture.mjTEXTURE_2D, width=rgb.shape[1],
                                    height=rgb.shape[0], nchannel=3)
        tex.data = rgb.tobytes()
        if linear:
            tex.colorspace = mujoco.mjtColorSpace.mjCOLORSPACE_LINEAR
        self.texture_names[key] = name
        return name

    def mesh_uvs(self, prim: Usd.Prim, material: str | None):
        """Texture coordinates of Mesh ``prim`` for its bound material (UV set and transform), or None."""
        desc = self.material_descs.get(material) if material else None
        name, transform = None, None
        if desc is not None and desc.texture:
            name = desc.texture_primvar
            transform = UvTransform(scale=desc.uv_scale, rotation=desc.uv_rotation + desc.texture_rotate,
                                    translation=desc.uv_translation)
        try:
            return mesh_texcoords(prim, name, transform)
        except TexcoordError as exc:
            raise CompileError(str(exc)) from None

    # ---- geometry ------------------------------------------------------
    def body_for_rigid(self, root: Usd.Prim):
        path = str(root.GetPath())
        if path in self.body_records:
            return self.body_records[path]
        link = self.joint_plan.links.get(path)
        kinematic = _is_kinematic(root)
        if link is not None:
            body = self.add_link(link)
        else:
            t, r, _ = decompose(world_matrix(root, self.cache))
            q = matrix_to_quat_wxyz(r)
            # A free body's reference orientation is the identity (its current one goes into qpos at
            # bind time): constants MuJoCo derives at qpos0 (inverse inertia weights) then do not
            # depend on where the body happens to be when the stage is compiled.
            body = self.spec.worldbody.add_body(name=path, pos=t.tolist(),
                                                quat=q.tolist() if kinematic else [1.0, 0.0, 0.0, 0.0],
                                                mocap=kinematic)
            if not kinematic:
                body.add_freejoint(name=f"{path}#free")
                self.free_poses[path] = np.concatenate([t, q])
                self.free_velocities[path] = authored_velocity(root)
        if not kinematic:
            disable = root.GetAttribute("physxRigidBody:disableGravity")
            if disable and disable.Get():
                body.gravcomp = 1.0
        self.body_records[path] = body
        self.body_mass[path] = _mass_api_values(root)
        return body

    def in_body_frame(self, prim: Usd.Prim, root: Usd.Prim) -> np.ndarray:
        """``prim``'s transform in its rigid body's frame (the body's scale kept in it), row-vector 4x4.

        Composed from the local transforms between the two prims rather than from
        their world transforms, so it is exactly the same wherever the body is:
        a recompile mid-simulation then builds a bit-identical body.
        """
        rel, _ = self.cache.ComputeRelativeTransform(prim, root)
        _, _, root_scale = decompose(world_matrix(root, self.cache))
        scale = np.eye(4)
        scale[0, 0], scale[1, 1], scale[2, 2] = clean_scale(root_scale)
        return np.array(rel, dtype=np.float64) @ scale

    def add_link(self, link: jointmap.TreeLink):
        """The MuJoCo body of a tree link: under its parent at the joint's zero pose, with its joint."""
        if link.parent == jointmap.WORLD:
            parent = self.spec.worldbody
        else:
            parent = self.body_for_rigid(self.stage.GetPrimAtPath(link.parent))
        rest = link.rest_pose()
        body = parent.add_body(name=link.body, pos=rest.pos.tolist(), quat=matrix_to_quat_wxyz(rest.rot).tolist())
        j = link.joint
        kinds = {"revolute": mujoco.mjtJoint.mjJNT_HINGE, "prismatic": mujoco.mjtJoint.mjJNT_SLIDE,
                 "spherical": mujoco.mjtJoint.mjJNT_BALL}
        if j.kind in kinds:
            joint = body.add_joint(name=j.path, type=kinds[j.kind], pos=link.child_frame.pos.tolist(),
                                   axis=link.axis_in_child().tolist(), armature=j.armature)
            if j.lower is not None:
                joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
                joint.range = [j.lower, j.upper]
            else:
                joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
        return body

    def add_joint_elements(self) -> None:
        """Tree bodies without geometry, drive actuators, weld constraints and self-collision filters."""
        jp = self.joint_plan
        for body in list(jp.links):
            self.body_for_rigid(self.stage.GetPrimAtPath(body))
        for path in jp.order:
            link = next(lk for lk in jp.links.values() if lk.joint.path == path)
            drive = link.joint.drive
            if drive is None or link.joint.kind not in ("revolute", "prismatic"):
                continue
            act = self.spec.add_actuator(name=path, target=path, trntype=mujoco.mjtTrn.mjTRN_JOINT)
            act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
            act.gainprm[0] = drive.stiffness
            act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            act.biasprm[:3] = [drive.damping * drive.target_velocity, -drive.stiffness, -drive.damping]
            act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
            if np.isfinite(drive.max_force):
                act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
                act.forcerange = [-drive.max_force, drive.max_force]
            else:
                act.forcelimited = mujoco.mjtLimited.mjLIMITED_FALSE
        for weld in jp.welds:
            for body in (weld.body0, weld.body1):
                if body != jointmap.WORLD:
                    self.body_for_rigid(self.stage.GetPrimAtPath(body))
            rel = weld.frame0 @ weld.frame1.inverse()      # body1 in body0's frame when the joint holds
            data = np.zeros(mujoco.mjNEQDATA)
            data[3:6] = rel.pos
            data[6:10] = matrix_to_quat_wxyz(rel.rot)
            data[10] = 1.0                                  # torque scale
            self.spec.add_equality(name=weld.path, type=mujoco.mjtEq.mjEQ_WELD, objtype=mujoco.mjtObj.mjOBJ_BODY,
                                   name1=weld.body0 or "world", name2=weld.body1 or "world",
                                   active=weld.enabled, data=data.tolist())
        for bodies in jp.no_self_collision:
            for i, a in enumerate(bodies):
                for b in bodies[i + 1:]:
                    self.spec.add_exclude(bodyname1=a, bodyname2=b)

    def add_gprim(self, prim: Usd.Prim) -> None:
        path = str(prim.GetPath())
        m_world = world_matrix(prim, self.cache)
        root = rigid_root(prim)
        if root is not None:
            body = self.body_for_rigid(root)
            t, r, scale = decompose(self.in_body_frame(prim, root))
        else:
            t, r, scale = decompose(m_world)
            body = self.spec.worldbody.add_body(name=path, pos=t.tolist(), quat=matrix_to_quat_wxyz(r).tolist(),
                                                mocap=True)
            t, r = np.zeros(3), np.eye(3)
        collides = _collides(prim)
        dynamic = root is not None and not _is_kinematic(root)
        visible = UsdGeom.Imageable(prim).ComputeVisibility(Usd.TimeCode.Default()) != UsdGeom.Tokens.invisible \
            and _is_renderable(prim)
        material = self.material(prim)
        type_name = prim.GetTypeName()
        mesh_data = None
        if type_name in ("Mesh", "Cone"):
            verts, tris = mesh_arrays(prim, scale)
            mesh_name = f"mesh:{path}"
            mesh = self.spec.add_mesh(name=mesh_name, uservert=(verts @ r.T + t).ravel().tolist(),
                                      userface=tris.ravel().tolist())
            uvs = self.mesh_uvs(prim, material) if type_name == "Mesh" else None
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
            parts = geom_subsets.add_part_geoms(self, prim, body, geom, *mesh_data, r, t, MUJOCO_DEFAULT_RGBA)
            if parts:
                geom.group = HIDDEN_GROUP      # it still collides and carries mass; its parts draw it
                self.part_records[path] = parts
        physical = [geom]
        if collides:
            physical = self.collision_shapes(prim, body, geom, mesh_data, t, r, dynamic, root is None)
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

    def collision_shapes(self, prim: Usd.Prim, body, geom, mesh_data, t: np.ndarray, r: np.ndarray,
                         dynamic: bool, static: bool) -> list:
        """The geoms that collide for ``prim``: its own geom, or proxies in :data:`COLLISION_ONLY_GROUP`."""
        type_name = prim.GetTypeName()
        if type_name == "Plane" and not dynamic:
            # PhysX collides a UsdGeom.Plane as an infinite plane; so does MuJoCo's plane geom.
            size = np.array(geom.size, dtype=np.float64)
            plane = body.add_geom(name=f"{prim.GetPath()}#plane", type=mujoco.mjtGeom.mjGEOM_PLANE,
                                  size=[max(size[0], 1e-3), max(size[1], 1e-3), 1.0], pos=list(geom.pos),
                                  quat=list(geom.quat), group=COLLISION_ONLY_GROUP)
            return [plane]
        if type_name != "Mesh":
            return [geom]
        verts, tris = mesh_data[:2]
        approximation = _approximation(prim)
        pieces = colliders.collision_pieces(verts, tris, approximation, dynamic)
        if len(pieces) == 1 and pieces[0].kind == "hull" and len(pieces[0].vertices) == len(np.unique(tris)):
            return [geom]      # the mesh itself is the hull MuJoCo collides with
        made = []
        q = matrix_to_quat_wxyz(r).tolist()
        for i, piece in enumerate(pieces):
            name = f"{prim.GetPath()}#collider{i}"
            if piece.kind == "box":
                made.append(body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=piece.half.tolist(),
                                          pos=(r @ piece.center + t).tolist(), quat=q,
                                          group=COLLISION_ONLY_GROUP))
            elif piece.kind == "sphere":
                made.append(body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_SPHERE,
                                          size=[piece.radius, 0, 0], pos=(r @ piece.center + t).tolist(),
                                          group=COLLISION_ONLY_GROUP))
            else:
                mesh = self.spec.add_mesh(name=f"mesh:{name}", uservert=(piece.vertices @ r.T + t).ravel().tolist())
                mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
                made.append(body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"mesh:{name}",
                                          group=COLLISION_ONLY_GROUP))
        return made

    def assign_masses(self) -> None:
        """Densities and masses from ``MassAPI`` (see the module docstring)."""
        bodies_with_colliders = {root for root, _, _, _, collides in self.mass_records if collides and root}
        for root, prim, geom, physical, collides in self.mass_records:
            if collides:
                friction, priority = _friction(prim)
                for part in physical:
                    part.friction = [friction, 0.005, 0.0001]
                    part.priority = priority
            if root is None:
                for part in physical:
                    part.density = DEFAULT_DENSITY if collides else 0.0
                continue
            mass, density = _mass_api_values(prim)
            if not density:
                density = self.body_mass[root][1] or DEFAULT_DENSITY
            carries_mass = collides or root not in bodies_with_colliders
            if not carries_mass:
                geom.density = 0.0
                continue
            if physical[0] is not geom:
                geom.density = 0.0
            for part in physical:
                part.density = density
                if mass > 0:
                    part.mass = mass / len(physical)

    def add_probes(self) -> None:
        """Collision-free box and sphere that scene queries pose and size (never drawn)."""
        probe = self.spec.worldbody.add_body(name="graphsdg:probe", mocap=True)
        for name, kind in ((PROBE_BOX, mujoco.mjtGeom.mjGEOM_BOX), (PROBE_SPHERE, mujoco.mjtGeom.mjGEOM_SPHERE)):
            probe.add_geom(name=name, type=kind, size=[1e-3, 1e-3, 1e-3], contype=0, conaffinity=0,
                           group=HIDDEN_GROUP, density=0.0)

    # ---- lights --------------------------------------------------------
    def add_light(self, prim: Usd.Prim) -> None:
        path = str(prim.GetPath())
        self.has_lights = True   # even a hidden light means the user lights the stage
        if UsdGeom.Imageable(prim).ComputeVisibility(Usd.TimeCode.Default()) == UsdGeom.Tokens.invisible:
            self.light_records.append((path, lightmap.LIGHT_KINDS[prim.GetTypeName()], []))
            return
        m = world_matrix(prim, self.cache)
        t, r, scale = decompose(m)
        params = lightmap.light_params(prim, scale)
        wb = self.spec.worldbody
        made = []
        if params.kind == "dome":
            up = np.array(up_axis_vector(self.stage))    # the sky light shines down the stage's up axis
            color, direction = params.color, -up
            if params.texture:
                try:
                    env = environment_map.load(params.texture)
                except environment_map.EnvironmentMapError as exc:
                    raise CompileError(f"dome light {path}: {exc}") from None
                # The map tints and scales the dome: irradiance relative to a uniform sky of radiance 1.
                color = params.color * env.up_irradiance / np.pi
                self.sky_maps.append((env, r, params.color))     # display value of radiance 1
                # Light mostly arrives from the map's bright side; keep it from grazing the floor.
                d = r @ env.dominant_direction
                k = int(np.argmax(up))
                d[k] = max(d[k], 0.5)
                direction = -d / np.linalg.norm(d)
            else:
                self.sky_flat = self.sky_flat + params.color
            self.ambient += 0.5 * color
            sky = wb.add_light(name=f"{path}#sky", type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
                               pos=(10 * up).tolist(), dir=direction.tolist(), castshadow=False)
            _set_light_color(sky, 0.5 * color)
            made.append(sky)
            self.sky_rgb = color if self.sky_rgb is None else self.sky_rgb + color
        elif params.kind == "distant":
            light = wb.add_light(name=path, type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL, pos=t.tolist(),
                                 dir=(-r[:, 2]).tolist(), castshadow=params.cast_shadow)
            _set_light_color(light, params.color)
            made.append(light)
        else:
            # MuJoCo's rasteriser draws spot and directional lights only: a spot with a
            # 180-degree cutoff is OpenGL's omnidirectional point light (sphere, cylinder);
            # rect and disk lights emit into the hemisphere below them with cosine falloff.
            area = params.kind in ("rect", "disk")
            light = wb.add_light(name=path, type=mujoco.mjtLightType.mjLIGHT_SPOT, pos=t.tolist(),
                                 dir=(-r[:, 2]).tolist(), castshadow=params.cast_shadow)
            light.attenuation = [0.0, 0.0, 1.0]
            light.cutoff = 90.0 if area else 180.0
            light.exponent = 1.0 if area else 0.0
            _set_light_color(light, params.color)
            made.append(light)
        self.light_records.append((path, params.kind, made))

    def finish_lighting(self) -> None:
        head = self.spec.visual.headlight
        if not self.has_lights:
            # A stage without lights would render black; light it from the camera like
            # Kit's default viewport light so a first script shows something.
            head.active = 1
            head.ambient = [0.3, 0.3, 0.3]
            head.diffuse = [0.6, 0.6, 0.6]
            head.specular = [0.1, 0.1, 0.1]
            return
        # The headlight carries the scene's ambient term (MuJoCo drops it when inactive),
        # so it stays active with no diffuse or specular part.
        head.active = 1
        head.ambient = np.minimum(self.ambient, 10.0).tolist()
        head.diffuse = [0, 0, 0]
        head.specular = [0, 0, 0]
        if self.sky_maps:
            # Textured domes: the background is their maps (summed if several), in display units.
            n = environment_map.FACE_SIZE
            display = np.zeros((6 * n, n, 3), dtype=np.float32) + self.sky_flat.astype(np.float32)
            for env, rotation, scale in self.sky_maps:
                display += environment_map.skybox_faces(env, rotation, n) * scale.astype(np.float32)
            tex = self.spec.add_texture(name=SKY_TEXTURE, type=mujoco.mjtTexture.mjTEXTURE_SKYBOX, width=n,
                                        height=6 * n, nchannel=3)
            tex.data = environment_map.tonemap(display).tobytes()
        elif self.sky_rgb is not None:
            rgb = np.clip(self.sky_rgb, 0, 1)
            self.spec.add_texture(name=SKY_TEXTURE, type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
                                  builtin=mujoco.mjtBuiltin.mjBUILTIN_FLAT, rgb1=rgb.tolist(), rgb2=rgb.tolist(),
                                  width=8, height=8)

    def add_pbr_camera(self) -> None:
        """One MuJoCo camera for the PBR backend to pose at each render product's USD camera (its rays are
        per pixel, so no field of view is needed); only where that backend draws, so the classic model is
        unchanged."""
        if self.pbr_maps:
            self.spec.worldbody.add_camera(name=PBR_CAMERA)

    def size_memory(self) -> None:
        """Skip contact detection when nothing collides; give big scenes a big enough arena.

        MuJoCo's broadphase scratch grows with the square of the body count, so
        thousands of visual-only bodies would overflow the default arena for nothing.
        """
        colliding = bool(self.collider_records)     # proxy shapes collide for their visual geoms
        if not colliding:
            self.spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
        nbody = len(self.geom_records) + len(self.body_records) + 1
        self.spec.memory = max(16 << 20, 16 * nbody * nbody + (8 << 20)) if colliding else -1

    # ---- top level -----------------------------------------------------
    def build(self) -> CompiledScene:
        self.configure()
        predicate = Usd.TraverseInstanceProxies(Usd.PrimIsActive & Usd.PrimIsDefined & ~Usd.PrimIsAbstract)
        prims = list(Usd.PrimRange.Stage(self.stage, predicate))
        joint_prims = [p for p in prims if p.GetTypeName() in jointmap.JOINT_KINDS]
        if joint_prims:
            try:
                self.joint_plan = jointmap.plan(self.stage, joint_prims, rigid_root,
                                                lambda path: _is_kinematic(self.stage.GetPrimAtPath(path)))
            except jointmap.JointError as exc:
                raise CompileError(str(exc)) from None
        for prim in prims:
            type_name = prim.GetTypeName()
            if type_name in lightmap.LIGHT_KINDS:
                self.add_light(prim)
            elif _is_renderable(prim) or (prim.GetTypeName() in GPRIM_TYPES and _collides(prim)):
                # a guide / proxy purpose collider is not drawn but collides (as in PhysX: addGroundPlane's plane)
                try:
                    self.add_gprim(prim)
                except CompileError:
                    raise
                except Exception as exc:  # pxr / mujoco errors: say which prim
                    raise CompileError(f"cannot compile prim {prim.GetPath()} ({type_name}): {exc}") from exc
        self.add_joint_elements()
        self.flex_plans = deformables.add_to_spec(self.spec, prims, self.cache)
        self.finish_lighting()
        self.add_pbr_camera()
        self.assign_masses()
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

    def _bind_joints(self, scene: CompiledScene) -> None:
        """Joint bindings; tree joints start at the value the links' authored poses show."""
        model, data = scene.model, scene.data
        jp = self.joint_plan
        for link in jp.links.values():
            j = link.joint
            b = JointBinding(path=j.path, kind=j.kind, body0=j.body0, body1=j.body1,
                             articulation=jp.articulation.get(link.body, ""), reversed=link.reversed)
            b.joint_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j.path)
            if b.joint_id >= 0:
                b.qpos_adr, b.dof_adr = int(model.jnt_qposadr[b.joint_id]), int(model.jnt_dofadr[b.joint_id])
                parent = jointmap.Frame(np.zeros(3), np.eye(3)) if link.parent == jointmap.WORLD else \
                    jointmap.Frame.of_prim(self.stage.GetPrimAtPath(link.parent), self.cache)
                child = jointmap.Frame.of_prim(self.stage.GetPrimAtPath(link.body), self.cache)
                value = jointmap.measured_position(link, parent, child)
                data.qpos[b.qpos_adr:b.qpos_adr + len(value)] = value
            b.actuator_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, j.path)
            if b.actuator_id >= 0:
                data.ctrl[b.actuator_id] = j.drive.target_position
            scene.joints[j.path] = b
        for weld in jp.welds:
            b = JointBinding(path=weld.path, kind=weld.kind, body0=weld.body0, body1=weld.body1)
            b.eq_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, weld.path)
            scene.joints[weld.path] = b

    def _bind(self, model: mujoco.MjModel, data: mujoco.MjData) -> CompiledScene:
        scene = CompiledScene(model=model, data=data, has_scene_lights=self.has_lights)
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
        rescaled = False
        for path in self.body_records:
            bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, path)
            binding = BodyBinding(path=path, body_id=bid, mocap_id=int(model.body_mocapid[bid]))
            binding.kinematic = binding.mocap_id >= 0
            binding.articulated = path in self.joint_plan.links
            if model.body_jntnum[bid] > 0 and model.jnt_type[model.body_jntadr[bid]] == mujoco.mjtJoint.mjJNT_FREE:
                jid = int(model.body_jntadr[bid])
                binding.qpos_adr, binding.qvel_adr = int(model.jnt_qposadr[jid]), int(model.jnt_dofadr[jid])
            scene.bodies[path] = binding
            mass = self.body_mass[path][0]
            if mass > 0 and model.body_mass[bid] > 0:
                # MassAPI mass on the body overrides the colliders' sum; the inertia keeps its shape.
                factor = mass / model.body_mass[bid]
                model.body_mass[bid] *= factor
                model.body_inertia[bid] *= factor
                rescaled = True
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
        for path, kind, made in self.light_records:
            ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_LIGHT, lt.name) for lt in made]
            scene.lights[path] = LightBinding(path=path, kind=kind, light_ids=ids)
        for path in self.material_names:
            scene.materials[path] = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_MATERIAL, path)
        place_directional_lights(model)
        scene.sky_texture_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXTURE, SKY_TEXTURE)
        # after mj_setConst, which uses the data as scratch: the current state
        for path, b in scene.bodies.items():
            if b.qpos_adr >= 0:
                data.qpos[b.qpos_adr:b.qpos_adr + 7] = self.free_poses[path]
                linear, angular = self.free_velocities[path]
                data.qvel[b.qvel_adr:b.qvel_adr + 3] = linear
                # MuJoCo's free-joint angular velocity is in the body's frame
                data.qvel[b.qvel_adr + 3:b.qvel_adr + 6] = quat_wxyz_to_matrix(self.free_poses[path][3:]).T @ angular
        self._bind_joints(scene)
        mujoco.mj_forward(model, data)
        scene.deformables = deformables.bind(self.flex_plans, model, data, scene.geoms, self.stage)
        return scene


def place_directional_lights(model: mujoco.MjModel) -> None:
    """Put directional lights up-light of the scene so their shadow maps cover it.

    A distant light has no position in USD; MuJoCo draws a directional light's
    shadow from its position, so it is placed at ``center - 2 * extent * dir``.
    """
    center, extent = np.asarray(model.stat.center), float(model.stat.extent)
    for lid in range(model.nlight):
        if model.light_type[lid] == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL:
            d = model.light_dir[lid] / max(np.linalg.norm(model.light_dir[lid]), 1e-12)
            model.light_pos[lid] = center - 2.0 * extent * d


def _set_light_color(light, rgb: np.ndarray) -> None:
    rgb = np.maximum(np.asarray(rgb, dtype=np.float64), 0.0)
    light.diffuse = rgb.tolist()
    light.specular = np.minimum(rgb * 0.3, 0.3).tolist()
    light.ambient = [0.0, 0.0, 0.0]


def compile_stage(stage: Usd.Stage, offscreen: tuple[int, int] = (640, 480)) -> CompiledScene:
    """Compile ``stage`` into a :class:`CompiledScene` (model, data and prim maps).

    ``offscreen`` is the size of MuJoCo's offscreen framebuffer (the largest
    render product).

    Example:
        >>> from graphsdg import stage
        >>> from pxr import UsdGeom
        >>> s = stage.new_stage(); _ = UsdGeom.Cube.Define(s, "/Cube")
        >>> compile_stage(s).model.ngeom
        1
    """
    import time

    start = time.perf_counter()
    scene = _Builder(stage, offscreen).build()
    scene.compile_seconds = time.perf_counter() - start
    return scene


def light_dir_and_pos(prim: Usd.Prim, cache: UsdGeom.XformCache | None = None) -> tuple[np.ndarray, np.ndarray]:
    """World position and -Z direction of a light prim."""
    t, r, _ = decompose(world_matrix(prim, cache))
    return t, -r[:, 2]


