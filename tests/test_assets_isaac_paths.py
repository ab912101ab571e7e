"""Stand-ins at the /Isaac/... paths Isaac's Replicator examples and tests load: layout, size, physics, materials.

Each test checks what a script relies on: prim names and paths it looks up, the
asset's size and origin, the physics it simulates (the Franka's kinematic chain
against Franka's DH parameters, computed here independently), and the MDL
materials it randomizes.
"""
from __future__ import annotations

import math
import os

import mujoco
import numpy as np
import pytest
from pxr import Usd, UsdGeom, UsdPhysics, UsdShade

import graphsdg as rep
from graphsdg.assets import builtin_pack_root, catalog, get_assets_root_path
from graphsdg.physics.articulations import ArticulationView
from graphsdg.engine.runtime import runtime
from graphsdg.stage import materials as matlib
from graphsdg.stage.mdl_modules import MdlModuleError, parse_module, read_module

ROOT = builtin_pack_root()
ISAAC_KEYS = sorted(catalog.ISAAC_ASSETS)


def _open(rel: str) -> Usd.Stage:
    return Usd.Stage.Open(os.path.join(ROOT, rel.lstrip("/")))


def _bounds(prim: Usd.Prim) -> tuple[np.ndarray, np.ndarray]:
    rng = UsdGeom.BBoxCache(Usd.TimeCode.Default(), ["default", "render"]).ComputeWorldBound(prim) \
        .ComputeAlignedRange()
    return np.array(rng.GetMin()), np.array(rng.GetMax())


def _run(seconds: float) -> None:
    tl = rep.timeline.get_timeline_interface()
    tl.play()
    for _ in range(int(round(seconds * 60))):
        rep.orchestrator.update()
    tl.pause()


@pytest.mark.parametrize("key", ISAAC_KEYS)
def test_stand_in_opens_z_up_in_metres_with_its_catalogued_size(key):
    asset = catalog.ISAAC_ASSETS[key]
    stage = _open(asset.path)
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    lo, hi = _bounds(stage.GetDefaultPrim())
    np.testing.assert_allclose(hi - lo, asset.size, atol=1e-3, err_msg=key)


def test_every_path_the_examples_load_resolves_in_the_pack():
    rels = [
        "/Isaac/Environments/Simple_Warehouse/Props/S_TrafficCone.usd",
        "/Isaac/Environments/Simple_Warehouse/Props/S_WetFloorSign.usd",
        "/Isaac/Environments/Simple_Warehouse/Props/SM_BarelPlastic_B_03.usd",
        "/Isaac/Environments/Simple_Warehouse/Props/SM_PaletteA_02.usd",
        "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxA_01.usd",
        "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxB_01.usd",
        "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxA_01_414.usd",
        "/Isaac/Environments/Simple_Warehouse/Props/SM_CardBoxD_04_1847.usd",
        "/Isaac/Environments/Simple_Warehouse/Materials/MI_PaperNotes_01.mdl",
        "/Isaac/Environments/Simple_Warehouse/Materials/MI_CardBoxB_05.mdl",
        "/Isaac/Props/Forklift/forklift.usd",
        "/Isaac/Props/Pallet/pallet.usd",
        "/Isaac/Props/KLT_Bin/small_KLT_visual.usd",
        "/Isaac/Props/Dolly/dolly.usd",
        "/Isaac/Robots/FrankaRobotics/FrankaPanda/franka.usd",
    ]
    missing = [r for r in rels if not os.path.isfile(get_assets_root_path() + r)]
    assert missing == []


# ---- props -------------------------------------------------------------------------------
def test_traffic_cone_stands_on_its_base_centre_and_is_orange_with_white_bands():
    stage = _open("/Isaac/Environments/Simple_Warehouse/Props/S_TrafficCone.usd")
    cone = stage.GetDefaultPrim()
    lo, hi = _bounds(cone)
    np.testing.assert_allclose(lo, (-0.18, -0.18, 0.0), atol=1e-4)
    np.testing.assert_allclose(hi, (0.18, 0.18, 0.70), atol=1e-4)
    # the bands sit within the cone's height and the cone narrows upwards
    band_lo, band_hi = _bounds(cone.GetChild("Bands"))
    assert 0.25 < band_lo[2] and band_hi[2] < 0.6
    assert band_hi[0] - band_lo[0] < 0.3
    colors = {}
    for name in ("Cone", "Bands"):
        mat = matlib.bound_material(cone.GetChild(name))
        img = __import__("cv2").imread(matlib.describe(mat).texture)[..., ::-1] / 255.0
        colors[name] = img.reshape(-1, 3).mean(0)
    assert colors["Cone"][0] > 0.8 and colors["Cone"][2] < 0.15          # orange
    assert colors["Bands"].min() > 0.8                                    # white


def test_forklift_forks_point_along_minus_y_from_an_origin_under_the_driver():
    stage = _open("/Isaac/Props/Forklift/forklift.usd")
    fork = stage.GetDefaultPrim()
    forks_lo, forks_hi = _bounds(fork.GetChild("Forks"))
    assert forks_lo[1] == pytest.approx(-1.95, abs=1e-3)                  # tips 1.95 m ahead along -Y
    assert forks_lo[2] == pytest.approx(0.05, abs=1e-3)
    lo, hi = _bounds(fork)
    assert lo[2] == pytest.approx(0.0, abs=1e-6) and hi[2] == pytest.approx(2.15, abs=1e-3)
    assert hi[1] == pytest.approx(1.25, abs=1e-3)                         # counterweight behind
    assert abs(lo[0] + hi[0]) < 1e-6                                      # centred across
    # every part is a mesh child of the default prim, as scripts reference and label the whole forklift
    meshes = [c.GetName() for c in fork.GetChildren() if c.IsA(UsdGeom.Mesh)]
    assert {"Body", "Forks", "Mast", "Wheels", "OverheadGuard"} <= set(meshes)


def test_klt_bin_is_centred_on_its_bounds_and_open_at_the_top():
    stage = _open("/Isaac/Props/KLT_Bin/small_KLT_visual.usd")
    lo, hi = _bounds(stage.GetDefaultPrim())
    np.testing.assert_allclose((lo + hi) / 2, 0.0, atol=1e-6)
    np.testing.assert_allclose(hi - lo, (0.297, 0.198, 0.147), atol=1e-6)
    floor_lo, floor_hi = _bounds(stage.GetDefaultPrim().GetChild("Floor"))
    assert floor_hi[2] < lo[2] + 0.01                                     # nothing but the floor low down
    assert not any(p.HasAPI(UsdPhysics.RigidBodyAPI) or p.HasAPI(UsdPhysics.CollisionAPI)
                   for p in Usd.PrimRange(stage.GetDefaultPrim()))        # "visual": no physics


def test_dolly_made_a_rigid_body_as_the_amr_example_does_stands_on_the_floor():
    root = get_assets_root_path()
    rep.functional.create.reference(usd_path=root + "/Isaac/Environments/Grid/default_environment.usd", name="Env")
    dolly = rep.functional.create.reference(usd_path=root + "/Isaac/Props/Dolly/dolly.usd", name="Dolly",
                                            position=(0.0, 0.0, 0.05))
    gprims = [c for c in dolly.GetChildren() if c.IsA(UsdGeom.Gprim)]
    assert len(gprims) == 1 and gprims[0].HasAPI(UsdPhysics.CollisionAPI)
    for g in gprims:                                                      # amr_navigation.py's loop
        rep.functional.physics.apply_rigid_body(g)
    _run(1.5)
    lo, hi = _bounds(dolly)
    assert lo[2] == pytest.approx(0.0, abs=0.01)                          # fell 5 cm onto the floor
    assert hi[2] == pytest.approx(0.5, abs=0.01)                          # deck top 0.5 m up


# ---- Franka --------------------------------------------------------------------------------
FRANKA = "/Isaac/Robots/FrankaRobotics/FrankaPanda/franka.usd"
LINKS = ["panda_link0", "panda_link1", "panda_link2", "panda_link3", "panda_link4", "panda_link5", "panda_link6",
         "panda_link7", "panda_hand", "panda_leftfinger", "panda_rightfinger"]
DOFS = ["panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4", "panda_joint5", "panda_joint6",
        "panda_joint7", "panda_finger_joint1", "panda_finger_joint2"]


def panda_flange(q) -> np.ndarray:
    """The Panda's flange (4x4) from its modified DH parameters (Craig): a, d, alpha per joint."""
    dh = [(0.0, 0.333, 0.0), (0.0, 0.0, -math.pi / 2), (0.0, 0.316, math.pi / 2), (0.0825, 0.0, math.pi / 2),
          (-0.0825, 0.384, -math.pi / 2), (0.0, 0.0, math.pi / 2), (0.088, 0.0, math.pi / 2)]
    t = np.eye(4)
    for (a, d, alpha), theta in zip(dh, q):
        ca, sa, ct, st = math.cos(alpha), math.sin(alpha), math.cos(theta), math.sin(theta)
        t = t @ np.array([[ct, -st, 0, a], [st * ca, ct * ca, -sa, -d * sa], [st * sa, ct * sa, ca, d * ca],
                          [0, 0, 0, 1]])
    flange = np.eye(4)
    flange[2, 3] = 0.107
    return t @ flange


def test_franka_has_isaacs_links_joints_and_articulation_root():
    stage = _open(FRANKA)
    root = stage.GetDefaultPrim()
    assert root.GetName() == "panda" and root.HasAPI(UsdPhysics.ArticulationRootAPI)
    links = [c.GetName() for c in root.GetChildren() if c.HasAPI(UsdPhysics.RigidBodyAPI)]
    assert links == LINKS
    joints = {str(p.GetPath()): p.GetTypeName() for p in Usd.PrimRange(root) if p.IsA(UsdPhysics.Joint)}
    expected = {f"/panda/panda_link{i}/panda_joint{i + 1}": "PhysicsRevoluteJoint" for i in range(7)}
    expected.update({"/panda/panda_link7/panda_hand_joint": "PhysicsFixedJoint",
                     "/panda/panda_hand/panda_finger_joint1": "PhysicsPrismaticJoint",
                     "/panda/panda_hand/panda_finger_joint2": "PhysicsPrismaticJoint",
                     "/panda/root_joint": "PhysicsFixedJoint"})
    assert joints == expected
    j4 = UsdPhysics.RevoluteJoint(stage.GetPrimAtPath("/panda/panda_link3/panda_joint4"))
    assert (j4.GetLowerLimitAttr().Get(), j4.GetUpperLimitAttr().Get()) == pytest.approx(
        (math.degrees(-3.0718), math.degrees(-0.0698)), abs=1e-3)
    fingers = UsdPhysics.PrismaticJoint(stage.GetPrimAtPath("/panda/panda_hand/panda_finger_joint1"))
    assert (fingers.GetLowerLimitAttr().Get(), fingers.GetUpperLimitAttr().Get()) == pytest.approx((0.0, 0.04))
    assert all(UsdPhysics.MassAPI(stage.GetPrimAtPath(f"/panda/{n}")).GetMassAttr().Get() > 0 for n in LINKS)


def test_franka_compiles_to_mujoco_with_franka_kinematics_where_it_is_placed():
    franka = rep.functional.create.reference(usd_path=get_assets_root_path() + FRANKA, name="Franka",
                                             position=(1.0, 2.0, 0.0), rotation=(0.0, 0.0, 90.0))
    view = ArticulationView(str(franka.GetPath()))
    assert view.dof_names == DOFS
    q = view.get_joint_positions()
    np.testing.assert_allclose(q, (0, -math.pi / 4, 0, -3 * math.pi / 4, 0, math.pi / 2, math.pi / 4, 0.04, 0.04),
                               atol=1e-6)
    s = runtime().sim
    m = s.model
    ids = {n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"/Franka/{n}") for n in LINKS}
    parents = {n: mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.body_parentid[i])) for n, i in ids.items()}
    assert parents["panda_link0"] == "world"
    chain = ["panda_link0", *[f"panda_link{i}" for i in range(1, 8)], "panda_hand"]
    for parent, child in zip(chain, chain[1:]):
        assert parents[child] == f"/Franka/{parent}"
    assert parents["panda_leftfinger"] == parents["panda_rightfinger"] == "/Franka/panda_hand"
    # the hand (the flange) where Franka's DH parameters put it, in the placed robot's frame
    place = np.eye(4)
    place[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    place[:3, 3] = (1.0, 2.0, 0.0)
    for pose in ((0.0,) * 7, (0.3, -0.5, 0.2, -2.0, 0.4, 1.8, -0.6)):
        view.set_joint_positions([*pose, 0.02, 0.02])
        mujoco.mj_kinematics(m, s.data)
        expected = place @ panda_flange(pose)
        np.testing.assert_allclose(s.data.xpos[ids["panda_hand"]], expected[:3, 3], atol=1e-5)
        # the hand is turned -45 degrees about the flange axis
        hand_x = s.data.xmat[ids["panda_hand"]].reshape(3, 3)[:, 0]
        np.testing.assert_allclose(hand_x, expected[:3, :3] @ (math.cos(-math.pi / 4), math.sin(-math.pi / 4), 0),
                                   atol=1e-5)
        gap = np.linalg.norm(s.data.xpos[ids["panda_leftfinger"]] - s.data.xpos[ids["panda_rightfinger"]])
        assert gap == pytest.approx(0.04, abs=1e-6)


def test_franka_drives_hold_the_ready_pose_against_gravity_and_follow_targets():
    franka = rep.functional.create.reference(usd_path=get_assets_root_path() + FRANKA, name="Franka")
    view = ArticulationView(str(franka.GetPath()))
    ready = view.get_joint_positions()
    _run(1.0)
    assert np.abs(view.get_joint_positions() - ready).max() < 0.01
    target = ready + np.array([0.3, 0.2, -0.2, 0.3, 0.3, -0.3, 0.4, -0.02, -0.02])
    view.set_joint_position_targets(target)
    _run(2.0)
    assert np.abs(view.get_joint_positions() - target).max() < 0.02


# ---- MDL materials ---------------------------------------------------------------------------
MATERIALS = "/Isaac/Environments/Simple_Warehouse/Materials"


def test_mdl_stand_ins_are_omnipbr_instances_with_textures_beside_them():
    for name, roughness in (("MI_PaperNotes_01", 0.75), ("MI_CardBoxB_05", 0.9)):
        path = get_assets_root_path() + f"{MATERIALS}/{name}.mdl"
        inst = read_module(path)[name]
        assert inst.base == "OmniPBR"
        assert inst.arguments["reflection_roughness_constant"] == pytest.approx(roughness)
        tex = inst.arguments["diffuse_texture"]
        assert tex == os.path.join(os.path.dirname(path), "Textures", f"{name}_BaseColor.png")
        assert os.path.isfile(tex)


def test_randomizing_card_box_materials_with_mdl_urls_renders_their_textures():
    """scene_based_sdg.py: rep.randomizer.materials([...mdl urls]) on a group of card-box meshes."""
    root = get_assets_root_path()
    urls = [f"{root}{MATERIALS}/MI_PaperNotes_01.mdl", f"{root}{MATERIALS}/MI_CardBoxB_05.mdl"]
    boxes = [rep.functional.create.reference(usd_path=root + "/Isaac/Environments/Simple_Warehouse/Props/"
                                             "SM_CardBoxD_04.usd", name=f"CardBox_{i}") for i in range(4)]
    meshes = [c.GetPath() for b in boxes for c in b.GetChildren() if c.IsA(UsdGeom.Mesh)]
    assert len(meshes) == 4
    with rep.trigger.on_custom_event("randomize_cardboxes_materials"):
        with rep.create.group(meshes):
            rep.randomizer.materials(urls)
    for _ in range(3):
        rep.utils.send_og_event(event_name="randomize_cardboxes_materials")
        rep.orchestrator.step()
    stage = rep.stage.get_stage()
    looks = stage.GetPrimAtPath("/Replicator/Looks")
    made = sorted(c.GetName() for c in looks.GetChildren() if c.IsA(UsdShade.Material))
    assert made == ["MI_CardBoxB_05", "MI_PaperNotes_01"]                  # one material per file, reused
    for path in meshes:
        desc = matlib.describe(matlib.bound_material(stage.GetPrimAtPath(path)))
        name = desc.path.rsplit("/", 1)[1]
        assert desc.texture == f"{root}{MATERIALS}/Textures/{name}_BaseColor.png"
        assert desc.roughness == pytest.approx(0.75 if name == "MI_PaperNotes_01" else 0.9)


def test_mdl_module_reader_names_what_it_cannot_read():
    with pytest.raises(MdlModuleError, match="not an MDL module"):
        parse_module("export material M(*) = OmniPBR();", "/x/M.mdl")
    with pytest.raises(MdlModuleError, match="cannot read the argument value 'foo"):
        parse_module("mdl 1.6; export material M(*) = OmniPBR(metallic_constant: foo(1));", "/x/M.mdl")
    with pytest.raises(MdlModuleError, match="exports no material"):
        parse_module("mdl 1.6; import ::OmniPBR::OmniPBR;", "/x/M.mdl")
    with pytest.raises(FileNotFoundError, match="nope.mdl"):
        rep.functional.randomizer.mdl_material("/no/such/nope.mdl")


# ---- warehouses ------------------------------------------------------------------------------
WAREHOUSE_DIR = "/Isaac/Environments/Simple_Warehouse"


def _mesh_boxes(stage: Usd.Stage) -> list[tuple[str, np.ndarray, np.ndarray]]:
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), ["default", "render"])
    out = []
    for p in stage.Traverse():
        if p.IsA(UsdGeom.Mesh):
            r = cache.ComputeWorldBound(p).ComputeAlignedRange()
            out.append((str(p.GetPath()), np.array(r.GetMin()), np.array(r.GetMax())))
    return out


def _blocking(boxes, lo, hi, skip=("/Floor", "FloorMarkings", "/Roof")) -> list[str]:
    """Meshes whose bounds overlap the box [lo, hi] (floor, paint and roof excluded)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return [p for p, a, b in boxes if not any(s in p for s in skip) and np.all(a < hi) and np.all(b > lo)]


def test_small_warehouse_keeps_the_spots_the_examples_use_free():
    stage = _open(f"{WAREHOUSE_DIR}/warehouse.usd")
    boxes = _mesh_boxes(stage)
    floor = stage.GetPrimAtPath("/Warehouse/Floor")
    assert floor.HasAPI(UsdPhysics.CollisionAPI) and _bounds(floor)[1][2] == pytest.approx(0.0)
    assert _blocking(boxes, (-7, -7, 0.01), (7, 7, 3)) == []             # AMR dolly / SDG workflow 2 floor
    assert _blocking(boxes, (-7.2, -0.5, 0.01), (-5.8, 9.2, 1.5)) == []   # box stacking: (-6.5, i * 1.75, 0)
    # the box-stacking snippet's shelf spots (-9.3, y, 1.3): a deck top at 1.30 m there and nothing above it
    cache = UsdGeom.XformCache()
    deck_boxes = []                    # each deck board of the west racks: its world corners' bounds
    for prim in Usd.PrimRange(stage.GetPrimAtPath("/Warehouse/Shelves/Rack_West")):
        if prim.GetName() == "Decks":
            m = np.array(cache.GetLocalToWorldTransform(prim))
            pts = np.array(UsdGeom.Mesh(prim).GetPointsAttr().Get(), dtype=float)
            world = (np.c_[pts, np.ones(len(pts))] @ m)[:, :3].reshape(-1, 8, 3)    # the decks are boxes
            deck_boxes += [(w.min(0), w.max(0)) for w in world]
    for y in (5.3, 7.3, -0.6):
        tops = [b[2] for a, b in deck_boxes if a[0] < -9.3 < b[0] and a[1] < y < b[1]]
        assert min(tops) == pytest.approx(1.3, abs=1e-4)
        assert _blocking(boxes, (-9.8, y - 0.5, 1.31), (-8.8, y + 0.5, 2.4), skip=("/Frame/",)) == []   # no stock


def test_full_warehouse_layout_fits_the_sdg_and_sensor_examples():
    stage = _open(f"{WAREHOUSE_DIR}/full_warehouse.usd")
    boxes = _mesh_boxes(stage)
    # scene-based SDG: forklift at (-20..-2, -1..3), its pallets up to ~5 m away
    assert _blocking(boxes, (-26, -6, 0.01), (4, 8, 3)) == []
    # RTX lidar / camera benchmarks: sensors at (-8, 13 + 2 i, 2); radar at (-0.937, -2 + 2 i, 0.894)
    for i in range(6):
        assert _blocking(boxes, (-8.3, 12.7 + 2 * i, 1.7), (-7.7, 13.3 + 2 * i, 2.3)) == []
        assert _blocking(boxes, (-1.2, -2.3 + 2 * i, 0.6), (-0.7, -1.7 + 2 * i, 1.2)) == []
    # a roof at 8 m: a top camera at 9-11 m with a 6 m near clip sees through it
    roof_lo, roof_hi = _bounds(stage.GetPrimAtPath("/Warehouse/Roof"))
    assert roof_lo[2] == pytest.approx(8.0) and roof_hi[2] < 9.0
    lights = [p for p in stage.Traverse() if p.GetTypeName() in ("RectLight", "DomeLight")]
    assert sorted(p.GetTypeName() for p in lights) == ["DomeLight", "RectLight", "RectLight"]
    # the ceiling bands cast no shadows: a shadow map costs every render a pass over the whole hall
    assert all(p.GetAttribute("inputs:shadow:enable").Get() is False for p in lights if p.GetTypeName() == "RectLight")
    assert stage.GetPrimAtPath("/Warehouse/Floor").HasAPI(UsdPhysics.CollisionAPI)
    # racks are stocked: every rack bay holds goods somewhere
    bays = [p for p in stage.Traverse() if p.GetName().startswith("Bay_")]
    assert len(bays) == 43 and all(any(c.GetName().startswith("Stock_") for c in b.GetChildren()) for b in bays)


def test_warehouse_with_forklifts_is_the_warehouse_plus_forklifts():
    stage = _open(f"{WAREHOUSE_DIR}/warehouse_with_forklifts.usd")
    forklifts = stage.GetPrimAtPath("/Warehouse/Forklifts").GetChildren()
    assert len(forklifts) == 3
    for f in forklifts:
        lo, hi = _bounds(f)
        assert hi[2] == pytest.approx(2.15, abs=1e-3) and lo[2] == pytest.approx(0.0, abs=1e-6)
    assert stage.GetPrimAtPath("/Warehouse/Shelves/Rack_West").IsValid()
    # camera_noise.py's camera at (-1, 5, 1) is inside and free
    assert _blocking(_mesh_boxes(stage), (-1.3, 4.7, 0.7), (-0.7, 5.3, 1.3)) == []


# ---- Nova Carter -------------------------------------------------------------------------------
CARTER = "/Isaac/Robots/NVIDIA/NovaCarter/nova_carter.usd"
NAV_ONLY = "/Isaac/Samples/Replicator/OmniGraph/nova_carter_nav_only.usd"


def test_nova_carter_nav_sample_has_the_children_and_cameras_the_scripts_look_up():
    rep.functional.create.scope(name="NavWorld")
    carter = rep.functional.create.reference(usd_path=get_assets_root_path() + NAV_ONLY, parent="/NavWorld",
                                             name="CarterNav", position=(-6.0, 4.0, 0.0))
    names = [c.GetName() for c in carter.GetChildren()]
    assert "targetXform" in names and "chassis_link" in names           # amr_navigation.py's lookups
    stage = rep.stage.get_stage()
    chassis = stage.GetPrimAtPath("/NavWorld/CarterNav/chassis_link")
    assert chassis.HasAPI(UsdPhysics.ArticulationRootAPI)
    assert chassis.GetAttribute("xformOp:translate").Get() is not None
    assert stage.GetPrimAtPath("/NavWorld/CarterNav/targetXform").GetAttribute("xformOp:translate").Get() is not None
    for side in ("left", "right"):
        cam = stage.GetPrimAtPath(f"/NavWorld/CarterNav/chassis_link/sensors/front_hawk/{side}/camera_{side}")
        assert cam.IsA(UsdGeom.Camera) and cam.GetAttribute("fStop").IsValid()
        m = np.array(UsdGeom.Xformable(cam).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
        np.testing.assert_allclose(-m[2, :3], (1, 0, 0), atol=1e-6)     # looks along the robot's +X
        np.testing.assert_allclose(m[1, :3], (0, 0, 1), atol=1e-6)      # image up is world up
        assert m[3, 0] == pytest.approx(-6.0 + 0.31) and m[3, 2] == pytest.approx(0.36)
    left = stage.GetPrimAtPath("/NavWorld/CarterNav/chassis_link/sensors/front_hawk/left/camera_left")
    right = stage.GetPrimAtPath("/NavWorld/CarterNav/chassis_link/sensors/front_hawk/right/camera_right")
    gap = (np.array(UsdGeom.Xformable(left).ComputeLocalToWorldTransform(0).ExtractTranslation())
           - np.array(UsdGeom.Xformable(right).ComputeLocalToWorldTransform(0).ExtractTranslation()))
    np.testing.assert_allclose(gap, (0, 0.15, 0), atol=1e-6)             # 0.15 m stereo baseline, left at +Y


def test_nova_carter_drives_on_its_wheel_dofs_and_turns_in_place():
    root = get_assets_root_path()
    rep.functional.create.reference(usd_path=root + "/Isaac/Environments/Grid/default_environment.usd", name="Env")
    rep.functional.create.reference(usd_path=root + CARTER, name="Carter")
    view = ArticulationView("/Carter/chassis_link")
    assert view.dof_names == ["joint_wheel_left", "joint_wheel_right"]
    chassis = rep.stage.get_stage().GetPrimAtPath("/Carter/chassis_link")
    _run(0.5)
    start = np.array(chassis.GetAttribute("xformOp:translate").Get())
    assert abs(start[2]) < 0.005                                          # resting on wheels and casters
    view.set_joint_velocity_targets([4.0, 4.0])                           # 4 rad/s x 0.14 m = 0.56 m/s
    _run(2.0)
    moved = np.array(chassis.GetAttribute("xformOp:translate").Get()) - start
    assert 0.9 < moved[0] < 1.12 and abs(moved[1]) < 0.01 and abs(moved[2]) < 0.01
    view.set_joint_velocity_targets([-1.5, 1.5])                          # spin left about the axle's middle

    def yaw() -> float:
        q = chassis.GetAttribute("xformOp:orient").Get()
        return 2 * math.atan2(q.GetImaginary()[2], q.GetReal())

    _run(1.0)                                                             # up to speed
    before, centre = yaw(), np.array(chassis.GetAttribute("xformOp:translate").Get())
    _run(0.5)
    # 1.5 rad/s x 0.14 m on each wheel, 0.413 m apart: 1.02 rad/s about the axle's middle
    assert (yaw() - before) / 0.5 == pytest.approx(2 * 1.5 * 0.14 / 0.413, rel=0.1)
    assert np.linalg.norm(np.array(chassis.GetAttribute("xformOp:translate").Get()) - centre) < 0.02


# ---- grid rooms and skies --------------------------------------------------------------------
def test_grid_rooms_have_a_colliding_floor_at_zero_and_walls_round_it():
    for rel in ("/Isaac/Environments/Grid/gridroom_black.usd", "/Isaac/Environments/Grid/gridroom_curved.usd"):
        stage = _open(rel)
        floor = stage.GetPrimAtPath("/GridRoom/Floor")
        assert floor.HasAPI(UsdPhysics.CollisionAPI)
        lo, hi = _bounds(floor)
        assert hi[2] == pytest.approx(0.0) and hi[0] - lo[0] == pytest.approx(20.0)
        assert any(p.GetTypeName() == "DistantLight" for p in stage.Traverse())
    # the cyclorama's coves: a point 1 m in from the north wall is on the curve, 0.17 m up (3 - sqrt(9 - 4))
    curved = _open("/Isaac/Environments/Grid/gridroom_curved.usd")
    pts = np.array(UsdGeom.Mesh(curved.GetPrimAtPath("/GridRoom/Cyclorama")).GetPointsAttr().Get())
    north = pts[np.abs(pts[:, 0]) < 10.5]
    d = 10.0 - north[:, 1]
    on_cove = (d > 1e-6) & (d < 3.0)
    np.testing.assert_allclose(north[on_cove, 2], 3.0 - np.sqrt(9.0 - (3.0 - d[on_cove]) ** 2), atol=1e-4)
    black = __import__("cv2").imread(get_assets_root_path() + "/Isaac/Environments/Grid/Materials/Textures/"
                                     "GridBlack_BaseColor.png")
    assert np.median(black) < 20 and black.max() > 120                    # black with light lines


def test_hotel_room_sky_is_an_hdr_lat_long_map_like_the_other_indoor_skies():
    import cv2
    path = get_assets_root_path() + "/NVIDIA/Assets/Skies/Indoor/hotel_room_4k.hdr"
    img = cv2.imread(path, cv2.IMREAD_ANYDEPTH | cv2.IMREAD_COLOR)
    assert img.shape == (128, 256, 3) and img.dtype == np.float32
    assert img.max() > 5.0 * np.median(img)                               # lamps and a window, brighter than walls


# ---- Office and Hospital props ------------------------------------------------------------------
def test_office_and_hospital_props_stand_on_their_bottom_centre_without_physics():
    from graphsdg.assets import interior_props
    office = sorted(f for f in os.listdir(get_assets_root_path() + "/Isaac/Environments/Office/Props")
                    if f.endswith(".usd"))
    assert office == ["SM_Board.usd", "SM_BookOpen_01.usd", "SM_Book_03.usd", "SM_Book_34.usd", "SM_Briefcase.usd",
                      "SM_Extinguisher.usd"]
    for prop in interior_props.INTERIOR_PROPS.values():
        stage = _open(f"{prop.folder}/{prop.name}.usd")
        root = stage.GetDefaultPrim()
        assert root.GetName() == prop.name
        lo, hi = _bounds(root)
        assert lo[2] == pytest.approx(0.0, abs=1e-5)
        np.testing.assert_allclose((lo[:2] + hi[:2]) / 2, 0.0, atol=1e-5)
        assert not any(p.HasAPI(UsdPhysics.RigidBodyAPI) or p.HasAPI(UsdPhysics.CollisionAPI)
                       for p in Usd.PrimRange(root))
        meshes = [p for p in Usd.PrimRange(root) if p.IsA(UsdGeom.Mesh)]
        assert meshes and all(matlib.bound_material(m) is not None for m in meshes)


# ---- the Cosmos warehouse sample stage ------------------------------------------------------------
def test_worker_and_anim_cameras_stage_holds_the_warehouse_a_walking_worker_and_cameras():
    from graphsdg.assets.sample_stages import worker_pose
    stage = _open("/Isaac/Samples/Replicator/Stage/full_warehouse_worker_and_anim_cameras.usd")
    assert stage.GetDefaultPrim().GetName() == "World"
    assert stage.GetPrimAtPath("/World/Warehouse/Floor").HasAPI(UsdPhysics.CollisionAPI)
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (0.0, 600.0)
    worker = UsdGeom.Xformable(stage.GetPrimAtPath("/World/Worker"))
    translate = stage.GetPrimAtPath("/World/Worker").GetAttribute("xformOp:translate")
    assert translate.GetNumTimeSamples() >= 10
    np.testing.assert_allclose(translate.Get(), (-1.0, 5.5, 0.0))                # default: the first pose
    np.testing.assert_allclose(translate.Get(300.0), (6.0, 5.5, 0.0), atol=1e-6)  # the far end half-way
    assert worker_pose(450.0)[0][0] == pytest.approx(2.5) and worker_pose(450.0)[1] == pytest.approx(180.0)
    # in view of the Cosmos example's robot camera at (-6, 4) looking along +X (41 degrees either side)
    assert math.degrees(math.atan2(5.5 - 4.0, -1.0 + 6.0)) < 35.0
    lo, hi = _bounds(stage.GetPrimAtPath("/World/Worker"))
    assert hi[2] - lo[2] == pytest.approx(1.75, abs=1e-3)
    for name in ("AnimCamera_01", "AnimCamera_02"):
        cam = stage.GetPrimAtPath(f"/World/Cameras/{name}")
        assert cam.IsA(UsdGeom.Camera) and cam.GetAttribute("xformOp:translate").GetNumTimeSamples() >= 2
        m = np.array(UsdGeom.Xformable(cam).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
        assert 0.0 < m[3, 2] < 8.0                                                # inside, under the roof


# ---- Infinigen dining rooms ---------------------------------------------------------------------
def test_infinigen_dining_rooms_carry_the_names_the_example_matches():
    folder = get_assets_root_path() + "/Isaac/Samples/Replicator/Infinigen/dining_rooms"
    rooms = sorted(f for f in os.listdir(folder) if f.endswith((".usd", ".usda", ".usdc")))
    assert rooms == ["dining_room_0.usd", "dining_room_1.usd"]           # the folder lists rooms only
    for name in rooms:
        stage = Usd.Stage.Open(os.path.join(folder, name))
        prims = list(Usd.PrimRange(stage.GetPseudoRoot()))
        tables = [p for p in prims if "TableDining" in str(p.GetPath()) and p.GetTypeName() == "Xform"]
        table = tables[0]
        loc = table.GetAttribute("xformOp:translate").Get()
        top = _bounds(table)[1][2]
        assert loc[2] == 0.0 and top == pytest.approx(0.75)
        lo, hi = _bounds(stage.GetDefaultPrim())
        assert lo[0] < loc[0] < hi[0] and lo[1] < loc[1] < hi[1]
        lamps = [p for p in prims if "001_SPLIT_GLA" in str(p.GetPath()) and p.GetTypeName() == "Xform"]
        assert len(lamps) == 1 and any(p.GetTypeName() == "SphereLight" for p in prims)
        assert sum(1 for p in prims if str(p.GetPath()).endswith("_exterior")) == 4
        assert sum(1 for p in prims if str(p.GetPath()).endswith("_ceiling")) == 1
        assert all(matlib.bound_material(p) is not None for p in prims if p.IsA(UsdGeom.Mesh))


# ---- camera calibration, simple room, ROS sample robot -------------------------------------------
def test_hawk_sees_the_checkerboard_corners_with_the_stereo_disparity_of_its_baseline():
    import cv2
    root = get_assets_root_path()
    rep.functional.create.dome_light(intensity=800)
    rep.functional.create.reference(usd_path=root + "/Isaac/Sensors/LeopardImaging/Hawk/hawk_v1.1_nominal.usd",
                                    name="Hawk")
    # as the ROS 2 camera-info test places it: 1.1 m ahead, its bottom 0.6 m below the cameras
    rep.functional.create.reference(usd_path=root + "/Isaac/Props/Camera/checkerboard_6x10.usd",
                                    name="calibration_target", position=(1.1, 0.0, -0.6))
    width, height = 320, 200
    centres = {}
    for side in ("left", "right"):
        rp = rep.create.render_product(f"/Hawk/{side}/camera_{side}", (width, height))
        rgb = rep.annotators.get("rgb")
        rgb.attach(rp)
        rep.orchestrator.step()
        gray = cv2.cvtColor(rgb.get_data()[..., :3].copy(), cv2.COLOR_RGB2GRAY)
        found, corners = cv2.findChessboardCorners(gray, (6, 10))
        assert found, side
        centres[side] = corners.reshape(-1, 2).mean(0)
    focal_px = 2.87 / 5.76 * width
    # the board's face is 1.09 m away (it is 0.01 m thick); its centre is on both optical axes' plane
    np.testing.assert_allclose(centres["left"][0] - centres["right"][0], focal_px * 0.15 / 1.09, atol=0.6)
    assert centres["left"][1] == pytest.approx(height / 2 - 0.5, abs=1.0)


def test_simple_room_and_ros_sample_robot_resolve_with_their_layout():
    stage = _open("/Isaac/Environments/Simple_Room/simple_room.usd")
    lo, hi = _bounds(stage.GetPrimAtPath("/SimpleRoom/Table"))
    assert hi[2] == pytest.approx(0.75)
    walls = stage.GetPrimAtPath("/SimpleRoom/Walls").GetChildren()
    assert len(walls) == 4 and all(w.HasAPI(UsdPhysics.CollisionAPI) for w in walls)
    assert any(p.GetTypeName() == "DomeLight" for p in stage.Traverse())
    ros = _open("/Isaac/Samples/ROS2/Robots/Nova_Carter_ROS.usd")
    assert ros.GetPrimAtPath("/Nova_Carter_ROS/chassis_link").HasAPI(UsdPhysics.ArticulationRootAPI)


def test_mdl_material_named_by_a_nucleus_url_reads_the_packs_module():
    url = ("omniverse://localhost/NVIDIA/Assets/Isaac/6.0/Isaac/Environments/Simple_Warehouse/Materials/"
           "MI_PaperNotes_01.mdl")
    cube = rep.functional.create.cube()
    mat = rep.functional.randomizer.mdl_material(url)
    matlib.bind(cube, UsdShade.Material(mat))
    desc = matlib.describe(matlib.bound_material(cube))
    assert desc.texture == get_assets_root_path() + f"{MATERIALS}/Textures/MI_PaperNotes_01_BaseColor.png"
    assert rep.functional.randomizer.mdl_material(url).GetPath() == mat.GetPath()      # made once
