"""The ``dope`` and ``pose`` annotators: labelled objects' poses and projections. Poses are in a chosen camera
frame.

Both start from the USD camera (its view and projection matrices, from ``camera_params``) and a *desired*
camera turned from it by ``cameraRotation`` (Euler degrees, X then Y then Z about fixed axes; ``(180, 0, 0)``
is the OpenCV camera: +Z forward, +Y down). Pixel coordinates are the image-space points of the USD camera's
view-projection with the desired rotation applied in clip space, scaled by ``width`` x ``height``, as Isaac's
DOPE and pose nodes compute them.

``dope`` (one row per ``bounding_box_3d`` row): ``semanticId``, ``visibility`` (1 - occlusion ratio),
``location`` (the prim's origin in the desired camera frame, in centimetres of a metre stage: scene units x
100), ``rotation`` (quaternion w, x, y, z of the prim in that frame, scale removed) and ``projected_cuboid``
(9 x 2 pixels: the box corners in DOPE's order, then the prim's origin). Its ``info`` has ``idToLabels``.

``pose`` (one row per labelled prim visible in the image, every labelled prim with ``includeOccludedPrims``):
``semanticId`` (numbered from 0 per distinct label set, in prim order), ``prims_to_desired_camera`` (4x4,
column-vector, scale removed) and ``center_coords_image_space`` (the prim origin's pixel). ``info``:
``idToLabels`` (keys as strings) and ``primPaths``.

Example:
    >>> import numpy as np, graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> _ = rep.functional.create.cube(position=(0, 0, -5), semantics=[("class", "box")], name="Box")
    >>> camera = rep.functional.create.camera(position=(0, 0, 0))
    >>> register_dope_annotator()      # the defaults: the USD camera, the render product's size
    >>> dope = rep.annotators.get("dope", init_params={"cameraRotation": [180.0, 0.0, 0.0]})
    >>> _ = dope.attach(rep.create.render_product(camera, (64, 64)))
    >>> rep.orchestrator.step()
    >>> row = dope.get_data()["data"][0]
    >>> np.round(row["location"], 4).tolist(), row["projected_cuboid"][8].tolist()   # 5 m ahead, image centre
    ([0.0, 0.0, 500.0], [32.0, 32.0])
"""
from __future__ import annotations

import json
from typing import Any

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry, AnnotatorSpec, get_output
from graphsdg.maths.rotations import decompose, euler_to_matrix, matrix_to_quat_wxyz

DOPE_DTYPE = np.dtype([("semanticId", "<u4"), ("visibility", "<f4"), ("location", "<f4", (3,)),
                       ("rotation", "<f4", (4,)), ("projected_cuboid", "<f4", (9, 2))])
POSE_DTYPE = np.dtype([("semanticId", "<u4"), ("prims_to_desired_camera", "<f4", (4, 4)),
                       ("center_coords_image_space", "<f4", (2,))])
# bounding_box_3d corners come x fastest, then y, then z (LDB, RDB, LUB, RUB, LDF, RDF, LUF, RUF); DOPE's
# cuboid takes them in this order, then the centre
DOPE_CORNER_ORDER = (5, 4, 6, 7, 1, 0, 2, 3)
_CORNER_PICKS = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=bool)


class DesiredCamera:
    """The USD camera of a frame and the desired camera turned from it (see the module docstring)."""

    def __init__(self, camera_params: dict, camera_rotation: Any, width: Any, height: Any) -> None:
        view = np.asarray(camera_params["cameraViewTransform"], dtype=np.float64).reshape(4, 4)   # row-vector
        projection = np.asarray(camera_params["cameraProjection"], dtype=np.float64).reshape(4, 4)
        rotation = np.eye(4)
        angles = np.asarray(camera_rotation if camera_rotation is not None else (0.0, 0.0, 0.0), dtype=np.float64)
        if angles.shape != (3,) or not np.all(np.isfinite(angles)):
            raise ValueError(f"cameraRotation must be 3 Euler angles in degrees, got {camera_rotation!r}")
        rotation[:3, :3] = euler_to_matrix(angles)
        res = np.asarray(camera_params["renderProductResolution"]).reshape(-1)
        self.width = float(width) if width else float(res[0])
        self.height = float(height) if height else float(res[1])
        self.world_to_camera = rotation @ view.T                    # column-vector, into the desired camera
        self.view_projection = view @ projection @ rotation.T       # row-vector, world -> desired clip space

    def pixels(self, points_world: np.ndarray) -> np.ndarray:
        """Pixel coordinates (N, 2) of world points (N, 3)."""
        pts = np.asarray(points_world, dtype=np.float64).reshape(-1, 3)
        clip = np.pad(pts, ((0, 0), (0, 1)), constant_values=1.0) @ self.view_projection
        with np.errstate(divide="ignore", invalid="ignore"):
            ndc = clip[:, :2] / clip[:, 3:]
        return 0.5 * (ndc + 1.0) * np.array([self.width, self.height])

    def pose_of(self, local_to_world_row: np.ndarray) -> np.ndarray:
        """The column-vector transform of a prim (row-vector local-to-world) into the desired camera, unscaled."""
        t, r, _ = decompose(np.asarray(local_to_world_row, dtype=np.float64).reshape(4, 4))
        prim = np.eye(4)
        prim[:3, :3], prim[:3, 3] = r, t
        return self.world_to_camera @ prim


def box_corners_world(rows: np.ndarray) -> np.ndarray:
    """The 8 corners (N, 8, 3) of ``bounding_box_3d`` rows in world coordinates (x fastest, then y, then z)."""
    lows = np.stack([rows["x_min"], rows["y_min"], rows["z_min"]], -1).astype(np.float64)
    highs = np.stack([rows["x_max"], rows["y_max"], rows["z_max"]], -1).astype(np.float64)
    corners = np.where(_CORNER_PICKS[None], highs[:, None, :], lows[:, None, :])
    homogeneous = np.concatenate([corners, np.ones(corners.shape[:2] + (1,))], -1)
    return np.einsum("nci,nij->ncj", homogeneous, rows["transform"].astype(np.float64))[..., :3]


def _inputs(frame: Any, params: dict) -> tuple[dict, dict]:
    types = params.get("semanticTypes")
    box3d = get_output(frame, AnnotatorRegistry.resolve("bounding_box_3d"),
                       {**AnnotatorRegistry.resolve("bounding_box_3d").defaults, "semanticTypes": types})
    camera = get_output(frame, AnnotatorRegistry.resolve("camera_params"), {})
    return box3d, camera["info"]


def dope(frame: Any, params: dict) -> dict:
    """DOPE rows of the frame's labelled boxes (see the module docstring)."""
    box3d, camera_params = _inputs(frame, params)
    camera = DesiredCamera(camera_params, params.get("cameraRotation"), params.get("width"), params.get("height"))
    rows = box3d["data"]
    out = np.zeros(len(rows), dtype=DOPE_DTYPE)
    if len(rows):
        corners = box_corners_world(rows)
        for i, row in enumerate(rows):
            pose = camera.pose_of(row["transform"])
            origin = row["transform"][3, :3].astype(np.float64)
            out[i]["semanticId"] = row["semanticId"]
            out[i]["visibility"] = 1.0 - row["occlusionRatio"]
            out[i]["location"] = pose[:3, 3] * 100.0
            out[i]["rotation"] = matrix_to_quat_wxyz(pose[:3, :3])
            out[i]["projected_cuboid"] = camera.pixels(np.vstack([corners[i][list(DOPE_CORNER_ORDER)], origin]))
    return {"data": out, "info": {"idToLabels": dict(box3d["info"].get("idToLabels", {}))}}


def prim_poses(frame: Any, params: dict) -> dict:
    """Pose rows of the frame's labelled prims (see the module docstring)."""
    box3d, camera_params = _inputs(frame, params)
    camera = DesiredCamera(camera_params, params.get("cameraRotation"), params.get("imageWidth"),
                           params.get("imageHeight"))
    rows, info = box3d["data"], box3d["info"]
    paths = list(info.get("primPaths", []))
    if not params.get("includeOccludedPrims", False):
        tight = get_output(frame, AnnotatorRegistry.resolve("bounding_box_2d_tight"),
                           {**AnnotatorRegistry.resolve("bounding_box_2d_tight").defaults,
                            "semanticTypes": params.get("semanticTypes")})
        visible = set(tight["info"].get("primPaths", []))
        keep = [i for i, p in enumerate(paths) if p in visible]
    else:
        keep = list(range(len(paths)))
    labels_of = info.get("idToLabels", {})
    ids: dict[str, int] = {}
    id_to_labels: dict[str, dict] = {}
    out = np.zeros(len(keep), dtype=POSE_DTYPE)
    for k, i in enumerate(keep):
        labels = labels_of.get(str(int(rows[i]["semanticId"])), {})
        key = json.dumps(labels, sort_keys=True)
        if key not in ids:
            ids[key] = len(ids)
            id_to_labels[str(ids[key])] = dict(labels)
        out[k]["semanticId"] = ids[key]
        out[k]["prims_to_desired_camera"] = camera.pose_of(rows[i]["transform"])
        if params.get("getCenters", True):
            out[k]["center_coords_image_space"] = camera.pixels(rows[i]["transform"][3, :3])[0]
    return {"data": out, "info": {"idToLabels": id_to_labels, "primPaths": [paths[i] for i in keep]}}


def register_dope_annotator(width: int | None = None, height: int | None = None,
                            camera_rotation: Any = (0.0, 0.0, 0.0), semantic_types: Any = ("class",)) -> None:
    """(Re)register ``dope`` with these defaults (``None`` sizes: the render product's)."""
    AnnotatorRegistry.register_spec(AnnotatorSpec(
        name="dope", passes=frozenset({"segmentation"}), compute=dope, doc=dope.__doc__ or "",
        defaults={"width": width, "height": height, "cameraRotation": list(camera_rotation),
                  "semanticTypes": list(semantic_types)}))


def register_pose_annotator(width: int | None = None, height: int | None = None,
                            camera_rotation: Any = (0.0, 0.0, 0.0), get_centers: bool = True,
                            include_occluded_prims: bool = False, semantic_types: Any = ("class",)) -> None:
    """(Re)register ``pose`` with these defaults (``None`` sizes: the render product's)."""
    AnnotatorRegistry.register_spec(AnnotatorSpec(
        name="pose", passes=frozenset({"segmentation"}), compute=prim_poses, doc=prim_poses.__doc__ or "",
        defaults={"imageWidth": width, "imageHeight": height, "cameraRotation": list(camera_rotation),
                  "getCenters": bool(get_centers), "includeOccludedPrims": bool(include_occluded_prims),
                  "semanticTypes": list(semantic_types)}))


register_dope_annotator()
register_pose_annotator()
