"""Compat mode's Kit experiences: ``$EXP_PATH`` names graphsdg's, ``SimulationApp(experience=...)`` applies one."""
from __future__ import annotations

import os

import pytest

from graphsdg.base import settings_store as settings
from graphsdg.compat import experiences, isaac


@pytest.fixture
def compat(monkeypatch):
    monkeypatch.delenv("EXP_PATH", raising=False)
    isaac.install()
    yield
    isaac.uninstall()


def test_exp_path_names_the_experiences_scripts_launch(compat):
    from isaacsim import SimulationApp
    path = f'{os.environ["EXP_PATH"]}/isaacsim.exp.base.zero_delay.kit'
    app = SimulationApp({"headless": True}, experience=path)
    assert app.config["experience"] == path
    for name in ("isaacsim.exp.base.kit", "isaacsim.exp.base.python.kit"):
        assert os.path.isfile(os.path.join(os.environ["EXP_PATH"], name))


def test_exp_path_is_taken_back_and_an_existing_one_kept(monkeypatch):
    monkeypatch.delenv("EXP_PATH", raising=False)
    isaac.install()
    isaac.uninstall()
    assert "EXP_PATH" not in os.environ
    monkeypatch.setenv("EXP_PATH", "/opt/isaac/apps")
    isaac.install()
    try:
        assert os.environ["EXP_PATH"] == "/opt/isaac/apps"
    finally:
        isaac.uninstall()
    assert os.environ["EXP_PATH"] == "/opt/isaac/apps"


def test_an_experience_settings_table_reaches_carb_settings(compat, tmp_path):
    from isaacsim import SimulationApp
    kit = tmp_path / "mine.kit"
    kit.write_text('[settings]\nomni.replicator.RTSubframes = 3\n"graphsdg".render.msaaSamples = 1\n'
                   '[settings.app.exts.folders]\n"++" = ["${app}/exts"]\n')
    try:
        SimulationApp({}, experience=str(kit))
        assert settings.get("/omni/replicator/RTSubframes") == 3
        assert settings.get("/graphsdg/render/msaaSamples") == 1
        assert settings.get("/app/exts/folders") is None          # Kit's list appends are not settings
    finally:
        settings.reset()
    assert experiences.flat_settings({"a": {"b": 1, "++": [2]}}) == {"/a/b": 1}


def test_a_missing_or_broken_experience_fails_naming_it(compat, tmp_path):
    from isaacsim import SimulationApp
    with pytest.raises(FileNotFoundError, match="nowhere.kit"):
        SimulationApp({}, experience=str(tmp_path / "nowhere.kit"))
    bad = tmp_path / "bad.kit"
    bad.write_text("[settings\n")
    with pytest.raises(ValueError, match="bad.kit"):
        SimulationApp({}, experience=str(bad))
