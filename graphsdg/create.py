"""``rep.create``: graph-API creators (prims under ``/Replicator``) and render products.

Every call returns a :class:`~graphsdg.graph.ReplicatorItem`. Prims are made when
the call is built; arguments given as distributions are re-sampled (one value
per prim) each time the enclosing trigger fires. Each creator is its node type in
``nodes/create.py``, made callable by :mod:`graphsdg.graph.calls`.

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

from graphsdg import modify
from graphsdg.graph.calls import add_family_node, family_calls
from graphsdg.graph.node import ReplicatorItem
from graphsdg.graph.registration import register_function
from graphsdg.io.file_search import get_usd_files
from graphsdg.render.render_product import create_render_product as render_product
from graphsdg.stage.context import get_stage

_calls = family_calls("create")
globals().update(_calls)


def from_dir(dir_path: str, recursive: bool = False, path_filter: str | None = None,
             semantics: Any = None) -> ReplicatorItem:
    """A group of references to the USD files in ``dir_path`` (``rep.utils.get_usd_files``' search), one
    ``/Replicator/Ref_Xform/Ref`` each."""
    paths = get_usd_files(dir_path, recursive=recursive, path_filter=path_filter)
    if not paths:
        raise ValueError(f"from_dir: no USD files found in {dir_path!r} (recursive={recursive}, "
                         f"path_filter={path_filter!r})")
    items = [_calls["from_usd"](path, semantics=semantics, name="Ref") for path in paths]
    return _calls["group"](items)


def stereo_camera(stereo_baseline: float, position: Any = None, rotation: Any = None, look_at: Any = None,
                  look_at_up_axis: Any = None, focal_length: float = 24.0, focus_distance: float = 400.0,
                  f_stop: float = 0.0, horizontal_aperture: float = 20.955, horizontal_aperture_offset: float = 0.0,
                  vertical_aperture_offset: float = 0.0, clipping_range: Any = (0.01, 1000000.0),
                  projection_type: str = "pinhole", count: int = 1, name: str | None = None, parent: Any = None,
                  **fisheye: Any) -> ReplicatorItem:
    """``count`` stereo rigs: an Xform (posed by ``position`` / ``rotation`` / ``look_at``) holding a left and a
    right camera ``stereo_baseline`` apart along the rig's horizontal axis (Y on a Z-up stage, X on a Y-up one),
    named ``<name>_L`` / ``<name>_R``. ``rep.create.render_product(rig, ...)`` makes one product per camera.
    Fisheye parameters are accepted and unused (pinhole only)."""
    name = name or "StereoCam"
    rigs = _calls["xform"](position=position, rotation=rotation, count=count, name=name, parent=parent)
    half = float(stereo_baseline) / 2.0
    z_up = str(get_stage().GetMetadata("upAxis") or "Z").upper() == "Z"
    offsets = {"L": (0.0, -half, 0.0) if z_up else (-half, 0.0, 0.0),
               "R": (0.0, half, 0.0) if z_up else (half, 0.0, 0.0)}
    lens = dict(focal_length=focal_length, focus_distance=focus_distance, f_stop=f_stop,
                horizontal_aperture=horizontal_aperture, horizontal_aperture_offset=horizontal_aperture_offset,
                vertical_aperture_offset=vertical_aperture_offset, clipping_range=clipping_range,
                projection_type=projection_type)
    for rig in rigs.get_output_prims()["prims"]:
        for side, offset in offsets.items():
            _calls["camera"](position=offset, parent=rig, name=f"{name}_{side}", **lens)
    if look_at is not None:
        with rigs:
            modify.pose(look_at=look_at, look_at_up_axis=look_at_up_axis)
    return rigs


def render_product_tiled(cameras: Any, tile_resolution: Any, force_new: bool = False,
                         name: str | None = None) -> Any:
    """Replicator's one render product holding a grid of camera tiles; graphsdg does not render tiles.

    Raises, saying to make one render product per camera (``rep.create.render_product(cameras, tile_resolution)``
    returns one per camera of a list), which renders the same images, each as its own array.
    """
    raise NotImplementedError(
        f"rep.create.render_product_tiled(cameras={cameras!r}, tile_resolution={tile_resolution!r}) renders several "
        f"cameras into one tiled image, which graphsdg's renderer does not do (its annotators and writers work on "
        f"one camera per render product). Make one render product per camera instead: "
        f"rep.create.render_product(cameras, tile_resolution) returns one per camera of a list")


def omni_lidar(position: Any = None, rotation: Any = None, look_at: Any = None, look_at_up_axis: Any = None,
               count: int = 1, parent: Any = None, name: str | None = None, config: str | None = None,
               variant: Any = None, **attributes: Any) -> ReplicatorItem:
    """``count`` ray-cast lidars (``OmniLidar`` prims, docs/sensors.md): ``config`` / ``variant`` pick a profile,
    keyword arguments set ``omni:sensor:Core:*`` attributes by name; pose arguments may be distributions."""
    return add_family_node("create", "omni_lidar", name=name, position=position, rotation=rotation,
                           look_at=look_at, look_at_up_axis=look_at_up_axis, count=count, parent=parent,
                           config=config, variant=variant, attributes=attributes)


def omni_radar(position: Any = None, rotation: Any = None, look_at: Any = None, look_at_up_axis: Any = None,
               count: int = 1, parent: Any = None, name: str | None = None, **attributes: Any) -> ReplicatorItem:
    """``count`` ray-cast radars (``OmniRadar`` prims, docs/sensors.md); keyword arguments set
    ``omni:sensor:WpmDmat:*`` attributes by name; pose arguments may be distributions."""
    return add_family_node("create", "omni_radar", name=name, position=position, rotation=rotation,
                           look_at=look_at, look_at_up_axis=look_at_up_axis, count=count, parent=parent,
                           attributes=attributes)


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.create.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = [*_calls, "from_dir", "stereo_camera", "omni_lidar", "omni_radar", "register", "render_product"]
