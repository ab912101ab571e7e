"""Lidar scans against analytic truth: ranges in a box room and to a plane, a moving box seen where it was
when each beam fired, accumulation and timing, ids against a camera's segmentation, bad input."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, UsdGeom

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.sensors.generic_model_output import decode
from graphsdg.sensors.lidar_profile import EmitterState, LidarProfile, LidarProfileError, author_lidar_profile
from graphsdg.sensors.profile_catalog import lidar_profile

ROOM = (5.0, 4.0, 3.0)   # half extents of the room's inside: walls at x = +-5, y = +-4, floor z = 0, ceiling z = 6


def box_room():
    hx, hy, hz = ROOM
    walls = [((hx + 0.5, 0, hz), (1, 2 * hy + 2, 2 * hz + 2)), ((-hx - 0.5, 0, hz), (1, 2 * hy + 2, 2 * hz + 2)),
             ((0, hy + 0.5, hz), (2 * hx + 2, 1, 2 * hz + 2)), ((0, -hy - 0.5, hz), (2 * hx + 2, 1, 2 * hz + 2)),
             ((0, 0, -0.5), (2 * hx + 2, 2 * hy + 2, 1)), ((0, 0, 2 * hz + 0.5), (2 * hx + 2, 2 * hy + 2, 1))]
    for i, (pos, scale) in enumerate(walls):
        rep.functional.create.cube(position=pos, scale=scale, name=f"wall_{i}",
                                   semantics={"class": "floor" if i == 4 else "wall"})


def small_rotary(channels=16, columns=90, rate=10.0, top=40.0, bottom=-60.0, spacing_ns=0.0) -> LidarProfile:
    return LidarProfile(name="small", scan_type="ROTARY", scan_rate_hz=rate, firing_rate_hz=rate * columns,
                        emitter_states=(EmitterState.uniform(channels, top, bottom, spacing_ns),),
                        near_range_m=0.1, far_range_m=100.0, min_reflectance_range_m=1000.0)


def lidar_at(position, profile, name="Lidar", **attributes):
    prim = rep.functional.create.omni_lidar(position=position, name=name)
    author_lidar_profile(prim, profile)
    for key, value in attributes.items():
        prim.GetAttribute(key).Set(value)
    return prim


def gmo_of(rp):
    annotator = rep.annotators.get("GenericModelOutput").attach(rp)
    return annotator


def test_box_room_ranges_match_geometry_within_a_millimetre():
    box_room()
    origin = np.array([1.0, -0.5, 1.5])
    lidar = lidar_at(origin, small_rotary())
    rp = rep.create.render_product(lidar, (1, 1))
    gmo = gmo_of(rp)
    rep.orchestrator.step(delta_time=0)          # no time passes: one whole scan as a snapshot
    out = decode(gmo.get_data())
    assert out.numElements == 16 * 90            # a closed room: every beam returns
    az, el, rng = np.radians(out.x), np.radians(out.y), out.z.astype(np.float64)
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    hx, hy, hz = ROOM
    with np.errstate(divide="ignore"):
        t = np.stack([np.where(d[:, 0] > 0, (hx - origin[0]) / d[:, 0], (-hx - origin[0]) / d[:, 0]),
                      np.where(d[:, 1] > 0, (hy - origin[1]) / d[:, 1], (-hy - origin[1]) / d[:, 1]),
                      np.where(d[:, 2] > 0, (2 * hz - origin[2]) / d[:, 2], -origin[2] / d[:, 2])], axis=1)
    expected = np.min(np.where(t > 0, t, np.inf), axis=1)
    assert np.abs(rng - expected).max() < 1e-3


def test_plane_at_a_known_distance():
    rep.functional.create.cube(position=(7.5, 0, 0), scale=(1, 40, 40), name="Plane")
    profile = LidarProfile(name="fan", scan_type="SOLID_STATE", scan_rate_hz=10, firing_rate_hz=10,
                           emitter_states=(EmitterState.grid((-30.0, 30.0), 7, (20.0, -20.0), 5, 1e8),),
                           min_reflectance_range_m=1000.0)
    lidar = lidar_at((0, 0, 0), profile)
    rp = rep.create.render_product(lidar, (1, 1))
    gmo = gmo_of(rp)
    rep.orchestrator.step(delta_time=0)
    out = decode(gmo.get_data())
    assert out.numElements == 35
    expected = 7.0 / (np.cos(np.radians(out.x)) * np.cos(np.radians(out.y)))
    np.testing.assert_allclose(out.z, expected, atol=1e-4)


def test_moving_box_is_seen_where_it_was_when_each_beam_fired():
    """A box approaching at 3 m/s: a beam fired dt before the capture sees its face 3 * dt farther."""
    rep.functional.physics.create_physics_scene(gravity_magnitude=0.0)
    box = rep.functional.create.cube(position=(6.5, 0, 0), scale=(1, 6, 6), name="Box")
    rep.functional.physics.apply_rigid_body(box, disableGravity=True)
    speed = 3.0
    # one beam straight ahead fired 40 times a frame (every 1/2400 s), so each sees the box at another time
    profile = LidarProfile(name="ahead", scan_type="ROTARY", scan_rate_hz=60.0, firing_rate_hz=2400.0,
                           emitter_states=(EmitterState.uniform(1, 0.0, 0.0),), valid_start_azimuth_deg=-180,
                           valid_end_azimuth_deg=180, min_reflectance_range_m=1000.0)
    profile = profile.with_values(emitter_states=(EmitterState(np.array([0.0]), np.array([0.0]),
                                                               np.array([0]), np.array([0])),),
                                  scan_type="SOLID_STATE", firing_rate_hz=2400.0)
    lidar = lidar_at((0, 0, 0), profile)
    rp = rep.create.render_product(lidar, (1, 1))
    gmo = gmo_of(rp)
    sim = runtime().sim
    sim.set_body_velocity(str(box.GetPath()), linear=(-speed, 0, 0))
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    for _ in range(3):
        rep.orchestrator.step(pause_timeline=False)
    out = decode(gmo.get_data())
    now = float(sim.data.time)
    face_now = float(sim.body_pose(str(box.GetPath()))[0][0]) - 0.5
    fired = (out.timestampNs + out.timeOffsetNs.astype(np.int64)) * 1e-9
    assert out.numElements >= 30 and np.ptp(fired) > 0.01
    expected = face_now + speed * (now - fired)
    np.testing.assert_allclose(out.z, expected, atol=1e-6)


def test_accumulated_scans_come_whole_once_per_period():
    box_room()
    lidar = lidar_at((0, 0, 1), small_rotary(channels=4, columns=60, rate=10.0, spacing_ns=1000.0),
                     **{"omni:sensor:Core:accumulateOutputs": True})
    rp = rep.create.render_product(lidar, (1, 1))
    gmo = gmo_of(rp)
    cloud = rep.annotators.get("sensor_point_cloud").attach(rp)
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    whole, between = [], 0
    for _ in range(20):
        rep.orchestrator.step(pause_timeline=False)
        out = decode(gmo.get_data())
        held = cloud.get_data()
        if out.numElements:
            whole.append(out)
            assert held["info"]["fresh"] and len(held["data"]) == out.numElements
        else:       # no new report: an empty GMO (as RTX), the point cloud holds the last report
            between += 1
            assert not held["info"]["fresh"]
            assert len(held["data"]) == (whole[-1].numElements if whole else 0)
    assert [o.timestampNs for o in whole] == [0, 100_000_000, 200_000_000] and between == 20 - 3
    assert all(o.scanComplete == 0 for o in whole)          # aux NONE: no auxiliary block
    assert whole[1].numElements == 4 * 60
    offsets = whole[1].timeOffsetNs
    assert np.all(np.diff(offsets) >= 0) and offsets.max() < 100_000_000


def test_returns_ids_agree_with_a_cameras_segmentation_at_the_lidars_pose():
    rep.functional.create.dome_light(intensity=500)
    for i, (y, z, label) in enumerate([(-1.5, 0.0, "crate"), (0.0, 0.5, "barrel"), (1.5, -0.5, "cone")]):
        rep.functional.create.cube(position=(6, y, z), scale=(0.5, 1.0, 1.0), name=f"Obj{i}",
                                   semantics={"class": label})
    rep.functional.create.cube(position=(9, 0, 0), scale=(0.5, 10, 10), name="Back", semantics={"class": "wall"})
    profile = LidarProfile(name="grid", scan_type="SOLID_STATE", scan_rate_hz=10, firing_rate_hz=10,
                           emitter_states=(EmitterState.grid((-30.0, 30.0), 41, (20.0, -20.0), 21, 1e8),),
                           min_reflectance_range_m=1000.0)
    lidar = lidar_at((0, 0, 0), profile)
    camera = rep.functional.create.camera(position=(0, 0, 0), look_at=(1, 0, 0), look_at_up_axis=(0, 0, 1))
    UsdGeom.Camera(camera).GetHorizontalApertureAttr().Set(20.955 * 2)   # wide enough to cover the lidar's field
    cam_rp = rep.create.render_product(camera, (128, 128))
    lidar_rp = rep.create.render_product(lidar, (1, 1))
    seg = rep.annotators.get("semantic_segmentation").attach(cam_rp)
    cloud = rep.annotators.get("sensor_point_cloud", init_params={"frame": "world"}).attach(lidar_rp)
    params = rep.annotators.get("camera_params").attach(cam_rp)
    rep.orchestrator.step(delta_time=0)
    points = cloud.get_data()["data"]
    semantic = cloud.get_data()["info"]["semanticId"]
    image = seg.get_data()["data"]
    view = np.asarray(params.get_data()["cameraViewTransform"]).reshape(4, 4)
    proj = np.asarray(params.get_data()["cameraProjection"]).reshape(4, 4)
    homogeneous = np.c_[points, np.ones(len(points))] @ view @ proj
    ndc = homogeneous[:, :2] / homogeneous[:, 3:4]
    px = np.floor((ndc[:, 0] + 1) / 2 * 128).astype(int)
    py = np.floor((1 - ndc[:, 1]) / 2 * 128).astype(int)
    inside = (px >= 1) & (px < 127) & (py >= 1) & (py < 127)
    assert inside.sum() > 500
    agree = image[py[inside], px[inside]] == semantic[inside]
    assert agree.mean() > 0.97
    labels = {int(k): v for k, v in seg.get_data()["info"]["idToLabels"].items()}
    assert {labels[int(s)]["class"] for s in np.unique(semantic)} == {"crate", "barrel", "cone", "wall"}


def test_stable_ids_are_those_of_the_stable_id_map():
    box_room()
    lidar = lidar_at((0, 0, 1), small_rotary(channels=8, columns=36), **{"omni:sensor:Core:auxOutputType": "EXTRA"})
    rp = rep.create.render_product(lidar, (1, 1))
    gmo = gmo_of(rp)
    sid = rep.annotators.get("StableIdMap").attach(rp)
    rep.orchestrator.step(delta_time=0)
    from graphsdg.nodes.isaac_annotators import decode_stable_id_map
    out = decode(gmo.get_data())
    mapping = decode_stable_id_map(sid.get_data())
    ids = out.objId.reshape(-1, 16)
    assert not ids[:, 8:].any()                          # 64-bit ids in the 128-bit field
    stable = ids[:, :8].copy().view("<u8").reshape(-1)
    paths = {mapping[int(i)] for i in np.unique(stable)}
    assert paths <= {f"/wall_{k}" for k in range(6)} and len(paths) >= 4
    # each return's id is the wall the ray geometrically meets first
    az, el = np.radians(out.x), np.radians(out.y)
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    hits = np.array([0.0, 0.0, 1.0]) + d * out.z[:, None]
    hx, hy, hz = ROOM
    nearest = np.argmin(np.abs(np.stack([hits[:, 0] - hx, hits[:, 0] + hx, hits[:, 1] - hy, hits[:, 1] + hy,
                                         hits[:, 2], hits[:, 2] - 2 * hz], axis=1)), axis=1)
    names = np.array([mapping[int(i)] for i in stable])
    corner = np.sort(np.abs(np.stack([hits[:, 0] - hx, hits[:, 0] + hx, hits[:, 1] - hy, hits[:, 1] + hy,
                                      hits[:, 2], hits[:, 2] - 2 * hz], axis=1)), axis=1)[:, 1] < 1e-3
    assert np.all(names[~corner] == np.array([f"/wall_{k}" for k in nearest])[~corner])


def test_unknown_config_negative_range_and_missing_parent_fail_naming_them():
    with pytest.raises(KeyError, match="NoSuchLidar"):
        lidar_profile("NoSuchLidar")
    with pytest.raises(LidarProfileError, match="nearRangeM must be >= 0 m, got -1.0"):
        small_rotary().with_values(near_range_m=-1.0)
    lidar = lidar_at((0, 0, 0), small_rotary())
    lidar.GetAttribute("omni:sensor:Core:farRangeM").Set(-5.0)
    rp = rep.create.render_product(lidar, (1, 1))
    gmo_of(rp)
    with pytest.raises(LidarProfileError, match=r"lidar /Lidar: farRangeM must be >= 0 m, got -5.0"):
        rep.orchestrator.step(delta_time=0)
    with pytest.raises(Exception, match="parent '/Nowhere' does not exist"):
        rep.functional.create.omni_lidar(parent="/Nowhere")


def test_every_profile_family_and_variant_builds():
    from graphsdg.sensors.profile_catalog import lidar_config_names
    names = lidar_config_names()
    assert {"Example_Rotary", "OS1", "HESAI_XT32_SD10", "SICK_picoScan100", "ZVISION_ML30S"} <= set(names)
    for name in names:
        p = lidar_profile(name)
        assert p.ticks_per_scan >= 1 and p.far_range_m > p.near_range_m
    os1 = lidar_profile("OS1", "OS1_REV6_32ch20hz512res")
    assert (os1.channels, os1.scan_rate_hz, os1.ticks_per_scan, os1.far_range_m) == (32, 20.0, 512, 120.0)
    pico = lidar_profile("SICK_picoScan100", {"Product": "picoScan150Core", "Profile": "Profile02_15Hz_0p33deg"})
    assert (pico.scan_rate_hz, pico.ticks_per_scan, pico.far_range_m) == (15.0, 1091, 40.0)
