"""Ray-cast sensors see meshes rescaled in place as the same meshes compiled at that scale."""
from __future__ import annotations

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.sensors.lidar_profile import EmitterState, LidarProfile, author_lidar_profile
from graphsdg.sensors.lidar_scan import LidarScanner

GRID = EmitterState.grid((-6.0, 6.0), 25, (6.0, -6.0), 25, 0)


def _scan_of_torus(scale: float, rescale_from: float | None) -> np.ndarray:
    """Ranges (grid order, 0 for no return) of a lidar ~5 m from a torus mesh of ``scale``: built at that scale,
    or built at ``rescale_from`` and rescaled in place (no recompile)."""
    stage = rep.stage.new_stage()
    built = scale if rescale_from is None else rescale_from
    torus = rep.functional.create.torus(position=(5.0, 0, 0), rotation=(90, 0, 0), scale=built, as_mesh=True,
                                        name="Torus")
    lidar = rep.functional.create.omni_lidar(position=(0.0, 0.0071, 0.0133), name="Lidar")   # off the mesh's edges
    author_lidar_profile(lidar, LidarProfile(name="grid", scan_type="SOLID_STATE", scan_rate_hz=10,
                                             firing_rate_hz=10, near_range_m=0.1, emitter_states=(GRID,)))
    sim = runtime().sim
    sim.ensure_compiled()
    compiles = sim.stats["compiles"]
    if rescale_from is not None:
        LidarScanner("/Lidar").capture(sim, stage, 0.0)      # the trees are read once before the rescale
        rep.functional.modify.pose([torus], scale_value=[(scale, scale, scale)])
        sim.sync_dirty_prims()
        sim.forward()
        assert sim.stats["compiles"] == compiles, "the rescale should be applied in place"
    scan = LidarScanner("/Lidar").capture(sim, stage, 0.0)
    ranges = np.zeros(GRID.count)
    ranges[scan.returns.emitter] = scan.returns.range_m
    return ranges


@pytest.mark.parametrize("scale,start", [(0.5, 1.0), (1.6, 1.0), (0.7, 1.3)])
def test_rescaled_mesh_returns_match_a_mesh_built_at_that_scale(scale: float, start: float) -> None:
    rebuilt = _scan_of_torus(scale, None)
    rescaled = _scan_of_torus(scale, start)
    assert (rebuilt > 0).sum() >= 20
    np.testing.assert_array_equal(rescaled > 0, rebuilt > 0)
    np.testing.assert_allclose(rescaled, rebuilt, atol=1e-5)


@pytest.mark.parametrize("module", ["mesh_bounds", "scan_pattern", "ray_caster", "scene_motion", "sensor_pose",
                                    "surface_materials", "generic_model_output", "scan_outputs", "lidar_scan",
                                    "radar_scan", "ray_backend", "stereo_depth"])
def test_sensor_room_examples(module: str) -> None:
    import doctest
    import importlib

    result = doctest.testmod(importlib.import_module(f"graphsdg.sensors.{module}"), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
