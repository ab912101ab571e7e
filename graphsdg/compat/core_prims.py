"""Isaac compat area: ``isaacsim.core.prims`` views: ``XFormPrim``, ``RigidPrim`` and ``GeometryPrim``.

A view wraps every prim that a path expression (or a list of them) matches,
segment by segment with Isaac's glob rules (``/World/envs/env_*/Cube``,
``/World/Env[1-5]``; :mod:`graphsdg.stage.path_patterns`), and reads or writes
them in batches, as NumPy arrays (Isaac's ``numpy`` backend; poses float32,
quaternions w, x, y, z). ``indices`` select a subset.

* :class:`XFormPrim`: world and local poses, scales, visibility, visual
  materials, a default state that ``post_reset()`` (``World.reset()``) restores.
  Poses are the stage's: physics writes simulated poses to USD after every step,
  so ``usd=False`` (Isaac's Fabric read) returns the same values.
* :class:`RigidPrim`: also velocities, masses, inertias, centres of mass,
  densities, forces. While physics runs (``SimulationManager.is_simulating()``:
  the timeline played or ``initialize_physics()``) poses and velocities go
  through the simulation (``_physics_view``: :class:`graphsdg.physics.rigid_body_tensor_view.RigidBodyTensorView`);
  before that, through the USD attributes, as Isaac's views do before their
  physics handles exist (``physics:angularVelocity`` is then in degrees per
  second, as authored). Forces act during the next physics step only.
* :class:`GeometryPrim`: colliders: collision on/off, mesh approximations,
  physics materials; PhysX contact offsets and torsional patch radii are
  authored (MuJoCo reads the rest offset only, docs/physics.md).

Example:
    >>> import numpy as np
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> for i in range(3):
    ...     _ = rep.functional.create.cube(name=f"Box_{i}", position=(i, 0, 0))
    >>> view = XFormPrim("/Box_*", name="boxes")
    >>> view.count, view.get_world_poses()[0][:, 0].tolist()
    (3, [0.0, 1.0, 2.0])
"""
from __future__ import annotations

import logging
import types
from typing import Any, Sequence

import mujoco
import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics, UsdShade

from graphsdg.compat import core_numpy
from graphsdg.compat.core_materials import OmniGlass, OmniPBR, PhysicsMaterial, PreviewSurface, VisualMaterial
from graphsdg.compat.core_types import DynamicsViewState, XFormPrimViewState
from graphsdg.compat.core_utils_prims import is_prim_non_root_articulation_link
from graphsdg.compat.experimental_arguments import warn_once
from graphsdg.compat.modules import CompatError, CompatModule, CompatObject
from graphsdg.compat.simulation_manager import SimulationManager
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz, quat_wxyz_to_matrix
from graphsdg.physics.forces import apply_force_at_pos
from graphsdg.physics.rigid_body_tensor_view import RigidBodyTensorView
from graphsdg.physics.world_pose import set_world_pose
from graphsdg.runtime import runtime
from graphsdg.stage.context import get_stage
from graphsdg.stage.path_patterns import match_prim_paths
from graphsdg.stage.xform import set_local_pose

log = logging.getLogger("carb")
_np = core_numpy.backend_utils()


def _array(values: Any, count: int, width: int, what: str) -> np.ndarray:
    """``values`` (list, array or ``.numpy()``-able) as a float64 ``(count, width)`` array."""
    raw = values.numpy() if hasattr(values, "numpy") and not isinstance(values, np.ndarray) else values
    try:
        arr = np.asarray(raw, dtype=np.float64)
        arr = np.broadcast_to(arr.reshape(-1, width) if arr.size == count * width else arr, (count, width))
    except (TypeError, ValueError):
        raise ValueError(f"{what} {values!r} must have shape ({count}, {width})") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} {values!r} holds a value that is not finite")
    return np.array(arr)


def _column(values: Any, count: int, what: str) -> np.ndarray:
    return _array(np.asarray(values, dtype=np.float64).reshape(-1, 1) if np.ndim(values) else values, count, 1,
                  what)[:, 0]


class XFormPrim(CompatObject):
    """``isaacsim.core.prims.XFormPrim``: a view of Xformable prims (see the module docstring)."""

    _compat_name = "isaacsim.core.prims.XFormPrim"

    def __init__(self, prim_paths_expr: str | list[str], name: str = "xform_prim_view", positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None, visibilities: Any = None,
                 reset_xform_properties: bool = True, usd: bool = True) -> None:
        backend = SimulationManager.get_backend()
        if backend != "numpy":
            raise CompatError(f"isaacsim.core.prims views with backend {backend!r} (SimulationManager.set_backend) are "
                              f"not available in graphsdg's compat mode: the core API runs its NumPy backend only. "
                              f"See docs/porting.md.")
        exprs = list(prim_paths_expr) if isinstance(prim_paths_expr, (list, tuple)) else [prim_paths_expr]
        self._regex_prim_paths = exprs
        self._prim_paths: list[str] = []
        for expr in exprs:
            self._prim_paths += [p for p in match_prim_paths(str(expr)) if p not in self._prim_paths]
        if not self._prim_paths:
            raise ValueError(f"prim path expression {exprs} matches no prim; a prim matching it must exist before "
                             f"it is wrapped as a view")
        stage = get_stage()
        self._prims = [stage.GetPrimAtPath(p) for p in self._prim_paths]
        self._name = name
        self._count = len(self._prim_paths)
        self._is_valid = True
        self._backend = "numpy"
        self._device = None
        self._backend_utils = _np
        self._applied_visual_materials: list[VisualMaterial | None] = [None] * self._count
        self._non_root_link = is_prim_non_root_articulation_link(self._prim_paths[0])
        self._default_state: XFormPrimViewState | None = None
        not_xformable = [p for p, prim in zip(self._prim_paths, self._prims) if not prim.IsA(UsdGeom.Xformable)]
        if not_xformable:
            raise ValueError(f"prims {not_xformable} are not Xformable; {type(self).__name__} wraps prims with "
                             f"a transform")
        if not self._non_root_link and reset_xform_properties:
            self._set_xform_properties()
        if not self._non_root_link:
            if translations is not None and positions is not None:
                raise ValueError("translations (local) and positions (world) cannot both be given")
            if translations is not None:
                XFormPrim.set_local_poses(self, translations, orientations)
            elif positions is not None or orientations is not None:
                XFormPrim.set_world_poses(self, positions, orientations)
            if scales is not None:
                XFormPrim.set_local_scales(self, scales)
        if visibilities is not None:
            XFormPrim.set_visibilities(self, visibilities)
        if not self._non_root_link:
            pos, quat = XFormPrim.get_world_poses(self)
            self._default_state = XFormPrimViewState(positions=pos, orientations=quat)

    # ---- description -----------------------------------------------------------------------------------
    @property
    def prim_paths(self) -> list[str]:
        """Paths of the wrapped prims."""
        return list(self._prim_paths)

    @property
    def name(self) -> str:
        """The view's name (its key in ``World.scene``)."""
        return self._name

    @property
    def count(self) -> int:
        """How many prims the view wraps."""
        return self._count

    @property
    def prims(self) -> list[Usd.Prim]:
        """The wrapped ``Usd.Prim`` objects."""
        return list(self._prims)

    @property
    def initialized(self) -> bool:
        """Whether physics is running (Isaac: the view's physics handles exist)."""
        return SimulationManager.is_simulating()

    @property
    def is_non_root_articulation_link(self) -> bool:
        """Whether the prims are articulation links moved by joints (their poses cannot be set)."""
        return self._non_root_link

    def is_valid(self, indices: Any = None) -> bool:
        """Whether every selected prim still exists."""
        idx = self._indices(indices)
        return self._is_valid and all(self._prims[i].IsValid() for i in idx)

    def _check(self) -> None:
        if not self._is_valid:
            raise RuntimeError(f"prim view {self._regex_prim_paths} was destroyed")
        gone = [p for p, prim in zip(self._prim_paths, self._prims) if not prim.IsValid()]
        if gone:
            raise RuntimeError(f"prim view {self._name!r}: the prims {gone} no longer exist on the stage")

    def _indices(self, indices: Any) -> np.ndarray:
        return _np.resolve_indices(indices, self._count)

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Nothing to create: graphsdg's views read the simulation directly."""

    def post_reset(self) -> None:
        """Return the prims to their default state (what ``World.reset()`` does to views in its scene)."""
        self._on_post_reset()

    def _on_post_reset(self) -> None:
        if self._non_root_link or self._default_state is None:
            return
        XFormPrim.set_world_poses(self, self._default_state.positions, self._default_state.orientations)

    def destroy(self) -> None:
        """Invalidate the view (every later call raises)."""
        self._is_valid = False

    # ---- xform ops --------------------------------------------------------------------------------------
    def _set_xform_properties(self) -> None:
        """Give every prim Isaac's translate, orient, scale ops (other rotation ops removed), keeping its world pose."""
        positions, orientations = XFormPrim.get_world_poses(self)
        removed = ("xformOp:rotateX", "xformOp:rotateY", "xformOp:rotateZ", "xformOp:rotateXYZ", "xformOp:rotateXZY",
                   "xformOp:rotateYXZ", "xformOp:rotateYZX", "xformOp:rotateZXY", "xformOp:rotateZYX",
                   "xformOp:transform")
        for prim in self._prims:
            names = prim.GetPropertyNames()
            xformable = UsdGeom.Xformable(prim)
            xformable.ClearXformOpOrder()
            for name in names:
                if name in removed:
                    prim.RemoveProperty(name)
            if "xformOp:scale" not in names:
                scale_op = xformable.AddXformOp(UsdGeom.XformOp.TypeScale, UsdGeom.XformOp.PrecisionDouble, "")
                scale_op.Set(Gf.Vec3d(1.0, 1.0, 1.0))
            else:
                scale_op = UsdGeom.XformOp(prim.GetAttribute("xformOp:scale"))
                if "xformOp:scale:unitsResolve" in names:   # fold the units scale in, as Isaac does
                    folded = np.array(scale_op.Get()) * np.array(prim.GetAttribute("xformOp:scale:unitsResolve").Get())
                    scale_op.GetAttr().Set(type(scale_op.Get())(*folded.tolist()))
                    prim.RemoveProperty("xformOp:scale:unitsResolve")
            translate_op = (UsdGeom.XformOp(prim.GetAttribute("xformOp:translate")) if "xformOp:translate" in names
                            else xformable.AddXformOp(UsdGeom.XformOp.TypeTranslate,
                                                      UsdGeom.XformOp.PrecisionDouble, ""))
            orient_op = (UsdGeom.XformOp(prim.GetAttribute("xformOp:orient")) if "xformOp:orient" in names
                         else xformable.AddXformOp(UsdGeom.XformOp.TypeOrient, UsdGeom.XformOp.PrecisionDouble, ""))
            for name in names:   # a units-resolve rotation would otherwise sit outside the op order
                if name.startswith("xformOp:") and name.endswith(":unitsResolve") and name != "xformOp:scale:unitsResolve":
                    prim.RemoveProperty(name)
            xformable.SetXformOpOrder([translate_op, orient_op, scale_op])
        XFormPrim.set_world_poses(self, positions, orientations)

    # ---- poses ------------------------------------------------------------------------------------------
    def get_world_poses(self, indices: Any = None, usd: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """(positions (M, 3), orientations (M, 4) w, x, y, z) in the world frame, float32."""
        self._check()
        idx = self._indices(indices)
        pos = np.zeros((len(idx), 3), dtype=np.float32)
        quat = np.zeros((len(idx), 4), dtype=np.float32)
        for k, i in enumerate(idx):
            m = np.array(UsdGeom.Xformable(self._prims[i]).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
            t, r, _ = decompose(m)
            pos[k], quat[k] = t, matrix_to_quat_wxyz(r)
        return pos, quat

    def set_world_poses(self, positions: Any = None, orientations: Any = None, indices: Any = None,
                        usd: bool = True) -> None:
        """Teleport the prims to world positions and / or orientations (w, x, y, z); world scales are kept."""
        self._check()
        idx = self._indices(indices)
        pos = None if positions is None else _array(positions, len(idx), 3, "positions")
        quat = None if orientations is None else _unit_quats(orientations, len(idx))
        for k, i in enumerate(idx):
            set_world_pose(self._prims[i], None if pos is None else pos[k], None if quat is None else quat[k])

    def get_local_poses(self, indices: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """(translations (M, 3), orientations (M, 4)) relative to each prim's parent, float32."""
        self._check()
        idx = self._indices(indices)
        pos = np.zeros((len(idx), 3), dtype=np.float32)
        quat = np.zeros((len(idx), 4), dtype=np.float32)
        for k, i in enumerate(idx):
            m = np.array(UsdGeom.Xformable(self._prims[i]).GetLocalTransformation(Usd.TimeCode.Default()))
            t, r, _ = decompose(m)
            pos[k], quat[k] = t, matrix_to_quat_wxyz(r)
        return pos, quat

    def set_local_poses(self, translations: Any = None, orientations: Any = None, indices: Any = None) -> None:
        """Set translations and / or orientations (w, x, y, z) relative to each prim's parent."""
        self._check()
        idx = self._indices(indices)
        t = None if translations is None else _array(translations, len(idx), 3, "translations")
        q = None if orientations is None else _unit_quats(orientations, len(idx))
        for k, i in enumerate(idx):
            set_local_pose(self._prims[i], position=None if t is None else t[k], rotation=None if q is None else q[k])

    def get_world_scales(self, indices: Any = None) -> np.ndarray:
        """Per-axis world scales (M, 3), float32."""
        self._check()
        idx = self._indices(indices)
        return np.array([decompose(np.array(UsdGeom.Xformable(self._prims[i]).ComputeLocalToWorldTransform(
            Usd.TimeCode.Default())))[2] for i in idx], dtype=np.float32).reshape(-1, 3)

    def get_local_scales(self, indices: Any = None) -> np.ndarray:
        """Per-axis local scales (M, 3), float32."""
        self._check()
        idx = self._indices(indices)
        return np.array([decompose(np.array(UsdGeom.Xformable(self._prims[i]).GetLocalTransformation(
            Usd.TimeCode.Default())))[2] for i in idx], dtype=np.float32).reshape(-1, 3)

    def set_local_scales(self, scales: Any, indices: Any = None) -> None:
        """Set per-axis local scales (M, 3)."""
        self._check()
        idx = self._indices(indices)
        s = _array(scales, len(idx), 3, "scales")
        for k, i in enumerate(idx):
            set_local_pose(self._prims[i], scale=s[k])

    # ---- default state ----------------------------------------------------------------------------------
    def get_default_state(self) -> XFormPrimViewState:
        """The world poses :meth:`post_reset` restores (the poses at construction unless set)."""
        self._check()
        if self._non_root_link:
            log.warning("This view corresponds to non root links that are included in an articulation")
        return self._default_state

    def set_default_state(self, positions: Any = None, orientations: Any = None, indices: Any = None) -> None:
        """Set the world poses :meth:`post_reset` restores."""
        self._check()
        if self._non_root_link:
            log.warning("This view corresponds to non root links that are included in an articulation")
            return
        state = self._default_state or XFormPrimViewState(*XFormPrim.get_world_poses(self))
        idx = self._indices(indices)
        if positions is not None:
            state.positions = np.array(state.positions, dtype=np.float32)
            state.positions[idx] = _array(positions, len(idx), 3, "positions")
        if orientations is not None:
            state.orientations = np.array(state.orientations, dtype=np.float32)
            state.orientations[idx] = _unit_quats(orientations, len(idx))
        self._default_state = state

    # ---- visibility -------------------------------------------------------------------------------------
    def set_visibilities(self, visibilities: Any, indices: Any = None) -> None:
        """Make the selected prims visible (True) or invisible (False)."""
        self._check()
        idx = self._indices(indices)
        flags = np.broadcast_to(np.asarray(visibilities).reshape(-1), (len(idx),))
        for flag, i in zip(flags, idx):
            imageable = UsdGeom.Imageable(self._prims[i])
            imageable.MakeVisible() if bool(flag) else imageable.MakeInvisible()

    def get_visibilities(self, indices: Any = None) -> np.ndarray:
        """Whether each selected prim is visible (its computed visibility), shape (M,)."""
        self._check()
        return np.array([UsdGeom.Imageable(self._prims[i]).ComputeVisibility(Usd.TimeCode.Default())
                         != UsdGeom.Tokens.invisible for i in self._indices(indices)], dtype=bool)

    # ---- visual materials -------------------------------------------------------------------------------
    def apply_visual_materials(self, visual_materials: VisualMaterial | list[VisualMaterial],
                               weaker_than_descendants: bool | list[bool] | None = None, indices: Any = None) -> None:
        """Bind a visual material to every selected prim, or one per selected prim (a list)."""
        self._check()
        idx = self._indices(indices)
        if isinstance(visual_materials, (list, tuple)):
            if len(visual_materials) != len(idx):
                raise ValueError(f"{len(visual_materials)} visual materials for {len(idx)} selected prims")
            materials = list(visual_materials)
            weaker = [False] * len(idx) if weaker_than_descendants is None else list(weaker_than_descendants)
            if len(weaker) != len(materials):
                raise ValueError(f"{len(weaker)} weaker_than_descendants flags for {len(materials)} materials")
        else:
            materials = [visual_materials] * len(idx)
            weaker = [bool(weaker_than_descendants)] * len(idx)
        for material, weak, i in zip(materials, weaker, idx):
            if not hasattr(material, "material"):
                raise TypeError(f"{material!r} is not a visual material (isaacsim.core.api.materials)")
            strength = UsdShade.Tokens.weakerThanDescendants if weak else UsdShade.Tokens.strongerThanDescendants
            UsdShade.MaterialBindingAPI.Apply(self._prims[i]).Bind(material.material, bindingStrength=strength)
            self._applied_visual_materials[i] = material

    def get_applied_visual_materials(self, indices: Any = None) -> list[VisualMaterial | None]:
        """The visual material bound to each selected prim (recognised PreviewSurface / OmniPBR / OmniGlass
        bindings are wrapped; None where nothing or an unrecognised material is bound)."""
        self._check()
        out = []
        for i in self._indices(indices):
            if self._applied_visual_materials[i] is None:
                self._applied_visual_materials[i] = _wrap_bound_material(self._prims[i])
            out.append(self._applied_visual_materials[i])
        return out

    def is_visual_material_applied(self, indices: Any = None) -> list[bool]:
        """Whether each selected prim has a direct material binding."""
        self._check()
        return [bool(UsdShade.MaterialBindingAPI(self._prims[i]).GetDirectBinding().GetMaterialPath())
                for i in self._indices(indices)]


def _unit_quats(orientations: Any, count: int) -> np.ndarray:
    q = _array(orientations, count, 4, "orientations")
    norms = np.linalg.norm(q, axis=1)
    if np.any(norms < 1e-9):
        raise ValueError(f"orientations {orientations!r} hold a zero quaternion; expected (w, x, y, z) unit "
                         f"quaternions")
    return q / norms[:, None]


def _wrap_bound_material(prim: Usd.Prim) -> VisualMaterial | None:
    """A core-API wrapper of the material directly bound to ``prim``, by its shader's kind."""
    path = UsdShade.MaterialBindingAPI(prim).GetDirectBinding().GetMaterialPath()
    if not path:
        return None
    stage = prim.GetStage()
    material = UsdShade.Material(stage.GetPrimAtPath(path))
    shader = None
    source = material.ComputeSurfaceSource()
    if source and source[0] and source[0].GetPrim().IsValid():
        shader = source[0]
    else:
        for name in ("shader", "Shader"):
            if stage.GetPrimAtPath(path.AppendChild(name)).IsValid():
                shader = UsdShade.Shader(stage.GetPrimAtPath(path.AppendChild(name)))
                break
    if shader is None:
        mdl = material.ComputeSurfaceSource("mdl")
        shader = mdl[0] if mdl and mdl[0] and mdl[0].GetPrim().IsValid() else None
    if shader is None:
        log.warning(f"the material bound to {prim.GetPath()} has no shader graphsdg's core API recognises")
        return None
    sub = shader.GetPrim().GetAttribute("info:mdl:sourceAsset:subIdentifier").Get()
    if shader.GetImplementationSource() == "id" and shader.GetShaderId() == "UsdPreviewSurface":
        return PreviewSurface(str(path), shader=shader)
    if sub == "OmniGlass":
        return OmniGlass(str(path), shader=shader)
    if sub == "OmniPBR":
        return OmniPBR(str(path), shader=shader)
    log.warning(f"the shader of the material bound to {prim.GetPath()} is not a PreviewSurface, OmniPBR or OmniGlass")
    return None


class RigidPrim(XFormPrim):
    """``isaacsim.core.prims.RigidPrim``: a view of rigid bodies (``RigidBodyAPI`` is applied where missing)."""

    _compat_name = "isaacsim.core.prims.RigidPrim"

    def __init__(self, prim_paths_expr: str | list[str], name: str = "rigid_prim_view", positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None, visibilities: Any = None,
                 reset_xform_properties: bool = True, masses: Any = None, densities: Any = None,
                 linear_velocities: Any = None, angular_velocities: Any = None, track_contact_forces: bool = False,
                 prepare_contact_sensors: bool = True, disable_stablization: bool = True,
                 contact_filter_prim_paths_expr: list[str] | None = None, max_contact_count: int = 0) -> None:
        if contact_filter_prim_paths_expr:
            raise CompatNotSupported("RigidPrim(contact_filter_prim_paths_expr=...)", "graphsdg reports each body's "
                                     "net contact force only (track_contact_forces=True), not per-filter matrices")
        self._track_contact_forces = bool(track_contact_forces)
        self._physics_view: RigidBodyTensorView | None = None
        super().__init__(prim_paths_expr, name, positions, translations, orientations, scales, visibilities,
                         reset_xform_properties)
        for prim in self._prims:
            if not prim.HasAPI(UsdPhysics.RigidBodyAPI):
                UsdPhysics.RigidBodyAPI.Apply(prim)
        if not self._non_root_link:
            if linear_velocities is not None:
                self.set_linear_velocities(linear_velocities)
            if angular_velocities is not None:
                self.set_angular_velocities(angular_velocities)
        if masses is not None:
            self.set_masses(masses)
        if densities is not None:
            self.set_densities(densities)
        # the velocities a reset returns to: those the bodies start with (authored ones; angular in rad/s, as the
        # simulation reads it), not whatever the first physics step left
        idx = np.arange(self._count)
        self._dynamics_default_state = DynamicsViewState(None, None, self._usd_velocities(idx, False),
                                                         np.radians(self._usd_velocities(idx, True)))

    # ---- physics handle ---------------------------------------------------------------------------------
    def is_physics_handle_valid(self) -> bool:
        """Whether physics runs (then reads and writes go through the simulation)."""
        return SimulationManager.is_simulating()

    def _view(self) -> RigidBodyTensorView | None:
        """The simulation's tensor view of the bodies while physics runs (``_physics_view``), else None."""
        if not self.is_physics_handle_valid():
            self._physics_view = None
            return None
        if self._physics_view is None:
            self._physics_view = RigidBodyTensorView(self._prim_paths)
        return self._physics_view

    def initialize(self, physics_sim_view: Any = None) -> None:
        """Bind the view to the running simulation and take the default velocities (the current ones) if unset."""
        if self._view() is None:
            return
        state = self._dynamics_default_state
        state.positions, state.orientations = self._default_state.positions, self._default_state.orientations
        if state.linear_velocities is None:
            state.linear_velocities = self.get_linear_velocities()
        if state.angular_velocities is None:
            state.angular_velocities = self.get_angular_velocities()

    @property
    def num_shapes(self) -> int:
        """Collision shapes of the first body (its colliding geoms in the compiled model)."""
        sim = runtime().sim
        sim.sync_dirty_prims()
        body = sim.body(self._prim_paths[0])
        model = sim.model
        return int(np.count_nonzero((model.geom_bodyid == body.body_id) & (model.geom_contype != 0)))

    # ---- poses ------------------------------------------------------------------------------------------
    def get_world_poses(self, indices: Any = None, clone: bool = True, usd: bool = True
                        ) -> tuple[np.ndarray, np.ndarray]:
        """(positions, orientations) of the bodies: simulated while physics runs, else the stage's."""
        view = self._view()
        if view is None:
            return XFormPrim.get_world_poses(self, indices)
        pos, quat = view.bodies.get_world_poses(self._indices(indices))
        return pos.astype(np.float32), quat.astype(np.float32)

    def set_world_poses(self, positions: Any = None, orientations: Any = None, indices: Any = None,
                        usd: bool = True) -> None:
        """Teleport the bodies (velocities kept)."""
        view = self._view()
        if view is None:
            return XFormPrim.set_world_poses(self, positions, orientations, indices)
        idx = self._indices(indices)
        pos = None if positions is None else _array(positions, len(idx), 3, "positions")
        quat = None if orientations is None else _unit_quats(orientations, len(idx))
        view.bodies.set_world_poses(pos, quat, idx)

    # ---- velocities -------------------------------------------------------------------------------------
    def _usd_velocities(self, idx: np.ndarray, angular: bool) -> np.ndarray:
        out = np.zeros((len(idx), 3), dtype=np.float32)
        for k, i in enumerate(idx):
            api = UsdPhysics.RigidBodyAPI(self._prims[i])
            value = (api.GetAngularVelocityAttr() if angular else api.GetVelocityAttr()).Get()
            out[k] = value if value is not None else (0.0, 0.0, 0.0)
        return out

    def get_linear_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """World-frame linear velocities (M, 3), m/s."""
        self._check()
        idx = self._indices(indices)
        view = self._view()
        return self._usd_velocities(idx, False) if view is None else \
            view.get_velocities()[idx, :3].astype(np.float32)

    def get_angular_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """World-frame angular velocities (M, 3): rad/s from the simulation, deg/s as authored before it runs."""
        self._check()
        idx = self._indices(indices)
        view = self._view()
        return self._usd_velocities(idx, True) if view is None else \
            view.get_velocities()[idx, 3:].astype(np.float32)

    def get_velocities(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """(M, 6): linear then angular velocities."""
        return np.concatenate([self.get_linear_velocities(indices), self.get_angular_velocities(indices)], axis=1)

    def _set_velocities(self, linear: Any, angular: Any, indices: Any) -> None:
        self._check()
        idx = self._indices(indices)
        lin = None if linear is None else _array(linear, len(idx), 3, "linear velocities")
        ang = None if angular is None else _array(angular, len(idx), 3, "angular velocities")
        view = self._view()
        if view is not None:
            view.bodies.set_velocities(lin, ang, idx)
            return
        for k, i in enumerate(idx):
            api = UsdPhysics.RigidBodyAPI(self._prims[i])
            if lin is not None:
                api.CreateVelocityAttr().Set(Gf.Vec3f(*lin[k].tolist()))
            if ang is not None:
                api.CreateAngularVelocityAttr().Set(Gf.Vec3f(*ang[k].tolist()))

    def set_linear_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set world-frame linear velocities (M, 3)."""
        self._set_velocities(velocities, None, indices)

    def set_angular_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set world-frame angular velocities (M, 3) (rad/s while physics runs, deg/s authored before)."""
        self._set_velocities(None, velocities, indices)

    def set_velocities(self, velocities: Any, indices: Any = None) -> None:
        """Set (M, 6) velocities: linear then angular."""
        v = _array(velocities, len(self._indices(indices)), 6, "velocities")
        self._set_velocities(v[:, :3], v[:, 3:], indices)

    # ---- forces -----------------------------------------------------------------------------------------
    def apply_forces(self, forces: Any, indices: Any = None, is_global: bool = True) -> None:
        """Push the bodies' centres of mass with forces (M, 3) N during the next physics step."""
        self.apply_forces_and_torques_at_pos(forces=forces, indices=indices, is_global=is_global)

    def apply_forces_and_torques_at_pos(self, forces: Any = None, torques: Any = None, positions: Any = None,
                                        indices: Any = None, is_global: bool = True) -> None:
        """Forces (M, 3) N at ``positions`` (M, 3) (the centres of mass when None) and torques (M, 3) N m, for the
        next physics step; world frame when ``is_global``, else each body's frame (positions too)."""
        self._check()
        if forces is None and torques is None:
            raise ValueError("apply_forces_and_torques_at_pos needs forces and / or torques")
        idx = self._indices(indices)
        f = np.zeros((len(idx), 3)) if forces is None else _array(forces, len(idx), 3, "forces")
        tau = np.zeros((len(idx), 3)) if torques is None else _array(torques, len(idx), 3, "torques")
        at = None if positions is None else _array(positions, len(idx), 3, "positions")
        sim = runtime().sim
        sim.sync_dirty_prims()
        data = sim.data
        for k, i in enumerate(idx):
            body = sim.body(self._prim_paths[i])
            rot = data.xmat[body.body_id].reshape(3, 3)
            com = data.xipos[body.body_id]
            force, torque = (f[k], tau[k]) if is_global else (rot @ f[k], rot @ tau[k])
            point = com if at is None else (at[k] if is_global else data.xpos[body.body_id] + rot @ at[k])
            if np.any(force):
                apply_force_at_pos(body.path, force, point)
            if np.any(torque):   # a couple: +F at com + r/2, -F at com - r/2 with r x F = torque
                r = np.cross(torque, [1.0, 0.0, 0.0] if abs(torque[0]) < 0.9 * np.linalg.norm(torque) else
                             [0.0, 1.0, 0.0])
                r /= np.linalg.norm(r)
                couple = np.cross(torque, r)
                apply_force_at_pos(body.path, couple, com + r / 2)
                apply_force_at_pos(body.path, -couple, com - r / 2)

    # ---- mass properties --------------------------------------------------------------------------------
    def get_masses(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """Masses (M,) kg: simulated while physics runs, else ``physics:mass`` (0 where unset)."""
        self._check()
        idx = self._indices(indices)
        view = self._view()
        if view is not None:
            return view.get_masses()[idx, 0].astype(np.float32)
        return np.array([UsdPhysics.MassAPI(self._prims[i]).GetMassAttr().Get() or 0.0 for i in idx],
                        dtype=np.float32)

    def get_inv_masses(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """Inverse masses (M,) (0 for a massless body)."""
        masses = self.get_masses(indices).astype(np.float64)
        return np.where(masses > 0, 1.0 / np.where(masses > 0, masses, 1.0), 0.0).astype(np.float32)

    def set_masses(self, masses: Any, indices: Any = None) -> None:
        """Set masses (kg): in the running simulation (inertias kept), else authored as ``physics:mass``."""
        self._check()
        idx = self._indices(indices)
        m = _column(masses, len(idx), "masses")
        if np.any(m < 0):
            raise ValueError(f"masses must be >= 0 kg, got {masses!r}")
        view = self._view()
        if view is not None:
            view.set_masses(m.reshape(-1, 1), idx)
            return
        for value, i in zip(m, idx):
            UsdPhysics.MassAPI.Apply(self._prims[i]).CreateMassAttr().Set(float(value))

    def get_densities(self, indices: Any = None) -> np.ndarray:
        """``physics:density`` (M,) kg/m^3 (0 where unset: the collider default of 1000 applies)."""
        self._check()
        return np.array([UsdPhysics.MassAPI(self._prims[i]).GetDensityAttr().Get() or 0.0
                         for i in self._indices(indices)], dtype=np.float32)

    def set_densities(self, densities: Any, indices: Any = None) -> None:
        """Author ``physics:density`` kg/m^3."""
        self._check()
        idx = self._indices(indices)
        d = _column(densities, len(idx), "densities")
        if np.any(d < 0):
            raise ValueError(f"densities must be >= 0 kg/m^3, got {densities!r}")
        for value, i in zip(d, idx):
            UsdPhysics.MassAPI.Apply(self._prims[i]).CreateDensityAttr().Set(float(value))

    def _compiled_bodies(self, idx: np.ndarray) -> tuple[Any, list[int]]:
        sim = runtime().sim
        sim.sync_dirty_prims()
        return sim.model, [sim.body(self._prim_paths[i]).body_id for i in idx]

    def get_inertias(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """Inertia tensors about the centres of mass, in each body's frame, flattened (M, 9) kg m^2."""
        self._check()
        model, bodies = self._compiled_bodies(self._indices(indices))
        out = np.zeros((len(bodies), 9), dtype=np.float32)
        for k, b in enumerate(bodies):
            r = quat_wxyz_to_matrix(model.body_iquat[b])
            out[k] = (r @ np.diag(model.body_inertia[b]) @ r.T).reshape(9)
        return out

    def get_inv_inertias(self, indices: Any = None, clone: bool = True) -> np.ndarray:
        """Inverse inertia tensors (M, 9)."""
        inertias = self.get_inertias(indices).astype(np.float64).reshape(-1, 3, 3)
        return np.linalg.inv(inertias).reshape(-1, 9).astype(np.float32)

    def set_inertias(self, values: Any, indices: Any = None) -> None:
        """Author ``physics:diagonalInertia`` from diagonal (M, 3) or full (M, 9) inertias (their principal
        moments and axes)."""
        self._check()
        idx = self._indices(indices)
        arr = np.asarray(values, dtype=np.float64).reshape(len(idx), -1)
        for row, i in zip(arr, idx):
            api = UsdPhysics.MassAPI.Apply(self._prims[i])
            if row.size == 3:
                api.CreateDiagonalInertiaAttr().Set(Gf.Vec3f(*row.tolist()))
                continue
            moments, axes = np.linalg.eigh(row.reshape(3, 3))
            if np.linalg.det(axes) < 0:
                axes[:, 0] = -axes[:, 0]
            api.CreateDiagonalInertiaAttr().Set(Gf.Vec3f(*moments.tolist()))
            api.CreatePrincipalAxesAttr().Set(Gf.Quatf(*matrix_to_quat_wxyz(axes).tolist()))

    def get_coms(self, indices: Any = None, clone: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Centres of mass in each body's frame: (positions (M, 3), principal-axes orientations (M, 4))."""
        self._check()
        model, bodies = self._compiled_bodies(self._indices(indices))
        return (np.array([model.body_ipos[b] for b in bodies], dtype=np.float32).reshape(-1, 3),
                np.array([model.body_iquat[b] for b in bodies], dtype=np.float32).reshape(-1, 4))

    def set_coms(self, positions: Any = None, orientations: Any = None, indices: Any = None) -> None:
        """Author ``physics:centerOfMass`` / ``physics:principalAxes`` (in each body's frame)."""
        self._check()
        idx = self._indices(indices)
        pos = None if positions is None else _array(positions, len(idx), 3, "positions")
        quat = None if orientations is None else _unit_quats(orientations, len(idx))
        for k, i in enumerate(idx):
            api = UsdPhysics.MassAPI.Apply(self._prims[i])
            if pos is not None:
                api.CreateCenterOfMassAttr().Set(Gf.Vec3f(*pos[k].tolist()))
            if quat is not None:
                api.CreatePrincipalAxesAttr().Set(Gf.Quatf(*quat[k].tolist()))

    # ---- switches -----------------------------------------------------------------------------------------
    def _set_attribute(self, name: str, type_name: Sdf.ValueTypeName, value: Any, indices: Any) -> None:
        self._check()
        for i in self._indices(indices):
            self._prims[i].CreateAttribute(name, type_name).Set(value)

    def enable_rigid_body_physics(self, indices: Any = None) -> None:
        """``physics:rigidBodyEnabled = True``: the prims simulate as bodies."""
        self._set_attribute("physics:rigidBodyEnabled", Sdf.ValueTypeNames.Bool, True, indices)

    def disable_rigid_body_physics(self, indices: Any = None) -> None:
        """``physics:rigidBodyEnabled = False``: the prims become static."""
        self._set_attribute("physics:rigidBodyEnabled", Sdf.ValueTypeNames.Bool, False, indices)

    def enable_gravities(self, indices: Any = None) -> None:
        """``physxRigidBody:disableGravity = False``."""
        self._set_attribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool, False, indices)

    def disable_gravities(self, indices: Any = None) -> None:
        """``physxRigidBody:disableGravity = True`` (MuJoCo compensates the bodies' gravity)."""
        self._set_attribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool, True, indices)

    def set_sleep_thresholds(self, thresholds: Any, indices: Any = None) -> None:
        """Author ``physxRigidBody:sleepThreshold`` (MuJoCo bodies never sleep; warns once)."""
        warn_once("RigidPrim.set_sleep_thresholds", "MuJoCo bodies do not sleep; the threshold is authored only")
        idx = self._indices(indices)
        for value, i in zip(_column(thresholds, len(idx), "thresholds"), idx):
            self._prims[i].CreateAttribute("physxRigidBody:sleepThreshold", Sdf.ValueTypeNames.Float).Set(float(value))

    def get_sleep_thresholds(self, indices: Any = None) -> np.ndarray:
        """``physxRigidBody:sleepThreshold`` (PhysX's default 5e-5 where unset)."""
        out = []
        for i in self._indices(indices):
            attr = self._prims[i].GetAttribute("physxRigidBody:sleepThreshold")
            out.append(attr.Get() if attr and attr.Get() is not None else 5e-5)
        return np.array(out, dtype=np.float32)

    # ---- states -------------------------------------------------------------------------------------------
    def set_default_state(self, positions: Any = None, orientations: Any = None, linear_velocities: Any = None,
                          angular_velocities: Any = None, indices: Any = None) -> None:
        """Set the poses and velocities :meth:`post_reset` restores."""
        XFormPrim.set_default_state(self, positions, orientations, indices)
        state = self._dynamics_default_state
        idx = self._indices(indices)
        for attr, values in (("linear_velocities", linear_velocities), ("angular_velocities", angular_velocities)):
            if values is None:
                continue
            current = getattr(state, attr)
            current = np.zeros((self._count, 3), dtype=np.float32) if current is None else np.array(current)
            current[idx] = _array(values, len(idx), 3, attr)
            setattr(state, attr, current)
        state.positions, state.orientations = self._default_state.positions, self._default_state.orientations

    def get_default_state(self) -> DynamicsViewState:
        """The poses and velocities :meth:`post_reset` restores."""
        state = self._dynamics_default_state
        state.positions, state.orientations = self._default_state.positions, self._default_state.orientations
        return state

    def get_current_dynamic_state(self) -> DynamicsViewState:
        """The bodies' current poses and velocities."""
        pos, quat = self.get_world_poses()
        return DynamicsViewState(pos, quat, self.get_linear_velocities(), self.get_angular_velocities())

    def _on_post_reset(self) -> None:
        XFormPrim._on_post_reset(self)
        if self._non_root_link:
            return
        state = self._dynamics_default_state
        zeros = np.zeros((self._count, 3), dtype=np.float32)
        self._set_velocities(zeros if state.linear_velocities is None else state.linear_velocities,
                             zeros if state.angular_velocities is None else state.angular_velocities, None)

    def get_net_contact_forces(self, indices: Any = None, clone: bool = True, dt: float = 1.0) -> np.ndarray | None:
        """World-frame net contact force on each body (normal and friction of all its contacts, from the last
        physics step) times ``physics_dt / dt``: PhysX's contact impulses for ``dt = 1``, newtons for ``dt`` = the
        physics step. Needs ``track_contact_forces=True`` (else a warning and None, as in Isaac)."""
        self._check()
        if not self._track_contact_forces:
            log.warning("contact forces cannot be retrieved with this API unless the RigidPrim is initialized with "
                        "track_contact_forces= True.")
            return None
        sim = runtime().sim
        sim.sync_dirty_prims()
        bodies = [sim.body(self._prim_paths[i]).body_id for i in self._indices(indices)]
        forces = net_contact_forces(sim.model, sim.data, bodies)
        return (forces * float(sim.model.opt.timestep) / float(dt)).astype(np.float32)

    def get_contact_force_matrix(self, *args: Any, **kwargs: Any) -> np.ndarray:
        """Not mapped: per-filter contact force matrices (raises naming it)."""
        raise CompatNotSupported("RigidPrim.get_contact_force_matrix / get_contact_force_data / get_friction_data",
                                 "graphsdg reports each body's net contact force only (get_net_contact_forces)")

    get_contact_force_data = get_friction_data = get_contact_force_matrix


def net_contact_forces(model: Any, data: Any, bodies: Sequence[int]) -> np.ndarray:
    """(len(bodies), 3) world-frame sums of the contact forces (normal and friction) acting on each MuJoCo body."""
    out = np.zeros((len(bodies), 3))
    rows = {b: k for k, b in enumerate(bodies)}
    wrench = np.zeros(6)
    for i in range(data.ncon):
        contact = data.contact[i]
        b1, b2 = int(model.geom_bodyid[contact.geom1]), int(model.geom_bodyid[contact.geom2])
        if b1 not in rows and b2 not in rows:
            continue
        mujoco.mj_contactForce(model, data, i, wrench)
        # the contact frame's rows are the normal (from geom1 to geom2) and two tangents; the force acts on geom2
        on_second = np.asarray(contact.frame).reshape(3, 3).T @ wrench[:3]
        if b2 in rows:
            out[rows[b2]] += on_second
        if b1 in rows:
            out[rows[b1]] -= on_second
    return out


class CompatNotSupported(AttributeError):
    """A core-API behaviour graphsdg cannot provide (named, with the reason); an ``AttributeError`` as
    :class:`graphsdg.compat.modules.CompatError` is."""

    def __init__(self, what: str, why: str) -> None:
        super().__init__(f"{what} is not available in graphsdg's compat mode: {why}. See docs/porting.md.")


_APPROXIMATIONS = ("none", "convexDecomposition", "convexHull", "boundingSphere", "boundingCube",
                   "meshSimplification", "sdf", "sphereFill")


class GeometryPrim(XFormPrim):
    """``isaacsim.core.prims.GeometryPrim``: a view of gprims with colliders and physics materials."""

    _compat_name = "isaacsim.core.prims.GeometryPrim"

    def __init__(self, prim_paths_expr: str | list[str], name: str = "geometry_prim_view", positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None, visibilities: Any = None,
                 reset_xform_properties: bool = True, collisions: Any = None, track_contact_forces: bool = False,
                 prepare_contact_sensors: bool = False, disable_stablization: bool = True,
                 contact_filter_prim_paths_expr: list[str] | None = None, max_contact_count: int = 0) -> None:
        if track_contact_forces or contact_filter_prim_paths_expr:
            raise CompatNotSupported("GeometryPrim(track_contact_forces=True)",
                                     "graphsdg has no PhysX contact-report views")
        super().__init__(prim_paths_expr, name, positions, translations, orientations, scales, visibilities,
                         reset_xform_properties)
        self._applied_physics_materials: list[PhysicsMaterial | None] = [None] * self._count
        if collisions is not None:   # True: the prim becomes a collider (False leaves it as it is, as in Isaac)
            for flag, i in zip(np.broadcast_to(np.asarray(collisions).reshape(-1), (self._count,)), range(self._count)):
                if bool(flag):
                    self.apply_collision_apis(indices=[i])

    @property
    def geoms(self) -> list[UsdGeom.Gprim]:
        """The prims as ``UsdGeom.Gprim`` schemas."""
        return [UsdGeom.Gprim(p) for p in self._prims]

    def apply_collision_apis(self, indices: Any = None) -> None:
        """Apply ``CollisionAPI`` (and ``MeshCollisionAPI`` on meshes)."""
        for i in self._indices(indices):
            UsdPhysics.CollisionAPI.Apply(self._prims[i])
            if self._prims[i].IsA(UsdGeom.Mesh):
                UsdPhysics.MeshCollisionAPI.Apply(self._prims[i])

    def enable_collision(self, indices: Any = None) -> None:
        """``physics:collisionEnabled = True`` (the API is applied where missing)."""
        for i in self._indices(indices):
            UsdPhysics.CollisionAPI.Apply(self._prims[i]).CreateCollisionEnabledAttr().Set(True)

    def disable_collision(self, indices: Any = None) -> None:
        """``physics:collisionEnabled = False`` on the colliders (prims without ``CollisionAPI`` already do not
        collide)."""
        for i in self._indices(indices):
            if self._prims[i].HasAPI(UsdPhysics.CollisionAPI):
                UsdPhysics.CollisionAPI(self._prims[i]).CreateCollisionEnabledAttr().Set(False)

    def is_collision_enabled(self, indices: Any = None) -> np.ndarray:
        """Whether each prim collides (an enabled ``CollisionAPI``)."""
        out = []
        for i in self._indices(indices):
            prim = self._prims[i]
            value = UsdPhysics.CollisionAPI(prim).GetCollisionEnabledAttr().Get()
            out.append(prim.HasAPI(UsdPhysics.CollisionAPI) and (value is None or bool(value)))
        return np.array(out, dtype=bool)

    def set_collision_approximations(self, approximation_types: str | Sequence[str], indices: Any = None) -> None:
        """Set ``physics:approximation`` (docs/physics.md lists what each becomes in MuJoCo)."""
        idx = self._indices(indices)
        values = [approximation_types] * len(idx) if isinstance(approximation_types, str) else list(approximation_types)
        if len(values) != len(idx):
            raise ValueError(f"{len(values)} approximations for {len(idx)} selected prims")
        for value, i in zip(values, idx):
            if value not in _APPROXIMATIONS:
                raise ValueError(f"collision approximation {value!r} is not one of {list(_APPROXIMATIONS)}")
            UsdPhysics.MeshCollisionAPI.Apply(self._prims[i]).CreateApproximationAttr().Set(value)

    def get_collision_approximations(self, indices: Any = None) -> list[str]:
        """Each prim's ``physics:approximation`` (``"none"`` where unset)."""
        out = []
        for i in self._indices(indices):
            value = UsdPhysics.MeshCollisionAPI(self._prims[i]).GetApproximationAttr().Get() \
                if self._prims[i].HasAPI(UsdPhysics.MeshCollisionAPI) else None
            out.append(str(value) if value else "none")
        return out

    def _set_physx(self, name: str, values: Any, indices: Any, warn: str | None) -> None:
        idx = self._indices(indices)
        if warn:
            warn_once(f"GeometryPrim {name}", warn)
        for value, i in zip(_column(values, len(idx), name), idx):
            self._prims[i].CreateAttribute(name, Sdf.ValueTypeNames.Float).Set(float(value))

    def _get_physx(self, name: str, default: float, indices: Any) -> np.ndarray:
        out = []
        for i in self._indices(indices):
            attr = self._prims[i].GetAttribute(name)
            out.append(attr.Get() if attr and attr.Get() is not None else default)
        return np.array(out, dtype=np.float32)

    def set_contact_offsets(self, offsets: Any, indices: Any = None) -> None:
        """Author ``physxCollision:contactOffset`` (MuJoCo finds contacts where they act; warns once)."""
        self._set_physx("physxCollision:contactOffset", offsets, indices,
                        "MuJoCo makes contacts at touching distance; the contact offset is authored only")

    def get_contact_offsets(self, indices: Any = None) -> np.ndarray:
        """``physxCollision:contactOffset`` (-inf, PhysX's automatic value, where unset)."""
        return self._get_physx("physxCollision:contactOffset", float("-inf"), indices)

    def set_rest_offsets(self, offsets: Any, indices: Any = None) -> None:
        """Author ``physxCollision:restOffset`` (MuJoCo's geom margin: shapes rest that far apart)."""
        self._set_physx("physxCollision:restOffset", offsets, indices, None)

    def get_rest_offsets(self, indices: Any = None) -> np.ndarray:
        """``physxCollision:restOffset`` (0 where unset)."""
        return self._get_physx("physxCollision:restOffset", 0.0, indices)

    def set_torsional_patch_radii(self, radii: Any, indices: Any = None) -> None:
        """Author ``physxCollision:torsionalPatchRadius`` (not simulated; warns once)."""
        self._set_physx("physxCollision:torsionalPatchRadius", radii, indices,
                        "MuJoCo's contacts use sliding friction only; torsional patch radii are authored only")

    def get_torsional_patch_radii(self, indices: Any = None) -> np.ndarray:
        """``physxCollision:torsionalPatchRadius`` (0 where unset)."""
        return self._get_physx("physxCollision:torsionalPatchRadius", 0.0, indices)

    def set_min_torsional_patch_radii(self, radii: Any, indices: Any = None) -> None:
        """Author ``physxCollision:minTorsionalPatchRadius`` (not simulated; warns once)."""
        self._set_physx("physxCollision:minTorsionalPatchRadius", radii, indices,
                        "MuJoCo's contacts use sliding friction only; torsional patch radii are authored only")

    def get_min_torsional_patch_radii(self, indices: Any = None) -> np.ndarray:
        """``physxCollision:minTorsionalPatchRadius`` (0 where unset)."""
        return self._get_physx("physxCollision:minTorsionalPatchRadius", 0.0, indices)

    def apply_physics_materials(self, physics_materials: PhysicsMaterial | list[PhysicsMaterial],
                                weaker_than_descendants: bool | list[bool] | None = None, indices: Any = None) -> None:
        """Bind physics materials (purpose ``physics``): their friction is the prims' contact friction."""
        idx = self._indices(indices)
        materials = list(physics_materials) if isinstance(physics_materials, (list, tuple)) else \
            [physics_materials] * len(idx)
        if len(materials) != len(idx):
            raise ValueError(f"{len(materials)} physics materials for {len(idx)} selected prims")
        weaker = [bool(weaker_than_descendants)] * len(idx) if not isinstance(weaker_than_descendants, (list, tuple)) \
            else list(weaker_than_descendants)
        for material, weak, i in zip(materials, weaker, idx):
            if not isinstance(material, PhysicsMaterial):
                raise TypeError(f"{material!r} is not an isaacsim.core.api.materials.PhysicsMaterial")
            strength = UsdShade.Tokens.weakerThanDescendants if weak else UsdShade.Tokens.strongerThanDescendants
            UsdShade.MaterialBindingAPI.Apply(self._prims[i]).Bind(material.material, bindingStrength=strength,
                                                                   materialPurpose="physics")
            self._applied_physics_materials[i] = material

    def get_applied_physics_materials(self, indices: Any = None) -> list[PhysicsMaterial | None]:
        """The physics material bound to each prim (wrapped; None where none)."""
        out = []
        for i in self._indices(indices):
            if self._applied_physics_materials[i] is None:
                path = UsdShade.MaterialBindingAPI(self._prims[i]).GetDirectBinding("physics").GetMaterialPath()
                if path:
                    self._applied_physics_materials[i] = PhysicsMaterial(str(path))
            out.append(self._applied_physics_materials[i])
        return out

    def get_net_contact_forces(self, *args: Any, **kwargs: Any) -> np.ndarray:
        """Not mapped: PhysX contact-report views."""
        raise CompatNotSupported("GeometryPrim.get_net_contact_forces", "graphsdg has no PhysX contact-report views")

    get_contact_force_matrix = get_contact_force_data = get_friction_data = get_net_contact_forces


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.prims``' views (the single-prim wrappers and articulations come from their own areas)."""
    return [CompatModule("isaacsim.core.prims", XFormPrim=XFormPrim, RigidPrim=RigidPrim, GeometryPrim=GeometryPrim)]


EXTENSIONS = {"isaacsim.core.prims": ("isaacsim.core.prims",)}
