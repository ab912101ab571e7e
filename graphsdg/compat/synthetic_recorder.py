"""Isaac compat area: ``isaacsim.replicator.synthetic_recorder`` (the recorder, without its window).

``SyntheticRecorder`` and ``RecorderState`` are :mod:`graphsdg.synthetic_recorder`. The extension's
window (``SyntheticRecorderWindow``, the menu entry) is Kit UI and out of scope. Isaac leaves the extension
off in a standalone app.
"""
from __future__ import annotations

import types

from graphsdg.compat.modules import CompatModule
from graphsdg import synthetic_recorder as engine

NAME = "isaacsim.replicator.synthetic_recorder"
EXTENSIONS = {NAME: (NAME,)}
OFF_AT_START = {NAME}
_HINT = "The recorder's window (SyntheticRecorderWindow) is Kit UI, which graphsdg does not have."


def modules() -> list[types.ModuleType]:
    """The extension's package and its ``synthetic_recorder`` module."""
    names = dict(SyntheticRecorder=engine.SyntheticRecorder, RecorderState=engine.RecorderState,
                 MAX_NUM_FRAMES=engine.MAX_NUM_FRAMES, MAX_RESOLUTION_WARN=engine.MAX_RESOLUTION_WARN,
                 SEMANTICS_ANNOTATORS=engine.SEMANTICS_ANNOTATORS)
    return [CompatModule(NAME, hint=_HINT, **names),
            CompatModule(f"{NAME}.synthetic_recorder", engine.__doc__ or "", hint=_HINT, **names)]
