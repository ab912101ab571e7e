"""The process's sensor scanners: one per sensor prim of the stage, captured once per frame.

A render product of an ``OmniLidar`` / ``OmniRadar`` prim drives that sensor: each capture asks
:data:`scanners` for the sensor's output at the capture's time, and every annotator of every product of the
same sensor gets the same scan (a lidar fires its beams once per frame however many ask). The scanners keep
what a lidar accumulates between frames; a new stage forgets them, and a clock running backwards (the timeline
stopped and played again) restarts a scanner.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.engine.runtime import runtime
    >>> stage = rep.stage.new_stage()
    >>> lidar = stage.DefinePrim("/Lidar", "OmniLidar")
    >>> _ = lidar.ApplyAPI("OmniSensorGenericLidarCoreAPI")
    >>> a = scanners.capture(runtime().sim, stage, "/Lidar", 0.0, frame_index=7)
    >>> a is scanners.capture(runtime().sim, stage, "/Lidar", 0.0, frame_index=7)
    True
"""
from __future__ import annotations

from typing import Any

from pxr import Usd

from graphsdg.sensors.lidar_profile import LidarProfileError
from graphsdg.sensors.lidar_scan import LidarScanner
from graphsdg.sensors.radar_scan import RadarScanner
from graphsdg.sim.scene import SimScene

SCANNER_TYPES = {"OmniLidar": LidarScanner, "OmniRadar": RadarScanner}


def is_sensor(prim: Usd.Prim) -> bool:
    """Whether ``prim`` is a ray-cast sensor graphsdg scans (an ``OmniLidar`` or ``OmniRadar``)."""
    return bool(prim) and prim.GetTypeName() in SCANNER_TYPES


class Scanners:
    """Scanners by (stage, sensor path), and each one's output of the current frame."""

    def __init__(self) -> None:
        self._scanners: dict[tuple[int, str], Any] = {}
        self._latest: dict[tuple[int, str], tuple[int, float, Any]] = {}

    def scanner(self, stage: Usd.Stage, path: str) -> Any:
        """The scanner of sensor ``path`` (made at first use, by the prim's type)."""
        key = (id(stage), str(path))
        found = self._scanners.get(key)
        prim = stage.GetPrimAtPath(str(path))
        kind = SCANNER_TYPES.get(prim.GetTypeName()) if prim else None
        if kind is None:
            raise LidarProfileError(f"{path!r} is not a lidar or radar prim (an OmniLidar or OmniRadar); it is "
                                    f"{'missing' if not prim else repr(prim.GetTypeName() or 'typeless')}")
        if not isinstance(found, kind):
            found = self._scanners[key] = kind(str(path))
        return found

    def capture(self, sim: SimScene, stage: Usd.Stage, path: str, now: float, frame_index: int) -> Any:
        """Sensor ``path``'s output at time ``now`` of capture ``frame_index`` (made once per capture)."""
        key = (id(stage), str(path))
        kept = self._latest.get(key)
        if kept is not None and kept[0] == frame_index and kept[1] == now:
            return kept[2]
        out = self.scanner(stage, path).capture(sim, stage, now)
        self._latest[key] = (frame_index, now, out)
        return out

    def clear(self) -> None:
        """Forget every scanner and its latest output."""
        self._scanners.clear()
        self._latest.clear()

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """Forget every scanner: they scanned the old stage's sensors."""
        self.clear()


#: The process's scanners (held by the session, :mod:`graphsdg.engine.session`).
scanners = Scanners()
