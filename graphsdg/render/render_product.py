"""Render products: a camera at a resolution, the unit annotators attach to.

Mirrors ``rep.create.render_product``: the returned object has ``.path``
(``/Render/RenderProduct_<name>``), ``.name``, ``.hydra_texture`` with
``set_updates_enabled``, and ``destroy()``.
"""
from __future__ import annotations

from typing import Iterable, Sequence

import numpy as np
from pxr import Usd, UsdGeom

from graphsdg.base import settings_store as settings
from graphsdg.errors import InvalidPrimError, RenderProductDestroyedError
from graphsdg.stage.sensor_schemas import SENSOR_PRIM_TYPES
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import resolve_prim, structure_version

DEFAULT_NAME = "Replicator"


class HydraTexture:
    """The rendering side of a product; ``set_updates_enabled(False)`` skips its renders."""

    def __init__(self) -> None:
        self._enabled = True

    def set_updates_enabled(self, enabled: bool) -> None:
        self._enabled = bool(enabled)

    def get_updates_enabled(self) -> bool:
        return self._enabled


class RenderProduct:
    """A camera prim rendered at ``resolution = (width, height)``."""

    def __init__(self, camera: str, resolution: tuple[int, int], name: str) -> None:
        self.camera = camera
        self.resolution = resolution
        self.name = name
        self.path = f"/Render/RenderProduct_{name}"
        self.hydra_texture = HydraTexture()
        self._destroyed = False
        self._camera_prim: tuple | None = None   # (id of the stage, camera path, structure version, prim)

    @property
    def width(self) -> int:
        return self.resolution[0]

    @property
    def height(self) -> int:
        return self.resolution[1]

    @property
    def destroyed(self) -> bool:
        return self._destroyed

    def check_alive(self) -> None:
        if self._destroyed:
            raise RenderProductDestroyedError(
                f"render product {self.name!r} ({self.path}) was destroyed; create a new one with "
                f"rep.create.render_product(camera, resolution)")

    def camera_prim(self, stage: Usd.Stage | None = None) -> Usd.Prim:
        """The camera's prim on ``stage`` (default: the current one); raises if it is gone or no camera.

        The prim object is kept while the stage's structure stands still (:func:`structure_version`): a
        frame asks for it several times, and each USD lookup costs tens of microseconds inside a capture
        loop."""
        stage = stage or get_stage()
        version = structure_version()
        kept = self._camera_prim
        if kept is not None and kept[0] == id(stage) and kept[1] == self.camera and kept[2] == version:
            return kept[3]
        prim = stage.GetPrimAtPath(self.camera)
        if not prim or not is_product_source(prim):
            raise InvalidPrimError(f"render product {self.name!r}: camera {self.camera!r} no longer exists "
                                   f"or is not a Camera (or a lidar / radar)")
        # the stage by id: holding it would keep its layers, and the edits in them, alive after it is closed
        self._camera_prim = (id(stage), self.camera, version, prim)
        return prim

    def destroy(self) -> None:
        """Release the product. Stepping while an annotator or writer is still attached to it raises."""
        if self._destroyed:
            return
        self._destroyed = True
        self._camera_prim = None
        registry.remove(self)

    def __repr__(self) -> str:
        state = "destroyed" if self._destroyed else f"{self.width}x{self.height}"
        return f"RenderProduct({self.name!r}, camera={self.camera!r}, {state})"


class RenderProductRegistry:
    """All live render products of the process, in creation order."""

    KEEP_DESTROYED = 64   # destroyed products remembered for a clear "was destroyed" error (bounded: no leak)

    def __init__(self) -> None:
        self._products: list[RenderProduct] = []
        self._destroyed: dict[str, RenderProduct] = {}   # path and name -> last destroyed product, oldest first

    def __iter__(self):
        return iter(list(self._products))

    def __len__(self) -> int:
        return len(self._products)

    def unique_name(self, name: str | None) -> str:
        base = name or DEFAULT_NAME
        taken = {p.name for p in self._products}
        if base not in taken:
            return base
        i = 1
        while f"{base}_{i:02d}" in taken:
            i += 1
        return f"{base}_{i:02d}"

    def add(self, rp: RenderProduct) -> None:
        self._products.append(rp)

    def remove(self, rp: RenderProduct) -> None:
        if rp in self._products:
            self._products.remove(rp)
            for key in (rp.path, rp.name):
                self._destroyed.pop(key, None)
                self._destroyed[key] = rp
            while len(self._destroyed) > 2 * self.KEEP_DESTROYED:
                del self._destroyed[next(iter(self._destroyed))]

    def find(self, value: "RenderProduct | str") -> RenderProduct:
        if isinstance(value, RenderProduct):
            value.check_alive()
            return value
        for rp in self._products:
            if value in (rp.path, rp.name):
                return rp
        gone = self._destroyed.get(value) if isinstance(value, str) else None
        if gone is not None:
            gone.check_alive()
        raise ValueError(f"no render product named or at path {value!r}; live products: "
                         f"{[p.path for p in self._products]}")

    def clear(self) -> None:
        """Destroy every live render product."""
        for rp in list(self._products):
            rp.destroy()

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """Destroy every render product: they showed the old stage."""
        self.clear()


#: The process's render products (held by the session, :mod:`graphsdg.engine.session`).
registry = RenderProductRegistry()


def _validate_resolution(resolution: object) -> tuple[int, int]:
    try:
        w, h = resolution  # type: ignore[misc]
    except (TypeError, ValueError):
        raise ValueError(f"resolution must be (width, height), two positive integers; got {resolution!r}") from None
    if any(isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v <= 0 for v in (w, h)):
        raise ValueError(f"resolution must be (width, height), two positive integers; got {resolution!r}")
    limit = int(settings.get("/graphsdg/render/maxResolution", 4096))
    if w > limit or h > limit:
        raise ValueError(f"resolution {w}x{h} exceeds the largest supported edge {limit} "
                         f"(setting /graphsdg/render/maxResolution)")
    return int(w), int(h)


def _scaled(resolution: tuple[int, int]) -> tuple[int, int]:
    """``resolution`` times the ``/graphsdg/render/resolutionScale`` setting (aspect kept up to rounding)."""
    scale = float(settings.get("/graphsdg/render/resolutionScale", 1.0))
    if not scale > 0:
        raise ValueError(f"setting /graphsdg/render/resolutionScale must be > 0, got {scale!r}")
    if scale == 1.0:
        return resolution
    return max(1, round(resolution[0] * scale)), max(1, round(resolution[1] * scale))


def is_product_source(prim: Usd.Prim) -> bool:
    """Whether a render product can be made of ``prim``: a ``UsdGeom.Camera``, or a ray-cast sensor (``OmniLidar``,
    ``OmniRadar``: its product's annotators read the sensor's scans, docs/sensors.md)."""
    return prim.IsA(UsdGeom.Camera) or prim.GetTypeName() in SENSOR_PRIM_TYPES


def _camera_path(camera: object) -> str:
    if hasattr(camera, "get_output_prims"):  # a graph item wrapping a camera node
        prims = camera.get_output_prims()["prims"]
        if len(prims) != 1:
            raise InvalidPrimError(f"render product camera item yields {len(prims)} prims; expected one camera")
        camera = prims[0]
    prim = resolve_prim(camera)  # type: ignore[arg-type]
    if not is_product_source(prim):
        raise InvalidPrimError(f"render product camera {str(prim.GetPath())!r} is a {prim.GetTypeName() or 'typeless'} "
                               f"prim, not a UsdGeom.Camera (or an OmniLidar / OmniRadar sensor)")
    return str(prim.GetPath())


def _item_cameras(item: object) -> list[Usd.Prim]:
    """The cameras (and sensors) of a graph item: each prim a product can be made of, else those below it
    (Replicator's Xform wrappers and stereo rigs)."""
    cameras: list[Usd.Prim] = []
    for prim in item.get_output_prims()["prims"]:  # type: ignore[attr-defined]
        if is_product_source(prim):
            cameras.append(prim)
        else:
            cameras += [p for p in Usd.PrimRange(prim) if is_product_source(p)]
    if not cameras:
        raise InvalidPrimError(f"render product camera item {item!r} holds no UsdGeom.Camera prim (or OmniLidar / "
                               f"OmniRadar sensor)")
    return cameras


def create_render_product(camera: object, resolution: Sequence[int], force_new: bool = False,
                          name: str | None = None, render_vars: Iterable[str] | None = None
                          ) -> RenderProduct | list[RenderProduct]:
    """Create a render product of ``camera`` (prim, path, or list of them) at ``(width, height)``.

    Example:
        >>> import graphsdg as rep
        >>> _ = rep.stage.new_stage()
        >>> cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0))
        >>> rp = rep.create.render_product(cam, (64, 48))
        >>> rp.resolution
        (64, 48)
    """
    res = _validate_resolution(resolution)
    if hasattr(camera, "get_output_prims"):   # a graph item: each camera it made (a stereo rig: both), as Replicator
        cameras = _item_cameras(camera)
        camera = cameras[0] if len(cameras) == 1 else cameras
    if isinstance(camera, (list, tuple)) and not (len(camera) == 3 and all(isinstance(c, (int, float))
                                                                           for c in camera)):
        return [create_render_product(c, res, force_new, name, render_vars) for c in camera]  # type: ignore
    path = _camera_path(camera)
    res = _scaled(res)
    if not force_new:
        for rp in registry:
            if rp.camera == path and rp.resolution == res and (name is None or rp.name == name):
                return rp
    rp = RenderProduct(path, res, registry.unique_name(name))
    registry.add(rp)
    return rp


__all__ = ["RenderProduct", "HydraTexture", "create_render_product", "registry"]
