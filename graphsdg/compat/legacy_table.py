"""Isaac Sim 4.5's rename table as data. Pre-4.5 module and extension names and what replaced them.

Isaac Sim 4.5 renamed its ``omni.isaac.*`` extensions (and a few ``omni.*`` ones)
to ``isaacsim.*``; until 5.0 the old extensions stayed as shims, each old module
re-exporting the new one, some names renamed on the way (``omni.isaac.core.prims.RigidPrim``
became ``isaacsim.core.prims.SingleRigidPrim``). The entries below were worked out
from those shims (Isaac Sim 5.1's ``source/deprecated``) and Isaac's migration
notes; :mod:`graphsdg.compat.legacy_names` turns them into importable modules.

* :data:`MOVED`: an old module *prefix* whose modules each stand for the new
  module at the same relative path, every name included (the common case:
  ``omni.isaac.core.utils.prims`` -> ``isaacsim.core.utils.prims``). The longest
  matching prefix wins.
* :data:`NAMES`: old modules that offer a chosen set of names, some renamed:
  ``old name -> "new.module:new name"``.
* :data:`REMOVED`: old names with no replacement, and why.
* :data:`EXTENSIONS`: old extension name -> the extension(s) replacing it.
"""
from __future__ import annotations

MOVED: dict[str, str] = {
    # core
    "omni.isaac.core": "isaacsim.core.api",
    "omni.isaac.core.utils": "isaacsim.core.utils",
    "omni.isaac.core.prims.base_sensor": "isaacsim.core.api.sensors.base_sensor",
    "omni.isaac.core.prims.rigid_contact_view": "isaacsim.core.api.sensors.rigid_contact_view",
    "omni.isaac.kit": "isaacsim.simulation_app",
    "omni.isaac.cloner": "isaacsim.core.cloner",
    "omni.isaac.utils": "isaacsim.core.utils",
    "omni.isaac.utils.scripts": "isaacsim.core.utils",
    "omni.isaac.version": "isaacsim.core.version",
    "omni.isaac.throttling": "isaacsim.core.throttling",
    "omni.isaac.core_nodes": "isaacsim.core.nodes",
    "omni.isaac.common_includes": "isaacsim.core.includes",
    "omni.isaac.nucleus": "isaacsim.storage.native",
    "omni.isaac.nucleus.nucleus": "isaacsim.storage.native",
    # replicator, sensors, benchmarks
    "omni.replicator.isaac.scripts": "isaacsim.replicator.writers",
    "omni.replicator.isaac.scripts.writers": "isaacsim.replicator.writers",
    "omni.replicator.isaac.scripts.attributes": "isaacsim.replicator.domain_randomization.scripts.attributes",
    "omni.replicator.isaac.scripts.context": "isaacsim.replicator.domain_randomization.scripts.context",
    "omni.replicator.isaac.scripts.gate": "isaacsim.replicator.domain_randomization.scripts.gate",
    "omni.replicator.isaac.scripts.physics_view": "isaacsim.replicator.domain_randomization.scripts.physics_view",
    "omni.replicator.isaac.scripts.trigger": "isaacsim.replicator.domain_randomization.scripts.trigger",
    "omni.replicator.isaac.scripts.utils": "isaacsim.replicator.domain_randomization.scripts.utils",
    "omni.isaac.synthetic_recorder": "isaacsim.replicator.synthetic_recorder",
    "omni.isaac.scene_blox": "isaacsim.replicator.scene_blox",
    "omni.isaac.scene_blox.generation.node_generator": "isaacsim.replicator.scene_blox.grid_utils.node_generation",
    "omni.isaac.benchmark.services": "isaacsim.benchmark.services",
    "omni.isaac.benchmark.services.datarecorders.interface": "isaacsim.benchmark.services.datarecorders.interfaces",
    "omni.isaac.benchmark.services.metrics.schemas": "isaacsim.benchmark.services.metrics.schema",
    "omni.isaac.benchmarks": "isaacsim.benchmark.examples",
    "omni.isaac.range_sensor": "isaacsim.sensors.physx",
    "omni.isaac.range_sensor.ui": "isaacsim.sensors.physx.ui",
    "omni.isaac.range_sensor.examples": "isaacsim.sensors.physx.examples",
    "omni.isaac.proximity_sensor": "isaacsim.sensors.physx",
    "omni.isaac.debug_draw": "isaacsim.util.debug_draw",
    # robots, motion, examples
    "omni.isaac.manipulators": "isaacsim.robot.manipulators",
    "omni.isaac.manipulators.ui": "isaacsim.robot.manipulators.ui",
    "omni.isaac.franka": "isaacsim.robot.manipulators.examples.franka",
    "omni.isaac.universal_robots": "isaacsim.robot.manipulators.examples.universal_robots",
    "omni.isaac.wheeled_robots": "isaacsim.robot.wheeled_robots",
    "omni.isaac.wheeled_robots.controllers.ackermann_controller":
        "isaacsim.robot.wheeled_robots.controllers.ackermann_controller_deprecated",
    "omni.isaac.wheeled_robots.ui": "isaacsim.robot.wheeled_robots.ui",
    "omni.isaac.surface_gripper": "isaacsim.robot.surface_gripper",
    "omni.isaac.surface_gripper.ui": "isaacsim.robot.surface_gripper.ui",
    "omni.isaac.quadruped": "isaacsim.robot.policy.examples",
    "omni.isaac.motion_generation": "isaacsim.robot_motion.motion_generation",
    "omni.isaac.lula": "isaacsim.robot_motion.lula",
    "omni.isaac.lula_test_widget": "isaacsim.robot_motion.lula_test_widget",
    "omni.isaac.grasp_editor": "isaacsim.robot_setup.grasp_editor",
    "omni.isaac.robot_assembler": "isaacsim.robot_setup.assembler",
    "omni.isaac.gain_tuner": "isaacsim.robot_setup.gain_tuner",
    "omni.isaac.robot_description_editor": "isaacsim.robot_setup.xrdf_editor",
    "omni.isaac.cortex": "isaacsim.cortex.framework",
    "omni.isaac.cortex.sample_behaviors": "isaacsim.cortex.behaviors",
    "omni.isaac.examples": "isaacsim.examples.interactive",
    "omni.isaac.examples.humanoid.h1": "isaacsim.robot.policy.examples.robots.h1",
    "omni.isaac.extension_templates": "isaacsim.examples.extension",
    "omni.isaac.ui_template": "isaacsim.examples.ui",
    "omni.isaac.doctest": "isaacsim.test.docstring",
    "omni.isaac.tests": "isaacsim.test.collection",
    # assets, apps, user interface, utilities, ROS
    "omni.isaac.asset_browser": "isaacsim.asset.browser",
    "omni.isaac.assets_check": "isaacsim.asset.browser",
    "omni.isaac.block_world": "isaacsim.asset.importer.heightmap",
    "omni.isaac.conveyor": "isaacsim.asset.gen.conveyor",
    "omni.isaac.conveyor.ui": "isaacsim.asset.gen.conveyor.ui",
    "omni.isaac.occupancy_map": "isaacsim.asset.gen.omap",
    "omni.isaac.occupancy_map.ui": "isaacsim.asset.gen.omap.ui",
    "omni.importer.urdf": "isaacsim.asset.importer.urdf",
    "omni.importer.mjcf": "isaacsim.asset.importer.mjcf",
    "omni.exporter.urdf": "isaacsim.asset.exporter.urdf",
    "omni.isaac.app.selector": "isaacsim.app.selector",
    "omni.isaac.app.setup": "isaacsim.app.setup",
    "omni.isaac.window.about": "isaacsim.app.about",
    "omni.isaac.ui": "isaacsim.gui.components",
    "omni.isaac.ui.element_wrappers.core_connectors": "isaacsim.examples.extension.core_connectors",
    "omni.isaac.menu": "isaacsim.gui.menu",
    "omni.kit.property.isaac": "isaacsim.gui.property",
    "omni.isaac.camera_inspector": "isaacsim.util.camera_inspector",
    "omni.isaac.merge_mesh": "isaacsim.util.merge_mesh",
    "omni.isaac.physics_utilities": "isaacsim.util.physics",
    "omni.isaac.articulation_inspector": "omni.physx.inspector",
    "omni.isaac.unit_converter": "omni.usd.metrics_assembler",
    "omni.isaac.vscode": "isaacsim.code_editor.vscode",
    "omni.isaac.jupyter_notebook": "isaacsim.code_editor.jupyter",
    "omni.isaac.ros2_bridge": "isaacsim.ros2.bridge",
    "omni.isaac.ros2_bridge.robot_description": "isaacsim.ros2.urdf",
    "omni.isaac.tf_viewer": "isaacsim.ros2.tf_viewer",
    "omni.usd.schema.isaac": "isaacsim.robot.schema",
}

_PRIMS = "isaacsim.core.prims"
_SENSOR_COMMANDS = {
    "IsaacSensorCreateContactSensor": "isaacsim.sensors.physics:IsaacSensorCreateContactSensor",
    "IsaacSensorCreateImuSensor": "isaacsim.sensors.physics:IsaacSensorCreateImuSensor",
    "IsaacSensorCreatePrim": "isaacsim.sensors.physics:IsaacSensorCreatePrim",
    "IsaacSensorCreateLightBeamSensor": "isaacsim.sensors.physx:IsaacSensorCreateLightBeamSensor",
    "IsaacSensorCreateRtxIDS": "isaacsim.sensors.rtx:IsaacSensorCreateRtxIDS",
    "IsaacSensorCreateRtxLidar": "isaacsim.sensors.rtx:IsaacSensorCreateRtxLidar",
    "IsaacSensorCreateRtxRadar": "isaacsim.sensors.rtx:IsaacSensorCreateRtxRadar",
}
_CAMERA = {name: f"isaacsim.sensors.camera:{name}" for name in (
    "Camera", "R_U_TRANSFORM", "U_R_TRANSFORM", "U_W_TRANSFORM", "W_U_TRANSFORM", "distort_point_kannala_brandt",
    "distort_point_rational_polynomial", "point_to_theta")}

NAMES: dict[str, dict[str, str]] = {
    # the single-prim classes took a Single prefix; the old *View classes took the plain names
    "omni.isaac.core.prims": {
        "XFormPrim": f"{_PRIMS}:SingleXFormPrim", "XFormPrimView": f"{_PRIMS}:XFormPrim",
        "RigidPrim": f"{_PRIMS}:SingleRigidPrim", "RigidPrimView": f"{_PRIMS}:RigidPrim",
        "GeometryPrim": f"{_PRIMS}:SingleGeometryPrim", "GeometryPrimView": f"{_PRIMS}:GeometryPrim",
        "ClothPrim": f"{_PRIMS}:SingleClothPrim", "ClothPrimView": f"{_PRIMS}:ClothPrim",
        "ParticleSystem": f"{_PRIMS}:SingleParticleSystem", "ParticleSystemView": f"{_PRIMS}:ParticleSystem",
        "BaseSensor": "isaacsim.core.api.sensors.base_sensor:BaseSensor",
        "RigidContactView": "isaacsim.core.api.sensors.rigid_contact_view:RigidContactView",
    },
    "omni.isaac.core.prims.xform_prim": {"XFormPrim": f"{_PRIMS}:SingleXFormPrim"},
    "omni.isaac.core.prims.xform_prim_view": {"XFormPrimView": f"{_PRIMS}:XFormPrim"},
    "omni.isaac.core.prims.rigid_prim": {"RigidPrim": f"{_PRIMS}:SingleRigidPrim"},
    "omni.isaac.core.prims.rigid_prim_view": {"RigidPrimView": f"{_PRIMS}:RigidPrim"},
    "omni.isaac.core.prims.geometry_prim": {"GeometryPrim": f"{_PRIMS}:SingleGeometryPrim"},
    "omni.isaac.core.prims.geometry_prim_view": {"GeometryPrimView": f"{_PRIMS}:GeometryPrim"},
    "omni.isaac.core.prims.sdf_shape_view": {"SdfShapeView": f"{_PRIMS}:SdfShapePrim"},
    "omni.isaac.core.prims.soft.cloth_prim": {"ClothPrim": f"{_PRIMS}:SingleClothPrim"},
    "omni.isaac.core.prims.soft.cloth_prim_view": {"ClothPrimView": f"{_PRIMS}:ClothPrim"},
    "omni.isaac.core.prims.soft.deformable_prim": {"DeformablePrim": f"{_PRIMS}:SingleDeformablePrim"},
    "omni.isaac.core.prims.soft.deformable_prim_view": {"DeformablePrimView": f"{_PRIMS}:DeformablePrim"},
    "omni.isaac.core.prims.soft.particle_system": {"ParticleSystem": f"{_PRIMS}:SingleParticleSystem"},
    "omni.isaac.core.prims.soft.particle_system_view": {"ParticleSystemView": f"{_PRIMS}:ParticleSystem"},
    "omni.isaac.core.articulations": {
        "Articulation": f"{_PRIMS}:SingleArticulation", "ArticulationView": f"{_PRIMS}:Articulation",
        "ArticulationGripper": "isaacsim.core.api.articulations:ArticulationGripper",
        "ArticulationSubset": "isaacsim.core.api.articulations:ArticulationSubset",
    },
    "omni.isaac.core.articulations.articulation": {"Articulation": f"{_PRIMS}:SingleArticulation"},
    "omni.isaac.core.articulations.articulation_view": {"ArticulationView": f"{_PRIMS}:Articulation"},
    "omni.isaac.core.articulations.articulation_gripper": {
        "ArticulationGripper": "isaacsim.core.api.articulations.articulation_gripper:ArticulationGripper"},
    "omni.isaac.core.articulations.articulation_subset": {
        "ArticulationSubset": "isaacsim.core.api.articulations.articulation_subset:ArticulationSubset",
        "require_initialized": "isaacsim.core.api.articulations.articulation_subset:require_initialized"},
    # the sensor extension was split four ways
    "omni.isaac.sensor": {
        **_CAMERA, **_SENSOR_COMMANDS, "CameraView": "isaacsim.sensors.camera:CameraView",
        "ContactSensor": "isaacsim.sensors.physics:ContactSensor", "IMUSensor": "isaacsim.sensors.physics:IMUSensor",
        "LidarRtx": "isaacsim.sensors.rtx:LidarRtx", "RotatingLidarPhysX": "isaacsim.sensors.physx:RotatingLidarPhysX",
        "_sensor": "isaacsim.sensors.physics:_sensor",
    },
    "omni.isaac.sensor.camera": _CAMERA,
    "omni.isaac.sensor.camera_view": {"CameraView": "isaacsim.sensors.camera:CameraView"},
    "omni.isaac.sensor.commands": _SENSOR_COMMANDS,
    "omni.isaac.sensor.contact_sensor": {"ContactSensor": "isaacsim.sensors.physics:ContactSensor"},
    "omni.isaac.sensor.imu_sensor": {"IMUSensor": "isaacsim.sensors.physics:IMUSensor"},
    "omni.isaac.sensor.effort_sensor": {"EffortSensor": "isaacsim.sensors.physics:EffortSensor",
                                        "EsSensorReading": "isaacsim.sensors.physics:EsSensorReading"},
    "omni.isaac.sensor.scripts.effort_sensor": {"EffortSensor": "isaacsim.sensors.physics:EffortSensor",
                                                "EsSensorReading": "isaacsim.sensors.physics:EsSensorReading"},
    "omni.isaac.sensor.lidar_rtx": {"LidarRtx": "isaacsim.sensors.rtx:LidarRtx"},
    "omni.isaac.sensor.rotating_lidar_physX": {"RotatingLidarPhysX": "isaacsim.sensors.physx:RotatingLidarPhysX"},
    "omni.isaac.proximity_sensor.extension": {
        "Sensor": "isaacsim.sensors.physx:ProximitySensor",
        "SensorManager": "isaacsim.sensors.physx:ProximitySensorManager",
        "clear_sensors": "isaacsim.sensors.physx:clear_sensors",
        "register_sensor": "isaacsim.sensors.physx:register_sensor"},
    "omni.isaac.occupancy_map.bindings": {"_occupancy_map": "isaacsim.asset.gen.omap.bindings:_omap"},
    # domain randomization and writers left omni.replicator.isaac
    "omni.replicator.isaac": {
        name: f"isaacsim.replicator.domain_randomization:{name}" for name in (
            "context", "gate", "physics_view", "trigger", "utils", "ARTICULATION_ATTRIBUTES", "RIGID_PRIM_ATTRIBUTES",
            "SIMULATION_CONTEXT_ATTRIBUTES", "TENDON_ATTRIBUTES")},
    **{f"omni.replicator.isaac.scripts.writers.{module}": {writer: f"isaacsim.replicator.writers:{writer}"}
       for module, writer in (("pose_writer", "PoseWriter"), ("dope_writer", "DOPEWriter"),
                              ("ycb_video_writer", "YCBVideoWriter"), ("pytorch_writer", "PytorchWriter"),
                              ("pytorch_listener", "PytorchListener"),
                              ("data_visualization_writer", "DataVisualizationWriter"))},
}

REMOVED: dict[str, str] = {
    "omni.isaac.dynamic_control": "Isaac Sim 4.5 deprecated it without a replacement (its articulation and rigid-body "
                                  "handles became isaacsim.core.prims' views)",
    "omni.isaac.physics_inspector": "Isaac Sim 4.2 replaced it by PhysX's visualization tools, which have no Python "
                                    "API",
    "omni.isaac.examples_nodes": "Isaac Sim 4.5 deprecated it without a replacement",
}

EXTENSIONS: dict[str, tuple[str, ...]] = {
    "omni.isaac.core": ("isaacsim.core.api",),
    "omni.isaac.kit": ("isaacsim.simulation_app",),
    "omni.isaac.cloner": ("isaacsim.core.cloner",),
    "omni.isaac.utils": ("isaacsim.core.utils",),
    "omni.isaac.version": ("isaacsim.core.version",),
    "omni.isaac.throttling": ("isaacsim.core.throttling",),
    "omni.isaac.core_nodes": ("isaacsim.core.nodes",),
    "omni.isaac.common_includes": ("isaacsim.core.includes",),
    "omni.isaac.nucleus": ("isaacsim.storage.native",),
    "omni.replicator.isaac": ("isaacsim.replicator.domain_randomization", "isaacsim.replicator.examples",
                              "isaacsim.replicator.writers"),
    "omni.isaac.synthetic_recorder": ("isaacsim.replicator.synthetic_recorder",),
    "omni.isaac.scene_blox": ("isaacsim.replicator.scene_blox",),
    "omni.isaac.benchmark.services": ("isaacsim.benchmark.services",),
    "omni.isaac.benchmarks": ("isaacsim.benchmark.examples",),
    "omni.isaac.sensor": ("isaacsim.sensors.camera", "isaacsim.sensors.physics", "isaacsim.sensors.physx",
                          "isaacsim.sensors.rtx"),
    "omni.isaac.range_sensor": ("isaacsim.sensors.physx",),
    "omni.isaac.range_sensor.ui": ("isaacsim.sensors.physx.ui",),
    "omni.isaac.range_sensor.examples": ("isaacsim.sensors.physx.examples",),
    "omni.isaac.proximity_sensor": ("isaacsim.sensors.physx",),
    "omni.isaac.debug_draw": ("isaacsim.util.debug_draw",),
    "omni.isaac.manipulators": ("isaacsim.robot.manipulators",),
    "omni.isaac.manipulators.ui": ("isaacsim.robot.manipulators.ui",),
    "omni.isaac.franka": ("isaacsim.robot.manipulators.examples",),
    "omni.isaac.universal_robots": ("isaacsim.robot.manipulators.examples",),
    "omni.isaac.wheeled_robots": ("isaacsim.robot.wheeled_robots", "isaacsim.robot.wheeled_robots.examples"),
    "omni.isaac.wheeled_robots.ui": ("isaacsim.robot.wheeled_robots.ui",),
    "omni.isaac.surface_gripper": ("isaacsim.robot.surface_gripper",),
    "omni.isaac.surface_gripper.ui": ("isaacsim.robot.surface_gripper.ui",),
    "omni.isaac.quadruped": ("isaacsim.robot.policy.examples",),
    "omni.isaac.motion_generation": ("isaacsim.robot_motion.motion_generation",),
    "omni.isaac.lula": ("isaacsim.robot_motion.lula",),
    "omni.isaac.lula_test_widget": ("isaacsim.robot_motion.lula_test_widget",),
    "omni.isaac.grasp_editor": ("isaacsim.robot_setup.grasp_editor",),
    "omni.isaac.robot_assembler": ("isaacsim.robot_setup.assembler",),
    "omni.isaac.gain_tuner": ("isaacsim.robot_setup.gain_tuner",),
    "omni.isaac.robot_description_editor": ("isaacsim.robot_setup.xrdf_editor",),
    "omni.isaac.cortex": ("isaacsim.cortex.framework",),
    "omni.isaac.cortex.sample_behaviors": ("isaacsim.cortex.behaviors",),
    "omni.isaac.examples": ("isaacsim.examples.interactive",),
    "omni.isaac.extension_templates": ("isaacsim.examples.extension",),
    "omni.isaac.ui_template": ("isaacsim.examples.ui",),
    "omni.isaac.doctest": ("isaacsim.test.docstring",),
    "omni.isaac.tests": ("isaacsim.test.collection",),
    "omni.isaac.asset_browser": ("isaacsim.asset.browser",),
    "omni.isaac.assets_check": ("isaacsim.asset.browser",),
    "omni.isaac.block_world": ("isaacsim.asset.importer.heightmap",),
    "omni.isaac.conveyor": ("isaacsim.asset.gen.conveyor",),
    "omni.isaac.conveyor.ui": ("isaacsim.asset.gen.conveyor.ui",),
    "omni.isaac.occupancy_map": ("isaacsim.asset.gen.omap",),
    "omni.isaac.occupancy_map.ui": ("isaacsim.asset.gen.omap.ui",),
    "omni.importer.urdf": ("isaacsim.asset.importer.urdf",),
    "omni.importer.mjcf": ("isaacsim.asset.importer.mjcf",),
    "omni.exporter.urdf": ("isaacsim.asset.exporter.urdf",),
    "omni.isaac.app.selector": ("isaacsim.app.selector",),
    "omni.isaac.app.setup": ("isaacsim.app.setup",),
    "omni.isaac.window.about": ("isaacsim.app.about",),
    "omni.isaac.ui": ("isaacsim.gui.components",),
    "omni.isaac.menu": ("isaacsim.gui.menu",),
    "omni.kit.property.isaac": ("isaacsim.gui.property",),
    "omni.isaac.camera_inspector": ("isaacsim.util.camera_inspector",),
    "omni.isaac.merge_mesh": ("isaacsim.util.merge_mesh",),
    "omni.isaac.physics_utilities": ("isaacsim.util.physics",),
    "omni.isaac.articulation_inspector": ("omni.physx.inspector",),
    "omni.isaac.unit_converter": ("omni.usd.metrics_assembler",),
    "omni.isaac.vscode": ("isaacsim.code_editor.vscode",),
    "omni.isaac.jupyter_notebook": ("isaacsim.code_editor.jupyter",),
    "omni.isaac.ros2_bridge": ("isaacsim.ros2.bridge",),
    "omni.isaac.ros2_bridge.robot_description": ("isaacsim.ros2.urdf",),
    "omni.isaac.tf_viewer": ("isaacsim.ros2.tf_viewer",),
    "omni.usd.schema.isaac": ("isaacsim.robot.schema",),
}
