"""Isaac compat area: deformable bodies and their materials (Isaac Sim 6's experimental API).

* ``isaacsim.core.experimental.prims.DeformablePrim``: applies Isaac's deformable
  body schemas (``OmniPhysicsDeformableBodyAPI`` with a surface or volume
  simulation mesh) by Isaac's rules, and reads / writes the simulated nodes;
* ``isaacsim.core.experimental.materials.VolumeDeformableMaterial`` and
  ``SurfaceDeformableMaterial``: ``UsdShade.Material`` prims with the
  ``omniphysics:*`` deformable material attributes.

The simulation is :mod:`graphsdg.sim.deformables` (MuJoCo flexes). Node arrays are
numpy arrays that also answer warp's ``.numpy()``.
"""
from __future__ import annotations

import types
import warnings
from typing import Any, Literal, Sequence

import numpy as np
from pxr import Sdf, Usd, UsdGeom, UsdShade

from graphsdg.compat.isaac_core import WarpLikeArray, XformPrim, _warp
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.engine.runtime import runtime
from graphsdg.sim import deformables as dfm
from graphsdg.stage.context import get_stage

BASE_MATERIAL_API = "OmniPhysicsBaseMaterialAPI"
_warned: set[str] = set()


def _warn_once(what: str, why: str) -> None:
    """Warn once per process that ``what`` has no effect here (``why``)."""
    if what not in _warned:
        _warned.add(what)
        warnings.warn(f"{what} has no effect in graphsdg: {why}", stacklevel=3)


def _paths(paths: str | Sequence[str]) -> list[str]:
    if isinstance(paths, (str, Sdf.Path)):
        return [str(paths)]
    out = [str(p) for p in paths]
    if not out:
        raise ValueError("no prim paths given; expected a path or a non-empty list of paths")
    return out


def _column(values: Any, count: int, name: str) -> np.ndarray:
    """``values`` broadcast to (count,) floats, as Isaac broadcasts ``(N, 1)`` inputs."""
    arr = np.asarray(values.numpy() if hasattr(values, "numpy") else values, dtype=np.float64).reshape(-1)
    if arr.size == 1:
        return np.full(count, float(arr[0]))
    if arr.size != count:
        raise ValueError(f"{name} has {arr.size} values for {count} prims; expected 1 or {count}")
    return arr


# ---- materials --------------------------------------------------------------------------
class _DeformableMaterial(CompatObject):
    """Deformable material prims at ``paths`` (created where missing, wrapped where present)."""

    _apis: tuple[str, ...] = ()
    _kind = ""

    def __init__(self, paths: str | Sequence[str], **values: Any) -> None:
        stage = get_stage()
        self.paths = _paths(paths)
        existing = [p for p in self.paths if stage.GetPrimAtPath(p)]
        if existing and len(existing) != len(self.paths):
            raise ValueError(f"{type(self).__name__}: some paths exist and some do not ({existing[0]!r} exists); "
                             f"pass only existing material prims or only new paths")
        self.prims: list[Usd.Prim] = []
        for path in self.paths:
            if existing:
                prim = stage.GetPrimAtPath(path)
                if not prim.IsA(UsdShade.Material):
                    raise ValueError(f"the prim at {path} is a {prim.GetTypeName() or 'typeless prim'}, not a "
                                     f"UsdShade.Material")
                kind = "surface" if dfm.has_api(prim, dfm.SURFACE_MATERIAL_API) else \
                    "volume" if dfm.has_api(prim, dfm.DEFORMABLE_MATERIAL_API) else "<unknown>"
                if kind != self._kind:
                    raise ValueError(f"invalid material type at {path}: expected {self._kind!r}, got {kind!r}")
            else:
                prim = UsdShade.Material.Define(stage, path).GetPrim()
                for api in self._apis:
                    dfm.add_api(prim, api)
                self._author_defaults(prim)
            self.prims.append(prim)
        self._set_values(values)

    def _author_defaults(self, prim: Usd.Prim) -> None:
        for name, value in (("omniphysics:staticFriction", 0.0), ("omniphysics:dynamicFriction", 0.0),
                            ("omniphysics:youngsModulus", dfm.DEFAULT_YOUNG),
                            ("omniphysics:poissonsRatio", dfm.DEFAULT_POISSON), ("omniphysics:density", 0.0)):
            prim.CreateAttribute(name, Sdf.ValueTypeNames.Float).Set(value)

    def _set_values(self, values: dict[str, Any]) -> None:
        setters = {"youngs_moduli": self.set_youngs_moduli, "poissons_ratios": self.set_poissons_ratios,
                   "densities": self.set_densities}
        if values.get("static_frictions") is not None or values.get("dynamic_frictions") is not None:
            self.set_friction_coefficients(values.pop("static_frictions", None), values.pop("dynamic_frictions", None))
        for name, value in values.items():
            if value is None:
                continue
            if name not in setters:
                raise TypeError(f"{type(self).__name__}() got an unexpected keyword argument {name!r}")
            setters[name](value)

    def __len__(self) -> int:
        return len(self.prims)

    def _selected(self, indices: Any) -> list[int]:
        if indices is None:
            return list(range(len(self.prims)))
        idx = [int(i) for i in np.atleast_1d(np.asarray(indices))]
        bad = [i for i in idx if not 0 <= i < len(self.prims)]
        if bad:
            raise IndexError(f"indices {bad} out of range for {len(self.prims)} materials")
        return idx

    def _set(self, name: str, values: Any, label: str, indices: Any, check=None) -> None:
        idx = self._selected(indices)
        col = _column(values, len(idx), label)
        for i, v in zip(idx, col):
            if check is not None and not check(v):
                raise ValueError(f"{label} value {v} for {self.paths[i]} is out of range")
            self.prims[i].CreateAttribute(name, Sdf.ValueTypeNames.Float).Set(float(v))

    def _get(self, name: str, indices: Any) -> WarpLikeArray:
        return _warp(np.array([[float(self.prims[i].GetAttribute(name).Get() or 0.0)]
                               for i in self._selected(indices)], dtype=np.float32))

    def set_friction_coefficients(self, static_frictions: Any = None, dynamic_frictions: Any = None, *,
                                  indices: Any = None) -> None:
        """Static and dynamic friction (``omniphysics:staticFriction`` / ``dynamicFriction``); the flex
        uses the dynamic one (MuJoCo has one friction coefficient)."""
        if static_frictions is None and dynamic_frictions is None:
            raise ValueError("set_friction_coefficients needs static_frictions or dynamic_frictions")
        if static_frictions is not None:
            self._set("omniphysics:staticFriction", static_frictions, "static_frictions", indices, lambda v: v >= 0)
        if dynamic_frictions is not None:
            self._set("omniphysics:dynamicFriction", dynamic_frictions, "dynamic_frictions", indices,
                      lambda v: v >= 0)

    def get_friction_coefficients(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        return self._get("omniphysics:staticFriction", indices), self._get("omniphysics:dynamicFriction", indices)

    def set_youngs_moduli(self, youngs_moduli: Any, *, indices: Any = None) -> None:
        """Young's modulus in Pa (the flex's FEM stiffness)."""
        self._set("omniphysics:youngsModulus", youngs_moduli, "youngs_moduli", indices, lambda v: v >= 0)

    def get_youngs_moduli(self, *, indices: Any = None) -> WarpLikeArray:
        return self._get("omniphysics:youngsModulus", indices)

    def set_poissons_ratios(self, poissons_ratios: Any, *, indices: Any = None) -> None:
        """Poisson's ratio in [0, 0.5] (0.5 is simulated as 0.49: MuJoCo's linear FEM needs nu < 0.5)."""
        self._set("omniphysics:poissonsRatio", poissons_ratios, "poissons_ratios", indices, lambda v: 0 <= v <= 0.5)

    def get_poissons_ratios(self, *, indices: Any = None) -> WarpLikeArray:
        return self._get("omniphysics:poissonsRatio", indices)

    def set_densities(self, densities: Any, *, indices: Any = None) -> None:
        """Density in kg/m³ (0: the default, 1000)."""
        self._set("omniphysics:density", densities, "densities", indices, lambda v: v >= 0)

    def get_densities(self, *, indices: Any = None) -> WarpLikeArray:
        return self._get("omniphysics:density", indices)

    @staticmethod
    def are_of_type(paths: str | Usd.Prim | Sequence[str | Usd.Prim]) -> WarpLikeArray:
        raise NotImplementedError   # defined per subclass below


class VolumeDeformableMaterial(_DeformableMaterial):
    """isaacsim.core.experimental.materials.VolumeDeformableMaterial (Young's modulus, Poisson's ratio,
    density, friction)."""

    _compat_name = "isaacsim.core.experimental.materials.VolumeDeformableMaterial"
    _apis = (BASE_MATERIAL_API, dfm.DEFORMABLE_MATERIAL_API)
    _kind = "volume"

    def __init__(self, paths: str | Sequence[str], *, static_frictions: Any = None, dynamic_frictions: Any = None,
                 youngs_moduli: Any = None, poissons_ratios: Any = None, densities: Any = None) -> None:
        super().__init__(paths, static_frictions=static_frictions, dynamic_frictions=dynamic_frictions,
                         youngs_moduli=youngs_moduli, poissons_ratios=poissons_ratios, densities=densities)

    @staticmethod
    def are_of_type(paths: str | Usd.Prim | Sequence[str | Usd.Prim]) -> WarpLikeArray:
        """Whether each prim is a volume deformable material."""
        return _are(paths, lambda p: dfm.has_api(p, dfm.DEFORMABLE_MATERIAL_API)
                    and not dfm.has_api(p, dfm.SURFACE_MATERIAL_API))


class SurfaceDeformableMaterial(_DeformableMaterial):
    """isaacsim.core.experimental.materials.SurfaceDeformableMaterial: a volume material's values plus the
    shell thickness; PhysX's separate stretch / shear / bend stiffnesses have no MuJoCo counterpart (the
    shell's stiffness follows from E, nu and the thickness) and warn once when set."""

    _compat_name = "isaacsim.core.experimental.materials.SurfaceDeformableMaterial"
    _apis = (BASE_MATERIAL_API, dfm.DEFORMABLE_MATERIAL_API, dfm.SURFACE_MATERIAL_API)
    _kind = "surface"

    def __init__(self, paths: str | Sequence[str], *, static_frictions: Any = None, dynamic_frictions: Any = None,
                 youngs_moduli: Any = None, poissons_ratios: Any = None, densities: Any = None,
                 surface_thicknesses: Any = None, surface_stretch_stiffnesses: Any = None,
                 surface_shear_stiffnesses: Any = None, surface_bend_stiffnesses: Any = None) -> None:
        super().__init__(paths, static_frictions=static_frictions, dynamic_frictions=dynamic_frictions,
                         youngs_moduli=youngs_moduli, poissons_ratios=poissons_ratios, densities=densities)
        if surface_thicknesses is not None:
            self.set_surface_thicknesses(surface_thicknesses)
        if any(v is not None for v in (surface_stretch_stiffnesses, surface_shear_stiffnesses,
                                       surface_bend_stiffnesses)):
            self.set_surface_stiffnesses(surface_stretch_stiffnesses, surface_shear_stiffnesses,
                                         surface_bend_stiffnesses)

    def _author_defaults(self, prim: Usd.Prim) -> None:
        super()._author_defaults(prim)
        prim.CreateAttribute("omniphysics:surfaceThickness", Sdf.ValueTypeNames.Float).Set(dfm.DEFAULT_THICKNESS)

    def set_surface_thicknesses(self, thicknesses: Any, *, indices: Any = None) -> None:
        """Shell thickness in m (the flex's thickness: bending stiffness and mass per area)."""
        self._set("omniphysics:surfaceThickness", thicknesses, "surface_thicknesses", indices, lambda v: v > 0)

    def get_surface_thicknesses(self, *, indices: Any = None) -> WarpLikeArray:
        return self._get("omniphysics:surfaceThickness", indices)

    def set_surface_stiffnesses(self, stretch_stiffnesses: Any = None, shear_stiffnesses: Any = None,
                                bend_stiffnesses: Any = None, *, indices: Any = None) -> None:
        """Authored as Isaac does (``omniphysics:surface{Stretch,Shear,Bend}Stiffness``); no effect here."""
        for name, values in (("surfaceStretchStiffness", stretch_stiffnesses),
                             ("surfaceShearStiffness", shear_stiffnesses), ("surfaceBendStiffness", bend_stiffnesses)):
            if values is not None:
                self._set(f"omniphysics:{name}", values, name, indices, lambda v: v >= 0)
                _warn_once(f"SurfaceDeformableMaterial {name}", "MuJoCo's shell stiffness follows from Young's "
                           "modulus, Poisson's ratio and the thickness")

    def get_surface_stiffnesses(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray, WarpLikeArray]:
        return tuple(self._get(f"omniphysics:{n}", indices) for n in ("surfaceStretchStiffness",
                                                                      "surfaceShearStiffness",
                                                                      "surfaceBendStiffness"))

    @staticmethod
    def are_of_type(paths: str | Usd.Prim | Sequence[str | Usd.Prim]) -> WarpLikeArray:
        """Whether each prim is a surface deformable material."""
        return _are(paths, lambda p: dfm.has_api(p, dfm.SURFACE_MATERIAL_API))


def _are(paths: Any, test) -> WarpLikeArray:
    items = [paths] if isinstance(paths, (str, Usd.Prim)) else list(paths)
    stage = get_stage()
    prims = [p if isinstance(p, Usd.Prim) else stage.GetPrimAtPath(str(p)) for p in items]
    return _warp(np.array([bool(p) and test(p) for p in prims]))


# ---- DeformablePrim -----------------------------------------------------------------------
def apply_deformable_schema(prim: Usd.Prim, deformable_type: str | None) -> tuple[str, str]:
    """Wrap or create a deformable body on ``prim`` by Isaac's rules: ("wrap" | "create", type).

    A triangle Mesh is a surface deformable itself, a TetMesh a volume one; an
    Xform either already is a deformable root (its simulation mesh says the
    type) or becomes one: ``surface`` simulates its first Mesh, ``volume`` cooks
    a hexahedral simulation TetMesh around its meshes
    (:func:`graphsdg.sim.deformables.cook_volume`).
    """
    path = prim.GetPath()
    if deformable_type not in (None, "surface", "volume"):
        raise ValueError(f"deformable_type {deformable_type!r} for {path}; expected 'surface', 'volume' or None")
    if prim.IsA(UsdGeom.Mesh):
        if deformable_type not in (None, "surface"):
            raise ValueError(f"the prim at {path} is a Mesh (surface), but deformable_type is {deformable_type!r}")
        counts = UsdGeom.Mesh(prim).GetFaceVertexCountsAttr().Get()
        if not counts or any(c != 3 for c in counts):
            raise ValueError(f"the Mesh at {path} is empty or has non-triangular faces; nest it under an Xform and "
                             f"make the Xform the surface deformable body")
        if dfm.has_api(prim, dfm.DEFORMABLE_BODY_API) and dfm.has_api(prim, dfm.SURFACE_SIM_API):
            return "wrap", "surface"
        dfm.save_rest_points(prim)
        dfm.add_api(prim, dfm.DEFORMABLE_BODY_API)
        dfm.add_api(prim, dfm.SURFACE_SIM_API)
        return "create", "surface"
    if prim.IsA(UsdGeom.TetMesh):
        if deformable_type not in (None, "volume"):
            raise ValueError(f"the prim at {path} is a TetMesh (volume), but deformable_type is {deformable_type!r}")
        if dfm.has_api(prim, dfm.DEFORMABLE_BODY_API) and dfm.has_api(prim, dfm.VOLUME_SIM_API):
            return "wrap", "volume"
        dfm.add_api(prim, dfm.DEFORMABLE_BODY_API)
        dfm.add_api(prim, dfm.VOLUME_SIM_API)
        return "create", "volume"
    if prim.IsA(UsdGeom.Imageable) and not prim.IsA(UsdGeom.Gprim):
        if dfm.has_api(prim, dfm.DEFORMABLE_BODY_API):
            _, kind = dfm.simulation_mesh(prim)
            if deformable_type not in (None, kind):
                raise ValueError(f"the prim at {path} is a {kind} deformable, but deformable_type is "
                                 f"{deformable_type!r}")
            return "wrap", kind
        if deformable_type is None:
            raise ValueError(f"the prim at {path} is a UsdGeom.Imageable, but deformable_type is not set; set it to "
                             f"'surface' or 'volume' to apply the deformable schema")
        meshes = dfm.render_meshes(prim)
        if not meshes:
            raise ValueError(f"failed to find a (cooking) child Mesh for the prim at {path}")
        if deformable_type == "surface":
            counts = UsdGeom.Mesh(meshes[0]).GetFaceVertexCountsAttr().Get()
            if not counts:
                raise ValueError(f"the Mesh {meshes[0].GetPath()} under {path} is empty")
            dfm.save_rest_points(meshes[0])   # polygons are fanned into triangles when compiled
            dfm.add_api(meshes[0], dfm.SURFACE_SIM_API)
            dfm.add_api(prim, dfm.DEFORMABLE_BODY_API)
            return "create", "surface"
        dfm.cook_volume(prim)
        dfm.add_api(prim, dfm.DEFORMABLE_BODY_API)
        return "create", "volume"
    raise ValueError(f"cannot apply the deformable schema to {path} ({prim.GetTypeName() or 'typeless'}): expected "
                     f"a triangle Mesh, a TetMesh or an Xform with a Mesh below it")


class DeformablePrim(XformPrim):
    """isaacsim.core.experimental.prims.DeformablePrim over :mod:`graphsdg.sim.deformables`.

    Node positions are world positions of the simulation mesh's nodes (the
    collision mesh is the simulation mesh here, and the rest mesh its rest
    shape); the arrays are ``(N, nodes per body, 3)``.
    """

    _compat_name = "isaacsim.core.experimental.prims.DeformablePrim"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = False, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = False,
                 deformable_type: Literal["surface", "volume"] | None = None) -> None:
        if resolve_paths:
            raise ValueError("DeformablePrim(resolve_paths=True): regular-expression paths are not mapped in "
                             "graphsdg's compat mode; pass exact prim paths")
        if translations is not None or scales is not None or reset_xform_op_properties:
            raise ValueError("DeformablePrim: translations, scales and reset_xform_op_properties are not mapped in "
                             "graphsdg's compat mode; set world positions / orientations, or edit the xform ops")
        if positions is not None and translations is not None:
            raise AssertionError("positions and translations cannot both be given")
        stage = get_stage()
        missing = [p for p in _paths(paths) if not stage.GetPrimAtPath(p)]
        if missing:
            raise ValueError(f"specified paths must correspond to existing prims: {', '.join(missing)}")
        kinds = {apply_deformable_schema(stage.GetPrimAtPath(p), deformable_type)[1] for p in _paths(paths)}
        if len(kinds) != 1:
            raise ValueError(f"multiple deformable types are not supported in one DeformablePrim: {sorted(kinds)}")
        self._deformable_type = kinds.pop()
        super().__init__(paths)
        if positions is not None or orientations is not None:
            self.set_world_poses(positions, orientations)

    # ---- USD-side properties
    @property
    def deformable_type(self) -> str:
        """``"surface"`` or ``"volume"``."""
        return self._deformable_type

    def _sim_meshes(self) -> list[Usd.Prim]:
        stage = get_stage()
        return [dfm.simulation_mesh(stage.GetPrimAtPath(p))[0] for p in self.paths]

    @property
    def simulation_mesh_paths(self) -> list[str]:
        return [str(p.GetPath()) for p in self._sim_meshes()]

    @property
    def collision_mesh_paths(self) -> list[str]:
        """The simulation meshes: here a flex collides with its own simulation elements."""
        return self.simulation_mesh_paths

    @property
    def num_nodes_per_element(self) -> int:
        return 4 if self._deformable_type == "volume" else 3

    @property
    def num_nodes_per_body(self) -> tuple[int, int, int]:
        n = max(len(b.rest_world) for b in self._bindings())
        return n, n, n

    @property
    def num_elements_per_body(self) -> tuple[int, int, int]:
        n = max(len(b.elements) for b in self._bindings())
        return n, n, n

    # ---- simulation
    def _scene(self):
        sim = runtime().sim
        sim.sync_dirty_prims()
        return sim

    def _bindings(self, indices: Any = None) -> list[dfm.FlexBinding]:
        compiled = self._scene().ensure_compiled()
        by_root = {b.root: b for b in compiled.deformables}
        by_sim = {b.sim_path: b for b in compiled.deformables}
        out = []
        for path in self._selected(indices):
            b = by_root.get(path) or by_sim.get(path)
            if b is None:
                raise ValueError(f"{path} is not simulated as a deformable body (is deformableBodyEnabled off?)")
            out.append(b)
        return out

    def is_physics_tensor_entity_valid(self) -> bool:
        """True: the simulated nodes are readable whenever the stage is compiled (no separate physics view)."""
        return True

    def _stack(self, arrays: list[np.ndarray]) -> WarpLikeArray:
        n = max(len(a) for a in arrays)
        out = np.zeros((len(arrays), n) + arrays[0].shape[1:], dtype=arrays[0].dtype)
        for i, a in enumerate(arrays):
            out[i, :len(a)] = a
        return _warp(out)

    def get_element_indices(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray, WarpLikeArray]:
        """(simulation, collision, rest) element node indices, (N, elements, 3 or 4)."""
        e = self._stack([b.elements.astype(np.int32) for b in self._bindings(indices)])
        return e, e.copy().view(WarpLikeArray), e.copy().view(WarpLikeArray)

    def get_nodal_positions(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray, WarpLikeArray]:
        """(simulation, collision, rest) node world positions, (N, nodes, 3) float32."""
        data = self._scene().data
        bindings = self._bindings(indices)
        sim = self._stack([dfm.node_positions(b, data).astype(np.float32) for b in bindings])
        rest = self._stack([b.rest_world.astype(np.float32) for b in bindings])
        return sim, sim.copy().view(WarpLikeArray), rest

    def set_nodal_positions(self, positions: Any, *, indices: Any = None) -> None:
        """Move the simulation nodes to world ``positions`` (broadcast to (N, nodes, 3))."""
        scene = self._scene()
        bindings = self._bindings(indices)
        values = self._broadcast(positions, bindings, "positions")
        for b, v in zip(bindings, values):
            dfm.set_node_positions(b, scene.data, v[:len(b.rest_world)])
        scene.forward()
        scene.follow_deformables()

    def get_nodal_velocities(self, *, indices: Any = None) -> WarpLikeArray:
        """Simulation node velocities (m/s, world), (N, nodes, 3) float32."""
        data = self._scene().data
        return self._stack([dfm.node_velocities(b, data).astype(np.float32) for b in self._bindings(indices)])

    def set_nodal_velocities(self, velocities: Any, *, indices: Any = None) -> None:
        scene = self._scene()
        bindings = self._bindings(indices)
        for b, v in zip(bindings, self._broadcast(velocities, bindings, "velocities")):
            dfm.set_node_velocities(b, scene.data, v[:len(b.rest_world)])

    def _broadcast(self, values: Any, bindings: list[dfm.FlexBinding], name: str) -> np.ndarray:
        arr = np.asarray(values.numpy() if hasattr(values, "numpy") else values, dtype=np.float64)
        shape = (len(bindings), max(len(b.rest_world) for b in bindings), 3)
        try:
            return np.broadcast_to(arr, shape)
        except ValueError:
            raise ValueError(f"nodal {name} of shape {arr.shape} do not broadcast to {shape}") from None

    # ---- materials
    def apply_physics_materials(self, materials: Any, *, weaker_than_descendants: bool | list | None = None,
                                indices: Any = None) -> None:
        """Bind deformable material(s) for physics (``material:binding:physics``), one or one per prim."""
        mats = materials if isinstance(materials, (list, tuple)) else [materials]
        prims = [m for mat in mats for m in getattr(mat, "prims", [mat])]
        paths = self._selected(indices)
        if len(prims) not in (1, len(paths)):
            raise ValueError(f"{len(prims)} materials for {len(paths)} prims; expected 1 or {len(paths)}")
        stage = get_stage()
        for i, path in enumerate(paths):
            material = UsdShade.Material(prims[0 if len(prims) == 1 else i])
            if not material:
                raise ValueError(f"{prims[i]} is not a UsdShade.Material")
            target = stage.GetPrimAtPath(path)
            strength = UsdShade.Tokens.weakerThanDescendants if weaker_than_descendants else \
                UsdShade.Tokens.strongerThanDescendants
            UsdShade.MaterialBindingAPI.Apply(target).Bind(material, strength, "physics")

    def get_applied_physics_materials(self, *, indices: Any = None) -> list[Any]:
        """The deformable material bound to each prim for physics (None where none is)."""
        stage = get_stage()
        out = []
        for path in self._selected(indices):
            mat = UsdShade.MaterialBindingAPI(stage.GetPrimAtPath(path)).GetDirectBinding("physics").GetMaterial()
            if not mat:
                out.append(None)
            elif dfm.has_api(mat.GetPrim(), dfm.SURFACE_MATERIAL_API):
                out.append(SurfaceDeformableMaterial(str(mat.GetPath())))
            else:
                out.append(VolumeDeformableMaterial(str(mat.GetPath())))
        return out


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    return [CompatModule("isaacsim.core.experimental.prims", DeformablePrim=DeformablePrim),
            CompatModule("isaacsim.core.experimental.materials", VolumeDeformableMaterial=VolumeDeformableMaterial,
                         SurfaceDeformableMaterial=SurfaceDeformableMaterial)]
