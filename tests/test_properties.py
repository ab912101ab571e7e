"""Property-based tests (hypothesis): distributions, poses and quaternions, the USD -> MuJoCo compiler, annotators.

Examples are few and images tiny so the whole file runs in seconds; ``derandomize``
makes every run (and CI) explore the same examples.
"""
from __future__ import annotations

import math

import mujoco
import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from pxr import Usd, UsdGeom

import graphsdg as rep
from graphsdg.maths import rotations
from graphsdg.render.camera import camera_view
from graphsdg.engine.runtime import runtime
from graphsdg.sim.pose_writes import mujoco_poses
from graphsdg.stage import xform

from test_graph_distributions import draw

FAST = settings(max_examples=25, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
SCENES = settings(max_examples=12, deadline=None, derandomize=True,
                  suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
angle = st.floats(-360.0, 360.0, allow_nan=False)
angles = st.tuples(angle, angle, angle)
unit = st.floats(-1.0, 1.0, allow_nan=False)


@st.composite
def quaternions(draw_):
    q = np.array(draw_(st.tuples(unit, unit, unit, unit)), dtype=np.float64)
    assume(np.linalg.norm(q) > 1e-3)
    return q / np.linalg.norm(q)


@st.composite
def bounds(draw_, width=None):
    """(lower, upper): scalars or equal-length tuples, lower <= upper."""
    n = draw_(st.sampled_from([None, 1, 2, 3])) if width is None else width
    if n is None:
        a, b = sorted(draw_(st.tuples(finite, finite)))
        return a, b
    pairs = [sorted(draw_(st.tuples(finite, finite))) for _ in range(n)]
    return tuple(p[0] for p in pairs), tuple(p[1] for p in pairs)


def _fresh_graph():
    rep.graph.clear()


# ---- distributions -----------------------------------------------------------------------------------------


@FAST
@given(bounds(), st.integers(1, 40), st.integers(0, 3))
def test_uniform_samples_lie_in_their_bounds_and_repeat(b, n, execution):
    _fresh_graph()
    lo, hi = b
    u = rep.distribution.uniform(lo, hi)
    x = np.asarray(draw(u, n, execution))
    assert x.shape == (n,) + np.shape(lo)
    lo_a, hi_a = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    assert np.all(x >= lo_a) and np.all((x < hi_a) | (lo_a == hi_a) | np.isclose(x, hi_a, rtol=1e-12))
    assert np.array_equal(x, np.asarray(draw(u, n, execution)))          # same execution, same values
    assert np.array_equal(np.asarray(draw(u, 1, execution))[0], x[0])     # count-aware: a prefix


@FAST
@given(st.floats(-50, 50), st.floats(0, 20), st.integers(1, 30))
def test_normal_shape_and_zero_std(mean, std, n):
    _fresh_graph()
    x = np.asarray(draw(rep.distribution.normal(mean, std), n))
    assert x.shape == (n,) and np.all(np.isfinite(x))
    if std == 0:
        assert np.all(x == mean)


@FAST
@given(st.floats(1e-3, 1e3), st.floats(1.0, 1e3), st.integers(1, 30))
def test_log_uniform_stays_in_bounds(lower, factor, n):
    _fresh_graph()
    upper = lower * factor
    x = np.asarray(draw(rep.distribution.log_uniform(lower, upper), n))
    assert np.all(x >= lower * (1 - 1e-12)) and np.all(x <= upper * (1 + 1e-12))


@FAST
@given(st.lists(st.integers(-5, 5), min_size=1, max_size=6), st.data())
def test_choice_draws_only_choices_and_never_zero_weights(choices, data):
    _fresh_graph()
    weights = data.draw(st.lists(st.sampled_from([0.0, 0.5, 1.0, 3.0]), min_size=len(choices),
                                 max_size=len(choices)))
    assume(sum(weights) > 0)
    n = data.draw(st.integers(1, 30))
    x = np.asarray(draw(rep.distribution.choice(choices, weights=weights), n)).tolist()
    allowed = {c for c, w in zip(choices, weights) if w > 0}
    assert len(x) == n and set(x) <= allowed
    k = data.draw(st.integers(1, len(choices)))
    y = np.asarray(draw(rep.distribution.choice(list(range(len(choices))), with_replacements=False), k)).tolist()
    assert len(set(y)) == k                                               # without replacement: distinct


@FAST
@given(st.lists(st.integers(0, 9), min_size=1, max_size=7), st.integers(1, 3), st.integers(0, 5))
def test_sequence_steps_through_items_in_order(items, n, execution):
    _fresh_graph()
    x = np.asarray(draw(rep.distribution.sequence(items), n, execution)).tolist()
    assert x == [items[execution % len(items)]] * n                       # one item per execution for all targets
    y = np.asarray(draw(rep.distribution.sequence(items, stride=n), 1, execution)[0]).tolist()
    assert y == [items[(execution * n + i) % len(items)] for i in range(n)]   # stride: n consecutive items


@FAST
@given(bounds(width=2), st.floats(-5, 5), st.integers(1, 20))
def test_combine_concatenates_in_order(b, constant, n):
    _fresh_graph()
    lo, hi = b
    v = np.asarray(draw(rep.distribution.combine([rep.distribution.uniform(lo, hi), constant]), n))
    assert v.shape == (n, 3) and np.all(v[:, 2] == constant)
    assert np.all((v[:, :2] >= lo) & ((v[:, :2] < hi) | (np.asarray(lo) == np.asarray(hi))))


# ---- poses and quaternions ---------------------------------------------------------------------------------


def _rotation_ok(r):
    return np.allclose(r @ r.T, np.eye(3), atol=1e-9) and np.isclose(np.linalg.det(r), 1.0, atol=1e-9)


def _same_quat(a, b, atol=1e-7):
    return np.allclose(a, b, atol=atol) or np.allclose(a, -b, atol=atol)


@FAST
@given(angles, st.sampled_from(rotations.ROTATION_ORDERS))
def test_euler_matrices_are_rotations_and_xyz_round_trips(a, order):
    r = rotations.euler_to_matrix(a, order)
    assert _rotation_ok(r)
    xyz = rotations.euler_to_matrix(a, "XYZ")
    assert np.allclose(rotations.euler_to_matrix(rotations.matrix_to_euler_xyz(xyz), "XYZ"), xyz, atol=1e-9)


@FAST
@given(quaternions())
def test_quaternion_matrix_round_trip(q):
    r = rotations.quat_wxyz_to_matrix(q)
    assert _rotation_ok(r)
    back = rotations.matrix_to_quat_wxyz(r)
    assert back[0] >= 0 and _same_quat(back, q)
    mj = np.empty(4)
    mujoco.mju_mat2Quat(mj, r.ravel())
    assert _same_quat(mj, q)                                               # MuJoCo agrees


@FAST
@given(st.lists(angles, min_size=1, max_size=6))
def test_vectorised_direct_write_rotations_match_the_stage_code(batch):
    a = np.array(batch)
    mats = rotations.euler_to_matrix(a)
    for ai, m in zip(a, mats):
        assert np.allclose(m, rotations.euler_to_matrix(ai, "XYZ"), atol=1e-12)
    quats = rotations.matrix_to_quat_wxyz(mats)
    assert np.all(quats[:, 0] >= 0) and np.allclose(np.linalg.norm(quats, axis=1), 1)
    for q, m in zip(quats, mats):
        assert _same_quat(q, rotations.matrix_to_quat_wxyz(m))


@FAST
@given(st.lists(quaternions(), min_size=1, max_size=5))
def test_vectorised_quaternions_near_half_turns(qs):
    """Rotations close to 180 degrees (trace near -1) are where Shepperd's branches matter."""
    mats = np.array([rotations.quat_wxyz_to_matrix(q) for q in qs] +
                    [rotations.quat_wxyz_to_matrix((1e-9, q[1], q[2], q[3])) for q in qs if np.linalg.norm(q[1:]) > 1e-3])
    for q, m in zip(rotations.matrix_to_quat_wxyz(mats), mats):
        assert np.allclose(rotations.quat_wxyz_to_matrix(q), m, atol=1e-9)


@FAST
@given(st.tuples(finite, finite, finite), angles, st.tuples(st.floats(0.05, 20), st.floats(0.05, 20),
                                                             st.floats(0.05, 20)))
def test_decompose_inverts_compose(t, a, s):
    r = rotations.euler_to_matrix(a, "XYZ")
    m = np.eye(4)
    m[:3, :3] = (r * np.asarray(s)).T          # row vectors: p_world = p_local @ M
    m[3, :3] = t
    t2, r2, s2 = rotations.decompose(m)
    assert np.allclose(t2, t) and np.allclose(r2, r, atol=1e-9) and np.allclose(s2, s)


@SCENES
@given(st.tuples(finite, finite, finite), angles, st.tuples(st.floats(0.2, 3), st.floats(0.2, 3), st.floats(0.2, 3)),
       st.tuples(finite, finite, finite), angles, st.one_of(angles, quaternions()), st.floats(0.2, 3))
def test_authored_local_pose_composes_with_the_parent(pt, pa, ps, ct, ca_unused, rot, cs):
    rep.stage.new_stage()
    parent = rep.functional.create.xform(name="P", position=pt, rotation=pa, scale=ps)
    child = rep.functional.create.cube(name="C", parent=parent)
    xform.set_local_pose(child, position=ct, rotation=tuple(rot), scale=cs)
    local = np.eye(4)
    r = rotations.quat_wxyz_to_matrix(rot) if len(rot) == 4 else rotations.euler_to_matrix(rot, "XYZ")
    local[:3, :3] = (r * cs).T
    local[3, :3] = ct
    expected = local @ xform.world_matrix(parent)
    assert np.allclose(xform.world_matrix(child), expected, atol=1e-6 * max(1.0, np.abs(expected).max()))


@SCENES
@given(st.tuples(finite, finite, finite), st.tuples(finite, finite, finite))
def test_look_at_points_minus_z_at_the_target(eye, target):
    assume(np.linalg.norm(np.subtract(target, eye)) > 1e-3)
    rep.stage.new_stage()
    cam = rep.functional.create.camera(position=eye, look_at=target)
    m = xform.world_matrix(cam)
    forward = -m[2, :3] / np.linalg.norm(m[2, :3])
    want = np.subtract(target, eye) / np.linalg.norm(np.subtract(target, eye))
    assert np.allclose(forward, want, atol=1e-6)


# ---- the USD -> MuJoCo compiler ---------------------------------------------------------------------------

SHAPES = ["cube", "sphere", "cylinder", "capsule", "cone"]


@st.composite
def scenes(draw_, max_prims=4):
    """Prims under an optional posed parent xform: (shape, position, rotation, scale, label)."""
    n = draw_(st.integers(1, max_prims))
    coord = st.floats(-1.2, 1.2, allow_nan=False)
    prims = []
    for _ in range(n):
        shape = draw_(st.sampled_from(SHAPES))
        uniform_only = shape in ("sphere", "capsule")
        s = draw_(st.floats(0.3, 1.0))
        scale = (s, s, s) if uniform_only else draw_(st.tuples(st.floats(0.3, 1.0), st.floats(0.3, 1.0),
                                                                 st.floats(0.3, 1.0)))
        prims.append((shape, draw_(st.tuples(coord, coord, coord)), draw_(angles), scale,
                      draw_(st.sampled_from(["box", "ball", None]))))
    parent = draw_(st.one_of(st.none(), st.tuples(st.tuples(coord, coord, coord), angles)))
    return parent, prims


W, H = 48, 36


def _build(scene):
    rep.stage.new_stage()
    parent_pose, prims = scene
    world = rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent=world, name="Dome")
    group = world if parent_pose is None else rep.functional.create.xform(
        name="Group", parent=world, position=parent_pose[0], rotation=parent_pose[1])
    made = []
    for i, (shape, pos, rot, scale, label) in enumerate(prims):
        made.append(getattr(rep.functional.create, shape)(
            position=pos, rotation=rot, scale=scale, parent=group, name=f"{shape}{i}",
            semantics={"class": label} if label else None))
    cam = rep.functional.create.camera(position=(5.0, -5.0, 4.0), look_at=(0, 0, 0), parent=world, name="Cam")
    return made, cam


def _body_pose(sim, path):
    b = sim.compiled.geoms[path]
    return sim.data.xpos[b.body_id].copy(), sim.data.xmat[b.body_id].reshape(3, 3).copy()


def _assert_poses_match_usd(sim, prims):
    for prim in prims:
        t, r, _ = rotations.decompose(xform.world_matrix(prim))
        pos, mat = _body_pose(sim, str(prim.GetPath()))
        assert np.allclose(pos, t, atol=1e-6), (prim.GetPath(), pos, t)
        assert np.allclose(mat, r, atol=1e-6), (prim.GetPath(), mat, r)


def _projected_bound(view, prim):
    """Pixel box of the prim's world-space bounding box, or None if part of it is behind the camera."""
    box = UsdGeom.BBoxCache(Usd.TimeCode.Default(), ["default", "render"]).ComputeWorldBound(prim)
    rng = box.ComputeAlignedRange()
    lo, hi = np.array(rng.GetMin()), np.array(rng.GetMax())
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    if np.any(view.world_to_camera(corners)[:, 2] > -1e-3):
        return None
    uv, _ = view.project(corners)
    return uv.min(0), uv.max(0)


@SCENES
@given(scenes())
def test_random_scenes_compile_render_and_round_trip_their_transforms(scene):
    prims, cam = _build(scene)
    sim = runtime().sim
    sim.sync_dirty_prims()
    sim.ensure_compiled()
    assert set(str(p.GetPath()) for p in prims) <= set(sim.compiled.geoms)
    _assert_poses_match_usd(sim, prims)
    # every pixel a prim covers lies inside the projection of its USD world bound (pose, scale, axis agree)
    view = camera_view(cam, W, H)
    out = runtime().rasterizer.render(runtime().render_scene, view, {"segmentation"}, 1)
    for prim in prims:
        gid = sim.compiled.geoms[str(prim.GetPath())].geom_id
        ys, xs = np.nonzero(out.geom_ids == gid)
        bound = _projected_bound(view, prim)
        if len(xs) == 0 or bound is None:
            continue
        (u0, v0), (u1, v1) = bound
        assert xs.min() >= math.floor(u0) - 1 and xs.max() <= math.ceil(u1) and \
            ys.min() >= math.floor(v0) - 1 and ys.max() <= math.ceil(v1), (prim.GetPath(), bound)
    # edits sync without recompiling, through USD and through direct writes (write-to-fabric) alike
    gen = np.random.default_rng(len(prims))
    new_pos = gen.uniform(-1, 1, (len(prims), 3))
    new_rot = gen.uniform(-180, 180, (len(prims), 3))
    version = sim.model_version
    rep.functional.modify.pose(prims, position_value=new_pos, rotation_value=new_rot)
    sim.sync_dirty_prims()
    assert sim.model_version == version
    _assert_poses_match_usd(sim, prims)
    via_usd = {str(p.GetPath()): _body_pose(sim, str(p.GetPath())) for p in prims}
    assert mujoco_poses.write_poses(sim, prims, new_pos[::-1].copy(), new_rot[::-1].copy(), None)
    assert mujoco_poses.write_poses(sim, prims, new_pos, new_rot, None)
    for p in prims:
        pos, mat = _body_pose(sim, str(p.GetPath()))
        assert np.allclose(pos, via_usd[str(p.GetPath())][0], atol=1e-9)
        assert np.allclose(mat, via_usd[str(p.GetPath())][1], atol=1e-9)


# ---- annotators ---------------------------------------------------------------------------------------------


@SCENES
@given(scenes(max_prims=5))
def test_random_scenes_ids_masks_and_boxes_agree(scene):
    prims, cam = _build(scene)
    rp = rep.create.render_product(cam, (W, H))
    names = ["semantic_segmentation", "instance_segmentation", "instance_id_segmentation", "bounding_box_2d_tight"]
    anns = {n: rep.annotators.get(n).attach(rp) for n in names}
    rep.orchestrator.step(delta_time=0)
    sem = anns["semantic_segmentation"].get_data()
    inst = anns["instance_segmentation"].get_data()
    ids = anns["instance_id_segmentation"].get_data()
    tight = anns["bounding_box_2d_tight"].get_data()
    labelled = {str(p.GetPath()) for p, (_, _, _, _, label) in zip(prims, scene[1]) if label}
    # every labelled instance in the image has exactly one box, and its box is the mask's extent
    visible = {inst["info"]["idToLabels"][str(i)] for i in np.unique(inst["data"]) if i > 1}
    assert set(tight["info"]["primPaths"]) == visible and visible <= labelled
    for row, bbox_id, path in zip(tight["data"], tight["info"]["bboxIds"], tight["info"]["primPaths"]):
        mask = inst["data"] == bbox_id
        ys, xs = np.nonzero(mask)
        assert (xs.min(), ys.min(), xs.max(), ys.max()) == (row["x_min"], row["y_min"], row["x_max"], row["y_max"])
        assert np.all(sem["data"][mask] == row["semanticId"])
        label = next(lab for p, (_, _, _, _, lab) in zip(prims, scene[1]) if str(p.GetPath()) == path)
        assert sem["info"]["idToLabels"][str(row["semanticId"])] == {"class": label}
    # the per-prim id image splits the same pixels: each prim's pixels carry one id there
    for i in np.unique(inst["data"]):
        if i > 1:
            assert len(np.unique(ids["data"][inst["data"] == i])) == 1
    # background and unlabelled prims carry no instance
    assert np.all((inst["data"] > 1) == np.isin(sem["data"], [int(k) for k, v in sem["info"]["idToLabels"].items()
                                                              if v.get("class") not in ("BACKGROUND", "UNLABELLED")]))
    for a in anns.values():
        a.detach()
    rp.destroy()
