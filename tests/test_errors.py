"""Every mistake in docs/errors.md raises exactly the error and message the table gives."""
from __future__ import annotations

import os
import warnings

import numpy as np
import pytest
from pxr import UsdGeom

import graphsdg as rep
from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.graph.registry import NodeRegistry
from graphsdg.io import backends
from error_cases import CASES, DOC, CommandFailed, cli, render_markdown

# The registries as graphsdg ships them (collected before any test registers its own writers, annotators,
# backends or nodes): messages that list known names list these.
_REGISTRIES = [(rep.WriterRegistry, "_writers"), (AnnotatorRegistry, "_specs"), (AnnotatorRegistry, "_aliases"),
               (AnnotatorRegistry, "_aovs"), (NodeRegistry, "_types"), (backends, "_registry")]
_BUILT_IN = [dict(getattr(owner, name)) for owner, name in _REGISTRIES]


@pytest.fixture
def built_in_registries():
    saved = [dict(getattr(owner, name)) for owner, name in _REGISTRIES]
    for (owner, name), shipped in zip(_REGISTRIES, _BUILT_IN):
        table = getattr(owner, name)
        table.clear()
        table.update(shipped)
    yield
    for (owner, name), current in zip(_REGISTRIES, saved):
        table = getattr(owner, name)
        table.clear()
        table.update(current)


@pytest.fixture
def scratch(tmp_path):
    (tmp_path / "bad.usda").write_text("#usda 1.0\n( garbage here\n")
    (tmp_path / "notes.txt").write_text("not a USD file\n")
    (tmp_path / "broken.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"\x00\x00\x00\x0dIHDR" + b"\x00" * 4)
    return str(tmp_path)


def _scene():
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=600, parent="/World", name="Dome")
    cube = rep.functional.create.cube(parent="/World", name="Cube", semantics={"class": "cube"})
    cam = rep.functional.create.camera(position=(0, -4, 0), look_at=(0, 0, 0), parent="/World", name="Camera")
    rp = rep.create.render_product(cam, (32, 32))
    return {"cube": cube, "cam": cam, "rp": rp}


def _raised(code: str, namespace: dict) -> tuple[str, str]:
    """(error type name, message) of running ``code``; warnings count as errors of their category."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            exec(compile(code, "<case>", "exec"), namespace)
        except CommandFailed as exc:
            return f"exit {exc.code}", str(exc)
        except Exception as exc:   # noqa: BLE001 - the type is what is checked
            return type(exc).__name__, str(exc)
    mine = [w for w in caught if issubclass(w.category, UserWarning) and "graphsdg" in str(w.message)]
    if mine:
        return mine[0].category.__name__, str(mine[0].message)
    return "no error", ""


@pytest.mark.parametrize("case", CASES, ids=[f"{i + 1}-{c.area}-{c.mistake[:40]}" for i, c in enumerate(CASES)])
def test_mistake_is_answered_exactly(case, scratch, built_in_registries):
    namespace = {"rep": rep, "os": os, "np": np, "UsdGeom": UsdGeom, "tmp": scratch, "cli": cli, **_scene()}
    try:
        kind, message = _raised(case.code, namespace)
    finally:
        rep.graph.clear()
        rep.orchestrator.wait_until_complete() if case.error != "WriterError" else None
        rep.settings.reset()
    assert (kind, message) == (case.error, case.message.replace("<tmp>", scratch))


def test_at_least_forty_mistakes_across_the_api():
    assert len(CASES) >= 40
    areas = {c.area for c in CASES}
    assert {"functional", "graph", "annotators", "writers", "backends", "render products", "orchestrator",
            "settings", "stage", "physics", "cli", "assets"} <= areas
    assert len({(c.area, c.mistake) for c in CASES}) == len(CASES)


def test_docs_errors_md_is_generated_from_the_cases():
    with open(DOC, encoding="utf-8") as f:
        assert f.read() == render_markdown(), "docs/errors.md is stale: run python tests/error_cases.py"
