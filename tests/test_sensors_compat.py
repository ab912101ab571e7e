"""Isaac's sensor APIs in compat mode: authoring, configs and variants, runtimes, commands, LidarRtx, parsers,
debug-draw writers and the refusals of what graphsdg does not model."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError


@pytest.fixture
def compat():
    isaac.install()
    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    yield
    isaac.uninstall()


def run_frames(count: int) -> None:
    import omni.kit.app
    import omni.timeline
    omni.timeline.get_timeline_interface().play()
    for _ in range(count):
        omni.kit.app.get_app().update()


def test_lidar_wraps_creates_and_validates(compat):
    from isaacsim.sensors.experimental.rtx import Lidar
    lidar = Lidar("/World/lidar", tick_rate=30.0, aux_output_level="EXTRA",
                  attributes={"omni:sensor:Core:outputFrameOfReference": "WORLD"})
    prim = lidar.prims[0]
    assert prim.GetTypeName() == "OmniLidar" and prim.HasAPI("OmniSensorGenericLidarCoreAPI")
    assert prim.HasAPI("OmniSensorGenericLidarCoreEmitterStateAPI", "s001")          # built into the core API
    assert prim.GetAttribute("omni:sensor:tickRate").Get() == pytest.approx(30.0)
    assert prim.GetAttribute("omni:sensor:Core:accumulateOutputs").Get() is True
    assert prim.GetAttribute("_replicator:rendervar:GenericModelOutput:channels").Get() == ["EXTRA"]
    wrapped = Lidar("/World/lidar", schemas=["OmniSensorGenericLidarCoreEmitterStateAPI:s002"])
    assert wrapped.prims[0].HasAPI("OmniSensorGenericLidarCoreEmitterStateAPI", "s002")
    rep.functional.create.xform(name="xform", parent="/World")
    with pytest.raises(ValueError, match="is not an 'OmniLidar' prim but a 'Xform' prim"):
        Lidar("/World/xform")
    with pytest.raises(ValueError, match="Invalid aux_output_level 'ALL'"):
        Lidar("/World/other", aux_output_level="ALL")


def test_configs_and_variants_author_graphsdgs_profiles(compat):
    from isaacsim.sensors.experimental.rtx import SUPPORTED_LIDAR_CONFIGS, Lidar
    from graphsdg.compat.sensors_rtx_configs import config_key
    from graphsdg.sensors.profile_catalog import lidar_profile
    for path, variants in SUPPORTED_LIDAR_CONFIGS.items():   # every config Isaac lists, and every variant
        for variant in (list(variants) or [None]):
            lidar_profile(config_key(path), variant)
    lidar = Lidar.create("/World/os1", config="OS1", variant="OS1_REV6_32ch20hz1024res", translations=[0, 0, 1])
    prim = lidar.prims[0]
    assert prim.GetAttribute("omni:sensor:Core:numberOfChannels").Get() == 32
    assert prim.GetAttribute("omni:sensor:Core:scanRateBaseHz").Get() == pytest.approx(20.0)
    assert prim.GetAttribute("omni:sensor:Core:patternFiringRateHz").Get() == pytest.approx(20480.0)
    assert len(prim.GetAttribute("omni:sensor:Core:emitterState:s001:elevationDeg").Get()) == 32
    sick = Lidar.create("/World/sick", config="SICK picoScan100",
                        variant={"Product": "picoScan150Pro", "Profile": "Profile01_15Hz_0p5deg"})
    assert sick.prims[0].GetAttribute("omni:sensor:Core:validEndAzimuthDeg").Get() == pytest.approx(138.0)
    with pytest.raises(ValueError, match=r"Lidar config 'OS9' not found\. Did you mean: 'OS2', 'OS1', 'OS0'"):
        Lidar.create("/World/bad", config="OS9")
    with pytest.raises(ValueError, match=r"Lidar config 'OS1' has no variant 'OS1_REV9_1ch'"):
        Lidar.create("/World/bad", config="OS1", variant="OS1_REV9_1ch")


def test_lidar_sensor_gives_gmo_and_stable_ids_that_resolve_to_prims(compat):
    from isaacsim.core.experimental.objects import Cube
    from isaacsim.sensors.experimental.rtx import (Lidar, LidarSensor, parse_generic_model_output_data,
                                                   parse_object_ids, parse_stable_id_map_data)
    Cube("/World/front", positions=np.array([5.0, 0.0, 0.0]), scales=np.array([1.0, 4.0, 4.0]))
    lidar = Lidar.create("/World/lidar", config="Example_Rotary", translations=np.array([0, 0, 0.5]),
                         aux_output_level="FULL")
    sensor = LidarSensor(lidar, annotators=["generic-model-output", "stable-id-map"])
    assert sensor.annotators == ["generic-model-output", "stable-id-map"]
    counts = []
    for _ in range(12):                 # Example_Rotary reports a whole scan every 0.1 s, nothing in between
        run_frames(1)
        data, info = sensor.get_data("generic-model-output")
        gmo = parse_generic_model_output_data(data)
        counts.append(gmo.numElements)
        if gmo.numElements:
            break
    assert counts[:-1] == [0] * (len(counts) - 1) and len(counts) >= 5
    assert gmo.numElements > 0 and gmo.hitNormals.size == 3 * gmo.numElements
    mapping = parse_stable_id_map_data(sensor.get_data("stable-id-map")[0])
    assert {mapping[i] for i in parse_object_ids(gmo.objId)} == {"/World/front"}
    assert str(sensor.render_product.GetPath()).startswith("/Render/RenderProduct_rtx_sensor_")
    with pytest.raises(ValueError, match="Unsupported annotator 'rgb'"):
        LidarSensor(lidar, annotators=["rgb"])


def test_commands_and_lidar_rtx(compat, tmp_path):
    import omni.kit.commands
    from isaacsim.sensors.rtx import LidarRtx, get_gmo_data
    _, lidar = omni.kit.commands.execute("IsaacSensorCreateRtxLidar", path="lidar", parent=None,
                                         config="Example_Rotary_2D", translation=Gf.Vec3d(0, 0, 1),
                                         orientation=Gf.Quatd(0.70711, 0, 0, 0.70711),
                                         **{"omni:sensor:Core:auxOutputType": "BASIC"})
    assert str(lidar.GetPath()) == "/lidar" and lidar.GetAttribute("omni:sensor:Core:auxOutputType").Get() == "BASIC"
    _, again = omni.kit.commands.execute("IsaacSensorCreateRtxLidar", path="lidar", config="Example_Rotary_2D")
    assert str(again.GetPath()) == "/lidar_01"
    _, radar = omni.kit.commands.execute("IsaacSensorCreateRtxRadar", path="/World/radar")
    assert radar.GetTypeName() == "OmniRadar"
    with pytest.raises(Exception, match="parent '/Missing' does not exist"):
        omni.kit.commands.execute("IsaacSensorCreateRtxLidar", path="lidar", parent="/Missing")
    with pytest.raises(ValueError, match="Lidar config 'NoSuch' not found"):
        omni.kit.commands.execute("IsaacSensorCreateRtxLidar", path="lidar", config="NoSuch")
    for i, (x, y, sx, sy) in enumerate([(5.5, 0, 1, 12), (-5.5, 0, 1, 12), (0, 5.5, 12, 1), (0, -5.5, 12, 1)]):
        rep.functional.create.cube(position=(x, y, 0), scale=(sx, sy, 2), name=f"wall{i}")   # walls all round
    rtx = LidarRtx("/World/lidar2d", config_file_name="Example_Rotary_2D")
    rtx.initialize()
    rtx.attach_annotator("IsaacComputeRTXLidarFlatScan")
    rtx.attach_annotator("GenericModelOutput")
    run_frames(8)
    frame = rtx.get_current_frame()
    assert frame["rendering_time"] > 0 and get_gmo_data(frame["GenericModelOutput"]).numElements >= 0
    assert rtx.get_horizontal_fov() == pytest.approx(360.0) and rtx.get_num_cols() == 1440
    assert rtx.get_rotation_frequency() == pytest.approx(10.0)
    depth = frame["linear_depth_data"]
    seen = depth > 0
    azimuth = -180.0 + 0.25 * np.flatnonzero(seen)
    expected = 5.0 / np.maximum(np.abs(np.cos(np.radians(azimuth))), np.abs(np.sin(np.radians(azimuth))))
    assert seen.sum() > 100 and np.abs(depth[seen] - expected).max() < 0.05   # walls 5 m away (1 cm noise)


def test_debug_draw_writer_writes_coloured_clouds_and_refusals_name_themselves(compat, tmp_path):
    from isaacsim.sensors.experimental.rtx import Acoustic, Lidar, LidarSensor
    from graphsdg.io.point_cloud_files import read_ply
    rep.functional.create.cube(position=(3, 0, 0), scale=(1, 6, 6), name="Wall")
    sensor = LidarSensor(Lidar.create("/World/lidar", config="Simple_Example_Solid_State"), annotators=[])
    writer = sensor.attach_writer("draw-point-cloud", size=0.05, color=[0.0, 1.0, 0.5, 1.0],
                                  output_dir=str(tmp_path))
    run_frames(3)
    rep.orchestrator.wait_until_complete()
    files = sorted(p for p in tmp_path.rglob("*.ply"))
    assert files and type(writer).__name__ == "RtxSensorDebugDrawPointCloud"
    cloud = read_ply(files[0].read_bytes())
    assert set(cloud["green"].tolist()) == {255} and set(cloud["blue"].tolist()) == {128}
    assert np.all(np.abs(cloud["x"] - 2.5) < 1e-4)
    with pytest.raises(CompatError, match="acoustic"):
        Acoustic("/World/acoustic")
