"""Physics from the UsdPhysics schema, the timeline, state access and scene queries.

Every check is against analytic truth (free fall under semi-implicit Euler, box
geometry) or a physical invariant (resting boxes do not sink into each other).
"""
from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, UsdGeom, UsdPhysics

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.physics import queries
from graphsdg.sim import bounds, transforms
from graphsdg.physics.bodies import RigidBodyView
from graphsdg.sim.colliders import ApproximationError
from graphsdg.sim.compile_error import CompileError
from graphsdg.sim.visual import COLLISION_ONLY_GROUP
from graphsdg.sim.timeline import TimelineEventType

G = 9.81
DT = 1.0 / 60.0                # one timeline frame
H = 1.0 / 120.0                # one physics step (two per frame by default)
PALLET_TOP = 0.14


def sim():
    s = runtime().sim
    s.sync_dirty_prims()
    return s


def run_ticks(n):
    tl = rep.timeline.get_timeline_interface()
    tl.play()
    for _ in range(n):
        rep.orchestrator.update()
    tl.pause()


def free_fall_z(z0, ticks, steps_per_tick=2):
    # MuJoCo's semi-implicit Euler: v_k = -g h k, z_n = z0 - g h² n (n + 1) / 2.
    n, h = ticks * steps_per_tick, DT / steps_per_tick
    return z0 - G * h * h * n * (n + 1) / 2


def falling_cube(z=10.0, **kwargs):
    cube = rep.functional.create.cube(position=(0, 0, z), name="Cube")
    rep.functional.physics.apply_rigid_body(cube, **kwargs)
    return cube


# ---- rigid bodies and masses ----------------------------------------------------
def test_free_fall_matches_semi_implicit_euler_and_writes_back_to_usd():
    cube = falling_cube()
    run_ticks(30)
    positions, orientations = RigidBodyView(cube).get_world_poses()
    linear, angular = RigidBodyView(cube).get_velocities()
    assert positions[0, 2] == pytest.approx(free_fall_z(10.0, 30), abs=1e-9)
    assert linear[0, 2] == pytest.approx(-G * DT * 30, abs=1e-9)
    assert sim().model.opt.timestep == pytest.approx(H)
    assert np.allclose(orientations[0], [1, 0, 0, 0]) and np.allclose(angular, 0)
    assert transforms.get_world_position(cube)[2] == pytest.approx(positions[0, 2], abs=1e-6)
    assert rep.timeline.get_timeline_interface().get_current_time() == pytest.approx(0.5)


def test_kinematic_body_does_not_fall_and_follows_pose_edits():
    cube = falling_cube(z=1.0, kinematicEnabled=True, with_collider=True)
    run_ticks(10)
    assert RigidBodyView(cube).get_world_poses()[0][0, 2] == pytest.approx(1.0)
    rep.functional.modify.position(cube, (0.5, 0, 1.0))
    assert RigidBodyView(cube).get_world_poses()[0][0].tolist() == pytest.approx([0.5, 0, 1.0])
    assert sim().body(str(cube.GetPath())).mocap_id >= 0


def test_masses_from_density_mass_api_and_collider_mass():
    default = rep.functional.create.cube(position=(0, 0, 1), name="Default")      # 1 m³ at 1000 kg/m³
    rep.functional.physics.apply_rigid_body(default, with_collider=True)
    light = rep.functional.create.cube(position=(3, 0, 1), name="Light")
    rep.functional.physics.apply_rigid_body(light, with_collider=True, density=250.0)
    heavy = rep.functional.create.cube(position=(6, 0, 1), scale=0.5, name="Heavy")
    rep.functional.physics.apply_rigid_body(heavy, with_collider=True, mass=7.0)
    group = rep.functional.create.xform(name="Group", position=(9, 0, 1))
    part = rep.functional.create.cube(parent=group, name="Part")
    rep.functional.physics.apply_collider(part)
    rep.functional.physics.apply_mass(part, mass=3.0)
    rep.functional.physics.apply_rigid_body(group)
    masses = RigidBodyView(["/Default", "/Light", "/Heavy", "/Group"]).get_masses()
    assert masses.tolist() == pytest.approx([1000.0, 250.0, 7.0, 3.0])
    # A plain pxr edit of the schema is honoured at the next sync.
    UsdPhysics.MassAPI(heavy).GetMassAttr().Set(11.0)
    assert RigidBodyView(heavy).get_masses()[0] == pytest.approx(11.0)


def test_negative_mass_is_a_clear_error_from_the_api_and_from_pxr():
    cube = rep.functional.create.cube()
    with pytest.raises(ValueError, match=r"mass must be a positive finite number, got -2"):
        rep.functional.physics.apply_rigid_body(cube, mass=-2.0)
    rep.functional.physics.apply_rigid_body(cube)
    UsdPhysics.MassAPI.Apply(cube).CreateMassAttr().Set(-5.0)
    with pytest.raises(CompileError, match=r"physics:mass of /Cube is -5\.0"):
        sim()


def test_rigid_body_without_geometry_and_unknown_approximation_are_clear_errors():
    empty = rep.functional.create.xform(name="Empty")
    with pytest.raises(ValueError, match=r"/Empty has no geometry under it"):
        rep.functional.physics.apply_rigid_body(empty)
    with pytest.raises(ValueError, match=r"/Empty has no geometry under it to collide with"):
        rep.functional.physics.apply_collider(empty)
    disk = rep.functional.create.disk(name="Disk")
    with pytest.raises(ApproximationError, match=r"'boundingBox'.*did you mean 'boundingCube'.*known approximations: "
                                                 r"none, convexHull"):
        rep.functional.physics.apply_collider(disk, approximation="boundingBox")
    rep.functional.physics.apply_collider(disk)
    UsdPhysics.MeshCollisionAPI.Apply(disk).CreateApproximationAttr().Set("cube")
    with pytest.raises(CompileError, match=r"unknown collider approximation 'cube' on /Disk"):
        sim()


def test_mesh_approximations_become_the_right_collision_shapes():
    torus = rep.functional.create.torus(name="Torus", scale=(2, 2, 2))     # major 0.75, minor 0.25 after scale
    rep.functional.physics.apply_collider(torus, approximation="boundingCube")
    s = sim()
    m = s.model
    proxies = [g for g, p in s.compiled.collider_prim.items() if p == "/Torus"]
    assert len(proxies) == 1 and m.geom_type[proxies[0]] == 6          # mjGEOM_BOX
    assert m.geom_group[proxies[0]] == COLLISION_ONLY_GROUP
    half = m.geom_size[proxies[0]]
    assert sorted(half.tolist()) == pytest.approx([0.25, 1.0, 1.0], abs=1e-6)
    visual = s.compiled.geoms["/Torus"].geom_id
    assert m.geom_contype[visual] == 0 and m.geom_contype[proxies[0]] == 1
    UsdPhysics.MeshCollisionAPI(torus).GetApproximationAttr().Set("boundingSphere")
    s = sim()
    proxies = [g for g, p in s.compiled.collider_prim.items() if p == "/Torus"]
    assert s.model.geom_type[proxies[0]] == 2 and s.model.geom_size[proxies[0], 0] == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("approximation,falls_through", [("none", True), ("convexHull", False)])
def test_exact_torus_lets_a_ball_through_its_hole_and_its_hull_does_not(approximation, falls_through):
    torus = rep.functional.create.torus(name="Torus", scale=(2, 2, 2))     # hole radius 0.5
    rep.functional.physics.apply_collider(torus, approximation=approximation)
    ball = rep.functional.create.sphere(name="Ball", position=(0, 0, 1.0), scale=0.4)
    rep.functional.physics.apply_rigid_body(ball, with_collider=True)
    run_ticks(60)
    z = RigidBodyView(ball).get_world_poses()[0][0, 2]
    if falls_through:
        assert z < -0.5
    else:
        assert z == pytest.approx(0.25 + 0.2, abs=0.01)       # resting on the hull's top face


def test_plane_collider_is_infinite_and_a_cube_rests_on_it():
    ground = rep.functional.create.plane(scale=(0.5, 0.5, 1), name="Ground")
    rep.functional.physics.apply_collider(ground)
    cube = falling_cube(z=0.5, with_collider=True)
    rep.functional.modify.position(cube, (3.0, 0, 0.6))      # far outside the drawn plane
    run_ticks(90)
    assert RigidBodyView(cube).get_world_poses()[0][0, 2] == pytest.approx(0.5, abs=0.005)


def test_physics_scene_gravity_and_timestep():
    rep.functional.physics.create_physics_scene(gravity_direction=(1, 0, 0), gravity_magnitude=2.0,
                                                time_steps_per_second=120)
    cube = falling_cube(z=0.0)
    run_ticks(6)
    s = sim()
    assert s.model.opt.timestep == pytest.approx(1 / 120)
    assert s.data.time == pytest.approx(0.1)
    n, h = 12, H
    assert RigidBodyView(cube).get_world_poses()[0][0].tolist() == pytest.approx(
        [2.0 * h * h * n * (n + 1) / 2, 0, 0], abs=1e-9)
    UsdPhysics.Scene(runtime().stage.GetPrimAtPath("/physicsScene")).GetGravityMagnitudeAttr().Set(0.0)
    before = RigidBodyView(cube).get_world_poses()[0][0, 0]
    velocity = RigidBodyView(cube).get_velocities()[0][0, 0]
    run_ticks(6)
    assert RigidBodyView(cube).get_world_poses()[0][0, 0] == pytest.approx(before + velocity * 0.1, abs=1e-9)


def test_disable_gravity():
    cube = falling_cube(z=2.0, disableGravity=True)
    run_ticks(20)
    assert RigidBodyView(cube).get_world_poses()[0][0, 2] == pytest.approx(2.0, abs=1e-9)


def _box_with_mesh_child(name, size, parent="/World"):
    """A referenced-asset-like box: an Xform with a Mesh child, origin at its bottom centre."""
    from pxr import Vt
    box = rep.functional.create.xform(name=name, parent=parent)
    sx, sy, sz = size
    pts = np.array([[x, y, z] for z in (0, sz) for y in (-sy / 2, sy / 2) for x in (-sx / 2, sx / 2)])
    mesh = UsdGeom.Mesh.Define(runtime().stage, box.GetPath().AppendChild("Mesh"))
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pts.astype(np.float32)))
    mesh.CreateFaceVertexCountsAttr([4] * 6)
    mesh.CreateFaceVertexIndicesAttr([0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5])
    return box, mesh.GetPrim()


def supported_on_pallet_or_floor(boxes, base=("/World/Ground", "/World/Pallet")):
    """Paths of boxes that rest, through a chain of contacts from below, on the pallet or the floor."""
    below = {str(b.GetPath()): {c.other_rigid_body for c in queries.get_contacts(b) if c.normal[2] > 0.3}
             for b in boxes}
    held = set(base)
    changed = True
    while changed:
        changed = False
        for path, supports in below.items():
            if path not in held and supports & held:
                held.add(path)
                changed = True
    return held - set(base)


def assert_no_interpenetration_or_sinking(boxes):
    s = sim()
    s.forward()
    d = s.data
    worst = max((-d.contact[i].dist for i in range(d.ncon)), default=0.0)
    assert worst <= 0.01, f"interpenetration {worst:.4f} m"
    cache = bounds.create_bbox_cache()
    for box in boxes:
        low = bounds.compute_aabb(box, cache)[2]
        assert low >= -0.01, f"{box.GetPath()} is below the floor ({low:.3f})"


def settle(boxes, max_ticks=600):
    """Tick until every box is at rest (|v| < 2 cm/s, |w| < 0.2 rad/s); return the ticks taken."""
    view = RigidBodyView(boxes)
    for k in range(0, max_ticks, 15):
        linear, angular = view.get_velocities()
        if np.abs(linear).max() < 0.02 and np.abs(angular).max() < 0.2:
            return k
        run_ticks(15)
    raise AssertionError(f"boxes still moving after {max_ticks} ticks")


def test_boxes_settle_on_pallet_and_floor_without_interpenetrating():
    """Workflow 1's physics with 0.1-0.4 m boxes: dropped on a kinematic pallet, re-dropped one at a time."""
    rep.functional.create.xform(name="World")
    ground = rep.functional.create.plane(parent="/World", name="Ground", scale=(20, 20, 1))
    rep.functional.physics.apply_collider(ground)
    pallet = rep.functional.create.xform(name="Pallet", parent="/World")
    rep.functional.create.cube(parent=pallet, name="Deck", position=(0, 0, PALLET_TOP / 2),
                               scale=(1.2, 0.8, PALLET_TOP))
    rep.functional.physics.apply_rigid_body(pallet, with_collider=True, kinematicEnabled=True)
    rng = rep.rng.ReplicatorRNG(seed=7)
    sizes = rng.generator.uniform(0.1, 0.4, size=(10, 3))
    boxes = []
    for i, size in enumerate(sizes):
        box, mesh = _box_with_mesh_child(f"Box_{i}", size)
        # As the seed does: plain pxr MeshCollisionAPI, then rigid bodies on the mesh and on the box.
        UsdPhysics.MeshCollisionAPI.Apply(mesh).CreateApproximationAttr().Set("boundingCube")
        rep.functional.physics.apply_rigid_body(mesh, with_collider=True, approximation="boundingCube")
        rep.functional.physics.apply_rigid_body(box)
        boxes.append(box)

    def drop(selected, start_height):
        for k, box in enumerate(selected):
            xy = rng.generator.uniform(-0.4, 0.4, 2)
            tilt = rng.generator.uniform(0, 15, 2)
            rep.functional.modify.pose(box, position_value=(*xy, start_height + 0.2 * k),
                                       rotation_value=(*tilt, rng.generator.uniform(0, 360)))
        run_ticks(75)
        assert_no_interpenetration_or_sinking(boxes)

    drop(boxes, 0.3)
    for _ in range(3):
        drop([boxes[int(rng.generator.integers(0, len(boxes)))]], 1.2)
    settle(boxes)
    assert_no_interpenetration_or_sinking(boxes)
    assert supported_on_pallet_or_floor(boxes) == {str(b.GetPath()) for b in boxes}
    assert any(c.other_rigid_body == "/World/Pallet" for b in boxes for c in queries.get_contacts(b))


# ---- timeline -------------------------------------------------------------------
def test_timeline_play_pause_stop_and_events():
    cube = falling_cube(z=5.0)
    tl = rep.timeline.get_timeline_interface()
    events = []
    sub = tl.subscribe(lambda e: events.append((TimelineEventType(e.type).name, dict(e.payload))))
    assert tl.get_time_codes_per_seconds() == 60.0 and tl.is_stopped() and not tl.is_playing()
    rep.orchestrator.update()                     # not playing: no time passes
    assert tl.get_current_time() == 0.0
    tl.play()
    assert tl.is_playing()
    rep.orchestrator.update()
    rep.orchestrator.update()
    tl.pause()
    rep.orchestrator.update()
    assert tl.get_current_time() == pytest.approx(2 * DT)
    assert transforms.get_world_position(cube)[2] == pytest.approx(free_fall_z(5.0, 2))
    tl.stop()
    assert tl.get_current_time() == 0.0 and sim().data.time == 0.0
    assert transforms.get_world_position(cube)[2] == pytest.approx(5.0)      # back where it was at play
    assert RigidBodyView(cube).get_velocities()[0][0].tolist() == [0, 0, 0]
    names = [n for n, _ in events if n != "CURRENT_TIME_TICKED_PERMANENT"]
    assert names == ["PLAY", "CURRENT_TIME_TICKED", "CURRENT_TIME_TICKED", "PAUSE", "STOP"]
    ticks = [p for n, p in events if n == "CURRENT_TIME_TICKED"]
    assert ticks[1]["currentTime"] == pytest.approx(2 * DT) and ticks[1]["dt"] == pytest.approx(DT)
    sub.unsubscribe()
    with pytest.raises(ValueError, match="positive"):
        tl.set_time_codes_per_second(0)
    with pytest.raises(ValueError, match="unknown timeline event type 42"):
        tl.subscribe(print, 42)


def test_tick_subscriber_can_pause_and_unsubscribe_itself():
    falling_cube(z=5.0)
    tl = rep.timeline.get_timeline_interface()
    seen = []

    def on_tick(event):
        seen.append(event.payload["currentTime"])
        if len(seen) == 3:
            tl.pause()
            sub.unsubscribe()

    sub = tl.subscribe(on_tick, TimelineEventType.CURRENT_TIME_TICKED)
    tl.play()
    for _ in range(10):
        rep.orchestrator.update()
    assert len(seen) == 3 and not tl.is_playing()
    assert tl.get_current_time() == pytest.approx(3 * DT)


def test_step_delta_time_zero_none_and_positive():
    cube = falling_cube(z=10.0)
    tl = rep.timeline.get_timeline_interface()
    rep.orchestrator.step(delta_time=0.0)
    assert tl.get_current_time() == 0.0 and transforms.get_world_position(cube)[2] == 10.0
    rep.orchestrator.step()                        # one frame, then paused
    assert tl.get_current_time() == pytest.approx(DT) and not tl.is_playing()
    assert transforms.get_world_position(cube)[2] == pytest.approx(free_fall_z(10.0, 1))
    rep.orchestrator.step(delta_time=0.5, pause_timeline=False)
    assert tl.get_current_time() == pytest.approx(DT + 0.5) and tl.is_playing()
    assert transforms.get_world_position(cube)[2] == pytest.approx(free_fall_z(10.0, 31), abs=1e-9)
    with pytest.raises(ValueError, match="delta_time"):
        rep.orchestrator.step(delta_time=-1.0)


def test_capture_on_play_captures_every_tick_only_when_enabled(out_dir):
    cube = falling_cube(z=3.0)
    RigidBodyView(cube).set_velocities(linear=[[0, 0, -6.0]])        # ~2.5 px per tick in this view
    cam = rep.functional.create.camera(position=(4, 0, 2.5), look_at=(0, 0, 2.5))
    rp = rep.create.render_product(cam, (64, 64))
    depth = rep.annotators.get("distance_to_image_plane")
    depth.attach(rp)
    tl = rep.timeline.get_timeline_interface()
    rep.orchestrator.set_capture_on_play(True)
    tl.play()
    rows = []
    for _ in range(3):
        rep.orchestrator.update()
        d = depth.get_data()
        rows.append(np.nonzero(np.isfinite(d).any(1))[0].min())     # top image row the cube covers
    assert rows[0] < rows[1] < rows[2]                            # a new capture every tick, cube lower each time
    rep.orchestrator.set_capture_on_play(False)
    rep.orchestrator.update()
    d = depth.get_data()
    assert np.nonzero(np.isfinite(d).any(1))[0].min() == rows[2]  # physics moved on, no new capture
    assert tl.get_current_time() == pytest.approx(4 * DT)


# ---- state access -----------------------------------------------------------------
def test_rigid_body_view_selects_by_path_regex_and_index_and_sets_state():
    cubes = [falling_cube(z=2.0 + i) for i in range(3)]
    view = RigidBodyView("/Cube.*")
    assert view.paths == [str(c.GetPath()) for c in cubes]
    assert view.get_world_poses(indices=[2])[0][0, 2] == pytest.approx(4.0)
    view.set_velocities(linear=[[1, 0, 0]], angular=[[0, 0, np.pi]], indices=[0])
    view.set_world_poses(positions=[[5, 5, 5]], indices=[1])
    assert transforms.get_world_position(cubes[1]).tolist() == [5, 5, 5]
    lin, ang = view.get_velocities(indices=[0])
    assert lin[0].tolist() == [1, 0, 0] and ang[0].tolist() == pytest.approx([0, 0, np.pi])
    with pytest.raises(ValueError, match="matches no rigid body"):
        RigidBodyView("/Nothing.*")
    plain = rep.functional.create.cube(name="Plain")
    with pytest.raises(ValueError, match="/Plain is not a rigid body"):
        RigidBodyView(plain)
    with pytest.raises(IndexError):
        view.get_world_poses(indices=[3])


def test_bounds_and_world_transforms():
    parent = rep.functional.create.xform(name="P", position=(1, 2, 0), rotation=(0, 0, 90))
    cube = rep.functional.create.cube(parent=parent, position=(1, 0, 0.5), scale=(2, 1, 1))
    assert transforms.get_world_position(cube).tolist() == pytest.approx([1, 3, 0.5])
    m = transforms.get_world_transform_matrix(cube)
    assert isinstance(m, Gf.Matrix4d) and tuple(m.ExtractTranslation()) == pytest.approx((1, 3, 0.5))
    aabb = bounds.compute_aabb(parent, bounds.create_bbox_cache(), include_children=True)
    assert aabb.tolist() == pytest.approx([0.5, 2, 0, 1.5, 4, 1])
    center, axes, half = bounds.compute_obb(cube)
    assert center.tolist() == pytest.approx([1, 3, 0.5]) and half.tolist() == pytest.approx([1, 0.5, 0.5])
    with pytest.raises(ValueError, match="has no geometry"):
        bounds.compute_aabb(rep.functional.create.xform(name="Empty"))


# ---- queries ------------------------------------------------------------------------
def _crates():
    a = rep.functional.create.cube(name="A", position=(0, 0, 0.5))
    b = rep.functional.create.cube(name="B", position=(3, 0, 0.5))
    rep.functional.physics.apply_rigid_body(a, with_collider=True)
    rep.functional.physics.apply_collider(b)
    rep.functional.create.cube(name="Ghost", position=(1.5, 0, 0.5))   # no collider: never reported
    return a, b


def test_overlap_box_reports_touched_bodies_and_callback_can_stop():
    _crates()
    hits = []
    n = queries.overlap_box((2.0, 0.3, 0.3), (1.5, 0, 0.5), (0, 0, 0, 1), lambda h: hits.append(h) or True)
    assert n == 2 and sorted(h.rigid_body for h in hits) == ["/A", "/B"]
    assert {h.collision for h in hits} == {"/A", "/B"}
    stopped = []
    assert queries.overlap_box((2.0, 0.3, 0.3), (1.5, 0, 0.5), (0, 0, 0, 1),
                               lambda h: stopped.append(h) or False) == 1
    assert len(stopped) == 1
    assert queries.overlap_box((0.9, 0.3, 0.3), (1.5, 0, 0.5), (0, 0, 0, 1), None) == 0   # gap between crates
    # Rotated 90° about z the long box no longer reaches either crate.
    s = np.sin(np.pi / 4)
    assert queries.overlap_box((2.0, 0.3, 0.3), (1.5, 0, 0.5), (0, 0, s, s), None) == 0
    assert queries.overlap_sphere(0.6, (0, 1.0, 0.5)) == 1


def test_overlap_box_reports_the_body_not_its_mesh_and_rejects_bad_extents():
    box, mesh = _box_with_mesh_child("Bin", (0.4, 0.4, 0.3), parent=None)
    rep.functional.physics.apply_rigid_body(box, with_collider=True)
    hits = []
    queries.overlap_box((0.1, 0.1, 0.1), (0, 0, 0.15), (0, 0, 0, 1), lambda h: hits.append(h) or True)
    assert [(h.rigid_body, h.collision) for h in hits] == [("/Bin", "/Bin/Mesh")]
    for bad in [(0, 1, 1), (1, -1, 1)]:
        with pytest.raises(ValueError, match=r"half_extent must be 3 positive numbers"):
            queries.overlap_box(bad, (0, 0, 0), (0, 0, 0, 1), None)
    with pytest.raises(ValueError, match="non-zero"):
        queries.overlap_box((1, 1, 1), (0, 0, 0), (0, 0, 0, 0), None)


def test_raycast_and_contacts():
    a, b = _crates()
    hit = queries.raycast_closest((0, 0, 5), (0, 0, -1), 10.0)
    assert hit["hit"] and hit["rigidBody"] == "/A" and hit["distance"] == pytest.approx(4.0)
    assert hit["normal"] == pytest.approx((0, 0, 1)) and hit["position"] == pytest.approx((0, 0, 1))
    assert queries.raycast_closest((1.5, 0, 5), (0, 0, -1), 10.0) == {"hit": False}   # the ghost has no collider
    assert queries.raycast_closest((-5, 0, 0.5), (1, 0, 0), 20.0)["rigidBody"] == "/A"
    assert queries.raycast_all((-5, 0, 0.5), (1, 0, 0), 20.0) == 2
    ground = rep.functional.create.plane(name="Ground", scale=(10, 10, 1))
    rep.functional.physics.apply_collider(ground)
    run_ticks(30)
    contacts = queries.get_contacts(a)
    assert contacts and all(c.other_rigid_body == "/Ground" for c in contacts)
    assert all(c.normal[2] == pytest.approx(1.0, abs=1e-6) for c in contacts)
    assert sum(c.normal_force for c in contacts) == pytest.approx(1000 * G, rel=0.02)   # 1 m³ at 1000 kg/m³
    with pytest.raises(ValueError, match="has no colliders"):
        queries.get_contacts(rep.functional.create.cube(name="Loose"))


def test_structural_edit_mid_fall_recompiles_and_keeps_the_state():
    cube = falling_cube(z=10.0)
    run_ticks(10)
    compiles = sim().stats["compiles"]
    rep.functional.create.sphere(name="Newcomer", position=(5, 5, 5))      # a prim added: recompile
    run_ticks(10)
    assert sim().stats["compiles"] == compiles + 1
    assert RigidBodyView(cube).get_world_poses()[0][0, 2] == pytest.approx(free_fall_z(10.0, 20), abs=1e-9)


def test_a_pile_of_boxes_is_deterministic():
    def pile():
        rep.stage.new_stage()
        ground = rep.functional.create.plane(scale=(5, 5, 1), name="Ground")
        rep.functional.physics.apply_collider(ground)
        g = np.random.default_rng(3)
        cubes = []
        for i in range(6):
            c = rep.functional.create.cube(name=f"C{i}", scale=g.uniform(0.1, 0.3, 3),
                                           position=(*g.uniform(-0.2, 0.2, 2), 0.3 + 0.3 * i),
                                           rotation=g.uniform(0, 40, 3))
            rep.functional.physics.apply_rigid_body(c, with_collider=True)
            cubes.append(c)
        run_ticks(60)
        return np.concatenate(RigidBodyView(cubes).get_world_poses(), axis=1)

    assert np.array_equal(pile(), pile())


def test_a_scene_without_degrees_of_freedom_advances_to_the_state_mj_step_gives():
    """No rigid bodies (nv = 0): advancing moves the clock step by step without mj_step's forward pass, to the
    same time and poses as stepping with mj_step, and physics callbacks still run once a step."""
    import mujoco
    for name, z in (("A", 0.5), ("B", 1.2)):
        rep.functional.physics.apply_collider(rep.functional.create.cube(position=(0, 0, z), name=name))
    s = sim()
    m, d = s.model, s.data
    assert m.nv == 0
    reference = mujoco.MjData(m)
    mujoco.mj_copyData(reference, m, d)
    calls = []
    s.add_physics_callback("count", lambda step: calls.append(step))
    s.advance(DT)
    for _ in range(2):
        mujoco.mj_step(m, reference)
    mujoco.mj_forward(m, reference)
    assert calls == [H, H]
    assert d.time == reference.time == pytest.approx(DT)
    np.testing.assert_array_equal(d.geom_xpos, reference.geom_xpos)
