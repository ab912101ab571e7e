"""Isaac compat area: the ``omni.syntheticdata`` names Isaac's Replicator code uses, mapped onto graphsdg's annotators.

``omni.syntheticdata`` is the layer under Replicator in Kit: render variables
("render vars") and the OmniGraph pipeline that turns them into annotator
outputs. graphsdg computes annotators directly, so what maps is:

* ``_syntheticdata.SensorType``: the legacy sensor types, each with the graphsdg
  annotator that produces that data (:data:`SENSOR_ANNOTATORS`, e.g.
  ``SensorType.Rgb`` -> ``rgb``);
* ``SyntheticData.convert_sensor_type_to_rendervar(name)``: Kit's render var name of
  a legacy sensor type (``"Rgb"`` -> ``"LdrColorSD"``, ``"MotionVector"`` ->
  ``"TargetMotionSD"``, any other ``<name>SD``);
* ``SyntheticData.NodeTemplate`` / ``NodeConnectionTemplate`` and ``SyntheticDataStage``:
  the pipeline descriptions writers build at import time (plain records here; an
  OmniGraph pipeline built from them raises where it is built);
* ``scripts.helpers.get_bbox_3d_corners``: the eight corners of ``bounding_box_3d`` rows;
* ``tests.utils.add_semantics(prim, semantic_label, type="class")``: a semantic label;
* ``sensors.next_render_simulation_async(render_product_path, num_simulation_frames)`` and
  ``sensors.next_sensor_data_async(viewport, ...)``: wait that many (one) app updates.

Everything that drives the pipeline itself (``SyntheticData.Get()``'s node methods,
``SyntheticData._get_node_path``, ``acquire_syntheticdata_interface``, the legacy
``sensors.enable_sensors`` / ``get_*`` viewport API) raises ``CompatError`` naming
itself: graphsdg has no OmniGraph render pipeline; use Replicator's annotators.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.syntheticdata._syntheticdata as sd
    >>> from omni.syntheticdata import SyntheticData
    >>> SyntheticData.convert_sensor_type_to_rendervar(sd.SensorType.Rgb.name)
    'LdrColorSD'
    >>> SENSOR_ANNOTATORS[sd.SensorType.DistanceToImagePlane]
    'distance_to_image_plane'
    >>> isaac.uninstall()
"""
from __future__ import annotations

import enum
import types
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pxr import Usd

from graphsdg.compat import kit
from graphsdg.compat.modules import CompatError, CompatModule, CompatObject
from graphsdg.stage import semantics

EXTENSIONS = {"omni.syntheticdata": ("omni.syntheticdata",)}

NO_PIPELINE = ("graphsdg has no OmniGraph synthetic-data pipeline (render vars and Sd* nodes); it computes "
               "annotators directly: use omni.replicator.core's AnnotatorRegistry / writers")


class SensorType(enum.IntEnum):
    """The legacy synthetic-data sensor types (values are graphsdg's own numbering)."""

    Rgb = 0
    DistanceToImagePlane = 1
    DistanceToCamera = 2
    InstanceSegmentation = 3
    SemanticSegmentation = 4
    BoundingBox2DTight = 5
    BoundingBox2DLoose = 6
    BoundingBox3D = 7
    Occlusion = 8
    Normal = 9
    MotionVector = 10
    Camera3dPosition = 11


#: The graphsdg annotator that gives each sensor type's data (Camera3dPosition has none: ``pointcloud`` is the
#: nearest, per labelled point rather than per pixel).
SENSOR_ANNOTATORS: dict[SensorType, str] = {
    SensorType.Rgb: "rgb", SensorType.DistanceToImagePlane: "distance_to_image_plane",
    SensorType.DistanceToCamera: "distance_to_camera", SensorType.InstanceSegmentation: "instance_segmentation",
    SensorType.SemanticSegmentation: "semantic_segmentation", SensorType.BoundingBox2DTight: "bounding_box_2d_tight",
    SensorType.BoundingBox2DLoose: "bounding_box_2d_loose", SensorType.BoundingBox3D: "bounding_box_3d",
    SensorType.Occlusion: "occlusion", SensorType.Normal: "normals", SensorType.MotionVector: "motion_vectors"}


class SyntheticDataStage:
    """The pipeline stage a node template runs in."""

    AUTO = -1
    SIMULATION = 0
    PRE_RENDER = 1
    POST_RENDER = 2
    ON_DEMAND = 3


class SyntheticDataException(Exception):
    """omni.syntheticdata's error type."""


class _PipelineClass(type):
    """Class attributes of ``SyntheticData`` that are not mapped fail naming themselves."""

    def __getattr__(cls, item: str) -> Any:
        if item.startswith("__"):
            raise AttributeError(item)
        raise CompatError(f"omni.syntheticdata.SyntheticData.{item} is not available in graphsdg's compat mode: "
                          f"{NO_PIPELINE}.")


class SyntheticData(CompatObject, metaclass=_PipelineClass):
    """omni.syntheticdata.SyntheticData: node templates and render var names (see the module docstring)."""

    _compat_name = "omni.syntheticdata.SyntheticData"

    @dataclass
    class NodeConnectionTemplate:
        """A connection of a pipeline node to another template (or render var)."""

        node_template_id: str
        render_product_idxs: tuple = (0,)
        attributes_mapping: dict = field(default_factory=dict)

    @dataclass
    class NodeTemplate:
        """A pipeline node: its stage, its node type, its connections and attribute values."""

        pipeline_stage: int
        node_type_id: str
        connections: list = field(default_factory=list)
        attributes: dict = field(default_factory=dict)

    @staticmethod
    def convert_sensor_type_to_rendervar(legacy_type_name: str) -> str:
        """Kit's render var name of a legacy sensor type name."""
        if not isinstance(legacy_type_name, str) or not legacy_type_name:
            raise TypeError(f"a sensor type name (such as 'Rgb') is needed, got {legacy_type_name!r}")
        return {"Rgb": "LdrColorSD", "MotionVector": "TargetMotionSD"}.get(legacy_type_name, f"{legacy_type_name}SD")

    @staticmethod
    def Get() -> "SyntheticData":  # noqa: N802 - Kit's name
        """The process's instance (its pipeline methods raise ``CompatError``)."""
        return _instance

    def __getattr__(self, item: str) -> Any:
        if item.startswith("__"):
            raise AttributeError(item)
        raise CompatError(f"omni.syntheticdata.SyntheticData.Get().{item} is not available in graphsdg's compat "
                          f"mode: {NO_PIPELINE}.")


_instance = SyntheticData()


def get_bbox_3d_corners(extents: Any) -> np.ndarray:
    """The corners of 3D boxes (``x_min`` .. ``z_max`` in the box's frame, ``transform`` 4x4 row-major with the
    translation in its last row, as ``bounding_box_3d`` rows hold them) in world coordinates, ``(N, 8, 3)``, in
    the order x_min/x_max fastest, then y, then z (LDB, RDB, LUB, RUB, LDF, RDF, LUF, RUF)."""
    lows = np.stack([np.asarray(extents[k], dtype=np.float64) for k in ("x_min", "y_min", "z_min")], -1)
    highs = np.stack([np.asarray(extents[k], dtype=np.float64) for k in ("x_max", "y_max", "z_max")], -1)
    lows, highs = np.atleast_2d(lows), np.atleast_2d(highs)
    picks = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=bool)   # (8, 3)
    corners = np.where(picks[None], highs[:, None, :], lows[:, None, :])                          # (N, 8, 3)
    homogeneous = np.concatenate([corners, np.ones(corners.shape[:2] + (1,))], -1)
    transforms = np.asarray(extents["transform"], dtype=np.float64).reshape(-1, 4, 4)
    return np.einsum("nci,nij->ncj", homogeneous, transforms)[..., :3]


def add_semantics(prim: Usd.Prim, semantic_label: str, semantic_type: str = "class") -> None:
    """Give ``prim`` the semantic label ``semantic_label`` of type ``semantic_type``."""
    if not prim or not prim.IsValid():
        raise ValueError(f"add_semantics needs a valid prim, got {prim!r}")
    semantics.apply(prim, {str(semantic_type): str(semantic_label)}, mode="add")


async def next_render_simulation_async(render_product_path: str, num_simulation_frames: int = 1) -> None:
    """Wait ``num_simulation_frames`` app updates."""
    for _ in range(max(1, int(num_simulation_frames))):
        await kit.get_app().next_update_async()


async def next_sensor_data_async(viewport: Any = None, waitSimFrame: bool = False,  # noqa: N803 - Kit's name
                                 inViewportId: int | None = None) -> None:  # noqa: N803
    """Wait one app update (the next frame of sensor data)."""
    await kit.get_app().next_update_async()


def _no_interface(*args: Any, **kwargs: Any) -> Any:
    raise CompatError("omni.syntheticdata._syntheticdata.acquire_syntheticdata_interface is not available in "
                      f"graphsdg's compat mode: {NO_PIPELINE}.")


def modules() -> list[types.ModuleType]:
    """``omni.syntheticdata`` with ``_syntheticdata``, ``sensors``, ``scripts.helpers`` and ``tests.utils``."""
    legacy = ("The legacy viewport sensor API (enable_sensors, get_rgb, ...) is not provided: attach "
              "omni.replicator.core annotators to the viewport's render product instead (SENSOR_ANNOTATORS in "
              "graphsdg.compat.syntheticdata names the annotator of each sensor type)")
    return [
        CompatModule("omni.syntheticdata", SyntheticData=SyntheticData, SyntheticDataStage=SyntheticDataStage,
                     SyntheticDataException=SyntheticDataException, hint=NO_PIPELINE + "."),
        CompatModule("omni.syntheticdata._syntheticdata", SensorType=SensorType,
                     acquire_syntheticdata_interface=_no_interface),
        CompatModule("omni.syntheticdata.sensors", next_render_simulation_async=next_render_simulation_async,
                     next_sensor_data_async=next_sensor_data_async, hint=legacy + "."),
        CompatModule("omni.syntheticdata.scripts.helpers", get_bbox_3d_corners=get_bbox_3d_corners),
        CompatModule("omni.syntheticdata.tests.utils", add_semantics=add_semantics),
    ]
