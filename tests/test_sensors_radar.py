"""Radar detections against analytic truth: range, angles, radial velocity of moving bodies, bad input."""
from __future__ import annotations

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.engine.runtime import runtime
from graphsdg.sensors.generic_model_output import Modality, decode
from graphsdg.sensors.lidar_profile import LidarProfileError

RADAR = {"omni:sensor:WpmDmat:horizontalFovDeg": 40.0, "omni:sensor:WpmDmat:verticalFovDeg": 10.0,
         "omni:sensor:WpmDmat:raysPerDegree": 2.0, "omni:sensor:WpmDmat:auxOutputType": "BASIC",
         "omni:sensor:WpmDmat:azimuthResolutionDeg": 4.0, "omni:sensor:WpmDmat:elevationResolutionDeg": 5.0,
         "omni:sensor:WpmDmat:rangeResolutionM": 0.5}


def radar_scene(velocity):
    rep.functional.physics.create_physics_scene(gravity_magnitude=0.0)
    target = rep.functional.create.cube(position=(10.5, 0, 0), scale=(1.0, 2.0, 2.0), name="Target")
    rep.functional.physics.apply_rigid_body(target, disableGravity=True)
    radar = rep.functional.create.omni_radar(position=(0, 0, 0), name="Radar", **RADAR)
    rp = rep.create.render_product(radar, (1, 1))
    gmo = rep.annotators.get("GenericModelOutput").attach(rp)
    runtime().sim.set_body_velocity(str(target.GetPath()), linear=velocity)
    return target, gmo


@pytest.mark.parametrize("velocity", [(-4.0, 0.0, 0.0), (2.0, 3.0, 0.0), (0.0, 0.0, 5.0)])
def test_radial_velocity_is_the_bodys_velocity_along_the_ray(velocity):
    target, gmo = radar_scene(velocity)
    rep.orchestrator.step(delta_time=0)
    out = decode(gmo.get_data())
    assert out.modality == Modality.RADAR and out.numElements > 0
    az, el = np.radians(out.x), np.radians(out.y)
    u = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    # a cell's detection is the cross-section-weighted mean over its rays: within the cell the projection
    # changes by at most |v| times the cell's angular size
    expected = u @ np.asarray(velocity)
    np.testing.assert_allclose(out.rv_ms, expected, atol=np.linalg.norm(velocity) * np.radians(3.0))
    assert np.all(np.abs(out.z * np.cos(el) * np.cos(az) - 10.0) < 0.05)   # on the face x = 10


def test_radial_velocity_of_a_head_on_target_is_exact_on_boresight():
    target, gmo = radar_scene((-6.0, 0.0, 0.0))
    rep.orchestrator.step(delta_time=0)
    out = decode(gmo.get_data())
    centre = np.argmin(np.abs(out.x) + np.abs(out.y))
    cos_angle = np.cos(np.radians(out.x[centre])) * np.cos(np.radians(out.y[centre]))
    assert out.rv_ms[centre] == pytest.approx(-6.0 * cos_angle, abs=0.05)


def test_static_scene_has_zero_doppler_and_detections_sorted_by_azimuth():
    target, gmo = radar_scene((0.0, 0.0, 0.0))
    rep.orchestrator.step(delta_time=0)
    out = decode(gmo.get_data())
    assert np.all(out.rv_ms == 0) and np.all(np.diff(out.x) >= 0)
    assert out.maxRangeM == pytest.approx(200.0) and out.maxAzRad == pytest.approx(np.radians(20.0))


def test_bad_radar_settings_fail_naming_them():
    radar = rep.functional.create.omni_radar(name="Radar")
    radar.GetAttribute("omni:sensor:WpmDmat:minRangeM").Set(-1.0)
    rp = rep.create.render_product(radar, (1, 1))
    rep.annotators.get("GenericModelOutput").attach(rp)
    with pytest.raises(LidarProfileError, match=r"radar /Radar: .*minRangeM=-1.0"):
        rep.orchestrator.step(delta_time=0)
    with pytest.raises(ValueError, match="has no attribute 'omni:sensor:WpmDmat:maxRange'"):
        rep.functional.create.omni_radar(**{"omni:sensor:WpmDmat:maxRange": 3.0})
