"""SimulationManager's physics-scene class methods in compat mode: Isaac Sim 6's deprecated PhysX settings
(solver, broadphase, CCD, GPU dynamics, stabilisation) authored on the USD scene and read back, the default
scene, and the deprecated PhysicsContext seeing the same settings."""
from __future__ import annotations

import logging

import pytest
from pxr import Sdf, UsdPhysics

from graphsdg.compat import isaac
from graphsdg.stage import get_stage

# (setter, getter, attribute, type, two values to set in turn)
PAIRS = [("set_solver_type", "get_solver_type", "physxScene:solverType", "token", ("PGS", "TGS")),
         ("set_broadphase_type", "get_broadphase_type", "physxScene:broadphaseType", "token", ("SAP", "MBP")),
         ("enable_ccd", "is_ccd_enabled", "physxScene:enableCCD", "bool", (True, False)),
         ("enable_gpu_dynamics", "is_gpu_dynamics_enabled", "physxScene:enableGPUDynamics", "bool", (False, True)),
         ("enable_stablization", "is_stablization_enabled", "physxScene:enableStabilization", "bool", (True, False))]


@pytest.fixture
def sm():
    isaac.install()
    from isaacsim.core.simulation_manager import SimulationManager
    yield SimulationManager
    SimulationManager.set_device("cpu")
    isaac.uninstall()


def scene(path: str):
    return UsdPhysics.Scene.Define(get_stage(), path).GetPrim()


def authored(prim, name):
    attr = prim.GetAttribute(name)
    return attr.Get() if attr and attr.HasAuthoredValue() else None


def test_no_scene_one_is_made_and_reads_physx_fallbacks(sm):
    assert sm.get_solver_type() == "TGS"
    prim = get_stage().GetPrimAtPath("/PhysicsScene")
    assert prim.IsA(UsdPhysics.Scene) and "PhysxSceneAPI" in prim.GetPrimTypeInfo().GetAppliedAPISchemas()
    assert (sm.get_broadphase_type(), sm.is_ccd_enabled(), sm.is_gpu_dynamics_enabled(),
            sm.is_stablization_enabled()) == ("GPU", False, True, False)
    assert [authored(prim, n) for n in ("physxScene:solverType", "physxScene:enableCCD")] == [None, None]


@pytest.mark.parametrize("setter, getter, name, type_name, values", PAIRS)
def test_each_pair_round_trips_through_the_scene_prim(sm, setter, getter, name, type_name, values):
    prim = scene("/World/physicsScene")
    for value in values:
        getattr(sm, setter)(value)
        assert authored(prim, name) == value
        assert getattr(sm, getter)() == value
    attr = prim.GetAttribute(name)
    assert attr.GetTypeName() == Sdf.ValueTypeNames.Find(type_name)
    assert "PhysxSceneAPI" in prim.GetPrimTypeInfo().GetAppliedAPISchemas()


@pytest.mark.parametrize("setter, getter, name, type_name, values", PAIRS)
def test_physics_scene_argument_targets_one_of_two_scenes(sm, setter, getter, name, type_name, values):
    first, second = scene("/World/sceneA"), scene("/World/sceneB")
    getattr(sm, setter)(values[0], physics_scene="/World/sceneB")
    assert authored(second, name) == values[0] and authored(first, name) is None
    assert getattr(sm, getter)(physics_scene="/World/sceneB") == values[0]
    getattr(sm, setter)(values[1])                       # no scene named: every scene, as Isaac
    assert authored(first, name) == values[1] and authored(second, name) == values[1]


def test_default_scene_is_what_getters_read(sm, caplog):
    scene("/World/sceneA"), scene("/World/sceneB")
    sm.set_solver_type("PGS", physics_scene="/World/sceneB")
    with caplog.at_level(logging.WARNING, logger="carb"):
        assert sm.get_default_physics_scene() is None                 # none set yet: Isaac warns, None
    assert "Invalid default physics scene path" in caplog.text
    assert sm.get_solver_type() == "TGS"                              # the first scene
    sm.set_default_physics_scene("/World/sceneB")
    assert sm.get_default_physics_scene() == "/World/sceneB"
    assert sm.get_solver_type() == "PGS"
    get_stage().RemovePrim("/World/sceneB")
    with caplog.at_level(logging.WARNING, logger="carb"):
        assert sm.get_solver_type() == "TGS"                          # gone: back to the first, with a warning
    assert "Using first physics scene found in stage: /World/sceneA" in caplog.text


def test_default_scene_refusals_and_a_new_stage_forgets_it(sm):
    import graphsdg as rep
    scene("/World/sceneA")
    get_stage().DefinePrim("/World/Cube", "Cube")
    with pytest.raises(ValueError, match="'/World/Nowhere' doesn't exist"):
        sm.set_default_physics_scene("/World/Nowhere")
    with pytest.raises(ValueError, match=r"'/World/Cube' is not a UsdPhysics.Scene.*/World/sceneA"):
        sm.set_default_physics_scene("/World/Cube")
    sm.set_default_physics_scene("/World/sceneA")
    rep.stage.new_stage()
    scene("/World/sceneA")
    assert sm.get_default_physics_scene() is None


def test_bad_values_raise_naming_them_and_author_nothing(sm):
    prim = scene("/World/physicsScene")
    with pytest.raises(ValueError, match=r"'TGS' or 'PGS', got 'XYZ'"):
        sm.set_solver_type("XYZ")
    with pytest.raises(ValueError, match=r"'MBP', 'GPU' or 'SAP', got 'ABP'"):
        sm.set_broadphase_type("ABP")
    for setter in ("enable_ccd", "enable_gpu_dynamics", "enable_stablization"):
        with pytest.raises(TypeError, match=rf"{setter.replace('stablization', 'stabilization')} takes a bool, "
                                            r"got 'yes'"):
            getattr(sm, setter)("yes")
    assert not [n for n in prim.GetAuthoredPropertyNames() if n.startswith("physxScene:")]
    with pytest.raises(ValueError, match=r"'/World/Other' is not a UsdPhysics.Scene.*/World/physicsScene"):
        sm.set_solver_type("PGS", physics_scene="/World/Other")
    with pytest.raises(ValueError, match="'/World/Other'"):
        sm.is_ccd_enabled(physics_scene="/World/Other")


def test_gpu_dynamics_turns_ccd_off_and_cuda_refuses_ccd(sm, caplog):
    prim = scene("/World/physicsScene")
    sm.enable_ccd(True)
    sm.enable_gpu_dynamics(True)
    assert (authored(prim, "physxScene:enableCCD"), sm.is_ccd_enabled()) == (False, False)
    sm.enable_gpu_dynamics(False)
    sm.enable_ccd(True)
    sm.set_device("cuda:0")
    sm.enable_ccd(False)                                              # disabling is always taken
    with caplog.at_level(logging.WARNING, logger="carb"):
        sm.enable_ccd(True)
    assert "CCD is not supported on GPU" in caplog.text
    assert authored(prim, "physxScene:enableCCD") is False


def test_physics_context_and_simulation_manager_see_each_others_settings(sm):
    from isaacsim.core.api import PhysicsContext
    physics = PhysicsContext()                   # Isaac's defaults: recorded on the scene, not authored
    prim = get_stage().GetPrimAtPath(physics.prim_path)
    assert (sm.get_solver_type(), sm.get_broadphase_type(), sm.is_ccd_enabled(), sm.is_gpu_dynamics_enabled(),
            sm.is_stablization_enabled()) == ("TGS", "MBP", True, False, False)
    assert authored(prim, "physxScene:enableCCD") is None
    sm.set_solver_type("PGS")
    sm.set_broadphase_type("SAP")
    sm.enable_stablization(True)
    assert (physics.get_solver_type(), physics.get_broadphase_type(), physics.is_stablization_enabled()) == \
        ("PGS", "SAP", True)
    physics.enable_gpu_dynamics(True)            # Isaac's PhysicsContext goes through SimulationManager: CCD off
    assert (sm.is_gpu_dynamics_enabled(), sm.is_ccd_enabled()) == (True, False)
    physics.enable_gpu_dynamics(False)
    physics.enable_ccd(True)
    physics.set_solver_type("TGS")
    assert (sm.is_ccd_enabled(), sm.get_solver_type(), authored(prim, "physxScene:solverType")) == \
        (True, "TGS", "TGS")
    sm.set_solver_type("PGS")
    PhysicsContext()                             # a new context authors Isaac's defaults again, over set values
    assert (sm.get_solver_type(), authored(prim, "physxScene:solverType")) == ("TGS", "TGS")
    with pytest.raises(ValueError, match="'MBP', 'GPU' or 'SAP', got 'X'"):
        physics.set_broadphase_type("X")


def test_the_settings_leave_mujoco_unchanged(sm):
    """The PhysX-only settings are authored, not simulated: a falling ball moves the same with all of them flipped."""
    from isaacsim.core.api.objects import DynamicSphere
    import graphsdg as rep

    def fall(flip: bool) -> float:
        rep.stage.new_stage()
        ball = DynamicSphere(prim_path="/World/Ball", position=(0, 0, 2), radius=0.1)
        sm.set_physics_dt(1 / 60)
        if flip:
            sm.set_solver_type("PGS"), sm.set_broadphase_type("SAP"), sm.enable_ccd(True)
            sm.enable_gpu_dynamics(False), sm.enable_stablization(True)
        sm.initialize_physics()
        sm.step(steps=10)
        return float(ball.get_world_pose()[0][2])

    assert fall(True) == fall(False) == pytest.approx(2 - 9.81 / 3600 * 55, abs=1e-5)


def test_deprecated_default_callback_toggles(sm):
    for toggle, name in (("enable_warm_start_callback", "warm_start"), ("enable_on_stop_callback", "on_stop"),
                         ("enable_stage_open_callback", "stage_open"),
                         ("enable_post_warm_start_callback", "post_warm_start")):
        getattr(sm, toggle)(False)
        assert sm.is_default_callback_enabled(name) is False
        getattr(sm, toggle)(True)
        assert sm.is_default_callback_enabled(name) is True
    sm.enable_all_default_callbacks(False)
    assert not any(sm.get_default_callback_status().values())
    sm.enable_all_default_callbacks(True)
    assert all(sm.get_default_callback_status().values())


def test_the_physics_engine_is_physx_s_interface(sm, caplog):
    assert sm.get_active_physics_engine() == "physx"
    assert sm.get_available_physics_engines() == [("physx", True)]
    assert sm.switch_physics_engine("PhysX") is True
    with caplog.at_level(logging.ERROR, logger="carb"):
        assert sm.switch_physics_engine("newton") is False
    assert "Engine 'newton' not found. Available: physx" in caplog.text
    assert sm.get_active_physics_engine() == "physx"
