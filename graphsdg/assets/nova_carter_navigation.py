"""The navigation action graph of the Nova Carter stand-in: drive to the ``targetXform`` prim's position.

Replicator's navigation sample (``nova_carter_nav_only.usd``) carries an OmniGraph
action graph that drives the robot to its ``targetXform`` child, wherever a
script moves it. This module writes such a graph (Kit's layout,
:mod:`graphsdg.assets.omnigraph_authoring`), with Isaac's wheeled-robot nodes:

* every timeline tick (``OnPlaybackTick``): the chassis' world transform
  (``GetPrimLocalToWorldTransform`` -> ``GetMatrix4Quaternion`` /
  ``GetMatrix4Translation``) feeds the ``QuinticPathPlanner`` (goal: the target
  prim's world pose; a path is planned again whenever the goal moves), then
  ``CheckGoal2D``, then ``StanleyControlPID`` (also fed the chassis speed by
  ``IsaacComputeOdometry``);
* its forward speed and turn rate go to the ``DifferentialController`` (the
  stand-in's wheel radius and wheel spacing), whose wheel speeds the
  ``IsaacArticulationController`` writes as velocity targets of
  ``joint_wheel_left`` / ``joint_wheel_right``.

Prims are named by relationships (``target`` inputs), so the graph follows the
asset wherever it is referenced.

Example:
    >>> NODES["planner"]
    'isaacsim.robot.wheeled_robots.QuinticPathPlanner'
"""
from __future__ import annotations

from pxr import Sdf, Usd

from graphsdg.assets.omnigraph_authoring import connect, define_graph, define_node, set_input, set_targets

NODES = {
    "on_playback_tick": "omni.graph.action.OnPlaybackTick",
    "chassis_transform": "omni.graph.nodes.GetPrimLocalToWorldTransform",
    "chassis_rotation": "omni.graph.nodes.GetMatrix4Quaternion",
    "chassis_translation": "omni.graph.nodes.GetMatrix4Translation",
    "planner": "isaacsim.robot.wheeled_robots.QuinticPathPlanner",
    "check_goal": "isaacsim.robot.wheeled_robots.CheckGoal2D",
    "steering": "isaacsim.robot.wheeled_robots.StanleyControlPID",
    "odometry": "isaacsim.core.nodes.IsaacComputeOdometry",
    "differential_controller": "isaacsim.robot.wheeled_robots.DifferentialController",
    "articulation_controller": "isaacsim.core.nodes.IsaacArticulationController",
}
# (source node, output, destination node, input, OGN type)
CONNECTIONS = [
    ("on_playback_tick", "tick", "planner", "execIn", "execution"),
    ("planner", "execOut", "check_goal", "execIn", "execution"),
    ("check_goal", "execOut", "steering", "execIn", "execution"),
    ("on_playback_tick", "tick", "odometry", "execIn", "execution"),
    ("on_playback_tick", "tick", "differential_controller", "execIn", "execution"),
    ("on_playback_tick", "tick", "articulation_controller", "execIn", "execution"),
    ("chassis_transform", "localToWorldTransform", "chassis_rotation", "matrix", "matrixd[4]"),
    ("chassis_transform", "localToWorldTransform", "chassis_translation", "matrix", "matrixd[4]"),
    *[("chassis_rotation", "quaternion", node, "currentOrientation", "quatd[4]")
      for node in ("planner", "check_goal", "steering")],
    *[("chassis_translation", "translation", node, "currentPosition", "vectord[3]")
      for node in ("planner", "check_goal", "steering")],
    ("planner", "pathArrays", "steering", "pathArrays", "double[]"),
    ("planner", "target", "check_goal", "target", "double[3]"),
    ("planner", "target", "steering", "target", "double[3]"),
    ("planner", "targetChanged", "check_goal", "targetChanged", "bool"),
    ("planner", "targetChanged", "steering", "targetChanged", "bool"),
    ("check_goal", "reachedGoal", "steering", "reachedGoal", "bool[]"),
    ("odometry", "linearVelocity", "steering", "currentSpeed", "vectord[3]"),
    ("steering", "linearVelocity", "differential_controller", "linearVelocity", "double"),
    ("steering", "angularVelocity", "differential_controller", "angularVelocity", "double"),
    ("differential_controller", "velocityCommand", "articulation_controller", "velocityCommand", "double[]"),
]


def define_navigation_graph(stage: Usd.Stage, graph_path: str, chassis: str, target: str, wheel_joints: list[str],
                            wheel_radius: float, wheel_distance: float) -> Usd.Prim:
    """Write the navigation graph at ``graph_path`` driving the robot whose articulation root and body is
    ``chassis`` to prim ``target`` (see the module docstring); returns the graph prim."""
    graph = define_graph(stage, graph_path, "execution")
    nodes = {name: define_node(stage, graph, name, node_type, 2 if name == "chassis_transform" else 1)
             for name, node_type in NODES.items()}
    for source, output, dest, input_, ogn_type in CONNECTIONS:
        connect(nodes[source], output, nodes[dest], input_, ogn_type)
    set_input(nodes["chassis_transform"], "usePath", "bool", False)
    set_targets(nodes["chassis_transform"], "prim", [chassis])
    set_targets(nodes["planner"], "targetPrim", [target])
    set_targets(nodes["odometry"], "chassisPrim", [chassis])
    set_input(nodes["differential_controller"], "wheelRadius", "double", wheel_radius)
    set_input(nodes["differential_controller"], "wheelDistance", "double", wheel_distance)
    set_targets(nodes["articulation_controller"], "targetPrim", [chassis])
    set_input(nodes["articulation_controller"], "jointNames", "token[]", list(wheel_joints))
    set_input(nodes["articulation_controller"], "robotPath", "string", "")
    return graph


__all__ = ["CONNECTIONS", "NODES", "define_navigation_graph"]
