"""``rep.create``: graph-API creators (prims under ``/Replicator``) and render products.

Every call returns a :class:`~graphsdg.graph.ReplicatorItem`. Prims are made when
the call is built; arguments given as distributions are re-sampled (one value
per prim) each time the enclosing trigger fires.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> lights = rep.create.light(light_type="Sphere", intensity=5000, count=2)
    >>> [str(p.GetPath()) for p in lights.get_output_prims()["prims"]]
    ['/Replicator/SphereLight_Xform/SphereLight', '/Replicator/SphereLight_Xform_01/SphereLight']
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.builder import add_node
from graphsdg.graph.node import ReplicatorItem
from graphsdg.graph.registration import register_function
from graphsdg.graph.registry import NodeRegistry
from graphsdg.render.render_product import create_render_product as render_product


def _shape(shape: str) -> Callable[..., ReplicatorItem]:
    def create_shape(position: Any = None, scale: Any = None, pivot: Any = None, rotation: Any = None,
                     look_at: Any = None, look_at_up_axis: Any = None, semantics: Any = None, material: Any = None,
                     visible: bool = True, as_mesh: bool = False, count: int = 1, name: str | None = None,
                     parent: Any = None) -> ReplicatorItem:
        return add_node(NodeRegistry.create(
            f"create.{shape}", name=name, position=position, scale=scale, pivot=pivot, rotation=rotation,
            look_at=look_at, look_at_up_axis=look_at_up_axis, semantics=semantics, material=material,
            visible=visible, as_mesh=as_mesh, count=count, parent=parent))

    create_shape.__name__ = create_shape.__qualname__ = shape
    create_shape.__doc__ = (f"``count`` unit {shape}s at ``/Replicator/{shape.capitalize()}_Xform/"
                            f"{shape.capitalize()}``; pose arguments may be distributions; ``as_mesh=True`` "
                            f"makes each a ``UsdGeom.Mesh`` (Replicator's default; graphsdg's is an implicit prim).")
    return create_shape


cube = _shape("cube")
sphere = _shape("sphere")
cylinder = _shape("cylinder")
cone = _shape("cone")
capsule = _shape("capsule")
torus = _shape("torus")
disk = _shape("disk")
plane = _shape("plane")


def xform(position: Any = None, scale: Any = None, rotation: Any = None, look_at: Any = None,
          look_at_up_axis: Any = None, semantics: Any = None, visible: bool = True, count: int = 1,
          name: str | None = None, parent: Any = None) -> ReplicatorItem:
    """``count`` empty Xforms."""
    return add_node(NodeRegistry.create("create.xform", name=name, position=position, scale=scale,
                                        rotation=rotation, look_at=look_at, look_at_up_axis=look_at_up_axis,
                                        semantics=semantics, visible=visible, count=count, parent=parent))


def light(position: Any = None, scale: Any = None, rotation: Any = None, look_at: Any = None,
          look_at_up_axis: Any = None, light_type: str = "Distant", color: Any = (1.0, 1.0, 1.0),
          intensity: Any = 1000.0, exposure: Any = None, temperature: Any = 6500, texture: Any = None,
          count: int = 1, name: str | None = None, parent: Any = None) -> ReplicatorItem:
    """``count`` lights of ``light_type`` (cylinder, disk, distant, dome, rect, sphere; any case).

    ``temperature`` is in Kelvin (colour temperature is switched on); ``texture``
    is a dome light's image. Every argument may be a distribution.
    """
    return add_node(NodeRegistry.create(
        "create.light", name=name, position=position, scale=scale, rotation=rotation, look_at=look_at,
        look_at_up_axis=look_at_up_axis, light_type=light_type, color=color, intensity=intensity,
        exposure=exposure, temperature=temperature, texture=texture, count=count, parent=parent))


def camera(position: Any = None, rotation: Any = None, look_at: Any = None, look_at_up_axis: Any = None,
           focal_length: Any = 24.0, focus_distance: Any = 400.0, f_stop: Any = 0.0,
           horizontal_aperture: Any = 20.955, horizontal_aperture_offset: float = 0.0,
           vertical_aperture_offset: float = 0.0, clipping_range: tuple[float, float] = (0.01, 1000000.0),
           projection_type: str = "pinhole", count: int = 1, parent: Any = None, name: str | None = None,
           **fisheye: Any) -> ReplicatorItem:
    """``count`` cameras. The near clip defaults to 0.01 (graphsdg stages are in metres; Replicator's 1.0
    is one centimetre on its default stage). Fisheye parameters are accepted and unused (pinhole only)."""
    return add_node(NodeRegistry.create(
        "create.camera", name=name, position=position, rotation=rotation, look_at=look_at,
        look_at_up_axis=look_at_up_axis, focal_length=focal_length, focus_distance=focus_distance, f_stop=f_stop,
        horizontal_aperture=horizontal_aperture, horizontal_aperture_offset=horizontal_aperture_offset,
        vertical_aperture_offset=vertical_aperture_offset, clipping_range=clipping_range,
        projection_type=projection_type, count=count, parent=parent))


def material_omnipbr(diffuse: Any = None, diffuse_texture: Any = None, roughness: Any = None,
                     roughness_texture: Any = None, metallic: Any = None, metallic_texture: Any = None,
                     specular: Any = None, emissive_color: Any = None, emissive_texture: Any = None,
                     emissive_intensity: Any = 0.0, project_uvw: bool = False, semantics: Any = None,
                     count: int = 1, name: str | None = None) -> ReplicatorItem:
    """``count`` OmniPBR materials under ``/Replicator/Looks``; distribution inputs re-sampled per material."""
    return add_node(NodeRegistry.create(
        "create.material_omnipbr", name=name, diffuse=diffuse, diffuse_texture=diffuse_texture,
        roughness=roughness, roughness_texture=roughness_texture, metallic=metallic,
        metallic_texture=metallic_texture, specular=specular, emissive_color=emissive_color,
        emissive_texture=emissive_texture, emissive_intensity=emissive_intensity, project_uvw=project_uvw,
        semantics=semantics, count=count))


def group(items: list, semantics: Any = None, name: str | None = None) -> ReplicatorItem:
    """The union of ``items`` (items, prims or paths): ``with group:`` edits each of them."""
    if not isinstance(items, (list, tuple)) or not items:
        raise ValueError(f"group needs a non-empty list of items, got {items!r}")
    return add_node(NodeRegistry.create("create.group", name=name, items=list(items), semantics=semantics))


def from_usd(usd: str, position: Any = None, scale: Any = None, rotation: Any = None, look_at: Any = None,
             look_at_up_axis: Any = None, semantics: Any = None, count: int = 1, name: str | None = None,
             parent: Any = None) -> ReplicatorItem:
    """``count`` references to the USD file ``usd``."""
    return add_node(NodeRegistry.create(
        "create.from_usd", name=name, usd=usd, position=position, scale=scale, rotation=rotation, look_at=look_at,
        look_at_up_axis=look_at_up_axis, semantics=semantics, count=count, parent=parent))


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.create.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = ["cube", "sphere", "cylinder", "cone", "capsule", "torus", "disk", "plane", "xform", "light", "camera",
           "material_omnipbr", "group", "from_usd", "register", "render_product"]
