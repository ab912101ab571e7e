"""Isaac compat area: ``isaacsim.core.utils.viewports``, ``.render_product`` and ``.carb``.

* ``set_camera_view(eye, target, camera_prim_path="/OmniverseKit_Persp")`` puts
  the camera at world ``eye`` looking at world ``target`` (the stage's up axis up;
  straight down or up when the target is right below or above) and authors Kit's
  ``omni:kit:centerOfInterest`` (the target in the camera's frame, ``(0, 0, -d)``);
* the viewport helpers answer for graphsdg's one headless viewport (named
  ``"Viewport"``): its intrinsics from the camera's lens and the viewport's
  resolution, depth back-projection, its camera; making or destroying viewport
  windows raises (there are none);
* the render-product helpers read and change graphsdg's render products by
  path (``rp.path``): resolution and camera take effect at the next capture;
  ``add_aov`` records the render variable (every AOV is available to annotators
  here, so nothing else is needed);
* ``set_carb_setting`` / ``get_carb_setting`` go through ``carb.settings``.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cam = rep.functional.create.camera(name="Cam")
    >>> set_camera_view(eye=[4.0, 0.0, 0.0], target=[0.0, 0.0, 0.0], camera_prim_path="/Cam")
    >>> from graphsdg.sim.transforms import get_world_transform_matrix
    >>> m = get_world_transform_matrix("/Cam")
    >>> [round(v, 6) + 0.0 for v in m.ExtractTranslation()], [round(v, 6) + 0.0 for v in m.GetRow3(2)]
    ([4.0, 0.0, 0.0], [1.0, 0.0, 0.0])
"""
from __future__ import annotations

import types
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom

from graphsdg.compat import viewport
from graphsdg.compat.kit import CarbSettings, Float3
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.compat.rendering_manager import aim_camera, camera_edit_context
from graphsdg.physics.world_pose import set_world_pose
from graphsdg.render.render_product import RenderProduct, create_render_product, registry
from graphsdg.stage.context import get_stage

_VIEWPORT_NAME = "Viewport"


# ---- viewports ------------------------------------------------------------------------------------------------------
def set_camera_view(eye: Any, target: Any, camera_prim_path: str = "/OmniverseKit_Persp",
                    viewport_api: Any = None) -> None:
    """Place the camera at ``eye`` looking at ``target`` (world positions)."""
    prim = get_stage().GetPrimAtPath(camera_prim_path)
    if not prim or not prim.IsA(UsdGeom.Camera):
        raise ValueError(f"set_camera_view: {camera_prim_path!r} is not a camera prim on the stage")
    eye = np.asarray(eye, dtype=np.float64).reshape(3)
    target = np.asarray(target, dtype=np.float64).reshape(3)
    up = 1 if UsdGeom.GetStageUpAxis(get_stage()) == UsdGeom.Tokens.y else 2
    across = [a for a in range(3) if a != up]
    if not np.allclose(eye[across], target[across]):
        aim_camera(prim, eye, target)
    with camera_edit_context(prim):
        if np.allclose(eye[across], target[across]):   # straight down (identity) or up (half turn about Y)
            set_world_pose(prim, position=eye, orientation=(1.0, 0.0, 0.0, 0.0) if target[up] < eye[up] else
                           (0.0, 0.0, 1.0, 0.0))
        prim.CreateAttribute("omni:kit:centerOfInterest", Sdf.ValueTypeNames.Vector3d, True,
                             Sdf.VariabilityUniform).Set(Gf.Vec3d(0.0, 0.0, -float(np.linalg.norm(target - eye))))


def get_viewport_names(usd_context_name: str | None = None) -> list[str]:
    """``["Viewport"]``: graphsdg's one viewport."""
    return [_VIEWPORT_NAME]


def get_id_from_index(index: int) -> int | None:
    """0 for the first (only) viewport, else None."""
    return 0 if index == 0 else None


def get_window_from_id(id: Any, usd_context_name: str | None = None) -> Any:
    """Not mapped: there are no viewport windows (raises naming it)."""
    raise CompatError("isaacsim.core.utils.viewports.get_window_from_id is not available in graphsdg's compat mode: "
                      "graphsdg has one headless viewport and no windows (omni.kit.viewport.utility."
                      "get_active_viewport()). See docs/porting.md.")


def destroy_all_viewports(usd_context_name: str | None = None, destroy_main_viewport: bool = True) -> None:
    """Not mapped: the headless viewport cannot be destroyed (raises naming it)."""
    raise CompatError("isaacsim.core.utils.viewports.destroy_all_viewports is not available in graphsdg's compat "
                      "mode: there are no viewport windows to destroy. See docs/porting.md.")


def create_viewport_for_camera(viewport_name: str, camera_prim_path: str, width: int = 1280, height: int = 720,
                               position_x: int = 0, position_y: int = 0) -> None:
    """Not mapped: graphsdg has one viewport (use ``set_active_viewport_camera``, or a render product)."""
    raise CompatError("isaacsim.core.utils.viewports.create_viewport_for_camera is not available in graphsdg's "
                      "compat mode: there is one headless viewport; render a camera with "
                      "rep.create.render_product(camera, resolution). See docs/porting.md.")


def set_active_viewport_camera(camera_prim_path: str, viewport_api: Any = None) -> None:
    """Make the camera the viewport's camera."""
    (viewport_api or viewport.get_active_viewport()).camera_path = camera_prim_path


def add_aov_to_viewport(viewport_api: Any, aov_name: str) -> bool:
    """Add a render variable to the viewport's render product (see :func:`add_aov`)."""
    add_aov(viewport_api.render_product_path, aov_name)
    return True


def _texture_resolution(viewport_api: Any) -> tuple[int, int]:
    getter = getattr(viewport_api, "get_texture_resolution", None)
    return tuple(getter()) if callable(getter) else tuple(viewport_api.resolution)


def _active_camera(viewport_api: Any) -> Usd.Prim:
    prim = get_stage().GetPrimAtPath(str(viewport_api.get_active_camera()))
    if not prim or not prim.IsA(UsdGeom.Camera):
        raise ValueError("Viewport does not have a valid camera prim")
    return prim


def get_intrinsics_matrix(viewport_api: Any) -> np.ndarray:
    """3x3 pinhole intrinsics of the viewport's camera at its resolution (+x right, +y down, square pixels)."""
    prim = _active_camera(viewport_api)
    width, height = _texture_resolution(viewport_api)
    focal = float(prim.GetAttribute("focalLength").Get())
    horizontal = float(prim.GetAttribute("horizontalAperture").Get())
    vertical = horizontal * height / width
    return np.array([[width * focal / horizontal, 0.0, width * 0.5],
                     [0.0, height * focal / vertical, height * 0.5], [0.0, 0.0, 1.0]])


def set_intrinsics_matrix(viewport_api: Any, intrinsics_matrix: np.ndarray, focal_length: float = 1.0) -> None:
    """Author the camera's focal length, apertures and aperture offsets from a 3x3 intrinsics matrix."""
    k = np.asarray(intrinsics_matrix, dtype=np.float64)
    if k.shape != (3, 3):
        raise ValueError("intrinsics_matrix must be 3x3")
    camera = UsdGeom.Camera(_active_camera(viewport_api))
    width, height = _texture_resolution(viewport_api)
    fx, fy, cx, cy = k[0, 0], k[1, 1], k[0, 2], k[1, 2]
    camera.GetFocalLengthAttr().Set(float(focal_length))
    camera.GetHorizontalApertureAttr().Set(float(width * focal_length / fx))
    camera.GetVerticalApertureAttr().Set(float(height * focal_length / fy))
    camera.GetHorizontalApertureOffsetAttr().Set(float((cx - width / 2) / fx))
    camera.GetVerticalApertureOffsetAttr().Set(float((cy - height / 2) / fy))


def backproject_depth(depth_image: np.ndarray, viewport_api: Any, max_clip_depth: float) -> np.ndarray:
    """(H * W, 3) camera-space points of a depth image (depths beyond ``max_clip_depth`` become 0)."""
    k = get_intrinsics_matrix(viewport_api)
    height, width = depth_image.shape[:2]
    xs, ys = np.meshgrid(np.arange(width), np.arange(height))
    z = np.array(depth_image, dtype=np.float64).reshape(-1)
    z[z > max_clip_depth] = 0
    x = (xs.reshape(-1) - k[0, 2]) * z / k[0, 0]
    y = (ys.reshape(-1) - k[1, 2]) * z / k[1, 1]
    return np.stack([x, y, z], -1)


def project_depth_to_worldspace(depth_image: np.ndarray, viewport_api: Any, max_clip_depth: float) -> list:
    """World points (``carb.Float3``) of a depth image seen by the viewport's camera."""
    prim = _active_camera(viewport_api)
    to_world = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
    depth = -np.clip(np.asarray(depth_image, dtype=np.float64) / UsdGeom.GetStageMetersPerUnit(get_stage()), 0,
                     max_clip_depth)
    points = []
    for x, y, z in backproject_depth(depth, viewport_api, max_clip_depth):
        p = to_world.Transform(Gf.Vec3d(-x, y, z))
        points.append(Float3(p[0], p[1], p[2]))
    return points


# ---- render products --------------------------------------------------------------------------------------------
_aovs: dict[str, list[str]] = {}   # render product path -> render variables added with add_aov


def _product(render_product_path: str) -> RenderProduct:
    try:
        return registry.find(str(render_product_path))
    except ValueError:
        raise RuntimeError(f'Invalid renderProduct "{render_product_path}"') from None


def add_aov(render_product_path: str, aov_name: str) -> None:
    """Record render variable ``aov_name`` on the product (graphsdg renders every AOV an annotator asks for)."""
    if not isinstance(aov_name, str) or not aov_name:
        raise ValueError(f"aov_name must be a non-empty string, got {aov_name!r}")
    product = _product(render_product_path)
    names = _aovs.setdefault(product.path, [])
    if aov_name not in names:
        names.append(aov_name)


def create_hydra_texture(resolution: tuple[int, int], camera_prim_path: str) -> tuple[Any, str]:
    """Isaac's older ``create_hydra_texture``: a new render product of the camera at ``resolution``;
    returns (its hydra texture, its path)."""
    product = create_render_product(camera_prim_path, resolution, force_new=True)
    return product.hydra_texture, product.path


def get_camera_prim_path(render_product_path: str) -> str:
    """The product's camera path."""
    return _product(render_product_path).camera


def set_camera_prim_path(render_product_path: str, camera_prim_path: str) -> None:
    """Render the product from another camera (from the next capture on)."""
    product = _product(render_product_path)
    prim = get_stage().GetPrimAtPath(str(camera_prim_path))
    if not prim.IsValid():
        raise RuntimeError(f'Invalid camera prim "{camera_prim_path}"')
    if not prim.IsA(UsdGeom.Camera):
        raise RuntimeError(f'"{camera_prim_path}" is a {prim.GetTypeName()}, not a Camera')
    product.camera = str(prim.GetPath())


def get_resolution(render_product_path: str) -> tuple[int, int]:
    """The product's (width, height)."""
    return tuple(_product(render_product_path).resolution)


def set_resolution(render_product_path: str, resolution: tuple[int, int]) -> None:
    """Render the product at (width, height) from the next capture on."""
    width, height = (int(v) for v in resolution)
    if width <= 0 or height <= 0:
        raise ValueError(f"resolution must be two positive integers, got {resolution!r}")
    _product(render_product_path).resolution = (width, height)


# ---- carb ---------------------------------------------------------------------------------------------------------
def set_carb_setting(carb_settings: CarbSettings, setting: str, value: Any) -> None:
    """Set ``setting`` through ``carb_settings`` (``carb.settings.get_settings()``)."""
    carb_settings.set(setting, value)


def get_carb_setting(carb_settings: CarbSettings, setting: str) -> Any:
    """The value of ``setting`` (None when unset)."""
    return carb_settings.get(setting)


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.utils.viewports``, ``.render_product`` and ``.carb``."""
    return [CompatModule("isaacsim.core.utils.viewports", set_camera_view=set_camera_view,
                         get_viewport_names=get_viewport_names, get_id_from_index=get_id_from_index,
                         get_window_from_id=get_window_from_id, destroy_all_viewports=destroy_all_viewports,
                         add_aov_to_viewport=add_aov_to_viewport, get_intrinsics_matrix=get_intrinsics_matrix,
                         set_intrinsics_matrix=set_intrinsics_matrix, backproject_depth=backproject_depth,
                         project_depth_to_worldspace=project_depth_to_worldspace,
                         create_viewport_for_camera=create_viewport_for_camera,
                         set_active_viewport_camera=set_active_viewport_camera),
            CompatModule("isaacsim.core.utils.render_product", add_aov=add_aov,
                         create_hydra_texture=create_hydra_texture,
                         get_camera_prim_path=get_camera_prim_path, set_camera_prim_path=set_camera_prim_path,
                         get_resolution=get_resolution, set_resolution=set_resolution),
            CompatModule("isaacsim.core.utils.carb", set_carb_setting=set_carb_setting,
                         get_carb_setting=get_carb_setting)]
