"""Isaac Sim capabilities graphsdg's compat mode leaves out on purpose. Each with the reason it gives.

Importing one of these modules, or enabling one of these extensions, fails with
:class:`~graphsdg.compat.modules.CompatImportError` naming the module and saying
why it is out of scope (docs/porting.md, "Out of scope"), instead of the generic
"not available" answer for names graphsdg has not mapped yet.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import isaacsim.ros2.bridge   # doctest: +SKIP
    CompatImportError: isaacsim.ros2.bridge is out of scope for graphsdg's compat mode: ROS 2 ...
"""
from __future__ import annotations

import types

_ROS2 = ("ROS 2: graphsdg writes datasets to files or S3 and publishes nothing on a ROS 2 graph; run the ROS 2 "
         "bridge in Isaac Sim, or read graphsdg's output with a ROS 2 node of your own")
_STREAMING = ("streaming and livestream: graphsdg runs headless and serves no viewport; look at what was generated "
              "with 'graphsdg view'")
_NUREC = "NuRec neural reconstruction: it needs NVIDIA's RTX neural renderer, which graphsdg does not have"
_TELEOP = ("teleoperation devices (XR headsets, hand tracking, spacemouse) and their recorded episodes; script the "
           "robot's motion instead")
_UI = "Kit's UI windows and menus: graphsdg has no GUI"
_MOTION = ("cuMotion and Lula motion generation: NVIDIA's closed CUDA motion-planning libraries, which are not "
           "published on a package index; plan with an open planner and drive the joints through Articulation")

# module or extension name prefix -> why it is out of scope
OUT_OF_SCOPE: dict[str, str] = {
    "isaacsim.ros2": _ROS2,
    "omni.isaac.ros2_bridge": _ROS2,
    "isaacsim.ros2.bridge": _ROS2,
    "omni.kit.livestream": _STREAMING,
    "isaacsim.streaming": _STREAMING,
    "omni.services.streaming": _STREAMING,
    "isaacsim.replicator.nurec_utils": _NUREC,
    "omni.nurec": _NUREC,
    "isaacsim.replicator.teleop": _TELEOP,
    "isaacsim.xr": _TELEOP,
    "omni.kit.xr": _TELEOP,
    "isaacsim.xr.input_devices": _TELEOP,
    "omni.ui": _UI,
    "omni.kit.ui_test": _UI,
    "omni.kit.window": _UI,
    "isaacsim.gui": _UI,
    "isaacsim.test.utils.menu_utils": _UI,
    "isaacsim.robot_motion": _MOTION,
    "omni.isaac.motion_generation": _MOTION,
}


def reason(name: str) -> str | None:
    """Why the module or extension ``name`` is out of scope, or None when it is not."""
    for prefix, why in OUT_OF_SCOPE.items():
        if name == prefix or name.startswith(prefix + "."):
            return why
    return None


def modules() -> list[types.ModuleType]:
    """No modules: the finder and the extension manager ask :func:`reason` for these names."""
    return []
