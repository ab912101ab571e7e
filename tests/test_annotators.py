"""The full annotator set, checked against analytic truth on small images."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, UsdGeom

import graphsdg as rep
from graphsdg.errors import RenderProductDestroyedError, UnknownNameError
from graphsdg.nodes.annotators import BBOX_2D_DTYPE, BBOX_3D_DTYPE, OCCLUSION_DTYPE
from graphsdg.render.camera import camera_view
from graphsdg.engine.runtime import runtime
from graphsdg.maths.rotations import euler_to_matrix

from conftest import cube_corners

W, H = 128, 96


def _scene(camera_position=(0.0, -4.0, 0.0), look_at=(0.0, 0.0, 0.0), resolution=(W, H), **camera_kw):
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    cam = rep.functional.create.camera(position=camera_position, look_at=look_at, parent="/World", name="Camera",
                                       **camera_kw)
    return cam, rep.create.render_product(cam, resolution)


def _attach(rp, *names, **init_params):
    return [rep.annotators.get(n, init_params=init_params.get(n)).attach(rp) for n in names]


def _pixel_extent(lo: float, hi: float) -> tuple[float, float]:
    """Continuous extent [lo, hi] -> the inclusive bounds of the pixels whose centres it covers."""
    return float(np.ceil(lo - 0.5)), float(np.floor(hi - 0.5))


def _sphere_extent(view, center, radius):
    """Exact image-space extent (u_min, v_min, u_max, v_max) of a sphere's silhouette."""
    c = view.world_to_camera(np.asarray(center, dtype=np.float64)[None])[0]
    x, y, z = c[0], c[1], -c[2]            # z: depth in front of the camera
    out = []
    for a, f, off, sign in ((x, view.fx, view.cx, 1), (y, view.fy, view.cy, -1)):
        # tangent planes a = t * z through the camera centre: (a - t z)^2 = r^2 (1 + t^2)
        qa, qb, qc = z * z - radius ** 2, -2 * a * z, a * a - radius ** 2
        ts = np.roots([qa, qb, qc]).real
        vals = sorted(off + sign * f * t for t in ts)
        out.append(vals)
    return out[0][0], out[1][0], out[0][1], out[1][1]


# ---- depth ------------------------------------------------------------------
def test_plane_depth_and_distance_to_camera():
    d = 3.0
    cam, rp = _scene(camera_position=(0.0, 0.0, d), look_at=(0.0, 0.0, 0.0))
    rep.functional.create.plane(parent="/World", name="Floor", scale=20.0)
    z_ann, dist_ann = _attach(rp, "distance_to_image_plane", "distance_to_camera")
    rep.orchestrator.step()
    z, dist = z_ann.get_data(), dist_ann.get_data()
    assert z.dtype == np.float32 and z.shape == (H, W) and dist.dtype == np.float32 and dist.shape == (H, W)
    np.testing.assert_allclose(z, d, rtol=1e-3)
    # angle of each pixel-centre ray from the USD camera attributes, computed independently
    g = UsdGeom.Camera(cam)
    fx = W * g.GetFocalLengthAttr().Get() / g.GetHorizontalApertureAttr().Get()
    u = (np.arange(W) + 0.5 - W / 2) / fx
    v = (np.arange(H) + 0.5 - H / 2) / fx
    uu, vv = np.meshgrid(u, v)
    cos = 1 / np.sqrt(1 + uu ** 2 + vv ** 2)
    np.testing.assert_allclose(dist, d / cos, rtol=1e-3)


def test_slanted_plane_depth_is_sampled_at_pixel_centres():
    # A plane through the origin tilted 40 degrees: z-depth varies across each pixel, so a
    # sample taken off the pixel centre (as a multisampled colour pass resolves) would be off.
    cam, rp = _scene(camera_position=(0.0, 0.0, 3.0))
    plane = rep.functional.create.plane(parent="/World", name="Slope", scale=20.0, rotation=(40.0, 0.0, 0.0))
    (z_ann,) = _attach(rp, "distance_to_image_plane")
    rep.orchestrator.step()
    view = camera_view(cam, W, H)
    n = euler_to_matrix((40.0, 0.0, 0.0)) @ np.array([0.0, 0.0, 1.0])
    top = 1e-4 * n                                   # MuJoCo's plane is a 0.2 mm thick box
    dirs = view.pixel_directions() @ view.rotation.T  # z-depth 1 along each ray
    depth = np.dot(top - view.position, n) / (dirs @ n)
    np.testing.assert_allclose(z_ann.get_data(), depth, rtol=1e-3)
    assert plane.IsValid()


# ---- 2D and 3D boxes ----------------------------------------------------------
def test_cube_and_sphere_boxes_match_analytic_projection():
    cam, rp = _scene(camera_position=(1.0, -5.0, 1.5), look_at=(0.0, 0.0, 0.2))
    cube = rep.functional.create.cube(position=(-0.8, 0.0, 0.0), rotation=(0.0, 0.0, 30.0), parent="/World",
                                      name="Cube", semantics={"class": "cube"})
    rep.functional.create.sphere(position=(0.9, 0.2, 0.4), scale=1.2, parent="/World", name="Ball",
                                 semantics={"class": "ball"})
    tight, loose = _attach(rp, "bounding_box_2d_tight", "bounding_box_2d_loose")
    rep.orchestrator.step()
    view = camera_view(cam, W, H)
    world = np.array(UsdGeom.Xformable(cube).ComputeLocalToWorldTransform(0))
    corners = np.c_[cube_corners(), np.ones(8)] @ world
    uv, _ = view.project(corners[:, :3])
    expected = {"/World/Cube": (*_pixel_extent(uv[:, 0].min(), uv[:, 0].max()),
                                *_pixel_extent(uv[:, 1].min(), uv[:, 1].max())),
                "/World/Ball": None}
    u0, v0, u1, v1 = _sphere_extent(view, (0.9, 0.2, 0.4), 0.6)
    expected["/World/Ball"] = (*_pixel_extent(u0, u1), *_pixel_extent(v0, v1))
    for ann in (tight, loose):
        data = ann.get_data()
        assert data["data"].dtype == BBOX_2D_DTYPE
        assert sorted(data["info"]["primPaths"]) == ["/World/Ball", "/World/Cube"]
        for row, path in zip(data["data"], data["info"]["primPaths"]):
            x0, x1, y0, y1 = expected[path]
            assert abs(row["x_min"] - x0) <= 1 and abs(row["x_max"] - x1) <= 1, (path, row, expected[path])
            assert abs(row["y_min"] - y0) <= 1 and abs(row["y_max"] - y1) <= 1, (path, row, expected[path])
            assert row["occlusionRatio"] == 0.0


def test_bounding_box_3d_extents_and_transform_are_exact():
    cam, rp = _scene(camera_position=(4.0, -4.0, 3.0))
    pos, rot, scale = (0.3, -0.2, 0.1), (20.0, -35.0, 50.0), (0.5, 1.0, 1.5)
    rep.functional.create.cube(position=pos, rotation=rot, scale=scale, parent="/World", name="Box",
                               semantics={"class": "box"})
    (ann,) = _attach(rp, "bounding_box_3d")
    rep.orchestrator.step()
    data = ann.get_data()
    rows = data["data"]
    assert rows.dtype == BBOX_3D_DTYPE and len(rows) == 1 and data["info"]["primPaths"] == ["/World/Box"]
    r = rows[0]
    np.testing.assert_allclose([r["x_min"], r["y_min"], r["z_min"]], [-0.5] * 3, atol=1e-5)
    np.testing.assert_allclose([r["x_max"], r["y_max"], r["z_max"]], [0.5] * 3, atol=1e-5)
    expected = np.eye(4)           # row-vector layout: p_world = p_local @ M
    expected[:3, :3] = np.diag(scale) @ euler_to_matrix(rot).T
    expected[3, :3] = pos
    np.testing.assert_allclose(r["transform"], expected, atol=1e-5)
    assert r["occlusionRatio"] == 0.0


def _half_hidden_scene():
    cam, rp = _scene(camera_position=(0.0, -5.0, 0.0))
    rep.functional.create.cube(parent="/World", name="Target", semantics={"class": "target"})
    # a wall in front covering x < 0 of the target, and a box entirely behind the wall
    rep.functional.create.cube(position=(-1.0, -1.5, 0.0), scale=(2.0, 0.1, 3.0), parent="/World", name="Wall",
                               semantics={"class": "wall"})
    rep.functional.create.cube(position=(-1.2, 0.0, 0.0), scale=0.5, parent="/World", name="Hidden",
                               semantics={"class": "hidden"})
    return cam, rp


def test_half_hidden_object_loose_covers_it_tight_does_not_and_occlusion_is_half():
    cam, rp = _half_hidden_scene()
    tight, loose, occ = _attach(rp, "bounding_box_2d_tight", "bounding_box_2d_loose", "occlusion")
    rep.orchestrator.step()
    view = camera_view(cam, W, H)
    uv, _ = view.project(cube_corners())
    full_x0, full_x1 = _pixel_extent(uv[:, 0].min(), uv[:, 0].max())
    center_u = view.project(np.zeros((1, 3)))[0][0, 0]

    def row(ann, path):
        d = ann.get_data()
        return {p: r for p, r in zip(d["info"]["primPaths"], d["data"])}.get(path)

    lo, ti = row(loose, "/World/Target"), row(tight, "/World/Target")
    assert abs(lo["x_min"] - full_x0) <= 1 and abs(lo["x_max"] - full_x1) <= 1       # covers the hidden half
    assert abs(ti["x_min"] - _pixel_extent(center_u, center_u)[0]) <= 1 and abs(ti["x_max"] - full_x1) <= 1
    assert abs(lo["occlusionRatio"] - 0.5) < 0.05 and abs(ti["occlusionRatio"] - 0.5) < 0.05
    occ_rows = {int(r["instanceId"]): r for r in occ.get_data()}
    ids = dict(zip(loose.get_data()["info"]["primPaths"], loose.get_data()["info"]["bboxIds"]))
    assert abs(occ_rows[int(ids["/World/Target"])]["occlusionRatio"] - 0.5) < 0.05
    assert occ.get_data().dtype == OCCLUSION_DTYPE
    # fully occluded but in view: a loose row (ratio 1) and no tight row
    assert row(tight, "/World/Hidden") is None
    hidden = row(loose, "/World/Hidden")
    assert hidden is not None and hidden["occlusionRatio"] == 1.0
    assert occ_rows[int(ids["/World/Hidden"])]["occlusionRatio"] == 1.0
    assert row(loose, "/World/Wall")["occlusionRatio"] == 0.0


def test_camera_params_reproject_3d_box_onto_loose_box():
    cam, rp = _scene(camera_position=(3.0, -4.0, 2.0), look_at=(0.0, 0.0, 0.3), horizontal_aperture_offset=1.5,
                     vertical_aperture_offset=-0.8)
    rep.functional.create.cube(position=(0.2, 0.1, 0.3), rotation=(10.0, 20.0, 30.0), scale=(0.8, 0.6, 1.0),
                               parent="/World", name="Box", semantics={"class": "box"})
    params, box3d, loose = _attach(rp, "camera_params", "bounding_box_3d", "bounding_box_2d_loose")
    rep.orchestrator.step()
    p = params.get_data()
    expected_keys = {"cameraAperture", "cameraApertureOffset", "cameraFocalLength", "cameraFocusDistance",
                     "cameraFStop", "cameraModel", "cameraNearFar", "cameraProjection", "cameraViewTransform",
                     "cameraFisheyeNominalWidth", "cameraFisheyeNominalHeight", "cameraFisheyeOpticalCentre",
                     "cameraFisheyePolynomial", "cameraFisheyeMaxFOV", "cameraFisheyeLensP", "cameraFisheyeLensS",
                     "metersPerSceneUnit", "renderProductResolution"}
    assert expected_keys <= set(p)
    assert p["renderProductResolution"].dtype == np.int32 and p["renderProductResolution"].tolist() == [W, H]
    assert p["metersPerSceneUnit"] == pytest.approx(1.0) and p["cameraModel"] == "pinhole"
    view_m = p["cameraViewTransform"].reshape(4, 4)
    cam_pos = np.array(UsdGeom.Xformable(cam).ComputeLocalToWorldTransform(0))[3, :3]
    np.testing.assert_allclose(np.r_[cam_pos, 1.0] @ view_m, [0, 0, 0, 1], atol=1e-9)   # world -> camera
    r = box3d.get_data()["data"][0]
    lo = [r["x_min"], r["y_min"], r["z_min"]]
    hi = [r["x_max"], r["y_max"], r["z_max"]]
    corners = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    pc = corners @ r["transform"].astype(np.float64) @ view_m
    # pinhole intrinsics (square pixels, horizontal fit, USD aperture offsets)
    f, (ap_h, _) = p["cameraFocalLength"], p["cameraAperture"]
    off_h, off_v = p["cameraApertureOffset"]
    fx = W * f / ap_h
    cx, cy = W / 2 - off_h * W / ap_h, H / 2 + off_v * W / ap_h
    u = cx + fx * pc[:, 0] / -pc[:, 2]
    v = cy - fx * pc[:, 1] / -pc[:, 2]
    # the projection matrix gives the same pixels
    clip = pc @ p["cameraProjection"].reshape(4, 4)
    ndc = clip[:, :3] / clip[:, 3:]
    np.testing.assert_allclose((ndc[:, 0] + 1) / 2 * W, u, atol=1e-6)
    np.testing.assert_allclose((1 - ndc[:, 1]) / 2 * H, v, atol=1e-6)
    assert np.all((ndc[:, 2] > 0) & (ndc[:, 2] < 1))
    row = loose.get_data()["data"][0]
    x0, x1 = _pixel_extent(u.min(), u.max())
    y0, y1 = _pixel_extent(v.min(), v.max())
    assert abs(row["x_min"] - x0) <= 1 and abs(row["x_max"] - x1) <= 1
    assert abs(row["y_min"] - y0) <= 1 and abs(row["y_max"] - y1) <= 1


# ---- normals and motion -------------------------------------------------------
def test_normals_of_cube_faces_and_sphere():
    cam, rp = _scene(camera_position=(3.0, -4.0, 2.0))
    rep.functional.create.cube(parent="/World", name="Cube", semantics={"class": "cube"})
    rep.functional.create.sphere(position=(0.0, 1.5, 1.2), scale=0.8, parent="/World", name="Ball",
                                 semantics={"class": "ball"})
    rep.functional.create.disk(position=(-1.2, 0.5, -0.3), rotation=(0.0, 30.0, 0.0), parent="/World",
                               name="Disk", semantics={"class": "disk"})   # a triangle mesh
    normals, depth, inst = _attach(rp, "normals", "distance_to_image_plane", "instance_segmentation")
    rep.orchestrator.step()
    n = normals.get_data()
    assert n.dtype == np.float32 and n.shape == (H, W, 4)
    ids = inst.get_data()
    by_path = {v: int(k) for k, v in ids["info"]["idToLabels"].items()}
    view = camera_view(cam, W, H)
    points = view.unproject(depth.get_data())
    cube = ids["data"] == by_path["/World/Cube"]
    faces = {(1, 0, 0): 0, (0, -1, 0): 1, (0, 0, 1): 2}
    for normal, axis in faces.items():
        on_face = cube & np.all(np.abs(n[..., :3] - normal) < 1e-5, axis=-1)
        assert on_face.sum() > 50, normal
        # the pixels reporting a face normal lie on that face
        assert np.allclose(points[on_face][:, axis], 0.5 * sum(normal), atol=1e-3)
    assert np.all(np.abs(np.linalg.norm(n[cube][:, :3], axis=1) - 1) < 1e-5)
    assert (n[..., 3][cube] == 1).all() and (n[ids["data"] == 0] == 0).all()
    ball = ids["data"] == by_path["/World/Ball"]
    radial = points[ball] - np.array([0.0, 1.5, 1.2])
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    assert np.median(np.einsum("ij,ij->i", radial, n[ball][:, :3])) > 0.9999
    disk = ids["data"] == by_path["/World/Disk"]
    assert disk.sum() > 30
    np.testing.assert_allclose(n[disk][:, :3], np.tile(euler_to_matrix((0.0, 30.0, 0.0))[:, 2], (disk.sum(), 1)),
                               atol=1e-5)


def test_motion_vectors_of_translated_cube_and_camera():
    cam, rp = _scene(camera_position=(0.0, -4.0, 0.0))
    cube = rep.functional.create.cube(parent="/World", name="Cube", semantics={"class": "cube"})
    motion, normals = _attach(rp, "motion_vectors", "normals")
    rep.orchestrator.step()
    assert np.all(motion.get_data() == 0)        # the first capture has no previous one
    dx, dz = 0.25, -0.1
    rep.functional.modify.position(cube, (dx, 0.0, dz))
    rep.orchestrator.step()
    mv = motion.get_data()
    assert mv.dtype == np.float32 and mv.shape == (H, W, 4)
    view = camera_view(cam, W, H)
    front = np.all(np.abs(normals.get_data()[..., :3] - (0, -1, 0)) < 1e-5, axis=-1)
    assert front.sum() > 200
    # front face at depth 3.5: the projected displacement is (fx dx / 3.5, -fy dz / 3.5) pixels;
    # Replicator's sign: previous minus current position
    np.testing.assert_allclose(mv[front][:, 0], -view.fx * dx / 3.5, atol=1.0)
    np.testing.assert_allclose(mv[front][:, 1], view.fy * dz / 3.5, atol=1.0)
    assert np.all(mv[front][:, 2:] == 0)
    background = normals.get_data()[..., 3] == 0
    np.testing.assert_allclose(mv[background], 0.0, atol=1e-6)    # static camera: the sky does not move
    # now the camera moves and the cube stays: the cube moves the other way in the image
    rep.functional.modify.position(cam, (dx, -4.0, 0.0))
    rep.orchestrator.step()
    mv = motion.get_data()
    front = np.all(np.abs(normals.get_data()[..., :3] - (0, -1, 0)) < 1e-5, axis=-1)
    np.testing.assert_allclose(mv[front][:, 0], view.fx * dx / 3.5, atol=1.0)
    background = normals.get_data()[..., 3] == 0
    np.testing.assert_allclose(mv[background][:, :2], 0.0, atol=1e-6)   # translation leaves infinity still


# ---- consistency ------------------------------------------------------------
def test_ids_images_and_box_rows_agree_in_every_frame():
    cam, rp = _scene(camera_position=(4.0, -4.0, 4.0))
    cubes = rep.functional.create_batch.cube(count=5, parent="/World", semantics={"class": "cube"}, scale=0.5)
    rep.functional.create.sphere(position=(0, 0, -1.5), parent="/World", name="Floorball")   # unlabelled
    names = ["semantic_segmentation", "instance_segmentation", "bounding_box_2d_tight", "bounding_box_2d_loose",
             "bounding_box_3d", "occlusion", "pointcloud"]
    anns = dict(zip(names, _attach(rp, *names)))
    rng = np.random.default_rng(4)
    for _ in range(4):
        rep.functional.modify.pose(cubes, position_value=rng.uniform(-1, 1, (5, 3)))
        rep.orchestrator.step()
        sem = anns["semantic_segmentation"].get_data()
        inst = anns["instance_segmentation"].get_data()
        tight = anns["bounding_box_2d_tight"].get_data()
        loose = anns["bounding_box_2d_loose"].get_data()
        box3d = anns["bounding_box_3d"].get_data()
        occ = anns["occlusion"].get_data()
        cloud = anns["pointcloud"].get_data()
        for r, bbox_id, path in zip(tight["data"], tight["info"]["bboxIds"], tight["info"]["primPaths"]):
            mask = inst["data"] == bbox_id
            ys, xs = np.nonzero(mask)
            assert (xs.min(), ys.min(), xs.max(), ys.max()) == (r["x_min"], r["y_min"], r["x_max"], r["y_max"])
            assert inst["info"]["idToLabels"][str(bbox_id)] == path
            assert np.all(sem["data"][mask] == r["semanticId"])
            assert sem["info"]["idToLabels"][str(r["semanticId"])] == tight["info"]["idToLabels"][str(r["semanticId"])]
        loose_rows = dict(zip(loose["info"]["bboxIds"].tolist(), loose["data"]))
        for r, bbox_id in zip(tight["data"], tight["info"]["bboxIds"].tolist()):
            lr = loose_rows[bbox_id]
            assert lr["x_min"] <= r["x_min"] and lr["y_min"] <= r["y_min"]
            assert lr["x_max"] >= r["x_max"] and lr["y_max"] >= r["y_max"]
            assert lr["occlusionRatio"] == r["occlusionRatio"] and lr["semanticId"] == r["semanticId"]
        assert loose["info"]["bboxIds"].tolist() == occ["instanceId"].tolist()
        assert loose["info"]["primPaths"] == box3d["info"]["primPaths"]
        assert np.array_equal(occ["occlusionRatio"], box3d["data"]["occlusionRatio"])
        labelled = inst["data"] > 1
        assert len(cloud["data"]) == labelled.sum()
        assert np.array_equal(cloud["info"]["pointInstance"], inst["data"][labelled])
        assert np.array_equal(cloud["info"]["pointSemantic"], sem["data"][labelled])


def test_isolated_render_crop_matches_the_full_render():
    cam, rp = _scene(camera_position=(3.0, -4.0, 2.0))
    rep.functional.create.cube(parent="/World", name="Cube")
    rep.functional.create.sphere(position=(0.8, -0.8, 0.3), parent="/World", name="Ball")
    _attach(rp, "instance_id_segmentation")
    rep.orchestrator.step()
    rt = runtime()
    view = camera_view(cam, W, H)
    out = rt.rasterizer.render(rt.render_scene, view, {"segmentation"})
    every = np.arange(rt.sim.model.ngeom)
    assert np.array_equal(out.render_isolated(every, (0, 0, W, H)), out.geom_ids)
    assert np.array_equal(out.render_isolated(every, (30, 20, 90, 70)), out.geom_ids[20:70, 30:90])
    alone = out.render_isolated([0], (0, 0, W, H))
    assert set(np.unique(alone)) == {-1, 0} and (alone == 0).sum() >= (out.geom_ids == 0).sum()


# ---- semantics ----------------------------------------------------------------
def _labelled_scene():
    cam, rp = _scene(camera_position=(0.0, -6.0, 1.0))
    car = rep.functional.create.xform(name="Car", parent="/World", semantics={"class": "vehicle"})
    rep.functional.create.cube(position=(-1.5, 0, 0), parent=car, name="Body",
                               semantics=[("class", "car"), ("color", "red")])
    rep.functional.create.sphere(position=(0, 0, 0), parent="/World", name="Person",
                                 semantics={"class": "pedestrian"})
    rep.functional.create.cone(position=(1.5, 0, 0), parent="/World", name="Cone", semantics={"shape": "cone"})
    return cam, rp


@pytest.mark.parametrize("params,expected", [
    (None, {"/World/Car/Body": {"class": "vehicle,car", "color": "red"},
            "/World/Person": {"class": "pedestrian"}, "/World/Cone": {"shape": "cone"}}),
    ({"semanticTypes": ["class"]}, {"/World/Car/Body": {"class": "vehicle,car"},
                                    "/World/Person": {"class": "pedestrian"}}),
    ({"semanticFilter": "class:car|pedestrian"}, {"/World/Car/Body": {"class": "car"},
                                                  "/World/Person": {"class": "pedestrian"}}),
    ({"semanticFilter": "*:cone|red"}, {"/World/Car/Body": {"color": "red"}, "/World/Cone": {"shape": "cone"}}),
    ({"semanticFilter": "class:* & !pedestrian"}, {"/World/Car/Body": {"class": "vehicle,car"}}),
    ({"semanticFilter": "class:car, color:red; shape:cone"},
     {"/World/Car/Body": {"class": "car", "color": "red"}, "/World/Cone": {"shape": "cone"}}),
    ({"semanticFilter": "class:vehicle"}, {"/World/Car": {"class": "vehicle"}}),
])
def test_semantic_filters_and_inherited_labels(params, expected):
    cam, rp = _labelled_scene()
    box = rep.annotators.get("bounding_box_2d_tight", init_params=params).attach(rp)
    seg = rep.annotators.get("semantic_segmentation", init_params=params).attach(rp)
    rep.orchestrator.step()
    d = box.get_data()
    got = {p: d["info"]["idToLabels"][str(r["semanticId"])] for p, r in zip(d["info"]["primPaths"], d["data"])}
    assert got == expected
    labels = seg.get_data()["info"]
    assert labels["idToLabels"]["0"] == {"class": "BACKGROUND"}
    for r in d["data"]:
        assert labels["idToLabels"][str(r["semanticId"])] == d["info"]["idToLabels"][str(r["semanticId"])]
    if params is None:   # graphsdg's own output keeps several labels of a type as a list
        lists = {p: d["info"]["idToLabelLists"][str(r["semanticId"])] for p, r in zip(d["info"]["primPaths"],
                                                                                         d["data"])}
        assert lists["/World/Car/Body"] == {"class": ["vehicle", "car"], "color": ["red"]}


# ---- colour -------------------------------------------------------------------
def test_ldr_and_hdr_colour():
    cam, rp = _scene(camera_position=(3.0, -4.0, 2.0))
    rep.functional.create.cube(parent="/World", name="Cube")
    ldr, hdr, rgb = _attach(rp, "LdrColor", "HdrColor", "rgb")
    rep.orchestrator.step()
    assert ldr.get_data().dtype == np.uint8 and ldr.get_data().shape == (H, W, 4)
    assert np.array_equal(ldr.get_data(), rgb.get_data())
    h = hdr.get_data()
    assert h.dtype == np.float16 and h.shape == (H, W, 4) and np.all(h[..., 3] == 1)
    np.testing.assert_allclose(h[..., :3].astype(np.float32), rgb.get_data()[..., :3] / 255.0, atol=1e-3)
    rep.orchestrator.step(rt_subframes=4)
    h = hdr.get_data()[..., :3].astype(np.float32) * 255
    # linear and not rounded to 8 bits: within half a level of the 8-bit image, and not on its grid
    assert np.abs(h - rgb.get_data()[..., :3]).max() <= 0.5 + 0.2
    assert np.abs(h - np.round(h)).max() > 0.1


# ---- several render products, only what is needed ------------------------------
def test_render_products_of_different_resolutions_in_one_step():
    cam, rp_small = _scene(camera_position=(3.0, -4.0, 2.0), resolution=(64, 48))
    rp_big = rep.create.render_product(cam, (128, 96))
    rep.functional.create.cube(parent="/World", name="Cube", semantics={"class": "cube"})
    box = rep.annotators.get("bounding_box_2d_loose").attach([rp_small, rp_big])
    depth = rep.annotators.get("distance_to_image_plane").attach([rp_small, rp_big])
    rep.orchestrator.step()
    boxes = box.get_data()
    small, big = boxes[rp_small.name]["data"][0], boxes[rp_big.name]["data"][0]
    for key in ("x_min", "y_min"):
        assert abs(2 * small[key] + 0.5 - big[key]) <= 1.5
    for key in ("x_max", "y_max"):
        assert abs(2 * small[key] + 1.5 - big[key]) <= 1.5
    d = depth.get_data()
    assert d[rp_small.name].shape == (48, 64) and d[rp_big.name].shape == (96, 128)
    center = (d[rp_small.name][24, 32], d[rp_big.name][48, 64])
    assert np.isfinite(center[0]) and abs(center[0] - center[1]) < 0.05


@pytest.mark.parametrize("names,drawn", [
    (["camera_params"], {}),
    (["rgb"], {"color": 1}),
    (["distance_to_image_plane"], {"ids": 1}),
    (["rgb", "semantic_segmentation", "distance_to_camera"], {"color": 1, "ids": 1}),
    (["bounding_box_2d_loose"], {"ids": 1, "isolated": (1, 2)}),   # one per overlap group of the 2 in view
])
def test_only_the_passes_something_attached_needs_are_rendered(names, drawn):
    cam, rp = _scene(camera_position=(3.0, -4.0, 2.0))
    rep.functional.create.cube(parent="/World", name="Cube", semantics={"class": "cube"})
    rep.functional.create.cube(position=(0, 0, 10), parent="/World", name="OutOfView", semantics={"class": "c"})
    rep.functional.create.sphere(position=(1, 1, 0), parent="/World", name="Ball", semantics={"class": "ball"})
    _attach(rp, *names)
    stats = runtime().rasterizer.stats
    stats.clear()
    rep.orchestrator.step()
    assert set(stats) == set(drawn)
    for kind, count in drawn.items():
        assert stats[kind] in (count if isinstance(count, tuple) else (count,)), (kind, stats[kind])


# ---- user annotators ------------------------------------------------------------
def test_user_annotators_from_function_and_aov_attach_to_writers():
    cam, rp = _scene(camera_position=(3.0, -4.0, 2.0))
    rep.functional.create.cube(parent="/World", name="Cube", semantics={"class": "cube"})

    def box_areas(bounding_box_2d_tight, scale=1.0):
        rows = bounding_box_2d_tight
        return scale * (rows["x_max"] - rows["x_min"] + 1) * (rows["y_max"] - rows["y_min"] + 1)

    rep.AnnotatorRegistry.register_annotator_from_function("box_areas", box_areas, inputs=["bounding_box_2d_tight"],
                                                           init_params={"scale": 1.0})
    name = rep.AnnotatorRegistry.register_annotator_from_aov("DepthLinearized", output_data_type=np.float64,
                                                             name="z_f64")
    assert name == "z_f64" and "box_areas" in rep.annotators.get_registered_annotators()
    seen = []

    class Probe(rep.Writer):
        def __init__(self):
            self.data_structure = "annotator"
            self.annotators = [rep.annotators.get("box_areas", init_params={"scale": 2.0}), "z_f64",
                               "bounding_box_2d_tight_fast", "distance_to_image_plane"]

        def write(self, data):
            seen.append(data["annotators"])

    rep.WriterRegistry.register(Probe)
    writer = rep.writers.get("Probe")
    writer.initialize()
    writer.attach(rp)
    rep.orchestrator.step()
    got = seen[0]
    rows = got["bounding_box_2d_tight_fast"][rp.name]["data"]
    expected = 2.0 * (rows["x_max"] - rows["x_min"] + 1) * (rows["y_max"] - rows["y_min"] + 1)
    assert np.array_equal(got["box_areas"][rp.name]["data"], expected)
    z = got["z_f64"][rp.name]["data"]
    assert z.dtype == np.float64 and np.array_equal(z, got["distance_to_image_plane"][rp.name]["data"])
    writer.detach()
    rep.AnnotatorRegistry.unregister("box_areas")
    rep.AnnotatorRegistry.unregister("z_f64")


def test_fast_aliases_and_replicator_names():
    for name in ("bounding_box_2d_tight_fast", "bounding_box_2d_loose_fast", "bounding_box_3d_fast",
                 "instance_segmentation_fast", "instance_id_segmentation_fast", "CameraParams", "MotionVectors",
                 "LdrColor", "HdrColor"):
        assert name in rep.annotators.get_registered_annotators()
        assert rep.annotators.get(name).spec is rep.AnnotatorRegistry.resolve(name)


# ---- bad input ------------------------------------------------------------------
def test_bad_annotator_input_errors():
    with pytest.raises(UnknownNameError, match=r"'normal'.*did you mean 'normals'.*known annotators: .*occlusion"):
        rep.annotators.get("normal")
    with pytest.raises(ValueError, match=r"'bounding_box_2d_tight' has no init param\(s\) \['colourize'\]"):
        rep.annotators.get("bounding_box_2d_tight", init_params={"colourize": True})
    with pytest.raises(ValueError, match="semanticTypes or semanticFilter, not both"):
        rep.annotators.get("semantic_segmentation", init_params={"semanticTypes": ["class"],
                                                                 "semanticFilter": "class:*"})
    with pytest.raises(ValueError, match=r"semanticFilter 'class car' does not parse.*':' after"):
        rep.annotators.get("bounding_box_2d_tight", init_params={"semanticFilter": "class car"})
    with pytest.raises(ValueError, match=r"'class:car\|' does not parse: expected a label"):
        rep.writers.get("BasicWriter").initialize(output_dir="/tmp/never", rgb=True,
                                                  semantic_filter_predicate="class:car|")
    with pytest.raises(UnknownNameError, match="unknown AOV 'Depth'.*DepthLinearized"):
        rep.AnnotatorRegistry.register_annotator_from_aov("Depth")
    cam, rp = _scene()
    rp.destroy()
    with pytest.raises(RenderProductDestroyedError, match=rp.name):
        rep.annotators.get("rgb").attach(rp)
    with pytest.raises(RenderProductDestroyedError, match=rp.path):
        rep.annotators.get("rgb").attach(rp.path)


def test_aperture_offset_shifts_the_image_as_usd_does():
    cam, rp = _scene(camera_position=(0.0, -4.0, 0.0), horizontal_aperture_offset=3.0, vertical_aperture_offset=-2.0)
    rep.functional.create.cube(parent="/World", name="Cube", semantics={"class": "cube"})
    (box,) = _attach(rp, "bounding_box_2d_tight")
    rep.orchestrator.step()
    # Gf.Camera's projection of the cube's front-face corners, independently of graphsdg
    g = UsdGeom.Camera(cam).GetCamera(0)
    g.verticalAperture = g.horizontalAperture * H / W
    proj = g.frustum.ComputeProjectionMatrix()
    view_m = g.frustum.ComputeViewMatrix()
    us, vs = [], []
    for x in (-0.5, 0.5):
        for z in (-0.5, 0.5):
            p = Gf.Vec4d(x, -0.5, z, 1.0) * view_m * proj
            us.append((p[0] / p[3] + 1) / 2 * W)
            vs.append((1 - p[1] / p[3]) / 2 * H)
    row = box.get_data()["data"][0]
    x0, x1 = _pixel_extent(min(us), max(us))
    y0, y1 = _pixel_extent(min(vs), max(vs))
    assert abs(row["x_min"] - x0) <= 1 and abs(row["x_max"] - x1) <= 1
    assert abs(row["y_min"] - y0) <= 1 and abs(row["y_max"] - y1) <= 1
    assert row["x_min"] < W / 2 - 30 and row["y_min"] < H / 2 - 30     # a +x offset moves it left, a -y one up


# ---- skeletons ------------------------------------------------------------------
def _skeleton_scene():
    from pxr import Sdf, UsdSkel, Vt
    cam, rp = _scene(camera_position=(0.0, -6.0, 0.7), look_at=(0.0, 0.0, 0.7))
    stage = rep.stage.get_stage()
    root = UsdSkel.Root.Define(stage, "/World/Char")
    UsdGeom.Xformable(root).AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, 0.2))
    skel = UsdSkel.Skeleton.Define(stage, "/World/Char/Skel")
    joints = ["root", "root/mid", "root/mid/tip"]
    rest = Vt.Matrix4dArray([Gf.Matrix4d(1).SetTranslate(Gf.Vec3d(0, 0, z)) for z in (0.0, 0.5, 0.5)])
    skel.CreateJointsAttr(joints)
    skel.CreateRestTransformsAttr(rest)
    skel.CreateBindTransformsAttr(Vt.Matrix4dArray([Gf.Matrix4d(1).SetTranslate(Gf.Vec3d(0, 0, z))
                                                    for z in (0.0, 0.5, 1.0)]))
    anim = UsdSkel.Animation.Define(stage, "/World/Char/Skel/Anim")
    anim.CreateJointsAttr(joints)
    anim.CreateTranslationsAttr(Vt.Vec3fArray([(0, 0, 0), (0, 0, 0.5), (0, 0, 0.5)]))
    half = np.sqrt(0.5)
    anim.CreateRotationsAttr(Vt.QuatfArray([Gf.Quatf(1, 0, 0, 0), Gf.Quatf(half, 0, half, 0), Gf.Quatf(1, 0, 0, 0)]))
    anim.CreateScalesAttr(Vt.Vec3hArray([(1, 1, 1)] * 3))
    UsdSkel.BindingAPI.Apply(skel.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])
    # a body mesh (drawn unskinned, at its authored points) around the root and mid joints
    body = UsdGeom.Mesh.Define(stage, "/World/Char/Body")
    pts = cube_corners((0.0, 0.0, 0.35), 0.4)
    body.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(*p) for p in pts]))
    faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    body.CreateFaceVertexCountsAttr([4] * 6)
    body.CreateFaceVertexIndicesAttr([i for f in faces for i in f])
    binding = UsdSkel.BindingAPI.Apply(body.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skel.GetPath()])
    binding.CreateJointIndicesPrimvar(True, 1).Set([0])
    binding.CreateJointWeightsPrimvar(True, 1).Set([1.0])
    binding.CreateGeomBindTransformAttr(Gf.Matrix4d(1))
    assert Sdf.Path("/World/Char/Skel").IsAbsolutePath()
    return cam, rp


def test_skeleton_data_from_usdskel(out_dir):
    import json
    import os
    cam, rp = _skeleton_scene()
    (ann,) = _attach(rp, "skeleton_data")
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, skeleton_data=True)
    writer.attach(rp)
    rep.orchestrator.step()
    d = ann.get_data()
    assert d["numSkeletons"] == 1 and d["skelPath"] == ["/World/Char/Skel"] and d["skelName"] == ["Skel"]
    assert d["skeletonJoints"] == ["root", "root/mid", "root/mid/tip"]
    assert d["skeletonParents"].tolist() == [-1, 0, 1] and d["skeletonParentsSizes"].tolist() == [3]
    np.testing.assert_allclose(d["restGlobalTranslations"], [[0, 0, 0.2], [0, 0, 0.7], [0, 0, 1.2]], atol=1e-6)
    np.testing.assert_allclose(d["restLocalTranslations"], [[0, 0, 0], [0, 0, 0.5], [0, 0, 0.5]], atol=1e-6)
    # the animation turns the mid joint 90 degrees about y: the tip swings to +x
    np.testing.assert_allclose(d["globalTranslations"], [[0, 0, 0.2], [0, 0, 0.7], [0.5, 0, 0.7]], atol=1e-5)
    np.testing.assert_allclose(d["localRotations"][1], [np.sqrt(0.5), 0, np.sqrt(0.5), 0], atol=1e-6)
    uv, _ = camera_view(cam, W, H).project(d["globalTranslations"].astype(np.float64))
    np.testing.assert_allclose(d["translations2d"], uv, atol=1e-3)
    # root and mid project onto the body mesh (visible); the tip is beside it (background)
    assert d["jointOcclusions"].tolist() == [False, False, True]
    assert d["occlusionTypes"] == [str(["None", "None", "BACKGROUND"])]
    assert d["inView"].tolist() == [True]
    rep.orchestrator.wait_until_complete()
    saved = json.load(open(os.path.join(out_dir, "skeleton_0000.json")))
    entry = saved["skeleton_0"]
    assert entry["skel_path"] == "/World/Char/Skel" and entry["skeleton_parents"] == [-1, 0, 1]
    assert entry["joint_occlusions"] == [False, False, True] and entry["in_view"] is True
    assert len(entry["translations_2d"]) == 3 and entry["skeleton_joints"][2] == "root/mid/tip"


# ---- BasicWriter -----------------------------------------------------------------
def test_basic_writer_writes_every_flag(out_dir):
    import json
    import os
    from PIL import Image
    cam, rp = _scene(camera_position=(3.0, -4.0, 2.0))
    rep.functional.create.cube(parent="/World", name="Cube", semantics={"class": "cube"})
    rep.functional.create.sphere(position=(0, 0, 1.2), scale=0.6, parent="/World", name="Ball",
                                 semantics=[("class", "ball"), ("color", "red")])
    flags = ["rgb", "bounding_box_2d_tight", "bounding_box_2d_loose", "semantic_segmentation",
             "instance_id_segmentation", "instance_segmentation", "distance_to_camera", "distance_to_image_plane",
             "bounding_box_3d", "occlusion", "normals", "motion_vectors", "camera_params", "pointcloud",
             "skeleton_data"]
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, colorize_depth=True, **{f: True for f in flags})
    writer.attach(rp)
    for _ in range(2):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    stems = {"rgb": ["png"], "normals": ["png"], "distance_to_camera": ["npy", "png"],
             "distance_to_image_plane": ["npy", "png"], "semantic_segmentation": ["png"],
             "semantic_segmentation_labels": ["json"], "instance_id_segmentation": ["png"],
             "instance_id_segmentation_mapping": ["json"], "instance_segmentation": ["png"],
             "instance_segmentation_mapping": ["json"], "instance_segmentation_semantics_mapping": ["json"],
             "motion_vectors": ["npy"], "occlusion": ["npy"], "camera_params": ["json"], "pointcloud": ["npy"],
             "pointcloud_rgb": ["npy"], "pointcloud_normals": ["npy"], "pointcloud_semantic": ["npy"],
             "pointcloud_instance": ["npy"], "skeleton": ["json"]}
    for box in ("2d_tight", "2d_loose", "3d"):
        stems[f"bounding_box_{box}"] = ["npy"]
        stems[f"bounding_box_{box}_labels"] = ["json"]
        stems[f"bounding_box_{box}_prim_paths"] = ["json"]
    expected = sorted([f"{stem}_{n:04d}.{ext}" for n in range(2) for stem, exts in stems.items() for ext in exts]
                      + ["metadata.txt"])
    assert sorted(os.listdir(out_dir)) == expected

    def load(name):
        path = os.path.join(out_dir, name)
        return json.load(open(path)) if name.endswith(".json") else (
            np.load(path) if name.endswith(".npy") else np.array(Image.open(path)))

    # the default filter is "class:*": the ball's colour label is not exported
    labels = load("bounding_box_3d_labels_0001.json")
    assert sorted(v["class"] for v in labels.values()) == ["ball", "cube"] and all(len(v) == 1 for v in labels.values())
    assert load("bounding_box_3d_0001.npy").dtype == BBOX_3D_DTYPE
    assert load("occlusion_0001.npy").dtype == OCCLUSION_DTYPE
    assert load("motion_vectors_0001.npy").shape == (H, W, 4)
    assert load("normals_0001.png").shape == (H, W, 4)
    points = load("pointcloud_0001.npy")
    assert points.dtype == np.float32 and points.shape[1] == 3
    n = len(points)
    assert load("pointcloud_rgb_0001.npy").shape == (n, 4) and load("pointcloud_normals_0001.npy").shape == (n, 4)
    assert load("pointcloud_semantic_0001.npy").shape == (n,) and load("pointcloud_instance_0001.npy").shape == (n,)
    params = load("camera_params_0001.json")
    assert params["renderProductResolution"] == [W, H] and len(params["cameraViewTransform"]) == 16
    assert load("skeleton_0001.json") == {}
    assert load("distance_to_camera_0001.png").dtype == np.uint8
    # the class masks' rows are stored unfiltered (label images), the colour's and the colorized depth's Sub
    import zlib
    for stem, filter_type in (("semantic_segmentation", 0), ("instance_segmentation", 0),
                              ("instance_id_segmentation", 0), ("rgb", 1), ("distance_to_camera", 1)):
        png = open(os.path.join(out_dir, f"{stem}_0001.png"), "rb").read()
        start = png.index(b"IDAT") + 4
        lines = zlib.decompress(png[start:start + int.from_bytes(png[start - 8:start - 4], "big")])
        row = len(lines) // H
        assert set(lines[::row]) == {filter_type}, stem


def test_orthographic_camera_boxes_depth_and_normals():
    cam, rp = _scene(camera_position=(0.0, -5.0, 0.0), projection_type="orthographic", horizontal_aperture=40.0)
    rep.functional.create.cube(position=(0.3, 0.0, 0.2), parent="/World", name="Cube", semantics={"class": "c"})
    box, depth, normals = _attach(rp, "bounding_box_2d_loose", "distance_to_image_plane", "normals")
    rep.orchestrator.step()
    # USD: an orthographic aperture is in tenths of a stage unit, so the image is 4 units wide
    px = W / 4.0
    row = box.get_data()["data"][0]
    assert (row["x_min"], row["x_max"]) == _pixel_extent(W / 2 + (0.3 - 0.5) * px, W / 2 + (0.3 + 0.5) * px)
    assert (row["y_min"], row["y_max"]) == _pixel_extent(H / 2 - (0.2 + 0.5) * px, H / 2 - (0.2 - 0.5) * px)
    z = depth.get_data()
    np.testing.assert_allclose(z[np.isfinite(z)], 4.5, rtol=1e-5)
    n = normals.get_data()
    assert np.all(n[np.isfinite(z)][:, :3] == (0, -1, 0))


def test_motion_vectors_of_a_turning_camera():
    cam, rp = _scene(camera_position=(0.0, 0.0, 0.0), look_at=(0.0, 1.0, 0.0))
    rep.functional.create.cube(position=(0.0, -5.0, 0.0), parent="/World", name="Behind")
    (motion,) = _attach(rp, "motion_vectors")
    rep.orchestrator.step()
    theta = np.radians(4.0)
    rep.functional.modify.pose(cam, position_value=(0.0, 0.0, 0.0), look_at_value=(np.sin(theta), np.cos(theta), 0.0))
    rep.orchestrator.step()
    mv = motion.get_data()
    view = camera_view(cam, W, H)
    row = H // 2
    u = np.arange(W) + 0.5
    # the camera turned right by theta: what pixel u shows now was seen theta further right before
    before = view.cx + view.fx * np.tan(np.arctan((u - view.cx) / view.fx) + theta)
    np.testing.assert_allclose(mv[row, :, 0], before - u, atol=0.05 * (1 + abs(row + 0.5 - view.cy)))
    assert mv[row, W // 2, 0] > 0.9 * view.fx * np.tan(theta)


def test_instances_that_cannot_overlap_share_an_isolated_render():
    cam, rp = _scene(camera_position=(0.0, -8.0, 0.0))
    for i, x in enumerate((-2.4, -0.8, 0.8, 2.4)):
        rep.functional.create.cube(position=(x, 0.0, 0.0), scale=0.4, parent="/World", name=f"C{i}",
                                   semantics={"class": "c"})
    rep.functional.create.cube(position=(0.8, -2.0, 0.0), scale=0.3, parent="/World", name="Front",
                               semantics={"class": "front"})   # in front of C2
    loose, occ = _attach(rp, "bounding_box_2d_loose", "occlusion")
    stats = runtime().rasterizer.stats
    stats.clear()
    rep.orchestrator.step()
    assert stats["isolated"] == 2          # the four separate cubes in one render, the front one alone
    ratios = dict(zip(loose.get_data()["info"]["primPaths"], loose.get_data()["data"]["occlusionRatio"]))
    assert ratios["/World/C2"] > 0.2 and ratios["/World/Front"] == 0
    assert all(ratios[f"/World/C{i}"] == 0 for i in (0, 1, 3))


def test_bounding_box_3d_360_lists_drawn_instances_outside_the_view():
    cam, rp = _scene(camera_position=(0.0, -5.0, 0.0))
    rep.functional.create.cube(parent="/World", name="Seen", semantics={"class": "c"})
    rep.functional.create.cube(position=(0.0, -10.0, 0.0), parent="/World", name="Behind", semantics={"class": "c"})
    rep.functional.create.cube(position=(2.0, 0.0, 0.0), parent="/World", name="Hidden", semantics={"class": "c"},
                               visible=False)
    in_view, all_round = _attach(rp, "bounding_box_3d", "bounding_box_3d_360")
    rep.orchestrator.step()
    assert in_view.get_data()["info"]["primPaths"] == ["/World/Seen"]
    d = all_round.get_data()
    rows = dict(zip(d["info"]["primPaths"], d["data"]))
    assert sorted(rows) == ["/World/Behind", "/World/Seen"]
    assert np.isnan(rows["/World/Behind"]["occlusionRatio"]) and rows["/World/Seen"]["occlusionRatio"] == 0
    np.testing.assert_allclose(rows["/World/Behind"]["transform"][3], [0, -10, 0, 1])


def test_tight_box_occlusion_is_filled_only_when_paid_for():
    from conftest import unit_cube_scene
    cube, cam, rp = unit_cube_scene(camera_position=(0, -4, 0), resolution=(64, 48))
    tight = rep.annotators.get("bounding_box_2d_tight")
    tight.attach(rp)
    rep.orchestrator.step()
    assert tight.get_data()["data"][0]["occlusionRatio"] == -1.0      # not computed: no isolated renders
    occ = rep.annotators.get("occlusion")
    occ.attach(rp)
    rep.orchestrator.step()
    assert tight.get_data()["data"][0]["occlusionRatio"] == pytest.approx(0.0, abs=0.01)


def _code_bounds(codes: np.ndarray, rows: int, shift: int = 0) -> np.ndarray:
    """(rows, 4) x_min, y_min, x_max, y_max of each code's pixels (x moved by ``shift``), -1 rows for absent codes."""
    bounds = np.full((rows, 4), -1, dtype=np.int32)
    for code in np.unique(codes):
        ys, xs = np.nonzero(codes == code)
        bounds[code] = xs.min() + shift, ys.min(), xs.max() + shift, ys.max()
    return bounds


def test_tight_boxes_and_label_tables_read_a_backends_code_bounds_when_it_makes_them(monkeypatch):
    """A backend that makes each id code's pixel bounds (pbr, on its device) hands them with the codes: the tight
    boxes and the segmentation's drawn-label table come from them, equal to what the pixels give."""
    _, rp = _scene(camera_position=(0.0, -5.0, 1.0))
    rep.functional.create.cube(position=(-1.2, 0, 0), scale=0.8, semantics={"class": "box"})
    rep.functional.create.sphere(position=(1.2, 0, 0), scale=0.7, semantics={"class": "ball"})
    rep.functional.create.cylinder(position=(0, 0, 1.2), scale=0.5, semantics={"class": "can"})
    boxes, seg = _attach(rp, "bounding_box_2d_tight", "semantic_segmentation")
    rep.orchestrator.step(delta_time=0)
    from_pixels, labels = boxes.get_data()["data"].copy(), seg.get_data()["info"]["idToLabels"]
    assert len(from_pixels) == 3

    rasterizer = runtime().rasterizer
    shift = {"x": 0}

    class WithCodeBounds:
        def render_batch(self, scene, requests):
            outs = rasterizer.render_batch(scene, requests)
            for out in outs:
                if out.id_lut is not None:
                    out.put("code_boxes", _code_bounds(out.id_codes, len(out.id_lut), shift["x"]))
            return outs

        def close(self):
            pass

    monkeypatch.setattr(type(runtime()), "renderer", property(lambda self: WithCodeBounds()))
    rep.orchestrator.step(delta_time=0)
    assert np.array_equal(boxes.get_data()["data"], from_pixels)
    assert seg.get_data()["info"]["idToLabels"] == labels
    shift["x"] = 1            # the boxes are the backend's: bounds it moves, the rows move with
    rep.orchestrator.step(delta_time=0)
    moved = boxes.get_data()["data"]
    assert np.array_equal(moved["x_min"], from_pixels["x_min"] + 1)
    assert np.array_equal(moved["x_max"], from_pixels["x_max"] + 1)


def test_tight_boxes_of_one_geom_instances_equal_the_union_of_their_geoms(monkeypatch):
    # one geom an instance (randomized assets): the boxes come straight from the geoms' boxes; they must be
    # what the general union of each instance's geoms gives
    from graphsdg.annotate.frame import InstanceMap
    rep.stage.new_stage()
    rep.functional.create.dome_light(intensity=500)
    rng = np.random.default_rng(3)
    for i in range(8):
        rep.functional.create.cube(position=tuple(rng.uniform(-1.5, 1.5, 3)), scale=0.4 + 0.2 * (i % 3),
                                   semantics={"class": f"c{i % 3}"})
    cam = rep.functional.create.camera(position=(6, 6, 5), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (96, 72))
    boxes = rep.annotators.get("bounding_box_2d_tight")
    boxes.attach(rp)
    rep.orchestrator.step()
    fast = boxes.get_data()
    original = InstanceMap.derived
    monkeypatch.setattr(InstanceMap, "derived",
                        lambda self, key, build: False if key == "one_geom_each" else original(self, key, build))
    rep.orchestrator.step(delta_time=0)
    general = boxes.get_data()
    assert len(fast["data"]) >= 4
    assert np.array_equal(fast["data"], general["data"])
    assert fast["info"]["primPaths"] == general["info"]["primPaths"]
