"""A one-colour sky filled in behind the geometry gives MuJoCo's skybox image, and is used only then."""
from __future__ import annotations

import mujoco
import numpy as np
import pytest

import graphsdg as rep
from graphsdg.render import rasterizer, sky
from graphsdg.engine.runtime import runtime

W = H = 96


def _cubes_under_a_dome(opacity: float | None = None):
    """Three lit cubes (one with ``opacity``) in front of a grey-blue dome; returns the rgb annotator."""
    rep.functional.create.xform(name="World")
    rep.functional.create.distant_light(intensity=2500, parent="/World", rotation=(30, 20, 0))
    rep.functional.create.dome_light(intensity=500, color=(0.6, 0.7, 0.9), parent="/World")
    cubes = [rep.functional.create.cube(parent="/World", name=f"Cube{i}", position=(x, 0, z), rotation=(20, 35, 10 * i),
                                        scale=0.8) for i, (x, z) in enumerate([(-1.2, 0.3), (0.2, -0.4), (1.3, 0.6)])]
    rep.functional.modify.display_color(cubes, [(0.9, 0.2, 0.1), (0.1, 0.8, 0.2), (0.2, 0.3, 0.9)])
    if opacity is not None:
        rep.functional.modify.attribute(cubes[1], "primvars:displayOpacity", [opacity], "float[]")
    cam = rep.functional.create.camera(position=(0, -6, 0.5), look_at=(0, 0, 0), parent="/World")
    rgb = rep.annotators.get("rgb")
    rgb.attach(rep.create.render_product(cam, (W, H)))
    return rgb


def _render(rgb) -> np.ndarray:
    rep.orchestrator.step(delta_time=0)
    return rgb.get_data()[..., :3].astype(int)


@pytest.fixture(autouse=True)
def _count_from_zero():
    runtime().rasterizer.skies_filled = 0   # the renderer outlives each test's stage


def _filled() -> int:
    """Colour renders that filled the sky in since the test began."""
    return runtime().rasterizer.skies_filled


@pytest.mark.parametrize("msaa", [4, 0])
def test_filled_sky_is_the_skybox_image(monkeypatch, msaa):
    rep.settings.set("/graphsdg/render/msaaSamples", msaa)
    rgb = _cubes_under_a_dome()
    filled = _render(rgb)
    assert _filled() == 1
    monkeypatch.setattr(rasterizer.sky, "fill_is_exact", lambda *a: False)   # MuJoCo's skybox instead
    drawn = _render(rgb)
    assert _filled() == 1
    assert (filled == drawn).all()                     # anti-aliased edges included
    background = runtime().rasterizer._flat_sky
    assert background is not None
    assert (filled[0, 0] == np.rint(np.array(background) * 255)).all()     # the sky's own bytes
    assert (filled[..., 0] > filled[..., 2] + 100).sum() > 50              # the red cube is there, lit
    assert not (filled.sum(-1) == 0).any()                                 # no unfilled (black) pixel


def test_a_transparent_geom_keeps_the_skybox_draw(monkeypatch):
    rgb = _cubes_under_a_dome(opacity=0.4)
    kept = _render(rgb)
    assert _filled() == 0
    # what the rule prevents: a fill after mjr_render paints the sky over the transparent cube
    monkeypatch.setattr(rasterizer.sky, "fill_is_exact", lambda *a: True)
    forced = _render(rgb)
    assert _filled() == 1
    assert np.abs(forced - kept).max() > 10


def test_a_dome_colour_edit_changes_the_composited_sky():
    rgb = _cubes_under_a_dome()
    before = _render(rgb)[0, 0]
    dome = [p for p in rep.stage.get_stage().Traverse() if p.GetTypeName() == "DomeLight"][0]
    rep.functional.modify.attribute(dome, "inputs:color", (0.9, 0.5, 0.2))
    after = _render(rgb)[0, 0]
    assert _filled() == 2
    assert after[0] > after[2] + 50 and before[2] > before[0]


def _model(xml_body: str, skybox: str = '<texture type="skybox" builtin="flat" rgb1=".2 .4 .6" rgb2=".2 .4 .6" '
                                          'width="8" height="8"/>') -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(f"<mujoco><asset>{skybox}</asset><worldbody>{xml_body}</worldbody></mujoco>")


def test_uniform_sky_reads_the_texture_bytes():
    model = _model('<geom type="box" size=".1 .1 .1"/>')
    r, g, b = sky.uniform_sky(model)
    assert (round(r * 255), round(g * 255), round(b * 255)) == tuple(model.tex_data[:3])
    gradient = _model("", '<texture type="skybox" builtin="gradient" rgb1=".2 .4 .6" rgb2="0 0 0" '
                          'width="8" height="8"/>')
    assert sky.uniform_sky(gradient) is None
    assert sky.uniform_sky(_model("", "")) is None


@pytest.mark.parametrize("body, exact", [
    ('<geom type="box" size=".1 .1 .1"/>', True),
    ('<geom type="box" size=".1 .1 .1" rgba="1 0 0 .5"/>', False),
    ('<geom type="box" size=".1 .1 .1" rgba="1 0 0 .5" group="5"/>', True),        # in an undrawn group
    ('<geom type="plane" size="0 0 .1"/>', False),                                  # infinite: horizon haze
    ('<geom type="plane" size="2 2 .1"/>', True),
])
def test_fill_is_exact(body, exact):
    model = _model(body)
    assert sky.fill_is_exact(model, model.geom_group != 5) is exact
