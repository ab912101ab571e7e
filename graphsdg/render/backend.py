"""The render backend seam: which renderer draws a render product's passes.

Render products, annotators and writers only see :class:`RenderBackend`: a
``render(scene, view, passes, subframes, defer, motion)`` that returns
:class:`RenderOutputs`, and ``render_batch(scene, requests)``
for a step's render products at once (:class:`RenderRequest`; the pbr backend draws
several in one launch, the classic one draw by draw), in one layout (uint8 RGBA
colour, linear float ``hdr``, planar-z depth with ``inf`` background, int32 geom
ids with -1 background). Two backends implement it:

* ``classic``: MuJoCo's OpenGL rasteriser (:class:`~graphsdg.render.rasterizer.Rasterizer`),
  headless through EGL, on any machine. It is the backend unchanged, not a wrapper,
  so its images are byte for byte those of before the seam.
* ``pbr``: mujoco-warp-pbr's batched physically based ray tracer on an NVIDIA GPU
  (:mod:`graphsdg.render.pbr`, the optional ``graphsdg[gpu]`` extra, Python >= 3.12).

The choice comes from settings (:func:`requested_backend`):

* ``/graphsdg/render/backend``: ``classic`` | ``pbr`` | ``auto`` (default). ``auto`` is
  ``pbr`` where the extra is installed and a CUDA GPU is present, else ``classic``;
  the outcome is logged once per process. ``pbr`` without what it needs raises
  :class:`PbrUnavailableError` naming what is missing.
* ``/graphsdg/render/pbrDevice``: the Warp device pbr renders on, ``cuda:0`` (default) or ``cpu``
  (Warp's CPU device: needs the extra but no GPU; slow, for checks at tiny sizes).
* ``/rtx/rendermode``: ``RaytracedLighting`` (Isaac's default) -> the real-time tier;
  ``PathTracing`` -> the path tier with ``max(/rtx/pathtracing/spp, /rtx/pathtracing/totalSpp)``
  samples per pixel per launch and ``/rtx/pathtracing/optixDenoiser/enabled`` as the denoiser.
* ``/graphsdg/render/pbrBatchPixels``: the pbr backend draws a step's render products in one
  launch while their pixels add up to at most this many (:func:`launch_groups`).
* ``/graphsdg/render/pbrPngOnDevice``: the pbr backend compresses each frame's colour PNG on its
  device (:mod:`graphsdg.render.device_png`; read when a camera's buffers are made).
"""
from __future__ import annotations

import importlib.util
import logging
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Protocol, Sequence, runtime_checkable

import numpy as np

from graphsdg.base import settings_store as settings

if TYPE_CHECKING:   # type names only: the cameras, the motion samples and the render scene import no backend
    from graphsdg.render.camera import CameraView
    from graphsdg.render.motion_blur import MotionSamples
    from graphsdg.render.render_scene import RenderScene

log = logging.getLogger("graphsdg.render")

BACKEND_KEY = "/graphsdg/render/backend"
#: the Warp device the pbr backend renders on: ``cuda:N`` (default ``cuda:0``) or ``cpu`` (Warp's CPU device:
#: no GPU needed, slow; for checking a script or the mapping on a machine without one)
DEVICE_KEY = "/graphsdg/render/pbrDevice"
#: whether the pbr backend compresses each frame's colour PNG on its device (graphsdg.render.device_png): the
#: writer wraps the stream read back instead of compressing on the CPU; files about a tenth larger
PNG_ON_DEVICE_KEY = "/graphsdg/render/pbrPngOnDevice"
BACKENDS = ("classic", "pbr", "auto")
DENOISER_KEY = "/rtx/pathtracing/optixDenoiser/enabled"
#: its default (the settings store's) is eight 512x512 products: the most pixels bench/pbr_products.py measured one
#: launch to be faster for (H100: 1.1-1.4x from two 512x512 to sixteen 128x128 products, docs/rendering.md)
BATCH_PIXELS_KEY = "/graphsdg/render/pbrBatchPixels"
#: the ``graphsdg[gpu]`` extra: import name -> distribution pinned in pyproject.toml
PBR_MODULES = {"warp": "warp-lang==1.19.0", "mujoco_warp": "mujoco-warp==3.17.0",
               "mujoco_warp_pbr": "mujoco-warp-pbr==0.2.0"}
PBR_MIN_PYTHON = (3, 12)
INSTALL_HINT = "pip install 'graphsdg[gpu]'"


class PbrUnavailableError(RuntimeError):
    """The PBR backend was asked for on a machine that cannot run it (the message says what is missing)."""


@dataclass
class RenderRequest:
    """One render product's render of a step: the arguments of :meth:`RenderBackend.render`.

    ``view``: the product's :class:`~graphsdg.render.camera.CameraView`; ``passes``: ``color``, ``hdr``,
    ``depth``, ``segmentation``; ``subframes``: renders accumulated; ``defer``: leave the pixels copying;
    ``motion``: motion-blur sub-frames (:mod:`graphsdg.render.motion_blur`) or None; ``frame``: the frame's
    number in the run (the graph's frame, which a shard or resumed run seeks to), which seeds the frame's
    random samples (soft shadows, path tracing), so they do not depend on what the process drew before;
    ``palettes``: with ``segmentation``, the class masks the annotators will colour from the ids, each a packed
    RGBA (uint32) per geom id with the background's last (index -1), which a backend may colour where the ids
    are (:attr:`RenderOutputs.palettes`).
    """

    view: CameraView
    passes: set[str]
    subframes: int = 1
    defer: bool = False
    motion: MotionSamples | None = None
    frame: int = 0
    palettes: tuple[np.ndarray, ...] = ()


Crop = tuple[int, int, int, int]   # x0, y0, x1, y1 pixel bounds (x1, y1 exclusive)


class RenderOutputs:
    """What one render of one camera produced (each ``None`` if not requested).

    * ``color``: uint8 (H, W, 4) RGBA, alpha 255
    * ``hdr``: float32 (H, W, 3) linear colour in [0, 1]
    * ``depth``: float32 (H, W) planar z, inf on background
    * ``geom_ids``: int32 (H, W) geom id per pixel, -1 on background
    * ``id_codes`` and ``id_lut``: the same ids as read back, uint16/uint32 (H, W)
      codes, and the table ``id_lut[code]`` -> geom id (so a per-geom table can
      be applied to the pixels in one lookup: ``table[id_lut][id_codes]``)
    * ``code_boxes``: int32 (n, 4) inclusive pixel bounds (x_min, y_min, x_max,
      y_max) of each id code, row = code (n at most ``len(id_lut)``), -1 rows for
      codes no pixel has; made
      where the ids are (the pbr backend's GPU) when the backend can, else absent
      and derived from the pixels by the annotators
    * ``render_isolated``: follow-up renders of the same view and state,
      ``(geom ids, crop) -> int32 ids of the crop``
    * ``id_colours`` and ``palettes``: uint8 (H, W, 4) class masks, the ids coloured with each of
      ``palettes`` (the request's :attr:`RenderRequest.palettes` the backend coloured where the ids are; an
      empty tuple where it coloured none), each ``palettes[k][geom id]`` at every pixel

    A pass whose pixels are still being copied off the GPU (a deferred render)
    is finished on first access; a pass derived from others on the CPU (``geom_ids``
    from the id codes) is computed on first access only.
    """

    def __init__(self) -> None:
        self._values: dict[str, np.ndarray | None] = {}
        self._pending: dict[str, Callable[[], np.ndarray]] = {}
        self._derived: dict[str, Callable[[RenderOutputs], np.ndarray]] = {}
        self.id_lut: np.ndarray | None = None
        self.render_isolated: Callable[[Sequence[int], Crop], np.ndarray] | None = None
        self.palettes: tuple[np.ndarray, ...] = ()

    def id_colours(self, palette: np.ndarray) -> np.ndarray | None:
        """The class mask the backend coloured with ``palette`` (the very array a request passed), or None."""
        for k, made in enumerate(self.palettes):
            if made is palette:
                return self.get("id_colours")[k]
        return None

    def put(self, name: str, value: np.ndarray | Callable[[], np.ndarray] | None) -> None:
        """Store a pass's pixels, or a callable that finishes them when first asked for."""
        if callable(value):
            self._pending[name] = value
        else:
            self._values[name] = value

    def derive(self, name: str, compute: Callable[["RenderOutputs"], np.ndarray]) -> None:
        """Make pass ``name`` from other passes on first access: ``compute(self)``. :meth:`finish` leaves it
        alone (nothing of the renderer's is held), and ``compute`` takes the outputs as its argument so that it
        need not refer to them (a reference cycle would keep every pass alive until the garbage collector ran)."""
        self._derived[name] = compute

    def get(self, name: str) -> np.ndarray | None:
        """A pass's pixels (finished first if still copying, made first if derived); None if it was not
        rendered."""
        if name in self._pending:
            self._values[name] = self._pending.pop(name)()
        elif name in self._derived:
            self._values[name] = self._derived.pop(name)(self)
        return self._values.get(name)

    def finish(self) -> None:
        """Finish every pending pass, which holds a renderer's buffer (the GL context must still exist);
        derived passes are made only when asked for."""
        for name in list(self._pending):
            self.get(name)

    color = property(lambda self: self.get("color"))
    hdr = property(lambda self: self.get("hdr"))
    depth = property(lambda self: self.get("depth"))
    geom_ids = property(lambda self: self.get("geom_ids"))
    id_codes = property(lambda self: self.get("id_codes"))
    code_boxes = property(lambda self: self.get("code_boxes"))


@runtime_checkable
class RenderBackend(Protocol):
    """What render products' captures call; both backends return the same :class:`RenderOutputs` layout."""

    def render(self, scene: RenderScene, view: CameraView, passes: set[str], subframes: int = 1,
               defer: bool = False, motion: MotionSamples | None = None) -> RenderOutputs:
        """Render ``passes`` (``color``, ``hdr``, ``depth``, ``segmentation``) of ``view`` of ``scene`` (a
        :class:`~graphsdg.render.render_scene.RenderScene`, the scene description both backends share) now."""
        ...

    def render_batch(self, scene: RenderScene, requests: list[RenderRequest]) -> list[RenderOutputs]:
        """Render every request of one step (one :class:`RenderOutputs` each, in order)."""
        ...

    def close(self) -> None:
        """Free the backend's device resources."""
        ...


@dataclass(frozen=True)
class BackendRequest:
    """What the settings ask the renderer for (before checking the machine can do it).

    ``backend``: ``classic``, ``pbr`` or ``auto``; ``tier``: ``realtime`` or ``path``;
    ``path_samples``: path-traced samples per pixel of one launch; ``denoise``: filter
    the path-traced image.
    """

    backend: str
    tier: str
    path_samples: int
    denoise: bool


_requested: tuple[int, BackendRequest | None] = (-1, None)


def requested_backend() -> BackendRequest:
    """The render backend and tier the current settings ask for (see the module docstring); read again only
    when a setting changed (a pbr frame asks several times)."""
    global _requested
    generation = settings.generation()
    if _requested[0] != generation or _requested[1] is None:
        _requested = (generation, _read_request())
    return _requested[1]


def _read_request() -> BackendRequest:
    backend = str(settings.get(BACKEND_KEY, "auto")).strip().lower()
    if backend not in BACKENDS:   # the validator refuses these on set(); a default edited by hand lands here
        raise ValueError(f"setting {BACKEND_KEY} must be one of {BACKENDS}, got {backend!r}")
    path = str(settings.get("/rtx/rendermode", "RaytracedLighting")).strip().lower() == "pathtracing"
    spp = int(settings.get("/rtx/pathtracing/spp", 1) or 1)
    total = int(settings.get("/rtx/pathtracing/totalSpp", 1) or 1)
    samples = max(spp, total, 1)
    cap = int(settings.get("/graphsdg/render/maxSubframes", 0) or 0)
    if cap > 0:   # CI-sized runs of full scripts bound path samples as they bound subframes
        samples = min(samples, cap)
    return BackendRequest(backend=backend, tier="path" if path else "realtime", path_samples=samples,
                          denoise=bool(settings.get(DENOISER_KEY, True)))


def launch_groups(pixels: list[int], limit: int | None = None) -> list[list[int]]:
    """Indices of a step's render products, grouped for the pbr backend's launches: consecutive products
    while their pixel counts add up to at most ``limit`` (default: ``/graphsdg/render/pbrBatchPixels``); a
    product larger than the limit, or a limit of 0, gets a launch of its own.

    Example:
        >>> launch_groups([512 * 512] * 4, limit=1 << 20)
        [[0, 1, 2, 3]]
        >>> launch_groups([512 * 512] * 3, limit=600_000)
        [[0, 1], [2]]
    """
    limit = int(settings.get(BATCH_PIXELS_KEY)) if limit is None else int(limit)
    groups: list[list[int]] = []
    total = 0
    for i, n in enumerate(pixels):
        if groups and total + n <= limit:
            groups[-1].append(i)
            total += n
        else:
            groups.append([i])
            total = n
    return groups


def pbr_device() -> str:
    """The Warp device the pbr backend renders on (``/graphsdg/render/pbrDevice``)."""
    device = str(settings.get(DEVICE_KEY, "cuda:0") or "cuda:0")
    settings.VALIDATORS[DEVICE_KEY](DEVICE_KEY, device)   # a default edited by hand lands here unchecked
    return device


def _installed(name: str) -> bool:
    """Whether module ``name`` can be imported (a finder that refuses it, as compat mode's for a missing Warp
    does, counts as not installed)."""
    try:
        return importlib.util.find_spec(name) is not None
    except ImportError:
        return False


def pbr_missing(has_module: Callable[[str], bool] | None = None,
                cuda_devices: Callable[[], int] | None = None,
                python: tuple[int, int] | None = None, device: str = "cuda:0") -> list[str]:
    """What this machine lacks to run the PBR backend, each with how to get it; empty when it can.

    The checks run cheapest first and stop at the first failing group, so a machine
    without the extra never imports Warp (which initialises CUDA). The arguments
    replace the real probes in tests.
    """
    has_module = has_module or _installed
    python = python or (sys.version_info.major, sys.version_info.minor)
    if tuple(python) < PBR_MIN_PYTHON:
        return [f"Python >= {PBR_MIN_PYTHON[0]}.{PBR_MIN_PYTHON[1]} (this is {python[0]}.{python[1]}; "
                f"mujoco-warp-pbr 0.2.0 needs it), then {INSTALL_HINT}"]
    absent = [pin for name, pin in PBR_MODULES.items() if not has_module(name)]
    if absent:
        return [f"the gpu extra ({', '.join(absent)} not installed): {INSTALL_HINT}"]
    if device == "cpu":
        return []
    count = (cuda_devices or _cuda_device_count)()
    if count < 1:
        return ["a CUDA GPU (Warp finds no CUDA device: an NVIDIA GPU and driver are needed)"]
    return []


def _cuda_device_count() -> int:
    try:
        import warp as wp

        from graphsdg.render.kernel_cache import configure_warp
        configure_warp()              # Warp's first start: the node's kernel cache (graphsdg.render.kernel_cache)
        return int(wp.get_cuda_device_count())
    except Exception:   # a broken driver or toolkit is "no usable GPU", said by pbr_missing
        return 0


_auto_logged = False
#: set when a PBR renderer exists in this process (also one on Warp's CPU device): compiles add its camera
pbr_in_use = False
_machine_lacks: list[str] | None = None


def _cached_missing() -> list[str]:
    """:func:`pbr_missing` once per process (the machine does not change; the CUDA probe costs a Warp init)."""
    global _machine_lacks
    if pbr_device() == "cpu":
        return pbr_missing(device="cpu")
    if _machine_lacks is None:
        _machine_lacks = pbr_missing()
    return _machine_lacks


def pbr_draws() -> bool:
    """Whether the PBR backend draws in this process (compiled models then carry its camera)."""
    return pbr_in_use or resolve_backend() == "pbr"


def resolve_backend(request: BackendRequest | None = None,
                    missing: Callable[[], list[str]] = _cached_missing) -> str:
    """``classic`` or ``pbr`` for ``request`` (default: the settings' request) on this machine.

    Raises:
        PbrUnavailableError: ``pbr`` was asked for explicitly and the machine cannot run it.
    """
    global _auto_logged
    request = request or requested_backend()
    if request.backend == "classic":
        return "classic"
    lacks = missing()
    if request.backend == "pbr":
        if lacks:
            raise PbrUnavailableError(
                f"setting {BACKEND_KEY} = 'pbr' needs " + "; and ".join(lacks)
                + f". Set {BACKEND_KEY} to 'classic' (or 'auto') to render with the OpenGL rasteriser.")
        return "pbr"
    chosen = "classic" if lacks else "pbr"
    if not _auto_logged:   # said once: which renderer draws this process's images, and why
        _auto_logged = True
        why = f" (pbr needs {'; '.join(lacks)})" if lacks else " (graphsdg[gpu] and a CUDA GPU found)"
        log.info("render backend auto -> %s%s", chosen, why)
    return chosen


__all__ = ["BACKENDS", "PNG_ON_DEVICE_KEY", "BackendRequest", "PbrUnavailableError", "RenderBackend", "RenderRequest",
           "launch_groups", "pbr_device", "pbr_missing", "requested_backend", "resolve_backend"]
