"""Isaac compat area: ``isaacsim.core.prims.GeometryPrim``, a view of gprims with colliders and physics materials.

Collision on / off (``physics:collisionEnabled``), mesh approximations
(``physics:approximation``, mapped as docs/physics.md lists) and physics materials
(bound with purpose ``physics``: the friction MuJoCo uses) reach the simulation;
PhysX contact offsets and torsional patch radii are authored (MuJoCo reads the
rest offset only). See :mod:`graphsdg.compat.core_prims` for what every view does.

Example:
    >>> import graphsdg as rep
    >>> from pxr import UsdPhysics
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.sphere(name="Ball")
    >>> view = GeometryPrim("/Ball", collisions=[True])
    >>> view.is_collision_enabled().tolist(), view.prims[0].HasAPI(UsdPhysics.CollisionAPI)
    ([True], True)
"""
from __future__ import annotations

import types
from typing import Any, Sequence

import numpy as np
from pxr import Sdf, UsdGeom, UsdPhysics, UsdShade

from graphsdg.compat.core_materials import PhysicsMaterial
from graphsdg.compat.core_prims import CompatNotSupported, XFormPrim, _column
from graphsdg.compat.experimental_arguments import warn_once
from graphsdg.compat.modules import CompatModule


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
    """``isaacsim.core.prims.GeometryPrim``."""
    return [CompatModule("isaacsim.core.prims", GeometryPrim=GeometryPrim)]
