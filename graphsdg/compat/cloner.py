"""Isaac compat area: ``isaacsim.core.cloner`` (``Cloner``, ``GridCloner``): many copies of an environment prim.

``Cloner.clone(source_prim_path, prim_paths, positions, orientations, ...)``
gives the source Isaac's translate / orient / scale ops (keeping its pose) and
authors, in the stage's root layer, each other path as a prim that *inherits*
the source (``copy_from_source=False``: later edits of the source show in every
clone) or a copy of its spec (``copy_from_source=True``), with its own
``xformOp:translate`` (``positions[i]``, else the source's), ``xformOp:orient``
(``orientations[i]``, w, x, y, z, else the source's) and the source's scale. A
source path listed in ``prim_paths`` is moved to its own slot. graphsdg
compiles every clone from USD; PhysX's physics replication
(``replicate_physics=True``) is a parsing shortcut with the same result, so it
is accepted, and ``clone_in_fabric=True`` clones into USD as well.

``GridCloner(spacing, num_per_row=-1)`` places clones on a grid: ``n`` clones
fill ``ceil(n / num_per_row)`` rows (``num_per_row`` defaults to
``int(sqrt(n))``) of ``ceil(n / rows)`` columns; clone ``i`` sits at row
``i // cols``, column ``i % cols``, at ``x = (rows - 1) * spacing / 2 - row *
spacing``, ``y = col * spacing - (cols - 1) * spacing / 2`` (``z = 0``; on a Y-up
stage the second coordinate is ``z``), plus ``position_offsets[i]``; its
orientation is ``orientation_offsets[i]`` (identity by default).

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cloner = GridCloner(spacing=2.0)
    >>> cloner.define_base_env("/World/envs")
    >>> _ = rep.functional.create.cube(name="env_0", parent="/World/envs")
    >>> positions = cloner.clone("/World/envs/env_0", cloner.generate_paths("/World/envs/env", 4))
    >>> [list(map(float, p)) for p in positions]
    [[1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, -1.0, 0.0], [-1.0, 1.0, 0.0]]
"""
from __future__ import annotations

import types
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, Vt

from graphsdg.compat.modules import CompatError, CompatModule, CompatObject
from graphsdg.stage.context import get_stage

_ROTATE_OPS = ("xformOp:rotateX", "xformOp:rotateY", "xformOp:rotateZ", "xformOp:rotateXYZ", "xformOp:rotateXZY",
               "xformOp:rotateYXZ", "xformOp:rotateYZX", "xformOp:rotateZXY", "xformOp:rotateZYX",
               "xformOp:transform", "xformOp:scale")


def _as_array(values: Any, count: int, width: int, what: str) -> np.ndarray:
    """``values`` (NumPy, lists, or a tensor with ``.detach().cpu().numpy()`` / ``.numpy()``) as ``(count, width)``."""
    for convert in (lambda v: v.detach().cpu().numpy(), lambda v: v.numpy()):
        try:
            values = convert(values)
            break
        except AttributeError:
            continue
    arr = np.asarray(values, dtype=np.float64)
    if len(arr) != count:
        raise ValueError(f"Dimension mismatch between {what} ({len(arr)}) and prim_paths ({count})!")
    if arr.shape != (count, width) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must have shape ({count}, {width}) of finite numbers, got shape {arr.shape}")
    return arr


class Cloner(CompatObject):
    """``isaacsim.core.cloner.Cloner`` (see the module docstring)."""

    _compat_name = "isaacsim.core.cloner.Cloner"

    def __init__(self, stage: Usd.Stage | None = None) -> None:
        self._base_env_path: str | None = None
        self._root_path: str | None = None
        self._stage = stage if stage is not None else get_stage()

    def define_base_env(self, base_env_path: str) -> None:
        """Define a ``Scope`` at ``base_env_path`` to hold the clones."""
        UsdGeom.Scope.Define(self._stage, base_env_path)
        self._base_env_path = base_env_path

    def generate_paths(self, root_path: str, num_paths: int) -> list[str]:
        """``[f"{root_path}_{i}" for i in range(num_paths)]``."""
        if isinstance(num_paths, bool) or not isinstance(num_paths, (int, np.integer)) or num_paths < 0:
            raise ValueError(f"num_paths must be an integer >= 0, got {num_paths!r}")
        self._root_path = root_path + "_"
        return [f"{root_path}_{i}" for i in range(int(num_paths))]

    def replicate_physics(self, source_prim_path: str, prim_paths: list[str], base_env_path: str | None,
                          root_path: str | None, enable_env_ids: bool = False, clone_in_fabric: bool = False) -> None:
        """Check PhysX replication's arguments; the clones' physics is compiled from USD (the same result)."""
        if enable_env_ids:
            raise CompatError("Cloner enable_env_ids=True (co-located clones with automatic collision filtering) is "
                              "not available in graphsdg's compat mode: MuJoCo has no environment ids; place the "
                              "clones apart (GridCloner). See docs/porting.md.")
        if base_env_path is None and self._base_env_path is None:
            raise ValueError("base_env_path needs to be specified!")
        if root_path is None and self._root_path is None:
            raise ValueError("root_path needs to be specified!")

    def disable_change_listener(self) -> None:
        """Nothing to pause: graphsdg syncs stage edits into the simulation when it next needs them."""

    def enable_change_listener(self) -> None:
        """Nothing to resume (see :meth:`disable_change_listener`)."""

    def _prepare_source(self, source: Usd.Prim) -> tuple[Gf.Vec3d, Any, Gf.Vec3d, bool]:
        """Give the source translate / orient / scale ops keeping its local pose; returns its translation,
        orientation, scale and whether its orient op is single precision."""
        xformable = UsdGeom.Xformable(source)
        names = source.GetPropertyNames()
        local = Gf.Transform(xformable.GetLocalTransformation(Usd.TimeCode.Default()))
        translation = local.GetTranslation()
        orientation = local.GetRotation().GetQuat()
        scale = Gf.Vec3d(source.GetAttribute("xformOp:scale").Get()) if "xformOp:scale" in names else \
            Gf.Vec3d(1.0, 1.0, 1.0)
        xformable.ClearXformOpOrder()
        for name in names:
            if name in _ROTATE_OPS or (name.startswith("xformOp:") and name.endswith(":unitsResolve")):
                source.RemoveProperty(name)
        names = source.GetPropertyNames()
        translate_op = UsdGeom.XformOp(source.GetAttribute("xformOp:translate")) if "xformOp:translate" in names \
            else xformable.AddXformOp(UsdGeom.XformOp.TypeTranslate, UsdGeom.XformOp.PrecisionDouble, "")
        translate_op.Set(translation)
        orient_op = UsdGeom.XformOp(source.GetAttribute("xformOp:orient")) if "xformOp:orient" in names \
            else xformable.AddXformOp(UsdGeom.XformOp.TypeOrient, UsdGeom.XformOp.PrecisionDouble, "")
        single = orient_op.GetPrecision() == UsdGeom.XformOp.PrecisionFloat
        orient_op.Set(Gf.Quatf(orientation) if single else Gf.Quatd(orientation))
        scale_op = xformable.AddXformOp(UsdGeom.XformOp.TypeScale, UsdGeom.XformOp.PrecisionDouble, "")
        scale_op.Set(scale)
        xformable.SetXformOpOrder([translate_op, orient_op, scale_op])
        return translation, orientation, scale, single

    def clone(self, source_prim_path: str, prim_paths: list[str], positions: Any = None, orientations: Any = None,
              replicate_physics: bool = False, base_env_path: str | None = None, root_path: str | None = None,
              copy_from_source: bool = False, unregister_physics_replication: bool = False,
              enable_env_ids: bool = False, clone_in_fabric: bool = False) -> None:
        """Clone ``source_prim_path`` to every other path of ``prim_paths`` (see the module docstring)."""
        if not isinstance(source_prim_path, str):
            raise TypeError(f"source_prim_path must be a str, got {type(source_prim_path).__name__}")
        if not Sdf.Path.IsValidPathString(source_prim_path):
            raise ValueError(f"source_prim_path {source_prim_path!r} is not a valid SdfPath")
        self.disable_change_listener()
        try:
            self._clone(source_prim_path, prim_paths, positions, orientations, replicate_physics, base_env_path,
                        root_path, copy_from_source, enable_env_ids, clone_in_fabric)
        finally:
            self.enable_change_listener()

    def _clone(self, source_prim_path: str, prim_paths: list[str], positions: Any, orientations: Any,
               replicate_physics: bool, base_env_path: str | None, root_path: str | None, copy_from_source: bool,
               enable_env_ids: bool, clone_in_fabric: bool) -> None:
        prim_paths = list(prim_paths)
        pos = None if positions is None else _as_array(positions, len(prim_paths), 3, "positions")
        quat = None if orientations is None else _as_array(orientations, len(prim_paths), 4, "orientations")
        if enable_env_ids:
            self.replicate_physics(source_prim_path, prim_paths, base_env_path, root_path, enable_env_ids)
        source = self._stage.GetPrimAtPath(source_prim_path)
        if not source:
            raise ValueError(f"Source prim {source_prim_path!r} does not exist")
        translation, orientation, scale, single = self._prepare_source(source)
        quat_type = Gf.Quatf if single else Gf.Quatd
        layer = self._stage.GetRootLayer()
        if copy_from_source and layer.GetPrimAtPath(source_prim_path) is None:
            raise ValueError(f"copy_from_source: the source {source_prim_path!r} has no spec in the root layer to copy")

        def pose(i: int) -> tuple[Gf.Vec3d, Any]:
            t = Gf.Vec3d(*pos[i].tolist()) if pos is not None else Gf.Vec3d(translation)
            q = quat_type(float(quat[i][0]), *quat[i][1:].tolist()) if quat is not None else quat_type(orientation)
            return t, q

        if source_prim_path in prim_paths:
            t, q = pose(prim_paths.index(source_prim_path))
            source.GetAttribute("xformOp:translate").Set(t)
            source.GetAttribute("xformOp:orient").Set(q)
        with Sdf.ChangeBlock():
            for i, path in enumerate(prim_paths):
                if path == source_prim_path:
                    continue
                spec = Sdf.CreatePrimInLayer(layer, path)
                if copy_from_source:
                    Sdf.CopySpec(layer, Sdf.Path(source_prim_path), layer, Sdf.Path(path))
                else:
                    spec.inheritPathList.Prepend(Sdf.Path(source_prim_path))
                t, q = pose(i)
                for name, type_name, value in (
                        ("xformOp:translate", Sdf.ValueTypeNames.Double3, t),
                        ("xformOp:orient", Sdf.ValueTypeNames.Quatf if single else Sdf.ValueTypeNames.Quatd, q),
                        ("xformOp:scale", Sdf.ValueTypeNames.Double3, scale)):
                    attr = spec.attributes.get(name) or Sdf.AttributeSpec(spec, name, type_name)
                    attr.default = value
                order = spec.attributes.get("xformOpOrder") or Sdf.AttributeSpec(
                    spec, "xformOpOrder", Sdf.ValueTypeNames.TokenArray, Sdf.VariabilityUniform)
                order.default = Vt.TokenArray(["xformOp:translate", "xformOp:orient", "xformOp:scale"])
        if replicate_physics and any(p != source_prim_path for p in prim_paths):
            self.replicate_physics(source_prim_path, prim_paths, base_env_path, root_path, enable_env_ids,
                                   clone_in_fabric)

    def filter_collisions(self, physicsscene_path: str, collision_root_path: str, prim_paths: list[str],
                          global_paths: list[str] | None = None) -> None:
        """Not mapped: graphsdg does not compile PhysX collision groups (raises naming it)."""
        raise CompatError("isaacsim.core.cloner.Cloner.filter_collisions is not available in graphsdg's compat mode: "
                          "graphsdg does not compile PhysX collision groups into MuJoCo, so clones cannot be kept "
                          "from colliding with each other; place them apart (GridCloner). See docs/porting.md.")


class GridCloner(Cloner):
    """``isaacsim.core.cloner.GridCloner``: clones on a grid (see the module docstring)."""

    _compat_name = "isaacsim.core.cloner.GridCloner"

    def __init__(self, spacing: float, num_per_row: int = -1, stage: Usd.Stage | None = None) -> None:
        if isinstance(spacing, bool) or not isinstance(spacing, (int, float, np.floating)) or not np.isfinite(spacing):
            raise ValueError(f"spacing must be a finite number, got {spacing!r}")
        self._spacing = float(spacing)
        self._num_per_row = num_per_row
        self._positions: list | None = None
        self._orientations: list | None = None
        self._cached_num_clones: int | None = None
        Cloner.__init__(self, stage)

    def get_clone_transforms(self, num_clones: int, position_offsets: Any = None,
                             orientation_offsets: Any = None) -> tuple[list, list]:
        """(positions, orientations w, x, y, z) of ``num_clones`` grid slots (offsets added / composed)."""
        offsets = None if position_offsets is None else _as_array(position_offsets, num_clones, 3, "position_offsets")
        turns = None if orientation_offsets is None else \
            _as_array(orientation_offsets, num_clones, 4, "orientation_offsets")
        if num_clones < 0:
            raise ValueError("num_clones must be non-negative")
        use_cache = offsets is None and turns is None
        if use_cache and self._positions is not None and self._cached_num_clones == num_clones:
            return self._positions, self._orientations
        positions: list = []
        orientations: list = []
        if num_clones:
            per_row = int(np.sqrt(num_clones)) if self._num_per_row == -1 else int(self._num_per_row)
            if per_row <= 0:
                raise ValueError("num_per_row must be positive")
            rows = np.ceil(num_clones / per_row)
            cols = np.ceil(num_clones / rows)
            row_offset = 0.5 * self._spacing * (rows - 1)
            col_offset = 0.5 * self._spacing * (cols - 1)
            z_up = UsdGeom.GetStageUpAxis(self._stage) == UsdGeom.Tokens.z
            for i in range(num_clones):
                row, col = i // cols, i % cols
                x, y = row_offset - row * self._spacing, col * self._spacing - col_offset
                position = [x, y, 0] if z_up else [x, 0, y]     # lists, as Isaac's (offsets make arrays)
                positions.append(offsets[i] + position if offsets is not None else position)
                q = Gf.Quatd.GetIdentity()
                if turns is not None:
                    q = Gf.Quatd(float(turns[i][0]), Gf.Vec3d(*turns[i][1:].tolist())) * q
                orientations.append([q.GetReal(), *q.GetImaginary()])
        if use_cache:
            self._positions, self._orientations, self._cached_num_clones = positions, orientations, num_clones
        return positions, orientations

    def clone(self, source_prim_path: str, prim_paths: list[str], position_offsets: Any = None,
              orientation_offsets: Any = None, replicate_physics: bool = False, base_env_path: str | None = None,
              root_path: str | None = None, copy_from_source: bool = False, enable_env_ids: bool = False,
              clone_in_fabric: bool = False) -> list:
        """Clone onto the grid; returns the clones' positions."""
        positions, orientations = self.get_clone_transforms(len(prim_paths), position_offsets, orientation_offsets)
        Cloner.clone(self, source_prim_path, prim_paths, positions=positions if positions else None,
                     orientations=orientations if orientations else None, replicate_physics=replicate_physics,
                     base_env_path=base_env_path, root_path=root_path, copy_from_source=copy_from_source,
                     enable_env_ids=enable_env_ids, clone_in_fabric=clone_in_fabric)
        return positions


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.cloner``."""
    return [CompatModule("isaacsim.core.cloner", Cloner=Cloner, GridCloner=GridCloner)]


EXTENSIONS = {"isaacsim.core.cloner": ("isaacsim.core.cloner",)}
