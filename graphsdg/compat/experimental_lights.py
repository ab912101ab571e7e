"""Isaac compat: ``isaacsim.core.experimental.objects`` lights: Distant, Sphere, Rect, Disk, Cylinder and Dome.

Each class wraps existing ``UsdLux`` lights of its type or defines new ones at
paths where there is no prim (never a mix, as in Isaac), then reads and writes
their attributes in batches: one row per light, inputs broadcast as NumPy does,
``indices`` selecting a subset, results as ``(N, 1)`` / ``(N, 3)`` arrays that also
answer warp's ``.numpy()``. Colours may be rgb rows or colour strings (``"white"``,
``"#ffaa00"``). graphsdg's renderer lights the scene from these prims
(:mod:`graphsdg.sim.lights`: type, intensity, exposure, colour, colour temperature,
shape sizes, dome textures); attributes it does not use (diffuse / specular
multipliers, normalisation, treat-as-point / line, stereo) are authored all the same.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from isaacsim.core.experimental.objects import SphereLight
    >>> _ = omni.usd.get_context().new_stage()
    >>> light = SphereLight("/World/Light", radii=0.25, positions=(0, 0, 2.5))
    >>> light.set_intensities(30000); light.get_intensities().tolist()
    [[30000.0]]
    >>> isaac.uninstall()
"""
from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdLux

from graphsdg.compat.experimental_arguments import color_rows, flags, resolve_indices, rows, tokens
from graphsdg.compat.experimental_objects import _wrap_or_define
from graphsdg.compat.experimental_prims import XformPrim
from graphsdg.compat.experimental_stage_scope import current_stage
from graphsdg.compat.warp_arrays import WarpLikeArray
from graphsdg.compat.warp_arrays import as_warp_like as _warp

TEXTURE_FORMATS = ("automatic", "latlong", "mirroredBall", "angular", "cubeMapVerticalCross")


def _scalar_methods(attr: str, name: str, what: str, minimum: float | None = 0.0
                    ) -> tuple[Callable[..., None], Callable[..., WarpLikeArray]]:
    """A ``set_<name>`` / ``get_<name>`` pair for the float attribute ``attr`` (``Get<Attr>Attr``) of each light."""
    def setter(self: "Light", values: Any, *, indices: Any = None) -> None:
        self._set_column(attr, values, indices, name, minimum)

    def getter(self: "Light", *, indices: Any = None) -> WarpLikeArray:
        return self._get_column(attr, indices, np.float32)

    setter.__doc__ = f"Set the {what} of the lights (shape (N, 1))."
    getter.__doc__ = f"The {what} of the lights, shape (N, 1)."
    return setter, getter


def _flag_methods(attr: str, name: str, what: str) -> tuple[Callable[..., None], Callable[..., WarpLikeArray]]:
    """A ``set_enabled_<name>`` / ``get_enabled_<name>`` pair for the bool attribute ``attr``."""
    def setter(self: "Light", enabled: Any, *, indices: Any = None) -> None:
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        for i, flag in zip(idx, flags(enabled, len(idx), name)):
            getattr(self._schema_of(i, attr), attr)().Set(flag)

    def getter(self: "Light", *, indices: Any = None) -> WarpLikeArray:
        return self._get_column(attr, indices, np.bool_)

    setter.__doc__ = f"Turn {what} of the lights on or off (shape (N, 1))."
    getter.__doc__ = f"Whether {what} is on for each light, shape (N, 1)."
    return setter, getter


class Light(XformPrim):
    """``isaacsim.core.experimental.objects.Light``: the base of the light classes (``lights``, intensity,
    exposure, colour, colour temperature, normalisation and diffuse / specular multipliers)."""

    _compat_name = "isaacsim.core.experimental.objects.Light"
    _schema: type = UsdLux.BoundableLightBase
    _what = "light"

    def __init__(self, paths: str | Sequence[str], *, resolve_paths: bool = True, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        if type(self) is Light:
            raise TypeError("Light is abstract; use DistantLight, SphereLight, RectLight, DiskLight, CylinderLight "
                            "or DomeLight")
        found = _wrap_or_define(paths, resolve_paths, self._schema, self._what)
        super().__init__(found, resolve_paths=False, positions=positions, translations=translations,
                         orientations=orientations, scales=scales,
                         reset_xform_op_properties=reset_xform_op_properties)
        self._lights = [self._schema(p) for p in self._prims]

    @property
    def lights(self) -> list:
        """The wrapped prims as their ``UsdLux`` light schema."""
        return list(self._lights)

    # ---- per-light columns ---------------------------------------------------------------------------
    def _schema_of(self, index: int, attr: str) -> Any:
        """The schema object that has ``attr``: the light's own type, else its ``LightAPI``."""
        light = self._lights[index]
        return light if hasattr(light, attr) else UsdLux.LightAPI(light.GetPrim())

    def _set_column(self, attr: str, values: Any, indices: Any, name: str, minimum: float | None) -> None:
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        column = rows(values, len(idx), 1, name)[:, 0]
        if minimum is not None and np.any(column < minimum):
            raise ValueError(f"{name} {values!r} must be >= {minimum}")
        for i, value in zip(idx, column):
            getattr(self._schema_of(i, attr), attr)().Set(float(value))

    def _get_column(self, attr: str, indices: Any, dtype: type) -> WarpLikeArray:
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        values = [getattr(self._schema_of(i, attr), attr)().Get() for i in idx]
        return _warp(np.array(values, dtype=dtype).reshape(-1, 1))

    set_intensities, get_intensities = _scalar_methods("GetIntensityAttr", "intensities",
                                                       "intensities (light power, scaled linearly)")
    set_exposures, get_exposures = _scalar_methods("GetExposureAttr", "exposures",
                                                   "exposures (light power scaled by 2 ** exposure)", None)
    set_color_temperatures, get_color_temperatures = _scalar_methods(
        "GetColorTemperatureAttr", "color_temperatures", "colour temperatures (kelvin; used where enabled)")
    set_enabled_normalizations, get_enabled_normalizations = _flag_methods(
        "GetNormalizeAttr", "enabled", "power normalisation by the light's area")
    set_enabled_color_temperatures, get_enabled_color_temperatures = _flag_methods(
        "GetEnableColorTemperatureAttr", "enabled", "the colour temperature")

    def set_multipliers(self, diffuse_multipliers: Any = None, specular_multipliers: Any = None, *,
                        indices: Any = None) -> None:
        """Set the multipliers of the lights' effect on materials' diffuse and / or specular response."""
        if diffuse_multipliers is None and specular_multipliers is None:
            raise ValueError("set_multipliers needs diffuse_multipliers and / or specular_multipliers")
        if diffuse_multipliers is not None:
            self._set_column("GetDiffuseAttr", diffuse_multipliers, indices, "diffuse_multipliers", 0.0)
        if specular_multipliers is not None:
            self._set_column("GetSpecularAttr", specular_multipliers, indices, "specular_multipliers", 0.0)

    def get_multipliers(self, *, indices: Any = None) -> tuple[WarpLikeArray, WarpLikeArray]:
        """(diffuse multipliers (N, 1), specular multipliers (N, 1))."""
        return (self._get_column("GetDiffuseAttr", indices, np.float32),
                self._get_column("GetSpecularAttr", indices, np.float32))

    def set_colors(self, colors: Any, *, indices: Any = None) -> None:
        """Set the lights' colours: rgb rows in [0, 1] or colour strings (``"white"``, ``"#ff8800"``)."""
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        for i, rgb in zip(idx, color_rows(colors, len(idx))):
            self._schema_of(i, "GetColorAttr").GetColorAttr().Set(Gf.Vec3f(*(float(c) for c in rgb)))

    def get_colors(self, *, indices: Any = None) -> WarpLikeArray:
        """The lights' rgb colours, shape (N, 3)."""
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        return _warp(np.array([list(self._schema_of(i, "GetColorAttr").GetColorAttr().Get()) for i in idx],
                              dtype=np.float32).reshape(-1, 3))

    # ---- texture files (dome and rect lights) -------------------------------------------------------------
    def _set_texture_files(self, texture_files: str | Sequence[str], indices: Any) -> None:
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        files = [texture_files] if isinstance(texture_files, str) else list(texture_files)
        if len(files) not in (1, len(idx)) or not all(isinstance(f, str) for f in files):
            raise ValueError(f"texture_files {texture_files!r} must be one path or {len(idx)} paths")
        for n, i in enumerate(idx):
            self._lights[i].GetTextureFileAttr().Set(Sdf.AssetPath(files[0 if len(files) == 1 else n]))

    def _get_texture_files(self, indices: Any) -> list[str | None]:
        self._check_valid()
        out = []
        for i in resolve_indices(indices, len(self)):
            value = self._lights[i].GetTextureFileAttr().Get()
            out.append(None if value is None or not value.path else value.path)
        return out

    # ---- type checks and instances -----------------------------------------------------------------------
    @classmethod
    def are_of_type(cls, paths: Any) -> WarpLikeArray:
        """Whether each prim (or path) is a light of this class's type."""
        stage = current_stage()
        items = paths if isinstance(paths, (list, tuple)) else [paths]
        return _warp(np.array([bool(p) and p.IsA(cls._schema) for p in
                               (i if isinstance(i, Usd.Prim) else stage.GetPrimAtPath(str(i)) for i in items)],
                              dtype=bool))

    @staticmethod
    def fetch_instances(paths: Any) -> list["Light | None"]:
        """A wrapper of the right light class for each prim (None where it is not a light graphsdg wraps)."""
        stage = current_stage()
        out: list[Light | None] = []
        for item in paths if isinstance(paths, (list, tuple)) else [paths]:
            prim = item if isinstance(item, Usd.Prim) else stage.GetPrimAtPath(str(item))
            kind = next((k for k in LIGHT_CLASSES if prim and prim.IsA(k._schema)), None)
            out.append(kind(prim.GetPath().pathString) if kind else None)
        return out


class DistantLight(Light):
    """``isaacsim.core.experimental.objects.DistantLight``: light from a distant source along the local -Z axis
    (``angles``: the source's angular diameter, degrees)."""

    _compat_name = "isaacsim.core.experimental.objects.DistantLight"
    _schema = UsdLux.DistantLight
    _what = "DistantLight"

    def __init__(self, paths: str | Sequence[str], *, angles: Any = None, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        super().__init__(paths, positions=positions, translations=translations, orientations=orientations,
                         scales=scales, reset_xform_op_properties=reset_xform_op_properties)
        if angles is not None:
            self.set_angles(angles)

    set_angles, get_angles = _scalar_methods("GetAngleAttr", "angles", "angular diameters (degrees)")


class SphereLight(Light):
    """``isaacsim.core.experimental.objects.SphereLight``: light emitted outward from a sphere (``radii``)."""

    _compat_name = "isaacsim.core.experimental.objects.SphereLight"
    _schema = UsdLux.SphereLight
    _what = "SphereLight"

    def __init__(self, paths: str | Sequence[str], *, radii: Any = None, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        super().__init__(paths, positions=positions, translations=translations, orientations=orientations,
                         scales=scales, reset_xform_op_properties=reset_xform_op_properties)
        if radii is not None:
            self.set_radii(radii)

    set_radii, get_radii = _scalar_methods("GetRadiusAttr", "radii", "radii")
    set_enabled_treat_as_points, get_enabled_treat_as_points = _flag_methods(
        "GetTreatAsPointAttr", "enabled", "treating the sphere as a point")


class RectLight(Light):
    """``isaacsim.core.experimental.objects.RectLight``: light from one side of a rectangle in the XY plane
    (along -Z): ``widths``, ``heights`` and an optional colour texture per light."""

    _compat_name = "isaacsim.core.experimental.objects.RectLight"
    _schema = UsdLux.RectLight
    _what = "RectLight"

    def __init__(self, paths: str | Sequence[str], *, widths: Any = None, heights: Any = None,
                 texture_files: str | Sequence[str] | None = None, positions: Any = None, translations: Any = None,
                 orientations: Any = None, scales: Any = None, reset_xform_op_properties: bool = True) -> None:
        super().__init__(paths, positions=positions, translations=translations, orientations=orientations,
                         scales=scales, reset_xform_op_properties=reset_xform_op_properties)
        if widths is not None:
            self.set_widths(widths)
        if heights is not None:
            self.set_heights(heights)
        if texture_files is not None:
            self.set_texture_files(texture_files)

    set_widths, get_widths = _scalar_methods("GetWidthAttr", "widths", "widths (local X)")
    set_heights, get_heights = _scalar_methods("GetHeightAttr", "heights", "heights (local Y)")

    def set_texture_files(self, texture_files: str | Sequence[str], *, indices: Any = None) -> None:
        """Set the colour texture file of each light."""
        self._set_texture_files(texture_files, indices)

    def get_texture_files(self, *, indices: Any = None) -> list[str | None]:
        """Each light's colour texture file (None where none)."""
        return self._get_texture_files(indices)


class DiskLight(Light):
    """``isaacsim.core.experimental.objects.DiskLight``: light from one side of a disk in the XY plane (``radii``)."""

    _compat_name = "isaacsim.core.experimental.objects.DiskLight"
    _schema = UsdLux.DiskLight
    _what = "DiskLight"

    def __init__(self, paths: str | Sequence[str], *, radii: Any = None, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        super().__init__(paths, positions=positions, translations=translations, orientations=orientations,
                         scales=scales, reset_xform_op_properties=reset_xform_op_properties)
        if radii is not None:
            self.set_radii(radii)

    set_radii, get_radii = _scalar_methods("GetRadiusAttr", "radii", "radii")


class CylinderLight(Light):
    """``isaacsim.core.experimental.objects.CylinderLight``: light from the side of a cylinder along local X
    (``radii``, ``lengths``)."""

    _compat_name = "isaacsim.core.experimental.objects.CylinderLight"
    _schema = UsdLux.CylinderLight
    _what = "CylinderLight"

    def __init__(self, paths: str | Sequence[str], *, radii: Any = None, lengths: Any = None, positions: Any = None,
                 translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        super().__init__(paths, positions=positions, translations=translations, orientations=orientations,
                         scales=scales, reset_xform_op_properties=reset_xform_op_properties)
        if radii is not None:
            self.set_radii(radii)
        if lengths is not None:
            self.set_lengths(lengths)

    set_radii, get_radii = _scalar_methods("GetRadiusAttr", "radii", "radii")
    set_lengths, get_lengths = _scalar_methods("GetLengthAttr", "lengths", "lengths (local X)")
    set_enabled_treat_as_lines, get_enabled_treat_as_lines = _flag_methods(
        "GetTreatAsLineAttr", "enabled", "treating the cylinder as a line")


class DomeLight(Light):
    """``isaacsim.core.experimental.objects.DomeLight``: light from a distant environment, optionally an
    image (``texture_files``, ``texture_formats``); ``radii`` are the guide radii (display only)."""

    _compat_name = "isaacsim.core.experimental.objects.DomeLight"
    _schema = UsdLux.DomeLight
    _what = "DomeLight"

    def __init__(self, paths: str | Sequence[str], *, radii: Any = None,
                 texture_files: str | Sequence[str] | None = None, texture_formats: str | Sequence[str] | None = None,
                 positions: Any = None, translations: Any = None, orientations: Any = None, scales: Any = None,
                 reset_xform_op_properties: bool = True) -> None:
        super().__init__(paths, positions=positions, translations=translations, orientations=orientations,
                         scales=scales, reset_xform_op_properties=reset_xform_op_properties)
        if radii is not None:
            self.set_guide_radii(radii)
        if texture_files is not None:
            self.set_texture_files(texture_files)
        if texture_formats is not None:
            self.set_texture_formats(texture_formats)

    set_guide_radii, get_guide_radii = _scalar_methods("GetGuideRadiusAttr", "radii", "guide radii")

    def set_texture_files(self, texture_files: str | Sequence[str], *, indices: Any = None) -> None:
        """Set each dome's environment image (a lat-long HDR renders as graphsdg's sky and lighting)."""
        self._set_texture_files(texture_files, indices)

    def get_texture_files(self, *, indices: Any = None) -> list[str | None]:
        """Each dome's environment image (None where none)."""
        return self._get_texture_files(indices)

    def set_texture_formats(self, texture_formats: str | Sequence[str], *, indices: Any = None) -> None:
        """Set how each dome's image maps to directions (``automatic``, ``latlong``, ``mirroredBall``, ...)."""
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        for i, value in zip(idx, tokens(texture_formats, len(idx), "texture_formats", TEXTURE_FORMATS)):
            self._lights[i].GetTextureFormatAttr().Set(value)

    def get_texture_formats(self, *, indices: Any = None) -> list[str]:
        """Each dome's image mapping."""
        self._check_valid()
        return [str(self._lights[i].GetTextureFormatAttr().Get()) for i in resolve_indices(indices, len(self))]


LIGHT_CLASSES: tuple[type[Light], ...] = (CylinderLight, DiskLight, DistantLight, DomeLight, RectLight, SphereLight)
