"""scatter_2d / scatter_3d: uniform by area or volume, no overlaps, clear failures."""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy import stats

import graphsdg as rep
from graphsdg.sim import bounds, transforms
from graphsdg.sim.placement import Volume, sample_surface, surface_of

scatter_2d = rep.functional.randomizer.scatter_2d
scatter_3d = rep.functional.randomizer.scatter_3d


def rng(seed=0):
    return rep.rng.ReplicatorRNG(seed=seed)


def world_boxes(prims):
    cache = bounds.create_bbox_cache()
    return np.array([bounds.compute_aabb(p, cache) for p in prims])


def overlapping_pairs(boxes, tol=1e-6):
    pairs = []
    for i, j in itertools.combinations(range(len(boxes)), 2):
        lo = np.maximum(boxes[i, :3], boxes[j, :3])
        hi = np.minimum(boxes[i, 3:], boxes[j, 3:])
        if np.all(hi - lo > tol):
            pairs.append((i, j))
    return pairs


def test_scattered_prims_never_overlap_and_sit_on_the_hidden_surface():
    floor = rep.functional.create.plane(scale=(3, 3, 1), position=(1, 2, 0.5), visible=False)
    crates = rep.functional.create_batch.cube(count=12, scale=(0.5, 0.3, 0.2), rotation=(0, 0, 30))
    scatter_2d(crates, floor, offset=0.1, check_for_collisions=True, rng=rng(4))
    boxes = world_boxes(crates)
    assert overlapping_pairs(boxes) == []
    origins = np.array([transforms.get_world_position(c) for c in crates])
    assert np.allclose(origins[:, 2], 0.6)                                  # surface z + offset along +Z
    assert np.all(np.abs(origins[:, :2] - (1, 2)) <= 1.5 + 1e-9)
    assert np.allclose([c.GetAttribute("xformOp:rotateXYZ").Get()[2] for c in crates], 30)   # rotation kept


def test_without_collision_checks_prims_may_overlap_but_still_land_on_the_surface():
    floor = rep.functional.create.plane(scale=(0.5, 0.5, 1))
    crates = rep.functional.create_batch.cube(count=20, scale=0.3)
    scatter_2d(crates, floor, rng=rng(1))
    assert overlapping_pairs(world_boxes(crates))
    origins = np.array([transforms.get_world_position(c) for c in crates])
    assert np.all(np.abs(origins[:, :2]) <= 0.25) and np.allclose(origins[:, 2], 0)


def test_no_collision_prims_are_avoided():
    floor = rep.functional.create.plane(scale=(2, 2, 1))
    wall = rep.functional.create.cube(scale=(1.0, 2.0, 1.0), position=(-0.5, 0, 0))   # covers the left half
    crates = rep.functional.create_batch.cube(count=6, scale=0.2)
    scatter_2d(crates, floor, no_collision_prims=[wall], check_for_collisions=True, rng=rng(2))
    boxes = world_boxes(crates)
    assert np.all(boxes[:, 0] >= -1e-6)                                     # all on the free right half
    assert overlapping_pairs(boxes) == []


def test_offset_is_along_the_surface_normal_of_a_tilted_mesh_surface():
    disk = rep.functional.create.disk(rotation=(90, 0, 0), position=(0, 0, 1))          # normal along -Y
    cubes = rep.functional.create_batch.cube(count=8, scale=0.05)
    scatter_2d(cubes, disk, offset=0.2, rng=rng(3))
    origins = np.array([transforms.get_world_position(c) for c in cubes])
    assert np.allclose(np.abs(origins[:, 1]), 0.2)
    assert np.all(np.hypot(origins[:, 0], origins[:, 2] - 1) <= 0.5 + 1e-9)


def test_sampling_is_uniform_by_area():
    small = rep.functional.create.plane(scale=(1, 1, 1), position=(-5, 0, 0))
    large = rep.functional.create.plane(scale=(3, 1, 1), position=(5, 0, 0))      # three times the area
    ball = rep.functional.create.sphere(scale=2, position=(0, 10, 0))              # area 4π
    surface = surface_of([small, large, ball])
    points, _ = sample_surface(surface, 40_000, np.random.default_rng(11))
    on_small = np.sum(points[:, 0] < -3)
    on_large = np.sum(points[:, 0] > 3)
    on_ball = len(points) - on_small - on_large
    areas = np.array([1.0, 3.0, surface.area - 4.0])
    assert surface.area - 4.0 == pytest.approx(4 * np.pi, rel=0.01)         # tessellated sphere ~ exact area
    chi = stats.chisquare([on_small, on_large, on_ball], areas / areas.sum() * len(points))
    assert chi.pvalue > 1e-3
    # Within the large plane: x uniform over [3.5, 6.5], y over [-0.5, 0.5].
    xs = points[points[:, 0] > 3][:, 0]
    assert stats.kstest(xs, stats.uniform(loc=3.5, scale=3).cdf).pvalue > 1e-3
    # On the sphere: z uniform over [-1, 1] (Archimedes), so area-uniform.
    zs = points[(np.abs(points[:, 0]) < 2)][:, 2]
    assert stats.kstest(zs, stats.uniform(loc=-1, scale=2).cdf).pvalue > 1e-3


def test_scatter_2d_is_deterministic_for_a_seed():
    floor = rep.functional.create.plane(scale=(4, 4, 1))
    cubes = rep.functional.create_batch.cube(count=5, scale=0.3)
    scatter_2d(cubes, floor, check_for_collisions=True, rng=rng(9))
    first = [transforms.get_world_position(c).tolist() for c in cubes]
    scatter_2d(cubes, floor, check_for_collisions=True, rng=rng(9))
    assert [transforms.get_world_position(c).tolist() for c in cubes] == first


def test_crowded_scatter_raises_with_the_count_that_fits_and_leaves_the_stage_unchanged():
    floor = rep.functional.create.plane(scale=(1, 1, 1), name="Small")
    crates = rep.functional.create_batch.cube(count=12, scale=0.4, position=(9, 9, 9))
    with pytest.raises(ValueError, match=r"could fit only (\d+) of 12 prims in /Small.*10000 attempts") as err:
        scatter_2d(crates, floor, check_for_collisions=True, rng=rng(0))
    fitted = int(err.value.args[0].split("only ")[1].split(" of")[0])
    assert 4 <= fitted < 12          # origins anywhere in 1x1, boxes 0.4 wide: at most a 3x3 packing region
    assert all(transforms.get_world_position(c).tolist() == [9, 9, 9] for c in crates)


def test_workflow_02_retry_pattern_scatters_fewer_after_a_value_error():
    plane = rep.functional.create.plane(scale=(1.08, 0.72, 1), position=(0, 0, 0.14), visible=False)
    boxes = rep.functional.create_batch.cube(count=12, scale=(0.4, 0.3, 0.3))
    while True:
        try:
            scatter_2d(boxes, plane, offset=0.15, check_for_collisions=True, rng=rng(5))
            break
        except ValueError:
            rep.stage.get_stage().RemovePrim(boxes.pop().GetPath())
    assert 1 <= len(boxes) < 12 and overlapping_pairs(world_boxes(boxes)) == []


def test_scatter_onto_prims_without_a_surface_is_a_clear_error():
    empty = rep.functional.create.xform(name="Nothing")
    cam = rep.functional.create.camera(name="Cam")
    cube = rep.functional.create.cube()
    for target in (empty, cam):
        with pytest.raises(ValueError, match=rf"{target.GetPath()} .* has no surface to scatter on"):
            scatter_2d(cube, target)
    with pytest.raises(ValueError, match="has no volume to scatter in"):
        scatter_3d(cube, rep.functional.create.plane(name="Flat"))
    with pytest.raises(ValueError, match="offset must be a finite number"):
        scatter_2d(cube, rep.functional.create.plane(name="P"), offset=float("nan"))
    with pytest.raises(ValueError, match="extents must be"):
        scatter_2d(cube, "/P", extents=[[1, 2]])


def test_extents_limit_where_origins_land():
    floor = rep.functional.create.plane(scale=(4, 4, 1))
    cubes = rep.functional.create_batch.cube(count=20, scale=0.05)
    scatter_2d(cubes, floor, extents=((0.5, None, None), (1.5, -1.0, None)), rng=rng(6))   # Replicator's min/max_samp
    origins = np.array([transforms.get_world_position(c) for c in cubes])
    assert np.all((origins[:, 0] >= 0.5) & (origins[:, 0] <= 1.5) & (origins[:, 1] <= -1.0))
    with pytest.raises(ValueError, match="extents need min <= max"):
        scatter_2d(cubes, floor, extents=((1, 0, 0), (0, 1, 1)))
    with pytest.raises(ValueError, match="could fit only 0 of 20"):
        scatter_2d(cubes, floor, extents=((10, 10, None), (11, 11, None)), rng=rng(1))   # off the surface


def test_scatter_3d_samples_inside_minus_excluded_and_keeps_bounds_inside():
    room = rep.functional.create.cube(scale=2, visible=False, name="Room")
    pillar = rep.functional.create.cylinder(scale=(0.8, 0.8, 2), visible=False, name="Pillar")
    balls = rep.functional.create_batch.sphere(count=15, scale=0.2)
    scatter_3d(balls, room, volume_excl_prims=[pillar], check_for_collisions=True, rng=rng(8))
    boxes = world_boxes(balls)
    assert np.all(boxes[:, :3] >= -1 - 1e-9) and np.all(boxes[:, 3:] <= 1 + 1e-9)      # inside the room
    origins = (boxes[:, :3] + boxes[:, 3:]) / 2
    assert np.all(np.hypot(origins[:, 0], origins[:, 1]) > 0.4)                          # outside the pillar
    assert overlapping_pairs(boxes) == []


def test_scatter_3d_is_uniform_in_a_sphere_and_handles_mesh_volumes():
    ball = rep.functional.create.sphere(scale=2, name="Ball")
    vol = Volume(ball)
    from graphsdg.sim.placement import sample_volumes
    pts = sample_volumes([vol], 20_000, np.random.default_rng(2))
    r = np.linalg.norm(pts, axis=1)
    assert r.max() <= 1.0
    assert stats.kstest(r ** 3, stats.uniform().cdf).pvalue > 1e-3        # uniform in volume: r³ ~ U(0, 1)
    torus = rep.functional.create.torus(name="Ring", scale=2)              # major 0.75, minor 0.25
    inside = Volume(torus).contains(np.array([[0.75, 0, 0], [0, 0, 0], [0, 0.75, 0.2], [1.1, 0, 0]]))
    assert inside.tolist() == [True, False, True, False]


def test_scatter_3d_raises_when_nothing_fits():
    box = rep.functional.create.cube(scale=0.5, name="Tiny")
    big = rep.functional.create.cube(scale=1.0, name="Big")
    with pytest.raises(ValueError, match=r"scatter_3d could fit only 0 of 1 prims in /Tiny"):
        scatter_3d(big, box, rng=rng(0))
    with pytest.raises(ValueError, match="resolution_scaling must be a positive number"):
        scatter_3d(big, box, resolution_scaling=0)
