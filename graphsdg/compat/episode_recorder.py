"""Isaac compat area: ``isaacsim.replicator.episode_recorder`` over :mod:`graphsdg.episodes`.

The recorder, replayer, recordables, session file layout (HDF5, schema 2),
manifest, registry, target discovery, stage snapshot and session injectors are
graphsdg's own (:mod:`graphsdg.episodes`); this face adds what is Kit's:

* the command bus: ``dispatch_episode_command`` sends
  :data:`EPISODE_CMD_EVENT` through ``carb.eventdispatcher``, and every recorder
  with an open session carries the commands addressed to it out;
  ``dispatch_episode_binding`` sends :data:`EPISODE_BINDING_EVENT`;
* while compat mode is installed, sessions sample on Isaac's
  ``SimulationManager`` post-step callbacks (as Isaac's recorder does: from the
  first step after play, and dropped, as Isaac drops them, when a new stage
  opens), the ``sim_time`` track reads its clock (time and steps since physics
  started on play), ``app_update`` sampling and driven replay follow Kit's app updates
  (``omni.kit.app`` update events, which come whether or not the timeline plays),
  and :meth:`EpisodeReplayer.replay_episode` updates the app through
  ``omni.kit.app.get_app().update()``.

Isaac leaves the extension off in a standalone app; scripts enable it first.
"""
from __future__ import annotations

import types
from typing import Any, Literal

from graphsdg import episodes
from graphsdg.compat import kit
from graphsdg.compat.event_dispatch import get_eventdispatcher
from graphsdg.compat.event_names import APP_UPDATE
from graphsdg.compat.modules import CompatModule
from graphsdg.episodes import articulation_recordable, pose_recordables, scalar_recordables, sim_clock, \
    target_discovery, tick_sources
from graphsdg.episodes.recorder import VALID_COMMANDS

NAME = "isaacsim.replicator.episode_recorder"
EXTENSIONS = {NAME: (NAME,)}
OFF_AT_START = {NAME}

EPISODE_CMD_EVENT = f"{NAME}.command"
EPISODE_BINDING_EVENT = f"{NAME}.binding"
VALID_BINDING_ACTIONS = frozenset({"attach", "detach"})
PoseBackend = Literal["usd", "usdrt", "fabric"]


def dispatch_episode_command(command: str, *, session_id: str | None = None, **payload: Any) -> None:
    """Send a recorder command (start, end, toggle, pause, resume, open_session, close_session) on the carb
    event bus, to the recorder of ``session_id`` or (``None``) to every recorder; extra items go in the payload."""
    get_eventdispatcher().dispatch_event(EPISODE_CMD_EVENT, payload={"command": command, "session_id": session_id,
                                                                      **payload})


def dispatch_episode_binding(action: str, *, binding_id: str, source: str, label: str | None = None,
                             command: str | None = None, session_id: str | None = None) -> None:
    """Announce an input bound to (``attach``) or released from (``detach``) the recorder command bus."""
    if action not in VALID_BINDING_ACTIONS:
        episodes.recorder.log.warning("dispatch_episode_binding: action %r is not one of %s; sent as it is",
                                      action, sorted(VALID_BINDING_ACTIONS))
    get_eventdispatcher().dispatch_event(EPISODE_BINDING_EVENT, payload={
        "action": action, "binding_id": binding_id, "source": source, "label": label, "command": command,
        "session_id": session_id})


class EpisodeRecorder(episodes.EpisodeRecorder):
    """``EpisodeRecorder``: graphsdg's recorder listening to the carb command bus while its session is open."""

    _command_guard: Any = None
    _tick = episodes.EpisodeRecorder.tick   # Isaac's name of one sampling tick (its tests drive it by hand)

    def open_session(self, output_path: str | None = None) -> str:
        path = super().open_session(output_path)
        self._command_guard = get_eventdispatcher().observe_event(
            event_name=EPISODE_CMD_EVENT, on_event=lambda event: self.handle_command(event.payload),
            observer_name=f"EpisodeRecorder.{self.session_id}")
        return path

    def close_session(self) -> None:
        guard, self._command_guard = self._command_guard, None
        if guard is not None:
            guard.reset()
        super().close_session()


class EpisodeReplayer(episodes.EpisodeReplayer):
    """``EpisodeReplayer``: graphsdg's replayer updating the app through Kit's ``omni.kit.app`` each frame."""

    def __init__(self, hdf5_path: str, *, policy: episodes.ReplayPolicy | None = None,
                 pose_backend: PoseBackend = "usd") -> None:
        super().__init__(hdf5_path, policy=policy, pose_backend=pose_backend, app_update=kit.get_app().update)


def _isaac_clock() -> tuple[float, int]:
    from graphsdg.compat.simulation_manager import SimulationManager
    return float(SimulationManager.get_simulation_time()), int(SimulationManager.get_num_physics_steps())


def _isaac_post_step(callback) -> tick_sources.Unsubscribe:
    from graphsdg.compat.simulation_manager import SimulationEvent, SimulationManager
    uid = SimulationManager.register_callback(lambda step_size, context: callback(),
                                              event=SimulationEvent.PHYSICS_POST_STEP)
    return lambda: SimulationManager.deregister_callback(uid)


def _kit_app_updates(callback) -> tick_sources.Unsubscribe:
    guard = get_eventdispatcher().observe_event(event_name=APP_UPDATE, on_event=lambda event: callback(),
                                                observer_name="episode_recorder.app_update")
    return guard.reset


def install() -> None:
    """Read Isaac's simulation clock and follow Kit's app updates while compat mode is installed."""
    sim_clock.set_clock(_isaac_clock)
    tick_sources.set_source("physics_post_step", _isaac_post_step)
    tick_sources.set_source("app_update", _kit_app_updates)


def uninstall() -> None:
    """Back to graphsdg's own clock and app-update source."""
    sim_clock.set_clock(None)
    tick_sources.set_source("physics_post_step", None)
    tick_sources.set_source("app_update", None)


def modules() -> list[types.ModuleType]:
    """The extension's package and the submodules scripts import from."""
    recorder_names = dict(EpisodeRecorder=EpisodeRecorder, SessionEvents=episodes.SessionEvents)
    replayer_names = dict(EpisodeReplayer=EpisodeReplayer)
    base = dict(ChannelDescriptor=episodes.ChannelDescriptor, Recordable=episodes.Recordable,
                ReplayPolicy=episodes.ReplayPolicy, SamplingConfig=episodes.SamplingConfig)
    commands = dict(EPISODE_CMD_EVENT=EPISODE_CMD_EVENT, EPISODE_BINDING_EVENT=EPISODE_BINDING_EVENT,
                    VALID_COMMANDS=VALID_COMMANDS, VALID_BINDING_ACTIONS=VALID_BINDING_ACTIONS,
                    dispatch_episode_command=dispatch_episode_command,
                    dispatch_episode_binding=dispatch_episode_binding)
    manifest = {n: getattr(episodes, n) for n in ("SCHEMA_VERSION", "SessionManifest", "build_manifest",
                                                   "read_manifest", "write_manifest")}
    registry = {n: getattr(episodes, n) for n in ("get_registered", "register_recordable", "registered_types",
                                                   "rehydrate", "unregister_recordable")}
    injectors = {n: getattr(episodes, n) for n in ("SessionInjector", "apply_session_injectors",
                                                    "clear_session_injectors", "register_session_injector",
                                                    "registered_session_injectors", "unregister_session_injector")}
    recordables = {n: getattr(episodes, n) for n in ("ArticulationRecordable", "AttributeRecordable",
                                                      "CameraRecordable", "RigidBodyRecordable",
                                                      "SimTimeRecordable", "XformRecordable")}
    storage = dict(DEFAULT_BUFFER_FRAMES=episodes.DEFAULT_BUFFER_FRAMES, SessionReader=episodes.SessionReader,
                   SessionStorage=episodes.SessionStorage)
    snapshot = dict(STAGE_SNAPSHOT_BASENAME=episodes.STAGE_SNAPSHOT_BASENAME,
                    export_stage_snapshot=episodes.export_stage_snapshot)
    discovery = {n: getattr(target_discovery, n) for n in (
        "sanitize_name", "assign_unique_name", "discover_articulations_under", "discover_rigid_bodies_under",
        "discover_xforms_under", "discover_all_under")}
    discovery_module = CompatModule(f"{NAME}.target_discovery", target_discovery.__doc__ or "", **discovery)
    controller = dict(TimelineDrivenEpisodeController=episodes.TimelineDrivenEpisodeController)
    package = CompatModule(
        NAME, __doc__ or "", **recorder_names, **replayer_names, **base, **commands, **manifest, **registry,
        **injectors, **recordables, **storage, **snapshot, **controller, PoseBackend=PoseBackend,
        require_h5py=episodes.require_h5py, target_discovery=discovery_module)
    leaves = {"ArticulationRecordable": ("articulation", articulation_recordable),
              "RigidBodyRecordable": ("rigid_body", pose_recordables), "XformRecordable": ("xform", pose_recordables),
              "CameraRecordable": ("camera", pose_recordables),
              "AttributeRecordable": ("attribute", scalar_recordables),
              "SimTimeRecordable": ("sim_time", scalar_recordables)}
    return [package, discovery_module,
            CompatModule(f"{NAME}.recorder", **recorder_names),
            CompatModule(f"{NAME}.replayer", **replayer_names),
            CompatModule(f"{NAME}.base", **base),
            CompatModule(f"{NAME}.commands", **commands),
            CompatModule(f"{NAME}.manifest", **manifest),
            CompatModule(f"{NAME}.registry", **registry),
            CompatModule(f"{NAME}.session_injectors", **injectors),
            CompatModule(f"{NAME}.storage", **storage),
            CompatModule(f"{NAME}.stage_snapshot", **snapshot),
            CompatModule(f"{NAME}.timeline_controller", **controller),
            CompatModule(f"{NAME}.recordables", **recordables),
            *[CompatModule(f"{NAME}.recordables.{leaf}", **{cls: getattr(module, cls)})
              for cls, (leaf, module) in leaves.items()]]
