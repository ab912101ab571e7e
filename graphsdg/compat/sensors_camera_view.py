"""Isaac compat: ``isaacsim.sensors.camera.CameraView``: the images of many cameras as one batch or one tiled image.

Isaac renders the cameras into one tiled render product; graphsdg renders each camera into its own render
product at ``camera_resolution`` (the same images) and lays them out on request:

* ``get_data(annotator_type)``: a batch ``(cameras, height, width, channels)``;
* ``get_data(annotator_type, tiled=True)``: one image of the tiles in Isaac's grid: ``round(sqrt(n))`` rows,
  as many columns as needed, camera ``i`` at row ``i // columns``, column ``i % columns`` (unused tiles zero);
  ``tiled_resolution`` is its ``(width, height)``.

A run's ``/graphsdg/render/resolutionScale`` scales the products, and ``camera_resolution`` /
``tiled_resolution`` then report the scaled sizes, so buffers a script sizes from them fit what it gets back.

Arrays come back as Warp arrays (``out`` filled where given; on ``cuda`` when Warp sees a GPU, else on the CPU) with
the channel counts and types of :data:`ANNOTATOR_SPEC` (``rgb`` drops alpha). ``get_rgb_tiled`` /
``get_depth_tiled`` return NumPy on ``cpu`` and torch tensors on ``cuda``; ``get_rgb`` / ``get_depth`` torch
tensors (Isaac's types). Poses take ``camera_axes`` as :class:`~graphsdg.compat.sensors_camera.Camera` does;
lens getters and setters work on every camera (``indices`` selects some), in stage units.

Example:
    >>> tile_grid(4, (256, 128))
    (512, 256)
"""
from __future__ import annotations

from typing import Any

import numpy as np
from pxr import Gf, Sdf

import graphsdg
from graphsdg.compat.core_prims import XFormPrim
from graphsdg.compat.modules import CompatModule
from graphsdg.compat.sensors_camera import CAMERA_AXES, TENTHS, as_quat_matrix
from graphsdg.maths.rotations import matrix_to_quat_wxyz

# annotator type -> the annotator read, its channels, NumPy dtype name
ANNOTATOR_TYPES = {
    "rgb": ("rgb", 4, "uint8"), "rgba": ("rgb", 4, "uint8"),
    "depth": ("distance_to_image_plane", 1, "float32"),
    "distance_to_image_plane": ("distance_to_image_plane", 1, "float32"),
    "distance_to_camera": ("distance_to_camera", 1, "float32"),
    "normals": ("normals", 4, "float32"), "motion_vectors": ("motion_vectors", 4, "float32"),
    "semantic_segmentation": ("semantic_segmentation", 1, "uint32"),
    "instance_segmentation_fast": ("instance_segmentation_fast", 1, "uint32"),
    "instance_id_segmentation_fast": ("instance_id_segmentation_fast", 1, "uint32"),
}


def _warp():
    import warp as wp

    return wp


def annotator_spec() -> dict[str, dict[str, Any]]:
    """Isaac's ``ANNOTATOR_SPEC``: annotator type -> output name, channels, Warp dtype."""
    wp = _warp()
    return {kind: {"name": "rgba" if source == "rgb" else source, "channels": channels, "dtype": getattr(wp, dtype)}
            for kind, (source, channels, dtype) in ANNOTATOR_TYPES.items()}


def tile_grid(count: int, resolution: tuple[int, int]) -> tuple[int, int]:
    """(width, height) of the tiled image of ``count`` cameras at ``resolution``."""
    rows = max(1, round(count ** 0.5))
    columns = (count + rows - 1) // rows
    return columns * int(resolution[0]), rows * int(resolution[1])


def default_device() -> str:
    """``cuda`` where Warp sees a GPU, else ``cpu``."""
    wp = _warp()
    return "cuda" if wp.get_cuda_device_count() > 0 else "cpu"



def _torch(what: str) -> Any:
    """PyTorch, which ``what`` returns its data in (as Isaac's ``CameraView`` does), or an error naming it."""
    try:
        import torch
    except ModuleNotFoundError as exc:
        raise ModuleNotFoundError(f"{what} returns torch tensors, as Isaac Sim's CameraView does, and PyTorch is "
                                  f"not installed: pip install torch (with CUDA for device='cuda'), or use "
                                  f"get_rgb_tiled / get_depth_tiled / get_data with device='cpu'", name="torch") from exc
    return torch

class CameraView(XFormPrim):
    """``isaacsim.sensors.camera.CameraView`` (module docstring)."""

    _compat_name = "isaacsim.sensors.camera.CameraView"

    def __init__(self, prim_paths_expr: str | None = None, name: str = "camera_prim_view",
                 camera_resolution: tuple[int, int] = (256, 256), output_annotators: list[str] | None = None,
                 positions: Any = None, translations: Any = None, orientations: Any = None, scales: Any = None,
                 visibilities: Any = None, reset_xform_properties: bool = True) -> None:
        XFormPrim.__init__(self, prim_paths_expr=prim_paths_expr, name=name, positions=positions,
                           translations=translations, orientations=orientations, scales=scales,
                           visibilities=visibilities, reset_xform_properties=reset_xform_properties)
        not_cameras = [p for p, prim in zip(self.prim_paths, self.prims) if prim.GetTypeName() != "Camera"]
        if not_cameras:
            raise ValueError(f"CameraView {name!r}: prims {not_cameras} are not Camera prims")
        self._output_annotators = list(output_annotators or ["rgb", "depth"])
        for kind in self._output_annotators:
            if kind not in ANNOTATOR_TYPES:
                raise ValueError(f"Unsupported annotator type: {kind!r}. Supported types are "
                                 f"{list(ANNOTATOR_TYPES)}")
        self._requested_resolution = tuple(int(v) for v in camera_resolution)
        self.camera_resolution = self._requested_resolution
        self._products: list[Any] = []
        self._annotators: dict[str, Any] = {}
        self._setup_tiled_sensor()

    def __del__(self) -> None:
        try:
            self._clean_up_tiled_sensor()
        except Exception:   # interpreter exit
            pass

    def destroy(self) -> None:
        """Detach the annotators and destroy the cameras' render products."""
        self._clean_up_tiled_sensor()
        XFormPrim.destroy(self)

    def _clean_up_tiled_sensor(self) -> None:
        for annotator in self._annotators.values():
            annotator.detach()
        self._annotators = {}
        for product in self._products:
            product.destroy()
        self._products = []

    def _setup_tiled_sensor(self) -> None:
        self._clean_up_tiled_sensor()
        self._products = [graphsdg.create.render_product(path, self._requested_resolution, force_new=True,
                                                          name=f"{self.name}_tile_{i}")
                          for i, path in enumerate(self.prim_paths)]
        if self._products:   # as rendered: a run's resolution scale applies to every product alike
            self.camera_resolution = tuple(int(v) for v in self._products[0].resolution)
        self.tiled_resolution = tile_grid(len(self.prims), self.camera_resolution)
        self._render_product_path = self._products[0].path if self._products else None
        for kind in self._output_annotators:
            source = ANNOTATOR_TYPES[kind][0]
            if source not in self._annotators:
                self._annotators[source] = graphsdg.AnnotatorRegistry.get_annotator(source)
                self._annotators[source].attach(self._products)

    # ---- resolution and poses -----------------------------------------------------------------------------
    def get_render_product_path(self) -> str | None:
        """The first camera's render product path (graphsdg gives each camera its own product)."""
        return self._render_product_path

    def get_render_product_paths(self) -> list[str]:
        """Every camera's render product path."""
        return [product.path for product in self._products]

    def set_resolutions(self, resolution: tuple[int, int]) -> None:
        """Render every camera at ``(width, height)`` (times a run's resolution scale)."""
        if tuple(resolution) != self._requested_resolution:
            self._requested_resolution = tuple(int(v) for v in resolution)
            self._setup_tiled_sensor()

    def get_resolutions(self) -> tuple[int, int]:
        """Each camera's (width, height) as rendered."""
        return self.camera_resolution

    def get_aspect_ratios(self) -> float:
        """Width over height."""
        width, height = self.get_resolutions()
        return float(width) / float(height)

    def _axes(self, camera_axes: str) -> np.ndarray:
        if camera_axes not in CAMERA_AXES:
            raise ValueError(f"camera_axes {camera_axes!r} is not one of {sorted(CAMERA_AXES)}")
        return CAMERA_AXES[camera_axes]

    def _turn(self, orientations: np.ndarray, axes: np.ndarray) -> np.ndarray:
        return np.array([matrix_to_quat_wxyz(as_quat_matrix(q) @ axes) for q in np.asarray(orientations)])

    def get_world_poses(self, indices: Any = None, camera_axes: str = "world", usd: bool = True) -> tuple:
        """(positions, scalar-first quaternions) of the cameras, axes as ``camera_axes`` says."""
        positions, orientations = XFormPrim.get_world_poses(self, indices)
        return positions, self._turn(orientations, self._axes(camera_axes))

    def set_world_poses(self, positions: Any = None, orientations: Any = None, indices: Any = None,
                        camera_axes: str = "world", usd: bool = True) -> None:
        """Place the cameras in the world; ``orientations`` give the ``camera_axes`` axes."""
        if orientations is not None:
            orientations = self._turn(np.asarray(orientations, dtype=np.float64).reshape(-1, 4),
                                      self._axes(camera_axes).T)
        XFormPrim.set_world_poses(self, positions, orientations, indices)

    def get_local_poses(self, indices: Any = None, camera_axes: str = "world") -> tuple:
        """(translations, scalar-first quaternions) relative to the parents."""
        translations, orientations = XFormPrim.get_local_poses(self, indices)
        return translations, self._turn(orientations, self._axes(camera_axes))

    def set_local_poses(self, translations: Any = None, orientations: Any = None, indices: Any = None,
                        camera_axes: str = "world") -> None:
        """Place the cameras relative to their parents."""
        if orientations is not None:
            orientations = self._turn(np.asarray(orientations, dtype=np.float64).reshape(-1, 4),
                                      self._axes(camera_axes).T)
        XFormPrim.set_local_poses(self, translations, orientations, indices)

    # ---- data ---------------------------------------------------------------------------------------------
    def _batch(self, kind: str) -> np.ndarray | None:
        source, channels, dtype = ANNOTATOR_TYPES[kind]
        annotator = self._annotators.get(source)
        if annotator is None:
            raise ValueError(f"The annotator type {kind!r} was not configured; list it in output_annotators when "
                             f"making the CameraView")
        try:
            data = annotator.get_data()
        except Exception:   # nothing rendered yet
            return None
        frames = [data.get(product.name) for product in self._products] if isinstance(data, dict) and \
            len(self._products) > 1 else [data]
        frames = [f.get("data") if isinstance(f, dict) else f for f in frames]
        if any(f is None or np.size(f) == 0 for f in frames):
            return None
        frames = [np.asarray(f) for f in frames]
        batch = np.stack([(f[..., None] if f.ndim == 2 else f)[..., :channels] for f in frames])
        if kind == "rgb":
            batch = batch[..., :3]
        return batch.astype(dtype, copy=False)

    def _tiled(self, batch: np.ndarray) -> np.ndarray:
        height, width = batch.shape[1:3]          # as rendered (a run may scale render products)
        columns = self.tiled_resolution[0] // self.camera_resolution[0]
        rows = self.tiled_resolution[1] // self.camera_resolution[1]
        tiled = np.zeros((rows * height, columns * width, batch.shape[-1]), dtype=batch.dtype)
        for i, image in enumerate(batch):
            r, c = divmod(i, columns)
            tiled[r * height:(r + 1) * height, c * width:(c + 1) * width] = image
        return tiled

    def get_data(self, annotator_type: str, *, tiled: bool = False, out: Any = None) -> tuple[Any, dict]:
        """(Warp array, info) of ``annotator_type`` for every camera: a batch, or one tiled image."""
        wp = _warp()
        if annotator_type not in ANNOTATOR_TYPES:
            raise ValueError(f"Unsupported annotator type: {annotator_type!r}. Supported types are "
                             f"{list(ANNOTATOR_TYPES)}")
        device = str(out.device) if out is not None else default_device()
        batch = self._batch(annotator_type)
        if batch is None:
            return wp.empty(0, device=device), {}
        array = self._tiled(batch) if tiled else batch
        if out is None:
            return wp.array(array, dtype=getattr(wp, ANNOTATOR_TYPES[annotator_type][2]), device=device), {}
        if tuple(out.shape) != array.shape:
            raise ValueError(f"get_data({annotator_type!r}): out has shape {tuple(out.shape)}, the data "
                             f"{array.shape}")
        wp.copy(out, wp.array(array, dtype=out.dtype, device=out.device))
        return out, {}

    def _host_or_torch(self, kind: str, out: Any, device: str) -> Any:
        data = self.get_data(kind, tiled=True)[0]
        if out is None:
            if device == "cuda":
                return _torch(f"get_*_tiled(device={device!r})").as_tensor(data.numpy(), device="cuda")
            return data.numpy()
        if isinstance(out, np.ndarray):
            out[:] = data.numpy().reshape(out.shape)
        else:
            out.copy_(_torch("get_*_tiled(out=<tensor>)").as_tensor(data.numpy(), device=out.device)
                      .reshape(out.shape))
        return out

    def get_rgb_tiled(self, out: Any = None, device: str = "cpu") -> Any:
        """The tiled RGB image (NumPy on ``cpu``, a torch tensor on ``cuda``; or into ``out``)."""
        return self._host_or_torch("rgb", out, device)

    def get_depth_tiled(self, out: Any = None, device: str = "cpu") -> Any:
        """The tiled depth image (distance to the image plane)."""
        return self._host_or_torch("distance_to_image_plane", out, device)

    def _torch_batch(self, kind: str, out: Any) -> Any:
        torch = _torch(f"CameraView.get_{'rgb' if kind == 'rgb' else 'depth'}")
        data = torch.as_tensor(self.get_data(kind)[0].numpy(),
                               device=out.device if out is not None else default_device())
        if out is None:
            return data
        out.copy_(data.reshape(out.shape))
        return out

    def get_rgb(self, out: Any = None) -> Any:
        """(cameras, height, width, 3) RGB as a torch tensor."""
        return self._torch_batch("rgb", out)

    def get_depth(self, out: Any = None) -> Any:
        """(cameras, height, width, 1) depth as a torch tensor."""
        return self._torch_batch("distance_to_image_plane", out)

    # ---- lenses -------------------------------------------------------------------------------------------
    def _rows(self, indices: Any) -> list[int]:
        if indices is None:
            return list(range(len(self.prims)))
        return [int(i) for i in np.asarray(indices).reshape(-1)]

    def _read(self, attr: str, indices: Any, default: Any, scale: float = 1.0) -> list:
        values = []
        for i in self._rows(indices):
            value = self.prims[i].GetAttribute(attr).Get() if self.prims[i].GetAttribute(attr) else None
            value = default if value is None else value
            values.append(float(value) / scale if scale != 1.0 or isinstance(default, float) else value)
        return values

    def _write(self, attr: str, values: Any, indices: Any, scale: float = 1.0, type_name: Any = None) -> None:
        rows = self._rows(indices)
        values = list(values) if isinstance(values, (list, tuple, np.ndarray)) else [values] * len(rows)
        if len(values) != len(rows):
            raise ValueError(f"{attr}: {len(values)} values for {len(rows)} cameras")
        for i, value in zip(rows, values):
            prim = self.prims[i]
            attribute = prim.GetAttribute(attr) or prim.CreateAttribute(attr, type_name or Sdf.ValueTypeNames.Float)
            attribute.Set(float(value) * scale if scale != 1.0 or type_name is None else value)

    def get_focal_lengths(self, indices: Any = None) -> list[float]:
        """Focal lengths (stage units)."""
        return self._read("focalLength", indices, 50.0, TENTHS)

    def set_focal_lengths(self, values: Any, indices: Any = None) -> None:
        """Set focal lengths (stage units)."""
        self._write("focalLength", values, indices, TENTHS)

    def get_focus_distances(self, indices: Any = None) -> list[float]:
        """Focus distances (stage units)."""
        return self._read("focusDistance", indices, 0.0)

    def set_focus_distances(self, values: Any, indices: Any = None) -> None:
        """Set focus distances."""
        self._write("focusDistance", values, indices)

    def get_lens_apertures(self, indices: Any = None) -> list[float]:
        """F-stops."""
        return self._read("fStop", indices, 0.0)

    def set_lens_apertures(self, values: Any, indices: Any = None) -> None:
        """Set f-stops."""
        self._write("fStop", values, indices)

    def get_horizontal_apertures(self, indices: Any = None) -> list[float]:
        """Horizontal apertures (stage units)."""
        return self._read("horizontalAperture", indices, 20.955, TENTHS)

    def set_horizontal_apertures(self, values: Any, indices: Any = None) -> None:
        """Set horizontal apertures (stage units)."""
        self._write("horizontalAperture", values, indices, TENTHS)

    def get_vertical_apertures(self, indices: Any = None) -> list[float]:
        """Vertical apertures (stage units)."""
        return self._read("verticalAperture", indices, 15.2908, TENTHS)

    def set_vertical_apertures(self, values: Any, indices: Any = None) -> None:
        """Set vertical apertures (stage units)."""
        self._write("verticalAperture", values, indices, TENTHS)

    def get_projection_types(self, indices: Any = None) -> list[str]:
        """``cameraProjectionType`` of each camera (``pinhole`` where unset; graphsdg renders pinhole)."""
        return [str(v) for v in self._read("cameraProjectionType", indices, "pinhole")]

    def set_projection_types(self, values: Any, indices: Any = None) -> None:
        """Author ``cameraProjectionType`` (graphsdg renders pinhole images)."""
        self._write("cameraProjectionType", values, indices, type_name=Sdf.ValueTypeNames.Token)

    def get_projection_modes(self, indices: Any = None) -> list[str]:
        """``perspective`` or ``orthographic`` per camera."""
        return [str(v) for v in self._read("projection", indices, "perspective")]

    def set_projection_modes(self, values: Any, indices: Any = None) -> None:
        """Set the USD projection per camera."""
        self._write("projection", values, indices, type_name=Sdf.ValueTypeNames.Token)

    def get_stereo_roles(self, indices: Any = None) -> list[str]:
        """``mono``, ``left`` or ``right`` per camera."""
        return [str(v) for v in self._read("stereoRole", indices, "mono")]

    def set_stereo_roles(self, values: Any, indices: Any = None) -> None:
        """Set stereo roles."""
        self._write("stereoRole", values, indices, type_name=Sdf.ValueTypeNames.Token)

    def get_shutter_properties(self, indices: Any = None) -> list[tuple[float, float]]:
        """(open delay, close delay) in seconds per camera."""
        return list(zip(self._read("shutter:open", indices, 0.0), self._read("shutter:close", indices, 0.0)))

    def set_shutter_properties(self, values: Any, indices: Any = None) -> None:
        """Set (open delay, close delay) per camera (one pair per selected camera)."""
        pairs = [tuple(pair) for pair in values]
        rows = self._rows(indices)
        if len(pairs) != len(rows):
            raise ValueError(f"set_shutter_properties: {len(pairs)} (open, close) pairs for {len(rows)} cameras")
        self._write("shutter:open", [p[0] for p in pairs], indices)
        self._write("shutter:close", [p[1] for p in pairs], indices)

    def get_clipping_ranges(self, indices: Any = None) -> list[tuple[float, float]]:
        """(near, far) per camera."""
        return [(float(v[0]), float(v[1])) for v in self._read("clippingRange", indices, Gf.Vec2f(1.0, 1e6))]


def modules() -> list:
    """``CameraView`` and ``ANNOTATOR_SPEC`` in Isaac's modules (Isaac's module imports Warp: so does the spec)."""
    view = CompatModule("isaacsim.sensors.camera.camera_view", CameraView=CameraView)
    try:
        view.ANNOTATOR_SPEC = annotator_spec()
    except Exception:   # no Warp: importing the module's spec fails as Isaac's import of Warp would
        pass
    return [CompatModule("isaacsim.sensors.camera", CameraView=CameraView), view]
