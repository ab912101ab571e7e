"""The settings store: one flat table keyed by Replicator's (carb) setting paths.

Isaac Sim scripts configure Replicator through carb settings such as
``/omni/replicator/captureOnPlay`` or ``rtx/post/dlss/execMode``. graphsdg keeps
one flat store keyed by normalised path. Keys that graphsdg honours are listed in
:data:`KNOWN_KEYS`; any other key is stored (so ``get`` returns what was set) and
a single warning per key says that it has no effect here.

graphsdg's own modules read and write settings here: it depends on nothing but
:mod:`graphsdg.errors`, so every layer can. Scripts use :mod:`graphsdg.settings`
(``rep.settings``), which offers these functions together with Replicator's
functions that change the stage and the renderer.

Example:
    >>> from graphsdg.base import settings_store
    >>> settings_store.set("/omni/replicator/RTSubframes", 4)
    >>> settings_store.get("/omni/replicator/RTSubframes")
    4
"""
from __future__ import annotations

import numbers
import os
import threading
import warnings
from typing import Any, Callable

from graphsdg.errors import closest

# key -> (default, meaning). Only these keys change graphsdg's behaviour.
KNOWN_KEYS: dict[str, tuple[Any, str]] = {
    "/omni/replicator/captureOnPlay": (True, "capture every timeline tick while playing"),
    "/omni/replicator/RTSubframes": (1, "default number of accumulated subframes per capture"),
    "/omni/replicator/globalSeed": (None, "global seed of every distribution and ReplicatorRNG"),
    "/omni/replicator/backend/writeThreads": (4, "writer worker threads of the I/O pool, at most (they start as "
                                                   "the backlog needs them)"),
    "/omni/replicator/backend/queueSize": (1000, "queued writes before the producer is throttled"),
    "/omni/replicator/backends/disk/root_dir": (None, "root of relative DiskBackend output dirs"),
    "/graphsdg/io/queueMaxBytes": (1 << 30, "bytes of image/array data queued writes may hold before the producer "
                                   "is throttled"),
    "/graphsdg/io/writeProcesses": ("auto", "writer processes that encode and write image, array and JSON files of up "
                                    "to 1 MiB to local folders outside the interpreter lock: a count (0: all writes on the "
                                    "writer threads) or auto (as many as writeThreads, when that is 2 or more, "
                                    "on 4 cores or more)"),
    "/graphsdg/io/fsync": (False, "fsync each file and its folder before a write counts as done (survives power "
                           "loss, slower)"),
    "/graphsdg/io/runState": (True, "keep graphsdg_run.json (which frames are complete on disk) in each writer's "
                              "output folder"),
    "/exts/omni.replicator.core/enableWriteToFabric": (
        False, "write randomized poses and colours straight into MuJoCo, camera poses beside the stage (stage not "
               "authored)"),
    "/graphsdg/run/numFrames": (None, "frames for orchestrator.run() calls without num_frames (graphsdg run --frames)"),
    "/graphsdg/run/shardIndex": (0, "this process's shard of a sharded run (graphsdg run --workers)"),
    "/graphsdg/run/shardCount": (1, "shards of a sharded run: shard i captures frames i, i+K, ..."),
    "/graphsdg/run/resume": (False, "skip frames complete on disk and adopt the writers' files (graphsdg run --resume)"),
    "/graphsdg/io/discardWrites": (False, "disk backends create and write nothing (graphsdg graph)"),
    "/graphsdg/render/shadowSize": (1024, "shadow map size of shadow-casting lights"),
    "/graphsdg/render/msaaSamples": (4, "multisample anti-aliasing samples of the colour pass"),
    "/graphsdg/render/exposure": (1.0, "scale from photometric light units to display values"),
    "/graphsdg/render/maxResolution": (4096, "largest render product edge"),
    "/graphsdg/render/resolutionScale": (1.0, "factor applied to every new render product's resolution "
                                         "(graphsdg run --resolution-scale; small test runs of full-size scripts)"),
    "/graphsdg/scenarios/palletizing/numBins": (36, "bins in the palletizing scenario's cell (BinStacking() without "
                                                    "num_bins); fewer make CI-sized runs"),
    "/persistent/isaac/asset_root/default": (None, "root that get_assets_root_path() returns instead of the "
                                             "built-in asset pack"),
    "/graphsdg/assets/nucleusMirror": (None, "local folder holding a Nucleus server's tree (NVIDIA/, Isaac/, ...): "
                                             "omniverse://<host>/<path> reads <folder>/<path> (graphsdg.assets.nucleus)"),
    "/rtx/rendermode": ("RayTracedLighting", "render mode; with the pbr backend RaytracedLighting is its "
                        "real-time tier and PathTracing its path tier; on the classic rasteriser PathTracing "
                        "enables the highest-quality settings (8x MSAA, shadow maps of 8 texels per image pixel "
                        "up to 4096 px, /rtx/pathtracing/totalSpp jittered subframes per capture)"),
    "/rtx/pathtracing/spp": (1, "samples per pixel per frame in PathTracing mode (pbr backend: path samples per "
                                "launch are the larger of spp and totalSpp)"),
    "/rtx/pathtracing/optixDenoiser/enabled": (True, "denoise path-traced images (pbr backend's path tier)"),
    "/graphsdg/render/backend": ("auto", "renderer: classic (MuJoCo's OpenGL rasteriser), pbr (mujoco-warp-pbr on "
                                         "a CUDA GPU; pip install 'graphsdg[gpu]', Python >= 3.12) or auto (pbr "
                                         "where it can run, else classic; said once in the log)"),
    "/graphsdg/render/pbrDevice": ("cuda:0", "the Warp device the pbr backend renders on: cuda:N, or cpu (Warp's "
                                             "CPU device: slow, for checks on machines without a GPU)"),
    "/graphsdg/render/pbrBatchPixels": (1 << 21, "the pbr backend draws a step's render products in one launch "
                                                 "while their pixels add up to at most this many (one camera "
                                                 "each; bench/pbr_products.py measured where it pays); 0: one "
                                                 "launch per product"),
    "/graphsdg/render/pbrPngOnDevice": (False, "the pbr backend compresses each frame's colour PNG on its device "
                                               "(graphsdg.render.device_png): less CPU a written frame, files "
                                               "about a tenth larger"),
    "/graphsdg/render/pbrKernel": ("compact", "how the pbr backend's render kernel is built: compact (the "
                                              "traversals' per-geom tests and the lights' shadow test called, "
                                              "not inlined: compiles about four times faster) or inlined "
                                              "(mujoco-warp-pbr's own build); graphsdg.render.pbr_kernel"),
    "/rtx/pathtracing/totalSpp": (1, "in PathTracing mode, the least number of jittered subframes each capture "
                                     "accumulates"),
    "/app/player/playSimulations": (True, "physics steps with the timeline's ticks; False: ticks advance time and "
                                          "send their events without stepping physics (Kit's render-only updates)"),
    "/app/player/timelineSubsampleRate": (1, "timeline ticks per frame: each app update's frame is split into this "
                                              "many ticks, each with its physics and tick events "
                                              "(omni.timeline set_ticks_per_frame)"),
    "/syntheticdata/sensors/perSubsetSegmentation": (True, "labels on a mesh's GeomSubsets make their faces separate "
                                                           "semantic instances (off: the faces carry the mesh's labels)"),
    "/graphsdg/render/maxSubframes": (0, "upper bound on accumulated subframes per capture (rt_subframes and "
                                         "path-tracing samples); 0 means no bound (CI-sized runs of full scripts)"),
    # motion blur (graphsdg.render.motion_blur)
    "/omni/replicator/captureMotionBlur": (False, "motion blur: colour accumulated over each step's motion"),
    "/omni/replicator/pathTracedMotionBlurSubSamples": (8, "motion-blur sub-frames over the whole step in "
                                                           "PathTracing mode"),
    "/rtx/post/motionblur/numSamples": (8, "motion-blur sub-frames outside PathTracing mode"),
    "/rtx/post/motionblur/exposureFraction": (1.0, "fraction of the step the shutter is open, outside PathTracing "
                                                   "mode (above 1: the whole step)"),
    "/rtx/post/motionblur/maxBlurDiameterFraction": (0.02, "longest motion-blur smear, as a fraction of the image's "
                                                           "larger side, outside PathTracing mode"),
    # ray-cast sensors (graphsdg.sensors, docs/sensors.md)
    "/graphsdg/sensors/rayBackend": ("auto", "where lidar and radar rays are cast: cpu (mj_multiRay on threads), "
                                             "gpu (MuJoCo Warp on a CUDA GPU; pip install 'graphsdg[gpu]') or auto "
                                             "(gpu where it can run, else cpu)"),
    "/graphsdg/sensors/rayThreads": (0, "threads the cpu ray backend casts on; 0: one per core"),
    "/rtx/materialDb/nonVisualMaterialSemantics/prefix": ("omni:simready:nonvisual", "attribute prefix of the "
                                                          "non-visual material labels lidar and radar read"),
}

def _integer(minimum: int, none_ok: bool = False) -> Callable[[str, Any], None]:
    def check(key: str, value: Any) -> None:
        if value is None and none_ok:
            return
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
            raise ValueError(f"setting {key} must be an integer >= {minimum}{' or None' if none_ok else ''}, "
                             f"got {value!r}")
    return check


def _boolean(key: str, value: Any) -> None:
    if not (isinstance(value, bool) or type(value).__name__ == "bool_" or (isinstance(value, numbers.Integral)
                                                                           and value in (0, 1))):
        raise ValueError(f"setting {key} must be True or False, got {value!r}")


def _positive_number(key: str, value: Any) -> None:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not value > 0:
        raise ValueError(f"setting {key} must be a number > 0, got {value!r}")


def _non_negative_number(key: str, value: Any) -> None:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not value >= 0:
        raise ValueError(f"setting {key} must be a number >= 0, got {value!r}")


def _fraction(key: str, value: Any) -> None:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not 0 <= value <= 1:
        raise ValueError(f"setting {key} must be a number in [0, 1], got {value!r}")


def _choice(*options: str) -> Callable[[str, Any], None]:
    def check(key: str, value: Any) -> None:
        if not isinstance(value, str) or value.strip().lower() not in options:
            raise ValueError(f"setting {key} must be one of {list(options)}, got {value!r}")
    return check


def _warp_device(key: str, value: Any) -> None:
    ok = isinstance(value, str) and (value in ("cpu", "cuda") or (value.startswith("cuda:") and value[5:].isdigit()))
    if not ok:
        raise ValueError(f"setting {key} must be 'cuda', 'cuda:N' or 'cpu', got {value!r}")


def _count_or_auto(key: str, value: Any) -> None:
    if value == "auto":
        return
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 0:
        raise ValueError(f"setting {key} must be 'auto' or an integer >= 0, got {value!r}")


def _path_or_none(key: str, value: Any) -> None:
    if value is not None and not isinstance(value, (str, os.PathLike)):
        raise ValueError(f"setting {key} must be a folder path or None, got {value!r}")


# key -> check(key, value): known keys refuse values graphsdg cannot use, naming the key (no late, obscure error).
VALIDATORS: dict[str, Callable[[str, Any], None]] = {
    "/omni/replicator/captureOnPlay": _boolean,
    "/omni/replicator/RTSubframes": _integer(0),
    "/omni/replicator/globalSeed": _integer(0, none_ok=True),
    "/omni/replicator/backend/writeThreads": _integer(1),
    "/omni/replicator/backend/queueSize": _integer(1),
    "/omni/replicator/backends/disk/root_dir": _path_or_none,
    "/graphsdg/io/queueMaxBytes": _integer(1),
    "/graphsdg/io/writeProcesses": _count_or_auto,
    "/graphsdg/io/fsync": _boolean,
    "/graphsdg/io/runState": _boolean,
    "/exts/omni.replicator.core/enableWriteToFabric": _boolean,
    "/graphsdg/run/numFrames": _integer(0, none_ok=True),
    "/graphsdg/run/shardIndex": _integer(0),
    "/graphsdg/run/shardCount": _integer(1),
    "/graphsdg/run/resume": _boolean,
    "/graphsdg/io/discardWrites": _boolean,
    "/graphsdg/render/shadowSize": _integer(1),
    "/graphsdg/render/msaaSamples": _integer(0),
    "/graphsdg/render/exposure": _positive_number,
    "/graphsdg/render/maxResolution": _integer(1),
    "/graphsdg/render/backend": _choice("classic", "pbr", "auto"),
    "/graphsdg/render/pbrDevice": _warp_device,
    "/graphsdg/render/pbrBatchPixels": _integer(0),
    "/graphsdg/render/pbrKernel": _choice("compact", "inlined"),
    "/graphsdg/render/pbrPngOnDevice": _boolean,
    "/rtx/pathtracing/spp": _integer(1),
    "/rtx/pathtracing/optixDenoiser/enabled": _boolean,
    "/omni/replicator/captureMotionBlur": _boolean,
    "/omni/replicator/pathTracedMotionBlurSubSamples": _integer(1),
    "/rtx/post/motionblur/numSamples": _integer(1),
    "/rtx/post/motionblur/exposureFraction": _non_negative_number,
    "/rtx/post/motionblur/maxBlurDiameterFraction": _fraction,
    "/app/player/timelineSubsampleRate": _integer(1),
    "/app/player/playSimulations": _boolean,
    "/syntheticdata/sensors/perSubsetSegmentation": _boolean,
    "/graphsdg/sensors/rayBackend": _choice("cpu", "gpu", "auto"),
    "/graphsdg/sensors/rayThreads": _integer(0),
}

_MISSING = object()


def normalize_key(key: str) -> str:
    """Return ``key`` with exactly one leading slash (carb accepts both forms)."""
    if not isinstance(key, str) or not key.strip("/"):
        raise ValueError(f"setting key must be a non-empty path string, got {key!r}")
    return "/" + key.strip().lstrip("/")


class SettingsStore:
    """The values set, which unknown keys were warned about, and a generation bumped by every change."""

    def __init__(self) -> None:
        self._values: dict[str, Any] = {}
        self._generation = 0   # bumped by every set and reset (readers cache what they derive from settings)
        self._warned: set[str] = set()
        self._lock = threading.Lock()

    def set(self, key: str, value: Any) -> None:  # noqa: A003 - mirrors carb's API name
        """Store ``value`` under ``key``; warn once if graphsdg does not use the key.

        A key graphsdg uses refuses a value it cannot use (``ValueError`` naming the key).
        """
        k = normalize_key(key)
        check = VALIDATORS.get(k)
        if check is not None:
            check(k, value)
        with self._lock:
            self._values[k] = value
            self._generation += 1
            unknown = k not in KNOWN_KEYS and k not in self._warned
            if unknown:
                self._warned.add(k)
        if unknown:
            warnings.warn(
                f"setting {k!r} has no effect in graphsdg (stored, but nothing reads it){closest(k, KNOWN_KEYS)}; "
                f"honoured keys: {', '.join(sorted(KNOWN_KEYS))}",
                stacklevel=2,
            )

    def get(self, key: str, default: Any = None) -> Any:
        """Return the value of ``key``: what was set, else graphsdg's default, else ``default``."""
        if type(key) is str:
            # A frame reads settings ~50 times: a key spelt as stored (stored keys are normalized) needs neither
            # normalizing nor the lock (one dict read is atomic)
            value = self._values.get(key, _MISSING)
            if value is not _MISSING:
                return value
            known = KNOWN_KEYS.get(key)   # a known key left at its default (most of a frame's reads)
            if known is not None:
                return known[0] if known[0] is not None else default
        k = normalize_key(key)
        with self._lock:
            if k in self._values:
                return self._values[k]
        if k in KNOWN_KEYS and KNOWN_KEYS[k][0] is not None:
            return KNOWN_KEYS[k][0]
        return default

    def reset(self) -> None:
        """Forget every value that was set (defaults apply again) and which keys were already warned about."""
        with self._lock:
            self._values.clear()
            self._warned.clear()
            self._generation += 1

    def generation(self) -> int:
        """A number that changes whenever a setting is set or the settings are reset: what a hot path derived
        from settings stays valid while it is the same.

        Example:
            >>> g = generation(); set("/omni/replicator/backend/writeThreads", 2); generation() != g
            True
            >>> reset()
        """
        return self._generation


#: The process's settings (held by the session, :mod:`graphsdg.engine.session`).
store = SettingsStore()

set = store.set  # noqa: A001 - mirrors carb's API name
get = store.get
reset = store.reset
generation = store.generation

# carb-style aliases so `settings.get_settings().set(...)` reads naturally.
set_bool = set_int = set_float = set_string = set
get_as_bool = get_as_int = get_as_float = get_as_string = get
