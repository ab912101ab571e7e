"""The session owns the process state: a replaced stage resets its stage pieces in the documented order, the
other pieces outlive the stage, and the rooms it took over keep no module-level state of their own."""
from __future__ import annotations

import ast
import doctest
import enum
import importlib
import inspect
import logging
import re
import types

import pytest

import graphsdg as rep
from graphsdg.base import settings_store
from graphsdg.engine import session as session_module
from graphsdg.engine.runtime import runtime
from graphsdg.engine.session import Session, session
from graphsdg.io.write_queue import get_write_queue
from graphsdg.physics.domain_randomization import randomization_targets
from graphsdg.physics.forces import apply_force_at_pos, pending
from graphsdg.sensors.scanners import scanners
from graphsdg.sim import physics_steps
from graphsdg.stage.context import stage_context
from graphsdg.stage.prims import structure_version

#: The modules whose state the session took over (the rooms migrated by issue 34's third item), and the rest of
#: the engine room and Replicator's face over it, which keep none.
MIGRATED = (
    "graphsdg.stage.context", "graphsdg.stage.prims", "graphsdg.render.attachments", "graphsdg.render.render_product",
    "graphsdg.render.motion_blur", "graphsdg.annotate.motion", "graphsdg.sensors.scanners",
    "graphsdg.sim.physics_steps", "graphsdg.base.settings_store", "graphsdg.base.profiling",
    "graphsdg.io.write_queue", "graphsdg.io.run_state", "graphsdg.io.frame_plan", "graphsdg.graph.current",
    "graphsdg.graph.scopes", "graphsdg.engine.runtime", "graphsdg.engine.state", "graphsdg.engine.session",
    "graphsdg.physics.forces", "graphsdg.physics.domain_randomization",
    "graphsdg.engine.capture", "graphsdg.engine.run_loop", "graphsdg.engine.frame_provider",
    "graphsdg.engine.progress", "graphsdg.graph.frame_provider", "graphsdg.orchestrator",
)

#: Upper-case module tables that are constants (filled once at import, only read after): the only mutable
#: module-level values the migrated rooms may hold outside the session.
CONSTANT_TABLES = {
    "graphsdg.sensors.scanners": {"SCANNER_TYPES"},
    "graphsdg.base.settings_store": {"KNOWN_KEYS", "VALIDATORS"},
    "graphsdg.physics.domain_randomization": {"ATTRIBUTES", "_ARTICULATION_TABLES"},
    "graphsdg.engine.runtime": {"NO_GRAPH"},
    "graphsdg.engine.frame_provider": {"NO_GRAPH"},
}

#: Values that hold no state: immutable ones, and the process-wide logging configuration.
STATELESS = (type(None), bool, int, float, complex, str, bytes, range, frozenset, tuple, re.Pattern,
             logging.Logger, enum.Enum)


def _dirty_every_stage_piece(tmp_path):
    """A stage on which every stage piece of the session holds something; returns what to check."""
    stage = rep.stage.new_stage()
    cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (32, 24))
    rgb = rep.annotators.get("rgb").attach(rp)
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=str(tmp_path / "out"), rgb=True)
    writer.attach(rp)
    rep.create.cube(position=(0, 0, 1))                      # a graph node: the current graph exists
    box = rep.functional.create.cube(position=(0, 0, 5), name="Box")
    rep.functional.physics.apply_rigid_body(box)
    rep.orchestrator.step()                                   # the runtime's simulation, a stage step
    rep.orchestrator.wait_until_complete()
    apply_force_at_pos("/Box", (0.0, 0.0, 1.0), (0.0, 0.0, 5.0))   # waits for the next physics step
    randomization_targets().register_simulation()
    lidar = stage.DefinePrim("/Lidar", "OmniLidar")
    lidar.ApplyAPI("OmniSensorGenericLidarCoreAPI")
    scanners.scanner(stage, "/Lidar")
    structure_version()
    return rp, rgb, writer


def _reset_now(clock_before: int) -> dict[str, bool]:
    """Whether each stage piece is reset (judged from its real state); ``clock_before``: the structure clock
    once the new stage was made (making it resyncs, which the clock counts too)."""
    rt = session.runtime
    targets = randomization_targets()
    return {
        "render_products": len(session.render_products) == 0,
        "attachments": len(session.attachments.writers) == 0 and len(session.attachments.annotators) == 0,
        "graph": session.graph.graph is None,
        "runtime": rt._sim is None and rt._render_scene is None,
        "engine_state": session.engine_state.stage_step == 0,
        "scanners": not scanners._scanners,
        "forces": pending() == [],
        "randomization_targets": targets.simulation is None and not targets.targets,
        "prim_structure": session.prim_structure.count == clock_before + 1,
    }


#: The documented order (graphsdg/engine/session.py, docs/design.md): the writers detach while the runtime still
#: holds the old stage's simulation and labels; the structure clock ticks last.
DOCUMENTED_ORDER = ("render_products", "attachments", "graph", "runtime", "engine_state", "scanners", "forces",
                    "randomization_targets", "prim_structure")


def test_the_reset_order_is_the_documented_one():
    assert Session.STAGE_RESETS == DOCUMENTED_ORDER


def test_a_replaced_stage_resets_every_stage_piece_in_the_documented_order(tmp_path, monkeypatch):
    rp, rgb, writer = _dirty_every_stage_piece(tmp_path)
    clock = [session.prim_structure.count]
    assert not any(_reset_now(clock[0]).values()), "a piece was clean before the stage was replaced"
    assert set(_reset_now(clock[0])) == set(Session.STAGE_RESETS)

    seen: list[tuple[str, dict[str, bool]]] = []
    for name in Session.STAGE_RESETS:
        part = getattr(session, name)
        reset = part.on_stage_replaced

        def recording(stage, name=name, reset=reset):
            if not seen:
                clock[0] = session.prim_structure.count
            seen.append((name, _reset_now(clock[0])))
            reset(stage)
        monkeypatch.setattr(part, "on_stage_replaced", recording)
    heard: list[dict[str, bool]] = []
    subscriber = lambda stage: heard.append(_reset_now(clock[0]))  # noqa: E731
    stage_context.subscribe_replaced(subscriber)
    try:
        rep.stage.new_stage()
    finally:
        stage_context.unsubscribe(subscriber)

    assert [name for name, _ in seen] == list(Session.STAGE_RESETS)
    for i, (name, state) in enumerate(seen):   # when a piece resets, exactly the pieces before it are reset
        done = set(Session.STAGE_RESETS[:i])
        assert {n for n, is_reset in state.items() if is_reset} == done, f"when {name!r} was reset"
    assert heard == [dict.fromkeys(Session.STAGE_RESETS, True)]   # subscribers hear of it after every reset
    assert rp.destroyed and rgb not in session.attachments.annotators and writer not in session.attachments.writers


def test_pieces_of_the_process_outlive_the_stage(tmp_path):
    rep.stage.new_stage()
    kept = settings_store.get("/omni/replicator/RTSubframes")
    settings_store.set("/omni/replicator/RTSubframes", 3)
    seen: list[float] = []
    handle = physics_steps.subscribe(False, 0, seen.append)
    queue = get_write_queue()
    before = {name: getattr(session, name) for name in Session.PROCESS_PARTS}
    try:
        rep.stage.new_stage()
        assert {name: getattr(session, name) for name in Session.PROCESS_PARTS} == before
        assert settings_store.get("/omni/replicator/RTSubframes") == 3
        assert physics_steps.is_subscribed(handle)
        runtime().sim.advance(1 / 60)
        assert seen and seen[0] > 0
        assert get_write_queue() is queue
    finally:
        physics_steps.unsubscribe(handle)
        settings_store.set("/omni/replicator/RTSubframes", kept)


def test_the_session_holds_every_piece_once_runtime_and_rooms_exist():
    runtime()
    assert list(session.parts()) == list(Session.STAGE_RESETS + Session.PROCESS_PARTS)
    assert not set(Session.STAGE_RESETS) & set(Session.PROCESS_PARTS)
    assert Session.ADOPTED <= set(Session.STAGE_RESETS + Session.PROCESS_PARTS)
    pieces = list(session.parts().values())
    assert len({id(p) for p in pieces}) == len(pieces), "a piece is held in two slots"
    assert session.stage_context is stage_context and stage_context._owner == session.stage_replaced


def test_adopt_refuses_a_slot_it_does_not_have_a_second_piece_and_a_stage_piece_without_a_reset():
    with pytest.raises(ValueError, match=r"no slot 'renderer'.*slots: \['engine_state', 'forces'"):
        session.adopt("renderer", object())
    with pytest.raises(RuntimeError, match=r"the session's 'graph' is already .*CurrentGraph"):
        session.adopt("graph", object())
    assert session.adopt("graph", session.graph) is session.graph    # handing over the same piece again is fine
    fresh = Session.__new__(Session)
    fresh.forces = None
    with pytest.raises(TypeError, match=r"'forces' is reset with the stage: .* needs on_stage_replaced"):
        fresh.adopt("forces", object())


def test_a_stage_context_has_one_owner():
    with pytest.raises(RuntimeError, match="already has an owner"):
        stage_context.own(lambda stage: None)
    stage_context.own(session.stage_replaced)        # the same owner again is fine


def _module_tree(name: str) -> ast.Module:
    return ast.parse(inspect.getsource(importlib.import_module(name)))


@pytest.mark.parametrize("name", MIGRATED)
def test_a_migrated_room_keeps_no_module_level_state_outside_the_session(name):
    runtime()   # the runtime's slot is filled on first use
    module = importlib.import_module(name)
    owned = {id(session)}
    for part in session.parts().values():
        owned.add(id(part))
        owned.update(id(value) for value in vars(part).values())   # what a piece holds (the graph's open blocks)
    loose = []
    for key, value in vars(module).items():
        if key.startswith("__") or isinstance(value, (types.ModuleType, type, types.FunctionType,
                                                      types.BuiltinFunctionType, STATELESS)):
            continue
        if type(value) is object or type(value).__module__ in ("typing", "__future__"):
            continue   # a sentinel; a typing construct
        if isinstance(value, types.MethodType) and id(value.__self__) in owned:
            continue   # a module-level name for a piece's method (settings_store.get, physics_steps.notify)
        if id(value) in owned or key in CONSTANT_TABLES.get(name, ()):
            continue
        loose.append(f"{key} ({type(value).__name__})")
    assert not loose, f"{name} holds module-level state the session does not own: {loose}"
    tree = _module_tree(name)
    rebinds = [node.names for node in ast.walk(tree) if isinstance(node, ast.Global)]
    assert not rebinds, f"{name} rebinds module globals {rebinds}: state belongs in a session piece"
    hooks = [node.lineno for node in ast.walk(tree) if isinstance(node, ast.Attribute)
             and node.attr == "subscribe_replaced" and name != "graphsdg.stage.context"]
    assert not hooks, f"{name} subscribes to stage replacement itself (lines {hooks}); the session resets it"


def test_the_scan_finds_state_a_module_would_keep(monkeypatch):
    module = importlib.import_module("graphsdg.sim.physics_steps")
    monkeypatch.setattr(module, "_cache", {}, raising=False)
    with pytest.raises(AssertionError, match=r"_cache \(dict\)"):
        test_a_migrated_room_keeps_no_module_level_state_outside_the_session("graphsdg.sim.physics_steps")


def test_the_session_module_examples_run():
    result = doctest.testmod(session_module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
