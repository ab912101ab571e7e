"""Recording simulation state into HDF5 episode sessions and replaying them on the live stage.

A session file holds a manifest (which recordables, bound to which prims) and
episodes of per-frame channels. :class:`EpisodeRecorder` samples
:class:`Recordable` plugins after every physics step (or app update);
:class:`EpisodeReplayer` rebuilds them from the manifest and puts each recorded
frame back on the stage, where writers can capture it. The built-in recordables
record poses of rigid bodies, xforms and cameras, an articulation's link poses,
USD attributes and the simulation clock. Needs the ``episodes`` extra (h5py).
"""
from graphsdg.episodes.articulation_recordable import ArticulationRecordable
from graphsdg.episodes.channels import ChannelDescriptor, ReplayPolicy, SamplingConfig
from graphsdg.episodes.hdf5 import MissingHdf5Error, require_h5py
from graphsdg.episodes.manifest import SCHEMA_VERSION, SessionManifest, build_manifest, read_manifest, write_manifest
from graphsdg.episodes.pose_recordables import CameraRecordable, RigidBodyRecordable, XformRecordable
from graphsdg.episodes.recordable import Recordable
from graphsdg.episodes.recorder import EpisodeRecorder
from graphsdg.episodes.registry import (get_registered, register_recordable, registered_types, rehydrate,
                                        unregister_recordable)
from graphsdg.episodes.replayer import EpisodeReplayer
from graphsdg.episodes.scalar_recordables import AttributeRecordable, SimTimeRecordable
from graphsdg.episodes.session_events import SessionEvents
from graphsdg.episodes.session_injectors import (SessionInjector, apply_session_injectors, clear_session_injectors,
                                                 register_session_injector, registered_session_injectors,
                                                 unregister_session_injector)
from graphsdg.episodes.session_reader import SessionReader
from graphsdg.episodes.session_storage import DEFAULT_BUFFER_FRAMES, SessionStorage
from graphsdg.episodes.stage_snapshot import STAGE_SNAPSHOT_BASENAME, export_stage_snapshot
from graphsdg.episodes.timeline_controller import TimelineDrivenEpisodeController

__all__ = ["ArticulationRecordable", "AttributeRecordable", "CameraRecordable", "ChannelDescriptor",
           "DEFAULT_BUFFER_FRAMES", "EpisodeRecorder", "EpisodeReplayer", "MissingHdf5Error", "Recordable",
           "ReplayPolicy", "RigidBodyRecordable", "SCHEMA_VERSION", "STAGE_SNAPSHOT_BASENAME", "SamplingConfig",
           "SessionEvents", "SessionInjector", "SessionManifest", "SessionReader", "SessionStorage",
           "SimTimeRecordable", "TimelineDrivenEpisodeController", "XformRecordable", "apply_session_injectors",
           "build_manifest", "clear_session_injectors", "export_stage_snapshot", "get_registered",
           "read_manifest", "register_recordable", "register_session_injector", "registered_session_injectors",
           "registered_types", "rehydrate", "require_h5py", "unregister_recordable", "unregister_session_injector",
           "write_manifest"]
