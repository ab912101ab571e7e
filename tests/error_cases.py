"""The mistakes a user can make, with the exact error graphsdg answers: the source of ``docs/errors.md``.

``tests/test_errors.py`` runs every case and asserts its exception type and its
whole message; ``python tests/error_cases.py`` regenerates ``docs/errors.md`` from
the same list (and a test checks that the file is current), so the table and the
behaviour cannot drift apart.

Each case's ``code`` runs on a fresh stage holding ``/World`` with a dome light,
a labelled unit ``cube`` at ``/World/Cube``, a ``cam`` at ``/World/Camera`` and a
32x32 render product ``rp`` of it. ``tmp`` is a scratch folder holding
``bad.usda`` (a USD file with a syntax error), ``notes.txt`` (not USD) and
``broken.png`` (a truncated PNG); ``<tmp>`` stands for it in messages. ``cli(...)``
runs the ``graphsdg`` command line in-process and reports its exit status and its
error line (the ``hint:`` line after it is left out).
"""
from __future__ import annotations

import contextlib
import io
import os
import sys
from dataclasses import dataclass

from graphsdg.compat import isaac as _isaac_areas  # noqa: F401 - its areas register their settings keys, which case 102 lists
from graphsdg.settings import KNOWN_KEYS

DOC = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "docs", "errors.md")


@dataclass(frozen=True)
class Case:
    area: str
    mistake: str
    code: str
    error: str          # exception class name, "UserWarning" (a warning, not an error) or "exit N" (command line)
    message: str        # the exact message; "<tmp>" stands for the scratch folder


class CommandFailed(Exception):
    """What ``cli(...)`` raises: the exit status and the error line of ``graphsdg ...``."""

    def __init__(self, code: int, line: str) -> None:
        super().__init__(line)
        self.code = code


def cli(*args: str) -> None:
    """Run ``graphsdg *args`` in-process; raise :class:`CommandFailed` unless it exits 0."""
    from graphsdg.jobs.cli import main
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        try:
            code = main(list(args))
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
    if code:
        lines = [line for line in err.getvalue().splitlines() if line and not line.startswith(("hint:", "usage:"))]
        raise CommandFailed(code, lines[-1] if lines else "")


def C(area: str, mistake: str, code: str, error: str, message: str) -> Case:  # noqa: N802 - reads as a table row
    return Case(area, mistake, code, error, message)


CASES: list[Case] = [
    # ---- functional API -------------------------------------------------------------------------------------
    C("functional", "a position with two numbers", "rep.functional.create.cube(position=(1, 2))",
      "ValueError", "position must be 3 finite numbers, got (1, 2)"),
    C("functional", "a position that is not numbers", 'rep.functional.create.cube(position="abc")',
      "ValueError", "position must be 3 finite numbers, got 'abc'"),
    C("functional", "a position that is not finite", 'rep.functional.modify.pose(cube, position_value=[float("nan"), 0, 0])',
      "ValueError", "position must be 3 finite numbers, got [nan, 0.0, 0.0]"),
    C("functional", "a rotation that is neither Euler angles nor a quaternion", "rep.functional.create.cube(rotation=(1, 2))",
      "ValueError", "rotation must be 3 Euler angles (degrees) or a quaternion (w, x, y, z), got (1, 2)"),
    C("functional", "an unknown rotation order",
      'rep.functional.modify.pose(cube, rotation_value=(0, 0, 0), rotation_order="XYY")',
      "ValueError", "rotation_order must be one of ('XYZ', 'XZY', 'YXZ', 'YZX', 'ZXY', 'ZYX'), got 'XYY'"),
    C("functional", "rotation and look_at together",
      "rep.functional.modify.pose(cube, rotation_value=(0, 0, 0), look_at_value=(1, 1, 1))",
      "ValueError", "rotation and look_at are exclusive; pass one of them"),
    C("functional", "a parent that does not exist", 'rep.functional.create.cube(parent="/Nope")',
      "PrimNotFoundError", "parent '/Nope' does not exist on the stage; create it first "
                           "(e.g. rep.functional.create.xform(name=...))"),
    C("functional", "a prim path that does not exist", 'rep.functional.modify.pose("/World/Nope", position_value=(1, 2, 3))',
      "PrimNotFoundError", "no prim at path '/World/Nope' on the current stage"),
    C("functional", "a relative prim path", 'rep.functional.modify.pose("World/Cube", position_value=(1, 2, 3))',
      "PrimNotFoundError", "'World/Cube' is not an absolute prim path (expected e.g. '/World/Cube')"),
    C("functional", "semantics given as a bare string", 'rep.functional.create.cube(semantics="cube")',
      "TypeError", "semantics must be a dict {'class': 'cube'} or a list of (type, label) pairs such as "
                   "[('class', 'cube')], got the string 'cube'"),
    C("functional", "an empty semantic label", 'rep.functional.modify.semantics(cube, {"class": ""})',
      "ValueError", "semantic label of type 'class' must be a non-empty string, got ''"),
    C("functional", "an unknown semantics mode", 'rep.functional.modify.semantics(cube, {"class": "x"}, mode="merge")',
      "ValueError", "semantics mode must be one of ('add', 'replace', 'clear'), got 'merge'"),
    C("functional", "one value per prim, but too many values", "rep.functional.modify.pose([cube, cam], position_value=[(0, 0, 0)] * 3)",
      "ValueError", "position_value has 3 rows but count/prims is 2"),
    C("functional", "a misspelt attribute name", 'rep.functional.modify.attribute(cube, "sizee", 3)',
      "ValueError", "prim /World/Cube has no attribute 'sizee' (did you mean 'size'?); pass attribute_type to create "
                    "it. Its attributes: ['doubleSided', 'extent', 'orientation', 'primvars:displayColor', "
                    "'primvars:displayOpacity', 'purpose', 'semantics:labels:class', 'size', 'visibility', "
                    "'xformOpOrder']"),
    C("functional", "an attribute value of the wrong type", 'rep.functional.modify.attribute(cube, "size", "big")',
      "TypeError", "cannot set /World/Cube.size to 'big': expected a value of type double"),
    C("functional", "visibility that is not a bool", 'rep.functional.modify.visibility(cube, "no")',
      "TypeError", "visibility must be True or False (or one of them per prim), got 'no'"),
    C("functional", "a display colour on a prim without one", "rep.functional.modify.display_color(cam, (1, 0, 0))",
      "TypeError", "prim /World/Camera (Camera) has no displayColor (not a gprim)"),
    C("functional", "binding a prim that is not a material", "rep.functional.modify.material(cube, cam)",
      "TypeError", "/World/Camera is a 'Camera' prim, not a Material"),
    C("functional", "a light intensity that is not a number", 'rep.functional.create.dome_light(intensity="bright")',
      "ValueError", "intensity must be a finite number, got 'bright'"),
    C("functional", "a light colour with two channels", "rep.functional.create.dome_light(color=(1, 0))",
      "ValueError", "color must be an (r, g, b) colour of 3 finite numbers >= 0, got (1, 0)"),
    C("functional", "a negative light radius", "rep.functional.create.sphere_light(radius=-1)",
      "ValueError", "radius must be a finite number > 0, got -1.0"),
    C("functional", "a camera focal length that is not a number", 'rep.functional.create.camera(focal_length="long")',
      "ValueError", "focal_length must be a finite number > 0, got 'long'"),
    C("functional", "a clipping range with near beyond far", "rep.functional.create.camera(clipping_range=(10, 1))",
      "ValueError", "clipping_range must be (near, far) with 0 < near < far, got (10, 1)"),
    C("functional", "a camera projection graphsdg does not render", 'rep.functional.create.camera(projection_type="fisheye")',
      "ValueError", "projection_type 'fisheye' is not available; graphsdg renders 'pinhole' (perspective) and "
                    "'orthographic' cameras"),
    C("functional", "a batch of zero prims", "rep.functional.create_batch.cube(count=0)",
      "ValueError", "count must be a positive integer, got 0"),
    C("functional", "a colour range with min above max",
      "rep.functional.randomizer.display_color([cube], min_value=(1, 1, 1), max_value=(0, 0, 0))",
      "ValueError", "display_color range must be two RGB triples with min <= max, got (1, 1, 1), (0, 0, 0)"),
    C("functional", "an int where a random generator is expected", "rep.functional.randomizer.display_color([cube], rng=42)",
      "TypeError", "rng must be a ReplicatorRNG, a numpy Generator or None, got int"),
    C("functional", "scattering onto nothing", "rep.functional.randomizer.scatter_2d([cube], surface_prims=[])",
      "ValueError", "scatter_2d needs at least one surface prim to scatter on, got none (surface_prims=[])"),
    C("functional", "scattering onto a prim without a surface", "rep.functional.randomizer.scatter_2d([cube], surface_prims=[cam])",
      "ValueError", "prim /World/Camera (Camera) has no surface to scatter on (expected a Plane, Mesh or other shape "
                    "at or below it)"),
    # ---- assets and USD ------------------------------------------------------------------------------------
    C("assets", "a texture file that does not exist",
      'rep.functional.create.material(mdl="OmniPBR.mdl", diffuse_texture="/no/such.png")',
      "FileNotFoundError", "diffuse_texture '/no/such.png' does not exist"),
    C("assets", "a sky texture that does not exist", 'rep.functional.create.dome_light(texture="/no/sky.hdr")',
      "FileNotFoundError", "dome light texture '/no/sky.hdr' does not exist"),
    C("assets", "a texture file that is not an image",
      'rep.functional.create.material(mdl="OmniPBR.mdl", diffuse_texture=os.path.join(tmp, "broken.png"), '
      "bind_prims=[cube])\nrep.annotators.get(\"rgb\").attach(rp)\nrep.orchestrator.step()",
      "CompileError", "material /OmniPBR: texture file '<tmp>/broken.png' could not be decoded as an image "
                      "(Truncated File Read)"),
    C("assets", "an unknown material input (typo)",
      'rep.functional.create.material(mdl="OmniPBR.mdl", diffuse_textur="wood.png")',
      "ValueError", "unknown material input(s) ['diffuse_textur'] (did you mean 'diffuse_texture'?); known: "
                    "['diffuse_color_constant', 'diffuse_texture', 'emissive_color', 'emissive_intensity', "
                    "'enable_emission', 'metallic_constant', 'project_uvw', 'reflection_roughness_constant', "
                    "'specular_level', 'texture_rotate', 'texture_scale']"),
    C("assets", "referencing a USD file that does not exist", 'rep.functional.create.reference(os.path.join(tmp, "missing.usd"))',
      "FileNotFoundError", "reference usd_path '<tmp>/missing.usd' does not exist"),
    C("assets", "referencing a USD file with a syntax error", 'rep.functional.create.reference(os.path.join(tmp, "bad.usda"))',
      "ValueError", "reference usd_path '<tmp>/bad.usda' does not parse as USD: <tmp>/bad.usda:2:3: Expected ) at "
                    "'garbage here' in </>"),
    C("assets", "referencing a file that is not USD", 'rep.create.from_usd(os.path.join(tmp, "notes.txt"))',
      "ValueError", "reference usd_path '<tmp>/notes.txt' does not parse as USD: Cannot determine file format for "
                    "@<tmp>/notes.txt@"),
    C("assets", "a mesh with no points (invalid USD geometry)",
      'UsdGeom.Mesh.Define(rep.stage.get_stage(), "/World/M")\nrep.annotators.get("rgb").attach(rp)\n'
      "rep.orchestrator.step()",
      "CompileError", "mesh /World/M has no points or faces"),
    C("assets", "a mesh whose faces index missing points",
      'm = UsdGeom.Mesh.Define(rep.stage.get_stage(), "/World/M")\nm.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (0, 1, 0)])\n'
      "m.CreateFaceVertexCountsAttr([3])\nm.CreateFaceVertexIndicesAttr([0, 1, 7])\n"
      'rep.annotators.get("rgb").attach(rp)\nrep.orchestrator.step()',
      "CompileError", "mesh /World/M has face indices outside its 3 points"),
    C("assets", "a cube with a negative size authored in USD",
      'cube.GetAttribute("size").Set(-2.0)\nrep.annotators.get("rgb").attach(rp)\nrep.orchestrator.step()',
      "CompileError", "Cube /World/Cube has size -2.0; expected a positive number"),
    # ---- stage ------------------------------------------------------------------------------------------------
    C("stage", "opening a USD file that does not exist", 'rep.stage.open_stage(os.path.join(tmp, "missing.usd"))',
      "FileNotFoundError", "cannot open stage: no USD file at '<tmp>/missing.usd'"),
    C("stage", "opening a USD file with a syntax error", 'rep.stage.open_stage(os.path.join(tmp, "bad.usda"))',
      "ValueError", "cannot open stage '<tmp>/bad.usda': the file does not parse as USD: <tmp>/bad.usda:2:3: "
                    "Expected ) at 'garbage here' in </>; Failed to open layer @<tmp>/bad.usda@"),
    C("stage", "saving an in-memory stage without a path", "rep.stage.save()",
      "ValueError", "the stage is in memory only; pass save(path='scene.usda')"),
    # ---- physics ----------------------------------------------------------------------------------------------
    C("physics", "a misspelt rigid-body argument", "rep.functional.physics.apply_rigid_body(cube, kinematic=True)",
      "ValueError", "apply_rigid_body got unknown argument(s) ['kinematic'] (did you mean 'kinematicEnabled'?); "
                    "known: with_collider, kinematicEnabled, approximation, mass, density, disableGravity"),
    C("physics", "a rigid body with nothing to collide", 'rep.functional.physics.apply_rigid_body(rep.functional.create.xform(name="Empty"))',
      "ValueError", "prim /Empty has no geometry under it; a rigid body needs a shape (a Cube, Sphere, Cylinder, Cone, "
                    "Capsule, Plane or Mesh at or below it)"),
    C("physics", "a zero mass", "rep.functional.physics.apply_rigid_body(cube, mass=0)",
      "ValueError", "mass must be a positive finite number, got 0"),
    C("physics", "a mass API with neither mass nor density", "rep.functional.physics.apply_mass(cube)",
      "ValueError", "apply_mass needs mass (kg) or density (kg/m³)"),
    C("physics", "a misspelt collider approximation", 'rep.functional.physics.apply_collider(cube, approximation="convexHulll")',
      "ApproximationError", "unknown collider approximation 'convexHulll' (did you mean 'convexHull'?); known "
                            "approximations: none, convexHull, convexDecomposition, boundingCube, boundingSphere, "
                            "meshSimplification, sdf, sphereFill"),
    C("physics", "a collider on a prim without geometry", "rep.functional.physics.apply_collider(cam)",
      "ValueError", "prim /World/Camera has no geometry under it to collide with (expected a Cube, Sphere, Cylinder, "
                    "Cone, Capsule, Plane or Mesh at or below it)"),
    C("physics", "a gravity direction of zero length",
      "rep.functional.physics.create_physics_scene(gravity_direction=(0, 0, 0))",
      "ValueError", "gravity_direction must be a non-zero 3-vector, got (0, 0, 0)"),
    # ---- graph API and distributions ----------------------------------------------------------------------------
    C("graph", "a uniform distribution with lower above upper", "rep.distribution.uniform(1, 0)",
      "ValueError", "uniform: lower 1 is greater than upper 0; expected lower <= upper element-wise"),
    C("graph", "uniform bounds of different lengths", "rep.distribution.uniform((0, 0), (1, 1, 1))",
      "ValueError", "uniform: lower (0, 0) and upper (1, 1, 1) have different shapes (2,) and (3,); give both as "
                    "numbers or as tuples of one length"),
    C("graph", "a negative standard deviation", "rep.distribution.normal(0, -1)",
      "ValueError", "normal: std -1 is negative; expected std >= 0"),
    C("graph", "a log-uniform distribution starting at 0", "rep.distribution.log_uniform(0, 1)",
      "ValueError", "log_uniform: lower 0 must be > 0"),
    C("graph", "choosing from nothing", "rep.distribution.choice([])",
      "ValueError", "choice: choices is empty ([]); give at least one value to choose from"),
    C("graph", "choice weights that do not match the choices", "rep.distribution.choice([1, 2], weights=[1])",
      "ValueError", "choice: weights [1] has 1 entries but there are 2 choices"),
    C("graph", "zero samples", "rep.distribution.uniform(0, 1, num_samples=0)",
      "ValueError", "num_samples must be a positive integer, got 0"),
    C("graph", "an unknown light type", 'rep.create.light(light_type="Spot")',
      "ValueError", "create.light: light_type 'Spot' is not one of ['cylinder', 'disk', 'distant', 'dome', 'rect', "
                    "'sphere'] (case-insensitive)"),
    C("graph", "a modifier outside any 'with' block and without input_prims", "rep.modify.pose(position=(1, 2, 3))",
      "GraphBuildError", "rep.modify.pose() has no target: call it inside 'with <item>:' (e.g. with "
                         "rep.get.prims(...):) or pass input_prims=..."),
    C("graph", "a trigger inside another trigger",
      "with rep.trigger.on_frame():\n    with rep.trigger.on_time(interval=1):\n        pass",
      "GraphBuildError", "on_time(interval=1, max_execs=0, rt_subframes=32, enable_capture_on_play=True, "
                         "reset_physics=True) is nested in trigger 'on_frame'; triggers cannot be nested: close the "
                         "outer 'with' block first"),
    C("graph", "a frame interval of 0", "rep.trigger.on_frame(interval=0)",
      "ValueError", "on_frame interval must be an integer >= 1, got 0"),
    C("graph", "a misspelt node type", 'rep.graph.NodeRegistry.create("distribution.unifrom")',
      "UnknownNameError", "unknown node type 'distribution.unifrom' (did you mean "
                          "'distribution.uniform'?); known node types: create.camera, create.capsule,"
                          ' create.cone, create.cube, create.cylinder, create.disk, create.from_usd, '
                          'create.group, create.light, create.material_omnipbr, create.omni_lidar, '
                          'create.omni_radar, create.plane, create.sphere, create.torus, '
                          'create.xform, distribution.choice, distribution.combine, '
                          'distribution.log_uniform, distribution.normal, distribution.sequence, '
                          'distribution.uniform, gate.environments, get.prim_at_path, get.prims, '
                          'modify.attribute, modify.material, modify.pose, '
                          'modify.pose_camera_relative, modify.pose_orbit, modify.semantics, '
                          'modify.timeline, modify.variant, modify.visibility, physics.collider, '
                          'physics.drive_properties, physics.mass, physics.physics_material, '
                          'physics.reset, physics.rigid_body, physics.simulate, randomizer.color, '
                          'randomizer.instantiate, randomizer.materials, randomizer.rotation, '
                          'randomizer.scatter_2d, randomizer.scatter_3d, randomizer.texture, '
                          'randomizer.write_articulation_view, randomizer.write_rigid_body_view, '
                          'randomizer.write_simulation, trigger.on_condition, '
                          'trigger.on_custom_event, trigger.on_frame, trigger.on_rl_frame, '
                          'trigger.on_time, trigger.on_time_end'),
    C("graph", "an invalid regular expression in get.prims", 'rep.get.prims(path_pattern="[")',
      "ValueError", "path_pattern '[' is not a valid regular expression: unterminated character set at position 0"),
    C("graph", "a distribution of 2-vectors for a 3-vector position",
      "with rep.trigger.on_frame():\n    rep.modify.pose(position=rep.distribution.uniform((0, 0), (0, 0)), "
      "input_prims=[cube])\nrep.orchestrator.step()",
      "ValueError", "modify.pose position (one draw of 'uniform'): got [0.0, 0.0] (shape (2,)) for 1 prim; expected "
                    "one value (a scalar or (x, y, z))"),
    C("graph", "seeking to a negative frame", "rep.graph.seek(-1)",
      "ValueError", "seek frame must be a non-negative integer, got -1"),
    # ---- annotators --------------------------------------------------------------------------------------------
    C("annotators", "a misspelt annotator name", 'rep.annotators.get("semantic_segmentaton")',
      "AnnotatorRegistryError", "unknown annotator 'semantic_segmentaton' (did you mean "
                                "'semantic_segmentation'?); known annotators: CameraParams, "
                                'DepthSensorDistance, DepthSensorDistance_fast, DepthSensorImager, '
                                'DepthSensorImager_fast, DepthSensorPointCloudColor, '
                                'DepthSensorPointCloudColor_fast, DepthSensorPointCloudPosition, '
                                'DepthSensorPointCloudPosition_fast, GenericModelOutput, '
                                'GenericModelOutput_fast, HdrColor, HdrColorSD, HdrColor_fast, '
                                'IsaacComputeRTXLidarFlatScan, IsaacComputeRTXLidarFlatScan_fast, '
                                'IsaacCreateRTXLidarScanBuffer, '
                                'IsaacCreateRTXLidarScanBufferForFlatScan, '
                                'IsaacCreateRTXLidarScanBufferForFlatScan_fast, '
                                'IsaacCreateRTXLidarScanBuffer_fast, IsaacCreateRTXRadarPointCloud, '
                                'IsaacCreateRTXRadarPointCloud_fast, IsaacExtractRTXSensorPointCloud,'
                                ' IsaacExtractRTXSensorPointCloudNoAccumulator, '
                                'IsaacExtractRTXSensorPointCloudNoAccumulator_fast, '
                                'IsaacExtractRTXSensorPointCloud_fast, IsaacNoop, IsaacNoop_fast, '
                                'IsaacReadSimulationTime, IsaacReadSimulationTime_fast, '
                                'IsaacReadSystemTime, IsaacReadSystemTime_fast, LdrColor, LdrColorSD,'
                                ' MotionVectors, Occlusion, ReferenceTime, ReferenceTime_fast, '
                                'StableIdMap, StableIdMap_fast, bounding_box_2d_loose, '
                                'bounding_box_2d_loose_fast, bounding_box_2d_tight, '
                                'bounding_box_2d_tight_fast, bounding_box_3d, bounding_box_3d_360, '
                                'bounding_box_3d_360_fast, bounding_box_3d_fast, camera_params, '
                                'camera_params_fast, distance_to_camera, distance_to_camera_fast, '
                                'distance_to_image_plane, distance_to_image_plane_fast, dope, '
                                'dope_fast, instance_id_segmentation, instance_id_segmentation_fast, '
                                'instance_segmentation, instance_segmentation_fast, motion_vectors, '
                                'motion_vectors_fast, normals, normals_fast, occlusion, '
                                'occlusion_fast, pointcloud, pointcloud_fast, pose, pose_fast, rgb, '
                                'rgb_fast, semantic_segmentation, semantic_segmentation_fast, '
                                'sensor_point_cloud, sensor_point_cloud_fast, skeleton_data, '
                                'skeleton_data_fast'),
    C("annotators", "an annotator name that is not a string", "rep.annotators.get(3)",
      "TypeError", "annotator name must be a string, got int"),
    C("annotators", "a misspelt init parameter",
      'rep.annotators.get("semantic_segmentation", init_params={"colorise": True})',
      "ValueError", "annotator 'semantic_segmentation' has no init param(s) ['colorise'] (did you mean 'colorize'?); "
                    "known: ['colorize', 'semanticFilter', 'semanticTypes']"),
    C("annotators", "semanticTypes that are not a list of names",
      'rep.annotators.get("bounding_box_2d_tight", init_params={"semanticTypes": 3})',
      "SemanticFilterError", "semanticTypes must be a non-empty list of type names such as ['class'], got 3"),
    C("annotators", "a semantic filter that does not parse",
      'rep.annotators.get("semantic_segmentation", init_params={"semanticFilter": "class:cube;;"})',
      "SemanticFilterError", "semanticFilter 'class:cube;;' does not parse: expected a semantic type (or '*'), found "
                             "';' at position 11; grammar: type:label|label&!label, type:label ; type:label   ('*' = "
                             "any type or label, '|' or, '&' and, '!' not, ',' and between clauses, ';' or between "
                             "conjuncts)"),
    C("annotators", "reading data from an annotator that was never attached", 'rep.annotators.get("rgb").get_data()',
      "RuntimeError", "annotator 'rgb' is not attached to a render product; call attach(render_product) and step "
                      "first"),
    C("annotators", "attaching to a render product name that does not exist", 'rep.annotators.get("rgb").attach("nope")',
      "ValueError", "no render product named or at path 'nope'; live products: ['/Render/RenderProduct_Replicator']"),
    C("annotators", "a raw render output (AOV) name that does not exist",
      'rep.AnnotatorRegistry.register_annotator_from_aov("LdrColour")',
      "UnknownNameError", "unknown AOV 'LdrColour' (did you mean 'LdrColor'?); known AOVs: Camera3dPositionSD, "
                          "DepthLinearized, DistanceToCameraSD, DistanceToImagePlaneSD, HdrColor, HdrColorSD, "
                          "LdrColor, LdrColorSD, Motion2d, MotionVectorsSD, NormalSD, SmoothNormal, TargetMotionSD"),
    # ---- writers -------------------------------------------------------------------------------------------------
    C("writers", "a misspelt writer name", 'rep.writers.get("BasicWritter")',
      "UnknownNameError", "unknown writer 'BasicWritter' (did you mean 'BasicWriter'?); known "
                          'writers: BasicWriter, BopWriter, CocoWriter, CosmosWriter, DOPEWriter, '
                          'KittiWriter, PointCloudWriter, PoseWriter, PytorchWriter, '
                          'WebDatasetWriter, YCBVideoWriter, YoloWriter'),
    C("writers", "a misspelt writer flag", 'rep.writers.get("BasicWriter").initialize(output_dir=tmp, rgb=True, '
                                           'bounding_box_2d_thight=True)',
      "TypeError", "BasicWriter.initialize() got unknown parameter(s) ['bounding_box_2d_thight'] (did you mean "
                   "'bounding_box_2d_tight'?); known: ['output_dir', 's3_bucket', 's3_region', 's3_endpoint', "
                   "'semantic_types', 'rgb', 'bounding_box_2d_tight', 'bounding_box_2d_loose', "
                   "'semantic_segmentation', 'instance_id_segmentation', 'instance_segmentation', "
                   "'distance_to_camera', 'distance_to_image_plane', 'bounding_box_3d', 'occlusion', 'normals', "
                   "'motion_vectors', 'camera_params', 'pointcloud', 'pointcloud_include_unlabelled', "
                   "'image_output_format', 'colorize_semantic_segmentation', 'colorize_instance_id_segmentation', "
                   "'colorize_instance_segmentation', 'colorize_depth', 'skeleton_data', 'frame_padding', "
                   "'semantic_filter_predicate', 'use_common_output_dir', 'backend', 'provenance']"),
    C("writers", "a BasicWriter with no annotator enabled", 'rep.writers.get("BasicWriter").initialize(output_dir=tmp)',
      "ValueError", "BasicWriter: no annotator enabled; set at least one flag such as rgb=True"),
    C("writers", "a writer with nowhere to write", 'rep.writers.get("BasicWriter").initialize(rgb=True)',
      "ValueError", "No `backend`, `output_dir` or `s3_` parameter specified; BasicWriter needs somewhere to write "
                    "(e.g. output_dir='_out')"),
    C("writers", "an output_dir that is a file", 'rep.writers.get("BasicWriter").initialize(output_dir=os.path.join(tmp, '
                                                 '"notes.txt"), rgb=True)',
      "NotADirectoryError", "output_dir '<tmp>/notes.txt' exists and is a file, not a directory"),
    C("writers", "an output_dir that is not a path", 'rep.writers.get("BasicWriter").initialize(output_dir=3, rgb=True)',
      "TypeError", "BasicWriter: output_dir must be a path (str or os.PathLike), got 3"),
    C("writers", "an image format BasicWriter does not write",
      'rep.writers.get("BasicWriter").initialize(output_dir=tmp, rgb=True, image_output_format="tiff")',
      "ValueError", "image_output_format must be one of ('png', 'jpg', 'jpeg'), got 'tiff'"),
    C("writers", "semantic_types and a semantic filter together",
      'rep.writers.get("BasicWriter").initialize(output_dir=tmp, rgb=True, semantic_types=["class"], '
      'semantic_filter_predicate="class:*")',
      "ValueError", "BasicWriter: `semantic_types` (['class']) and `semantic_filter_predicate` ('class:*') are "
                    "mutually exclusive; pass one"),
    C("writers", "an S3 bucket name that S3 refuses",
      'rep.writers.get("BasicWriter").initialize(output_dir=tmp, rgb=True, s3_bucket="B")',
      "ValueError", "'B' is not an S3 bucket name (3-63 characters: lower-case letters, digits, '.', '-')"),
    C("writers", "an S3 region without a bucket",
      'rep.writers.get("BasicWriter").initialize(output_dir=tmp, rgb=True, s3_region="us-east-1")',
      "ValueError", "BasicWriter: s3_region given without s3_bucket; S3 output needs the bucket (s3_bucket=...)"),
    C("writers", "attaching a writer before initialize()", 'rep.writers.get("BasicWriter").attach(rp)',
      "ValueError", "BasicWriter.attach() before initialize(): call writer.initialize(...) first (BasicWriter: e.g. "
                    "output_dir='_out', rgb=True)"),
    C("writers", "attaching a writer to no render product",
      'w = rep.writers.get("BasicWriter")\nw.initialize(output_dir=tmp, rgb=True)\nw.attach([])',
      "ValueError", "BasicWriter.attach() needs at least one render product, got []"),
    C("writers", "a COCO segmentation format that does not exist",
      'rep.writers.get("CocoWriter").initialize(output_dir=tmp, segmentation="mask")',
      "ValueError", "CocoWriter: segmentation must be one of ('rle', 'polygon'), got 'mask'"),
    C("writers", "KITTI thresholds in the wrong order",
      'rep.writers.get("KittiWriter").initialize(output_dir=tmp, partly_occluded_threshold=2)',
      "ValueError", "KittiWriter: need 0 <= partly_occluded_threshold (2) <= fully_visible_threshold (0.95) <= 1"),
    C("writers", "registering something that is not a writer", "rep.WriterRegistry.register(object)",
      "TypeError", "WriterRegistry.register expects a rep.Writer subclass, got <class 'object'>"),
    # ---- backends ------------------------------------------------------------------------------------------------
    C("backends", "a misspelt backend name", 'rep.backends.get("DiskBackendd")',
      "UnknownNameError", "unknown backend 'DiskBackendd' (did you mean 'DiskBackend'?); known backends: "
                          "BackendDispatch, BackendGroup, DiskBackend, S3Backend"),
    C("backends", "writing through a backend that was never initialized", 'rep.backends.get("DiskBackend").write_blob("a.txt", b"x")',
      "RuntimeError", "DiskBackend was not initialized; call backend.initialize(output_dir=...)"),
    C("backends", "a path that leaves the output folder",
      'b = rep.backends.get("DiskBackend")\nb.initialize(output_dir=tmp)\nb.write_blob("../x.txt", b"x")',
      "ValueError", "path '../x.txt' escapes the output directory '<tmp>'"),
    C("backends", "a background write that fails (the error reaches the script)",
      'b = rep.backends.get("DiskBackend", init_params={"output_dir": tmp})\n'
      'b.schedule(rep.functional.write_image, data=np.zeros((4, 4), np.float64), path="bad.png")\n'
      "rep.orchestrator.wait_until_complete()",
      "WriterError", "a background write of 'bad.png' failed: ValueError: cannot encode an image of dtype float64; "
                     "expected uint8 or uint16"),
    # ---- render products -----------------------------------------------------------------------------------------
    C("render products", "a resolution with a zero edge", "rep.create.render_product(cam, (0, 10))",
      "ValueError", "resolution must be (width, height), two positive integers; got (0, 10)"),
    C("render products", "a resolution that is not integers", "rep.create.render_product(cam, (32.5, 32))",
      "ValueError", "resolution must be (width, height), two positive integers; got (32.5, 32)"),
    C("render products", "a resolution beyond the largest supported", "rep.create.render_product(cam, (100000, 10))",
      "ValueError", "resolution 100000x10 exceeds the largest supported edge 4096 (setting "
                    "/graphsdg/render/maxResolution)"),
    C("render products", "a render product of a prim that is not a camera", "rep.create.render_product(cube, (32, 32))",
      "InvalidPrimError", "render product camera '/World/Cube' is a Cube prim, not a UsdGeom.Camera "
                          '(or an OmniLidar / OmniRadar sensor)'),
    C("render products", "stepping after destroying a product an annotator still uses",
      'a = rep.annotators.get("rgb")\na.attach(rp)\nrp.destroy()\nrep.orchestrator.step()',
      "RenderProductDestroyedError", "render product 'Replicator' (/Render/RenderProduct_Replicator) was destroyed "
                                     "but annotator 'rgb' is still attached to it; call detach() before destroy(), "
                                     "or attach to a live render product"),
    # ---- orchestrator --------------------------------------------------------------------------------------------
    C("orchestrator", "zero subframes", "rep.orchestrator.step(rt_subframes=0)",
      "ValueError", "rt_subframes must be -1 (use the default) or a positive integer, got 0"),
    C("orchestrator", "a negative time step", "rep.orchestrator.step(delta_time=-1)",
      "ValueError", "delta_time must be None, 0 or a positive number of seconds, got -1"),
    C("orchestrator", "run() that would never stop", "rep.orchestrator.run()",
      "OrchestratorError", "run() without num_frames needs a graph whose on_frame/on_time triggers set max_execs; "
                           "pass num_frames=N"),
    C("orchestrator", "a fractional frame count", "rep.orchestrator.run(num_frames=2.5)",
      "ValueError", "num_frames must be None or a non-negative integer, got 2.5"),
    C("orchestrator", "capture-on-play given a string", 'rep.orchestrator.set_capture_on_play("yes")',
      "ValueError", "setting /omni/replicator/captureOnPlay must be True or False, got 'yes'"),
    # ---- settings and seeds --------------------------------------------------------------------------------------
    C("settings", "a misspelt setting key (a warning: the value is stored but unused)",
      'rep.settings.set("/omni/replicator/RTSubframe", 4)',
      "UserWarning", "setting '/omni/replicator/RTSubframe' has no effect in graphsdg (stored, but nothing reads it) "
                     "(did you mean '/omni/replicator/RTSubframes'?); honoured keys: "
                     + ", ".join(sorted(KNOWN_KEYS))),
    C("settings", "a setting value of the wrong type", 'rep.settings.set("/omni/replicator/RTSubframes", "four")',
      "ValueError", "setting /omni/replicator/RTSubframes must be an integer >= 0, got 'four'"),
    C("settings", "a write queue of size 0", 'rep.settings.set("/omni/replicator/backend/queueSize", 0)',
      "ValueError", "setting /omni/replicator/backend/queueSize must be an integer >= 1, got 0"),
    C("settings", "an empty setting key", 'rep.settings.set("", 1)',
      "ValueError", "setting key must be a non-empty path string, got ''"),
    C("settings", "a negative global seed", "rep.set_global_seed(-1)",
      "ValueError", "global seed must be a non-negative integer, got -1"),
    C("settings", "a seed given as a string", 'rep.set_global_seed("7")',
      "ValueError", "global seed must be a non-negative integer, got '7'"),
    # ---- command line --------------------------------------------------------------------------------------------
    C("cli", "zero frames for the demo", 'cli("demo", "--frames", "0")',
      "exit 2", "graphsdg demo: error: argument --frames: must be a positive integer, got 0"),
    C("cli", "running a script that does not exist", 'cli("run", os.path.join(tmp, "job.py"))',
      "exit 1", "graphsdg: error: script '<tmp>/job.py' does not exist"),
    C("cli", "validating a folder that does not exist", 'cli("validate", os.path.join(tmp, "nowhere"))',
      "exit 1", "graphsdg: error: dataset directory '<tmp>/nowhere' does not exist"),
]


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", "<br>")


def _code(text: str) -> str:
    return "<br>".join(f"`{_cell(line)}`" if line.strip() else "" for line in text.split("\n"))


def render_markdown(cases: list[Case] = CASES) -> str:
    """``docs/errors.md``: every case as a table row."""
    areas = sorted({c.area for c in cases}, key=[c.area for c in cases].index)
    lines = [
        "# Mistakes and the errors graphsdg answers them with",
        "",
        "Generated from `tests/error_cases.py` by `python tests/error_cases.py`; `tests/test_errors.py` runs every",
        "row and asserts the exception type and the whole message, and checks that this file is current.",
        "",
        "Each message names the bad value and what was expected, and suggests the closest valid name where",
        "there is one. The calls run on a stage holding a labelled unit `cube` (`/World/Cube`), a camera `cam`",
        "(`/World/Camera`) and a 32x32 render product `rp` of it; `<tmp>` stands for a scratch folder holding",
        "`bad.usda` (a USD syntax error), `notes.txt` (not USD) and `broken.png` (a truncated PNG). Command-line",
        "rows give the exit status and the error line (a `hint:` line follows it). graphsdg's own exception",
        "types live in `graphsdg.errors` (`PrimNotFoundError` is a `ValueError`, `InvalidPrimError` a `TypeError`,",
        "`UnknownNameError` a `KeyError` and a `ValueError`, `WriterError` a `RuntimeError`); `CompileError`",
        "(`graphsdg.sim.compile_error`), `GraphBuildError` (`graphsdg.graph`), `SemanticFilterError`",
        "(`graphsdg.annotate.semantic_filter`), `ApproximationError` (`graphsdg.sim.colliders`) and",
        "`OrchestratorError` (`graphsdg.orchestrator`) are `ValueError`s or `RuntimeError`s too, so",
        "`except ValueError` catches the mistakes a script can correct.",
        "",
        f"{len(cases)} mistakes in {len(areas)} areas: " + ", ".join(areas) + ".",
        "",
        "| # | Area | Mistake | Call | Error | Message |",
        "|---|---|---|---|---|---|",
    ]
    for i, c in enumerate(cases, 1):
        lines.append(f"| {i} | {c.area} | {_cell(c.mistake)} | {_code(c.code)} | `{c.error}` | `{_cell(c.message)}` |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    with open(DOC, "w", encoding="utf-8") as f:
        f.write(render_markdown())
    print(f"wrote {DOC} ({len(CASES)} cases)", file=sys.stderr)
