"""Episode recording and replay (graphsdg.episodes): HDF5 sessions of simulated state, put back on the stage.

The truth a recording is checked against is the simulation itself: an observer
after the recorder's own, at every physics step, reads the Franka's joint
values and its links' MuJoCo frames, and the free cube's pose.
"""
from __future__ import annotations

import doctest
import importlib
import json
import os
import sys

import h5py
import mujoco
import numpy as np
import pytest
from pxr import Gf, Sdf, UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg import episodes
from graphsdg.assets import get_assets_root_path
from graphsdg.episodes import (ArticulationRecordable, AttributeRecordable, CameraRecordable, ChannelDescriptor,
                               EpisodeRecorder, EpisodeReplayer, ReplayPolicy, RigidBodyRecordable,
                               SamplingConfig, SessionReader, XformRecordable, target_discovery)
from graphsdg.physics.articulation_dofs import ArticulationDofs
from graphsdg.physics.joint_fit import fit_joint_positions
from graphsdg.engine.runtime import runtime
from graphsdg.sim import physics_steps

FRANKA = "/Isaac/Robots/FrankaRobotics/FrankaPanda/franka.usd"


def build_scene():
    """/World with a physics scene, the Franka (referenced, as Isaac's example does) and a small falling cube."""
    stage = rep.stage.get_stage()
    stage.DefinePrim("/World", "Xform")
    stage.DefinePrim("/World/PhysicsScene", "PhysicsScene")
    stage.DefinePrim("/World/Franka", "Xform").GetReferences().AddReference(get_assets_root_path() + FRANKA)
    cube = UsdGeom.Cube.Define(stage, "/World/Cube")
    cube.CreateSizeAttr(0.1)
    cube.AddTranslateOp().Set(Gf.Vec3d(0.6, 0.6, 1.0))
    UsdPhysics.RigidBodyAPI.Apply(cube.GetPrim())
    UsdPhysics.CollisionAPI.Apply(cube.GetPrim())
    return stage


class Truth:
    """What the simulation holds after each physics step (observed after the recorder samples)."""

    def __init__(self, dofs: ArticulationDofs, links: list[str]):
        self.dofs, self.links = dofs, links
        self.q, self.link_pos, self.link_quat, self.cube = [], [], [], []
        self.handle = physics_steps.subscribe(False, 10, self._observe)

    def _observe(self, step_size):
        c = runtime().sim.compiled
        mujoco.mj_kinematics(c.model, c.data)
        self.q.append(self.dofs.get_positions())
        ids = [c.bodies[p].body_id for p in self.links]
        self.link_pos.append(c.data.xpos[ids].copy())
        self.link_quat.append(c.data.xquat[ids].copy())
        b = c.bodies["/World/Cube"]
        self.cube.append(c.data.qpos[b.qpos_adr:b.qpos_adr + 7].copy())

    def stop(self):
        physics_steps.unsubscribe(self.handle)


def record(tmp_path, updates=12, **recorder_args):
    """Record one episode of the driven Franka and the falling cube; (session path, truth, recorder)."""
    build_scene()
    arts, prims = target_discovery.discover_all_under("/World")
    assert arts == {"Franka": "/World/Franka"} and prims == {"Cube": "/World/Cube"}
    recorder = EpisodeRecorder(str(tmp_path), session_metadata={"task": "test"}, **recorder_args)
    recorder.add(ArticulationRecordable(group="state/Franka", prim_path="/World/Franka"))
    recorder.add(RigidBodyRecordable(group="state/Cube", prim_path="/World/Cube"))
    path = recorder.open_session()
    timeline = runtime().timeline
    timeline.play()
    rep.orchestrator.update()
    dofs = ArticulationDofs("/World/Franka")
    links = recorder.recordables()[1].link_paths[1:]   # the root xform is not a body
    truth = Truth(dofs, links)
    recorder.start_episode(metadata={"take": 1})
    for i in range(updates):
        dofs.set_position_targets(0.4 * np.sin(0.5 * i + np.arange(len(dofs.dofs))))
        rep.orchestrator.update()
    recorder.end_episode(success=True)
    truth.stop()
    timeline.stop()
    recorder.close_session()
    return path, truth, recorder


def test_recorded_link_poses_are_the_simulated_ones_and_give_back_the_joint_values(tmp_path):
    path, truth, _ = record(tmp_path)
    with SessionReader(path) as reader:
        assert reader.list_episodes() == ["episode_00000"]
        n = reader.num_frames(0)
        assert n == len(truth.q) == 24            # one frame per 120 Hz physics step, two per app update
        positions = reader.read_channel(0, "state/Franka", "positions")
        orientations = reader.read_channel(0, "state/Franka", "orientations")
        assert positions.shape == (n, 12, 3) and orientations.shape == (n, 12, 4)
        np.testing.assert_allclose(positions[:, 1:], np.array(truth.link_pos), atol=2e-6)
        signs = np.sign(np.sum(orientations[:, 1:] * np.array(truth.link_quat), axis=-1, keepdims=True))
        np.testing.assert_allclose(orientations[:, 1:] * signs, np.array(truth.link_quat), atol=2e-6)
        np.testing.assert_allclose(positions[:, 0], 0.0)        # /World/Franka itself does not move
        cube = reader.read_group_all_frames(0, "state/Cube")
        np.testing.assert_allclose(cube["position"], np.array(truth.cube)[:, :3], atol=2e-6)
        steps = reader.read_channel(0, "meta/time", "physics_step")
        np.testing.assert_array_equal(np.diff(steps), 1)
        np.testing.assert_allclose(np.diff(reader.read_channel(0, "meta/time", "sim_time")), 1 / 120, atol=1e-9)
        attrs = reader.episode_attrs(0)
        assert attrs["success"] and attrs["num_frames"] == n and attrs["user_metadata"] == {"take": 1}
        assert reader.manifest().session == {"task": "test"}
        assert reader.root_attrs()["task"] == "test"
    # the recorded link frames determine the joint values: solving them gives the simulated DOF states
    c = runtime().sim.ensure_compiled()
    ids = [c.bodies[p].body_id for p in truth.links]
    assert np.ptp(np.array(truth.q)[:, :7], axis=0).min() > 1e-3      # every arm joint moved
    for f in (0, n // 2, n - 1):
        fit_joint_positions(c.model, c.data, {b: (positions[f, 1 + k], orientations[f, 1 + k])
                                              for k, b in enumerate(ids)})
        np.testing.assert_allclose(ArticulationDofs("/World/Franka").get_positions(), truth.q[f], atol=2e-5)


def test_replay_puts_the_recorded_poses_back_and_stopping_reverts_them(tmp_path):
    path, truth, _ = record(tmp_path, updates=6)
    rep.stage.new_stage()
    stage = build_scene()
    root_layer_before = stage.GetRootLayer().ExportToString()
    dofs = ArticulationDofs("/World/Franka")
    q_before = dofs.get_positions().copy()
    links = truth.links
    seen = []

    def check(f):
        c = runtime().sim.compiled
        np.testing.assert_allclose(ArticulationDofs("/World/Franka").get_positions(), truth.q[f], atol=2e-5)
        ids = [c.bodies[p].body_id for p in links]
        np.testing.assert_allclose(c.data.xpos[ids], truth.link_pos[f], atol=2e-5)
        for k, p in enumerate(links):   # the stage shows the same poses (written back as simulated poses are)
            t = np.array(UsdGeom.Xformable(stage.GetPrimAtPath(p)).ComputeLocalToWorldTransform(0).ExtractTranslation())
            np.testing.assert_allclose(t, truth.link_pos[f][k], atol=2e-5)
        b = c.bodies["/World/Cube"]
        np.testing.assert_allclose(c.data.qpos[b.qpos_adr:b.qpos_adr + 3], truth.cube[f][:3], atol=2e-6)
        seen.append(f)

    replayer = EpisodeReplayer(path, policy=ReplayPolicy(strictness="strict"))
    assert replayer.session_metadata() == {"task": "test"}
    replayer.replay_episode(0, post_frame_hook=check, render_interval=3)
    assert seen == list(range(0, len(truth.q), 3))
    assert replayer.pose_batch_size == 13
    # edits went to the replay's own layer, not the stage's
    assert stage.GetRootLayer().ExportToString() == root_layer_before
    assert len(stage.GetSessionLayer().subLayerPaths) == 1
    replayer.close()
    assert len(stage.GetSessionLayer().subLayerPaths) == 0
    np.testing.assert_allclose(ArticulationDofs("/World/Franka").get_positions(), q_before, atol=1e-12)
    assert stage.GetEditTarget().GetLayer() == stage.GetRootLayer()


def test_replay_frames_render_the_replayed_robot(tmp_path):
    path, truth, _ = record(tmp_path, updates=6)
    rep.stage.new_stage()
    build_scene()
    camera = rep.create.camera(position=(1.6, 1.6, 1.2), look_at=(0.0, 0.0, 0.4))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rep.create.render_product(camera, (64, 64)))
    images = {}

    def capture(f):
        rep.orchestrator.step(delta_time=0.0, pause_timeline=False)
        images[f] = rgb.get_data()[..., :3].astype(int)

    with EpisodeReplayer(path) as replayer:
        replayer.replay_episode(0, post_frame_hook=capture, render_interval=len(truth.q) - 1)
    first, last = images[0], images[len(truth.q) - 1]
    assert np.abs(first - last).mean() > 0.5         # the arm moved between the first and last frames
    # the same frame replayed again draws the same pixels
    with EpisodeReplayer(path) as replayer:
        replayer.prepare_episode(0)
        replayer.apply_frame(0)
        rep.orchestrator.step(delta_time=0.0, pause_timeline=False)
        np.testing.assert_array_equal(rgb.get_data()[..., :3].astype(int), first)
    rgb.detach()


def test_session_layout_buffering_decimation_and_pause(tmp_path):
    build_scene()
    recorder = EpisodeRecorder(str(tmp_path), buffer_frames=4, sampling=SamplingConfig(decimation=2),
                               file_prefix="take")
    recorder.add(XformRecordable(group="world/cube", prim_path="/World/Cube"))
    recorder.add(XformRecordable(group="local/cube", prim_path="/World/Cube", space="local"))
    recorder.add(AttributeRecordable(group="attr/size", prim_path="/World/Cube", attribute_name="size"))
    events = []
    recorder.events.add_episode_ended(lambda i, s, n: events.append((i, s, n)))
    recorder.events.add_paused(lambda: events.append("paused"))
    path = recorder.open_session()
    assert os.path.basename(path).startswith("take_") and path.endswith(".hdf5")
    assert recorder.state == "session_open"
    with pytest.raises(RuntimeError, match="before open_session"):
        recorder.add(XformRecordable(group="late", prim_path="/World/Cube"))
    timeline = runtime().timeline
    timeline.play()
    recorder.start_episode()
    for _ in range(5):                    # 10 physics steps, every 2nd sampled
        rep.orchestrator.update()
    recorder.pause()
    for _ in range(3):
        rep.orchestrator.update()
    recorder.resume()
    rep.orchestrator.update()
    recorder.end_episode(success=False, metadata={"note": "x"})
    recorder.start_episode()
    rep.orchestrator.update()
    timeline.stop()
    recorder.close_session()               # ends the open episode, success unknown
    assert recorder.state == "closed"
    assert events == ["paused", (0, False, 6)]
    with h5py.File(path) as f:
        assert int(f.attrs["schema_version"]) == 2 and int(f.attrs["num_episodes"]) == 2
        ep = f["episodes/episode_00000"]
        assert int(ep.attrs["num_frames"]) == 6 and not ep.attrs["success"]
        assert json.loads(ep.attrs["user_metadata"]) == {"note": "x"}
        world = ep["world/cube/position"]
        assert world.shape == (6, 3) and world.chunks == (4, 3) and world.attrs["units"] == "meters"
        assert ep["world/cube/orientation"].attrs["quaternion_order"] == "wxyz"
        np.testing.assert_allclose(ep["local/cube/position"][:], world[:], atol=1e-6)   # /World is identity
        np.testing.assert_allclose(ep["attr/size/value"][:], 0.1)
        assert int(f["episodes/episode_00001"].attrs["num_frames"]) == 1
        assert "success" not in f["episodes/episode_00001"].attrs
        tracks = json.loads(f["manifest/tracks"][()])
        assert [t["type"] for t in tracks] == ["sim_time", "xform", "xform", "usd_attribute"]
        assert json.loads(f["manifest/sampling"][()]) == {"decimation": 2, "mode": "physics_post_step"}
        z = ep["world/cube/position"][:, 2]
        assert np.all(np.diff(z) < 0)       # falling, sampled every other step
        steps = ep["meta/time/physics_step"][:]
        assert np.diff(steps).tolist() == [2, 2, 2, 2, 8]   # the pause skipped three updates


def test_camera_recordable_and_strict_replay_errors(tmp_path):
    stage = build_scene()
    cam = rep.functional.create.camera(position=(0, 0, 5), name="Cam", parent="/World")
    recorder = EpisodeRecorder(str(tmp_path), auto_attach_sim_time=False, sampling=SamplingConfig("app_update"))
    recorder.add(CameraRecordable(group="cam", prim_path=str(cam.GetPath()), resolution=(64, 48)))
    path = recorder.open_session()
    runtime().timeline.play()
    recorder.start_episode()
    for i in range(3):
        cam.GetAttribute("focalLength").Set(20.0 + i)
        rep.functional.modify.pose(cam, position_value=(i, 0, 5))
        rep.orchestrator.update()
    recorder.end_episode()
    runtime().timeline.stop()
    recorder.close_session()
    with SessionReader(path) as reader:
        frames = reader.read_group_all_frames(0, "cam")
        assert frames["focal_length"].tolist() == [20.0, 21.0, 22.0]
        np.testing.assert_allclose(frames["position"][:, 0], [0, 1, 2])
        assert reader.manifest().tracks == [{"type": "camera", "group": "cam", "prim_path": "/World/Cam",
                                             "resolution": [64, 48]}]
    cam.GetAttribute("focalLength").Set(50.0)
    with EpisodeReplayer(path, policy=ReplayPolicy("strict")) as replayer:
        replayer.prepare_episode(0)
        replayer.apply_frame(1)
        assert cam.GetAttribute("focalLength").Get() == 21.0
        np.testing.assert_allclose(UsdGeom.Xformable(cam).ComputeLocalToWorldTransform(0).ExtractTranslation(),
                                   (1, 0, 5), atol=1e-6)
        with pytest.raises(IndexError, match="out of range"):
            replayer.apply_frame(3)
    assert cam.GetAttribute("focalLength").Get() == 50.0     # stopping took the replay layer off
    stage.RemovePrim("/World/Cam")
    with pytest.raises(RuntimeError, match="/World/Cam"):
        EpisodeReplayer(path, policy=ReplayPolicy("strict")).prepare_episode(0)
    with EpisodeReplayer(path) as lenient:                   # best effort: the camera is skipped
        lenient.prepare_episode(0)
        assert lenient.prepared_recordables == []


def test_channel_policy_and_group_validation():
    with pytest.raises(ValueError, match="non-negative ints"):
        ChannelDescriptor(shape=(3, -1), dtype="f4")
    with pytest.raises(ValueError, match="not a NumPy dtype"):
        ChannelDescriptor(shape=(), dtype="float99")
    with pytest.raises(ValueError, match="'best_effort', 'strict'"):
        ReplayPolicy("lenient")
    with pytest.raises(ValueError, match="decimation"):
        SamplingConfig(decimation=0)
    with pytest.raises(ValueError, match="empty segments"):
        XformRecordable(group="a//b", prim_path="/x")
    rec = XformRecordable(group="/a/b/", prim_path="/x", space="local")
    assert rec.group == "a/b" and episodes.rehydrate(rec.to_manifest()).space == "local"
    with pytest.raises(KeyError, match="unknown recordable type 'nope'"):
        episodes.rehydrate({"type": "nope", "group": "g"})


def test_target_discovery_names_are_unique_and_safe():
    stage = rep.stage.get_stage()
    for path in ("/World/A/Box", "/World/B/Box", "/World/Würfel"):
        cube = UsdGeom.Cube.Define(stage, path)
        UsdPhysics.RigidBodyAPI.Apply(cube.GetPrim())
    UsdGeom.Xform.Define(stage, "/World/Marker")
    arts, prims = target_discovery.discover_all_under("/World", include_loose_xforms=True)
    assert arts == {}
    assert prims == {"W_rfel": "/World/Würfel", "Box": "/World/B/Box", "Box_1": "/World/A/Box",
                     "Marker": "/World/Marker"}      # /World/A and /World/B are typeless: no pose
    assert target_discovery.discover_rigid_bodies_under("/World", max_depth=1) == {"W_rfel": "/World/Würfel"}
    assert target_discovery.sanitize_name("3 d-cam") == "_3_d_cam" and target_discovery.sanitize_name("..") == "prim"
    with pytest.raises(ValueError, match="no prim at '/Nope'"):
        target_discovery.discover_all_under("/Nope")


def test_missing_h5py_names_the_extra(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "h5py", None)
    with pytest.raises(episodes.MissingHdf5Error, match=r"pip install 'graphsdg\[episodes\]'"):
        EpisodeRecorder(str(tmp_path)).open_session()


@pytest.mark.parametrize("name", ["graphsdg.episodes.recorder", "graphsdg.episodes.session_storage",
                                  "graphsdg.episodes.stage_snapshot", "graphsdg.episodes.target_discovery",
                                  "graphsdg.episodes.registry", "graphsdg.episodes.channels",
                                  "graphsdg.episodes.session_injectors", "graphsdg.episodes.session_events",
                                  "graphsdg.episodes.sim_clock", "graphsdg.physics.joint_fit",
                                  "graphsdg.physics.simulated_poses"])
def test_docstring_examples(name):
    assert doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS).failed == 0
