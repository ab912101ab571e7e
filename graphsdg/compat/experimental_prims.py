"""Isaac compat: ``isaacsim.core.experimental.prims`` wrappers: ``Prim``, ``XformPrim``, ``GeomPrim``, ``RigidPrim``.

Each wrapper holds prims matched by path(s) (an exact path, or a regular
expression per path segment, as Isaac's ``resolve_paths``) and reads or writes
them in batches: inputs broadcast to ``(N, width)`` following NumPy's rules,
``indices`` selects a subset, and results are numpy arrays that also answer
warp's ``.numpy()`` (:mod:`graphsdg.compat.experimental_arguments`; the ``Prim`` base
is :mod:`graphsdg.compat.experimental_prim_base`). Poses go through :mod:`graphsdg.sim.transforms` (world) and
:func:`graphsdg.stage.xform.set_local_pose` (local); rigid bodies through
:class:`graphsdg.physics.bodies.RigidBodyView`; collision and physics-material
properties are the ``UsdPhysics`` / ``physx*`` attributes the compiler reads.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics, UsdShade

from graphsdg.compat.experimental_arguments import flags, resolve_indices, rows, tokens, warn_once
from graphsdg.compat.experimental_materials import VisualMaterial, fetch_physics_material
from graphsdg.compat.experimental_prim_base import Prim
from graphsdg.compat.warp_arrays import WarpLikeArray
from graphsdg.compat.warp_arrays import as_warp_like as _warp
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz
from graphsdg.physics.bodies import RigidBodyView
from graphsdg.physics.world_pose import set_world_pose
from graphsdg.sim.transforms import get_local_pose, get_world_pose
from graphsdg.compat.experimental_stage_scope import current_stage as get_stage
from graphsdg.stage.xform import set_local_pose


# ---- XformPrim ------------------------------------------------------------------------------------
class XformPrim(Prim):
    """``isaacsim.core.experimental.prims.XformPrim``: poses, scales, visibility and visual materials.

    The prims must exist. ``positions`` / ``orientations`` (world) or ``translations``
    (local) and ``scales`` are applied at construction; ``reset_xform_op_properties``
    rewrites each prim's ops to translate, orient, scale (same local transform).
    """

    _compat_name = "isaacsim.core.experimental.prims.XformPrim"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = False) -> None:
        super().__init__(paths, resolve_paths=resolve_paths)
        missing = [p for p, prim in zip(self._paths, self._prims) if not prim]
        if missing:
            raise ValueError(f"specified paths must correspond to existing prims: {', '.join(missing)}")
        if positions is not None and translations is not None:
            raise ValueError("positions (world) and translations (local) cannot both be given")
        self._default_state: tuple[np.ndarray | None, np.ndarray | None] = (None, None)
        if reset_xform_op_properties:
            self.reset_xform_op_properties()
        if scales is not None:
            self.set_local_scales(scales)
        if translations is not None:
            self.set_local_poses(translations, None)
        if positions is not None or orientations is not None:
            self.set_world_poses(positions, orientations)

    def _selected(self, indices: Any) -> list[str]:
        """Paths of the prims ``indices`` selects (all when None)."""
        return [self._paths[i] for i in resolve_indices(indices, len(self._paths))]

    # ---- xform ops ---------------------------------------------------------------
    def _check_xformable(self, what: str) -> None:
        """Raise naming the wrapped prims without a transform (Isaac wraps them, and fails where a pose is needed)."""
        not_xformable = [p for p, prim in zip(self._paths, self._prims) if not prim.IsA(UsdGeom.Xformable)]
        if not_xformable:
            raise ValueError(f"{what}: prims {not_xformable} are not Xformable (they have no transform)")

    def reset_xform_op_properties(self) -> None:
        """Rewrite each prim's ops as ``translate``, ``orient``, ``scale``, keeping its local transform.

        New ops are double precision; an op attribute the prim already has (perhaps from a referenced asset, where
        it cannot be removed) is kept at its own precision, as Isaac keeps it.
        """
        self._check_xformable("reset_xform_op_properties")
        for prim in self._prims:
            xf = UsdGeom.Xformable(prim)
            m = np.array(xf.GetLocalTransformation(Usd.TimeCode.Default()), dtype=np.float64)
            t, r, s = decompose(m)
            q = matrix_to_quat_wxyz(r)
            names = [op.GetOpName() for op in xf.GetOrderedXformOps()]
            xf.ClearXformOpOrder()
            for name in names:   # old op attributes would otherwise linger, unused
                if name not in _STANDARD_OPS:
                    prim.RemoveProperty(name)
            ops = [_standard_op(prim, xf, name) for name in _STANDARD_OPS]
            for op, value in zip(ops, (t, q, s)):
                _set_op_value(op, value)
            xf.SetXformOpOrder(ops)

    # ---- poses ----------------------------------------------------------------------
    def get_world_poses(self, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(positions (k, 3), orientations (k, 4) w, x, y, z) in the world frame."""
        poses = [get_world_pose(p) for p in self._selected(indices)]
        return _warp([p[0] for p in poses]), _warp([p[1] for p in poses])

    def set_world_poses(self, positions: Any = None, orientations: Any = None, indices: Any = None) -> None:
        """Move the prims to world positions and / or orientations (quaternions w, x, y, z)."""
        paths = self._selected(indices)
        pos = None if positions is None else rows(positions, len(paths), 3, "positions")
        quat = None if orientations is None else _unit_quats(orientations, len(paths))
        for i, path in enumerate(paths):
            set_world_pose(path, None if pos is None else pos[i], None if quat is None else quat[i])

    def get_local_poses(self, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(translations (k, 3), orientations (k, 4) w, x, y, z) relative to each prim's parent."""
        t_out, q_out = [], []
        for path in self._selected(indices):
            t, q = get_local_pose(path)
            t_out.append(t)
            q_out.append(q)
        return _warp(t_out), _warp(q_out)

    def set_local_poses(self, translations: Any = None, orientations: Any = None, indices: Any = None) -> None:
        """Set translations and / or orientations (w, x, y, z) relative to each prim's parent."""
        paths = self._selected(indices)
        t = None if translations is None else rows(translations, len(paths), 3, "translations")
        q = None if orientations is None else _unit_quats(orientations, len(paths))
        for i, path in enumerate(paths):
            set_local_pose(get_stage().GetPrimAtPath(path), position=None if t is None else t[i],
                           rotation=None if q is None else q[i])

    def get_local_scales(self, indices: Any = None) -> WarpLikeArray:
        """Scales (k, 3) of each prim's local transform."""
        out = []
        for path in self._selected(indices):
            m = np.array(UsdGeom.Xformable(get_stage().GetPrimAtPath(path)).GetLocalTransformation(
                Usd.TimeCode.Default()), dtype=np.float64)
            out.append(decompose(m)[2])
        return _warp(out)

    def set_local_scales(self, scales: Any = None, indices: Any = None) -> None:
        """Set each prim's local scale (k, 3)."""
        paths = self._selected(indices)
        if scales is None:
            return
        s = rows(scales, len(paths), 3, "scales")
        for i, path in enumerate(paths):
            set_local_pose(get_stage().GetPrimAtPath(path), scale=s[i])

    # ---- default state --------------------------------------------------------------
    def set_default_state(self, positions: Any = None, orientations: Any = None, indices: Any = None) -> None:
        """Remember world poses that :meth:`reset_to_default_state` returns to."""
        idx = resolve_indices(indices, len(self))
        pos, quat = self._default_state
        if positions is not None:
            pos = np.full((len(self), 3), np.nan) if pos is None else pos
            pos[idx] = rows(positions, len(idx), 3, "positions")
        if orientations is not None:
            quat = np.full((len(self), 4), np.nan) if quat is None else quat
            quat[idx] = _unit_quats(orientations, len(idx))
        self._default_state = (pos, quat)

    def get_default_state(self, indices: Any = None) -> tuple[WarpLikeArray | None, WarpLikeArray | None]:
        """The default (positions, orientations); None where never set."""
        idx = resolve_indices(indices, len(self))
        pos, quat = self._default_state
        return (None if pos is None else _warp(pos[idx]), None if quat is None else _warp(quat[idx]))

    def reset_to_default_state(self) -> None:
        """Move the prims back to their default world poses (those set)."""
        pos, quat = self._default_state
        for i in range(len(self)):
            p = None if pos is None or np.isnan(pos[i]).any() else pos[i]
            q = None if quat is None or np.isnan(quat[i]).any() else quat[i]
            if p is not None or q is not None:
                self.set_world_poses(None if p is None else [p], None if q is None else [q], indices=[i])

    # ---- visibility and visual materials ------------------------------------------------------
    def set_visibilities(self, visibilities: Any, indices: Any = None) -> None:
        """Make the prims visible (True, ``inherited``) or invisible (False)."""
        paths = self._selected(indices)
        for path, visible in zip(paths, flags(visibilities, len(paths), "visibilities")):
            img = UsdGeom.Imageable(get_stage().GetPrimAtPath(path))
            img.MakeVisible() if visible else img.MakeInvisible()

    def get_visibilities(self, indices: Any = None) -> WarpLikeArray:
        """Whether each prim is visible (its computed visibility)."""
        return _warp([UsdGeom.Imageable(get_stage().GetPrimAtPath(p)).ComputeVisibility(Usd.TimeCode.Default())
                      != UsdGeom.Tokens.invisible for p in self._selected(indices)])

    def apply_visual_materials(self, materials: Any, indices: Any = None) -> None:
        """Bind visual materials (a VisualMaterial wrapper or a list of them: one for all, or one per prim)."""
        paths = self._selected(indices)
        targets = _material_list(materials, len(paths), "visual")
        for path, material in zip(paths, targets):
            UsdShade.MaterialBindingAPI.Apply(get_stage().GetPrimAtPath(path)).Bind(
                material, UsdShade.Tokens.weakerThanDescendants)

    def get_applied_visual_materials(self, indices: Any = None) -> list:
        """The visual material wrapper bound to each prim (None where none)."""
        out = []
        for path in self._selected(indices):
            material, _ = UsdShade.MaterialBindingAPI(get_stage().GetPrimAtPath(path)).ComputeBoundMaterial()
            out.append(VisualMaterial.fetch_instances([str(material.GetPath())])[0] if material else None)
        return out

    @property
    def is_non_root_articulation_link(self) -> bool:
        """Whether the prims are links of an articulation below its root (their poses are not theirs to set)."""
        for prim in self._prims:
            if not prim.HasAPI(UsdPhysics.RigidBodyAPI) or prim.HasAPI(UsdPhysics.ArticulationRootAPI):
                return False
            p = prim.GetParent()
            while p and not p.IsPseudoRoot():
                if p.HasAPI(UsdPhysics.ArticulationRootAPI):
                    break
                p = p.GetParent()
            else:
                return False
        return True


def _unit_quats(orientations: Any, count: int) -> np.ndarray:
    q = rows(orientations, count, 4, "orientations")
    norms = np.linalg.norm(q, axis=1)
    if np.any(norms < 1e-9):
        raise ValueError(f"orientations {orientations!r} hold a zero quaternion; expected (w, x, y, z) unit "
                         f"quaternions")
    return q / norms[:, None]


def _material_list(materials: Any, count: int, kind: str) -> list[UsdShade.Material]:
    """UsdShade.Material objects for ``count`` prims from material wrapper(s)."""
    items = materials if isinstance(materials, (list, tuple)) else [materials]
    found: list[UsdShade.Material] = []
    for item in items:
        mats = getattr(item, "materials", None)
        if mats is None:
            raise TypeError(f"{item!r} is not a {kind} material wrapper (an isaacsim.core.experimental.materials "
                            f"object with .materials)")
        found += list(mats)
    if len(found) not in (1, count):
        raise ValueError(f"{len(found)} {kind} materials for {count} prims; expected 1 or {count}")
    return found * count if len(found) == 1 else found


# ---- GeomPrim -----------------------------------------------------------------------------------------
_APPROXIMATIONS = ("none", "convexDecomposition", "convexHull", "boundingSphere", "boundingCube", "meshSimplification",
                   "sdf", "sphereFill")


class GeomPrim(XformPrim):
    """``isaacsim.core.experimental.prims.GeomPrim``: gprims with collision and physics-material properties.

    As in Isaac, any prim may be wrapped (a regular expression matching a gprim's siblings, say); collision
    schemas authored on prims that are not gprims are left unused by the simulation, as PhysX leaves them.

    ``apply_collision_apis=True`` applies ``CollisionAPI`` (and ``MeshCollisionAPI`` on meshes)
    at construction. Collision enablement, mesh approximations and physics materials
    reach MuJoCo; contact / rest offsets and torsional patch radii are authored
    (``physxCollision:*``) and warn once that MuJoCo does not use them.
    """

    _compat_name = "isaacsim.core.experimental.prims.GeomPrim"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, apply_collision_apis: bool = False,
                 positions: Any = None, translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = False) -> None:
        super().__init__(paths, resolve_paths=resolve_paths, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        if apply_collision_apis:
            self.apply_collision_apis()

    @property
    def geoms(self) -> list[UsdGeom.Gprim]:
        """The wrapped prims as ``UsdGeom.Gprim``."""
        return [UsdGeom.Gprim(p) for p in self._prims]

    def _selected_prims(self, indices: Any) -> list[Usd.Prim]:
        return [self._prims[i] for i in resolve_indices(indices, len(self))]

    def apply_collision_apis(self, indices: Any = None) -> None:
        """Apply ``CollisionAPI`` (and ``MeshCollisionAPI`` on meshes): the prims collide."""
        for prim in self._selected_prims(indices):
            UsdPhysics.CollisionAPI.Apply(prim)
            if prim.IsA(UsdGeom.Mesh):
                UsdPhysics.MeshCollisionAPI.Apply(prim)

    def set_enabled_collisions(self, enabled: Any, indices: Any = None) -> None:
        """Turn collision on or off (``physics:collisionEnabled``; the API is applied where missing)."""
        prims = self._selected_prims(indices)
        for prim, on in zip(prims, flags(enabled, len(prims), "enabled")):
            UsdPhysics.CollisionAPI.Apply(prim).CreateCollisionEnabledAttr().Set(on)

    def get_enabled_collisions(self, indices: Any = None) -> WarpLikeArray:
        """Whether each prim collides (has an enabled ``CollisionAPI``)."""
        out = []
        for prim in self._selected_prims(indices):
            value = UsdPhysics.CollisionAPI(prim).GetCollisionEnabledAttr().Get() if prim.HasAPI(
                UsdPhysics.CollisionAPI) else False
            out.append(bool(value) if value is not None else True)
        return _warp(np.array(out).reshape(-1, 1))

    def set_collision_approximations(self, approximations: str | Sequence[str], indices: Any = None) -> None:
        """Set meshes' collision approximation (``physics:approximation``); see docs/physics.md for the mapping."""
        prims = self._selected_prims(indices)
        for prim, value in zip(prims, tokens(approximations, len(prims), "approximation", _APPROXIMATIONS)):
            UsdPhysics.MeshCollisionAPI.Apply(prim).CreateApproximationAttr().Set(value)

    def get_collision_approximations(self, indices: Any = None) -> list[str]:
        """Each prim's collision approximation (``"none"`` where unset)."""
        out = []
        for prim in self._selected_prims(indices):
            attr = UsdPhysics.MeshCollisionAPI(prim).GetApproximationAttr() if prim.HasAPI(
                UsdPhysics.MeshCollisionAPI) else None
            value = attr.Get() if attr else None
            out.append(str(value) if value is not None else "none")
        return out

    def _physx_values(self, names: Sequence[str], values: Sequence[Any], indices: Any, what: str, why: str) -> None:
        prims = self._selected_prims(indices)
        for name, value in zip(names, values):
            if value is None:
                continue
            column = rows(value, len(prims), 1, name)[:, 0]
            for prim, v in zip(prims, column):
                prim.CreateAttribute(name, Sdf.ValueTypeNames.Float).Set(float(v))
        warn_once(what, why)

    def _physx_get(self, name: str, default: float, indices: Any) -> WarpLikeArray:
        out = []
        for prim in self._selected_prims(indices):
            attr = prim.GetAttribute(name)
            value = attr.Get() if attr and attr.IsValid() else None
            out.append([default if value is None else float(value)])
        return _warp(np.array(out, dtype=np.float32))

    def set_offsets(self, contact_offsets: Any = None, rest_offsets: Any = None, indices: Any = None) -> None:
        """Author ``physxCollision:contactOffset`` / ``restOffset`` (MuJoCo does not use them; warns once)."""
        if contact_offsets is None and rest_offsets is None:
            raise ValueError("set_offsets needs contact_offsets and / or rest_offsets")
        self._physx_values(("physxCollision:contactOffset", "physxCollision:restOffset"),
                           (contact_offsets, rest_offsets), indices, "GeomPrim.set_offsets",
                           "MuJoCo contacts start at touching distance; PhysX's contact and rest offsets are "
                           "authored but not simulated")

    def get_offsets(self, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(contact offsets, rest offsets), shape (k, 1) each (PhysX's defaults, -inf and 0, where unset)."""
        return (self._physx_get("physxCollision:contactOffset", float("-inf"), indices),
                self._physx_get("physxCollision:restOffset", 0.0, indices))

    def set_torsional_patch_radii(self, radii: Any, indices: Any = None, minimum: bool = False) -> None:
        """Author ``physxCollision:(min)torsionalPatchRadius`` (MuJoCo does not use it; warns once)."""
        name = "physxCollision:minTorsionalPatchRadius" if minimum else "physxCollision:torsionalPatchRadius"
        self._physx_values((name,), (radii,), indices, "GeomPrim.set_torsional_patch_radii",
                           "MuJoCo's contacts use sliding friction only; torsional patch radii are authored but "
                           "not simulated")

    def get_torsional_patch_radii(self, indices: Any = None, minimum: bool = False) -> WarpLikeArray:
        """The (minimum) torsional patch radii, shape (k, 1) (0 where unset)."""
        name = "physxCollision:minTorsionalPatchRadius" if minimum else "physxCollision:torsionalPatchRadius"
        return self._physx_get(name, 0.0, indices)

    def apply_physics_materials(self, materials: Any, weaker_than_descendants: bool | None = None,
                                indices: Any = None) -> None:
        """Bind physics materials (purpose ``physics``): their friction is the prims' contact friction."""
        prims = self._selected_prims(indices)
        strength = UsdShade.Tokens.weakerThanDescendants if weaker_than_descendants else \
            UsdShade.Tokens.strongerThanDescendants
        for prim, material in zip(prims, _material_list(materials, len(prims), "physics")):
            UsdShade.MaterialBindingAPI.Apply(prim).Bind(material, strength, "physics")

    def get_applied_physics_materials(self, indices: Any = None) -> list:
        """The physics material wrapper bound to each prim (None where none)."""
        out = []
        for prim in self._selected_prims(indices):
            material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial("physics")
            out.append(fetch_physics_material(material.GetPrim()) if material else None)
        return out


# ---- RigidPrim ------------------------------------------------------------------------------------------
class RigidPrim(XformPrim):
    """``isaacsim.core.experimental.prims.RigidPrim`` over graphsdg's rigid-body view (simulated poses and
    velocities); as in Isaac, ``RigidBodyAPI`` is applied to the wrapped prims that lack it."""

    _compat_name = "isaacsim.core.experimental.prims.RigidPrim"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, masses: Any = None,
                 densities: Any = None, positions: Any = None, translations: Any = None, orientations: Any = None,
                 scales: Any = None, reset_xform_op_properties: bool = False) -> None:
        super().__init__(paths, resolve_paths=resolve_paths, translations=translations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        for prim in self._prims:
            if not prim.HasAPI(UsdPhysics.RigidBodyAPI):
                UsdPhysics.RigidBodyAPI.Apply(prim)
        self._view = RigidBodyView(self.paths)
        if masses is not None or densities is not None:
            self._set_mass_api(masses, densities)
        if positions is not None or orientations is not None:
            self.set_world_poses(positions, orientations)

    def _set_mass_api(self, masses: Any, densities: Any) -> None:
        n = len(self)
        m = None if masses is None else rows(masses, n, 1, "masses")[:, 0]
        d = None if densities is None else rows(densities, n, 1, "densities")[:, 0]
        for i, prim in enumerate(self._prims):
            api = UsdPhysics.MassAPI.Apply(prim)
            if m is not None:
                api.CreateMassAttr().Set(float(m[i]))
            if d is not None:
                api.CreateDensityAttr().Set(float(d[i]))

    def get_world_poses(self, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """Simulated (positions (k, 3), orientations (k, 4) w, x, y, z)."""
        pos, quat = self._view.get_world_poses(indices)
        return _warp(pos), _warp(quat)

    def set_world_poses(self, positions: Any = None, orientations: Any = None, indices: Any = None) -> None:
        """Teleport the bodies (velocities kept)."""
        self._view.set_world_poses(positions, orientations, indices)

    def get_velocities(self, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """World-frame (linear (k, 3) m/s, angular (k, 3) rad/s) velocities."""
        lin, ang = self._view.get_velocities(indices)
        return _warp(lin), _warp(ang)

    def set_velocities(self, linear_velocities: Any = None, angular_velocities: Any = None,
                       indices: Any = None) -> None:
        """Set world-frame linear and / or angular velocities."""
        self._view.set_velocities(linear_velocities, angular_velocities, indices)

    def get_masses(self, indices: Any = None) -> WarpLikeArray:
        """Simulated masses (kg)."""
        return _warp(self._view.get_masses(indices))


_STANDARD_OPS = ("xformOp:translate", "xformOp:orient", "xformOp:scale")
_OP_TYPES = {"xformOp:translate": UsdGeom.XformOp.TypeTranslate, "xformOp:orient": UsdGeom.XformOp.TypeOrient,
             "xformOp:scale": UsdGeom.XformOp.TypeScale}


def _standard_op(prim: Usd.Prim, xf: UsdGeom.Xformable, name: str) -> UsdGeom.XformOp:
    """The prim's op ``name``: its existing attribute at its own precision, else a new double-precision op."""
    attr = prim.GetAttribute(name)
    if attr and attr.IsValid():
        return UsdGeom.XformOp(attr)
    return xf.AddXformOp(_OP_TYPES[name], UsdGeom.XformOp.PrecisionDouble, "")


def _set_op_value(op: UsdGeom.XformOp, value: np.ndarray) -> None:
    """Set a translate/scale vector or a (w, x, y, z) quaternion on ``op`` at the op's precision."""
    values = [float(v) for v in value]
    if op.GetOpType() == UsdGeom.XformOp.TypeOrient:
        quat = {UsdGeom.XformOp.PrecisionFloat: Gf.Quatf, UsdGeom.XformOp.PrecisionHalf: Gf.Quath}
        op.Set(quat.get(op.GetPrecision(), Gf.Quatd)(*values))
        return
    vec = {UsdGeom.XformOp.PrecisionFloat: Gf.Vec3f, UsdGeom.XformOp.PrecisionHalf: Gf.Vec3h}
    op.Set(vec.get(op.GetPrecision(), Gf.Vec3d)(*values))
