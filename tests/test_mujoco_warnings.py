"""MuJoCo's warnings are logged once each, never written to MUJOCO_LOG.TXT in the working folder."""
from __future__ import annotations

import logging
import os

import mujoco

import graphsdg.sim.compiler  # noqa: F401  (installs the handler)


def test_unstable_simulation_warning_is_logged_not_written(tmp_path, monkeypatch, caplog):
    monkeypatch.chdir(tmp_path)
    model = mujoco.MjModel.from_xml_string("<mujoco><worldbody><body><freejoint/><geom size='.1'/></body>"
                                           "</worldbody></mujoco>")
    data = mujoco.MjData(model)
    with caplog.at_level(logging.WARNING, logger="graphsdg.mujoco"):
        for _ in range(2):
            data.qvel[:] = float("nan")
            mujoco.mj_step(model, data)
    assert data.warning[mujoco.mjtWarning.mjWARN_BADQVEL].number >= 1
    messages = [r.getMessage() for r in caplog.records if r.name == "graphsdg.mujoco"]
    assert len(messages) == 1 and "Nan, Inf or huge value" in messages[0]
    assert not os.path.exists(tmp_path / "MUJOCO_LOG.TXT")
