"""Isaac compat: ``isaacsim.core.experimental.objects.Camera``: ``UsdGeom.Camera`` prims and their optics.

Wraps existing cameras or defines new ones (never a mix), reading and writing
their optics in batches as Isaac does. Isaac's lengths are in stage units while
USD authors the lens in tenths of a stage unit (millimetres on a centimetre
stage): focal lengths, apertures and aperture offsets are multiplied by 10 when
authored and divided by 10 when read, exactly as Isaac does. graphsdg renders a
camera from its focal length, apertures, aperture offsets, clipping range and
projection (docs/rendering.md); focus distance, f-stop, shutter times and the
stereo role are authored for the writers and annotators that read them.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from isaacsim.core.experimental.objects import Camera
    >>> _ = omni.usd.get_context().new_stage()
    >>> camera = Camera("/World/Camera")
    >>> camera.set_focal_lengths(2.4)
    >>> camera.get_focal_lengths().tolist(), camera.geoms[0].GetFocalLengthAttr().Get()
    ([[2.4000000953674316]], 24.0)
    >>> isaac.uninstall()
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from pxr import Gf, Usd, UsdGeom

from graphsdg.compat.experimental_arguments import resolve_indices, rows, tokens
from graphsdg.compat.experimental_objects import _wrap_or_define
from graphsdg.compat.experimental_prims import XformPrim
from graphsdg.compat.experimental_stage_scope import current_stage
from graphsdg.compat.warp_arrays import WarpLikeArray
from graphsdg.compat.warp_arrays import as_warp_like as _warp

LENS_SCALE = 10.0   # USD's lens attributes are in tenths of a stage unit; Isaac's API in stage units
STEREO_ROLES = ("mono", "left", "right")
PROJECTIONS = ("perspective", "orthographic")
SQUARE_PIXEL_MODES = ("horizontal", "vertical")


class Camera(XformPrim):
    """``isaacsim.core.experimental.objects.Camera`` (see the module docstring)."""

    _compat_name = "isaacsim.core.experimental.objects.Camera"

    def __init__(self, paths: str | Sequence[str], *, positions: Any = None, translations: Any = None,
                 orientations: Any = None, scales: Any = None, reset_xform_op_properties: bool = True) -> None:
        found = _wrap_or_define(paths, True, UsdGeom.Camera, "Camera")
        super().__init__(found, resolve_paths=False, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        self._geoms = [UsdGeom.Camera(p) for p in self._prims]

    @property
    def geoms(self) -> list[UsdGeom.Camera]:
        """The wrapped prims as ``UsdGeom.Camera``."""
        return list(self._geoms)

    @staticmethod
    def are_of_type(paths: Any) -> WarpLikeArray:
        """Whether each prim (or path) is a ``UsdGeom.Camera``."""
        stage = current_stage()
        items = paths if isinstance(paths, (list, tuple)) else [paths]
        return _warp(np.array([bool(p) and p.IsA(UsdGeom.Camera) for p in
                               (i if isinstance(i, Usd.Prim) else stage.GetPrimAtPath(str(i)) for i in items)],
                              dtype=bool))

    # ---- batched attribute access -------------------------------------------------------------------------
    def _set(self, attr: str, values: Any, indices: Any, name: str, scale: float = 1.0,
             minimum: float | None = None) -> None:
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        column = rows(values, len(idx), 1, name)[:, 0]
        if minimum is not None and np.any(column < minimum):
            raise ValueError(f"{name} {values!r} must be >= {minimum}")
        for i, value in zip(idx, column):
            getattr(self._geoms[i], attr)().Set(float(value * scale))

    def _get(self, attr: str, indices: Any, scale: float = 1.0) -> WarpLikeArray:
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        data = np.array([getattr(self._geoms[i], attr)().Get() for i in idx], dtype=np.float32).reshape(-1, 1)
        return _warp(data / np.float32(scale))

    def _set_pair(self, attrs: tuple[str, str], first: Any, second: Any, indices: Any,
                  names: tuple[str, str], scale: float = 1.0, minimum: float | None = None) -> None:
        if first is None and second is None:
            raise ValueError(f"define {names[0]} and / or {names[1]}; both are None")
        for attr, values, name in zip(attrs, (first, second), names):
            if values is not None:
                self._set(attr, values, indices, name, scale, minimum)

    # ---- optics -----------------------------------------------------------------------------------------------
    def set_focal_lengths(self, focal_lengths: Any, *, indices: Any = None) -> None:
        """Set the perspective focal lengths (stage units; authored x10)."""
        self._set("GetFocalLengthAttr", focal_lengths, indices, "focal_lengths", LENS_SCALE, 0.0)

    def get_focal_lengths(self, *, indices: Any = None) -> WarpLikeArray:
        """The focal lengths (stage units), shape (N, 1)."""
        return self._get("GetFocalLengthAttr", indices, LENS_SCALE)

    def set_focus_distances(self, focus_distances: Any, *, indices: Any = None) -> None:
        """Set the distances from the cameras to their focus planes (stage units)."""
        self._set("GetFocusDistanceAttr", focus_distances, indices, "focus_distances", 1.0, 0.0)

    def get_focus_distances(self, *, indices: Any = None) -> WarpLikeArray:
        """The focus distances, shape (N, 1)."""
        return self._get("GetFocusDistanceAttr", indices)

    def set_fstops(self, fstops: Any, *, indices: Any = None) -> None:
        """Set the lens apertures as f-stops (0 turns depth of field off)."""
        self._set("GetFStopAttr", fstops, indices, "fstops", 1.0, 0.0)

    def get_fstops(self, *, indices: Any = None) -> WarpLikeArray:
        """The f-stops, shape (N, 1)."""
        return self._get("GetFStopAttr", indices)

    def set_apertures(self, horizontal_apertures: Any = None, vertical_apertures: Any = None, *,
                      indices: Any = None) -> None:
        """Set the horizontal and / or vertical film apertures (stage units; authored x10)."""
        self._set_pair(("GetHorizontalApertureAttr", "GetVerticalApertureAttr"), horizontal_apertures,
                       vertical_apertures, indices, ("horizontal_apertures", "vertical_apertures"), LENS_SCALE, 0.0)

    def get_apertures(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(horizontal apertures (N, 1), vertical apertures (N, 1)) in stage units."""
        return (self._get("GetHorizontalApertureAttr", indices, LENS_SCALE),
                self._get("GetVerticalApertureAttr", indices, LENS_SCALE))

    def set_aperture_offsets(self, horizontal_offsets: Any = None, vertical_offsets: Any = None, *,
                             indices: Any = None) -> None:
        """Set the horizontal and / or vertical aperture offsets (stage units; authored x10)."""
        self._set_pair(("GetHorizontalApertureOffsetAttr", "GetVerticalApertureOffsetAttr"), horizontal_offsets,
                       vertical_offsets, indices, ("horizontal_offsets", "vertical_offsets"), LENS_SCALE)

    def get_aperture_offsets(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(horizontal offsets (N, 1), vertical offsets (N, 1)) in stage units."""
        return (self._get("GetHorizontalApertureOffsetAttr", indices, LENS_SCALE),
                self._get("GetVerticalApertureOffsetAttr", indices, LENS_SCALE))

    def set_shutter_times(self, open_times: Any = None, close_times: Any = None, *, indices: Any = None) -> None:
        """Set the frame-relative shutter open and / or close times."""
        self._set_pair(("GetShutterOpenAttr", "GetShutterCloseAttr"), open_times, close_times, indices,
                       ("open_times", "close_times"))

    def get_shutter_times(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(shutter open times (N, 1), shutter close times (N, 1))."""
        return self._get("GetShutterOpenAttr", indices), self._get("GetShutterCloseAttr", indices)

    def set_clipping_ranges(self, near_distances: Any = None, far_distances: Any = None, *,
                            indices: Any = None) -> None:
        """Set the near and / or far clipping distances (stage units); near must stay below far."""
        if near_distances is None and far_distances is None:
            raise ValueError("define near_distances and / or far_distances; both are None")
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        near = None if near_distances is None else rows(near_distances, len(idx), 1, "near_distances")[:, 0]
        far = None if far_distances is None else rows(far_distances, len(idx), 1, "far_distances")[:, 0]
        for n, i in enumerate(idx):
            attr = self._geoms[i].GetClippingRangeAttr()
            lo, hi = attr.Get()
            lo = lo if near is None else float(near[n])
            hi = hi if far is None else float(far[n])
            if not 0 < lo < hi:
                raise ValueError(f"camera {self._paths[i]}: clipping range ({lo}, {hi}) must have 0 < near < far")
            attr.Set(Gf.Vec2f(lo, hi))

    def get_clipping_ranges(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(near distances (N, 1), far distances (N, 1))."""
        self._check_valid()
        ranges = np.array([list(self._geoms[i].GetClippingRangeAttr().Get())
                           for i in resolve_indices(indices, len(self))], dtype=np.float32).reshape(-1, 2)
        return _warp(ranges[:, :1]), _warp(ranges[:, 1:])

    def set_projections(self, projections: str | Sequence[str], *, indices: Any = None) -> None:
        """Set each camera's projection, ``"perspective"`` or ``"orthographic"``."""
        self._set_tokens("GetProjectionAttr", projections, indices, "projections", PROJECTIONS)

    def get_projections(self, *, indices: Any = None) -> list[str]:
        """Each camera's projection."""
        return self._get_tokens("GetProjectionAttr", indices)

    def set_stereo_roles(self, roles: str | Sequence[str], *, indices: Any = None) -> None:
        """Set each camera's stereo role, ``"mono"``, ``"left"`` or ``"right"``."""
        self._set_tokens("GetStereoRoleAttr", roles, indices, "roles", STEREO_ROLES)

    def get_stereo_roles(self, *, indices: Any = None) -> list[str]:
        """Each camera's stereo role."""
        return self._get_tokens("GetStereoRoleAttr", indices)

    def _set_tokens(self, attr: str, values: str | Sequence[str], indices: Any, name: str,
                    allowed: Sequence[str]) -> None:
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        for i, value in zip(idx, tokens(values, len(idx), name, allowed)):
            getattr(self._geoms[i], attr)().Set(value)

    def _get_tokens(self, attr: str, indices: Any) -> list[str]:
        self._check_valid()
        return [str(getattr(self._geoms[i], attr)().Get()) for i in resolve_indices(indices, len(self))]

    def enforce_square_pixels(self, resolutions: Any, *, modes: str | Sequence[str] = "horizontal",
                              indices: Any = None) -> None:
        """Make each camera's aperture aspect match its resolution ``(height, width)``: the horizontal aperture
        sets the vertical one (``"horizontal"``), or the reverse (``"vertical"``)."""
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        mode_list = tokens(modes, len(idx), "modes", SQUARE_PIXEL_MODES)
        res = rows(resolutions, len(idx), 2, "resolutions")
        if np.any(res <= 0):
            raise ValueError(f"resolutions {resolutions!r} must be positive (height, width) pairs")
        horizontal, vertical = (np.asarray(a)[:, 0] for a in self.get_apertures(indices=idx))
        for n, i in enumerate(idx):
            aspect = res[n][1] / float(res[n][0])
            if mode_list[n] == "horizontal":
                expected = horizontal[n] / aspect
                if not np.isclose(vertical[n], expected, rtol=1e-5, atol=1e-8):
                    self._geoms[i].GetVerticalApertureAttr().Set(float(expected * LENS_SCALE))
            else:
                expected = vertical[n] * aspect
                if not np.isclose(horizontal[n], expected, rtol=1e-5, atol=1e-8):
                    self._geoms[i].GetHorizontalApertureAttr().Set(float(expected * LENS_SCALE))
