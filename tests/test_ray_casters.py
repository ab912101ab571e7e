"""The ray casters against MuJoCo's own ``mj_ray``: every geom type, masks, moving bodies, rescaled meshes.

The CPU caster runs everywhere. The Warp caster runs on Warp's CPU device where the ``gpu`` extra is installed
(Python >= 3.12); its world-space scene (meshes as one triangle mesh, primitives in a BVH) must give the same
hits as ``mj_ray``, within float32.
"""
from __future__ import annotations

import importlib.util
import sys

import mujoco
import numpy as np
import pytest

import graphsdg  # noqa: F401  (selects the GL backend before MuJoCo renders)
from graphsdg.sensors.ray_caster import CpuRayCaster, drawn_group_mask
from graphsdg.sensors.scene_motion import GeomMotion

CUBE = " ".join(f"{x} {y} {z}" for x in (-.3, .3) for y in (-.3, .3) for z in (-.3, .3))
SCENE = f"""<mujoco><option gravity="0 0 0"/>
<asset><mesh name="tet" vertex="0 0 0 1 0 0 0 1 0 0 0 1" scale="0.5 0.5 0.5"/><mesh name="cube" vertex="{CUBE}"/>
<material name="clear" rgba="1 1 1 0"/></asset>
<worldbody><geom type="plane" size="10 10 .1"/>
<body pos="2 0 0.5" euler="10 20 30"><freejoint/><geom type="box" size=".3 .4 .5"/></body>
<body pos="-2 0 0.5"><geom type="sphere" size=".4"/></body>
<body pos="0 2 0.5"><geom type="mesh" mesh="tet"/></body>
<body pos="0 -2 0.5" euler="0 0 45"><freejoint/><geom type="mesh" mesh="cube"/></body>
<body pos="1.5 1.5 0.5"><geom type="capsule" size=".2 .3"/></body>
<body pos="-1.5 -1.5 0.5"><geom type="cylinder" size=".2 .3"/></body>
<body pos="-1.5 1.5 0.5"><geom type="ellipsoid" size=".2 .3 .4"/></body>
<body pos="1.5 -1.5 0.5"><geom type="box" size=".2 .3 .4" group="4"/></body>
<body pos="0 0 3"><geom type="box" size=".5 .5 .4" rgba="1 1 1 0"/></body>
<body pos="0 0 -3"><geom type="box" size=".5 .5 .4" material="clear"/></body>
</worldbody></mujoco>"""


def scene(velocities: bool = False):
    model = mujoco.MjModel.from_xml_string(SCENE)
    data = mujoco.MjData(model)
    if velocities:
        data.qvel[:6] = (0.0, 0.0, 0.0, 0.0, 0.0, 4.0)      # the box spins about z
        data.qvel[6:9] = (0.0, 3.0, 0.0)                    # the mesh cube moves along y
    mujoco.mj_forward(model, data)
    return model, data


def rays(count: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    directions = rng.normal(size=(count, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    origins = np.array([0.0, 0.0, 0.5]) + rng.normal(scale=0.1, size=(count, 3))
    return origins, directions


def mj_ray_truth(model, data, origins, directions, group=None):
    group = drawn_group_mask() if group is None else group
    geom = np.zeros(1, np.int32)
    out = [(mujoco.mj_ray(model, data, o, d, group, 1, -1, geom), int(geom[0])) for o, d in zip(origins, directions)]
    return np.array([o[0] for o in out]), np.array([o[1] for o in out])


def test_cpu_caster_sees_bodies_away_from_the_origin():
    """``mj_multiRay`` culls each body by a sphere about its inertial centre: the caster's scratch data must
    hold those centres, or rays pass through bodies away from the world origin."""
    model, data = scene()
    origins, directions = rays(3000)
    dist, geom = mj_ray_truth(model, data, origins, directions)
    hits = CpuRayCaster(threads=2).cast(model, data, origins, directions, np.zeros(len(origins)), cutoff=50.0)
    np.testing.assert_array_equal(hits.geom, geom)
    np.testing.assert_allclose(hits.distance, dist, atol=1e-9)
    assert set(geom.tolist()) >= {0, 1, 2, 3, 4, 5, 6, 7}     # every drawn geom type was hit
    assert not np.isin(geom, [8, 9, 10]).any()                  # excluded group, transparent geom and material


def test_cpu_caster_moves_body_culling_spheres_with_their_bodies():
    """Rays fired earlier see a moving body where it was; the body's culling sphere moves with it."""
    model, data = scene(velocities=True)
    motion = GeomMotion.of(model, data)
    origins, directions = rays(2000, seed=1)
    dt = np.repeat([-0.1, -0.05, 0.0], [700, 700, 600])
    hits = CpuRayCaster(threads=1).cast(model, data, origins, directions, dt, motion=motion, cutoff=50.0)
    for when in (-0.1, -0.05, 0.0):
        posed = mujoco.MjData(model)
        posed.qpos[:], posed.qvel[:] = data.qpos, data.qvel
        mujoco.mj_forward(model, posed)
        xpos, xmat = motion.poses_at(data, when)
        posed.geom_xpos[motion.geoms], posed.geom_xmat[motion.geoms] = xpos, xmat
        bodies = model.geom_bodyid[motion.geoms]
        posed.xipos[bodies] = motion.points_at(data.xipos[bodies], when)
        pick = dt == when
        dist, geom = mj_ray_truth(model, posed, origins[pick], directions[pick])
        np.testing.assert_array_equal(hits.geom[pick], geom)
        np.testing.assert_allclose(hits.distance[pick], dist, atol=1e-9)


def _warp_missing() -> str | None:
    if sys.version_info < (3, 12):
        return "MuJoCo Warp needs Python >= 3.12"
    for name in ("warp", "mujoco_warp"):
        if importlib.util.find_spec(name) is None:
            return f"{name} is not installed (the gpu extra)"
    return None


needs_warp = pytest.mark.skipif(_warp_missing() is not None, reason=str(_warp_missing()))


def _warp_caster():
    from graphsdg.sensors.warp_rays import WarpRayCaster

    import warp as wp

    wp.init()
    return WarpRayCaster(device="cuda:0" if wp.get_cuda_device_count() else "cpu")


@needs_warp
def test_warp_world_scene_matches_mj_ray():
    model, data = scene()
    origins, directions = rays(4000, seed=2)
    dist, geom = mj_ray_truth(model, data, origins, directions)
    caster = _warp_caster()
    hits = caster.cast(model, data, origins, directions, np.zeros(len(origins)), cutoff=50.0)
    assert caster._scene is not None                      # primitives and meshes: the world-space scene
    np.testing.assert_array_equal(hits.geom, geom)
    np.testing.assert_allclose(hits.distance, dist, atol=1e-4)
    # a narrower group mask, and a cutoff that drops far hits
    group = np.array([1, 0, 0, 0, 1, 0], dtype=np.uint8)
    dist, geom = mj_ray_truth(model, data, origins, directions, group)
    hits = caster.cast(model, data, origins, directions, np.zeros(len(origins)), cutoff=2.0, geomgroup=group)
    geom = np.where(dist > 2.0, -1, geom)
    np.testing.assert_array_equal(hits.geom, geom)
    assert (hits.geom == 8).any()


@needs_warp
def test_warp_world_scene_follows_moving_bodies_and_rescaled_meshes():
    model, data = scene(velocities=True)
    motion = GeomMotion.of(model, data)
    origins, directions = rays(2000, seed=3)
    dt = np.repeat([-0.1, 0.0], [1000, 1000])
    caster = _warp_caster()
    cpu = CpuRayCaster(threads=1).cast(model, data, origins, directions, dt, motion=motion, cutoff=50.0)
    gpu = caster.cast(model, data, origins, directions, dt, motion=motion, cutoff=50.0)
    np.testing.assert_array_equal(gpu.geom, cpu.geom)
    np.testing.assert_allclose(gpu.distance, cpu.distance, atol=1e-4)
    # the tetrahedron grows in place (as graphsdg's rescales do) and is seen at its new size: the truth is a
    # model compiled with the bigger tetrahedron, its body moved so that the mesh frames coincide
    mesh = int(model.geom_dataid[3])
    v0, nv = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    model.mesh_vert[v0:v0 + nv] *= 1.5
    centre = data.geom_xpos[3] - np.array([0.0, 2.0, 0.5])
    body = np.array([0.0, 2.0, 0.5]) - 0.5 * centre
    grown_xml = SCENE.replace('scale="0.5 0.5 0.5"', 'scale="0.75 0.75 0.75"').replace(
        '<body pos="0 2 0.5">', '<body pos="{} {} {}">'.format(*body.tolist()))
    truth_model = mujoco.MjModel.from_xml_string(grown_xml)
    truth_data = mujoco.MjData(truth_model)
    mujoco.mj_forward(truth_model, truth_data)
    np.testing.assert_allclose(truth_data.geom_xpos[3], data.geom_xpos[3], atol=1e-12)
    still = np.zeros(len(origins))
    caster.cast(model, data, origins, directions, still, cutoff=50.0)
    data.qvel[:] = 0.0
    mujoco.mj_forward(model, data)
    truth_data.qpos[:] = data.qpos
    mujoco.mj_forward(truth_model, truth_data)
    dist, geom = mj_ray_truth(truth_model, truth_data, origins, directions)
    grown = caster.cast(model, data, origins, directions, still, cutoff=50.0, mesh_stamps=np.array([1, 0]))
    assert (geom == 3).sum() > 10
    np.testing.assert_array_equal(grown.geom, geom)
    np.testing.assert_allclose(grown.distance, dist, atol=1e-4)


TWO_SIDED = """<mujoco><asset>
<mesh name="plate" inertia="shell" vertex="0 -1 -1  0 1 -1  0 1 1  0 -1 1  -0.01 0 0"
      face="0 1 2  0 2 3  0 2 1  0 3 2"/>
</asset><worldbody><body pos="3 0 1"><geom type="mesh" mesh="plate"/></body></worldbody></mujoco>"""


@needs_warp
def test_warp_world_scene_sees_two_sided_surfaces_from_both_sides():
    """A plate made of the same triangles wound both ways: from either side, the front-facing copy is hit
    at the plate's distance (a back face at the same distance must not hide it)."""
    model = mujoco.MjModel.from_xml_string(TWO_SIDED)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rng = np.random.default_rng(4)
    count = 500
    targets = np.column_stack([np.full(count, 3.0), rng.uniform(-0.9, 0.9, count), rng.uniform(0.1, 1.9, count)])
    origins = np.where(np.arange(count)[:, None] % 2 == 0, [[0.0, 0.0, 1.0]], [[6.0, 0.0, 1.0]])
    directions = targets - origins
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    dist, geom = mj_ray_truth(model, data, origins, directions)
    assert (geom == 0).all()
    hits = _warp_caster().cast(model, data, origins, directions, np.zeros(count), cutoff=50.0)
    np.testing.assert_array_equal(hits.geom, geom)
    np.testing.assert_allclose(hits.distance, dist, atol=1e-5)
