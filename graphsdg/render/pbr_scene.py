"""graphsdg's scene as mujoco-warp-pbr needs it: rays, materials, lights, environment, per-world arrays.

Pure numpy (and USD reads): no Warp, so CI tests it on any Python. The PBR
backend (:mod:`graphsdg.render.pbr`) uploads what this module computes.

* **Camera rays.** A USD camera (:class:`~graphsdg.render.camera.CameraView`:
  Omniverse's horizontal aperture fit, aperture offsets, clipping range,
  orthographic apertures in tenths of a unit) becomes one ray per pixel centre in
  the camera frame (x right, y up, looking down -z: USD's and MuJoCo's camera frame
  alike), starting on the near plane. The renderer reports the distance ``t`` along
  each (normalised) ray; planar depth is ``near + t * cos`` (:func:`planar_depth`),
  ``inf`` past the far plane, as the classic path reports it.
* **Materials.** UsdPreviewSurface and OmniPBR inputs -> :class:`SurfaceFields`:
  base colour, opacity, metallic, perceptual roughness, Filament reflectance
  (``F0 = 0.16 r^2``: OmniPBR's ``specular_level`` is that same ``r``; a Preview
  surface's ``ior`` gives ``F0 = ((ior - 1) / (ior + 1))^2``, its specular workflow
  the luminance of ``specularColor``), emission in nits, and texture maps by role
  (base colour, normal, ORM or separate occlusion / roughness / metallic, emissive,
  opacity).
* **Lights and one exposure.** The classic path shows irradiance ``E`` on a white
  diffuse surface as ``E * exposure / (pi * 600)`` (:mod:`graphsdg.sim.lights`). A
  physically based renderer shows it as ``(E / pi) * k`` for a linear exposure ``k``,
  so ``k = exposure / 600`` (:func:`linear_exposure`) makes one stage look alike in
  both: a dome of 600 nits lights a white floor to white. The compiler stores each
  light's ``diffuse`` as ``colour * power / (pi * 600 / exposure)``, so every scene
  light's physical intensity (lux for distant lights, candela for the rest) is
  ``diffuse * pi * 600 / exposure`` (:func:`light_intensities`). The compiler's
  stand-ins for dome lights (``<path>#sky`` directional lights) get 0: the dome is
  the environment map instead.
* **Dome -> environment map.** Lat-long radiance in nits (texture x colour x
  ``intensity * 2^exposure``), resampled from UsdLux's orientation and the dome's
  rotation into the renderer's frame (row 0 = +z, centre column = +x); several
  domes add up. A dome turned only about the up axis keeps its map and passes the
  turn as the renderer's per-world yaw (:func:`dome_yaw`).
* **Per-world arrays.** :class:`WorldArrays` holds everything a randomizer may
  change per frame without recompiling (colours, materials, lights, environment
  intensity and yaw, exposure); :func:`stack_worlds` batches several frames or
  render products of one model as the renderer's worlds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import mujoco
import numpy as np
from pxr import Gf, Usd, UsdShade

from graphsdg.render.camera import CameraView
from graphsdg.sim import lights as lightmap
from graphsdg.stage import materials as matlib

#: radiance (nits) that shows as display value 1 at exposure 1, in both backends
WHITE_NITS = 600.0
LUMA = np.array([0.2126, 0.7152, 0.0722])
#: texture map roles (mujoco-warp-pbr reads MuJoCo's texture roles of the same names)
MAP_ROLES = ("base_color", "normal", "orm", "occlusion", "roughness", "metallic", "emissive", "opacity")
SKY_LIGHT_SUFFIX = "#sky"


# ---- camera ---------------------------------------------------------------------------------------
def camera_rays(view: CameraView) -> np.ndarray:
    """Per-pixel camera-frame rays of ``view``, (H, W, 2, 3) float32: ``[..., 0]`` origin, ``[..., 1]`` unit
    direction, through each pixel centre, starting on the near plane.

    The layout is mujoco-warp-pbr's ``camera_rays``; the frame is the camera's (x right, y up, -z forward),
    which the renderer places in the world by the camera's pose (:func:`camera_pose`).
    """
    h, w = view.height, view.width
    rays = np.empty((h, w, 2, 3), dtype=np.float64)
    if view.projection == "orthographic":
        xs = (np.arange(w) + 0.5 - view.cx) / view.fx
        ys = -(np.arange(h) + 0.5 - view.cy) / view.fy
        xx, yy = np.meshgrid(xs, ys)
        rays[..., 0, :] = np.stack([xx, yy, np.full_like(xx, -view.near)], axis=-1)
        rays[..., 1, :] = (0.0, 0.0, -1.0)
    else:
        d = view.pixel_directions()            # scaled to z = -1
        rays[..., 0, :] = d * view.near        # on the near plane (z = -near)
        rays[..., 1, :] = d / np.linalg.norm(d, axis=-1, keepdims=True)
    return rays.astype(np.float32)


def ray_cosines(view: CameraView) -> np.ndarray:
    """(H, W) cosine between each pixel's ray and the optical axis (1 for orthographic cameras)."""
    return view.ray_cosines()


def planar_depth(distance: np.ndarray, view: CameraView, hit: np.ndarray | None = None) -> np.ndarray:
    """Planar z (float32, inf where nothing was hit or beyond the far plane) from the renderer's distance
    along each ray of :func:`camera_rays`."""
    z = view.near + np.asarray(distance, dtype=np.float64) * ray_cosines(view)
    miss = ~np.isfinite(z) | (z > view.far)
    if hit is not None:
        miss |= ~hit
    z[miss] = np.inf
    return z.astype(np.float32)


def camera_pose(view: CameraView) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,), 3x3 matrix) for the renderer's camera: MuJoCo's ``cam_xmat`` has the camera axes as
    columns, which is exactly :attr:`CameraView.rotation`."""
    return np.asarray(view.position, dtype=np.float64), np.asarray(view.rotation, dtype=np.float64)


# ---- exposure and lights --------------------------------------------------------------------------
def linear_exposure(exposure_setting: float = 1.0) -> float:
    """The renderer's linear exposure for graphsdg's ``/graphsdg/render/exposure`` (see the module docstring)."""
    return float(exposure_setting) / WHITE_NITS


def ev100(exposure_setting: float = 1.0) -> float:
    """EV100 with that linear exposure (Filament: ``exposure = 1 / (1.2 * 2^EV100)``)."""
    return math.log2(1.0 / (1.2 * linear_exposure(exposure_setting)))


def light_intensities(model: mujoco.MjModel, exposure_setting: float = 1.0) -> np.ndarray:
    """Physical intensity (nlight,) float32 per MuJoCo light: lux (directional) or candela (the rest).

    The renderer multiplies a light's ``diffuse`` colour by its intensity; the compiler stored
    ``diffuse = colour * power / (pi * 600 / exposure)``, so the intensity undoing that scale is the same
    for every light, and a randomizer that rewrites ``light_diffuse`` changes the physical light with no
    other bookkeeping. Dome stand-ins (``#sky``) are 0: the environment map lights instead.
    """
    k = lightmap.REFERENCE_IRRADIANCE / float(exposure_setting)
    sky = np.array([model.light(i).name.endswith(SKY_LIGHT_SUFFIX) for i in range(model.nlight)], dtype=bool)
    return np.where(sky, 0.0, k).astype(np.float32)


# ---- materials ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SurfaceFields:
    """A material as the physically based renderer shades it (linear colour, Filament conventions)."""

    path: str
    base_color: tuple[float, float, float] = (0.7, 0.7, 0.7)
    opacity: float = 1.0
    metallic: float = 0.0
    roughness: float = 0.5             # perceptual roughness
    reflectance: float = 0.5           # F0 = 0.16 * reflectance^2 (0.5: 4%, common dielectrics)
    emissive_nits: tuple[float, float, float] = (0.0, 0.0, 0.0)
    maps: dict[str, str] = field(default_factory=dict)   # role (MAP_ROLES) -> texture file

    @property
    def f0(self) -> float:
        """Dielectric reflectance at normal incidence."""
        return 0.16 * self.reflectance ** 2


def reflectance_from_ior(ior: float) -> float:
    """Filament reflectance of a dielectric of index ``ior`` (1.5 -> 0.5, F0 = 4%)."""
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    return float(np.clip(math.sqrt(f0 / 0.16), 0.0, 1.0))


def reflectance_from_f0(f0: float) -> float:
    return float(np.clip(math.sqrt(max(f0, 0.0) / 0.16), 0.0, 1.0))


def _value(shader: UsdShade.Shader, name: str, default):
    inp = shader.GetInput(name)
    if not inp or inp.HasConnectedSource():
        return default
    v = inp.Get()
    return default if v is None else v


def surface_fields(material: UsdShade.Material) -> SurfaceFields:
    """Read ``material``'s UsdPreviewSurface network, or its OmniPBR MDL shader, into :class:`SurfaceFields`."""
    desc = matlib.describe(material)   # base colour, opacity, roughness, metallic as the classic path reads them
    path = str(material.GetPath())
    base = dict(path=path, base_color=tuple(float(c) for c in desc.rgba[:3]), opacity=float(desc.rgba[3]),
                metallic=float(desc.metallic), roughness=float(desc.roughness))
    shader = matlib.surface_shader(material)
    if shader is not None:
        return _preview_fields(material, shader, base)
    mdl = material.ComputeSurfaceSource("mdl")
    mdl_shader = mdl[0] if mdl and mdl[0] and mdl[0].GetPrim().IsValid() else None
    return _omnipbr_fields(material, mdl_shader, base) if mdl_shader is not None else SurfaceFields(**base)


def _preview_fields(material: UsdShade.Material, shader: UsdShade.Shader, base: dict) -> SurfaceFields:
    if int(_value(shader, "useSpecularWorkflow", 0)):
        spec = np.asarray(_value(shader, "specularColor", Gf.Vec3f(0, 0, 0)), dtype=np.float64)
        base["reflectance"] = reflectance_from_f0(float(LUMA @ spec))
        base["metallic"] = 0.0          # the specular workflow has no metalness
    else:
        base["reflectance"] = reflectance_from_ior(float(_value(shader, "ior", 1.5)))
    emissive = np.asarray(_value(shader, "emissiveColor", Gf.Vec3f(0, 0, 0)), dtype=np.float64)
    # Preview emission is a display value (1 shows white): in nits at graphsdg's reference exposure
    base["emissive_nits"] = tuple(float(c) for c in emissive * WHITE_NITS)
    return SurfaceFields(maps=matlib.texture_maps(material), **base)


def _omnipbr_fields(material: UsdShade.Material, shader: UsdShade.Shader, base: dict) -> SurfaceFields:
    def get(name: str, default):
        inp = shader.GetInput(name)
        v = matlib._input_value(inp) if inp else None
        return default if v is None else v

    base["reflectance"] = float(np.clip(float(get("specular_level", 0.5)), 0.0, 1.0))
    if bool(get("enable_emission", False)):
        colour = np.asarray(get("emissive_color", Gf.Vec3f(1, 0.1, 0.1)), dtype=np.float64)
        base["emissive_nits"] = tuple(float(c) for c in colour * float(get("emissive_intensity", 40.0)))
    return SurfaceFields(maps=matlib.texture_maps(material), **base)


@dataclass
class GeomSurfaces:
    """Per-geom surface arrays of one world, (ngeom,) float32 each (the renderer's ``geom_*`` tables)."""

    metallic: np.ndarray
    roughness: np.ndarray
    reflectance: np.ndarray


def geom_surfaces(model: mujoco.MjModel, by_material: dict[int, SurfaceFields]) -> GeomSurfaces:
    """Metallic, roughness and reflectance of every geom from its current MuJoCo material.

    ``by_material``: MuJoCo material id -> its USD material's fields. Geoms without a material (display
    colour only) take USD's defaults (dielectric, roughness 0.5, F0 4%). Material randomizers rebind
    ``geom_matid``, so calling this per frame follows them.
    """
    # one row per MuJoCo material and a last row of defaults, indexed by geom_matid (-1: the defaults)
    table = np.tile(np.array([0.0, 0.5, 0.5], dtype=np.float32), (model.nmat + 1, 1))
    for mat, surface in by_material.items():
        if 0 <= mat < model.nmat:
            table[mat] = surface.metallic, surface.roughness, surface.reflectance
    matid = np.asarray(model.geom_matid)
    rows = table[np.where((matid >= 0) & (matid < model.nmat), matid, model.nmat)]
    metallic, roughness, reflectance = (np.ascontiguousarray(rows[:, i]) for i in range(3))
    return GeomSurfaces(metallic, roughness, reflectance)


# ---- environment ----------------------------------------------------------------------------------
def renderer_directions(width: int, height: int) -> np.ndarray:
    """World directions (H, W, 3) of the renderer's lat-long texel centres: row 0 = +z, centre column = +x,
    longitude growing towards +y (mujoco-warp-pbr's ``uv_to_direction``)."""
    phi = ((np.arange(width) + 0.5) / width - 0.5) * 2 * math.pi
    theta = (np.arange(height) + 0.5) / height * math.pi
    pp, tt = np.meshgrid(phi, theta)
    return np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)], axis=-1)


def usd_latlong_lookup(radiance: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Bilinear lookup of a UsdLux lat-long map (``graphsdg.imaging.environment_map`` convention: top row up,
    longitude 0 along -Y of a Z-up frame) at map-frame unit ``directions`` (..., 3)."""
    import cv2
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    lat = np.arcsin(np.clip(d[:, 2], -1.0, 1.0))
    lon = np.arctan2(d[:, 0], -d[:, 1])
    h, w = radiance.shape[:2]
    map_x = ((math.pi - lon) / (2 * math.pi) * w - 0.5).astype(np.float32)
    map_y = ((math.pi / 2 - lat) / math.pi * h - 0.5).astype(np.float32)
    padded = np.concatenate([radiance[:, -1:], radiance, radiance[:, :1]], axis=1).astype(np.float32)
    # OpenCV maps are 2D and under 32767 on a side: lay the lookups out in rows of 1024
    n, cols = len(d), 1024
    rows = -(-n // cols)
    grid_x = np.zeros(rows * cols, dtype=np.float32)
    grid_y = np.zeros(rows * cols, dtype=np.float32)
    grid_x[:n], grid_y[:n] = map_x + 1, map_y
    out = cv2.remap(padded, grid_x.reshape(rows, cols), grid_y.reshape(rows, cols), cv2.INTER_LINEAR,
                    borderMode=cv2.BORDER_REPLICATE)
    return out.reshape(-1, 3)[:n].reshape(*np.shape(directions)[:-1], 3)


def dome_yaw(rotation: np.ndarray) -> float | None:
    """The turn (radians) about +z when ``rotation`` (3x3) is only that, else None."""
    r = np.asarray(rotation, dtype=np.float64)
    if not (np.allclose(r[2], (0, 0, 1), atol=1e-9) and np.allclose(r[:, 2], (0, 0, 1), atol=1e-9)):
        return None
    return float(math.atan2(r[1, 0], r[0, 0]))


def dome_environment(radiance: np.ndarray | None, rotation: np.ndarray, nits: np.ndarray,
                     width: int = 1024, resample: bool = True) -> np.ndarray:
    """A dome's environment map in the renderer's frame, (width / 2, width, 3) float32 radiance in nits.

    ``radiance``: the dome texture (UsdLux lat-long, linear), or None for a uniform dome; ``rotation``:
    the dome's world rotation; ``nits``: colour x intensity x 2^exposure (3,). With ``resample`` False the
    map is only re-laid into the renderer's convention at the identity rotation (the caller passes a pure
    yaw as the renderer's ``env_yaw`` instead, see :func:`dome_yaw`).
    """
    nits = np.asarray(nits, dtype=np.float32).reshape(3)
    h = width // 2
    if radiance is None:
        return np.broadcast_to(nits, (h, width, 3)).astype(np.float32)
    dirs = renderer_directions(width, h)
    if resample:
        dirs = dirs @ np.asarray(rotation, dtype=np.float64)       # rows: R^T d, the map-frame direction
    return (usd_latlong_lookup(radiance, dirs) * nits).astype(np.float32)


# ---- per-world arrays -----------------------------------------------------------------------------
@dataclass
class WorldArrays:
    """Everything one world (a frame of one render product) may change without recompiling.

    Shapes are one world's; :func:`stack_worlds` adds the leading world axis the renderer indexes with
    ``worldid % shape[0]``.
    """

    geom_rgba: np.ndarray          # (ngeom, 4) colour randomizers
    geom_matid: np.ndarray         # (ngeom,) material randomizers
    geom_metallic: np.ndarray      # (ngeom,)
    geom_roughness: np.ndarray     # (ngeom,)
    geom_reflectance: np.ndarray   # (ngeom,)
    light_diffuse: np.ndarray      # (nlight, 3) light colour randomizers (colour x power, display-scaled)
    light_intensity: np.ndarray    # (nlight,) lux / candela multiplier of light_diffuse
    exposure: float                # linear exposure
    env_intensity: float           # environment radiance scale
    env_yaw: float                 # environment turn about +z, radians


def world_arrays(model: mujoco.MjModel, by_material: dict[int, SurfaceFields], exposure_setting: float = 1.0,
                 env_intensity: float = 1.0, env_yaw: float = 0.0) -> WorldArrays:
    """One world's arrays from the model as randomizers left it now."""
    surfaces = geom_surfaces(model, by_material)
    return WorldArrays(
        geom_rgba=np.array(model.geom_rgba, dtype=np.float32), geom_matid=np.array(model.geom_matid, dtype=np.int32),
        geom_metallic=surfaces.metallic, geom_roughness=surfaces.roughness, geom_reflectance=surfaces.reflectance,
        light_diffuse=np.array(model.light_diffuse, dtype=np.float32),
        light_intensity=light_intensities(model, exposure_setting), exposure=linear_exposure(exposure_setting),
        env_intensity=float(env_intensity), env_yaw=float(env_yaw))


def stack_worlds(worlds: list[WorldArrays]) -> WorldArrays:
    """The worlds' arrays stacked along a new leading world axis, in order."""
    if not worlds:
        raise ValueError("stack_worlds needs at least one world")
    out = {}
    for f in fields(WorldArrays):
        values = [getattr(w, f.name) for w in worlds]
        out[f.name] = np.stack([np.asarray(v) for v in values]).astype(np.asarray(values[0]).dtype, copy=False) \
            if np.ndim(values[0]) else np.asarray(values, dtype=np.float32)
    return WorldArrays(**out)


__all__ = ["GeomSurfaces", "MAP_ROLES", "SurfaceFields", "WHITE_NITS", "WorldArrays", "camera_pose", "camera_rays",
           "dome_environment", "dome_yaw", "ev100", "geom_surfaces", "light_intensities", "linear_exposure",
           "planar_depth", "reflectance_from_ior", "renderer_directions", "stack_worlds", "surface_fields",
           "usd_latlong_lookup", "world_arrays"]
