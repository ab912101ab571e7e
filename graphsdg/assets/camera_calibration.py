"""Stand-ins for Isaac's camera-calibration assets. A 6 x 10 checkerboard target and the Hawk stereo camera.

* ``/Isaac/Props/Camera/checkerboard_6x10.usd``: a calibration board with
  6 x 10 inner corners (7 x 11 squares of 0.1 m) on a white margin, 0.8 m wide
  and 1.2 m tall, standing in the YZ plane with its printed face towards -X;
  its origin is the middle of its bottom edge, so a board placed 0.6 m below a
  camera looking along +X fills the view round the optical axis.
* ``/Isaac/Sensors/LeopardImaging/Hawk/hawk_v1.1_nominal.usd``: the Hawk stereo
  camera: a housing and two ``UsdGeom.Camera`` at ``left/camera_left`` and
  ``right/camera_right`` (0.15 m baseline, left at +Y), looking along +X with
  +Z up, with the AR0234 sensor's optics: 2.87 mm focal length on a
  5.76 x 3.6 mm sensor (90 degrees across, 1920 x 1200).

Example:
    >>> BOARD_SQUARES, SQUARE_M
    ((7, 11), 0.1)
"""
from __future__ import annotations

import numpy as np
from pxr import Gf, Kind, UsdGeom

from graphsdg.assets import authoring, geometry, textures
from graphsdg.assets.entries import UsdAsset, pack_file
from graphsdg.assets.props import part_texture
from graphsdg.maths.rotations import matrix_to_quat_wxyz

CHECKERBOARD_PATH = "/Isaac/Props/Camera/checkerboard_6x10.usd"
HAWK_PATH = "/Isaac/Sensors/LeopardImaging/Hawk/hawk_v1.1_nominal.usd"
BOARD_SQUARES = (7, 11)          # squares across (Y) and up (Z): 6 x 10 inner corners
SQUARE_M, MARGIN_M, BOARD_T = 0.1, 0.05, 0.01
BOARD_SIZE = (BOARD_T, BOARD_SQUARES[0] * SQUARE_M + 2 * MARGIN_M, BOARD_SQUARES[1] * SQUARE_M + 2 * MARGIN_M)
PX_PER_SQUARE = 16
HAWK_BASELINE, HAWK_FOCAL_MM, HAWK_SENSOR_MM = 0.15, 2.87, (5.76, 3.6)
HAWK_SIZE = (0.03, 0.19, 0.04)
# A USD camera looks along its -Z with +Y up; these look along +X with +Z up (columns: camera X, Y, Z).
CAMERA_AXES = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def checkerboard_image() -> np.ndarray:
    """The printed face: black and white squares inside a white margin (rows run down the board)."""
    cols, rows = BOARD_SQUARES
    margin = int(round(MARGIN_M / SQUARE_M * PX_PER_SQUARE))
    img = np.ones((rows * PX_PER_SQUARE + 2 * margin, cols * PX_PER_SQUARE + 2 * margin, 3))
    for r in range(rows):
        for c in range(cols):
            if (r + c) % 2 == 0:
                y, x = margin + r * PX_PER_SQUARE, margin + c * PX_PER_SQUARE
                img[y:y + PX_PER_SQUARE, x:x + PX_PER_SQUARE] = 0.02
    return img


def _board_mesh() -> geometry.MeshData:
    """The board (x in [-t, 0], face at x = -t towards -X); the face's UVs span the printed image exactly."""
    _, w, h = BOARD_SIZE
    face = np.array([(-BOARD_T, w / 2, 0.0), (-BOARD_T, -w / 2, 0.0), (-BOARD_T, -w / 2, h), (-BOARD_T, w / 2, h)])
    # seen from -X, +Y is on the left: u runs from +Y to -Y, v from the bottom up
    face_uv = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])
    # the white back and edges stand just behind the printed face (no two faces in one plane)
    back = geometry.box((-BOARD_T + 0.001, -w / 2, 0.0), (0.0, w / 2, h), lambda c, a: np.full((4, 2), 0.999))
    front = geometry.polygons([face], [face_uv])
    return geometry.merge([front, back])


def build_checkerboard(root: str) -> list[str]:
    """Write ``checkerboard_6x10.usd`` and its printed texture."""
    tex_rel = "/Isaac/Props/Camera/Textures/checkerboard_6x10.png"
    textures.write_png(pack_file(root, tex_rel), checkerboard_image())
    stage, prim = authoring.new_asset_stage(pack_file(root, CHECKERBOARD_PATH), "checkerboard")
    look = authoring.define_textured_material(stage, "/checkerboard/Looks/Print", "./Textures/checkerboard_6x10.png",
                                              roughness=0.9)
    mesh = authoring.define_mesh(stage, "/checkerboard/board", _board_mesh(), authoring.COMPACT_DECIMALS)
    authoring.bind_material(mesh.GetPrim(), look)
    authoring.save(stage)
    return [CHECKERBOARD_PATH, tex_rel]


def define_hawk_camera(stage, path: str) -> UsdGeom.Camera:
    """A Hawk imager at ``path``: a ``UsdGeom.Camera`` looking along its parent's +X with the AR0234's optics."""
    cam = UsdGeom.Camera.Define(stage, path)
    q = matrix_to_quat_wxyz(CAMERA_AXES)
    cam.AddOrientOp().Set(Gf.Quatf(float(q[0]), *map(float, q[1:])))
    cam.CreateFocalLengthAttr(HAWK_FOCAL_MM)
    cam.CreateHorizontalApertureAttr(HAWK_SENSOR_MM[0])
    cam.CreateVerticalApertureAttr(HAWK_SENSOR_MM[1])
    cam.CreateClippingRangeAttr(Gf.Vec2f(0.01, 1000.0))
    cam.CreateFStopAttr(0.0)
    cam.CreateFocusDistanceAttr(400.0)
    return cam


def build_hawk(root: str) -> list[str]:
    """Write ``hawk_v1.1_nominal.usd``: the housing and the two cameras."""
    tex_rel = "/Isaac/Sensors/LeopardImaging/Hawk/Textures/hawk_Housing.png"
    textures.write_png(pack_file(root, tex_rel), part_texture((0.08, 0.08, 0.09), 951))
    stage, prim = authoring.new_asset_stage(pack_file(root, HAWK_PATH), "Hawk", kind=Kind.Tokens.component)
    look = authoring.define_textured_material(stage, "/Hawk/Looks/Housing", "./Textures/hawk_Housing.png",
                                              roughness=0.5)
    dx, dy, dz = HAWK_SIZE
    housing = authoring.define_mesh(stage, "/Hawk/housing",
                                    geometry.box((-dx, -dy / 2, -dz / 2), (0.0, dy / 2, dz / 2)),
                                    authoring.COMPACT_DECIMALS)
    authoring.bind_material(housing.GetPrim(), look)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        holder = UsdGeom.Xform.Define(stage, f"/Hawk/{side}")
        holder.AddTranslateOp().Set(Gf.Vec3d(0.0, sign * HAWK_BASELINE / 2, 0.0))
        define_hawk_camera(stage, f"/Hawk/{side}/camera_{side}")
    authoring.save(stage)
    return [HAWK_PATH, tex_rel]


ASSETS: list[UsdAsset] = [
    UsdAsset("checkerboard_6x10", CHECKERBOARD_PATH, BOARD_SIZE,
             "calibration checkerboard, 6 x 10 inner corners (0.1 m squares), in the YZ plane facing -X; origin at the "
             "middle of its bottom edge", build_checkerboard),
    UsdAsset("hawk", HAWK_PATH, HAWK_SIZE,
             "Hawk stereo camera: housing, left/camera_left and right/camera_right (0.15 m baseline) looking along +X, "
             "2.87 mm focal length on a 5.76 x 3.6 mm sensor", build_hawk),
]
