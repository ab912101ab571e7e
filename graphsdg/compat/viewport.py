"""Kit's viewport in compat mode: the viewport cameras every Kit stage has, and ``omni.kit.viewport.utility``.

Kit authors four cameras into the session layer of every stage it opens:
``/OmniverseKit_Persp`` (perspective, at (5, 5, 5) m looking at the origin)
and the orthographic ``/OmniverseKit_Top``, ``/OmniverseKit_Front`` and
``/OmniverseKit_Right``. Isaac scripts make render products from them
(``rep.create.render_product("/OmniverseKit_Persp", (512, 512))``), so compat
mode authors them too, on every stage the USD context opens. They live in the
session layer: a saved stage does not contain them, as in Kit.

graphsdg has no viewport window; the active viewport is an object holding the
camera path that ``get_active_viewport().camera_path`` reads and sets, and
whose ``render_product_path`` is a render product made from that camera.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> omni.usd.get_context().new_stage()
    True
    >>> omni.usd.get_context().get_stage().GetPrimAtPath("/OmniverseKit_Persp").GetTypeName()
    'Camera'
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Any

from pxr import Gf, Sdf, Usd, UsdGeom

from graphsdg import create
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.stage.context import get_stage
from graphsdg.stage.xform import set_local_pose

PERSPECTIVE = "/OmniverseKit_Persp"
# name -> (position in metres, orthographic); Kit's defaults for a Z-up stage (its centimetres over 100)
VIEWPORT_CAMERAS: dict[str, tuple[tuple[float, float, float], bool]] = {
    PERSPECTIVE: ((5.0, 5.0, 5.0), False),
    "/OmniverseKit_Top": ((0.0, 0.0, 500.0), True),
    "/OmniverseKit_Front": ((500.0, 0.0, 0.0), True),
    "/OmniverseKit_Right": ((0.0, -500.0, 0.0), True),
}


def author_viewport_cameras(stage: Usd.Stage) -> None:
    """Author Kit's viewport cameras in ``stage``'s session layer (left alone where they exist)."""
    up = UsdGeom.GetStageUpAxis(stage)
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        for path, (position, ortho) in VIEWPORT_CAMERAS.items():
            if stage.GetPrimAtPath(path):
                continue
            cam = UsdGeom.Camera.Define(stage, Sdf.Path(path))
            cam.CreateFocalLengthAttr(18.147562)   # Kit's viewport lens
            cam.CreateHorizontalApertureAttr(5000.0 if ortho else 20.955)
            cam.CreateVerticalApertureAttr(5000.0 if ortho else 15.2908)
            cam.CreateClippingRangeAttr(Gf.Vec2f(0.01, 10000000.0))
            cam.CreateProjectionAttr("orthographic" if ortho else "perspective")
            if up == UsdGeom.Tokens.y:   # the same views on a Y-up stage
                position = (position[0], position[2], -position[1])
            up_axis = (0.0, 1.0, 0.0) if up == UsdGeom.Tokens.y else (0.0, 0.0, 1.0)
            if path == "/OmniverseKit_Top":   # looking along the up axis: the image's up is the stage's +Y
                up_axis = (0.0, 0.0, -1.0) if up == UsdGeom.Tokens.y else (0.0, 1.0, 0.0)
            set_local_pose(cam.GetPrim(), position=position, look_at=(0.0, 0.0, 0.0), look_at_up_axis=up_axis)
            cam.GetPrim().SetCustomDataByKey("hide_in_stage_window", True)   # Kit hides them in its UI


class ViewportAPI(CompatObject):
    """The active viewport (omni.kit.viewport's ViewportAPI): its camera and its render product."""

    _compat_name = "omni.kit.viewport.window.ViewportAPI"

    def __init__(self) -> None:
        self._camera_path = PERSPECTIVE
        self._resolution = (1280, 720)
        self._render_product = None

    @property
    def camera_path(self) -> Sdf.Path:
        return Sdf.Path(self._camera_path)

    @camera_path.setter
    def camera_path(self, path: str | Sdf.Path) -> None:
        prim = get_stage().GetPrimAtPath(str(path))
        if not prim or not prim.IsA(UsdGeom.Camera):
            raise ValueError(f"viewport camera_path {str(path)!r} is not a camera prim on the stage")
        self._camera_path = str(path)
        self._render_product = None

    def get_active_camera(self) -> Sdf.Path:
        return self.camera_path

    def set_active_camera(self, path: str | Sdf.Path) -> None:
        self.camera_path = path

    @property
    def resolution(self) -> tuple[int, int]:
        return self._resolution

    @resolution.setter
    def resolution(self, value: tuple[int, int]) -> None:
        w, h = (int(v) for v in value)
        if w <= 0 or h <= 0:
            raise ValueError(f"viewport resolution must be two positive integers, got {value!r}")
        self._resolution = (w, h)
        self._render_product = None

    @property
    def render_product_path(self) -> str:
        """A render product of the viewport's camera at its resolution (made on first use)."""
        if self._render_product is None or self._render_product.destroyed:   # a script may destroy it
            self._render_product = create.render_product(self._camera_path, self._resolution,
                                                                  name="Viewport")
        return self._render_product.path

    @property
    def usd_context_name(self) -> str:
        return ""

    @property
    def stage(self) -> Usd.Stage:
        return get_stage()


_viewport = ViewportAPI()


class ViewportWindow(CompatObject):
    """The viewport's window: graphsdg has no window, only the viewport it would show (``viewport_api``)."""

    _compat_name = "omni.kit.viewport.window.ViewportWindow"

    def __init__(self, viewport_api: ViewportAPI) -> None:
        self.viewport_api = viewport_api
        self.name = "Viewport"
        self.title = "Viewport"


class ViewportCapture(CompatObject):
    """What :func:`capture_viewport_to_file` returns: the file is already written when it is returned."""

    _compat_name = "omni.kit.widget.viewport.capture.FileCapture"

    def __init__(self, file_path: str) -> None:
        self.file_path = file_path

    async def wait_for_result(self, completion_frames: int = 2) -> bool:
        """True: the capture was written synchronously."""
        return True


def get_active_viewport_window(window_name: str | None = None, usd_context_name: str = "") -> ViewportWindow:
    """omni.kit.viewport.utility.get_active_viewport_window: the one viewport's window."""
    return ViewportWindow(_viewport)


def capture_viewport_to_file(viewport_api: ViewportAPI | None = None, file_path: str | None = None,
                             is_hdr: bool = False, render_product_path: str | None = None,
                             format_desc: dict | None = None) -> ViewportCapture:
    """omni.kit.viewport.utility.capture_viewport_to_file: render the viewport's camera now and write it.

    The image is the viewport's render product drawn outside any capture (no annotators, writers or time
    advance, as Kit's viewport redraw), written as an 8-bit image whose format the file's extension picks.

    Raises:
        ValueError: no ``file_path``, or ``is_hdr`` (graphsdg's viewport draws LDR colour only).
    """
    from PIL import Image

    from graphsdg import orchestrator
    from graphsdg.render.render_product import registry

    if not file_path:
        raise ValueError("capture_viewport_to_file needs file_path, the image file to write")
    if is_hdr:
        raise ValueError("capture_viewport_to_file(is_hdr=True): graphsdg's viewport draws LDR colour only; "
                         "attach the HdrColor annotator to a render product for HDR data")
    viewport_api = viewport_api or _viewport
    product = registry.find(render_product_path or viewport_api.render_product_path)
    color = orchestrator.draw([product])[0].get("color")
    pixels = (color if color.dtype == "uint8" else (color.clip(0, 1) * 255 + 0.5).astype("uint8"))[..., :3]
    Image.fromarray(pixels).save(file_path)
    return ViewportCapture(str(file_path))


def get_active_viewport(usd_context_name: str = "") -> ViewportAPI:
    """omni.kit.viewport.utility.get_active_viewport."""
    return _viewport


def get_active_viewport_camera_path(usd_context_name: str = "") -> Sdf.Path:
    return _viewport.camera_path


def get_active_viewport_camera_string(usd_context_name: str = "") -> str:
    return str(_viewport.camera_path)


def get_num_viewports(usd_context_name: str = "") -> int:
    return 1


def modules() -> list[types.ModuleType]:
    """``omni.kit.viewport.utility``."""
    return [CompatModule("omni.kit.viewport.utility", get_active_viewport=get_active_viewport,
                         get_active_viewport_camera_path=get_active_viewport_camera_path,
                         get_active_viewport_camera_string=get_active_viewport_camera_string,
                         get_num_viewports=get_num_viewports,
                         get_active_viewport_window=get_active_viewport_window,
                         capture_viewport_to_file=capture_viewport_to_file)]


def _reset(_: Any = None) -> None:
    _viewport.__init__()


def install() -> None:
    """A fresh viewport for each install (Kit's app starts with its default camera and resolution)."""
    _reset()
