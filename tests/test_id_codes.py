"""Id passes read back at 8, 16 or 24 bits per pixel, and the per-pixel lookups through them."""
from __future__ import annotations

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.render import rasterizer, readback
from graphsdg.render.lookup import lookup

W, H = 96, 64


def _two_balls_and_a_box():
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World")
    rep.functional.create.sphere(parent="/World", name="Left", position=(-1.2, 0, 0), scale=0.5,
                                 semantics={"class": "ball"})
    rep.functional.create.sphere(parent="/World", name="Right", position=(1.2, 0, 0), scale=0.5,
                                 semantics={"class": "ball"})
    rep.functional.create.cube(parent="/World", name="Box", position=(0, 1.0, 0), scale=0.8,
                               semantics={"class": "box"})
    cam = rep.functional.create.camera(position=(0, -5, 0), look_at=(0, 0, 0), parent="/World")
    return rep.create.render_product(cam, (W, H))


def _capture():
    rp = _two_balls_and_a_box()
    names = ("instance_segmentation", "bounding_box_2d_tight", "distance_to_image_plane")
    anns = [rep.annotators.get(n) for n in names]
    for a in anns:
        a.attach(rp)
    rep.orchestrator.step()
    return [a.get_data() for a in anns]


@pytest.mark.parametrize("bits", [16, 24])
def test_wider_codes_give_the_same_ids_boxes_and_depth(monkeypatch, bits):
    seg8, boxes8, depth8 = _capture()
    assert readback.code_bits(len(rasterizer._segid_lut(rasterizer_scene()))) == 8   # this scene reads 8 bits
    rep.stage.new_stage()
    monkeypatch.setattr(rasterizer, "_segid_lut", _widened(rasterizer._segid_lut, bits))
    seg, boxes, depth = _capture()
    np.testing.assert_array_equal(seg["data"], seg8["data"])
    np.testing.assert_array_equal(boxes["data"], boxes8["data"])
    np.testing.assert_array_equal(depth, depth8)
    assert len(boxes["data"]) == 3 and len(np.unique(seg["data"])) == 4   # three objects and the background


def rasterizer_scene():
    from graphsdg.engine.runtime import runtime
    return runtime().rasterizer._scene


def _widened(segid_lut, bits):
    """The code -> geom table padded past 2^8 (16 bits) or 2^16 (24 bits) codes: read as if the scene had
    that many geoms, without drawing them."""
    def lut(scene):
        small = segid_lut(scene)
        size = 1 << 16 if bits == 16 else (1 << 16) + 300
        out = np.full(size, -1, dtype=small.dtype)
        out[:len(small)] = small
        return out
    return lut


def test_scene_of_more_than_255_geoms_reads_16_bit_codes():
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World")
    # a 20 x 15 wall of small boxes facing the camera: 300 geoms, one per cell
    cells = [(x, z) for z in range(15) for x in range(20)]
    boxes = rep.functional.create_batch.cube(count=len(cells), parent="/World", name="Cell",
                                             semantics={"class": "cell"})
    rep.functional.modify.pose(boxes, position_value=[(0.5 * x - 4.75, 0.0, 0.5 * z - 3.5) for x, z in cells],
                               scale_value=0.4)
    cam = rep.functional.create.camera(position=(0, -14, 0), look_at=(0, 0, 0), parent="/World")
    rp = rep.create.render_product(cam, (200, 150))
    tight = rep.annotators.get("bounding_box_2d_tight")
    tight.attach(rp)
    rep.orchestrator.step()
    assert readback.code_bits(len(rasterizer._segid_lut(rasterizer_scene()))) == 16
    rows = tight.get_data()["data"]
    assert len(rows) == len(cells)                            # every box seen, each its own instance
    widths = rows["x_max"] - rows["x_min"] + 1
    assert widths.min() >= 5 and widths.max() <= 10   # ~6.5 px cubes: none merged with a cell 256 codes away


def test_code_bits():
    assert [readback.code_bits(n) for n in (2, 256, 257, 1 << 16, (1 << 16) + 1)] == [8, 8, 16, 16, 24]


def test_lookup_matches_indexing_for_every_kernel():
    rng = np.random.default_rng(0)
    for shape in ((64, 48), (1024, 512)):             # the second passes OpenCV's threading size: split in blocks
        codes = rng.integers(0, 200, shape).astype(np.uint8)
        for dtype in (np.uint8, np.int32, np.uint32, np.float32, np.int64, bool):
            table = (rng.random(200) * 100).astype(dtype)
            out = lookup(table, codes)
            assert out.dtype == table.dtype and np.array_equal(out, table[codes])
    wide = rng.integers(0, 70000, (32, 16)).astype(np.uint32)
    table = np.arange(70000, dtype=np.int32)[::-1].copy()
    assert np.array_equal(lookup(table, wide), table[wide])
    empty = np.zeros((0, 5), dtype=np.uint8)
    assert lookup(np.arange(3), empty).shape == (0, 5)


def test_id_pass_after_the_colour_pass_matches_an_id_pass_alone():
    """The id pass draws the scene the colour pass just updated (no second mjv_updateScene): the ids and
    depth are byte-identical to an id pass that updates the scene itself, rescaled meshes included."""
    from graphsdg.render.camera import camera_view
    from graphsdg.engine.runtime import runtime

    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    rp = _two_balls_and_a_box()
    shapes = rep.functional.create_batch.torus(count=3, parent="/World") + \
        rep.functional.create_batch.cone(count=3, parent="/World")
    rng = np.random.default_rng(4)
    rt = runtime()
    for _ in range(3):
        rep.functional.modify.pose(shapes, position_value=rng.uniform(-1.5, 1.5, (6, 3)),
                                   rotation_value=rng.uniform(0, 360, (6, 3)),
                                   scale_value=rng.uniform(0.3, 0.9, 6))
        rt.sim.sync_dirty_prims()
        view = camera_view(rp.camera_prim(), W, H)
        both = rt.rasterizer.render(rt.render_scene, view, {"color", "segmentation", "depth"})
        alone = rt.rasterizer.render(rt.render_scene, view, {"segmentation", "depth"})
        np.testing.assert_array_equal(both.geom_ids, alone.geom_ids)
        np.testing.assert_array_equal(both.depth, alone.depth)
        torus_geoms = {rt.sim.compiled.geoms[str(p.GetPath())].geom_id for p in shapes}
        assert torus_geoms & set(np.unique(alone.geom_ids).tolist())     # the rescaled meshes are in view


def test_id_framebuffer_depth_is_read_unpacked_and_matches_mujocos_buffer():
    """Id passes draw into graphsdg's own framebuffer (float depth, no stencil: read back as stored, 4
    bytes a pixel); its depth is byte-identical to the depth of MuJoCo's own single-sample buffer."""
    from graphsdg.render.camera import camera_view
    from graphsdg.engine.runtime import runtime

    rep.settings.set("/graphsdg/render/msaaSamples", 0)   # colour + depth from MuJoCo's buffer, in one pass
    rp = _two_balls_and_a_box()
    rt = runtime()
    view = camera_view(rp.camera_prim(), W, H)
    from_ids = rt.rasterizer.render(rt.render_scene, view, {"segmentation", "depth"}).depth
    from_mujoco = rt.rasterizer.render(rt.render_scene, view, {"color", "depth"}).depth
    np.testing.assert_array_equal(from_ids, from_mujoco)
    assert np.isfinite(from_ids).sum() > 300 and np.isinf(from_ids).sum() > 3000   # objects and background
    packed = rt.rasterizer._reads._packed_depth
    assert packed[rt.rasterizer._ids.fbo] is False          # DEPTH_COMPONENT32F: a plain copy
    assert True in packed.values()                          # MuJoCo's DEPTH32F_STENCIL8, read as stored


def test_id_framebuffer_refuses_an_empty_size():
    from graphsdg.render.id_framebuffer import IdFramebuffer
    with pytest.raises(ValueError, match="must be positive, got 0x64"):
        IdFramebuffer(0, 64)


@pytest.mark.parametrize("bits, size", [(8, 1), (16, 2), (24, 4)])
def test_id_framebuffer_stores_only_the_code_bytes(bits, size):
    """R8 / RG8 / RGBA8 colour for 8 / 16 / 24-bit codes: reading the codes back is a plain copy."""
    from OpenGL import GL

    from graphsdg.render.id_framebuffer import IdFramebuffer
    from graphsdg.engine.runtime import runtime
    rep.functional.create.cube()
    rep.orchestrator.step()          # a GL context, current
    runtime().rasterizer._ensure_gl()
    ids = IdFramebuffer(8, 8, bits)
    try:
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, ids.fbo)
        got = [int(GL.glGetFramebufferAttachmentParameteriv(GL.GL_READ_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0, p))
               for p in (GL.GL_FRAMEBUFFER_ATTACHMENT_RED_SIZE, GL.GL_FRAMEBUFFER_ATTACHMENT_GREEN_SIZE,
                         GL.GL_FRAMEBUFFER_ATTACHMENT_BLUE_SIZE)]
        assert sum(1 for b in got if b) == min(size, 3) and all(b in (0, 8) for b in got)
    finally:
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, 0)
        ids.free()
    with pytest.raises(ValueError, match="8, 16 or 24 bits, got 12"):
        IdFramebuffer(8, 8, 12)
