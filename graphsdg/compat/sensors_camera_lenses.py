"""The lens-distortion models of Isaac's deprecated ``Camera`` (``isaacsim.sensors.camera``): authored, not rendered.

Each setter applies the model's ``OmniLensDistortion<Model>API``, sets ``omni:lensdistortion:model`` and writes
the coefficients (in the order Isaac's setters take them, :data:`DISTORTION_COEFFICIENTS`) and the named values
(``nominal_height`` -> ``omni:lensdistortion:<model>:nominalHeight``, ...). The getters give Isaac's tuples
back (None, with a warning, while another model is selected). graphsdg renders the pinhole image; writers and
``camera_params`` read the authored model.

Example:
    >>> DISTORTION_COEFFICIENTS["opencvFisheye"]
    ('k1', 'k2', 'k3', 'k4')
"""
from __future__ import annotations

import logging
import sys
from typing import Any

import numpy as np
from pxr import Gf

log = logging.getLogger("carb")

# each lens-distortion model's coefficient names, in the order Isaac's setters take them
DISTORTION_COEFFICIENTS = {
    "opencvPinhole": ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4"),
    "opencvFisheye": ("k1", "k2", "k3", "k4"), "ftheta": ("k0", "k1", "k2", "k3", "k4"),
    "kannalaBrandtK3": ("k0", "k1", "k2", "k3"),
    "radTanThinPrism": ("k0", "k1", "k2", "k3", "k4", "k5", "p0", "p1", "s0", "s1", "s2", "s3"), "lut": ()}

def carb_warn(message: str) -> None:
    """``carb.log_warn`` as scripts see it (tests patch it), else the ``carb`` logger."""
    carb = sys.modules.get("carb")
    (carb.log_warn if carb is not None and hasattr(carb, "log_warn") else log.warning)(message)



class CameraLenses:
    """The lens-distortion setters and getters of ``Camera`` (module docstring); a mixin over its prim access."""

    def _author_distortion(self, model: str, attr: str, coefficients: Any = None, **named: Any) -> None:
        """Apply ``OmniLensDistortion<model>API``, select ``attr`` and author its coefficients and named values."""
        from pxr import Sdf

        self.set_lens_distortion_model(f"OmniLensDistortion{model}API")
        self._set("omni:lensdistortion:model", attr, Sdf.ValueTypeNames.Token)
        names = DISTORTION_COEFFICIENTS[attr]
        for name, value in zip(names, coefficients if coefficients is not None else ()):
            if value is not None:
                self._set(f"omni:lensdistortion:{attr}:{name}", float(value))
        for key, value in named.items():
            if value is None:
                continue
            head, *rest = key.split("_")
            name = f"omni:lensdistortion:{attr}:{head}{''.join(part.capitalize() for part in rest)}"
            if isinstance(value, str):
                self._set(name, Sdf.AssetPath(value), Sdf.ValueTypeNames.Asset)
            elif np.ndim(value) == 1:
                self._set(name, Gf.Vec2f(*[float(v) for v in value]), Sdf.ValueTypeNames.Float2)
            else:
                self._set(name, float(value))

    def _read_distortion(self, attr: str, keys: tuple[str, ...], with_coefficients: bool = True) -> tuple | None:
        """Isaac's getter tuple: the named values, then the coefficients (None where the model is another)."""
        if self._get("omni:lensdistortion:model") != attr:
            carb_warn(f"Camera {self.prim_path}: omni:lensdistortion:model is not {attr!r}")
            return None
        values = []
        for key in keys:
            head, *rest = key.split("_")
            value = self._get(f"omni:lensdistortion:{attr}:{head}{''.join(part.capitalize() for part in rest)}")
            values.append(tuple(value) if isinstance(value, Gf.Vec2f) else value)
        if with_coefficients:
            values.append([self._get(f"omni:lensdistortion:{attr}:{name}") for name in DISTORTION_COEFFICIENTS[attr]])
        return tuple(values)

    def set_ftheta_properties(self, nominal_height: float | None = None, nominal_width: float | None = None,
                              optical_center: Any = None, max_fov: float | None = None,
                              distortion_coefficients: Any = None) -> None:
        """Author the f-theta lens model (k0..k4)."""
        self._author_distortion("Ftheta", "ftheta", distortion_coefficients, nominal_height=nominal_height,
                                nominal_width=nominal_width, optical_center=optical_center, max_fov=max_fov)

    def get_ftheta_properties(self) -> tuple | None:
        """(nominal height, nominal width, optical centre, max FOV, coefficients) of the f-theta model."""
        return self._read_distortion("ftheta", ("nominal_height", "nominal_width", "optical_center", "max_fov"))

    def set_kannala_brandt_k3_properties(self, nominal_height: float | None = None, nominal_width: float | None = None,
                                         optical_center: Any = None, max_fov: float | None = None,
                                         distortion_coefficients: Any = None) -> None:
        """Author the Kannala-Brandt K3 lens model (k0..k3)."""
        self._author_distortion("KannalaBrandtK3", "kannalaBrandtK3", distortion_coefficients,
                                nominal_height=nominal_height, nominal_width=nominal_width,
                                optical_center=optical_center, max_fov=max_fov)

    def get_kannala_brandt_k3_properties(self) -> tuple | None:
        """(nominal height, nominal width, optical centre, max FOV, coefficients) of the K3 model."""
        return self._read_distortion("kannalaBrandtK3", ("nominal_height", "nominal_width", "optical_center",
                                                         "max_fov"))

    def set_rad_tan_thin_prism_properties(self, nominal_height: float | None = None,
                                          nominal_width: float | None = None, optical_center: Any = None,
                                          max_fov: float | None = None, distortion_coefficients: Any = None) -> None:
        """Author the radial-tangential thin-prism lens model (k0..k5, p0, p1, s0..s3)."""
        self._author_distortion("RadTanThinPrism", "radTanThinPrism", distortion_coefficients,
                                nominal_height=nominal_height, nominal_width=nominal_width,
                                optical_center=optical_center, max_fov=max_fov)

    def get_rad_tan_thin_prism_properties(self) -> tuple | None:
        """(nominal height, nominal width, optical centre, max FOV, coefficients) of the thin-prism model."""
        return self._read_distortion("radTanThinPrism", ("nominal_height", "nominal_width", "optical_center",
                                                         "max_fov"))

    def set_lut_properties(self, nominal_height: float | None = None, nominal_width: float | None = None,
                           optical_center: Any = None, ray_enter_direction_texture: str | None = None,
                           ray_exit_position_texture: str | None = None) -> None:
        """Author the look-up-table lens model (its two textures)."""
        self._author_distortion("Lut", "lut", None, nominal_height=nominal_height, nominal_width=nominal_width,
                                optical_center=optical_center, ray_enter_direction_texture=ray_enter_direction_texture,
                                ray_exit_position_texture=ray_exit_position_texture)

    def get_lut_properties(self) -> tuple | None:
        """(nominal height, nominal width, optical centre, ray-enter texture, ray-exit texture)."""
        values = self._read_distortion("lut", ("nominal_height", "nominal_width", "optical_center",
                                               "ray_enter_direction_texture", "ray_exit_position_texture"), False)
        return None if values is None else tuple(v.path if hasattr(v, "path") else v for v in values)

    def set_opencv_pinhole_properties(self, cx: float | None = None, cy: float | None = None, fx: float | None = None,
                                      fy: float | None = None, pinhole: Any = None) -> None:
        """Author OpenCV's pinhole model (k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4)."""
        self._author_distortion("OpenCvPinhole", "opencvPinhole", pinhole, cx=cx, cy=cy, fx=fx, fy=fy)

    def get_opencv_pinhole_properties(self) -> tuple | None:
        """(cx, cy, fx, fy, coefficients) of OpenCV's pinhole model."""
        return self._read_distortion("opencvPinhole", ("cx", "cy", "fx", "fy"))

    def set_opencv_fisheye_properties(self, cx: float | None = None, cy: float | None = None, fx: float | None = None,
                                      fy: float | None = None, fisheye: Any = None) -> None:
        """Author OpenCV's fisheye model (k1..k4)."""
        self._author_distortion("OpenCvFisheye", "opencvFisheye", fisheye, cx=cx, cy=cy, fx=fx, fy=fy)

    def get_opencv_fisheye_properties(self) -> tuple | None:
        """(cx, cy, fx, fy, coefficients) of OpenCV's fisheye model."""
        return self._read_distortion("opencvFisheye", ("cx", "cy", "fx", "fy"))

    def set_rational_polynomial_properties(self, nominal_width: float, nominal_height: float,
                                           optical_centre_x: float, optical_centre_y: float, max_fov: float | None,
                                           distortion_model: Any) -> None:
        """Deprecated form of :meth:`set_opencv_pinhole_properties` (focal lengths from the lens; >= 8
        coefficients)."""
        if len(distortion_model) < 8:
            carb_warn(f"set_rational_polynomial_properties: {len(distortion_model)} distortion coefficients, "
                      f"expected at least 8")
            return
        fx = nominal_width * self.get_focal_length() / self.get_horizontal_aperture()
        fy = nominal_height * self.get_focal_length() / self.get_vertical_aperture()
        self.set_opencv_pinhole_properties(cx=optical_centre_x, cy=optical_centre_y, fx=fx, fy=fy,
                                           pinhole=distortion_model)

    def set_kannala_brandt_properties(self, nominal_width: float, nominal_height: float, optical_centre_x: float,
                                      optical_centre_y: float, max_fov: float | None, distortion_model: Any) -> None:
        """Deprecated form of :meth:`set_opencv_fisheye_properties` (focal lengths from the lens; >= 4
        coefficients)."""
        if len(distortion_model) < 4:
            carb_warn(f"set_kannala_brandt_properties: {len(distortion_model)} distortion coefficients, expected "
                      f"at least 4")
            return
        fx = nominal_width * self.get_focal_length() / self.get_horizontal_aperture()
        fy = nominal_height * self.get_focal_length() / self.get_vertical_aperture()
        self.set_opencv_fisheye_properties(cx=optical_centre_x, cy=optical_centre_y, fx=fx, fy=fy,
                                           fisheye=distortion_model)
