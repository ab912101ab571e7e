"""isaacsim.core.cloner in compat mode: the grid layout contract, analytic, and clones that render and simulate."""
from __future__ import annotations

import math

import numpy as np
import pytest
from pxr import UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def grid(n: int, spacing: float, per_row: int | None = None) -> np.ndarray:
    """Isaac's grid: rows of ``per_row`` (int(sqrt(n)) by default), x down the rows, y across, centred."""
    per_row = per_row or int(math.sqrt(n))
    rows = math.ceil(n / per_row)
    cols = math.ceil(n / rows)
    out = []
    for i in range(n):
        row, col = divmod(i, cols)
        out.append([spacing * (rows - 1) / 2 - row * spacing, col * spacing - spacing * (cols - 1) / 2, 0.0])
    return np.array(out)


@pytest.mark.parametrize("n, spacing, per_row", [(1, 1.0, None), (4, 1.5, None), (9, 2.0, None), (10, 1.0, None),
                                                  (7, 0.5, 3), (6, 1.0, 6)])
def test_grid_clone_transforms_follow_isaacs_layout(compat, n, spacing, per_row):
    from isaacsim.core.cloner import GridCloner
    cloner = GridCloner(spacing=spacing, num_per_row=per_row or -1)
    positions, orientations = cloner.get_clone_transforms(n)
    np.testing.assert_allclose(np.array(positions), grid(n, spacing, per_row), atol=1e-12)
    np.testing.assert_allclose(np.array(orientations), [[1.0, 0.0, 0.0, 0.0]] * n)


def test_grid_offsets_and_errors(compat):
    from isaacsim.core.cloner import GridCloner
    cloner = GridCloner(spacing=2.0)
    offsets = np.array([[0.0, 0.0, 1.0]] * 4)
    turn = [math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)]   # 90 degrees about z
    positions, orientations = cloner.get_clone_transforms(4, position_offsets=offsets,
                                                          orientation_offsets=np.array([turn] * 4))
    np.testing.assert_allclose(np.array(positions), grid(4, 2.0) + offsets)
    np.testing.assert_allclose(np.array(orientations), [turn] * 4, atol=1e-12)
    with pytest.raises(ValueError, match="Dimension mismatch"):
        cloner.get_clone_transforms(3, position_offsets=offsets)
    with pytest.raises(ValueError, match="num_per_row must be positive"):
        GridCloner(spacing=1.0, num_per_row=0).get_clone_transforms(2)
    assert cloner.generate_paths("/World/envs/env", 3) == ["/World/envs/env_0", "/World/envs/env_1",
                                                           "/World/envs/env_2"]
    # without offsets the positions are plain lists, as Isaac's (scripts compare them with ==)
    rep.stage.new_stage()
    positions, _ = GridCloner(spacing=2.0).get_clone_transforms(9)
    assert positions[0] == [2.0, -2.0, 0] and positions[-1] == [-2.0, 2.0, 0]
    assert GridCloner(spacing=2.0).get_clone_transforms(0) == ([], [])


def test_clone_pauses_the_change_listener_around_its_work(compat):
    from unittest import mock

    from isaacsim.core.cloner import Cloner
    stage = rep.stage.new_stage()
    UsdGeom.Cube.Define(stage, "/World/Cube_0")
    cloner = Cloner()
    with mock.patch.object(cloner, "disable_change_listener") as pause, \
            mock.patch.object(cloner, "enable_change_listener") as resume:
        with pytest.raises(ValueError, match="positions"):
            cloner.clone("/World/Cube_0", ["/World/Cube_0"], positions=np.zeros((2, 3)))
    assert pause.call_count == 1 and resume.call_count == 1
    with pytest.raises(TypeError, match="source_prim_path"):
        cloner.clone(None, [])
    with pytest.raises(ValueError, match="valid SdfPath"):
        cloner.clone("not a valid path!!!", [])


def test_clone_places_inheriting_copies_on_the_grid(compat):
    from isaacsim.core.cloner import GridCloner
    stage = rep.stage.get_stage()
    cloner = GridCloner(spacing=3.0)
    cloner.define_base_env("/World/envs")
    assert stage.GetPrimAtPath("/World/envs").GetTypeName() == "Scope"
    env = UsdGeom.Xform.Define(stage, "/World/envs/env_0").GetPrim()
    rep.functional.create.cube(name="Box", parent=env, position=(0.0, 0.0, 0.5))
    positions = cloner.clone("/World/envs/env_0", cloner.generate_paths("/World/envs/env", 9))
    for i, expected in enumerate(grid(9, 3.0)):
        box = UsdGeom.Xformable(stage.GetPrimAtPath(f"/World/envs/env_{i}/Box"))
        world = np.array(box.ComputeLocalToWorldTransform(0).ExtractTranslation())
        np.testing.assert_allclose(world, expected + [0.0, 0.0, 0.5], atol=1e-12)
        np.testing.assert_allclose(positions[i], expected)
    clone = stage.GetPrimAtPath("/World/envs/env_4")
    assert list(clone.GetMetadata("inheritPaths").GetAddedOrExplicitItems()) == ["/World/envs/env_0"]
    # inheriting clones follow later edits of the source
    UsdGeom.Gprim(stage.GetPrimAtPath("/World/envs/env_0/Box")).CreateDisplayColorAttr([(1.0, 0.0, 0.0)])
    assert list(UsdGeom.Gprim(stage.GetPrimAtPath("/World/envs/env_8/Box")).GetDisplayColorAttr().Get()[0]) == \
        [1.0, 0.0, 0.0]


def test_copied_clones_are_independent_and_keep_the_source_pose(compat):
    from isaacsim.core.cloner import Cloner
    stage = rep.stage.get_stage()
    rep.functional.create.xform(name="World")
    source = rep.functional.create.cube(name="Src", parent="/World", position=(1.0, 2.0, 3.0),
                                       rotation=(0.0, 0.0, 90.0))
    cloner = Cloner()
    cloner.clone("/World/Src", ["/World/Copy_0", "/World/Copy_1"], copy_from_source=True,
                 positions=np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]]))
    ops = [op.GetOpName() for op in UsdGeom.Xformable(source).GetOrderedXformOps()]
    assert ops == ["xformOp:translate", "xformOp:orient", "xformOp:scale"]
    for path, where in (("/World/Copy_0", [0.0, 0.0, 0.0]), ("/World/Copy_1", [5.0, 0.0, 0.0])):
        prim = stage.GetPrimAtPath(path)
        assert prim.GetTypeName() == "Cube" and not prim.GetMetadata("inheritPaths")
        m = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(0)
        np.testing.assert_allclose(list(m.ExtractTranslation()), where, atol=1e-12)
        np.testing.assert_allclose(list(m.GetRow3(0)), [0.0, 1.0, 0.0], atol=1e-9)   # the source's 90 degrees
    source.GetAttribute("size").Set(3.0)
    assert stage.GetPrimAtPath("/World/Copy_1").GetAttribute("size").Get() == 1.0


def test_cloned_rigid_bodies_simulate_independently(compat):
    from isaacsim.core.api import World
    from isaacsim.core.api.objects import DynamicSphere
    from isaacsim.core.cloner import GridCloner
    from isaacsim.core.prims import RigidPrim
    world = World(physics_dt=1 / 60)
    cloner = GridCloner(spacing=1.0)
    cloner.define_base_env("/World/envs")
    UsdGeom.Xform.Define(world.stage, "/World/envs/env_0")
    DynamicSphere("/World/envs/env_0/ball", radius=0.1, position=np.array([0.0, 0.0, 2.0]))
    cloner.clone("/World/envs/env_0", cloner.generate_paths("/World/envs/env", 4), replicate_physics=True)
    balls = world.scene.add(RigidPrim("/World/envs/env_*/ball", name="balls"))
    assert balls.count == 4 and all(p.HasAPI(UsdPhysics.RigidBodyAPI) for p in balls.prims)
    world.reset()
    balls.set_velocities(np.array([[0.0, 0.0, 0.0, 0.0, 0.0, 0.0]] * 3 + [[0.0, 0.0, 3.0, 0.0, 0.0, 0.0]]))
    for _ in range(10):
        world.step(render=False)
    z = balls.get_world_poses()[0][:, 2]
    assert z[0] == pytest.approx(z[1]) == pytest.approx(z[2])
    assert z[3] - z[0] == pytest.approx(3.0 * 10 / 60, abs=1e-4)   # only the pushed clone rises faster
    World.clear_instance()


def test_unsupported_cloner_features_raise(compat):
    from isaacsim.core.cloner import Cloner
    rep.functional.create.cube(name="Src")
    with pytest.raises(CompatError, match="filter_collisions"):
        Cloner().filter_collisions("/physicsScene", "/World/collisions", ["/Src"])
    with pytest.raises(CompatError, match="enable_env_ids"):
        Cloner().clone("/Src", ["/Src_0", "/Src_1"], enable_env_ids=True)
    with pytest.raises(ValueError, match="does not exist"):
        Cloner().clone("/Missing", ["/A"])
