"""Randomizer nodes: each execution calls the matching ``graphsdg.functional.randomizer`` function. It passes the
node's per-execution stream as ``rng``."""
from __future__ import annotations

import os
from typing import Any

import numpy as np
from pxr import Sdf, Usd

from graphsdg.functional import create as FC
from graphsdg.functional import modify as FM
from graphsdg.functional import randomizer as FR
from graphsdg.graph.calls import Call
from graphsdg.graph.graph import REPLICATOR_ROOT
from graphsdg.graph.node import ExecContext, Node, Port, flatten_prims, is_random_value
from graphsdg.graph.registry import register_node
from graphsdg.graph.samples import Samples
from graphsdg.graph.value_shapes import SCALAR, value_shape

from .mirrored_ports import mirrored_port, mirrored_ports
from .modify import TARGET


class Randomizer(Node):
    """Base of randomizer nodes: each is the call ``rep.randomizer.<name>``."""

    family = "randomizer"
    call = Call()
    outputs = {"prims": Port("prims")}


@register_node
class Color(Randomizer):
    """Give each prim its own material with a diffuse colour from ``colors`` (usually a distribution)."""

    type_name = "randomizer.color"
    call = Call(named=False)
    inputs = {**TARGET, "colors": Port("rgb", required=True), "per_sub_mesh": Port(bool, False),
              "seed": Port(int)}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        value = ctx.value("colors")
        if isinstance(value, Samples) or value_shape(value) in ((3,), (4,)):
            colors = ctx.per_prim("colors", n, ((3,), (4,)))    # one colour, or a distribution's draws
        else:   # a list of colours, as Replicator reads it: one drawn per prim
            shape = value_shape(value)
            if shape is None or len(shape) != 2 or shape[1] not in (3, 4) or shape[0] == 0:
                raise ValueError(f"randomizer.color colors: got {value!r}; expected one (r, g, b), a list of "
                                 f"colours to draw from, or a distribution")
            palette = list(value)
            colors = [palette[int(k)] for k in ctx.rng.integers(0, len(palette), size=n)]
        applied = FR.color(prims, colors=np.array([np.asarray(c, dtype=np.float64)[:3] for c in colors]))
        ctx.record("colors", applied)
        return {"prims": prims}


def _material_prims(value: Any, what: str) -> list[Usd.Prim]:
    return flatten_prims(FR.with_mdl_materials(value), what)   # .mdl files: their materials, made once


@register_node
class Materials(Randomizer):
    """Bind each prim a material drawn from ``materials`` (a material_omnipbr item, prims, paths or ``.mdl``
    files)."""

    type_name = "randomizer.materials"
    inputs = {**TARGET, "materials": Port("materials", required=True), "seed": Port(int),
              "max_cached_materials": Port(int, 0)}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        if isinstance(ctx.value("materials"), Samples):   # a distribution of materials: its draws, one per prim
            chosen = ctx.per_prim("materials", len(prims), SCALAR)
            for prim, mat in zip(prims, chosen):
                FM.material(prim, mat)
            return {"prims": prims}
        mats = _material_prims(ctx.value("materials"), "randomizer.materials materials")
        ctx.record("materials", FR.materials(prims, mats, rng=ctx.rng))
        return {"prims": prims}


@register_node
class Texture(Randomizer):
    """Give each prim a material textured with a file drawn from ``textures``; UV scale and rotation (degrees)."""

    type_name = "randomizer.texture"
    call = Call(named=False)
    inputs = {**TARGET, "textures": Port(list, required=True), "texture_scale": Port("vec2"),
              "texture_rotate": Port(float), "per_sub_mesh": Port(bool, False), "project_uvw": Port(bool, False),
              "seed": Port(int)}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        n = len(prims)
        scales = ctx.per_prim("texture_scale", n, ((2,), ()))
        rotates = ctx.per_prim("texture_rotate", n, SCALAR)
        textures = ctx.value("textures")
        if isinstance(textures, Samples):   # a distribution of paths: its draws, one per prim
            files = [os.fspath(f) for f in ctx.per_prim("textures", n, SCALAR)]
        else:                               # a list of paths, as Replicator's: one drawn per prim
            listed = [textures] if isinstance(textures, (str, os.PathLike)) else list(textures)
            if not listed:
                raise ValueError("randomizer.texture textures: got an empty list; give texture files to draw from")
            files = [os.fspath(listed[int(k)]) for k in ctx.rng.integers(0, len(listed), size=n)]
        chosen = []
        for i, prim in enumerate(prims):
            scale = None if scales is None else np.broadcast_to(np.asarray(scales[i], dtype=np.float64), (2,))
            rotate = None if rotates is None else float(np.asarray(rotates[i]).reshape(-1)[0])
            chosen += FR.texture([prim], [files[i]], texture_scale=scale, texture_rotate=rotate, rng=ctx.rng)
        ctx.record("textures", chosen)
        return {"prims": prims}


@register_node
class Rotation(Randomizer):
    """Rotate each prim uniformly on SO(3) (within XYZ Euler limits in degrees)."""

    type_name = "randomizer.rotation"
    call = Call(named=False)
    inputs = {**TARGET, **mirrored_ports(FR.rotation, min_angle="vec3", max_angle="vec3"), "seed": Port(int)}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        angles = FR.rotation(prims, ctx.value("min_angle"), ctx.value("max_angle"), rng=ctx.rng)
        ctx.record("rotation", angles)
        return {"prims": prims}


UNBOUNDED = (None, None, None)   # a sampling corner that limits no axis (Replicator's min_samp / max_samp)


def _opt_prims(ctx: ExecContext, port: str) -> list[Usd.Prim] | None:
    return ctx.prims(port) if ctx.given(port) else None


@register_node
class Scatter2D(Randomizer):
    """Place the prims on ``surface_prims`` (``graphsdg.functional.randomizer.scatter_2d``)."""

    type_name = "randomizer.scatter_2d"
    inputs = {**TARGET, "surface_prims": Port("prims", required=True), "no_coll_prims": Port("prims"),
              "min_samp": Port("vec3", UNBOUNDED), "max_samp": Port("vec3", UNBOUNDED), "seed": Port(int),
              # Replicator's graph call takes the int 0, its functional call 0.0 (plain values are part of the
              # node's identity)
              "offset": Port(float, 0), **mirrored_ports(FR.scatter_2d, check_for_collisions=bool)}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        kwargs: dict[str, Any] = {"no_collision_prims": _opt_prims(ctx, "no_coll_prims"),
                                  "offset": float(ctx.value("offset")),
                                  "check_for_collisions": bool(ctx.value("check_for_collisions")), "rng": ctx.rng}
        extents = _extents(ctx)
        if extents is not None:
            kwargs["extents"] = extents
        FR.scatter_2d(prims, ctx.prims("surface_prims"), **kwargs)
        ctx.record("positions", [_translation(p) for p in prims])
        return {"prims": prims}


@register_node
class Scatter3D(Randomizer):
    """Place the prims inside ``volume_prims`` (``graphsdg.functional.randomizer.scatter_3d``)."""

    type_name = "randomizer.scatter_3d"
    inputs = {**TARGET, "volume_prims": Port("prims"), "no_coll_prims": Port("prims"),
              "volume_excl_prims": Port("prims"), "min_samp": Port("vec3", UNBOUNDED),
              "max_samp": Port("vec3", UNBOUNDED),
              "resolution_scaling": mirrored_port(FR.scatter_3d, "resolution_scaling", float),
              "voxel_size": mirrored_port(FR.scatter_3d, "input_voxel_size", float),
              **mirrored_ports(FR.scatter_3d, check_for_collisions=bool, prevent_vol_overlap=bool,
                               viz_sampled_voxels=bool), "seed": Port(int)}

    def compute(self, ctx: ExecContext) -> dict:
        prims = ctx.prims()
        kwargs: dict[str, Any] = {"no_collision_prims": _opt_prims(ctx, "no_coll_prims"),
                                  "volume_excl_prims": _opt_prims(ctx, "volume_excl_prims"),
                                  "check_for_collisions": bool(ctx.value("check_for_collisions")),
                                  "prevent_vol_overlap": bool(ctx.value("prevent_vol_overlap")),
                                  "viz_sampled_voxels": bool(ctx.value("viz_sampled_voxels")),
                                  "resolution_scaling": float(ctx.value("resolution_scaling")),
                                  "input_voxel_size": float(ctx.value("voxel_size")), "rng": ctx.rng}
        extents = _extents(ctx)
        if extents is not None:
            kwargs["extents"] = extents
        FR.scatter_3d(prims, _opt_prims(ctx, "volume_prims"), **kwargs)
        ctx.record("positions", [_translation(p) for p in prims])
        return {"prims": prims}


def _extents(ctx: ExecContext) -> Any:
    lo, hi = ctx.value("min_samp"), ctx.value("max_samp")
    if lo is None and hi is None or (all(v is None for v in (lo or ())) and all(v is None for v in (hi or ()))):
        return None
    return (lo, hi)


def _translation(prim: Usd.Prim) -> list[float]:
    attr = prim.GetAttribute("xformOp:translate")
    value = attr.Get() if attr else None
    return [float(v) for v in value] if value is not None else [0.0, 0.0, 0.0]


@register_node
class Instantiate(Randomizer):
    """``size`` instances under ``/Replicator``, each referencing a USD file drawn from ``paths``."""

    type_name = "randomizer.instantiate"
    call = Call(name_before="use_cache")
    inputs = {"paths": Port(list, required=True), "size": Port(int, required=True), "weights": Port(list),
              "mode": Port(str, "scene_instance"), "with_replacements": Port(bool, True), "seed": Port(int),
              "use_cache": Port(bool, True), "semantics": Port(list)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        if isinstance(values.get("paths"), str):
            values["paths"] = [values["paths"]]
        elif "paths" in values and not is_random_value(values["paths"]):
            values["paths"] = list(values["paths"])
        super().__init__(name=name, **values)
        paths, size = self.value_of("paths"), self.value_of("size")
        if isinstance(size, bool) or not isinstance(size, int) or size < 1:
            raise ValueError(f"instantiate: size must be a positive integer, got {size!r}")
        if self.value_of("mode") not in ("scene_instance", "point_instance", "reference"):
            raise ValueError(f"instantiate: mode must be 'scene_instance', 'point_instance' or 'reference', "
                             f"got {self.value_of('mode')!r}")
        if is_random_value(paths):   # a distribution of USD files: its draws fill the slots each execution
            return
        if not paths:
            raise ValueError(f"instantiate: paths must be a non-empty list of USD files, got {paths!r}")
        weights = self.value_of("weights")
        if weights is not None and (len(weights) != len(paths) or sum(weights) <= 0 or min(weights) < 0):
            raise ValueError(f"instantiate: weights {weights!r} must be {len(paths)} non-negative numbers "
                             f"with a positive sum")
        if not self.value_of("with_replacements") and size > len(paths):
            raise ValueError(f"instantiate: {size} instances without replacement from only {len(paths)} paths")

    def setup(self, ctx: ExecContext) -> None:
        base = self.user_name or "Instance"
        slots = []
        for _ in range(int(self.value_of("size"))):
            prim = FC.xform(name=f"{base}_Xform", parent=Sdf.Path(REPLICATOR_ROOT),
                            semantics=self.value_of("semantics"))
            prim.SetInstanceable(self.value_of("mode") == "scene_instance")
            slots.append(prim)
        self.output_values = {"prims": slots}

    def compute(self, ctx: ExecContext) -> dict:
        slots = list(self.output_values["prims"])
        if ctx.is_random("paths"):
            chosen = [os.fspath(p) for p in ctx.per_prim("paths", len(slots), SCALAR)]
            FM.reference(slots, chosen)
            if self.value_of("semantics"):
                FM.semantics(slots, self.value_of("semantics"))
            return {"prims": slots}
        paths = list(self.value_of("paths"))
        weights = self.value_of("weights")
        p = None if weights is None else np.asarray(weights, dtype=np.float64) / float(sum(weights))
        idx = ctx.rng.choice(len(paths), size=len(slots), replace=bool(self.value_of("with_replacements")), p=p)
        chosen = [paths[int(i)] for i in idx]
        FM.reference(slots, chosen)
        if self.value_of("semantics"):
            FM.semantics(slots, self.value_of("semantics"))
        ctx.record("paths", chosen)
        return {"prims": slots}
