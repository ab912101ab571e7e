"""Isaac compat: ``LidarSensor`` / ``RadarSensor`` and the GMO helpers of ``isaacsim.sensors.experimental.rtx``.

A sensor runtime wraps a :class:`~graphsdg.compat.sensors_rtx_authoring.Lidar` / ``Radar`` (or makes one from a
path), makes a render product of its prim (the product runs graphsdg's scanner each capture), attaches the
annotators named in its annotator specs (``generic-model-output`` -> ``GenericModelOutput``, ``stable-id-map``
-> ``StableIdMap``, and any :func:`register_annotator_spec` adds) and the writers named in the writer specs
(``draw-point-cloud``, registered by ``isaacsim.sensors.rtx.nodes``), and returns their data with
``get_data(name)`` as ``(array, info)``.

The parsers read graphsdg's buffers: :func:`parse_generic_model_output_data` a GMO
(:mod:`graphsdg.sensors.generic_model_output`), :func:`parse_stable_id_map_data` a ``StableIdMap``, and
:func:`parse_object_ids` a GMO's 16-byte object ids into the integers the map is keyed by.

Example:
    >>> import numpy as np
    >>> parse_object_ids(np.array([7, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0], dtype=np.uint8))
    [7]
"""
from __future__ import annotations

import ctypes
import itertools
import logging
from typing import Any

import numpy as np
from pxr import UsdRender

import graphsdg
from graphsdg.compat.modules import CompatObject
from graphsdg.compat.sensors_rtx_authoring import Lidar, Radar, _SensorAuthoring
from graphsdg.compat.warp_arrays import as_warp_like
from graphsdg.render.product_prims import sync_product_prims
from graphsdg.sensors import generic_model_output as gmo_format

log = logging.getLogger(__name__)

ANNOTATOR_SPEC: dict[str, dict] = {
    "generic-model-output": {"name": "GenericModelOutput"},
    "stable-id-map": {"name": "StableIdMap"},
}
WRITER_SPEC: dict[str, dict] = {}
_product_numbers = itertools.count()


def register_annotator_spec(name: str, spec: dict) -> None:
    """Let sensor runtimes attach annotator ``name`` (``spec["name"]``: the registry's name)."""
    ANNOTATOR_SPEC[name] = spec


def unregister_annotator_spec(name: str) -> None:
    """Remove annotator spec ``name``."""
    ANNOTATOR_SPEC.pop(name, None)


def register_writer_spec(name: str, spec: dict) -> None:
    """Let sensor runtimes attach writer ``name`` (``spec["name"]``: the registry's name; ``spec["defaults"]``:
    its initialize arguments)."""
    WRITER_SPEC[name] = spec


def unregister_writer_spec(name: str) -> None:
    """Remove writer spec ``name``."""
    WRITER_SPEC.pop(name, None)


def parse_generic_model_output_data(data: Any) -> gmo_format.GenericModelOutput:
    """The :class:`GenericModelOutput` of an annotator's GMO buffer (array, warp array, or an address)."""
    if data is None:
        log.warning("parse_generic_model_output_data: No data provided")
        return gmo_format.GenericModelOutput()
    if hasattr(data, "numpy") and not isinstance(data, np.ndarray):
        data = data.numpy()
    if isinstance(data, (np.ndarray, bytes, bytearray, memoryview)):
        gmo = gmo_format.decode(np.frombuffer(bytes(data), np.uint8) if not isinstance(data, np.ndarray) else data)
    else:
        header = (ctypes.c_char * 28).from_address(int(data))
        size = int(np.frombuffer(bytes(header[16:24]), np.uint64)[0])
        gmo = gmo_format.decode(bytes((ctypes.c_char * size).from_address(int(data))))
    if gmo.magicNumber != gmo_format.MAGIC_NUMBER:
        log.warning("parse_generic_model_output_data: Invalid magic number")
        gmo = gmo_format.GenericModelOutput()
    return gmo


def parse_stable_id_map_data(data: Any) -> dict[int, str]:
    """``{stable id: prim path}`` of a ``StableIdMap`` buffer."""
    raw = (data.numpy() if hasattr(data, "numpy") and not isinstance(data, np.ndarray) else np.asarray(data))
    raw = np.asarray(raw, dtype=np.uint8).tobytes()
    count = int.from_bytes(raw[-4:], byteorder="little")
    entries = np.frombuffer(raw[:count * 24], "<u4").reshape(-1, 6)
    return {int.from_bytes(e[:4].tobytes(), "little"): raw[int(e[5]):int(e[5]) + int(e[4])].decode("utf8").rstrip()
            for e in entries}


def parse_object_ids(obj_ids: np.ndarray) -> list[int]:
    """Each 16-byte object id of a GMO ``objId`` buffer (uint8, uint32 or uint64) as a Python int."""
    ids = np.ascontiguousarray(obj_ids)
    widths = {np.dtype(np.uint8): 16, np.dtype(np.uint32): 4, np.dtype(np.uint64): 2}
    if ids.dtype not in widths:
        raise ValueError(f"Unsupported dtype for object IDs: {ids.dtype}. Expected uint8, uint32, or uint64.")
    return [int.from_bytes(group.tobytes(), "little") for group in ids.reshape(-1, widths[ids.dtype])]


class _SensorRuntime(CompatObject):
    """Base of :class:`LidarSensor` and :class:`RadarSensor` (module docstring)."""

    _AUTHORING_CLASS: type = _SensorAuthoring
    _AUTHORING_ATTR = "_sensor"

    def __init__(self, path: "str | _SensorAuthoring", *, annotators: Any = None, writers: Any = None,
                 render_vars: list[str] | None = None) -> None:
        self._hydra_texture = None
        self._annotators: dict[str, Any] = {}
        self._writers: dict[str, Any] = {}
        self._annotators_spec = dict(ANNOTATOR_SPEC)
        self._writers_spec = dict(WRITER_SPEC)
        if annotators is not None:
            self._validate(annotators, self._annotators_spec, "annotator")
        if writers is not None:
            self._validate(writers, self._writers_spec, "writer")
        authoring = path if isinstance(path, self._AUTHORING_CLASS) else self._AUTHORING_CLASS(path)
        setattr(self, self._AUTHORING_ATTR, authoring)
        if len(authoring) > 1:
            raise ValueError(f"The sensor only supports one {self._AUTHORING_CLASS._PRIM_TYPE} prim, but the "
                             f"provided argument refers to {len(authoring)} prims: {authoring.paths}")
        self._hydra_texture = graphsdg.create.render_product(authoring.paths[0], (300, 300),
                                                              name=f"rtx_sensor_{next(_product_numbers)}",
                                                              force_new=True)
        self.attach_annotators(annotators or [])
        for name in ([writers] if isinstance(writers, str) else writers or []):
            spec = self._writers_spec[name]
            self.attach_writer(spec["name"], **spec.get("defaults", {}))

    @staticmethod
    def _validate(names: Any, specs: dict, kind: str) -> None:
        for name in [names] if isinstance(names, str) else names:
            if name not in specs:
                raise ValueError(f"Unsupported {kind} '{name}'. Supported {kind}s are {list(specs.keys())}")

    @property
    def authoring_object(self) -> _SensorAuthoring:
        """The wrapped :class:`Lidar` / :class:`Radar`."""
        return getattr(self, self._AUTHORING_ATTR)

    @property
    def annotators(self) -> list[str]:
        """The attached annotators' spec names, sorted."""
        return sorted(self._annotators)

    @property
    def render_product(self) -> UsdRender.Product:
        """The sensor's render product prim."""
        for prim in sync_product_prims():
            if str(prim.GetPath()) == self._hydra_texture.path:
                return UsdRender.Product(prim)
        raise RuntimeError(f"Invalid render product at path '{self._hydra_texture.path}'")

    def attach_annotators(self, annotators: Any) -> dict[str, Any]:
        """Attach annotators by spec name; returns them by name."""
        names = [annotators] if isinstance(annotators, str) else list(annotators)
        self._validate(names, self._annotators_spec, "annotator")
        for name in names:
            annotator = graphsdg.AnnotatorRegistry.get_annotator(self._annotators_spec[name]["name"],
                                                                 do_array_copy=False)
            self._annotators[name] = annotator.attach([self._hydra_texture.path])
        return {name: self._annotators[name] for name in names}

    def detach_annotators(self, annotators: Any) -> None:
        """Detach annotators by spec name (one not attached is skipped with a warning)."""
        names = [annotators] if isinstance(annotators, str) else list(annotators)
        self._validate(names, self._annotators_spec, "annotator")
        for name in names:
            if name not in self._annotators:
                log.warning("Unable to detach annotator '%s'. It might have been already detached", name)
                continue
            self._annotators.pop(name).detach([self._hydra_texture.path])

    def get_data(self, annotator: str) -> tuple[Any, dict[str, Any]]:
        """``(data, info)`` of attached annotator ``annotator`` (``(None, {})`` before its first capture)."""
        self._validate(annotator, self._annotators_spec, "annotator")
        if annotator not in self._annotators:
            raise ValueError(f"The annotator '{annotator}' was not configured. Enable it when instantiating the class")
        out = self._annotators[annotator].get_data()
        info: dict[str, Any] = {}
        if isinstance(out, dict) and "data" in out:
            info = {k: v for k, v in out.items() if k != "data"}
            out = out["data"]
        return (as_warp_like(out) if isinstance(out, np.ndarray) else out), info

    def attach_writer(self, writer_name: str, **kwargs: Any) -> Any:
        """Attach a writer (a writer spec's name or a registry name) initialized with ``kwargs``."""
        spec = self._writers_spec.get(writer_name)
        registry_name, merged = (spec["name"], {**spec.get("defaults", {}), **kwargs}) if spec else \
            (writer_name, kwargs)
        writer = graphsdg.writers.get(registry_name)
        writer.initialize(**merged)
        writer.attach([self._hydra_texture.path])
        self._writers[writer_name] = writer
        return writer

    def detach_writer(self, writer_name: str) -> None:
        """Detach a writer attached with :meth:`attach_writer`."""
        writer = self._writers.pop(writer_name, None)
        if writer is None:
            log.warning("Unable to detach writer '%s'. It might have been already detached", writer_name)
        else:
            writer.detach()


class LidarSensor(_SensorRuntime):
    """``isaacsim.sensors.experimental.rtx.LidarSensor`` (module docstring)."""

    _compat_name = "isaacsim.sensors.experimental.rtx.LidarSensor"
    _AUTHORING_CLASS = Lidar
    _AUTHORING_ATTR = "_lidar"

    @property
    def lidar(self) -> Lidar:
        """The wrapped :class:`Lidar`."""
        return self._lidar


class RadarSensor(_SensorRuntime):
    """``isaacsim.sensors.experimental.rtx.RadarSensor`` (module docstring)."""

    _compat_name = "isaacsim.sensors.experimental.rtx.RadarSensor"
    _AUTHORING_CLASS = Radar
    _AUTHORING_ATTR = "_radar"

    @property
    def radar(self) -> Radar:
        """The wrapped :class:`Radar`."""
        return self._radar
