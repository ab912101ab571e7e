"""The walking skeleton: stage -> MuJoCo -> pixels -> labels -> files, checked against analytic truth."""
from __future__ import annotations

import json
import os

import numpy as np
import pytest
from PIL import Image
from pxr import Gf, UsdGeom, UsdSemantics

import graphsdg as rep
from graphsdg.errors import InvalidPrimError, PrimNotFoundError, RenderProductDestroyedError, UnknownNameError
from graphsdg.nodes.annotators import BBOX_2D_DTYPE

from conftest import cube_corners, project_box, unit_cube_scene

W, H = 128, 96


def _step_boxes(rp):
    ann = rep.annotators.get("bounding_box_2d_tight")
    ann.attach(rp)
    rep.orchestrator.step()
    return ann, ann.get_data()


@pytest.mark.parametrize("center,cam_pos", [((0, 0, 0), (5, 5, 5)), ((0.4, -0.3, 0.2), (3, -2, 1.5)),
                                             ((0, 0, 0), (0, -4, 0.0))])
def test_cube_box_matches_pinhole_projection(center, cam_pos):
    cube, cam, rp = unit_cube_scene(position=center, camera_position=cam_pos, resolution=(W, H))
    _, data = _step_boxes(rp)
    rows = data["data"]
    assert rows.dtype == BBOX_2D_DTYPE and len(rows) == 1
    lo, hi = project_box(cam, W, H, cube_corners(center))
    r = rows[0]
    # inclusive pixel bounds vs continuous projection: pixel i spans [i, i+1)
    assert abs(r["x_min"] - lo[0]) <= 2 and abs(r["y_min"] - lo[1]) <= 2
    assert abs(r["x_max"] + 1 - hi[0]) <= 2 and abs(r["y_max"] + 1 - hi[1]) <= 2
    assert data["info"]["primPaths"] == ["/World/Cube"]
    assert data["info"]["idToLabels"] == {str(r["semanticId"]): {"class": "cube"}}


def test_semantic_mask_covers_the_box_pixels():
    cube, cam, rp = unit_cube_scene(camera_position=(3, 4, 2), resolution=(W, H))
    box = rep.annotators.get("bounding_box_2d_tight")
    sem = rep.annotators.get("semantic_segmentation")
    box.attach(rp)
    sem.attach(rp)
    rep.orchestrator.step()
    ids = sem.get_data()["data"]
    row = box.get_data()["data"][0]
    mask = ids == row["semanticId"]
    ys, xs = np.nonzero(mask)
    assert (xs.min(), ys.min(), xs.max(), ys.max()) == (row["x_min"], row["y_min"], row["x_max"], row["y_max"])
    labels = sem.get_data()["info"]["idToLabels"]
    assert labels["0"] == {"class": "BACKGROUND"} and labels["1"] == {"class": "UNLABELLED"}
    assert labels[str(row["semanticId"])] == {"class": "cube"}
    assert set(np.unique(ids)) == {0, row["semanticId"]}


def test_depth_of_cube_face_is_exact():
    cube, cam, rp = unit_cube_scene(camera_position=(0, -4, 0), resolution=(W, H))
    depth = rep.annotators.get("distance_to_image_plane")
    depth.attach(rp)
    rep.orchestrator.step()
    d = depth.get_data()
    assert d.dtype == np.float32 and d.shape == (H, W)
    assert abs(d[H // 2, W // 2] - 3.5) < 1e-3     # front face at y = -0.5, camera at y = -4
    assert np.isinf(d[0, 0])                        # background


def _center_rgb(rgb_ann):
    img = rgb_ann.get_data()
    assert img.dtype == np.uint8 and img.shape == (H, W, 4) and (img[..., 3] == 255).all()
    return img[H // 2, W // 2, :3].astype(int)


def test_display_color_and_attribute_edits_show_in_rgb():
    cube, cam, rp = unit_cube_scene(camera_position=(0, -4, 1.0), resolution=(W, H))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rp)
    rep.functional.modify.display_color(cube, (1.0, 0.0, 0.0))
    rep.orchestrator.step()
    r, g, b = _center_rgb(rgb)
    assert r > 60 and g < 10 and b < 10
    rep.functional.modify.attribute(cube, "primvars:displayColor", [(0.0, 0.0, 1.0)])
    rep.orchestrator.step()
    r, g, b = _center_rgb(rgb)
    assert b > 60 and r < 10 and g < 10
    rep.functional.randomizer.display_color(cube, rng=rep.rng.ReplicatorRNG(seed=3))
    rep.orchestrator.step()
    expected = np.array(UsdGeom.Gprim(cube).GetDisplayColorAttr().Get()[0])
    got = _center_rgb(rgb) / 255.0
    # a lit face: colour channels keep the authored ratios
    assert np.allclose(got / got.max(), expected / expected.max(), atol=0.06)


def test_plain_pxr_edits_are_honoured():
    cube, cam, rp = unit_cube_scene(camera_position=(4, -4, 3), resolution=(W, H))
    ann, data = _step_boxes(rp)
    assert len(data["data"]) == 1
    UsdGeom.Imageable(cube).MakeInvisible()
    rep.orchestrator.step()
    assert len(ann.get_data()["data"]) == 0
    UsdGeom.Imageable(cube).MakeVisible()
    cube.GetAttribute("xformOp:translate").Set(Gf.Vec3d(0.0, 0.0, 0.5))   # pxr pose edit
    rep.orchestrator.step()
    lo, hi = project_box(cam, W, H, cube_corners((0, 0, 0.5)))
    row = ann.get_data()["data"][0]
    assert abs(row["y_min"] - lo[1]) <= 2 and abs(row["y_max"] + 1 - hi[1]) <= 2
    # semantics added with the plain UsdSemantics schema are picked up too
    sphere = rep.functional.create.sphere(position=(0, 0, -1.2), parent="/World", name="Ball")
    UsdSemantics.LabelsAPI.Apply(sphere, "class").CreateLabelsAttr(["ball"])
    rep.orchestrator.step()
    assert sorted(ann.get_data()["info"]["primPaths"]) == ["/World/Ball", "/World/Cube"]


def test_get_data_is_the_latest_step():
    cube, cam, rp = unit_cube_scene(camera_position=(0, -4, 0), resolution=(W, H))
    ann, first = _step_boxes(rp)
    rep.functional.modify.position(cube, (1.0, 0.0, 0.0))
    rep.orchestrator.step()
    second = ann.get_data()["data"][0]
    assert second["x_min"] > first["data"][0]["x_min"] + 10


def _capture(out_dir, seed=11, frames=3):
    rep.stage.new_stage()
    rep.set_global_seed(seed)
    rng = rep.rng.ReplicatorRNG(seed=seed)
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=500, parent="/World")
    cubes = rep.functional.create_batch.cube(count=4, parent="/World", semantics={"class": "cube"}, scale=0.4)
    cam = rep.functional.create.camera(position=(4, 4, 4), look_at=(0, 0, 0), parent="/World")
    rp = rep.create.render_product(cam, (W, H))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True)
    writer.attach(rp)
    for _ in range(frames):
        rep.functional.modify.pose(cubes, position_value=rng.generator.uniform(-1, 1, (4, 3)))
        rep.functional.randomizer.display_color(cubes, rng=rng)
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    rp.destroy()
    return {f: open(os.path.join(out_dir, f), "rb").read() for f in sorted(os.listdir(out_dir))}


def test_same_seed_same_bytes(tmp_path):
    a = _capture(str(tmp_path / "a"))
    b = _capture(str(tmp_path / "b"))
    assert a.keys() == b.keys() and len(a) == 3 * 6 + 1      # + metadata.txt
    assert all(a[k] == b[k] for k in a)
    c = _capture(str(tmp_path / "c"), seed=12)
    assert any(a[k] != c[k] for k in a if k.startswith("rgb"))


def test_basic_writer_files_match_replicator_layout(out_dir):
    cube, cam, rp = unit_cube_scene(camera_position=(3, -3, 2), resolution=(W, H))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True,
                      frame_padding=4)
    writer.attach(rp)
    for _ in range(2):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    names = sorted(os.listdir(out_dir))
    expected = sorted([f"{stem}_{n:04d}.{ext}" for n in range(2) for stem, ext in [
        ("rgb", "png"), ("bounding_box_2d_tight", "npy"), ("bounding_box_2d_tight_labels", "json"),
        ("bounding_box_2d_tight_prim_paths", "json"), ("semantic_segmentation", "png"),
        ("semantic_segmentation_labels", "json")]] + ["metadata.txt"])
    assert names == expected
    boxes = np.load(os.path.join(out_dir, "bounding_box_2d_tight_0000.npy"))
    assert boxes.dtype == BBOX_2D_DTYPE and len(boxes) == 1
    labels = json.load(open(os.path.join(out_dir, "bounding_box_2d_tight_labels_0000.json")))
    assert labels == {str(boxes[0]["semanticId"]): {"class": "cube"}}
    assert json.load(open(os.path.join(out_dir, "bounding_box_2d_tight_prim_paths_0000.json"))) == ["/World/Cube"]
    rgb = np.array(Image.open(os.path.join(out_dir, "rgb_0000.png")))
    assert rgb.shape == (H, W, 4) and rgb.dtype == np.uint8
    seg = np.array(Image.open(os.path.join(out_dir, "semantic_segmentation_0000.png")))
    assert seg.shape == (H, W, 4)
    seg_labels = json.load(open(os.path.join(out_dir, "semantic_segmentation_labels_0000.json")))
    assert seg_labels["(0, 0, 0, 0)"] == {"class": "BACKGROUND"}
    cube_colors = [k for k, v in seg_labels.items() if v == {"class": "cube"}]
    assert len(cube_colors) == 1
    color = tuple(int(c) for c in cube_colors[0].strip("()").split(","))
    cube_pixels = np.all(seg == color, axis=-1)
    b = boxes[0]
    ys, xs = np.nonzero(cube_pixels)
    assert (xs.min(), ys.min(), xs.max(), ys.max()) == (b["x_min"], b["y_min"], b["x_max"], b["y_max"])
    assert not any(n.endswith(".tmp") for n in os.listdir(out_dir))


def test_rt_subframes_smooth_edges():
    rep.settings.set("/graphsdg/render/msaaSamples", 0)    # isolate the accumulation from MSAA
    cube, cam, rp = unit_cube_scene(camera_position=(3, -4, 2), resolution=(W, H))
    rep.functional.modify.display_color(cube, (1.0, 1.0, 1.0))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rp)

    def grey(subframes):
        rep.orchestrator.step(rt_subframes=subframes)
        return rgb.get_data()[..., :3].astype(int).sum(-1)

    aliased, smooth = grey(1), grey(8)
    flat_levels = set(np.unique(aliased))
    assert len(flat_levels) <= 4                       # background + three flat faces, hard edges
    blended = ~np.isin(smooth, list(flat_levels))      # edge pixels mixing two levels
    assert blended.sum() > 60 and len(np.unique(smooth)) >= len(flat_levels) + 6
    # away from edges the image is unchanged
    assert (smooth == aliased).mean() > 0.9


def test_settings_accept_replicator_keys():
    with pytest.warns(UserWarning, match="no effect"):
        rep.settings.set("rtx/post/dlss/execMode", 2)
    assert rep.settings.get("/rtx/post/dlss/execMode") == 2
    rep.orchestrator.set_capture_on_play(False)
    assert rep.settings.get("/omni/replicator/captureOnPlay") is False
    rep.settings.set("/omni/replicator/RTSubframes", 4)   # honoured key: no warning
    assert rep.settings.get("omni/replicator/RTSubframes") == 4


def test_rng_generator_and_global_seed():
    a = rep.rng.ReplicatorRNG(seed=42).generator.uniform(size=3)
    b = rep.rng.ReplicatorRNG(seed=42).generator.uniform(size=3)
    assert isinstance(rep.rng.ReplicatorRNG(seed=1).generator, np.random.Generator)
    assert np.array_equal(a, b)
    rep.set_global_seed(5)
    c = rep.rng.ReplicatorRNG().generator.uniform()
    rep.set_global_seed(5)
    assert rep.rng.ReplicatorRNG().generator.uniform() == c
    with pytest.raises(ValueError, match="-1"):
        rep.set_global_seed(-1)


# ---- bad input ---------------------------------------------------------------
def test_unknown_prim_path_and_missing_parent():
    with pytest.raises(PrimNotFoundError, match="/World/Nope"):
        rep.functional.modify.position("/World/Nope", (0, 0, 0))
    with pytest.raises(PrimNotFoundError, match="/Missing"):
        rep.functional.create.cube(parent="/Missing")


def test_unknown_annotator_and_writer_names():
    with pytest.raises(UnknownNameError, match="'bounding_box_2d_tigth'.*did you mean 'bounding_box_2d_tight'"):
        rep.annotators.get("bounding_box_2d_tigth")
    with pytest.raises(UnknownNameError, match="BasicWritter.*BasicWriter"):
        rep.writers.get("BasicWritter")


def test_writer_attach_needs_render_products(out_dir):
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True)
    with pytest.raises(ValueError, match="at least one render product"):
        writer.attach([])
    with pytest.raises(ValueError, match="No `backend`, `output_dir`"):
        rep.writers.get("BasicWriter").initialize(rgb=True)
    with pytest.raises(ValueError, match="no annotator enabled"):
        rep.writers.get("BasicWriter").initialize(output_dir=out_dir)
    with pytest.raises(TypeError, match="rbg"):
        rep.writers.get("BasicWriter").initialize(output_dir=out_dir, rbg=True)


def test_render_product_validation():
    cube, cam, rp = unit_cube_scene()
    with pytest.raises(InvalidPrimError, match="/World/Cube.*not a UsdGeom.Camera"):
        rep.create.render_product(cube, (64, 64))
    for bad in [(0, 64), (64, -1), (64,), "64x64", (64.0, 64), None]:
        with pytest.raises(ValueError, match="two positive integers"):
            rep.create.render_product(cam, bad)
    with pytest.raises(ValueError, match="rt_subframes.*0"):
        rep.orchestrator.step(rt_subframes=0)


def test_step_after_destroy_raises():
    cube, cam, rp = unit_cube_scene()
    ann = rep.annotators.get("rgb")
    ann.attach(rp)
    rep.orchestrator.step()
    rp.destroy()
    with pytest.raises(RenderProductDestroyedError, match=rp.name):
        rep.orchestrator.step()
    ann.detach()
    rep.orchestrator.step()   # nothing attached any more: fine
    with pytest.raises(RenderProductDestroyedError):
        rep.annotators.get("rgb").attach(rp)


def test_hydra_texture_updates_disabled_skips_render():
    cube, cam, rp = unit_cube_scene()
    ann = rep.annotators.get("rgb")
    ann.attach(rp)
    rep.orchestrator.step()
    first = ann.get_data().copy()
    rp.hydra_texture.set_updates_enabled(False)
    rep.functional.modify.display_color(cube, (1, 0, 0))
    rep.orchestrator.step()
    assert np.array_equal(ann.get_data(), first)
    rp.hydra_texture.set_updates_enabled(True)
    rep.orchestrator.step()
    assert not np.array_equal(ann.get_data(), first)


def test_attribute_edits_sync_without_recompiling():
    from graphsdg.engine.runtime import runtime
    cube, cam, rp = unit_cube_scene(camera_position=(0, -4, 0), resolution=(W, H))
    ann, _ = _step_boxes(rp)
    sim = runtime().sim
    compiles = sim.stats["compiles"]
    rep.functional.modify.pose(cube, position_value=(0.5, 0, 0), scale_value=(0.5, 0.5, 0.5))
    rep.functional.modify.display_color(cube, (0.2, 0.9, 0.2))
    UsdGeom.Imageable(cube).MakeInvisible()
    rep.orchestrator.step()
    UsdGeom.Imageable(cube).MakeVisible()
    rep.orchestrator.step()
    assert sim.stats["compiles"] == compiles
    lo, hi = project_box(cam, W, H, cube_corners((0.5, 0, 0), half=0.25))
    row = ann.get_data()["data"][0]
    assert abs(row["x_min"] - lo[0]) <= 2 and abs(row["x_max"] + 1 - hi[0]) <= 2
    rep.functional.create.sphere(parent="/World")      # structural: one recompile, state kept
    rep.orchestrator.step()
    assert sim.stats["compiles"] == compiles + 1


@pytest.mark.parametrize("shape", ["cone", "torus"])
def test_mesh_rescale_is_live_and_exact(shape):
    """Rescaling a mesh prim twice neither recompiles nor re-uploads, and renders what a fresh compile renders."""
    from graphsdg.engine.runtime import runtime
    rep.functional.create.xform(name="World")
    rep.functional.create.distant_light(intensity=1500, parent="/World", rotation=(315, 0, 0))
    rep.functional.create.dome_light(intensity=600, parent="/World")
    prim = getattr(rep.functional.create, shape)(parent="/World", name="Shape", semantics={"class": shape},
                                                 rotation=(30, 10, 0))
    rep.functional.create.sphere(parent="/World", name="Ball", position=(1.2, 0, -0.6), scale=0.4,
                                  semantics={"class": "ball"})
    cam = rep.functional.create.camera(position=(0, -5, 0.5), look_at=(0, 0, 0), parent="/World")
    rp = rep.create.render_product(cam, (W, H))
    ann, _ = _step_boxes(rp)
    rgb = rep.annotators.get("rgb")
    rgb.attach(rp)
    sim = runtime().sim
    compiles = sim.stats["compiles"]
    rep.functional.modify.pose(prim, scale_value=(0.8, 0.8, 0.8))
    rep.orchestrator.step()
    runtime().render_scene.require_offscreen(2 * W, 2 * H)   # a new GL context: it uploads the rescaled mesh,
    # later maps are relative
    rep.orchestrator.step()
    rep.functional.modify.pose(prim, scale_value=(1.6, 0.7, 1.2), rotation_value=(0, 40, 20))
    rep.orchestrator.step()
    assert sim.stats["compiles"] == compiles and runtime().render_scene.mesh_maps   # drawn through the map
    live_boxes, live_rgb = ann.get_data()["data"], rgb.get_data()[..., :3].astype(int)
    sim.recompile()                        # the same scale compiled from scratch
    assert not runtime().render_scene.mesh_maps
    rep.orchestrator.step()
    fresh_boxes, fresh_rgb = ann.get_data()["data"], rgb.get_data()[..., :3].astype(int)
    assert len(live_boxes) == len(fresh_boxes) == 2          # the shape and the sphere
    for live, fresh in zip(live_boxes, fresh_boxes):
        assert all(abs(int(live[k]) - int(fresh[k])) <= 1 for k in ("x_min", "y_min", "x_max", "y_max"))
    diff = np.abs(live_rgb - fresh_rgb).max(axis=2)
    # Only silhouette pixels may differ (a multisample flips with float rounding); wrong normals or
    # a wrong scale would change the whole shaded surface.
    assert np.count_nonzero(diff > 2) <= 0.002 * diff.size and diff.mean() < 0.05


def test_write_to_fabric_matches_usd_authoring():
    """The direct MuJoCo write path renders exactly what authoring USD renders."""
    def capture(fabric):
        rep.stage.new_stage()
        rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", fabric)
        rep.functional.create.xform(name="World")
        rep.functional.create.dome_light(intensity=600, parent="/World")
        prims = [rep.functional.create.cube(parent="/World", semantics={"class": "a"}),
                 rep.functional.create.sphere(parent="/World", semantics={"class": "b"}),
                 rep.functional.create.torus(parent="/World", semantics={"class": "c"})]
        cam = rep.functional.create.camera(position=(5, -5, 4), look_at=(0, 0, 0), parent="/World")
        rp = rep.create.render_product(cam, (W, H))
        rgb, box = rep.annotators.get("rgb"), rep.annotators.get("bounding_box_2d_tight")
        rgb.attach(rp)
        box.attach(rp)
        rep.orchestrator.step()
        rng = np.random.default_rng(4)
        for _ in range(2):
            rep.functional.modify.pose(prims, position_value=rng.uniform(-1.5, 1.5, (3, 3)),
                                       rotation_value=rng.uniform(0, 360, (3, 3)),
                                       scale_value=rng.uniform(0.3, 1.0, (3, 1)).repeat(3, 1))
            rep.functional.modify.display_color(prims, rng.uniform(0, 1, (3, 3)))
            rep.orchestrator.step()
        authored = prims[0].GetAttribute("xformOp:translate").Get()
        return rgb.get_data().copy(), box.get_data()["data"].copy(), authored

    usd_rgb, usd_box, usd_t = capture(False)
    fab_rgb, fab_box, fab_t = capture(True)
    assert np.array_equal(usd_box, fab_box)
    assert np.abs(usd_rgb.astype(int) - fab_rgb).max() <= 2
    assert usd_t is not None and fab_t is None       # the fast path leaves the stage unauthored


def test_vectorized_quaternions_match_mujoco():
    import mujoco
    from graphsdg.maths.rotations import euler_to_matrix, matrix_to_quat_wxyz
    angles = np.random.default_rng(0).uniform(-360, 360, (200, 3))
    angles[:4] = [[0, 0, 0], [180, 0, 0], [0, 180, 0], [0, 0, 180]]
    mats = euler_to_matrix(angles)
    assert np.allclose(mats, [euler_to_matrix(a, "XYZ") for a in angles], atol=1e-12)
    quats = matrix_to_quat_wxyz(mats)
    for m, q in zip(mats, quats):
        ref = np.empty(4)
        mujoco.mju_mat2Quat(ref, m.ravel())
        assert np.allclose(q, ref if ref[0] >= 0 else -ref, atol=1e-9) or np.allclose(q, -ref, atol=1e-9)


def test_euler_convention_matches_usd_rotate_xyz():
    from graphsdg.maths.rotations import euler_to_matrix, matrix_to_euler_xyz
    cube = rep.functional.create.cube(rotation=(30, -50, 110))
    usd = np.array(UsdGeom.Xformable(cube).GetLocalTransformation())[:3, :3].T   # row-vector -> column
    assert np.allclose(usd, euler_to_matrix((30, -50, 110), "XYZ"), atol=1e-9)
    assert np.allclose(matrix_to_euler_xyz(usd), (30, -50, 110), atol=1e-9)


def test_pose_value_shapes():
    cubes = rep.functional.create_batch.cube(count=5)
    rep.functional.modify.pose(cubes, scale_value=[0.1, 0.2, 0.3, 0.4, 0.5])       # one scalar per prim
    assert tuple(cubes[3].GetAttribute("xformOp:scale").Get()) == (0.4, 0.4, 0.4)
    rep.functional.modify.pose(cubes, position_value=(1, 2, 3))                   # one vector for all
    assert all(tuple(c.GetAttribute("xformOp:translate").Get()) == (1, 2, 3) for c in cubes)
    with pytest.raises(ValueError, match="4 rows but count/prims is 5"):
        rep.functional.modify.pose(cubes, position_value=np.zeros((4, 3)))


def test_colour_and_depth_share_one_render_without_msaa():
    from graphsdg.engine.runtime import runtime
    rep.settings.set("/graphsdg/render/msaaSamples", 0)
    cube, cam, rp = unit_cube_scene(camera_position=(0, -4, 0), resolution=(W, H))
    rgb, depth = rep.annotators.get("rgb"), rep.annotators.get("distance_to_image_plane")
    rgb.attach(rp)
    depth.attach(rp)
    rep.orchestrator.step()
    stats = dict(runtime().rasterizer.stats)
    rep.orchestrator.step()
    after = runtime().rasterizer.stats
    assert after["color"] - stats["color"] == 1 and after.get("ids", 0) == stats.get("ids", 0)
    assert abs(depth.get_data()[H // 2, W // 2] - 3.5) < 1e-3
