"""Replicator's registry calls (add / remove / default lists), rep.functional.get, create_batch.camera and the
annotators Isaac's extensions add (StableIdMap, IsaacNoop, IsaacReadSimulationTime, IsaacReadSystemTime)."""
from __future__ import annotations

import time

import numpy as np
import pytest
from pxr import Gf, UsdGeom

import graphsdg as rep
from graphsdg.errors import UnknownNameError
from graphsdg.nodes.isaac_annotators import decode_stable_id_map, encode_stable_id_map

from conftest import unit_cube_scene


class _CountingWriter(rep.Writer):
    def __init__(self):
        self.annotators = ["rgb"]
        self.frames = 0

    def write(self, data):
        self.frames += 1


def test_writer_registry_default_list_and_unregister():
    defaults = rep.WriterRegistry._default_writers
    assert isinstance(defaults, list) and "BasicWriter" in defaults
    defaults.append("MyNodeWriter")              # what Isaac's extensions do for their writers
    assert "MyNodeWriter" in rep.WriterRegistry._default_writers
    defaults.remove("MyNodeWriter")
    assert "MyNodeWriter" not in rep.WriterRegistry._default_writers

    _, _, rp = unit_cube_scene(resolution=(16, 12))
    rep.writers.register_writer(_CountingWriter)
    writer = rep.writers.get("_CountingWriter")
    writer.initialize()
    writer.attach(rp)
    rep.orchestrator.step()
    assert writer.frames == 1
    rep.WriterRegistry.unregister_writer("_CountingWriter")   # detaches its instances, then forgets the class
    assert "_CountingWriter" not in rep.writers.get_writers()
    rep.orchestrator.step()
    assert writer.frames == 1 and writer not in rep.WriterRegistry.get_attached_writers()
    with pytest.raises(UnknownNameError, match="unknown writer '_CountingWriter'"):
        rep.writers.unregister_writer("_CountingWriter")


def test_register_node_writer_says_what_to_do_instead():
    with pytest.raises(NotImplementedError, match="OmniGraph node.*rep.writers.register_writer"):
        rep.writers.register_node_writer(name="CustomROS2PublishImage",
                                         node_type_id="isaacsim.ros2.bridge.ROS2PublishImage", annotators=["rgb"])


def test_annotator_registry_errors_defaults_and_unregister():
    with pytest.raises(rep.annotators.AnnotatorRegistryError, match="unknown annotator 'rbg'.*'rgb'"):
        rep.AnnotatorRegistry.get_annotator("rbg")
    with pytest.raises(UnknownNameError):   # still the error type graphsdg raised before
        rep.annotators.get("rbg")
    defaults = rep.AnnotatorRegistry._default_annotators
    assert isinstance(defaults, list) and {"rgb", "StableIdMap", "bounding_box_2d_tight"} <= set(defaults)

    rep.AnnotatorRegistry.register_annotator_from_aov("DepthLinearized", name="my_depth_for_unregister")
    assert "my_depth_for_unregister" in rep.annotators.get_registered_annotators()
    rep.AnnotatorRegistry.unregister_annotator("my_depth_for_unregister")
    assert "my_depth_for_unregister" not in rep.annotators.get_registered_annotators()
    with pytest.raises(rep.annotators.AnnotatorRegistryError, match="my_depth_for_unregister"):
        rep.AnnotatorRegistry.unregister_annotator("my_depth_for_unregister")


def test_register_copies_an_augmented_annotator_under_a_new_name():
    _, _, rp = unit_cube_scene(resolution=(24, 18))

    def plus_two(data_in):
        return data_in + np.float32(2.0)

    source = rep.annotators.get("distance_to_camera").augment(plus_two)
    rep.annotators.register("depth_plus_two", source)
    try:
        plain = rep.annotators.get("distance_to_camera").attach(rp)
        copied = rep.annotators.get("depth_plus_two").attach(rp)
        rep.orchestrator.step()
        d = plain.get_data()
        finite = np.isfinite(d)
        assert finite.any()
        np.testing.assert_array_equal(copied.get_data()[finite], d[finite] + np.float32(2.0))
    finally:
        rep.AnnotatorRegistry.unregister_annotator("depth_plus_two")
    with pytest.raises(rep.annotators.AnnotatorRegistryError):
        rep.annotators.register("x", 3)


def test_functional_get_selects_prims_and_lists_render_products():
    cube, cam, rp = unit_cube_scene(resolution=(32, 16))
    assert [str(p.GetPath()) for p in rep.functional.get.prims(semantics=[("class", "cube")])] == ["/World/Cube"]
    assert [str(p.GetPath()) for p in rep.functional.get.camera()] == ["/World/Camera"]
    assert [str(p.GetPath()) for p in rep.functional.get.light()] == ["/World/Dome"]
    assert rep.functional.get.prim_at_path("/World/Cube")[0] == cube
    with pytest.raises(Exception, match="/World/Nope"):
        rep.functional.get.prim_at_path("/World/Nope")

    second = rep.create.render_product(cam, (8, 4), name="tiny")
    products = rep.functional.get.renderproduct()
    found = {str(p.GetPath()): (str(p.GetRelationship("camera").GetTargets()[0]),
                                tuple(p.GetAttribute("resolution").Get())) for p in products}
    assert found == {rp.path: ("/World/Camera", (32, 16)), second.path: ("/World/Camera", (8, 4))}
    stage = rep.stage.get_stage()
    assert not stage.GetRootLayer().GetPrimAtPath(rp.path)          # session layer only: saves carry none
    second.destroy()
    assert [str(p.GetPath()) for p in rep.functional.get.renderproduct()] == [rp.path]


def test_create_batch_camera_poses_each_camera():
    positions = np.array([[0.0, 0.0, 5.0], [3.0, 0.0, 5.0], [0.0, -3.0, 2.0]])
    rep.functional.create.xform(name="World")
    cams = rep.functional.create_batch.camera(count=3, position=positions, look_at=(0, 0, 0), parent="/World",
                                              name="Camera", focal_length=35.0)
    assert [str(c.GetPath()) for c in cams] == ["/World/Camera", "/World/Camera_01", "/World/Camera_02"]
    for cam, position in zip(cams, positions):
        m = UsdGeom.Xformable(cam).ComputeLocalToWorldTransform(0)
        assert np.allclose(m.ExtractTranslation(), position)
        forward = -np.array(m.TransformDir(Gf.Vec3d(0, 0, 1)))   # cameras look down their -Z
        assert np.allclose(forward, -position / np.linalg.norm(position), atol=1e-6)
        assert UsdGeom.Camera(cam).GetFocalLengthAttr().Get() == pytest.approx(35.0)
    with pytest.raises(ValueError, match="count"):
        rep.functional.create_batch.camera(count=0)
    with pytest.raises(ValueError, match="rows but count"):
        rep.functional.create_batch.camera(count=2, position=positions)


def test_stable_id_map_lists_the_drawn_gprims_with_instance_segmentation_ids():
    _, _, rp = unit_cube_scene(resolution=(32, 24))
    rep.functional.create.sphere(position=(0.0, 3.0, 0.0), parent="/World", name="Ball")
    sid = rep.annotators.get("StableIdMap").attach(rp)
    seg = rep.annotators.get("instance_id_segmentation").attach(rp)
    rep.orchestrator.step()
    raw = sid.get_data()
    assert raw.dtype == np.uint8
    mapping = decode_stable_id_map(raw)
    assert sorted(mapping.values()) == ["/World/Ball", "/World/Cube"]
    seg_labels = seg.get_data()["info"]["idToLabels"]
    for stable_id, path in mapping.items():
        if str(stable_id) in seg_labels:   # the gprims in view: the same id in both annotators
            assert seg_labels[str(stable_id)] == path
    assert "/World/Cube" in seg_labels.values()
    # the layout Isaac parses: 24-byte entries, then the paths, then the count
    assert int(np.frombuffer(raw[-4:].tobytes(), "<u4")[0]) == 2
    words = np.frombuffer(raw[:48].tobytes(), "<u4").reshape(2, 6)
    assert all(raw[w[5]:w[5] + w[4]].tobytes().decode() in mapping.values() for w in words)
    big = {2 ** 100 + 7: "/A", 3: "/Bé"}
    assert decode_stable_id_map(encode_stable_id_map(big)) == big


def test_isaac_time_and_noop_annotators():
    _, _, rp = unit_cube_scene(resolution=(16, 12))
    sim_time = rep.annotators.get("IsaacReadSimulationTime")
    sim_time.initialize(resetOnStop=True)
    sim_time.attach(rp)
    system_time = rep.annotators.get("IsaacReadSystemTime").attach(rp)
    reference = rep.annotators.get("ReferenceTime").attach(rp)
    noop = rep.annotators.get("IsaacNoop").attach(rp)
    rep.orchestrator.step(delta_time=0.25)
    rep.orchestrator.step(delta_time=0.25)
    ref = reference.get_data()
    assert sim_time.get_data()["simulationTime"] == pytest.approx(
        ref["referenceTimeNumerator"] / ref["referenceTimeDenominator"])
    assert sim_time.get_data()["simulationTime"] == pytest.approx(0.5)
    assert abs(system_time.get_data()["systemTime"] - time.time()) < 5.0
    assert noop.get_data() == {}
    with pytest.raises(ValueError, match="resetOnStop=False"):
        rep.annotators.get("IsaacReadSimulationTime").initialize(resetOnStop=False)
    with pytest.raises(ValueError, match="no init param"):
        rep.annotators.get("IsaacNoop").initialize(colorize=True)


def test_render_product_tiled_says_what_to_do_instead():
    cams = rep.functional.create_batch.camera(count=2, position=[(0, 0, 5), (0, 0, 9)])
    with pytest.raises(NotImplementedError, match="one render product per camera"):
        rep.create.render_product_tiled(cameras=[str(c.GetPath()) for c in cams], tile_resolution=(32, 32))
    products = rep.create.render_product([str(c.GetPath()) for c in cams], (32, 32))   # the suggested form
    assert [p.camera for p in products] == [str(c.GetPath()) for c in cams]
