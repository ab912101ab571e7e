"""Deformable bodies (Isaac's DeformablePrim and deformable materials) simulated as MuJoCo flexes."""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg.compat import isaac
from graphsdg.engine.runtime import runtime


@pytest.fixture
def compat():
    """The Isaac module names, for one test."""
    isaac.install()
    yield
    isaac.uninstall()


def _box_mesh(stage, path, half=0.05):
    """A closed box Mesh of half-size ``half`` (quads), centred on its prim."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    v = [(x, y, z) for z in (-half, half) for y in (-half, half) for x in (-half, half)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    mesh.CreatePointsAttr([Gf.Vec3f(*p) for p in v])
    mesh.CreateFaceVertexCountsAttr([4] * 6)
    mesh.CreateFaceVertexIndicesAttr([i for f in faces for i in f])
    return mesh


def _cloth_mesh(stage, path, size=0.6, n=13, z=0.3):
    """A flat square triangle grid of ``n`` x ``n`` points at height ``z``."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    xs = np.linspace(-size / 2, size / 2, n)
    pts = [Gf.Vec3f(float(x), float(y), z) for y in xs for x in xs]
    tris = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i, (j + 1) * n + i + 1
            tris += [a, b, d, a, d, c]
    mesh.CreatePointsAttr(pts)
    mesh.CreateFaceVertexCountsAttr([3] * (len(tris) // 3))
    mesh.CreateFaceVertexIndicesAttr(tris)
    return mesh


def _ground():
    ground = rep.functional.create.cube(position=(0, 0, -0.5), scale=(4, 4, 1), name="Ground")
    rep.functional.physics.apply_collider(ground)
    return ground


def _soft_cube(youngs_modulus=5e5, height=0.3):
    from isaacsim.core.experimental.materials import VolumeDeformableMaterial
    from isaacsim.core.experimental.prims import DeformablePrim
    stage = rep.stage.get_stage()
    root = UsdGeom.Xform.Define(stage, "/World/Soft")
    UsdGeom.XformCommonAPI(root).SetTranslate((0.0, 0.0, height))
    _box_mesh(stage, "/World/Soft/mesh")
    rep.functional.modify.semantics(root.GetPrim(), {"class": "soft_cube"}, mode="add")
    material = VolumeDeformableMaterial("/World/SoftMaterial", youngs_moduli=[youngs_modulus],
                                        poissons_ratios=[0.45], densities=[500.0])
    deformable = DeformablePrim("/World/Soft", deformable_type="volume")
    deformable.apply_physics_materials(material)
    return deformable


def test_volume_cube_falls_and_rests_on_the_ground_with_its_mesh(compat):
    rep.functional.create.xform(name="World")
    _ground()
    cube = _soft_cube()
    assert cube.deformable_type == "volume" and cube.num_nodes_per_element == 4
    sim, _, rest = cube.get_nodal_positions()
    assert sim.shape == rest.shape and sim.shape[0] == 1
    np.testing.assert_allclose(rest[0, :, 2].min(), 0.25, atol=1e-6)       # the box's bottom face at rest
    runtime().sim.advance(1.5)
    nodes = cube.get_nodal_positions()[0].numpy()[0]
    # it fell 0.25 m and rests on the plane: every node above it, the bottom within the contact radius
    assert nodes[:, 2].min() > -2e-3 and nodes[:, 2].min() < 0.01
    height = nodes[:, 2].max() - nodes[:, 2].min()
    assert 0.08 < height <= 0.102                                   # 0.1 m tall, slightly squashed at most
    assert np.abs(cube.get_nodal_velocities().numpy()).max() < 0.05   # at rest
    # the render mesh's USD points followed the nodes (world = local + the root's 0.3 m)
    points = np.asarray(UsdGeom.Mesh(rep.stage.get_stage().GetPrimAtPath("/World/Soft/mesh")).GetPointsAttr().Get())
    np.testing.assert_allclose(points[:, 2].min() + 0.3, nodes[:, 2].min(), atol=1e-4)
    np.testing.assert_allclose(points[:, 2].max() + 0.3, nodes[:, 2].max(), atol=1e-4)


def test_softer_material_squashes_more():
    heights = []
    for young in (2e3, 2e6):
        rep.stage.new_stage()
        isaac.install()
        try:
            rep.functional.create.xform(name="World")
            _ground()
            cube = _soft_cube(youngs_modulus=young, height=0.06)
            runtime().sim.advance(1.0)
            nodes = cube.get_nodal_positions()[0].numpy()[0]
            heights.append(nodes[:, 2].max() - nodes[:, 2].min())
        finally:
            isaac.uninstall()
    # under its own weight (500 kg/m³ x 0.1 m x g ~ 500 Pa), strain ~ 500 / E
    assert heights[0] < heights[1] - 1e-3 and abs(heights[1] - 0.1) < 2e-3, heights


def test_cloth_drapes_over_a_box(compat):
    from isaacsim.core.experimental.materials import SurfaceDeformableMaterial
    from isaacsim.core.experimental.prims import DeformablePrim
    stage = rep.stage.get_stage()
    rep.functional.create.xform(name="World")
    _ground()
    table = rep.functional.create.cube(position=(0, 0, 0.1), scale=(0.2, 0.2, 0.2), name="Table")
    rep.functional.physics.apply_collider(table)
    _cloth_mesh(stage, "/World/Cloth", z=0.3)
    cloth = DeformablePrim("/World/Cloth")
    assert cloth.deformable_type == "surface" and cloth.num_nodes_per_element == 3
    cloth.apply_physics_materials(SurfaceDeformableMaterial("/World/ClothMaterial", youngs_moduli=[1e5],
                                                            poissons_ratios=[0.3], dynamic_frictions=[0.8],
                                                            surface_thicknesses=[0.002]))
    runtime().sim.advance(1.5)
    nodes = cloth.get_nodal_positions()[0].numpy()[0]
    n = 13
    centre, corner = nodes[(n // 2) * n + n // 2], nodes[0]
    # the centre rests on the box top (z = 0.2), the overhanging border sags well below it
    assert 0.195 < centre[2] < 0.215, centre
    assert corner[2] < 0.2 - 0.08, corner
    assert nodes[:, 2].min() > -2e-3


def test_deformable_is_labelled_in_segmentation_and_deterministic(compat):
    def run():
        rep.stage.new_stage()
        rep.functional.create.xform(name="World")
        rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
        _ground()
        _soft_cube(height=0.2)
        cam = rep.functional.create.camera(position=(0, 0, 1.2), look_at=(0, 0, 0), parent="/World", name="Cam")
        rp = rep.create.render_product(cam, (64, 64))
        seg = rep.AnnotatorRegistry.get_annotator("semantic_segmentation")
        seg.attach(rp)
        runtime().sim.advance(0.5)
        rep.orchestrator.step()
        data = seg.get_data()
        nodes = runtime().sim.data.qpos.copy()
        seg.detach()
        return data, nodes

    (first, q1), (second, q2) = run(), run()
    ids = first["data"]
    labels = {int(k): v for k, v in first["info"]["idToLabels"].items()}
    soft = [k for k, v in labels.items() if v.get("class") == "soft_cube"]
    assert len(soft) == 1
    mask = ids == soft[0]
    # seen from above, the fallen 0.1 m cube covers the image centre
    assert mask[32, 32] and 20 < mask.sum() < 64 * 64 / 2
    assert q1.tobytes() == q2.tobytes() and np.array_equal(ids, second["data"])


def test_bad_inputs_name_themselves(compat):
    from isaacsim.core.experimental.materials import VolumeDeformableMaterial
    from isaacsim.core.experimental.prims import DeformablePrim
    stage = rep.stage.get_stage()
    UsdGeom.Xform.Define(stage, "/World")
    with pytest.raises(ValueError, match="poissons_ratios value 0.7"):
        VolumeDeformableMaterial("/World/M", poissons_ratios=[0.7])
    UsdGeom.Xform.Define(stage, "/World/Empty")
    with pytest.raises(ValueError, match="deformable_type is not set"):
        DeformablePrim("/World/Empty")
    with pytest.raises(ValueError, match="deformable_type 'solid'"):
        DeformablePrim("/World/Empty", deformable_type="solid")
