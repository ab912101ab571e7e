"""Id codes at and beyond the end of the code -> geom table map to a geom or to the background, never to an
IndexError; crowded scenes (over 255 geoms: two bytes a code) read and label every object.

The bench's hand-written loop crashed on NVIDIA at 500 assets ("index 502 is out of bounds for axis 0 with
size 501"): mujoco.Renderer reads its id colours out of a multisampled buffer, NVIDIA's driver resolves them
(Mesa does not: MuJoCo turns multisampling off for them), and averaging two codes byte by byte gives a code
that no geom has, beyond the renderer's table of ngeom + 1 rows. These tests replay that resolve on the CPU.
"""
from __future__ import annotations

import mujoco
import numpy as np
import pytest

import graphsdg as rep
from graphsdg.benchmark import throughput
from graphsdg.render import rasterizer, readback

SAMPLES = 4


def _model_scene(ngeom: int) -> mujoco.MjvScene:
    """A MuJoCo scene of ``ngeom`` small spheres (no graphsdg involved)."""
    geoms = "".join(f"<geom pos='{i % 50} {i // 50} 0' size='.1'/>" for i in range(ngeom))
    model = mujoco.MjModel.from_xml_string(f"<mujoco><worldbody>{geoms}</worldbody></mujoco>")
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    scene = mujoco.MjvScene(model, maxgeom=ngeom + 10)
    mujoco.mjv_updateScene(model, data, mujoco.MjvOption(), None, mujoco.MjvCamera(), mujoco.mjtCatBit.mjCAT_ALL,
                           scene)
    return scene


def _resolve(codes: np.ndarray) -> np.ndarray:
    """What resolving a multisampled buffer of MuJoCo id colours (code = segid + 1 in red, green, blue) does:
    each colour byte averaged over the samples (last axis), rounded to nearest, the bytes read back as one
    code."""
    rgb = np.stack([(codes >> shift) & 0xFF for shift in (0, 8, 16)], axis=-1).astype(np.float64)
    mean = np.floor(rgb.mean(axis=-2) + 0.5).astype(np.int64)
    return mean[..., 0] | (mean[..., 1] << 8) | (mean[..., 2] << 16)


def test_resolving_two_byte_codes_makes_codes_beyond_every_geom():
    """The crash: an edge pixel half on segid 254 (code 255 = 0x00FF), half on segid 492 (0x01ED)."""
    scene = _model_scene(500)
    edge = np.array([[[255, 255, 493, 493]]])
    resolved = _resolve(edge)
    assert resolved.tolist() == [[502]] and resolved.max() > scene.ngeom
    renderers_table = np.full((scene.ngeom + 1, 2), -1)          # mujoco.Renderer's segid -> object table
    with pytest.raises(IndexError, match="index 502 is out of bounds for axis 0 with size 501"):
        renderers_table[resolved]
    lut = rasterizer._segid_lut(scene)                            # graphsdg's: every 16-bit code indexes it
    assert len(lut) == 1 << 16 and lut[502] == -1 and lut[255] == 254 and lut[493] == 492


def test_resolving_one_byte_codes_gives_a_third_geoms_code():
    """Under 256 geoms a resolved code stays inside the table but names a geom that is not there: why ids
    are drawn single-sample (graphsdg's id framebuffer, the bench loop's second renderer)."""
    resolved = _resolve(np.array([[[10, 10, 30, 30]]]))
    assert resolved.tolist() == [[20]]


@pytest.mark.parametrize("ngeom, bits", [(40, 8), (255, 8), (256, 16), (1200, 16)])
def test_every_code_of_the_read_width_indexes_the_table(ngeom, bits):
    scene = _model_scene(ngeom)
    lut = rasterizer._segid_lut(scene)
    assert readback.code_bits(len(lut)) == bits and len(lut) == 1 << bits
    codes = np.arange(1 << bits, dtype=np.uint8 if bits == 8 else np.uint16).reshape(-1, 256)
    geoms = rasterizer.lookup(lut, codes).ravel()
    assert geoms[0] == -1                                         # code 0: nothing drawn
    np.testing.assert_array_equal(geoms[1:ngeom + 1], np.arange(ngeom))
    assert (geoms[ngeom + 1:] == -1).all()                        # no geom has these codes: background


def test_24_bit_codes_beyond_the_table_are_clipped_to_the_background():
    size = (1 << 16) + 302                                        # 65,836 geoms' codes and the background's
    words = np.array([0, 1, size - 2, size - 1, size, 0x00FFFFFF, 0xFFFFFFFF], dtype=np.uint32)
    codes = readback.codes_from_rgba(size)(words.view(np.uint8).reshape(1, -1, 4))
    assert codes.tolist() == [[0, 1, size - 2, size - 1, size - 1, size - 1, size - 1]]
    lut = np.full(size, -1, dtype=np.int32)
    lut[1:size - 1] = np.arange(size - 2)
    assert rasterizer.lookup(lut, codes).tolist() == [[-1, 0, size - 3, -1, -1, -1, -1]]


def _cubes(count: int):
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World")
    cubes = rep.functional.create_batch.cube(count=count, parent="/World", semantics={"class": "cube"})
    cols = int(np.ceil(np.sqrt(count)))
    rep.functional.modify.pose(cubes, position_value=[(0.5 * (i % cols), 0.0, 0.5 * (i // cols)) for i in range(count)],
                               scale_value=0.3)
    cam = rep.functional.create.camera(position=(0, -20, 0), look_at=(0, 0, 0), parent="/World")
    return cubes, cam


@pytest.mark.parametrize("count, size", [(40, 64), (300, 256)])
def test_annotators_label_every_code_of_the_read_width(monkeypatch, count, size):
    """The id pass replaced by an image holding every code the read can hold: pixels whose code is a cube's
    get its class and instance, all others the background, and each cube's tight box spans its pixels."""
    cubes, cam = _cubes(count)
    rp = rep.create.render_product(cam, (size, size))
    names = ("semantic_segmentation", "instance_segmentation", "bounding_box_2d_tight")
    anns = {n: rep.annotators.get(n) for n in names}
    for a in anns.values():
        a.attach(rp)
    real = rasterizer.Rasterizer._render_ids
    seen = {}

    def every_code(self, *args, **kwargs):
        codes, lut, depth = real(self, *args, **kwargs)
        bits = readback.code_bits(len(lut))
        dtype = np.uint8 if bits == 8 else np.uint16
        image = (np.arange(size * size) % (1 << bits)).astype(dtype).reshape(size, size)
        seen.update(lut=lut, image=image)
        return (lambda: image), lut, depth

    monkeypatch.setattr(rasterizer.Rasterizer, "_render_ids", every_code)
    rep.orchestrator.step()
    lut, image = seen["lut"], seen["image"]
    assert readback.code_bits(len(lut)) == (8 if count < 255 else 16)
    geom_of_pixel = lut[image]
    from graphsdg.engine.runtime import runtime
    geom_ids = {runtime().sim.compiled.geoms[str(c.GetPath())].geom_id: str(c.GetPath()) for c in cubes}
    is_cube = np.isin(geom_of_pixel, list(geom_ids))
    semantic = anns["semantic_segmentation"].get_data()
    cube_id = int(next(k for k, v in semantic["info"]["idToLabels"].items() if v == {"class": "cube"}))
    np.testing.assert_array_equal(semantic["data"], np.where(is_cube, cube_id, 0))   # 0: background
    instance = anns["instance_segmentation"].get_data()
    path_of_id = {int(k): v for k, v in instance["info"]["idToLabels"].items()}
    ids = instance["data"]
    assert (ids[~is_cube] == 0).all()
    for g in np.unique(geom_of_pixel[is_cube]):
        pixels = geom_of_pixel == g
        assert {path_of_id[int(i)] for i in np.unique(ids[pixels])} == {geom_ids[int(g)]}
    boxes = anns["bounding_box_2d_tight"].get_data()
    assert len(boxes["data"]) == count                            # each cube's code is in the image
    for row, path in zip(boxes["data"], boxes["info"]["primPaths"]):
        g = next(k for k, v in geom_ids.items() if v == path)
        ys, xs = np.nonzero(geom_of_pixel == g)
        assert (row["x_min"], row["y_min"], row["x_max"], row["y_max"]) == (xs.min(), ys.min(), xs.max(), ys.max())


def test_a_crowded_scene_reads_two_byte_codes_and_labels_only_its_objects():
    """1,000 assets of the bench scene at 64 px: every id in range, every box made of its own pixels."""
    config = throughput.BenchConfig(asset_count=200, resolution=(64, 64))
    assets, _, rps = throughput.build_scene(config)
    throughput._apply(throughput.Randomization(config).draw(), assets, [])
    anns = {n: rep.annotators.get(n) for n in ("instance_segmentation", "bounding_box_2d_tight")}
    for a in anns.values():
        a.attach(rps)
    rep.orchestrator.step()
    from graphsdg.engine.runtime import runtime
    scene = runtime().rasterizer._scene
    assert scene.ngeom >= 1000 and readback.code_bits(len(rasterizer._segid_lut(scene))) == 16
    instance = anns["instance_segmentation"].get_data()
    paths = {int(k): v for k, v in instance["info"]["idToLabels"].items()}
    ids = instance["data"]
    drawn = set(np.unique(ids).tolist()) - {0}
    asset_paths = {str(a.GetPath()) for a in assets}
    assert len(drawn) > 100 and {paths[i] for i in drawn} <= asset_paths
    boxes = anns["bounding_box_2d_tight"].get_data()
    assert len(boxes["data"]) == len(drawn)
    for row, bbox_id in zip(boxes["data"], boxes["info"]["bboxIds"]):
        ys, xs = np.nonzero(ids == bbox_id)
        assert (row["x_min"], row["y_min"], row["x_max"], row["y_max"]) == (xs.min(), ys.min(), xs.max(), ys.max())


def test_the_bench_loop_runs_crowded_scenes():
    """The hand-written loop at 300 assets (two-byte codes) reads its ids single-sample and finishes."""
    config = throughput.BenchConfig(frames=1, warmup=0, asset_count=60, resolution=(64, 64),
                                   annotators=("semantic_segmentation", "bounding_box_2d_tight"), skip_write=True)
    result = throughput.run_handwritten(config)
    assert result.frames == 1 and "baseline:boxes" in result.profile
