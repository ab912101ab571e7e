"""Rigid-body velocities in USD: authored ones start the simulation, simulated ones are written back."""
from __future__ import annotations

import numpy as np
from pxr import UsdPhysics

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.sim.transforms import get_world_pose


def _floating_cube():
    rep.stage.new_stage()
    cube = rep.functional.create.cube(position=(0, 0, 5), scale=0.2)
    rep.functional.physics.apply_rigid_body(cube, with_collider=True)
    UsdPhysics.Scene.Define(rep.stage.get_stage(), "/physicsScene").CreateGravityMagnitudeAttr(0.0)
    return cube, UsdPhysics.RigidBodyAPI(cube)


def test_authored_velocities_start_the_body_and_edits_change_it_live():
    cube, body = _floating_cube()
    body.CreateVelocityAttr((1.0, 0.0, 0.0))
    body.CreateAngularVelocityAttr((0.0, 0.0, 90.0))          # degrees per second, world frame
    sim = runtime().sim
    sim.sync_dirty_prims()
    sim.advance(1.0)
    position, orientation = get_world_pose(cube)
    assert np.allclose(position, (1, 0, 5), atol=1e-6)
    assert np.allclose(orientation, (np.sqrt(0.5), 0, 0, np.sqrt(0.5)), atol=1e-4)   # 90 degrees about z
    compiles = sim.stats.get("compiles", None)
    body.GetVelocityAttr().Set((0.0, 2.0, 0.0))              # a live edit, not a recompile
    sim.sync_dirty_prims()
    assert sim.stats.get("compiles", None) == compiles
    sim.advance(0.5)
    assert np.allclose(get_world_pose(cube)[0], (1, 1, 5), atol=1e-6)


def test_simulated_velocities_are_written_back_in_world_frame():
    cube, body = _floating_cube()
    rep.stage.get_stage().GetPrimAtPath("/physicsScene").GetAttribute("physics:gravityMagnitude").Set(9.81)
    body.CreateAngularVelocityAttr((0.0, 45.0, 0.0))
    sim = runtime().sim
    sim.sync_dirty_prims()
    sim.advance(0.5)
    linear, angular = np.array(body.GetVelocityAttr().Get()), np.array(body.GetAngularVelocityAttr().Get())
    assert np.allclose(linear, (0, 0, -9.81 * 0.5), atol=0.02)          # free fall for half a second
    assert np.allclose(angular, (0, 45, 0), atol=1e-3)                  # torque-free spin about a symmetry axis
