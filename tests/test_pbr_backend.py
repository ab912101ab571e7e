"""The PBR backend on Warp's CPU device at tiny sizes: same layout, ids and depth as the classic path.

Skipped where the gpu extra is absent (CI's Python 3.11). ``GRAPHSDG_PBR_TEST_DEVICE=cuda:0`` runs them on a
GPU instead (the device machine's check of the CUDA path). The first run compiles Warp kernels (about a minute
on a laptop-class CPU, cached afterwards in Warp's kernel cache)."""
from __future__ import annotations

import os

import numpy as np
import pytest

pytest.importorskip("mujoco_warp_pbr", reason="needs the gpu extra: pip install 'graphsdg[gpu]' (Python >= 3.12)")

import graphsdg as rep  # noqa: E402
from graphsdg.render.camera import camera_view  # noqa: E402
from graphsdg.render.pbr import PbrRenderer  # noqa: E402
from graphsdg.render.pbr_outputs import code_format, code_table  # noqa: E402
from graphsdg.engine.runtime import runtime  # noqa: E402

W, H = 32, 24
DEVICE = os.environ.get("GRAPHSDG_PBR_TEST_DEVICE", "cpu")


@pytest.fixture(scope="module")
def renderer():
    r = PbrRenderer(device=DEVICE)
    yield r
    r.close()


def _scene():
    rep.functional.create.dome_light(intensity=600)          # 600 nits: white at exposure 1
    rep.functional.create.distant_light(intensity=1500, rotation=(30, 20, 0))
    cube = rep.functional.create.cube(position=(0, 0, 0.5), name="Cube")
    ball = rep.functional.create.sphere(position=(1.2, 0.3, 0.4), scale=0.8, name="Ball")
    cam = rep.functional.create.camera(position=(3, -4, 2.5), look_at=(0.3, 0, 0.4))
    return cube, ball, cam


def test_pbr_labels_match_the_classic_path_and_colour_has_its_layout(renderer):
    cube, ball, cam = _scene()
    rt = runtime()
    scene = rt.render_scene
    view = camera_view(cam, W, H)
    out = renderer.render(scene, view, {"color", "hdr", "depth", "segmentation"})
    classic = rt.rasterizer.render(scene, view, {"depth", "segmentation"})
    assert out.color.shape == (H, W, 4) and out.color.dtype == np.uint8 and (out.color[..., 3] == 255).all()
    assert out.hdr.shape == (H, W, 3) and out.hdr.dtype == np.float32
    assert out.geom_ids.dtype == np.int32 and np.array_equal(out.geom_ids, classic.geom_ids)
    assert np.array_equal(np.isinf(out.depth), np.isinf(classic.depth))
    hit = np.isfinite(out.depth)
    rel = np.abs(out.depth[hit] - classic.depth[hit]) / classic.depth[hit]
    assert np.median(rel) < 1e-3 and rel.max() < 1e-2
    # the 600-nit dome behind everything shows white, as it does on the classic path
    sky = out.geom_ids == -1
    assert sky.any() and (out.color[sky][:, :3] == 255).all()
    # ids come back as one byte a pixel (a scene under 255 geoms), read through their table as the classic ids
    assert out.id_codes.dtype == np.uint8 and np.array_equal(out.id_lut[out.id_codes], classic.geom_ids)
    # each code's pixel bounds, made on the device, are the pixels' own
    assert np.array_equal(out.code_boxes, _pixel_bounds(out.id_codes, len(out.code_boxes)))


def test_pbr_follows_poses_and_is_deterministic(renderer):
    cube, ball, cam = _scene()
    sim = runtime().sim
    view = camera_view(cam, W, H)
    scene = runtime().render_scene
    first = renderer.render(scene, view, {"color", "segmentation"})
    again = renderer.render(scene, view, {"color", "segmentation"})
    assert np.array_equal(first.color, again.color)
    rep.functional.modify.pose(cube, position_value=(-1.5, 0, 0.5))
    sim.sync_dirty_prims()
    sim.forward()
    moved = renderer.render(scene, view, {"segmentation"})
    classic = runtime().rasterizer.render(scene, view, {"segmentation"})
    assert not np.array_equal(moved.geom_ids, first.geom_ids)
    assert np.array_equal(moved.geom_ids, classic.geom_ids)


def _leaf_order(renderer) -> list[int]:
    """The geoms' order in the depth-first walk of the scene tree the renderer last traced: the tree's shape."""
    import warp as wp

    @wp.kernel(enable_backward=False)
    def walk(bvh: wp.uint64, order: wp.array[int], count: wp.array[int]):
        query = wp.bvh_query_aabb(bvh, wp.vec3(-1.0e6), wp.vec3(1.0e6))
        index = int(0)
        n = int(0)
        while wp.bvh_query_next(query, index):
            order[n] = index
            n += 1
        count[0] = n

    (ctx,) = renderer._contexts.values()
    bvh = ctx.rc.base.bvh
    order = wp.zeros(4096, dtype=int, device=bvh.device)
    count = wp.zeros(1, dtype=int, device=bvh.device)
    wp.launch(walk, dim=1, inputs=[bvh.id], outputs=[order, count], device=bvh.device)
    return order.numpy()[:count.numpy()[0]].tolist()


def test_a_frame_is_traced_through_its_own_boxes_tree_whatever_frame_the_model_was_compiled_at():
    """A process that compiled its model at one arrangement and moved on traces a frame through the tree a
    process that compiled at that frame does (a shard or resumed run compiles where it starts): its pixels do
    not depend on where the run started."""
    rep.functional.create.dome_light(intensity=600)
    boxes = [rep.functional.create.cube(position=(i - 3.5, 0, 0.3), scale=0.5, name=f"Box{i}") for i in range(8)]
    cam = rep.functional.create.camera(position=(0, -9, 4), look_at=(0, 0, 0.3))
    sim, scene = runtime().sim, runtime().render_scene
    view = camera_view(cam, W, H)
    started_early, started_late = PbrRenderer(device=DEVICE), PbrRenderer(device=DEVICE)
    try:
        started_early.render(scene, view, {"color"})                 # compiled with the boxes in a row
        for box, x in zip(boxes, [3.5, -3.5, 0.5, -0.5, 2.5, -2.5, 1.5, -1.5]):   # shuffled along it
            rep.functional.modify.pose(box, position_value=(x, 0.0, 0.3))
        sim.sync_dirty_prims()
        sim.forward()
        early = started_early.render(scene, view, {"color", "depth", "segmentation"})
        early_order = _leaf_order(started_early)
        sim.recompile()                                              # as a run starting here compiles
        late = started_late.render(scene, view, {"color", "depth", "segmentation"})
        assert early_order == _leaf_order(started_late)
        for name in ("color", "depth", "geom_ids"):
            assert np.array_equal(getattr(early, name), getattr(late, name))
        # a frame whose boxes are the last rebuild's keeps its tree; a move rebuilds it
        trees = started_late.stats["scene_trees"]
        started_late.render(scene, view, {"color"})
        assert started_late.stats["scene_trees"] == trees
        rep.functional.modify.pose(boxes[0], position_value=(0.0, 1.0, 0.3))
        sim.sync_dirty_prims()
        sim.forward()
        started_late.render(scene, view, {"color"})
        assert started_late.stats["scene_trees"] == trees + 1
    finally:
        started_early.close()
        started_late.close()


def test_path_samples_are_seeded_by_the_frame_not_by_what_the_process_drew_before():
    """Path-traced noise is the frame's own: a process that drew frame 3 first draws frame 9 as one that did
    not (a shard, a resumed run), and frames 3 and 9 draw different samples."""
    from graphsdg.base import settings_store
    from graphsdg.render.backend import DENOISER_KEY
    cube, ball, cam = _scene()
    scene, view = runtime().render_scene, camera_view(cam, W, H)
    saved = {k: settings_store.get(k) for k in ("/rtx/rendermode", "/rtx/pathtracing/spp", DENOISER_KEY)}
    settings_store.set("/rtx/rendermode", "PathTracing")
    settings_store.set("/rtx/pathtracing/spp", 1)
    settings_store.set(DENOISER_KEY, False)
    drew_before, fresh = PbrRenderer(device=DEVICE), PbrRenderer(device=DEVICE)
    try:
        drew_before.render(scene, view, {"color"}, frame=3)
        after = drew_before.render(scene, view, {"color"}, frame=9).color
        alone = fresh.render(scene, view, {"color"}, frame=9).color
        other = fresh.render(scene, view, {"color"}, frame=3).color
    finally:
        drew_before.close()
        fresh.close()
        for key, value in saved.items():
            settings_store.set(key, value)
    assert np.array_equal(after, alone)
    assert not np.array_equal(alone, other)


def test_id_codes_use_the_fewest_bytes_and_their_table_maps_them_to_geoms():
    assert code_format(10) == (np.uint8, 256) and code_format(254) == (np.uint8, 256)
    assert code_format(255) == (np.uint16, 65536) and code_format(70000) == (np.uint32, 70002)
    table = code_table(255)
    assert table[0] == -1 and table[1] == 0 and table[255] == 254 and (table[256:] == -1).all()
    assert len(code_table(10)) == 256 and (code_table(10)[11:] == -1).all()


def test_pbr_ids_of_a_scene_of_more_than_255_geoms_come_back_in_two_bytes(renderer):
    """A crowded scene (300 boxes: codes past one byte): the GPU writes uint16 codes, and their table gives the
    classic path's geom ids."""
    rep.functional.create.dome_light(intensity=600)
    xs, ys = np.meshgrid(np.linspace(-2.0, 2.0, 20), np.linspace(-1.5, 1.5, 15))
    positions = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1)
    rep.functional.create_batch.cube(count=300, position=positions, scale=0.12, name="Box")
    cam = rep.functional.create.camera(position=(0, 0, 6), look_at=(0, 0, 0))
    sim = runtime().sim
    assert sim.ensure_compiled().model.ngeom >= 300
    scene = runtime().render_scene
    view = camera_view(cam, W, H)
    out = renderer.render(scene, view, {"segmentation"})
    classic = runtime().rasterizer.render(scene, view, {"segmentation"})
    assert out.id_codes.dtype == np.uint16 and len(out.id_lut) == 1 << 16
    assert len(np.unique(out.geom_ids)) > 50, "many boxes in view"
    assert (out.id_lut[out.id_codes] != classic.geom_ids).sum() <= 2   # pixel centres on an edge may differ
    # two-byte codes' bounds from the device, one row per geom (+ background), as the pixels give them; the
    # annotators' per-geom boxes from them are the ones the CPU path gets from the runs of the pixels
    assert out.code_boxes.shape == (sim.model.ngeom + 1, 4)
    assert np.array_equal(out.code_boxes, _pixel_bounds(out.id_codes, sim.model.ngeom + 1))
    from graphsdg.annotate.frame import _geom_boxes_of_codes, _run_boxes, _runs
    assert np.array_equal(_geom_boxes_of_codes(out.code_boxes, out.id_lut, sim.model.ngeom),
                          _run_boxes(_runs(out.geom_ids), W, sim.model.ngeom))


def _pixel_bounds(codes: np.ndarray, rows: int) -> np.ndarray:
    """(rows, 4) x_min, y_min, x_max, y_max of each code's pixels, -1 rows for codes no pixel has."""
    bounds = np.full((rows, 4), -1, dtype=np.int32)
    for code in np.unique(codes):
        ys, xs = np.nonzero(codes == code)
        bounds[code] = xs.min(), ys.min(), xs.max(), ys.max()
    return bounds


def test_pbr_follows_rescaled_meshes_sizes_and_camera_intrinsics(renderer):
    """Randomizers that rescale meshes and primitives, or change a camera's focal length, reach the renderer
    without a new render context: its ids stay the classic path's, pixel for pixel."""
    from pxr import UsdGeom
    cube, ball, cam = _scene()
    mesh = rep.functional.create.cube(position=(-1.0, 0.8, 0.4), scale=0.5, name="MeshCube", as_mesh=True)
    sim = runtime().sim
    scene = runtime().render_scene

    def compare():
        sim.sync_dirty_prims()
        sim.forward()
        view = camera_view(cam, W, H)
        out = renderer.render(scene, view, {"depth", "segmentation"})
        classic = runtime().rasterizer.render(scene, view, {"depth", "segmentation"})
        # a pixel centre lying on a silhouette edge may fall either side in a rasteriser and a ray tracer
        diff = out.geom_ids != classic.geom_ids
        assert diff.sum() <= 2, (diff.sum(), np.argwhere(diff)[:5])
        return out

    before = compare()
    contexts = renderer.stats["contexts"]
    rep.functional.modify.pose(mesh, scale_value=(1.4, 1.4, 1.4))
    rep.functional.modify.pose(ball, scale_value=(0.3, 0.3, 0.3))
    rescaled = compare()
    assert scene.mesh_maps, "the mesh was rescaled in place"
    assert not np.array_equal(before.geom_ids, rescaled.geom_ids)
    UsdGeom.Camera(cam).GetFocalLengthAttr().Set(35.0)
    zoomed = compare()
    assert not np.array_equal(rescaled.geom_ids, zoomed.geom_ids)
    assert renderer.stats["contexts"] == contexts, "no new render context for per-frame changes"


def test_pbr_draws_a_steps_products_in_one_launch_each_at_its_own_size(renderer):
    """render_batch: two products of different sizes and cameras as two cameras of one launch; each product's
    ids and depth are the classic path's, and a product alone (its own launch) gives the same labels."""
    from graphsdg import settings
    from graphsdg.render.backend import RenderRequest
    cube, ball, cam = _scene()
    side = rep.functional.create.camera(position=(0.5, 4.0, 1.5), look_at=(0.3, 0, 0.4))
    scene = runtime().render_scene
    views = [camera_view(cam, W, H), camera_view(side, 20, 16)]
    passes = {"color", "depth", "segmentation"}
    launches = renderer.stats["color"]
    outs = renderer.render_batch(scene, [RenderRequest(v, passes) for v in views])
    assert renderer.stats["color"] == launches + 1, "both products in one launch"
    assert scene.pbr_cameras >= 2
    for view, out in zip(views, outs):
        classic = runtime().rasterizer.render(scene, view, {"depth", "segmentation"})
        assert out.color.shape == (view.height, view.width, 4)
        assert (out.geom_ids != classic.geom_ids).sum() <= 1
        hit = np.isfinite(out.depth) & np.isfinite(classic.depth)
        assert np.median(np.abs(out.depth[hit] - classic.depth[hit]) / classic.depth[hit]) < 1e-3
        alone = renderer.render(scene, view, passes)
        assert np.array_equal(alone.geom_ids, out.geom_ids) and np.array_equal(alone.depth, out.depth)
        assert np.abs(alone.color.astype(int) - out.color.astype(int)).mean() < 2.0
    assert len({out.geom_ids.tobytes() for out in outs}) == 2, "each camera saw its own view"
    settings.set("/graphsdg/render/pbrBatchPixels", 0)     # one launch per product
    launches = renderer.stats["color"]
    renderer.render_batch(scene, [RenderRequest(v, passes) for v in views])
    assert renderer.stats["color"] == launches + 2


def test_pbr_motion_blur_smears_by_the_projected_travel():
    """Through the orchestrator with /graphsdg/render/backend = pbr on Warp's CPU device: a box moving during
    the shutter smears by its analytic image travel (as the classic path's test asserts), labels stay crisp."""
    from pxr import Sdf, UsdPhysics

    from graphsdg import settings
    dt, half, w, h = 1 / 30, 0.25, 64, 16

    def capture(speed: float):
        rep.stage.new_stage()
        for key, value in {"/graphsdg/render/backend": "pbr", "/graphsdg/render/pbrDevice": DEVICE,
                           "/omni/replicator/captureMotionBlur": True, "/rtx/post/motionblur/numSamples": 8,
                           "/rtx/post/motionblur/maxBlurDiameterFraction": 1.0}.items():
            settings.set(key, value)
        rep.functional.create.dome_light(intensity=0)
        rep.functional.create.distant_light(intensity=3000, rotation=(0, 0, 0))
        box = rep.functional.create.cube(position=(0, 0, 0), scale=2 * half)
        rep.functional.physics.apply_rigid_body(box)
        box.CreateAttribute("physxRigidBody:disableGravity", Sdf.ValueTypeNames.Bool).Set(True)
        UsdPhysics.RigidBodyAPI(box).GetVelocityAttr().Set((speed, 0, 0))
        cam = rep.functional.create.camera(position=(0, 0, 2), look_at=(0, 0, 0))
        rp = rep.create.render_product(cam, (w, h))
        rgb, seg = rep.annotators.get("rgb"), rep.annotators.get("semantic_segmentation")
        rgb.attach(rp)
        rep.orchestrator.step(delta_time=dt)
        return rgb.get_data()[h // 2, :, :3].astype(int).max(axis=1), cam

    static, _ = capture(0.0)
    moving, cam = capture(3.0)
    assert type(runtime().renderer).__name__ == "PbrRenderer"
    view = camera_view(cam, w, h)
    uv, _ = view.project(np.array([[0.0, 0.0, half], [3.0 * dt, 0.0, half]]))
    extra = int((moving > 3).sum()) - int((static > 3).sum())
    assert extra == pytest.approx(float(np.linalg.norm(uv[1] - uv[0])), abs=2.0)
    lit = moving[moving > 3]
    assert lit.min() < 100 and lit.max() >= 200      # a smear: partly covered ends


def test_pbr_tight_boxes_and_segmentation_ids_come_from_the_devices_code_bounds():
    """Through the orchestrator on pbr: the tight boxes annotator reads each geom's pixel bounds as the device
    made them (no pass over the pixels on the CPU), and they bound exactly the pixels the semantic
    segmentation image gives each class; the segmentation's label table lists the classes drawn."""
    from graphsdg import settings
    rep.stage.new_stage()
    settings.set("/graphsdg/render/backend", "pbr")
    settings.set("/graphsdg/render/pbrDevice", DEVICE)
    rep.functional.create.dome_light(intensity=600)
    rep.functional.create.cube(position=(0, 0, 0.5), semantics={"class": "box"})
    rep.functional.create.sphere(position=(1.2, 0.3, 0.4), scale=0.8, semantics={"class": "ball"})
    rep.functional.create.cylinder(position=(-1.0, 0.8, 0.4), scale=0.6, semantics={"class": "can"})
    cam = rep.functional.create.camera(position=(3, -4, 2.5), look_at=(0.3, 0, 0.4))
    rp = rep.create.render_product(cam, (48, 32))
    boxes, seg = rep.annotators.get("bounding_box_2d_tight"), rep.annotators.get("semantic_segmentation")
    boxes.attach(rp)
    seg.attach(rp)
    rep.orchestrator.step(delta_time=0)
    assert type(runtime().renderer).__name__ == "PbrRenderer"
    rows, image = boxes.get_data()["data"], seg.get_data()["data"]
    labels = seg.get_data()["info"]["idToLabels"]
    assert sorted(v["class"] for k, v in labels.items() if v.get("class") in ("box", "ball", "can")) == \
        ["ball", "box", "can"]
    assert len(rows) == 3
    for row in rows:
        ys, xs = np.nonzero(image == row["semanticId"])
        assert (row["x_min"], row["y_min"], row["x_max"], row["y_max"]) == (xs.min(), ys.min(), xs.max(), ys.max())


def test_a_deferred_pbr_render_gives_its_own_frames_pixels_when_read_after_the_next_render(renderer):
    """``defer`` (a pipelined step) leaves the copies in flight; the next render reads into other buffers, so a
    deferred frame read after it still shows its own instant."""
    from graphsdg.render.backend import RenderRequest
    cube, ball, cam = _scene()
    sim = runtime().sim
    view = camera_view(cam, W, H)
    scene = runtime().render_scene
    passes = {"color", "depth", "segmentation"}
    now = renderer.render(scene, view, passes)
    deferred = renderer.render_batch(scene, [RenderRequest(view, passes, defer=True)])[0]
    rep.functional.modify.pose(cube, position_value=(-1.5, 0, 0.5))
    sim.sync_dirty_prims()
    sim.forward()
    moved = renderer.render(scene, view, passes)          # reuses the deferred render's buffers
    assert not np.array_equal(moved.geom_ids, now.geom_ids)
    for name in ("color", "depth", "id_codes", "code_boxes"):
        assert np.array_equal(deferred.get(name), now.get(name)), name


def _pixel_body(kernel):
    """The per-pixel function (mujoco-warp-pbr's ``render_pixel``) a megakernel calls."""
    return next(cell.cell_contents for cell in kernel.func.__closure__
                if str(getattr(cell.cell_contents, "key", "")).endswith("render_pixel"))


def test_a_compact_build_calls_the_lights_shadow_test_where_its_cuts_name_it(renderer, monkeypatch):
    from mujoco_warp_pbr._src import render as pbr_render

    from graphsdg.render import pbr_kernel
    cube, ball, cam = _scene()
    ctx = renderer._context(runtime().render_scene, [camera_view(cam, W, H)], 1)
    for cuts, hint in ((("any-geom", "closest-geom"), None), (("any-geom", "shadow-visibility"), "noinline")):
        monkeypatch.setattr(pbr_kernel, "CALLED_TRAVERSALS", cuts)
        with pbr_kernel.building("compact"):
            pixel = _pixel_body(pbr_render._build_megakernel(ctx.model, ctx.rc))
        assert pbr_kernel.nested_function(pixel, "light_visibility").inline_hint == hint
    with pbr_kernel.building("inlined"):
        pixel = _pixel_body(pbr_render._build_megakernel(ctx.model, ctx.rc))
    assert pbr_kernel.nested_function(pixel, "light_visibility").inline_hint is None


def test_the_megakernels_replays_render_what_the_librarys_launches_render(renderer):
    """A replayed megakernel launch (only the seed set) gives the library's pixels for that seed and the arrays'
    current contents; a field replaced by another array goes through the library again and is recorded anew."""
    import mujoco_warp_pbr as mjpbr
    import warp as wp

    from graphsdg.render.megakernel_launch import MegakernelLaunch

    rep.functional.create.dome_light(intensity=100)
    rep.functional.create.cube(position=(0, 0, 0.5), name="Cube")
    rep.functional.create.plane(scale=5, name="Floor")   # a bulb's soft shadows on a floor: the seed shows
    rep.functional.create.sphere_light(intensity=3000, radius=0.6, position=(0.5, -1.5, 2.0))
    cam = rep.functional.create.camera(position=(3, -4, 2.5), look_at=(0.3, 0, 0.4))
    scene, view = runtime().render_scene, camera_view(cam, W, H)
    renderer.render(scene, view, {"color", "depth", "segmentation"})
    ctx = next(c for c in renderer._contexts.values() if c.layouts[0].shape == (H, W))
    m, d, rc = ctx.model, ctx.data, ctx.rc
    samples = rc.shadow_samples
    rc.shadow_samples = 8

    def pixels(launch) -> tuple[np.ndarray, ...]:
        launch()
        wp.synchronize_device(rc.base.rgb_data.device)
        return rc.base.rgb_data.numpy().copy(), rc.base.depth_data.numpy().copy(), rc.base.seg_data.numpy().copy()

    draw = MegakernelLaunch()
    seen = set()
    for step, seed in enumerate((3, 4, 4, 11)):
        if step == 2:    # new contents of an array the recording points at: a cube moved on the device
            xpos = d.geom_xpos.numpy()
            xpos[0, :, 0] += 0.4
            d.geom_xpos.assign(xpos)
        replayed = pixels(lambda: draw(m, d, rc, seed))
        library = pixels(lambda: mjpbr.render(m, d, rc, seed=seed))
        assert all(np.array_equal(a, b) for a, b in zip(replayed, library))
        seen.add(replayed[0].tobytes())
    assert draw.replays == 3 and len(seen) == 3          # seeds 3, 4 and the move change the colour

    rough = rc.geom_roughness
    try:
        rc.geom_roughness = wp.clone(rough)              # another object: the library launches and is recorded
        rc.geom_roughness.fill_(0.05)
        replayed = pixels(lambda: draw(m, d, rc, 5))
        library = pixels(lambda: mjpbr.render(m, d, rc, seed=5))
        assert draw.replays == 3 and all(np.array_equal(a, b) for a, b in zip(replayed, library))
        assert all(np.array_equal(a, b) for a, b in zip(pixels(lambda: draw(m, d, rc, 5)), library))
        assert draw.replays == 4
    finally:
        rc.geom_roughness, rc.shadow_samples = rough, samples


def _scene_on_pbr(png_on_device: bool):
    """A new stage of :func:`_scene` rendered by the pbr backend on the test's device, PNGs made on the device or
    not."""
    from graphsdg import settings
    rep.stage.new_stage()
    for key, value in {"/graphsdg/render/backend": "pbr", "/graphsdg/render/pbrDevice": DEVICE,
                       "/graphsdg/render/pbrPngOnDevice": png_on_device}.items():
        settings.set(key, value)
    return _scene()


@pytest.mark.parametrize("png_on_device", [False, True])
def test_pipelined_pbr_steps_write_the_bytes_of_waited_steps(tmp_path, png_on_device):
    """Two frames in flight on the pbr backend (each step draws its frame, then writes the previous one) write
    what steps that wait for each frame write, PNGs made on the device or not."""
    from graphsdg import settings
    from test_pipelined_steps import _graph_run

    def run(name, wait):
        for key, value in {"/graphsdg/render/backend": "pbr", "/graphsdg/render/pbrDevice": DEVICE,
                           "/graphsdg/render/pbrPngOnDevice": png_on_device}.items():
            settings.set(key, value)
        return _graph_run(str(tmp_path / name), wait)

    waited, pipelined = run("waited", True), run("pipelined", False)
    assert len([f for f in waited if f.startswith("rgb_")]) == 5 and pipelined == waited


def _device_stream(image: np.ndarray, labels: bool = False) -> bytes:
    """The zlib stream graphsdg.render.device_png makes of an RGBA image (a label image's: ``labels``) on the
    test's device."""
    import warp as wp

    from graphsdg.render import device_png
    room = wp.zeros(W * H * 3, dtype=wp.uint32, device=DEVICE)
    meta = wp.zeros(2, dtype=wp.int64, device=DEVICE)
    codes = device_png.LABEL_CODES if labels else device_png.COLOUR_CODES
    device_png.DevicePng(W, H, DEVICE, room, meta, codes).queue(
        wp.array(np.ascontiguousarray(image).view(np.uint32).reshape(-1), dtype=wp.uint32, device=DEVICE))
    return device_png.zlib_stream(meta.numpy(), room.numpy())


def test_colour_pngs_compressed_on_the_device_are_the_files_basic_writer_writes(tmp_path):
    """With /graphsdg/render/pbrPngOnDevice, the rgb annotator's image carries the stream compressed where it was
    rendered, and BasicWriter's rgb file is that stream wrapped (not ISA-L's bytes), decoding to the pixels; the
    same frame without the setting is compressed on the CPU."""
    import io
    import zlib

    from PIL import Image

    from graphsdg.imaging.precompressed import PrecompressedImage
    from graphsdg.io.png import encode_png, filtered_lines

    def capture(on_device: bool, out: str):
        _, _, cam = _scene_on_pbr(on_device)
        rp = rep.create.render_product(cam, (W, H))
        rgb = rep.annotators.get("rgb")
        rgb.attach(rp)
        writer = rep.writers.get("BasicWriter", init_params={"output_dir": out, "rgb": True}, render_products=rp)
        rep.orchestrator.step(delta_time=0)
        rep.orchestrator.wait_until_complete()
        writer.detach()
        with open(os.path.join(out, "rgb_0000.png"), "rb") as f:
            return rgb.get_data(), f.read()

    pixels, written = capture(True, str(tmp_path / "device"))
    assert isinstance(pixels, PrecompressedImage)         # a view of the frame's image: the stream stays with it
    start = written.index(b"IDAT")
    idat = written[start + 4:start + 4 + int.from_bytes(written[start - 4:start], "big")]
    assert idat == _device_stream(pixels)
    assert zlib.decompress(idat) == filtered_lines(pixels).tobytes()
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(written))), pixels)
    cpu_pixels, cpu_written = capture(False, str(tmp_path / "cpu"))
    assert type(cpu_pixels) is np.ndarray and np.array_equal(cpu_pixels, pixels)
    assert cpu_written == encode_png(np.asarray(pixels)) != written


def test_class_masks_coloured_on_the_device_are_the_annotators_and_the_files_basic_writer_writes(tmp_path):
    """With /graphsdg/render/pbrPngOnDevice, the colorized semantic segmentation is coloured and compressed where
    the ids are drawn: the same pixels as the CPU's lookup, a label image carrying the device's stream (rows
    unfiltered, the label codes), which BasicWriter's file wraps; without the setting the CPU colours it and
    stores its rows unfiltered too."""
    import io
    import zlib

    from PIL import Image

    from graphsdg.imaging.label_image import LabelImage
    from graphsdg.imaging.precompressed import PrecompressedLabelImage
    from graphsdg.io.png import encode_png, filtered_lines

    def capture(on_device: bool, out: str):
        cube, ball, cam = _scene_on_pbr(on_device)
        rep.functional.modify.semantics(cube, {"class": "cube"})
        rep.functional.modify.semantics(ball, {"class": "ball"})
        rp = rep.create.render_product(cam, (W, H))
        seg = rep.annotators.get("semantic_segmentation", init_params={"colorize": True})
        seg.attach(rp)
        writer = rep.writers.get("BasicWriter", init_params={"output_dir": out, "semantic_segmentation": True},
                                 render_products=rp)
        rep.orchestrator.step(delta_time=0)
        rep.orchestrator.wait_until_complete()
        writer.detach()
        with open(os.path.join(out, "semantic_segmentation_0000.png"), "rb") as f:
            return seg.get_data()["data"], f.read()

    def idat(png: bytes) -> bytes:
        start = png.index(b"IDAT")
        return png[start + 4:start + 4 + int.from_bytes(png[start - 4:start], "big")]

    mask, written = capture(True, str(tmp_path / "device"))
    cpu_mask, cpu_written = capture(False, str(tmp_path / "cpu"))
    assert isinstance(mask, PrecompressedLabelImage) and isinstance(cpu_mask, LabelImage)
    assert not isinstance(cpu_mask, PrecompressedLabelImage) and np.array_equal(mask, cpu_mask)
    assert len({tuple(c) for c in np.asarray(mask).reshape(-1, 4).tolist()}) >= 3    # cube, ball, background
    assert idat(written) == _device_stream(mask, labels=True)          # the data is a view: no stream of its own
    assert np.array_equal(np.asarray(Image.open(io.BytesIO(written))), mask)
    assert cpu_written == encode_png(cpu_mask) != written
    for png in (written, cpu_written):                                 # both store the mask's rows unfiltered
        assert zlib.decompress(idat(png)) == filtered_lines(cpu_mask).tobytes()
        assert set(zlib.decompress(idat(png))[::W * 4 + 1]) == {0}
