"""What a scan becomes: the GMO byte layout Isaac's parser reads, point-cloud files, determinism."""
from __future__ import annotations

import json
import os
import struct

import numpy as np

import graphsdg as rep
from graphsdg.io.point_cloud_files import read_pcd, read_ply
from graphsdg.sensors.generic_model_output import (HEADER_SIZE, MAGIC_NUMBER, AuxType, GmoContent, LidarAuxHas,
                                                   Modality, decode, encode)
from graphsdg.sensors.lidar_profile import EmitterState, LidarProfile, author_lidar_profile


def test_gmo_header_offsets_are_isaacs():
    n = 3
    content = GmoContent(modality=Modality.LIDAR, x=np.array([1.0, 2, 3]), y=np.zeros(n), z=np.array([4.0, 5, 6]),
                         scalar=np.full(n, 0.5), time_offset_ns=np.array([0, 10, 20], np.int32), timestamp_ns=77,
                         aux_type=AuxType.EXTRA,
                         lidar_members=LidarAuxHas.EMITTER_ID | LidarAuxHas.MAT_ID | LidarAuxHas.OBJ_ID,
                         aux={"emitterId": np.array([7, 8, 9]), "matId": np.array([1, 2, 3]),
                              "objId": np.arange(48, dtype=np.uint8)})
    raw = encode(content).tobytes()
    magic, major, minor, patch = struct.unpack_from("<4I", raw, 0)
    size, count = struct.unpack_from("<QI", raw, 16)          # Isaac reads the size at bytes 16-23
    assert (magic, major, minor, patch, size, count) == (MAGIC_NUMBER, 1, 0, 0, len(raw), n)
    assert struct.unpack_from("<Q", raw, 40)[0] == 77           # timestampNs
    assert struct.unpack_from("<II", raw, 200) == (AuxType.EXTRA, Modality.LIDAR)
    # elements right after the 264-byte header: timeOffsetNs, x, y, z, scalar, flags, padded to 8 bytes
    assert np.frombuffer(raw, "<i4", n, HEADER_SIZE).tolist() == [0, 10, 20]
    assert np.frombuffer(raw, "<f4", n, HEADER_SIZE + 4 * n).tolist() == [1, 2, 3]
    aux = HEADER_SIZE + (4 * 5 + 1) * n + 1                     # 63 bytes of elements, 1 of padding
    assert struct.unpack_from("<I", raw, aux + 8)[0] == int(content.lidar_members)
    # members after the 88-byte block in the header's order: emitter, channel, material, tick, ..., object ids
    assert np.frombuffer(raw, "<u4", n, aux + 88).tolist() == [7, 8, 9]
    assert np.frombuffer(raw, "<u4", n, aux + 88 + 12).tolist() == [1, 2, 3]
    assert np.frombuffer(raw, np.uint8, 48, aux + 88 + 24).tolist() == list(range(48))
    back = decode(raw)
    assert back.emitterId.tolist() == [7, 8, 9] and back.matId.tolist() == [1, 2, 3] and back.objId.size == 48
    assert decode(b"\0" * 300).magicNumber == 0


def _lidar_scene(seed_noise: bool = False):
    rep.functional.create.cube(position=(0, 0, -0.5), scale=(20, 20, 1), name="Floor", semantics={"class": "floor"})
    rep.functional.create.cube(position=(4, 0, 1), scale=(1, 2, 2), name="Crate", semantics={"class": "crate"})
    profile = LidarProfile(name="t", scan_type="ROTARY", scan_rate_hz=10, firing_rate_hz=10 * 72,
                           emitter_states=(EmitterState.uniform(8, 10.0, -30.0),), min_reflectance_range_m=1000.0,
                           range_accuracy_m=0.02 if seed_noise else 0.0)
    lidar = rep.functional.create.omni_lidar(position=(0, 0, 1), name="Lidar")
    author_lidar_profile(lidar, profile)
    return rep.create.render_product(lidar, (1, 1))


def test_point_cloud_writer_files_hold_the_annotators_points_ids_and_labels(tmp_path):
    rp = _lidar_scene()
    writer = rep.writers.get("PointCloudWriter")
    writer.initialize(output_dir=str(tmp_path), formats=["npy", "ply", "pcd"])
    writer.attach(rp)
    cloud = rep.annotators.get("sensor_point_cloud", init_params={"frame": "world"}).attach(rp)
    rep.orchestrator.step(delta_time=0)
    rep.orchestrator.wait_until_complete()
    stem = os.path.join(str(tmp_path), rp.name, "pointcloud_0000")
    npy = np.load(stem + ".npy")
    with open(stem + ".ply", "rb") as f:
        ply = read_ply(f.read())
    with open(stem + ".pcd", "rb") as f:
        pcd = read_pcd(f.read())
    points = cloud.get_data()["data"]
    assert len(npy) == len(points) > 100
    np.testing.assert_array_equal(np.stack([npy["x"], npy["y"], npy["z"]], 1), points)
    for other in (ply, pcd):
        np.testing.assert_array_equal(other["x"], npy["x"])
        np.testing.assert_array_equal(other["object_id"], npy["object_id"])
    with open(stem + ".json") as f:
        meta = json.load(f)
    classes = {meta["objects"][str(i)]["labels"]["class"][0] for i in np.unique(npy["object_id"])}
    assert classes == {"floor", "crate"}
    crate = npy["object_id"] == [int(k) for k, v in meta["objects"].items() if v["path"] == "/Crate"][0]
    assert np.all(np.abs(npy["x"][crate] - 3.5) < 1e-4)        # the crate's near face


def test_noisy_scans_repeat_exactly_with_the_same_seed():
    def scan_bytes():
        rep.stage.new_stage()
        rp = _lidar_scene(seed_noise=True)
        gmo = rep.annotators.get("GenericModelOutput").attach(rp)
        rep.orchestrator.step(delta_time=0)
        return gmo.get_data().tobytes()
    rep.set_global_seed(5)
    first = scan_bytes()
    second = scan_bytes()
    rep.set_global_seed(6)
    third = scan_bytes()
    assert first == second and first != third
    z = decode(first).z
    assert np.std(np.diff(np.sort(z))) > 0                      # noise is there
