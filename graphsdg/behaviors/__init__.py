"""Behavior scripts: per-prim Python behaviors and graphsdg's randomizing behaviors. Scripts attach through
``omni:scripting:scripts`` and are driven by the timeline or by events; the randomizing behaviors (location,
rotation, look-at, light, texture, volume stacking) expose their settings as USD attributes.
"""
from graphsdg.behaviors.exposed_variables import (EXPOSED_ATTR_NS, EXPOSED_VARS_CHANGED_EVENT, EXTENSION_NAME,
                                                  SCOPE_NAME, add_behavior_script,
                                                  add_behavior_script_with_parameters_async,
                                                  publish_event_and_wait_for_completion_async)
from graphsdg.behaviors.interval_behavior import IntervalBehavior
from graphsdg.behaviors.light_randomizer import LightRandomizer
from graphsdg.behaviors.location_randomizer import LocationRandomizer
from graphsdg.behaviors.look_at_behavior import LookAtBehavior
from graphsdg.behaviors.rotation_randomizer import RotationRandomizer
from graphsdg.behaviors.script_runtime import BehaviorScript, ScriptManager, attach_script, script_manager
from graphsdg.behaviors.texture_randomizer import TextureRandomizer
from graphsdg.behaviors.volume_stack_randomizer import BehaviorState, VolumeStackRandomizer

__all__ = ["BehaviorScript", "BehaviorState", "EXPOSED_ATTR_NS", "EXPOSED_VARS_CHANGED_EVENT", "EXTENSION_NAME",
           "IntervalBehavior", "LightRandomizer", "LocationRandomizer", "LookAtBehavior", "RotationRandomizer",
           "SCOPE_NAME", "ScriptManager", "TextureRandomizer", "VolumeStackRandomizer", "add_behavior_script",
           "add_behavior_script_with_parameters_async", "attach_script", "publish_event_and_wait_for_completion_async",
           "script_manager"]
