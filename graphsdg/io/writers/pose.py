"""PoseWriter: each visible object's 6-DoF pose and projected 3D box, per frame. Poses are in the camera frame.

Isaac Sim's PoseWriter (``isaacsim.replicator.writers``) layout and keys. Per
render product and frame, numbered ``{n}`` (``frame_padding`` digits; without
``use_subfolders`` the number counts every written render-product frame)::

    <output_dir>[/<rp_name>]/{n}.json          camera_data, keypoint_order, objects
    <output_dir>[/<rp_name>]/{n}.png           the rgb image
    <output_dir>[/<rp_name>]/{n}_overlay.png   write_debug_images: boxes, keypoints and axes drawn

``camera_data``: ``aperture``, ``aperture_offset``, ``focal_length``,
``resolution``, ``meters_per_scene_unit``, ``intrinsics`` (``fx, fy, cx, cy``
in pixels, the ones the image was rendered with), ``camera_view_matrix``
(world -> camera) and ``camera_projection_matrix`` (row-vector 4x4).

Each object (``bounding_box_3d`` rows whose visibility ``1 - occlusionRatio``
exceeds ``visibility_threshold``): ``label``, ``prim_path``, ``visibility``,
``local_to_world_transform``, ``location_world_frame``,
``rotation_matrix_world_frame``, ``quat_wxyz_world_frame``,
``location_camera_frame``, ``rotation_matrix_camera_frame``,
``quat_wxyz_camera_frame`` (USD camera frame: -Z forward, +Y up; rotation
matrices in USD row-vector layout, scale included, as Isaac's), ``size`` (the
scaled box dimensions), ``cuboid_keypoints_{world,camera}_frame`` and
``cuboid_keypoints_projected`` (pixels, floats; order ``keypoint_order``:
centre, then corners), ``truncation_ratio`` (share of the projected box outside
the image), and graphsdg's ``scale`` and ``local_bounds`` (``[min, max]`` of
the box in the prim's frame), so that a corner ``p`` lies at
``R(quat) @ (scale * p) + location`` in the camera frame.

``format="dope"`` / ``"centerpose"`` write those tools' keys instead
(``location``, ``quaternion_xyzw``, ``projected_cuboid``; centerpose adds
``scale`` and ``keypoints_3d``).

Example:
    >>> import graphsdg as rep, tempfile
    >>> w = rep.writers.get("PoseWriter")
    >>> w.initialize(output_dir=tempfile.mkdtemp(), write_debug_images=True)
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from PIL import Image, ImageDraw

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io import io_functions as iof
from graphsdg.io.camera_geometry import CUBOID_KEYPOINTS, PinholeCamera, box_corners, truncation_ratio
from graphsdg.io.labels import class_name
from graphsdg.io.writers import arguments
from graphsdg.io.writers.format_writer import FormatWriter
from graphsdg.maths.rotations import decompose, matrix_to_quat_wxyz

FORMATS = ("dope", "centerpose")
# Cuboid edges by keypoint index (1..8 = corners): Isaac's front (x_min), back (x_max) and connecting edges.
EDGES = {"front": [(1, 2), (2, 4), (4, 3), (3, 1)], "back": [(5, 6), (6, 8), (8, 7), (7, 5)],
         "connecting": [(1, 5), (2, 6), (3, 7), (4, 8)]}
EDGE_COLORS = {"front": (255, 0, 0), "back": (0, 0, 255), "connecting": (0, 200, 0)}
KEYPOINT_COLORS = [(255, 255, 255), (255, 0, 0), (0, 200, 0), (0, 0, 255), (255, 255, 0), (0, 255, 255),
                   (255, 0, 255), (255, 165, 0), (128, 0, 128)]


class PoseWriter(FormatWriter):
    """Object poses and projected cuboids per frame (see the module docstring)."""

    def __init__(self, output_dir: str | None = None, use_subfolders: bool = False,
                 visibility_threshold: float = 0.0, skip_empty_frames: bool = True,
                 write_debug_images: bool = False, frame_padding: int = 6, format: str | None = None,
                 semantic_types: Sequence[str] | None = None, use_s3: bool = False, s3_bucket: str | None = None,
                 s3_endpoint_url: str | None = None, s3_region: str | None = None, backend=None) -> None:
        super().__init__(output_dir, backend, version="0.0.1", use_s3=bool(use_s3), s3_bucket=s3_bucket,
                         s3_endpoint=s3_endpoint_url, s3_region=s3_region)
        name = type(self).__name__
        if format is not None and str(format).lower() not in FORMATS:
            raise ValueError(f"{name}: unsupported format {format!r}; supported: {FORMATS} or None")
        if isinstance(visibility_threshold, bool) or not isinstance(visibility_threshold, (int, float)) \
                or not 0.0 <= visibility_threshold <= 1.0:
            raise ValueError(f"{name}: visibility_threshold must be in [0, 1], got {visibility_threshold!r}")
        self._format = None if format is None else str(format).lower()
        self._use_subfolders = bool(use_subfolders)
        self._threshold = float(visibility_threshold)
        self._skip_empty = bool(skip_empty_frames)
        self._debug = bool(write_debug_images)
        self._padding = arguments.frame_padding(name, frame_padding)
        filter_text = self.semantic_filter(semantic_types, default_types=["class"])
        self._frame_id = 0
        self.annotators = [
            AnnotatorRegistry.get_annotator("rgb"),
            AnnotatorRegistry.get_annotator("bounding_box_3d_fast", init_params={"semanticFilter": filter_text}),
            AnnotatorRegistry.get_annotator("camera_params"),
        ]

    def get_current_frame_id(self) -> int:
        return self._frame_id

    def write(self, data: dict) -> None:
        products = data["renderProducts"]
        for rp_name, rp in products.items():
            camera = PinholeCamera.from_params(rp["camera_params"])
            objects = self.objects(rp["bounding_box_3d_fast"], camera)
            if self._skip_empty and not objects:
                continue
            folder = f"{rp_name}/" if self._use_subfolders and len(products) > 1 else ""
            stem = f"{folder}{self._frame_id:0{self._padding}d}"
            frame = {"camera_data": self.camera_data(rp["camera_params"], camera),
                     "keypoint_order": list(CUBOID_KEYPOINTS), "objects": [self._public(o) for o in objects]}
            self.backend.schedule(iof.write_json, data=frame, path=f"{stem}.json", indent=2)
            rgb = rp["rgb"]["data"]
            self.backend.schedule(iof.write_image, data=rgb, path=f"{stem}.png")
            if self._debug:
                self.backend.schedule(write_overlay, rgb=rgb, objects=objects, camera=camera,
                                      path=f"{stem}_overlay.png")
            if not self._use_subfolders:
                self._frame_id += 1
        if self._use_subfolders:
            self._frame_id += 1

    # ---- content -----------------------------------------------------------
    def camera_data(self, params: dict, camera: PinholeCamera) -> dict:
        out: dict[str, Any] = {}
        if self._format is None:
            out.update(aperture=np.asarray(params["cameraAperture"]).tolist(),
                       aperture_offset=np.asarray(params["cameraApertureOffset"]).tolist(),
                       focal_length=float(params["cameraFocalLength"]),
                       resolution=[camera.width, camera.height], meters_per_scene_unit=camera.meters_per_unit)
        out["intrinsics"] = {"fx": camera.fx, "fy": camera.fy, "cx": camera.cx, "cy": camera.cy}
        out["camera_view_matrix"] = camera.world_to_camera.tolist()
        out["camera_projection_matrix"] = np.asarray(params["cameraProjection"], dtype=np.float64).reshape(4, 4).tolist()
        if self._format == "centerpose":
            out.update(width=camera.width, height=camera.height)
        return out

    def objects(self, boxes: dict, camera: PinholeCamera) -> list[dict]:
        """Every object above the visibility threshold, with all pose fields (private ones start with ``_``)."""
        out = []
        for row, prim_path in zip(boxes["data"], boxes["primPaths"]):
            occlusion = float(row["occlusionRatio"])
            visibility = 1.0 - abs(occlusion) if np.isfinite(occlusion) else 0.0
            if visibility <= self._threshold:
                continue
            m = np.asarray(row["transform"], dtype=np.float64).reshape(4, 4)
            lo = np.array([row["x_min"], row["y_min"], row["z_min"]], dtype=np.float64)
            hi = np.array([row["x_max"], row["y_max"], row["z_max"]], dtype=np.float64)
            local = np.vstack([(lo + hi) / 2, box_corners(lo, hi)])
            world = local @ m[:3, :3] + m[3, :3]
            cam_pts = camera.to_camera(world)
            projected = camera.project(cam_pts)
            r_cam, t_cam, scale = camera.object_pose(m)
            _, r_world, _ = decompose(m)
            to_cam = m @ camera.world_to_camera
            label = class_name(boxes["idToLabels"].get(str(int(row["semanticId"]))), self.semantic_types)
            out.append({
                "label": label, "prim_path": prim_path, "visibility": round(visibility, 3),
                "local_to_world_transform": m.tolist(), "location_world_frame": m[3, :3].tolist(),
                "rotation_matrix_world_frame": m[:3, :3].tolist(),
                "quat_wxyz_world_frame": matrix_to_quat_wxyz(r_world).tolist(),
                "location_camera_frame": t_cam.tolist(), "rotation_matrix_camera_frame": to_cam[:3, :3].tolist(),
                "quat_wxyz_camera_frame": matrix_to_quat_wxyz(r_cam).tolist(),
                "size": (np.abs(scale) * (hi - lo)).tolist(), "scale": scale.tolist(),
                "local_bounds": [lo.tolist(), hi.tolist()],
                "cuboid_keypoints_world_frame": world.tolist(), "cuboid_keypoints_camera_frame": cam_pts.tolist(),
                "cuboid_keypoints_projected": projected.tolist(),
                "truncation_ratio": truncation_ratio(projected[1:], cam_pts[1:], camera.width, camera.height),
                "_axes": (local[0], np.abs(hi - lo).mean() * 0.25, m),
            })
        return out

    def _public(self, obj: dict) -> dict:
        if self._format is None:
            return {k: v for k, v in obj.items() if not k.startswith("_")}
        w, x, y, z = obj["quat_wxyz_camera_frame"]
        out = {"label": obj["label"], "prim_path": obj["prim_path"], "visibility": obj["visibility"],
               "location": obj["location_camera_frame"], "quaternion_xyzw": [x, y, z, w],
               "projected_cuboid": obj["cuboid_keypoints_projected"], "truncation_ratio": obj["truncation_ratio"]}
        if self._format == "centerpose":
            out.update(scale=obj["size"], keypoints_3d=obj["cuboid_keypoints_camera_frame"])
        return out

    def detach(self) -> None:
        super().detach()
        self._frame_id = 0


def write_overlay(rgb: np.ndarray, objects: list[dict], camera: PinholeCamera, path: str,
                  backend_instance=None) -> None:
    """The rgb image with every object's projected cuboid, keypoints and local axes drawn (runs on a worker)."""
    image = Image.fromarray(np.asarray(rgb)[..., :3].astype(np.uint8))
    draw = ImageDraw.Draw(image)
    for obj in objects:
        pts = [tuple(p) for p in obj["cuboid_keypoints_projected"]]
        if obj["truncation_ratio"] >= 1.0 and any(c[2] >= 0 for c in obj["cuboid_keypoints_camera_frame"]):
            continue                                  # a corner behind the camera has no image point
        for kind, edges in EDGES.items():
            for a, b in edges:
                draw.line([pts[a], pts[b]], fill=EDGE_COLORS[kind], width=1)
        for p, color in zip(pts, KEYPOINT_COLORS):
            draw.ellipse((p[0] - 1.5, p[1] - 1.5, p[0] + 1.5, p[1] + 1.5), fill=color)
        origin, length, m = obj["_axes"]
        ends = np.vstack([origin, origin + np.eye(3) * length])
        axes = camera.project(camera.to_camera(ends @ m[:3, :3] + m[3, :3]))
        for k, color in enumerate([(255, 0, 0), (0, 200, 0), (0, 0, 255)]):
            draw.line([tuple(axes[0]), tuple(axes[k + 1])], fill=color, width=1)
    iof.write_image(data=np.asarray(image), path=path, backend_instance=backend_instance)
