"""Randomized poses written straight into MuJoCo (write-to-fabric): the vectorised arithmetic and caches."""
from __future__ import annotations

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.maths import rotations
from graphsdg.engine.runtime import runtime
from graphsdg.sim import mesh_scaling
from graphsdg.sim.pose_writes import mujoco_poses, targets


def test_euler_quaternions_match_the_matrix_route():
    angles = np.random.default_rng(1).uniform(-720, 720, (300, 3))
    angles[:5] = [[0, 0, 0], [180, 0, 0], [0, 180, 0], [0, 0, 180], [90, 90, 90]]
    quats = rotations.euler_xyz_to_quat(angles)
    ref = rotations.matrix_to_quat_wxyz(rotations.euler_to_matrix(angles))
    assert np.all(quats[:, 0] >= 0) and np.allclose(np.linalg.norm(quats, axis=1), 1.0)
    for q, r, a in zip(quats, ref, angles):
        # the same rotation: q and r agree, or are opposite where w = 0 leaves the sign open
        assert np.allclose(q, r, atol=1e-12) or np.allclose(q, -r, atol=1e-12), a
        assert np.allclose(rotations.quat_wxyz_to_matrix(q), rotations.euler_to_matrix(a, "XYZ"), atol=1e-12)


def test_quaternion_products_compose_rotations():
    rng = np.random.default_rng(2)
    a = rotations.euler_xyz_to_quat(rng.uniform(0, 360, (20, 3)))
    b = rotations.euler_xyz_to_quat(rng.uniform(0, 360, (20, 3)))
    for p, qa, qb in zip(rotations.quat_multiply(a, b), a, b):
        want = rotations.quat_wxyz_to_matrix(qa) @ rotations.quat_wxyz_to_matrix(qb)
        assert np.allclose(rotations.quat_wxyz_to_matrix(p), want, atol=1e-12)


def test_decompose_keeps_rotation_scale_and_mirror():
    r = rotations.euler_to_matrix((30, -50, 110), "XYZ")
    for s in ([1, 1, 1], [0.5, 2, 3], [-1, 2, 2]):
        m = np.eye(4)
        m[:3, :3] = (r * np.array(s)).T       # row-vector convention: rows are the scaled axes
        m[3, :3] = (1, 2, 3)
        t, rot, scale = rotations.decompose(m)
        assert np.allclose(t, (1, 2, 3))
        assert np.allclose(np.abs(scale), np.abs(s)) and np.isclose(np.prod(scale), np.prod(s))
        assert np.allclose(rot @ rot.T, np.eye(3), atol=1e-12) and np.isclose(np.linalg.det(rot), 1.0)
        assert np.allclose((rot * scale).T, m[:3, :3], atol=1e-12)


def test_decompose_drops_shear():
    m = np.eye(4)
    m[1, 0] = 0.3                             # y axis leans towards x
    _, rot, _ = rotations.decompose(m)
    assert np.allclose(rot @ rot.T, np.eye(3), atol=1e-12) and np.isclose(np.linalg.det(rot), 1.0)


@pytest.mark.parametrize("contiguous", [True, False])
def test_vertex_blocks_scale_like_one_mesh_at_a_time(contiguous):
    rng = np.random.default_rng(3)
    vert = rng.uniform(-1, 1, (40, 3)).astype(np.float32)
    starts, counts = (np.array([10, 0, 4]), np.array([6, 4, 6])) if contiguous else \
        (np.array([30, 2, 12]), np.array([5, 4, 9]))
    k = rng.uniform(0.1, 2.0, 3)
    want = vert.copy()
    for s, c, f in zip(starts, counts, k):
        want[s:s + c] *= float(f)
    mesh_scaling._scale_vertex_blocks(vert, starts, counts, k)
    np.testing.assert_array_equal(vert, want)


def _batch_scene():
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    rep.functional.create.xform(name="World")
    return rep.functional.create_batch.torus(count=3, parent="/World") + \
        rep.functional.create_batch.cone(count=2, parent="/World") + \
        rep.functional.create_batch.sphere(count=2, parent="/World")


def test_batched_mesh_rescale_matches_rescaling_one_by_one():
    prims = _batch_scene()
    sim = runtime().sim
    rep.functional.modify.pose(prims, scale_value=0.5)
    mesh_prims = prims[:5]
    geoms = np.array([sim.compiled.geoms[str(p.GetPath())].geom_id for p in mesh_prims])
    model = sim.model
    before = model.mesh_vert.copy(), model.geom_pos.copy(), model.geom_rbound.copy()
    new = np.repeat(np.linspace(0.3, 1.1, 5)[:, None], 3, axis=1)
    rep.functional.modify.pose(mesh_prims, scale_value=new)
    batched = model.mesh_vert.copy(), model.geom_pos.copy(), model.geom_rbound.copy()
    model.mesh_vert[:], model.geom_pos[:], model.geom_rbound[:] = before
    for g, s in zip(geoms, new):
        mesh_scaling.rescale_mesh_geom(model, int(g), np.full(3, 0.5), s)
    for got, want in zip(batched, (model.mesh_vert, model.geom_pos, model.geom_rbound)):
        np.testing.assert_allclose(got, want, rtol=1e-6)
    assert not np.allclose(batched[0], before[0])


def test_unevenly_scaled_sphere_falls_back_to_the_stage():
    prims = _batch_scene()
    sphere = prims[-1]
    assert mujoco_poses.write_poses(runtime().sim, [sphere], None, None, np.array([[1.0, 1.0, 1.0]]))
    assert not mujoco_poses.write_poses(runtime().sim, [sphere], None, None, np.array([[1.0, 2.0, 1.0]]))
    rep.functional.modify.pose([sphere], scale_value=[(1.0, 2.0, 1.0)])   # authored on the stage instead
    assert tuple(sphere.GetAttribute("xformOp:scale").Get()) == (1.0, 2.0, 1.0)


def test_cached_targets_follow_the_prims_passed():
    prims = _batch_scene()
    sim = runtime().sim
    a = targets.targets_for(sim, prims)
    assert targets.targets_for(sim, list(prims)) is a          # an equal list: the cached indices
    b = targets.targets_for(sim, prims[::-1])
    assert b is not a and list(b.geom_ids) == list(a.geom_ids)[::-1]
    rep.functional.modify.pose(prims[::-1], position_value=np.arange(21.0).reshape(7, 3))
    for i, p in enumerate(prims[::-1]):
        body = sim.compiled.geoms[str(p.GetPath())].body_id
        assert np.allclose(sim.data.xpos[body], np.arange(21.0).reshape(7, 3)[i])


def test_zero_quaternion_is_refused():
    prims = _batch_scene()
    with pytest.raises(ValueError, match="must not be zero"):
        mujoco_poses.write_poses(runtime().sim, prims[:1], None, np.zeros((1, 4)), None)


def test_poses_under_a_transformed_parent_match_authored_ones():
    """Direct writes compose with the parent's pose as the stage does (the quaternion product route)."""
    def world_poses(fabric: bool):
        rep.stage.new_stage()
        rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", fabric)
        parent = rep.functional.create.xform(name="Rig", position=(1, -2, 0.5), rotation=(20, 40, -70), scale=2.0)
        cubes = rep.functional.create_batch.cube(count=4, parent=parent)
        rng = np.random.default_rng(5)
        rep.functional.modify.pose(cubes, position_value=rng.uniform(-1, 1, (4, 3)),
                                   rotation_value=rng.uniform(0, 360, (4, 3)))
        authored = cubes[0].GetAttribute("xformOp:translate").Get()
        moved_on_stage = authored is not None and tuple(authored) != (0, 0, 0)
        assert moved_on_stage == (not fabric)                  # with fabric the poses go to MuJoCo only
        sim = runtime().sim
        sim.sync_dirty_prims()
        import mujoco
        mujoco.mj_kinematics(sim.model, sim.data)
        bodies = [sim.compiled.geoms[str(c.GetPath())].geom_id for c in cubes]
        return sim.data.geom_xpos[bodies].copy(), sim.data.geom_xmat[bodies].copy()

    pos_usd, mat_usd = world_poses(False)
    pos_fab, mat_fab = world_poses(True)
    np.testing.assert_allclose(pos_fab, pos_usd, atol=1e-9)
    np.testing.assert_allclose(mat_fab, mat_usd, atol=1e-9)


def test_bounding_radius_of_an_x_axis_cylinder_matches_a_compile():
    """Tubes not along z are sized one by one from USD; their bounding radius still uses the tube's
    half extents (radius, radius, half height), as the compiler's does."""
    def rbound(fabric: bool) -> float:
        rep.stage.new_stage()
        rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", fabric)
        cyl = rep.functional.create.cylinder(name="Tube")
        cyl.GetAttribute("axis").Set("X")
        sim = runtime().sim
        sim.sync_dirty_prims()
        sim.ensure_compiled()
        rep.functional.modify.pose([cyl], scale_value=[(1.0, 1.0, 3.0)])
        sim.sync_dirty_prims()
        return float(sim.model.geom_rbound[sim.compiled.geoms[str(cyl.GetPath())].geom_id])

    compiled = rbound(False)
    assert compiled > 1.0 and rbound(True) == pytest.approx(compiled, rel=1e-9)


def test_scales_stay_right_when_usd_and_direct_writes_alternate():
    """A direct write after a scale synced through USD starts from the synced scale (the bindings' scales are
    rows of one array; a binding given a new scale object is taken back into it)."""
    prims = _batch_scene()
    sim = runtime().sim
    cone = prims[0]
    rep.functional.modify.pose(prims, scale_value=0.5)                        # direct
    binding = sim.compiled.geoms[str(cone.GetPath())]
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", False)
    rep.functional.modify.pose([cone], scale_value=2.0)                        # through USD, synced
    sim.sync_dirty_prims()
    assert np.allclose(binding.scale, 2.0)
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", True)
    rep.functional.modify.pose(prims, scale_value=0.8)                        # direct again, from 2.0
    rbound = sim.model.geom_rbound[binding.geom_id]
    assert np.allclose(binding.scale, 0.8)
    compiled = sim.recompile(keep_state=False)                                  # the stage says 2.0 (USD)
    fresh = compiled.model.geom_rbound[compiled.geoms[str(cone.GetPath())].geom_id]
    assert np.isclose(rbound, fresh * 0.8 / 2.0, rtol=1e-5)


def test_a_batch_checked_valid_is_checked_again_after_a_removal():
    from graphsdg.errors import PrimNotFoundError
    from graphsdg.stage import prims as prim_lookup
    rep.functional.create.xform(name="World")
    cubes = rep.functional.create_batch.cube(count=40, parent="/World")
    assert prim_lookup.resolve_prims(cubes) == cubes and prim_lookup.checked_batch.holds(cubes)
    assert not prim_lookup.checked_batch.holds(cubes[:-1]) and not prim_lookup.checked_batch.holds(cubes[::-1])
    cubes[0].GetStage().RemovePrim(cubes[7].GetPath())
    assert not prim_lookup.checked_batch.holds(cubes)
    with pytest.raises(PrimNotFoundError, match="Cube_07"):
        prim_lookup.resolve_prims(cubes)
    others = rep.functional.create_batch.cube(count=40, parent="/World")
    prim_lookup.resolve_prims(others)
    rep.stage.new_stage()                                                      # its prims expire with it
    assert not prim_lookup.checked_batch.holds(others)


def _camera_rig(fabric: bool):
    """A camera under a translated, rotated and scaled xform, a cube to look at, a 64x48 depth product."""
    rep.stage.new_stage()
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", fabric)
    rig = rep.functional.create.xform(name="Rig", position=(1, -2, 0.5), rotation=(20, 40, -70), scale=2.0)
    cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0), parent=rig, name="Cam")
    cube = rep.functional.create.cube(name="Box", position=(0.5, 0, 0))
    rp = rep.create.render_product(cam, (64, 48))
    depth = rep.annotators.get("distance_to_image_plane")
    depth.attach(rp)
    return cam, cube, rp, depth


CAMERA_POSES = [
    dict(position_value=(4.0, 1.0, 2.0), look_at_value=(0.0, 0.0, 0.0), look_at_up_axis=(0.0, 0.0, 1.0)),
    dict(rotation_value=(10.0, 20.0, 30.0)),
    dict(position_value=(2.0, 2.0, 5.0)),                              # keeps the rotation
    dict(rotation_value=tuple(np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2]))),
    dict(look_at_value="/Box"),                                        # aim at a prim, keeping the position
]


def test_cameras_posed_with_write_to_fabric_match_authored_poses():
    """Camera poses written beside the stage give the view and the depth image the stage's authoring gives;
    the stage keeps its authored pose."""
    from graphsdg.engine.capture import _camera_view

    def run(fabric: bool):
        cam, cube, rp, depth = _camera_rig(fabric)
        authored = tuple(cam.GetAttribute("xformOp:translate").Get())
        views, images = [], []
        for kwargs in CAMERA_POSES:
            rep.functional.modify.pose(cam, **kwargs)
            rep.orchestrator.step()
            view = _camera_view(runtime(), rp)
            views.append((view.position, view.rotation))
            images.append(depth.get_data())
        assert (tuple(cam.GetAttribute("xformOp:translate").Get()) == authored) == fabric
        assert (runtime().render_scene.camera_poses.local(str(cam.GetPath())) is not None) == fabric
        return views, images

    stage_views, stage_images = run(False)
    fabric_views, fabric_images = run(True)
    for (t_usd, r_usd), (t_fab, r_fab) in zip(stage_views, fabric_views):
        np.testing.assert_allclose(t_fab, t_usd, atol=1e-9)
        np.testing.assert_allclose(r_fab, r_usd, atol=1e-9)
    for usd, fab in zip(stage_images, fabric_images):
        assert np.array_equal(np.isfinite(usd), np.isfinite(fab))
        np.testing.assert_allclose(fab[np.isfinite(fab)], usd[np.isfinite(usd)], rtol=1e-5)
    assert sum(bool(np.isfinite(usd).any()) for usd in stage_images) >= 3     # the box is in view
    assert len({(round(float(t[0]), 6), round(float(r[0, 0]), 6)) for t, r in stage_views}) == len(CAMERA_POSES)


def test_a_later_stage_edit_of_a_fabric_posed_camera_wins():
    """Authoring the camera's transform after a fabric pose makes the stage's pose count again; a fabric pose
    after a stage edit is kept (the edit is synced first); a parent moved on the stage carries the fabric-posed
    camera along."""
    from graphsdg.engine.capture import _camera_view
    from graphsdg.stage.xform import set_local_pose, world_matrix

    cam, cube, rp, depth = _camera_rig(True)
    poses, path = runtime().render_scene.camera_poses, str(cam.GetPath())
    rep.functional.modify.pose(cam, position_value=(4.0, 1.0, 2.0), look_at_value=(0.0, 0.0, 0.0))
    fabric_t = _camera_view(runtime(), rp).position
    set_local_pose(cam, position=(0.0, 0.0, 6.0), look_at=(0.0, 0.0, 0.0))    # authored on the stage
    rep.orchestrator.step()
    assert poses.local(path) is None
    np.testing.assert_allclose(_camera_view(runtime(), rp).position, world_matrix(cam)[3, :3], atol=1e-12)
    assert not np.allclose(_camera_view(runtime(), rp).position, fabric_t)
    set_local_pose(cam, position=(0.0, 0.0, 7.0))                              # authored, not synced yet
    rep.functional.modify.pose(cam, position_value=(4.0, 1.0, 2.0), look_at_value=(0.0, 0.0, 0.0))
    rep.orchestrator.step()
    np.testing.assert_allclose(_camera_view(runtime(), rp).position, fabric_t, atol=1e-12)
    local = poses.local(path).copy()
    set_local_pose(cam.GetParent(), position=(0.0, 0.0, 1.0))                  # the parent moves on the stage
    rep.orchestrator.step()
    np.testing.assert_array_equal(poses.local(path), local)
    moved = (local @ world_matrix(cam.GetParent()))[3, :3]
    np.testing.assert_allclose(_camera_view(runtime(), rp).position, moved, atol=1e-12)
    assert not np.allclose(moved, fabric_t)
    cam.GetAttribute("focalLength").Set(35.0)                                  # not a pose: kept
    rep.orchestrator.step()
    assert poses.local(path) is not None


def test_cameras_with_other_op_stacks_are_authored():
    """A camera whose op stack is not translate / rotate / scale (here a pivot op) keeps the stage route."""
    from pxr import UsdGeom

    cam, cube, rp, depth = _camera_rig(True)
    UsdGeom.Xformable(cam).AddTranslateOp(UsdGeom.XformOp.PrecisionDouble, "pivot")
    rep.functional.modify.pose(cam, position_value=(4.0, 1.0, 2.0), look_at_value=(0.0, 0.0, 0.0))
    assert runtime().render_scene.camera_poses.local(str(cam.GetPath())) is None
    assert tuple(cam.GetAttribute("xformOp:translate").Get()) == (4.0, 1.0, 2.0)


def test_camera_poses_keep_the_parts_they_were_composed_from_until_the_stage_edits_the_camera():
    from pxr import Sdf

    from graphsdg.maths.rotations import compose, decompose, euler_to_matrix
    from graphsdg.sim.pose_writes.camera_poses import CameraPoses
    from graphsdg.stage.changes import ChangeSet
    poses = CameraPoses()
    m = compose(np.array([1.0, 2.0, 3.0]), euler_to_matrix(np.array([10.0, 20.0, 30.0]), "XYZ"),
                np.array([1.0, 2.0, 1.0]))
    poses.set_local("/C", m)                                 # no parts given: decomposed when asked
    for got, want in zip(poses.local_parts("/C"), decompose(m)):
        np.testing.assert_allclose(got, want)
    parts = (np.zeros(3), np.eye(3), np.ones(3))
    poses.set_local("/C", compose(*parts), parts)
    assert poses.local_parts("/C") is parts
    poses.forget_edited(ChangeSet(edited={Sdf.Path("/C"): {"xformOp:translate"}}))
    assert poses.local_parts("/C") is None and poses.local("/C") is None
