"""The graph-API calls are their node classes made callable, with the signatures Replicator scripts use."""
from __future__ import annotations

import doctest
import inspect

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.functional.per_prim import per_prim, per_prim_array
from graphsdg.graph import calls
from graphsdg.graph.calls import Call, call_name, family_calls
from graphsdg.graph.node import Node, Port
from graphsdg.graph.registry import NodeRegistry

NAMESPACES = {"create": rep.create, "modify": rep.modify, "randomizer": rep.randomizer, "get": rep.get,
              "distribution": rep.distribution, "trigger": rep.trigger, "physics": rep.physics}

# every call's parameters and defaults, as the hand-written faces had them before they were derived
SIGNATURES = {
    "create.camera": "(position=None, rotation=None, look_at=None, look_at_up_axis=None, "
                     "focal_length=24.0, focus_distance=400.0, f_stop=0.0, horizontal_aperture=20.955, "
                     "horizontal_aperture_offset=0.0, vertical_aperture_offset=0.0, clipping_range=(0.01,"
                     " 1000000.0), projection_type='pinhole', count=1, parent=None, name=None, **fisheye)",
    "create.capsule": "(position=None, scale=None, pivot=None, rotation=None, look_at=None, "
                      "look_at_up_axis=None, semantics=None, material=None, visible=True, as_mesh=False, "
                      "count=1, name=None, parent=None)",
    "create.cone": "(position=None, scale=None, pivot=None, rotation=None, look_at=None, "
                   "look_at_up_axis=None, semantics=None, material=None, visible=True, as_mesh=False, "
                   "count=1, name=None, parent=None)",
    "create.cube": "(position=None, scale=None, pivot=None, rotation=None, look_at=None, "
                   "look_at_up_axis=None, semantics=None, material=None, visible=True, as_mesh=False, "
                   "count=1, name=None, parent=None)",
    "create.cylinder": "(position=None, scale=None, pivot=None, rotation=None, look_at=None, "
                       "look_at_up_axis=None, semantics=None, material=None, visible=True, as_mesh=False,"
                       " count=1, name=None, parent=None)",
    "create.disk": "(position=None, scale=None, pivot=None, rotation=None, look_at=None, "
                   "look_at_up_axis=None, semantics=None, material=None, visible=True, as_mesh=False, "
                   "count=1, name=None, parent=None)",
    "create.from_usd": "(usd, position=None, scale=None, rotation=None, look_at=None, "
                       "look_at_up_axis=None, semantics=None, count=1, name=None, parent=None)",
    "create.group": "(items, semantics=None, name=None)",
    "create.light": "(position=None, scale=None, rotation=None, look_at=None, look_at_up_axis=None, "
                    "light_type='Distant', color=(1.0, 1.0, 1.0), intensity=1000.0, exposure=None, "
                    "temperature=6500, texture=None, count=1, name=None, parent=None)",
    "create.material_omnipbr": "(diffuse=None, diffuse_texture=None, roughness=None, "
                               "roughness_texture=None, metallic=None, metallic_texture=None, "
                               "specular=None, emissive_color=None, emissive_texture=None, "
                               "emissive_intensity=0.0, project_uvw=False, semantics=None, count=1, "
                               "name=None)",
    "create.plane": "(position=None, scale=None, pivot=None, rotation=None, look_at=None, "
                    "look_at_up_axis=None, semantics=None, material=None, visible=True, as_mesh=False, "
                    "count=1, name=None, parent=None)",
    "create.sphere": "(position=None, scale=None, pivot=None, rotation=None, look_at=None, "
                     "look_at_up_axis=None, semantics=None, material=None, visible=True, as_mesh=False, "
                     "count=1, name=None, parent=None)",
    "create.torus": "(position=None, scale=None, pivot=None, rotation=None, look_at=None, "
                    "look_at_up_axis=None, semantics=None, material=None, visible=True, as_mesh=False, "
                    "count=1, name=None, parent=None)",
    "create.xform": "(position=None, scale=None, rotation=None, look_at=None, look_at_up_axis=None, "
                    "semantics=None, visible=True, count=1, name=None, parent=None)",
    "modify.attribute": "(name, value, attribute_type=None, input_prims=None)",
    "modify.material": "(value, input_prims=None, name=None)",
    "modify.pose": "(position=None, position_x=None, position_y=None, position_z=None, rotation=None, "
                   "rotation_x=None, rotation_y=None, rotation_z=None, rotation_order='XYZ', scale=None, "
                   "size=None, pivot=None, look_at=None, look_at_up_axis=None, input_prims=None, "
                   "name=None)",
    "modify.semantics": "(semantics=None, input_prims=None, mode='add')",
    "modify.visibility": "(value=None, input_prims=None, name=None)",
    "randomizer.color": "(colors, per_sub_mesh=False, seed=None, input_prims=None)",
    "randomizer.instantiate": "(paths, size, weights=None, mode='scene_instance', with_replacements=True,"
                              " seed=None, name=None, use_cache=True, semantics=None)",
    "randomizer.materials": "(materials, seed=None, max_cached_materials=0, input_prims=None, name=None)",
    "randomizer.rotation": "(min_angle=(-180.0, -180.0, -180.0), max_angle=(180.0, 180.0, 180.0), "
                           "seed=None, input_prims=None)",
    "randomizer.scatter_2d": "(surface_prims, no_coll_prims=None, min_samp=(None, None, None), "
                             "max_samp=(None, None, None), seed=None, offset=0, "
                             "check_for_collisions=False, input_prims=None, name=None)",
    "randomizer.scatter_3d": "(volume_prims=None, no_coll_prims=None, volume_excl_prims=None, "
                             "min_samp=(None, None, None), max_samp=(None, None, None), "
                             "resolution_scaling=1.0, voxel_size=0.0, check_for_collisions=False, "
                             "prevent_vol_overlap=True, viz_sampled_voxels=False, seed=None, "
                             "input_prims=None, name=None)",
    "randomizer.texture": "(textures, texture_scale=None, texture_rotate=None, per_sub_mesh=False, "
                          "project_uvw=False, seed=None, input_prims=None)",
    "get.prim_at_path": "(path, name=None)",
    "get.prims": "(path_pattern=None, path_match=None, path_pattern_exclusion=None, prim_types=None, "
                 "prim_types_exclusion=None, semantics=None, semantics_exclusion=None, cache_result=True,"
                 " ignore_case=True, name=None)",
    "distribution.choice": "(choices, weights=None, num_samples=1, seed=-1, with_replacements=True, "
                           "name=None)",
    "distribution.combine": "(distributions, name=None)",
    "distribution.log_uniform": "(lower, upper, num_samples=1, seed=None, name=None)",
    "distribution.normal": "(mean, std, num_samples=1, seed=None, name=None)",
    "distribution.sequence": "(items, ordered=True, seed=-1, name=None, stride=None)",
    "distribution.uniform": "(lower, upper, num_samples=1, seed=None, name=None)",
    "trigger.on_custom_event": "(event_name)",
    "trigger.on_time_end": "(interval=1, name='on_time_end', rt_subframes=32, enable_capture_on_play=True, "
                           "max_execs=0)",
    "trigger.on_condition": "(condition, max_execs=0, rt_subframes=1)",
    "modify.variant": "(name, value, input_prims=None)",
    "modify.timeline": "(value, modify_type=None)",
    "modify.pose_camera_relative": "(camera, render_product, distance, horizontal_location=0, vertical_location=0, "
                                   "input_prims=None)",
    "modify.pose_orbit": "(barycentre, distance, azimuth, elevation, look_at_barycentre=True, input_prims=None)",
    "physics.rigid_body": "(velocity=(0.0, 0.0, 0.0), angular_velocity=None, contact_offset=None, "
                          "rest_offset=None, overwrite=False, physics_scene=None, input_prims=None)",
    "physics.collider": "(approximation_shape='convexHull', contact_offset=None, rest_offset=None, "
                        "physics_scene=None, input_prims=None)",
    "physics.mass": "(mass=None, density=None, center_of_mass=None, diagonal_inertia=None, principal_axes=None, "
                    "input_prims=None)",
    "physics.physics_material": "(static_friction=None, dynamic_friction=None, restitution=None, input_prims=None)",
    "physics.drive_properties": "(stiffness=0.0, damping=0.0, input_prims=None)",
    "physics.simulate": "(time, step_dt=None, physics_scene=None)",
    "physics.reset": "(physics_scene=None)",
    "trigger.on_frame": "(interval=1, num_frames=0, name='on_frame', rt_subframes=1, max_execs=0)",
    "trigger.on_time": "(interval=1, num=0, name='on_time', rt_subframes=32, enable_capture_on_play=True,"
                       " reset_physics=True, max_execs=0)",
}


def _plain_signature(fn) -> str:
    params = [p.replace(annotation=inspect.Parameter.empty) for p in inspect.signature(fn).parameters.values()]
    return str(inspect.Signature(params))


@pytest.mark.parametrize("call", sorted(SIGNATURES))
def test_each_call_keeps_its_signature(call):
    family, name = call.split(".")
    assert _plain_signature(getattr(NAMESPACES[family], name)) == SIGNATURES[call]


def test_every_node_type_with_a_call_is_in_its_namespace_and_nothing_else_is():
    derived = {f"{cls.family}.{call_name(cls)}" for cls in map(NodeRegistry.get, NodeRegistry.types())
               if isinstance(getattr(cls, "call", None), Call)}
    assert derived == set(SIGNATURES)
    for type_name in derived:
        family, name = type_name.split(".")
        fn, node_cls = getattr(NAMESPACES[family], name), NodeRegistry.get(type_name)
        assert fn.__doc__ == node_cls.__doc__ and fn.__doc__, type_name
        assert fn.__module__ == f"graphsdg.{family}" and name in NAMESPACES[family].__all__


def test_call_defaults_are_the_node_ports_defaults():
    for type_name in SIGNATURES:
        node_cls = NodeRegistry.get(type_name)
        params = inspect.signature(getattr(NAMESPACES[node_cls.family], call_name(node_cls))).parameters
        for port, spec in node_cls.inputs.items():
            param = params[node_cls.call.renamed.get(port, port)]
            if port != "input_prims" and param.default is not inspect.Parameter.empty:
                assert param.default == spec.default and type(param.default) is type(spec.default), (type_name, port)


def test_the_faces_name_no_node_type():
    """The rep.<family> modules reach their node classes through the registry, never by a type-name string."""
    for family, namespace in NAMESPACES.items():
        with open(namespace.__file__) as f:
            text = f.read()
        assert "NodeRegistry" not in text and f'"{family}.' not in text, family


def test_a_bad_call_fails_as_a_python_function_would():
    with pytest.raises(TypeError, match=r"^pose\(\) got an unexpected keyword argument 'positon'$"):
        rep.modify.pose(positon=(1, 2, 3))
    with pytest.raises(TypeError, match=r"^uniform\(\) missing a required argument: 'upper'$"):
        rep.distribution.uniform(0)
    with pytest.raises(TypeError, match=r"^attribute\(\) missing a required argument: 'value'$"):
        rep.modify.attribute("visibility")


def test_positional_renamed_deprecated_and_ignored_parameters():
    rep.stage.new_stage()
    cube = rep.create.cube((1, 2, 3), 2.0, name="Box", **{})
    assert cube.node.user_name == "Box" and cube.node.values["position"] == (1, 2, 3)
    cam = rep.create.camera(position=(0, 0, 5), fisheye_polynomial_a=1.0)   # accepted and unused
    assert "fisheye_polynomial_a" not in cam.node.values
    item = rep.modify.attribute("primvars:size", 2.0, "float", input_prims=cube)
    assert item.node.values["attribute"] == "primvars:size" and item.node.user_name is None
    trigger = rep.trigger.on_frame(num_frames=3)
    assert trigger.node.value_of("max_execs") == 3 and trigger.name == "on_frame"
    with rep.trigger.on_custom_event("recolor") as event:
        pass
    assert event.node.user_name == "recolor"


def test_a_registered_node_class_with_a_call_becomes_a_call():
    class Nudge(Node):
        """Move the prims up by ``height``."""

        type_name = "modify.nudge_for_test"
        family = "modify"
        call = Call()
        inputs = {"input_prims": Port("prims", required=True), "height": Port(float, 0.5)}
        outputs = {"prims": Port("prims")}

    saved = dict(NodeRegistry._types)
    try:
        NodeRegistry.register(Nudge)
        fn = family_calls("modify")["nudge_for_test"]
        assert str(inspect.signature(fn)) == ("(height: 'float' = 0.5, input_prims: 'Any' = None, "
                                              "name: 'str | None' = None) -> 'ReplicatorItem'")
        assert fn.__doc__ == Nudge.__doc__
    finally:
        NodeRegistry._types.clear()
        NodeRegistry._types.update(saved)


def test_a_call_whose_order_misses_a_port_is_refused():
    class Broken(Node):
        type_name = "modify.broken_for_test"
        family = "modify"
        call = Call(params=("height",))
        inputs = {"height": Port(float, 0.5), "depth": Port(float, 1.0)}

    with pytest.raises(TypeError, match="Broken.call lists parameters"):
        calls.graph_call(Broken)


# ---- one value, or one per prim -------------------------------------------------------------------------------
def test_one_value_or_one_per_prim():
    assert per_prim_array((1, 2, 3), 2, "position").tolist() == [[1, 2, 3], [1, 2, 3]]
    assert per_prim_array((1, 0, 0, 0), 2, "rotation").shape == (2, 4)           # a quaternion for all
    assert per_prim_array(np.eye(3)[:2], 2, "position").tolist() == [[1, 0, 0], [0, 1, 0]]
    assert per_prim_array(2.0, 2, "scale", uniform=True).tolist() == [[2, 2, 2]] * 2
    assert per_prim_array([1, 2], 2, "scale", uniform_per_prim=True).tolist() == [[1, 1, 1], [2, 2, 2]]
    assert per_prim_array([[1], [2]], 2, "scale", uniform_per_prim=True).tolist() == [[1, 1, 1], [2, 2, 2]]
    assert per_prim_array((2, 3), 2, "texture_scale", width=2, uniform=True).tolist() == [[2, 3], [2, 3]]
    assert per_prim(None, 3, "pivot") == [None] * 3
    shared = per_prim((1, 2, 3), 3, "position")
    assert shared[0] is shared[2]                                              # one array, not N views
    with pytest.raises(ValueError, match=r"^position_value has 3 rows but count/prims is 2$"):
        per_prim_array(np.zeros((3, 3)), 2, "position_value")
    with pytest.raises(ValueError, match=r"^position must be one 3-vector or an \(N, 3\) array, got shape \(\)$"):
        per_prim_array(1.0, 2, "position")
    with pytest.raises(ValueError, match="texture_scale must be one 2-vector"):
        per_prim_array(np.zeros((2, 3)), 2, "texture_scale", width=2, uniform=True)


def test_a_scalar_distribution_gives_each_prim_its_own_uniform_scale():
    rep.stage.new_stage()
    cubes = rep.create.cube(count=4, scale=rep.distribution.uniform(1.0, 2.0, seed=5))
    scales = [tuple(p.GetAttribute("xformOp:scale").Get()) for p in cubes.get_output_prims()["prims"]]
    assert all(s[0] == s[1] == s[2] for s in scales) and len(set(scales)) == 4


@pytest.mark.parametrize("name", ["graphsdg.graph.calls", "graphsdg.functional.per_prim"])
def test_docstring_examples(name):
    import importlib
    rep.stage.new_stage()
    assert doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS).failed == 0


def test_a_vector_is_one_value_for_as_many_prims_as_it_has_numbers():
    """Replicator's rule: position=(1, 2, 3) or scale=(1, 2, 3) on three prims gives each prim that vector, while
    a scalar distribution still draws one number per prim (three prims: three uniform scales)."""
    from pxr import UsdGeom

    from graphsdg.stage.context import get_stage

    def ops(prim):
        return {op.GetOpName(): tuple(op.Get()) for op in UsdGeom.Xformable(prim).GetOrderedXformOps()}

    assert per_prim_array((1, 2, 3), 3, "scale", uniform=True, uniform_per_prim=True).tolist() == [[1, 2, 3]] * 3
    rep.create.cube(count=3, position=(1, 2, 3), scale=(1, 2, 3))
    rep.orchestrator.step()
    cubes = [p for p in get_stage().Traverse() if p.GetTypeName() == "Cube"]
    assert len(cubes) == 3
    for cube in cubes:
        assert ops(cube)["xformOp:translate"] == (1.0, 2.0, 3.0) and ops(cube)["xformOp:scale"] == (1.0, 2.0, 3.0)
    with rep.trigger.on_frame():
        rep.modify.pose(input_prims=cubes, scale=rep.distribution.uniform(0.5, 2.0))
    rep.orchestrator.step()
    scales = [ops(c)["xformOp:scale"] for c in cubes]
    assert all(s[0] == s[1] == s[2] for s in scales) and len(set(scales)) == 3
    rep.functional.modify.pose(cubes, scale_value=(1, 2, 3))
    assert all(ops(c)["xformOp:scale"] == (1.0, 2.0, 3.0) for c in cubes)
