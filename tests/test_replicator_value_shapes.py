"""Replicator's value shapes, call by call, against prim states worked out by hand.

Every per-prim argument takes one value for all prims, one value per prim, or a distribution of either
(``graphsdg/graph/value_shapes.py``); a registered function that returns nothing still drives its prims on
every trigger execution. Each test builds a small graph, steps it, and reads the prims back with pxr.
"""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Sdf, UsdGeom, UsdPhysics, UsdShade

import graphsdg as rep
from graphsdg.stage import materials as matlib


def _cubes(n: int, name: str = "Box"):
    """``n`` cubes in a row, as one item (a group of separately created cubes, as scripts group them)."""
    items = [rep.create.cube(position=(2.0 * i, 0.0, 0.0), name=f"{name}{i}") for i in range(n)]
    group = rep.create.group(items)
    return group, group.get_output_prims()["prims"]


def _visible(prims):
    return [UsdGeom.Imageable(p).ComputeVisibility() != UsdGeom.Tokens.invisible for p in prims]


def _translation(prim):
    return tuple(float(v) for v in prim.GetAttribute("xformOp:translate").Get())


def _steps(n):
    for _ in range(n):
        rep.orchestrator.step()


# ---- visibility: the case and every other shape ------------------------------------------------------

def test_visibility_sequence_of_per_prim_tuples_sets_each_prim_from_its_item():
    group, prims = _cubes(3)
    items = [(True, False, True), (False, True, False), (True, True, False)]
    with rep.trigger.on_frame(max_execs=3):
        with group:
            rep.modify.visibility(rep.distribution.sequence(items))
    seen = []
    for _ in range(3):
        rep.orchestrator.step()
        seen.append(tuple(_visible(prims)))
    assert seen == items


@pytest.mark.parametrize("value,expected", [
    (False, [False, False, False]),                              # one value for every prim
    ([False, True, False], [False, True, False]),                # one per prim
    ([False], [False, False, False]),                            # a one-item list is one value
])
def test_visibility_plain_values(value, expected):
    group, prims = _cubes(3)
    with group:
        rep.modify.visibility(value)
    assert _visible(prims) == expected


def test_visibility_sequence_of_scalars_gives_every_prim_the_item():
    group, prims = _cubes(3)
    with rep.trigger.on_frame(max_execs=3):
        with group:
            rep.modify.visibility(rep.distribution.sequence([False, True, False]))
    seen = []
    for _ in range(3):
        rep.orchestrator.step()
        seen.append(_visible(prims))
    assert seen == [[False] * 3, [True] * 3, [False] * 3]


def test_visibility_choice_of_per_prim_tuples_draws_one_tuple_a_frame():
    group, prims = _cubes(3)
    options = [(True, False, False), (False, False, True)]
    with rep.trigger.on_frame(max_execs=12):
        with group:
            rep.modify.visibility(rep.distribution.choice(options))
    seen = set()
    for _ in range(12):
        rep.orchestrator.step()
        state = tuple(_visible(prims))
        assert state in options          # whole tuples, never mixed per prim
        seen.add(state)
    assert seen == set(options)          # 12 draws of two options: both appear (p = 1 - 2 ** -11)


def test_visibility_choice_of_scalars_draws_per_prim():
    group, prims = _cubes(8)
    with rep.trigger.on_frame(max_execs=1):
        with group:
            rep.modify.visibility(rep.distribution.choice([True, False]))
    rep.orchestrator.step()
    assert 0 < sum(_visible(prims)) < 8  # 8 independent draws: not all alike (p = 2 ** -7)


def test_visibility_wrong_count_names_the_call_value_and_shapes():
    group, _ = _cubes(3)
    with pytest.raises(ValueError, match=r"modify.visibility value: got \[True, False\] \(shape \(2,\)\) for 3 "
                                         r"prims; expected one value \(a scalar\) for every prim, or a list "
                                         r"of 3"):
        with group:
            rep.modify.visibility([True, False])


# ---- pose -------------------------------------------------------------------------------------------------------

def test_pose_position_shapes():
    group, prims = _cubes(3)
    with group:
        rep.modify.pose(position=(1.0, 2.0, 3.0))          # one (x, y, z): every prim, even three of them
    assert [_translation(p) for p in prims] == [(1.0, 2.0, 3.0)] * 3
    rows = [(0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)]
    with group:
        rep.modify.pose(position=rows)                      # one per prim
    assert [_translation(p) for p in prims] == rows


def test_pose_position_sequence_of_vectors_and_of_per_prim_lists():
    group, prims = _cubes(2)
    shared = [(0.0, 0.0, 1.0), (0.0, 0.0, 2.0)]
    per_prim = [[(1.0, 0.0, 0.0), (2.0, 0.0, 0.0)], [(3.0, 0.0, 0.0), (4.0, 0.0, 0.0)]]
    with rep.trigger.on_frame(max_execs=2):
        with group:
            rep.modify.pose(position=rep.distribution.sequence(shared),
                            rotation=rep.distribution.sequence([[(0, 0, 10), (0, 0, 20)], [(0, 0, 30), (0, 0, 40)]]))
    rep.orchestrator.step()
    assert [_translation(p) for p in prims] == [(0.0, 0.0, 1.0)] * 2
    rep.orchestrator.step()
    assert [_translation(p) for p in prims] == [(0.0, 0.0, 2.0)] * 2
    assert [tuple(p.GetAttribute("xformOp:rotateXYZ").Get()) for p in prims] == [(0, 0, 30), (0, 0, 40)]

    rep.graph.clear()
    group, prims = _cubes(2, name="Other")
    with rep.trigger.on_frame(max_execs=2):
        with group:
            rep.modify.pose(position=rep.distribution.sequence(per_prim))
    for expected in per_prim:
        rep.orchestrator.step()
        assert [_translation(p) for p in prims] == expected


def test_pose_uniform_draws_one_position_per_prim_inside_its_bounds():
    group, prims = _cubes(4)
    with rep.trigger.on_frame(max_execs=1):
        with group:
            rep.modify.pose(position=rep.distribution.uniform((-1.0, -1.0, 5.0), (1.0, 1.0, 6.0)))
    rep.orchestrator.step()
    points = np.array([_translation(p) for p in prims])
    assert np.all(points >= (-1, -1, 5)) and np.all(points <= (1, 1, 6))
    assert len({tuple(r) for r in points}) == 4            # independent draws


def test_pose_scale_shapes():
    group, prims = _cubes(4)
    with group:
        rep.modify.pose(scale=2.0)                          # a number: uniform scale
    assert [tuple(p.GetAttribute("xformOp:scale").Get()) for p in prims] == [(2.0, 2.0, 2.0)] * 4
    with group:
        rep.modify.pose(scale=[0.5, 1.0, 1.5, 2.0])         # four numbers on four prims: one uniform scale each
    assert [tuple(p.GetAttribute("xformOp:scale").Get()) for p in prims] == \
        [(0.5,) * 3, (1.0,) * 3, (1.5,) * 3, (2.0,) * 3]
    group3, prims3 = _cubes(3, name="Three")
    with group3:
        rep.modify.pose(scale=(1.0, 2.0, 3.0))              # three numbers on three prims: one (x, y, z) scale
    assert [tuple(p.GetAttribute("xformOp:scale").Get()) for p in prims3] == [(1.0, 2.0, 3.0)] * 3


def test_pose_per_axis_components_take_per_prim_values():
    group, prims = _cubes(3)
    with group:
        rep.modify.pose(position_z=[1.0, 2.0, 3.0])
    assert [_translation(p) for p in prims] == [(0.0, 0.0, 1.0), (2.0, 0.0, 2.0), (4.0, 0.0, 3.0)]


def test_create_takes_per_prim_positions_and_a_sequence_of_per_prim_intensities():
    with rep.trigger.on_frame(max_execs=2):
        lights = rep.create.light(light_type="Sphere", count=2, position=[(0, 0, 1), (0, 0, 2)],
                                  intensity=rep.distribution.sequence([(10.0, 20.0), (30.0, 40.0)]))
    prims = lights.get_output_prims()["prims"]
    assert [_translation(p.GetParent()) if not p.GetAttribute("xformOp:translate") else _translation(p)
            for p in prims] == [(0.0, 0.0, 1.0), (0.0, 0.0, 2.0)]
    rep.orchestrator.step()
    assert [p.GetAttribute("inputs:intensity").Get() for p in prims] == [10.0, 20.0]
    rep.orchestrator.step()
    assert [p.GetAttribute("inputs:intensity").Get() for p in prims] == [30.0, 40.0]


# ---- attribute, material, variant ------------------------------------------------------------------------------

def test_attribute_shapes_follow_the_attribute_type():
    group, prims = _cubes(3)
    with group:
        rep.modify.attribute("size", [1.0, 2.0, 3.0])                        # a float: one per prim
        rep.modify.attribute("primvars:tint", (0.1, 0.2, 0.3), attribute_type="color3f")   # one colour for all
    assert [p.GetAttribute("size").Get() for p in prims] == [1.0, 2.0, 3.0]
    assert all(np.allclose(p.GetAttribute("primvars:tint").Get(), (0.1, 0.2, 0.3)) for p in prims)
    with rep.trigger.on_frame(max_execs=2):
        with group:
            rep.modify.attribute("size", rep.distribution.sequence([(4.0, 5.0, 6.0), (7.0, 8.0, 9.0)]))
    rep.orchestrator.step()
    assert [p.GetAttribute("size").Get() for p in prims] == [4.0, 5.0, 6.0]
    rep.orchestrator.step()
    assert [p.GetAttribute("size").Get() for p in prims] == [7.0, 8.0, 9.0]


def _material(name: str):
    return rep.functional.create.material(name=name, parent="/World", diffuse_color_constant=(1.0, 0.0, 0.0))


def _bound(prim) -> str:
    return str(UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0].GetPath())


def test_material_one_for_all_a_sequence_per_prim_and_a_list_drawn_per_prim():
    rep.functional.create.xform(name="World")
    red, blue = _material("Red"), _material("Blue")
    group, prims = _cubes(2)
    with group:
        rep.modify.material(red)
    assert [_bound(p) for p in prims] == ["/World/Red", "/World/Red"]
    with rep.trigger.on_frame(max_execs=2):
        with group:
            rep.modify.material(rep.distribution.sequence([["/World/Blue", "/World/Red"],
                                                           ["/World/Red", "/World/Red"]]))
    rep.orchestrator.step()
    assert [_bound(p) for p in prims] == ["/World/Blue", "/World/Red"]
    rep.orchestrator.step()
    assert [_bound(p) for p in prims] == ["/World/Red", "/World/Red"]
    rep.graph.clear()
    group, prims = _cubes(12, name="Many")
    with group:
        rep.modify.material([red, blue])
    assert {_bound(p) for p in prims} == {"/World/Red", "/World/Blue"}   # 12 draws of 2 (p = 2 ** -11)


def _variant_cube(stage, path: str):
    prim = stage.DefinePrim(path, "Cube")
    variants = prim.GetVariantSets().AddVariantSet("colour")
    for v in ("red", "green", "blue"):
        variants.AddVariant(v)
    return prim


def test_variant_one_value_and_a_sequence_of_per_prim_values():
    stage = rep.stage.get_stage()
    prims = [_variant_cube(stage, f"/V{i}") for i in range(2)]
    item = rep.get.prim_at_path(["/V0", "/V1"])
    with item:
        rep.modify.variant("colour", "green")
    assert [p.GetVariantSets().GetVariantSelection("colour") for p in prims] == ["green", "green"]
    with rep.trigger.on_frame(max_execs=1):
        with item:
            rep.modify.variant("colour", rep.distribution.sequence([("red", "blue")]))
    rep.orchestrator.step()
    assert [p.GetVariantSets().GetVariantSelection("colour") for p in prims] == ["red", "blue"]
    with pytest.raises(ValueError, match="has no variant 'purple'"):
        with item:
            rep.modify.variant("colour", "purple")


# ---- randomizers and physics -----------------------------------------------------------------------------------

def _diffuse(prim):
    material = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0]
    return tuple(round(float(c), 6) for c in matlib.surface_shader(material).GetInput("diffuseColor").Get())


def test_color_one_colour_a_palette_and_a_sequence_of_per_prim_colours():
    group, prims = _cubes(3)
    with group:
        rep.randomizer.color(colors=(0.0, 0.5, 1.0))
    assert [_diffuse(p) for p in prims] == [(0.0, 0.5, 1.0)] * 3
    palette = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    with group:
        rep.randomizer.color(colors=palette)                 # a list of colours: one drawn per prim
    assert all(_diffuse(p) in palette for p in prims)
    with rep.trigger.on_frame(max_execs=1):
        with group:
            rep.randomizer.color(colors=rep.distribution.sequence([[(1, 0, 0), (0, 1, 0), (0, 0, 1)]]))
    rep.orchestrator.step()
    assert [_diffuse(p) for p in prims] == [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]


def test_physics_mass_and_velocity_take_per_prim_values():
    group, prims = _cubes(2)
    with group:
        rep.physics.collider()
        rep.physics.rigid_body(velocity=[(1.0, 0.0, 0.0), (0.0, 2.0, 0.0)])
        rep.physics.mass(mass=[3.0, 4.0])
        rep.physics.physics_material(static_friction=0.25)
    assert [tuple(UsdPhysics.RigidBodyAPI(p).GetVelocityAttr().Get()) for p in prims] == [(1, 0, 0), (0, 2, 0)]
    assert [UsdPhysics.MassAPI(p).GetMassAttr().Get() for p in prims] == [3.0, 4.0]
    materials = [UsdShade.MaterialBindingAPI(p).ComputeBoundMaterial("physics")[0] for p in prims]
    assert [UsdPhysics.MaterialAPI(m.GetPrim()).GetStaticFrictionAttr().Get() for m in materials] == [0.25, 0.25]


# ---- registered randomizers ------------------------------------------------------------------------------------

def test_a_registered_randomizer_without_return_drives_its_prims_every_frame():
    rep.functional.create.cube(name="Target", semantics={"class": "target"})
    heights = [0.5, 1.5, 2.5, 3.5]

    def lift_targets():
        targets = rep.get.prims(semantics=[("class", "target")])
        with targets:
            rep.modify.pose(position=rep.distribution.sequence([(0.0, 0.0, z) for z in heights]))
        # no return, as scripts written for Replicator often have

    rep.randomizer.register(lift_targets)
    with rep.trigger.on_frame(max_execs=4):
        assert rep.randomizer.lift_targets() is None
    prim = rep.stage.get_stage().GetPrimAtPath("/Target")
    seen = []
    for _ in range(4):
        rep.orchestrator.step()
        seen.append(_translation(prim)[2])
    assert seen == heights


def test_a_registered_randomizer_may_return_items_or_a_node():
    def two_lights():
        a = rep.create.light(light_type="Sphere", intensity=rep.distribution.sequence([1.0, 2.0]))
        b = rep.create.light(light_type="Sphere", intensity=rep.distribution.sequence([3.0, 4.0]))
        return [a, b.node]

    rep.randomizer.register(two_lights)
    with rep.trigger.on_frame(max_execs=2):
        items = rep.randomizer.two_lights()
    assert [type(i).__name__ for i in items] == ["ReplicatorItem", "ReplicatorItem"]
    _steps(2)
    assert [i.get_output_prims()["prims"][0].GetAttribute("inputs:intensity").Get() for i in items] == [2.0, 4.0]


def test_sequence_stride_chunks_consecutive_items_per_prim():
    group, prims = _cubes(2)
    with rep.trigger.on_frame(max_execs=2):
        with group:
            rep.modify.visibility(rep.distribution.sequence([True, False, False, True], stride=2))
    rep.orchestrator.step()
    assert _visible(prims) == [True, False]
    rep.orchestrator.step()
    assert _visible(prims) == [False, True]


def test_an_array_attribute_value_is_never_split():
    group, prims = _cubes(2)
    with group:
        rep.modify.attribute("primvars:weights", [0.5, 0.25], attribute_type="float[]")
    assert [list(p.GetAttribute("primvars:weights").Get()) for p in prims] == [[0.5, 0.25], [0.5, 0.25]]
    assert prims[0].GetAttribute("primvars:weights").GetTypeName() == Sdf.ValueTypeNames.FloatArray


def _texture_shader(prim):
    material = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0]
    return material.GetPrim().GetStage().GetPrimAtPath(material.GetPath().AppendChild("DiffuseTexture"))


def test_texture_scale_and_rotation_one_for_all_and_per_prim():
    texture = rep.example.TEXTURES[0]
    group, prims = _cubes(2)
    with group:
        rep.randomizer.texture(textures=[texture], texture_scale=[(0.5, 2.0)], texture_rotate=[30, 60])
    shaders = [_texture_shader(p) for p in prims]
    assert [tuple(s.GetAttribute("inputs:scale").Get())[:2] for s in shaders] == [(0.5, 2.0), (0.5, 2.0)]
    assert [s.GetAttribute("graphsdg:textureRotate").Get() for s in shaders] == [30.0, 60.0]
    assert all(s.GetAttribute("inputs:file").Get().path == texture for s in shaders)
    with rep.trigger.on_frame(max_execs=1):
        with group:
            rep.randomizer.texture(textures=[texture], texture_rotate=rep.distribution.sequence([(10, 20)]))
    rep.orchestrator.step()
    assert [s.GetAttribute("graphsdg:textureRotate").Get() for s in shaders] == [10.0, 20.0]


def test_material_and_camera_arguments_re_sampled_per_prim():
    with rep.trigger.on_frame(max_execs=1):
        mats = rep.create.material_omnipbr(diffuse=rep.distribution.sequence([[(1, 0, 0), (0, 0, 1)]]), count=2)
        cams = rep.create.camera(focal_length=rep.distribution.sequence([(18.0, 35.0)]), count=2)
    rep.orchestrator.step()
    colours = [tuple(matlib.surface_shader(UsdShade.Material(m)).GetInput("diffuseColor").Get())
               for m in mats.get_output_prims()["prims"]]
    assert colours == [(1.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    assert [UsdGeom.Camera(c).GetFocalLengthAttr().Get() for c in cams.get_output_prims()["prims"]] == [18.0, 35.0]
