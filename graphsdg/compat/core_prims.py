"""Isaac compat area: ``isaacsim.core.prims.XFormPrim`` and the helpers the other views share.

A view wraps every prim that a path expression (or a list of them) matches,
segment by segment with Isaac's glob rules (``/World/envs/env_*/Cube``,
``/World/Env[1-5]``; :mod:`graphsdg.stage.path_patterns`), and reads or writes
them in batches, as NumPy arrays (Isaac's ``numpy`` backend; poses float32,
quaternions w, x, y, z). ``indices`` select a subset.

* :class:`XFormPrim`: world and local poses, scales, visibility, visual
  materials, a default state that ``post_reset()`` (``World.reset()``) restores.
  Poses are the stage's: physics writes simulated poses to USD after every step,
  so ``usd=False`` (Isaac's Fabric read) returns the same values.
* :class:`~graphsdg.compat.core_rigid_prims.RigidPrim` (rigid bodies) and
  :class:`~graphsdg.compat.core_geometry_prims.GeometryPrim` (colliders) build
  on :class:`XFormPrim` in their own modules.

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
from typing import Any

import numpy as np
from pxr import Gf, Usd, UsdGeom, UsdShade

from graphsdg.compat import core_numpy
from graphsdg.compat.core_materials import OmniGlass, OmniPBR, PreviewSurface, VisualMaterial
from graphsdg.compat.core_types import XFormPrimViewState
from graphsdg.compat.core_utils_prims import is_prim_non_root_articulation_link
from graphsdg.compat.modules import CompatError, CompatModule, CompatObject
from graphsdg.compat.simulation_manager import SimulationManager
from graphsdg.maths.rotations import decompose
from graphsdg.physics.world_pose import set_world_pose
from graphsdg.stage.context import get_stage
from graphsdg.stage.path_patterns import match_prim_paths
from graphsdg.sim import transforms
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
        not_xformable = [f"{p} ({prim.GetTypeName() or 'typeless'})" for p, prim in zip(self._prim_paths, self._prims)
                         if not prim.IsA(UsdGeom.Xformable)]
        if not_xformable:   # Isaac authors xform ops that no transform reads on such prims; graphsdg refuses
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
                if name.startswith("xformOp:") and name.endswith(":unitsResolve") and \
                        name != "xformOp:scale:unitsResolve":
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
            pos[k], quat[k] = transforms.get_world_pose(self._prims[i])
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
            pos[k], quat[k] = transforms.get_local_pose(self._prims[i])
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


class CompatNotSupported(CompatError):
    """A core-API behaviour graphsdg cannot provide (named, with the reason): a
    :class:`graphsdg.compat.modules.CompatError` (an ``AttributeError``)."""

    def __init__(self, what: str, why: str) -> None:
        super().__init__(f"{what} is not available in graphsdg's compat mode: {why}. See docs/porting.md.")


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.prims.XFormPrim`` (the other views and wrappers come from their own areas)."""
    return [CompatModule("isaacsim.core.prims", XFormPrim=XFormPrim)]


EXTENSIONS = {"isaacsim.core.prims": ("isaacsim.core.prims",)}
