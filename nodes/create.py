"""Create nodes: make prims under ``/Replicator`` when built, re-sample their distributions per execution.

Each prim gets Replicator's layout: an Xform wrapper with the prim under it
(``/Replicator/Cube_Xform/Cube``, ``/Replicator/Cube_Xform_01/Cube``, ...). The
item's prims are the inner prims. Plain arguments are applied once, at creation;
distribution arguments are sampled (one value per prim) each time the trigger
fires. Prim creation itself goes through ``graphsdg.functional.create``.
"""
from __future__ import annotations

import os
import warnings
from typing import Any, Callable

import numpy as np
from pxr import Sdf, Usd, UsdShade

from graphsdg.functional import create as FC
from graphsdg.functional import modify as FM
from graphsdg.graph.calls import Call
from graphsdg.graph.graph import REPLICATOR_ROOT
from graphsdg.graph.node import ExecContext, Node, Port, flatten_prims, is_random_value
from graphsdg.graph.registry import register_node
from graphsdg.graph.value_shapes import SCALAR, VEC3, attribute_shapes
from graphsdg.stage.context import get_stage
from graphsdg.stage.materials import surface_shader

from .mirrored_ports import mirrored_port, mirrored_ports
from .modify import POSE_PORTS, apply_pose

# ports in the order of the calls' parameters (a node lists its values in this order)
POSE = {"position": Port("vec3"), "scale": Port("vec3|float"), "rotation": Port("vec3"),
        "look_at": Port("vec3|prim"), "look_at_up_axis": Port("vec3")}
SHAPE_POSE = {"position": POSE["position"], "scale": POSE["scale"], "pivot": Port("vec3"), "rotation": POSE["rotation"],
              "look_at": POSE["look_at"], "look_at_up_axis": POSE["look_at_up_axis"]}
COMMON = {"count": Port(int, 1), "parent": Port("prim")}
LOOKS = REPLICATOR_ROOT + "/Looks"


def _count(node: Node) -> int:
    count = node.value_of("count")
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ValueError(f"{node.type_name}: count must be a positive integer, got {count!r}")
    return int(count)


def _plain(node: Node, port: str) -> Any:
    """The port's plain value, or None when it is a distribution (sampled at execution)."""
    value = node.value_of(port)
    return None if is_random_value(value) else value


class CreateNode(Node):
    """Base of create nodes: ``make(ctx, name, parent)`` makes one prim; setup makes ``count``."""

    family = "create"
    call = Call(name_before="parent")
    outputs = {"prims": Port("prims")}
    default_name = "Prim"
    attribute_ports: dict[str, str] = {}   # port -> USD attribute re-sampled per execution

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        _count(self)

    def make(self, ctx: ExecContext, name: str, parent: Sdf.Path) -> Usd.Prim:
        raise NotImplementedError

    def parent_path(self) -> Sdf.Path:
        parent = self.value_of("parent")
        if parent is None:
            return Sdf.Path(REPLICATOR_ROOT)
        prims = flatten_prims(parent, f"{self.type_name}.parent")
        if len(prims) != 1:
            raise ValueError(f"{self.type_name}: parent must name one prim, got {len(prims)}")
        return prims[0].GetPath()

    def setup(self, ctx: ExecContext) -> None:
        base = self.user_name or self.default_name
        prims = []
        for _ in range(_count(self)):
            wrapper = FC.xform(name=f"{base}_Xform", parent=self.parent_path())
            prims.append(self.make(ctx, base, wrapper.GetPath()))
            if self.graph is not None:
                self.graph.created_prims.append(str(wrapper.GetPath()))
        self.output_values = {"prims": prims}
        if not any(is_random_value(self.values.get(p)) for p in POSE_PORTS):
            apply_pose(ctx, prims)

    def compute(self, ctx: ExecContext) -> dict:
        prims = list(self.output_values.get("prims") or [])
        if any(is_random_value(self.values.get(p)) for p in POSE_PORTS):
            apply_pose(ctx, prims)
        for port, attr in self.attribute_ports.items():
            if ctx.is_random(port) and prims:
                shapes = attribute_shapes(prims[0].GetAttribute(attr).GetTypeName()) \
                    if prims[0].GetAttribute(attr) else SCALAR
                for prim, v in zip(prims, ctx.per_prim(port, len(prims), shapes)):
                    FM.attribute(prim, attr, self.convert(port, v))
        return {"prims": prims}

    def convert(self, port: str, value: Any) -> Any:
        return value.tolist() if isinstance(value, np.ndarray) else value


def _shape_node(shape: str) -> type[CreateNode]:
    make_fn: Callable[..., Usd.Prim] = getattr(FC, shape)

    class Shape(CreateNode):
        __doc__ = (f"``count`` unit {shape}s at ``/Replicator/{shape.capitalize()}_Xform/"
                   f"{shape.capitalize()}``; pose arguments may be distributions; ``as_mesh=True`` "
                   f"makes each a ``UsdGeom.Mesh`` (Replicator's default; graphsdg's is an implicit prim).")
        type_name = f"create.{shape}"
        default_name = shape.capitalize()
        inputs = {**SHAPE_POSE, "semantics": Port(list), "material": Port("material"),
                  **mirrored_ports(make_fn, visible=bool, as_mesh=bool), **COMMON}

        def make(self, ctx: ExecContext, name: str, parent: Sdf.Path) -> Usd.Prim:
            prim = make_fn(name=name, parent=parent, semantics=self.value_of("semantics"),
                           visible=bool(self.value_of("visible")), as_mesh=bool(self.value_of("as_mesh")))
            material = self.value_of("material")
            if material is not None:
                mats = flatten_prims(ctx.value("material"), f"{self.type_name}.material")
                FM.material(prim, mats[0])
            return prim

    Shape.__name__ = Shape.__qualname__ = f"Create{shape.capitalize()}"
    return register_node(Shape)


SHAPES = ("cube", "sphere", "cylinder", "cone", "capsule", "torus", "disk", "plane")
SHAPE_NODES = {s: _shape_node(s) for s in SHAPES}


@register_node
class CreateXform(CreateNode):
    """``count`` empty Xforms."""

    type_name = "create.xform"
    default_name = "Xform"
    inputs = {**POSE, "semantics": Port(list), **mirrored_ports(FC.xform, visible=bool), **COMMON}

    def make(self, ctx: ExecContext, name: str, parent: Sdf.Path) -> Usd.Prim:
        return FC.xform(name=name, parent=parent, semantics=self.value_of("semantics"),
                        visible=bool(self.value_of("visible")))


LIGHT_TYPES = {"cylinder": FC.cylinder_light, "disk": FC.disk_light, "distant": FC.distant_light,
               "dome": FC.dome_light, "rect": FC.rect_light, "sphere": FC.sphere_light}


@register_node
class CreateLight(CreateNode):
    """``count`` lights of ``light_type`` (cylinder, disk, distant, dome, rect, sphere; any case).

    ``temperature`` is in Kelvin (colour temperature is switched on); ``texture``
    is a dome light's image. Every argument may be a distribution.
    """

    # the renderer turns Kelvin into RGB with graphsdg.sim.lights.kelvin_to_rgb and multiplies it with color;
    # temperature's default is the int 6500, as Replicator's (plain values are part of the node's identity);
    # every light function of graphsdg.functional.create has the same default intensity
    type_name = "create.light"
    inputs = {**POSE, "light_type": Port(str, "Distant"), "color": Port("rgb", (1.0, 1.0, 1.0)),
              "intensity": mirrored_port(FC.distant_light, "intensity", float), "exposure": Port(float),
              "temperature": Port(float, 6500), "texture": Port(str), **COMMON}
    attribute_ports = {"color": "inputs:color", "intensity": "inputs:intensity", "exposure": "inputs:exposure",
                       "temperature": "inputs:colorTemperature", "texture": "inputs:texture:file"}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        kind = self.value_of("light_type")
        if not isinstance(kind, str) or kind.lower() not in LIGHT_TYPES:
            raise ValueError(f"create.light: light_type {kind!r} is not one of {sorted(LIGHT_TYPES)} "
                             f"(case-insensitive)")
        if self.value_of("texture") is not None and kind.lower() != "dome":
            raise ValueError(f"create.light: texture applies to Dome lights only, not {kind!r}")
        tex = _plain(self, "texture")
        if tex is not None and not os.path.isfile(os.fspath(tex)):
            raise FileNotFoundError(f"create.light: texture {os.fspath(tex)!r} does not exist")

    @property
    def default_name(self) -> str:  # type: ignore[override]
        return f"{self.value_of('light_type').capitalize()}Light"

    def make(self, ctx: ExecContext, name: str, parent: Sdf.Path) -> Usd.Prim:
        kind = self.value_of("light_type").lower()
        kwargs: dict[str, Any] = {"name": name, "parent": parent}
        for port in ("intensity", "exposure", "color", "temperature"):
            plain = _plain(self, port)
            if plain is not None:
                kwargs[port] = plain
        # a drawn temperature starts at the port's default; each execution then sets its draw
        kwargs.setdefault("temperature", float(self.inputs["temperature"].default))
        if kind == "dome" and _plain(self, "texture") is not None:
            kwargs["texture"] = _plain(self, "texture")
        return LIGHT_TYPES[kind](**kwargs)

    def convert(self, port: str, value: Any) -> Any:
        if port == "texture":
            return Sdf.AssetPath(os.fspath(value))
        if port in ("intensity", "exposure", "temperature"):
            return float(np.asarray(value).reshape(-1)[0])
        return super().convert(port, value)


@register_node
class CreateCamera(CreateNode):
    """``count`` cameras. The near clip defaults to 0.01 (graphsdg stages are in metres; Replicator's 1.0
    is one centimetre on its default stage). Fisheye parameters are accepted and unused (pinhole only)."""

    # a pinhole camera; focal length and apertures in tenths of a stage unit
    type_name = "create.camera"
    default_name = "Camera"
    call = Call(ignored_keywords="fisheye")
    inputs = {**{k: p for k, p in POSE.items() if k != "scale"},
              **mirrored_ports(FC.camera, focal_length=float, focus_distance=float, f_stop=float,
                               horizontal_aperture=float, horizontal_aperture_offset=float,
                               vertical_aperture_offset=float, clipping_range="vec2", projection_type=str),
              **COMMON}
    attribute_ports = {"focal_length": "focalLength", "focus_distance": "focusDistance", "f_stop": "fStop",
                       "horizontal_aperture": "horizontalAperture"}

    def make(self, ctx: ExecContext, name: str, parent: Sdf.Path) -> Usd.Prim:
        kwargs = {k: _plain(self, k) for k in ("focal_length", "focus_distance", "f_stop", "horizontal_aperture",
                                               "horizontal_aperture_offset", "vertical_aperture_offset",
                                               "clipping_range", "projection_type")}
        return FC.camera(name=name, parent=parent, **{k: v for k, v in kwargs.items() if v is not None})

    def convert(self, port: str, value: Any) -> Any:
        return float(np.asarray(value).reshape(-1)[0])


MDL_INPUTS = {"diffuse": "diffuse_color_constant", "diffuse_texture": "diffuse_texture",
              "roughness": "reflection_roughness_constant", "metallic": "metallic_constant",
              "emissive_color": "emissive_color", "emissive_intensity": "emissive_intensity"}
# OmniPBR inputs kept on the material's shader for readers of the stage; the classic renderer draws none of them
UNRENDERED_INPUTS = {"roughness_texture": "reflectionroughness_texture", "metallic_texture": "metallic_texture",
                     "emissive_texture": "emissive_color_texture", "specular": "specular_level"}
_warned_unrendered: set[str] = set()


@register_node
class CreateMaterialOmniPBR(CreateNode):
    """``count`` OmniPBR materials under ``/Replicator/Looks``; distribution inputs re-sampled per material."""

    type_name = "create.material_omnipbr"
    default_name = "OmniPBR"
    call = Call()
    inputs = {"diffuse": Port("rgb"), "diffuse_texture": Port(str), "roughness": Port(float),
              "roughness_texture": Port(str), "metallic": Port(float), "metallic_texture": Port(str),
              "specular": Port(float), "emissive_color": Port("rgb"), "emissive_texture": Port(str),
              "emissive_intensity": Port(float, 0.0), "project_uvw": Port(bool, False), "semantics": Port(list),
              "count": Port(int, 1)}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        super().__init__(name=name, **values)
        given = [k for k in UNRENDERED_INPUTS if values.get(k) is not None and k not in _warned_unrendered]
        if given:
            _warned_unrendered.update(given)
            warnings.warn(f"material_omnipbr: {given} are authored on the material's shader but not rendered "
                          f"(graphsdg draws diffuse, diffuse_texture, roughness, metallic and emission)",
                          stacklevel=4)

    def setup(self, ctx: ExecContext) -> None:
        stage = get_stage()
        if not stage.GetPrimAtPath(LOOKS).IsValid():
            FC.scope(name="Looks", parent=REPLICATOR_ROOT)
        mats = []
        for _ in range(_count(self)):
            inputs = {mdl: _plain(self, port) for port, mdl in MDL_INPUTS.items()}
            inputs = {k: v for k, v in inputs.items() if v is not None}
            if self.value_of("emissive_intensity") and "emissive_color" not in inputs:
                inputs["emissive_color"] = (1.0, 1.0, 1.0)
            prim = FC.material(mdl="OmniPBR.mdl", name=self.user_name or "OmniPBR", parent=LOOKS, **inputs)
            for port, mdl in UNRENDERED_INPUTS.items():
                if _plain(self, port) is not None:
                    _author_unrendered(prim, mdl, _plain(self, port))
            if self.value_of("semantics"):
                FM.semantics(prim, self.value_of("semantics"))
            mats.append(prim)
        self.output_values = {"prims": mats}

    def compute(self, ctx: ExecContext) -> dict:
        mats = list(self.output_values["prims"])
        inputs = {}
        for port, mdl in MDL_INPUTS.items():
            if ctx.is_random(port):
                shapes = VEC3 if port in ("diffuse", "emissive_color") else SCALAR
                values = ctx.per_prim(port, len(mats), shapes)
                inputs[mdl] = values if port == "diffuse_texture" else np.array(values, dtype=np.float64)
        if inputs:
            FM.material_inputs(mats, **inputs)
        for port, mdl in UNRENDERED_INPUTS.items():
            if ctx.is_random(port):
                for mat, value in zip(mats, ctx.per_prim(port, len(mats), SCALAR)):
                    _author_unrendered(mat, mdl, value)
        return {"prims": mats}


def _author_unrendered(material: Usd.Prim, mdl_input: str, value: Any) -> None:
    """Keep an OmniPBR input graphsdg does not render on the material's surface shader (``inputs:<name>``)."""
    shader = surface_shader(UsdShade.Material(material))
    target = shader.GetPrim() if shader is not None else material
    if mdl_input.endswith("_texture"):
        target.CreateAttribute(f"inputs:{mdl_input}", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(os.fspath(value)))
    else:
        target.CreateAttribute(f"inputs:{mdl_input}", Sdf.ValueTypeNames.Float).Set(
            float(np.asarray(value).reshape(-1)[0]))


@register_node
class CreateGroup(Node):
    """The union of ``items`` (items, prims or paths): ``with group:`` edits each of them."""

    type_name = "create.group"
    family = "create"
    call = Call()
    inputs = {"items": Port(list, required=True), "semantics": Port(list)}
    outputs = {"prims": Port("prims")}

    def __init__(self, name: str | None = None, **values: Any) -> None:
        items = values.get("items")
        if not isinstance(items, (list, tuple)) or not items:
            raise ValueError(f"group needs a non-empty list of items, got {items!r}")
        super().__init__(name=name, **{**values, "items": list(items)})

    def setup(self, ctx: ExecContext) -> None:
        prims = flatten_prims(ctx.value("items"), "create.group items")
        if self.value_of("semantics"):
            FM.semantics(prims, self.value_of("semantics"))
        self.output_values = {"prims": prims}

    def compute(self, ctx: ExecContext) -> dict:
        return {"prims": flatten_prims(ctx.value("items"), "create.group items")}


@register_node
class CreateFromUsd(CreateNode):
    """``count`` references to the USD file ``usd``."""

    type_name = "create.from_usd"
    inputs = {"usd": Port(str, required=True), **POSE, "semantics": Port(list), **COMMON}

    @property
    def default_name(self) -> str:  # type: ignore[override]
        return os.path.splitext(os.path.basename(os.fspath(self.value_of("usd"))))[0] or "Asset"

    def make(self, ctx: ExecContext, name: str, parent: Sdf.Path) -> Usd.Prim:
        return FC.reference(self.value_of("usd"), name=name, parent=parent, semantics=self.value_of("semantics"))
