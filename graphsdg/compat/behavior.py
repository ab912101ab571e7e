"""Isaac compat area: ``isaacsim.replicator.behavior`` and the behavior-script host (``omni.behavior.scripting.core``,
``omni.kit.scripting``), over :mod:`graphsdg.behaviors`.

The behavior scripts, their exposed variables, the event-driven stacking and the script runtime are
graphsdg's own. While compat mode is installed the scripts hear Kit's world: their events go through
``carb.eventdispatcher`` (so ``dispatch_event`` / ``observe_event`` of a script reach them and theirs reach
the script), "the next app update" is ``omni.kit.app``'s, and every app update picks up newly attached scripts
(as Kit's script manager does). Isaac leaves the extension off in a standalone app.
"""
from __future__ import annotations

import types
from typing import Any

from graphsdg import behaviors
from graphsdg.behaviors import (exposed_variables, host, interval_behavior, light_randomizer, location_randomizer,
                                look_at_behavior, rotation_randomizer, script_runtime, stacking_scene,
                                texture_randomizer, volume_stack_randomizer, xform_edits)
from graphsdg.compat import kit, kit_command_registry
from graphsdg.compat.event_dispatch import get_eventdispatcher
from graphsdg.compat.event_names import APP_UPDATE
from graphsdg.compat.modules import CompatModule
from graphsdg.compat.physx_schema import intToSdfPath
from graphsdg.stage.context import get_stage

NAME = "isaacsim.replicator.behavior"
EXTENSIONS = {NAME: (NAME,), "omni.behavior.scripting.core": ("omni.behavior.scripting.core",),
              "omni.kit.scripting": ("omni.kit.scripting",)}
OFF_AT_START = {NAME}
_guards: list[Any] = []


async def apply_forces_and_simulate_async(stage_id: int, body_ids: list[int], forces: list, positions: list,
                                          sim_steps: int, physx_dt: float, render: bool = True) -> None:
    """Isaac's form: bodies named by ``PhysicsSchemaTools.sdfPathToInt`` ids (``stage_id`` is the current stage)."""
    paths = [str(intToSdfPath(int(i))) for i in body_ids]
    await stacking_scene.apply_forces_and_simulate_async(paths, forces, positions, sim_steps, physx_dt, render)


class ApplyScriptingAPICommand(kit_command_registry.Command):
    """Kit's ``ApplyScriptingAPICommand``: give prims the scripting API and an empty script list."""

    def __init__(self, paths: list, **_: Any) -> None:
        self._paths = [str(p) for p in paths]

    def do(self) -> None:
        stage = get_stage()
        for path in self._paths:
            script_runtime.apply_scripting_api(stage.GetPrimAtPath(path))


def install() -> None:
    """Route behavior events through carb, wait on Kit's app updates, sync scripts at every update."""
    kit_command_registry.register(ApplyScriptingAPICommand)
    host.set_event_bus(get_eventdispatcher())
    host.set_next_update(lambda: kit.get_app().next_update_async())
    _guards[:] = [get_eventdispatcher().observe_event(event_name=APP_UPDATE,
                                                      on_event=lambda e: script_runtime.script_manager().sync(),
                                                      observer_name="behaviors.script_sync")]


def uninstall() -> None:
    """Back to graphsdg's own bus and updates; the scripts of the stage are destroyed."""
    kit_command_registry.unregister(ApplyScriptingAPICommand)
    for guard in _guards:
        guard.reset()
    _guards.clear()
    script_runtime.script_manager().stop()
    host.set_event_bus(None)
    host.set_next_update(None)


def modules() -> list[types.ModuleType]:
    """The extension's package, ``behaviors``, ``global_variables``, ``base_behavior``, ``utils`` and the
    scripting host's modules."""
    classes = {cls.__name__: cls for cls in (
        light_randomizer.LightRandomizer, location_randomizer.LocationRandomizer, look_at_behavior.LookAtBehavior,
        rotation_randomizer.RotationRandomizer, texture_randomizer.TextureRandomizer,
        volume_stack_randomizer.VolumeStackRandomizer)}
    leaves = {"LightRandomizer": "light_randomizer", "LocationRandomizer": "location_randomizer",
              "LookAtBehavior": "look_at_behavior", "RotationRandomizer": "rotation_randomizer",
              "TextureRandomizer": "texture_randomizer", "VolumeStackRandomizer": "volume_stack_randomizer"}
    constants = {n: getattr(exposed_variables, n) for n in ("EXTENSION_NAME", "EXPOSED_ATTR_NS", "SCOPE_NAME",
                                                            "EXPOSED_VARS_CHANGED_EVENT")}
    behavior_utils = {n: getattr(exposed_variables, n) for n in (
        "create_exposed_variable", "create_exposed_variables", "check_if_exposed_variables_should_be_removed",
        "remove_exposed_variable", "remove_exposed_variables", "get_exposed_variable", "set_exposed_variables",
        "remove_empty_scopes", "add_behavior_script", "add_behavior_script_with_parameters_async",
        "publish_event_and_wait_for_completion_async")}
    scene_utils = {n: getattr(xform_edits, n) for n in (
        "get_world_location", "get_world_rotation", "get_rotation_op_and_value", "set_rotation_op_and_value",
        "set_rotation_with_ops", "decompose_rotation", "calculate_look_at_rotation", "set_location",
        "set_transform_attributes")}
    scene_utils.update({n: getattr(stacking_scene, n) for n in (
        "create_asset", "create_physics_material", "add_colliders", "disable_colliders", "add_rigid_body_dynamics",
        "disable_rigid_body_dynamics", "create_collision_walls", "run_simulation_async")})
    scene_utils["apply_forces_and_simulate_async"] = apply_forces_and_simulate_async
    utils_behavior = CompatModule(f"{NAME}.utils.behavior_utils", exposed_variables.__doc__ or "", **behavior_utils)
    utils_scene = CompatModule(f"{NAME}.utils.scene_utils", xform_edits.__doc__ or "", **scene_utils)
    behaviors_module = CompatModule(f"{NAME}.behaviors", __all__=sorted(classes), **classes)
    scripting = dict(BehaviorScript=behaviors.BehaviorScript)
    return [CompatModule(NAME, behaviors=behaviors_module),
            behaviors_module,
            *[CompatModule(f"{NAME}.behaviors.{leaf}", **{cls: classes[cls]}) for cls, leaf in leaves.items()],
            CompatModule(f"{NAME}.behaviors.volume_stack_randomizer",
                         BehaviorState=volume_stack_randomizer.BehaviorState),
            CompatModule(f"{NAME}.global_variables", **constants),
            CompatModule(f"{NAME}.base_behavior", BaseBehavior=interval_behavior.IntervalBehavior),
            CompatModule(f"{NAME}.utils", behavior_utils=utils_behavior, scene_utils=utils_scene),
            utils_behavior, utils_scene,
            CompatModule("omni.behavior.scripting.core", **scripting),
            CompatModule("omni.kit.scripting", **scripting)]
