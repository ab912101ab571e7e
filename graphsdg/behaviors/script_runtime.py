"""Behavior scripts: Python classes attached to prims through the ``omni:scripting:scripts`` attribute.

A prim lists script files in ``omni:scripting:scripts`` (an asset array). For each file the
:class:`ScriptManager` loads the module (a file graphsdg already imported is that module) and instantiates
every :class:`BehaviorScript` subclass the module itself defines, once per prim, calling ``on_init()``. Its
instances then hear of the timeline: ``on_play()``, ``on_pause()``, ``on_stop()``, and ``on_update(
current_time, delta_time)`` after every tick of the playing timeline. A script removed from the list (or its
prim removed, or the stage replaced) gets ``on_destroy()``. A hook that raises is logged and the others run.

Changes to the script lists are picked up at the next :meth:`ScriptManager.sync`, which runs when
:func:`attach_script` attaches one, before every timeline event, and whenever the host calls it (at every
app update: compat mode's Kit updates, or :func:`graphsdg.behaviors.host.next_update`), so scripts are
instantiated (and their exposed variables created) even while the timeline is stopped.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(name="Cube")
    >>> from graphsdg.behaviors import location_randomizer
    >>> attach_script(cube, location_randomizer.__file__)
    >>> manager = script_manager(); manager.sync()
    >>> [type(s).__name__ for s in manager.instances("/Cube")]
    ['LocationRandomizer']
"""
from __future__ import annotations

import importlib.util
import logging
import os
import sys
import types
from typing import Any

from pxr import Sdf, Tf, Usd

from graphsdg.engine.runtime import runtime
from graphsdg.sim.timeline import TimelineEventType
from graphsdg.stage.context import get_stage, stage_context

SCRIPTS_ATTR = "omni:scripting:scripts"
SCRIPTING_API = "OmniScriptingAPI"
log = logging.getLogger("graphsdg.behaviors")


class BehaviorScript:
    """The base class of behavior scripts: one instance per prim and script file (see the module docstring)."""

    def __init__(self, prim_path: Sdf.Path | str) -> None:
        self._prim_path = Sdf.Path(str(prim_path))
        self._stage = get_stage()

    @property
    def prim_path(self) -> Sdf.Path:
        """The path of the prim the script is attached to."""
        return self._prim_path

    @property
    def stage(self) -> Usd.Stage:
        """The stage of the prim."""
        return self._stage

    @property
    def prim(self) -> Usd.Prim:
        """The prim the script is attached to (an invalid prim once its stage is gone)."""
        if self._stage is None or self._stage.expired:
            return Usd.Prim()
        return self._stage.GetPrimAtPath(self._prim_path)

    def on_init(self) -> None:
        """Called once the script is attached to the prim."""

    def on_destroy(self) -> None:
        """Called when the script is detached (or its prim or stage goes away)."""

    def on_play(self) -> None:
        """Called when the timeline starts playing."""

    def on_pause(self) -> None:
        """Called when the timeline pauses."""

    def on_stop(self) -> None:
        """Called when the timeline stops."""

    def on_update(self, current_time: float, delta_time: float) -> None:
        """Called after every tick of the playing timeline."""


def apply_scripting_api(prim: Usd.Prim) -> Usd.Attribute:
    """Give ``prim`` the scripting API and its ``omni:scripting:scripts`` attribute (no value yet); the attribute."""
    if prim is None or not prim.IsValid():
        raise ValueError(f"the scripting API needs a valid prim, got {prim!r}")
    attr = prim.GetAttribute(SCRIPTS_ATTR)
    if not attr:
        prim.AddAppliedSchema(SCRIPTING_API)
        attr = prim.CreateAttribute(SCRIPTS_ATTR, Sdf.ValueTypeNames.AssetArray, custom=False)
    return attr


def attach_script(prim: Usd.Prim, script_path: str, allow_duplicates: bool = False) -> None:
    """Add ``script_path`` to the prim's ``omni:scripting:scripts`` (applying the scripting API first)."""
    attr = apply_scripting_api(prim)
    current = [a.path for a in (attr.Get() or [])]
    if allow_duplicates or str(script_path) not in current:
        attr.Set(Sdf.AssetPathArray(current + [str(script_path)]))
    script_manager().sync()


def script_paths(prim: Usd.Prim) -> list[str]:
    """The script files a prim lists (resolved paths where USD resolved them)."""
    attr = prim.GetAttribute(SCRIPTS_ATTR) if prim and prim.IsValid() else None
    if not attr:
        return []
    return [a.resolvedPath or a.path for a in (attr.Get() or []) if a.path]


def _has_scripts(prim: Usd.Prim) -> bool:
    return bool(prim) and prim.HasAttribute(SCRIPTS_ATTR)


def _file_of(path: str) -> str:
    path = path[len("file:"):] if path.startswith("file:") else path
    return os.path.realpath(path)


class ScriptManager:
    """Instantiates the stage's behavior scripts and relays timeline events to them (see the module docstring)."""

    def __init__(self) -> None:
        self._instances: dict[str, dict[str, list[BehaviorScript]]] = {}   # prim path -> script file -> objects
        self._modules: dict[str, types.ModuleType] = {}
        self._dirty: set[Sdf.Path] | None = None      # None: scan the whole stage
        self._listener: Any = None
        self._stage: Usd.Stage | None = None
        self._subscriptions: list[Any] = []
        self._started = False

    # ---- hooks ---------------------------------------------------------------------------
    def start(self) -> None:
        """Listen to the timeline and to stage replacement (starting twice does nothing)."""
        if self._started:
            return
        self._started = True
        timeline = runtime().timeline
        self._subscriptions = [timeline.subscribe(self._on_timeline)]
        stage_context.subscribe_replaced(self._on_stage_replaced)

    def stop(self) -> None:
        """Destroy every instance and stop listening."""
        self._destroy_all()
        for subscription in self._subscriptions:
            subscription.unsubscribe()
        self._subscriptions = []
        if self._started:
            stage_context.unsubscribe(self._on_stage_replaced)
        self._started = False
        self._drop_listener()

    def _on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        self._destroy_all()
        self._drop_listener()
        self._dirty = None

    def _drop_listener(self) -> None:
        if self._listener is not None:
            self._listener.Revoke()
        self._listener, self._stage = None, None

    def _listen(self, stage: Usd.Stage) -> None:
        if self._stage is stage and self._listener is not None:
            return
        self._drop_listener()
        self._stage = stage
        self._listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, self._on_objects_changed, stage)
        self._dirty = None

    def _on_objects_changed(self, notice: Usd.Notice.ObjectsChanged, stage: Usd.Stage) -> None:
        if self._dirty is None:
            return
        for path in notice.GetResyncedPaths():
            self._dirty.add(path.GetPrimPath())
        for path in notice.GetChangedInfoOnlyPaths():
            if path.IsPropertyPath() and path.name == SCRIPTS_ATTR:
                self._dirty.add(path.GetPrimPath())

    def _on_timeline(self, event: Any) -> None:
        kind = int(event.type)
        if kind in (TimelineEventType.PLAY, TimelineEventType.PAUSE, TimelineEventType.STOP):
            self.sync()
            hook = {TimelineEventType.PLAY: "on_play", TimelineEventType.PAUSE: "on_pause",
                    TimelineEventType.STOP: "on_stop"}[TimelineEventType(kind)]
            for script in self.all_instances():
                self._call(script, hook)
        elif kind == TimelineEventType.CURRENT_TIME_TICKED:
            self.sync()
            now, dt = float(event.payload.get("currentTime", 0.0)), float(event.payload.get("dt", 0.0))
            for script in self.all_instances():
                self._call(script, "on_update", now, dt)

    @staticmethod
    def _call(script: BehaviorScript, hook: str, *args: Any) -> None:
        try:
            getattr(script, hook)(*args)
        except Exception:  # noqa: BLE001 - one script must not stop the others (Kit logs and goes on)
            log.exception("%s.%s of %s raised", type(script).__name__, hook, script.prim_path)

    # ---- instances ----------------------------------------------------------------------
    def instances(self, prim_path: str | Sdf.Path) -> list[BehaviorScript]:
        """The script objects attached to the prim at ``prim_path``."""
        return [s for objs in self._instances.get(str(prim_path), {}).values() for s in objs]

    def all_instances(self) -> list[BehaviorScript]:
        """Every script object on the stage, in prim path order."""
        return [s for path in sorted(self._instances) for s in self.instances(path)]

    def sync(self) -> None:
        """Instantiate scripts newly listed and destroy those no longer listed."""
        self.start()
        stage = get_stage()
        if stage is None:
            return
        self._listen(stage)
        dirty, self._dirty = self._dirty, set()
        if dirty is None:
            paths = {str(p.GetPath()) for p in stage.TraverseAll() if p.HasAttribute(SCRIPTS_ATTR)}
            paths |= set(self._instances)
        else:
            paths = {str(p) for p in dirty if str(p) in self._instances or _has_scripts(stage.GetPrimAtPath(p))}
            for root in dirty:   # a resynced subtree may have gained or lost scripted prims
                prim = stage.GetPrimAtPath(root)
                if prim:
                    paths |= {str(p.GetPath()) for p in Usd.PrimRange(prim) if _has_scripts(p)}
                paths |= {p for p in self._instances if Sdf.Path(p).HasPrefix(root)}
        for path in sorted(paths):
            self._reconcile(stage, path)

    def _reconcile(self, stage: Usd.Stage, path: str) -> None:
        prim = stage.GetPrimAtPath(path)
        wanted = [_file_of(p) for p in script_paths(prim)] if prim else []
        held = self._instances.setdefault(path, {})
        for script_file in [f for f in held if f not in wanted]:
            for script in held.pop(script_file):
                self._call(script, "on_destroy")
        for script_file in wanted:
            if script_file in held:
                continue
            objects = []
            for cls in self._classes(script_file):
                try:
                    script = cls(Sdf.Path(path))
                except Exception:  # noqa: BLE001 - reported, the others still run
                    log.exception("could not make %s for %s", cls.__name__, path)
                    continue
                objects.append(script)
                self._call(script, "on_init")
                if runtime().timeline.is_playing():
                    self._call(script, "on_play")
            held[script_file] = objects
        if not held:
            self._instances.pop(path, None)

    def _classes(self, script_file: str) -> list[type[BehaviorScript]]:
        module = self._module(script_file)
        if module is None:
            return []
        return [obj for obj in vars(module).values()
                if isinstance(obj, type) and issubclass(obj, BehaviorScript) and obj is not BehaviorScript
                and obj.__module__ == module.__name__]

    def _module(self, script_file: str) -> types.ModuleType | None:
        if script_file in self._modules:
            return self._modules[script_file]
        for module in list(sys.modules.values()):   # a file already imported (graphsdg's own behaviors) is reused
            origin = getattr(module, "__file__", None)
            if origin and os.path.realpath(origin) == script_file:
                self._modules[script_file] = module
                return module
        if not os.path.isfile(script_file):
            log.error("behavior script %s does not exist", script_file)
            return None
        name = f"graphsdg_behavior_script_{len(self._modules)}_{os.path.splitext(os.path.basename(script_file))[0]}"
        spec = importlib.util.spec_from_file_location(name, script_file)
        module = importlib.util.module_from_spec(spec)
        try:
            sys.modules[name] = module
            spec.loader.exec_module(module)
        except Exception:  # noqa: BLE001 - a broken script file is reported, the stage goes on
            sys.modules.pop(name, None)
            log.exception("behavior script %s could not be loaded", script_file)
            return None
        self._modules[script_file] = module
        return module

    def _destroy_all(self) -> None:
        held, self._instances = self._instances, {}
        for objects_by_file in held.values():
            for objects in objects_by_file.values():
                for script in objects:
                    self._call(script, "on_destroy")


_manager = ScriptManager()


def script_manager() -> ScriptManager:
    """The process's script manager."""
    return _manager

