"""The pictures of docs/sensors.md: one scan of a 128-channel lidar over the warehouse.

Run: ``MUJOCO_GL=egl python docs/images/lidar_pictures.py [--out docs/images]``. Opens the asset pack's
``/Isaac/Environments/Simple_Warehouse/full_warehouse.usd``, puts an ``Example_Rotary`` lidar (128 channels,
1,024 columns, 10 Hz) 2 m up in an aisle and a camera beside it, captures frames until the lidar reports its first whole scan, and
writes:

* ``lidar_warehouse_bev.png``: the scan from above, each return coloured by its height, the lidar a cross;
* ``lidar_warehouse_camera.png``: the camera image with the returns on surfaces it sees drawn over it, coloured
  by range (each return projected through the camera's intrinsics and kept where the rendered depth agrees to
  5 cm: the lidar and the renderer see the same geometry).
"""
from __future__ import annotations

import argparse
import os

import cv2
import numpy as np

import graphsdg as rep
from graphsdg.assets import get_assets_root_path

LIDAR_AT = (-8.0, 13.0, 2.0)


def colour_map(values: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """uint8 (N, 3) RGB of ``values`` on OpenCV's turbo map between ``lo`` and ``hi``."""
    scaled = np.clip((values - lo) / max(hi - lo, 1e-9), 0, 1)
    bgr = cv2.applyColorMap((scaled * 255).astype(np.uint8).reshape(-1, 1), cv2.COLORMAP_TURBO).reshape(-1, 3)
    return bgr[:, ::-1]


def bird_eye(points: np.ndarray, size: int = 900, half: float = 22.0) -> np.ndarray:
    """The points from above within ``half`` metres of the lidar, coloured by height."""
    img = np.full((size, size, 3), 20, np.uint8)
    rel = points[:, :2] - np.array(LIDAR_AT[:2])
    keep = (np.abs(rel) < half).all(axis=1)
    rel, z = rel[keep], points[keep, 2]
    uv = np.stack([size / 2 + rel[:, 0] * size / (2 * half), size / 2 - rel[:, 1] * size / (2 * half)], 1)
    order = np.argsort(z)             # high points drawn last
    for (u, v), c in zip(uv[order].astype(int), colour_map(z[order], -0.2, 6.0)):
        cv2.circle(img, (int(u), int(v)), 1, tuple(int(x) for x in c), -1)
    cv2.drawMarker(img, (size // 2, size // 2), (255, 255, 255), cv2.MARKER_CROSS, 18, 2)
    cv2.putText(img, f"{len(points):,} returns, one 10 Hz scan, height -0.2 (blue) .. 6 m (red)", (12, size - 14),
                cv2.FONT_HERSHEY_SIMPLEX, 0.55, (230, 230, 230), 1, cv2.LINE_AA)
    return img


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=os.path.dirname(os.path.abspath(__file__)))
    parser.add_argument("--width", type=int, default=640)
    args = parser.parse_args()
    from graphsdg.render.camera import camera_view
    from graphsdg.stage.context import get_stage, open_stage

    open_stage(get_assets_root_path() + "/Isaac/Environments/Simple_Warehouse/full_warehouse.usd")
    rep.functional.create.xform(name="Sensors")
    rep.functional.create.omni_lidar(position=LIDAR_AT, name="Lidar", parent="/Sensors", config="Example_Rotary")
    camera = rep.functional.create.camera(position=(-8.0, 11.0, 2.5), look_at=(-3.0, 16.0, 1.0), parent="/Sensors",
                                          name="Camera")
    height = args.width * 9 // 16
    lidar_rp = rep.create.render_product("/Sensors/Lidar", (64, 64))
    camera_rp = rep.create.render_product(str(camera.GetPath()), (args.width, height))
    cloud = rep.annotators.get("sensor_point_cloud", init_params={"frame": "world"})
    cloud.attach(lidar_rp)
    rgb = rep.annotators.get("rgb")
    rgb.attach(camera_rp)
    depth_image = rep.annotators.get("distance_to_image_plane")
    depth_image.attach(camera_rp)
    for _ in range(12):               # the lidar reports at its 10 Hz tick: the first scan ends at 0.1 s
        rep.orchestrator.step()
        if cloud.get_data()["info"].get("fresh"):
            break
    points = np.asarray(cloud.get_data()["data"], dtype=np.float64)
    image = np.ascontiguousarray(rgb.get_data()[..., :3])
    cv2.imwrite(os.path.join(args.out, "lidar_warehouse_bev.png"), cv2.cvtColor(bird_eye(points),
                                                                                cv2.COLOR_RGB2BGR))
    view = camera_view(get_stage().GetPrimAtPath(str(camera.GetPath())), args.width, height)
    pixels, depth = view.project(points)
    seen = (depth > 0) & (pixels[:, 0] >= 0) & (pixels[:, 0] < args.width) & (pixels[:, 1] >= 0) & \
        (pixels[:, 1] < height)
    # only the returns on surfaces the camera sees (not hidden behind what is nearer to the camera)
    rendered = np.asarray(depth_image.get_data(), dtype=np.float64)
    u, v = pixels[seen].astype(int).T
    seen[np.flatnonzero(seen)] = depth[seen] <= rendered[v, u] + 0.05
    ranges = np.linalg.norm(points - np.array(LIDAR_AT), axis=1)
    overlay = image.copy()
    for (u, v), c in zip(pixels[seen].astype(int), colour_map(ranges[seen], 0.0, 20.0)):
        cv2.circle(overlay, (int(u), int(v)), 1, tuple(int(x) for x in c), -1)
    cv2.imwrite(os.path.join(args.out, "lidar_warehouse_camera.png"), cv2.cvtColor(overlay, cv2.COLOR_RGB2BGR))
    print(f"{len(points)} returns; {int(seen.sum())} in the camera's view; pictures in {args.out}")


if __name__ == "__main__":
    main()
