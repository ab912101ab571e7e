"""Isaac compat area: the deprecated ``isaacsim.sensors.rtx`` over graphsdg's ray-cast sensors. ``LidarRtx``,
``get_gmo_data`` and the Kit commands ``IsaacSensorCreateRtxLidar`` / ``IsaacSensorCreateRtxRadar``.

* The commands (registered while compat mode is installed, as Kit registers them at startup) create an
  ``OmniLidar`` / ``OmniRadar`` prim at the next free ``path`` under ``parent`` (which must exist), placed by
  ``translation`` and ``orientation`` (``Gf.Quatd``, w first); ``config`` authors graphsdg's profile of Isaac's
  named asset (``variant`` picks its variant; an unknown one raises naming it, where Isaac falls back to a
  default lidar with a warning), ``usd_path`` references a file and finds the sensor in it, and keyword
  arguments set schema attributes. ``force_camera_prim`` (Isaac 4's camera-prim sensors) raises.
* ``LidarRtx`` wraps or creates a lidar (made with the command), keeps a render product of it, attaches
  annotators and writers by name, and after :meth:`LidarRtx.initialize` reports each annotator's latest data in
  :meth:`LidarRtx.get_current_frame` (read when asked, not on a Kit update event).
* ``get_gmo_data`` parses a GMO buffer (graphsdg's annotators give arrays; an address is read too).

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.kit.commands, omni.usd
    >>> _ = omni.usd.get_context().new_stage()
    >>> _, lidar = omni.kit.commands.execute("IsaacSensorCreateRtxLidar", path="/Lidar", config="Example_Rotary")
    >>> lidar.GetPath(), int(lidar.GetAttribute("omni:sensor:Core:numberOfChannels").Get())
    (Sdf.Path('/Lidar'), 128)
    >>> isaac.uninstall()
"""
from __future__ import annotations

import logging
import types
from typing import Any

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade

import graphsdg
from graphsdg import functional
from graphsdg.compat import kit_command_registry
from graphsdg.compat.core_world import BaseSensor
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.compat.sensors_checker import CHECKER_NAMES
from graphsdg.compat.sensors_rtx import generic_model_output_module
from graphsdg.compat.sensors_rtx_authoring import config_prim, radar_profile_attributes
from graphsdg.compat.sensors_rtx_configs import (SUPPORTED_LIDAR_CONFIGS, SUPPORTED_LIDAR_VARIANT_SET_NAME,
                                                 SUPPORTED_RADAR_CONFIGS, check_variant, config_key,
                                                 resolve_config_path)
from graphsdg.compat.sensors_rtx_runtime import parse_generic_model_output_data, parse_object_ids, \
    parse_stable_id_map_data
from graphsdg.functional.sensors import set_sensor_attributes
from graphsdg.render.product_prims import sync_product_prims
from graphsdg.engine.runtime import runtime
from graphsdg.sim.timeline import TimelineEventType
from graphsdg.sensors.lidar_profile import author_lidar_profile
from graphsdg.sensors import surface_materials
from graphsdg.sensors.profile_catalog import lidar_profile
from graphsdg.stage.context import get_stage
from graphsdg.stage.prims import parent_path, unique_child_path
from graphsdg.stage.xform import set_local_pose

log = logging.getLogger(__name__)
NAME = "isaacsim.sensors.rtx"
EXTENSIONS = {NAME: (NAME,)}


class IsaacSensorCreateRtxSensorCommand(kit_command_registry.Command):
    """Base of the RTX sensor creation commands (module docstring)."""

    _sensor_type = "sensor"
    _registry: dict[str, Any] = {}

    def __init__(self, path: str | None = None, parent: str | None = None, config: str | None = None,
                 usd_path: str | None = None, translation: Any = Gf.Vec3d(0, 0, 0),
                 orientation: Any = Gf.Quatd(1, 0, 0, 0), visibility: bool = False, variant: Any = None,
                 force_camera_prim: bool = False, **kwargs: Any) -> None:
        if force_camera_prim:
            raise CompatError(f"IsaacSensorCreateRtx{self._sensor_type.capitalize()}(force_camera_prim=True) makes an "
                              f"Isaac Sim 4 camera-prim sensor, which graphsdg does not model; use an "
                              f"Omni{self._sensor_type.capitalize()} prim (the default). See docs/sensors.md.")
        if config and usd_path:
            log.warning("Both 'config' and 'usd_path' provided for Omni%s. Using 'config' (%s) and ignoring "
                        "'usd_path' (%s).", self._sensor_type.capitalize(), config, usd_path)
            usd_path = None
        self._path = path or f"/Rtx{self._sensor_type.capitalize()}"
        self._parent, self._config, self._usd_path, self._variant = parent, config, usd_path, variant
        self._translation, self._orientation, self._attributes = translation, orientation, kwargs
        self._prim_path: str | None = None

    def _new_path(self) -> Sdf.Path:
        """The next free path for the sensor: ``parent`` must exist (else an error names it); the ancestors
        ``path`` itself names are made as Xforms where missing, as Isaac's sensor classes do."""
        path = self._path if self._path.startswith("/") else "/" + self._path
        base = parent_path(self._parent)   # raises naming a parent that does not exist
        head = path.rsplit("/", 1)[0]
        folder = base if not head else Sdf.Path(head) if base == Sdf.Path.absoluteRootPath else \
            Sdf.Path(str(base) + head)
        stage = get_stage()
        if not stage.GetPrimAtPath(folder).IsValid():
            stage.DefinePrim(folder, "Xform")
        return unique_child_path(folder, path.rsplit("/", 1)[1])

    def _create(self, path: Sdf.Path) -> Usd.Prim:
        raise NotImplementedError

    def do(self) -> Usd.Prim:
        """Create the sensor prim and return it."""
        path = self._new_path()
        self._prim_path = str(path)
        if self._usd_path:
            prim = get_stage().DefinePrim(path, f"Omni{self._sensor_type.capitalize()}"
                                          if self._usd_path.endswith(".usda") else "Xform")
            prim.GetReferences().AddReference(self._usd_path)
            for set_name, choice in _variant_pairs(self._variant):
                prim.GetVariantSet(set_name).SetVariantSelection(choice)
            prim = next((p for p in Usd.PrimRange(prim)
                         if p.GetTypeName() == f"Omni{self._sensor_type.capitalize()}"), None)
            if prim is None:
                raise ValueError(f"No Omni{self._sensor_type.capitalize()} prim found in the referenced asset at "
                                 f"{path}. USD path: {self._usd_path}")
        else:
            prim = self._create(path)
        xf = UsdGeom.Xformable(get_stage().GetPrimAtPath(path))   # the asset's top prim, as Isaac places it
        xf.ClearXformOpOrder()
        t, q = self._translation, self._orientation
        if t is not None:
            xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*[float(v) for v in t]))
        if q is not None:
            xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(q) if isinstance(q, Gf.Quatd) else
                                                                Gf.Quatd(*[float(v) for v in q]))
        for name, value in self._attributes.items():
            if prim.HasAttribute(name):
                prim.GetAttribute(name).Set(value)
            else:
                log.warning("Sensor at %s does not have attribute %s", prim.GetPath(), name)
        return prim

    def undo(self) -> None:
        """Remove the created prim."""
        if self._prim_path:
            get_stage().RemovePrim(self._prim_path)


def _parent_or_root(path: Sdf.Path) -> str | None:
    parent = path.GetParentPath()
    return None if parent == Sdf.Path.absoluteRootPath else str(parent)


def _variant_pairs(variant: Any) -> list[tuple[str, str]]:
    if variant is None:
        return []
    return list(variant.items()) if isinstance(variant, dict) else [(SUPPORTED_LIDAR_VARIANT_SET_NAME, variant)]


class IsaacSensorCreateRtxLidarCommand(IsaacSensorCreateRtxSensorCommand):
    """``IsaacSensorCreateRtxLidar``: an ``OmniLidar`` prim (module docstring)."""

    _sensor_type = "lidar"

    def _create(self, path: Sdf.Path) -> Usd.Prim:
        if not self._config:
            return functional.create.omni_lidar(name=path.name, parent=_parent_or_root(path))
        found = resolve_config_path(self._config, SUPPORTED_LIDAR_CONFIGS, sensor_type="Lidar")
        check_variant(found, self._variant, SUPPORTED_LIDAR_CONFIGS, "Lidar")
        prim = config_prim(str(path), found, "OmniLidar")
        author_lidar_profile(prim, lidar_profile(config_key(found), self._variant))
        return prim


class IsaacSensorCreateRtxRadarCommand(IsaacSensorCreateRtxSensorCommand):
    """``IsaacSensorCreateRtxRadar``: an ``OmniRadar`` prim (module docstring)."""

    _sensor_type = "radar"

    def _create(self, path: Sdf.Path) -> Usd.Prim:
        if not self._config:
            return functional.create.omni_radar(name=path.name, parent=_parent_or_root(path))
        found = resolve_config_path(self._config, SUPPORTED_RADAR_CONFIGS, sensor_type="Radar")
        prim = config_prim(str(path), found, "OmniRadar")
        set_sensor_attributes(prim, radar_profile_attributes(config_key(found)))
        return prim


class IsaacSensorCreateRtxIDSCommand(IsaacSensorCreateRtxSensorCommand):
    """``IsaacSensorCreateRtxIDS``: not modelled."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        raise CompatError("IsaacSensorCreateRtxIDS is not available in graphsdg's compat mode: graphsdg does not model "
                          "RTX IDS sensors. See docs/sensors.md.")


COMMANDS = (IsaacSensorCreateRtxLidarCommand, IsaacSensorCreateRtxRadarCommand, IsaacSensorCreateRtxIDSCommand)


def _label_name(value: Any, table: dict[str, int], what: str) -> str | None:
    """The table name of ``value`` (a name or an index), or None (logged as Isaac logs it)."""
    if isinstance(value, str):
        name = surface_materials.base_name(value) if table is surface_materials.BASES else value
        if name in table:
            return name
        log.error("%s '%s' not found in %s dictionary", what, value, what.lower() + "s")
        return None
    found = next((n for n, i in table.items() if i == value), None)
    if found is None:
        log.error("%s ID '%s' not found in %s dictionary", what, value, what.lower() + "s")
    return found


def apply_nonvisual_material(prim: Usd.Prim, base: "str | int", coating: "str | int" = "none",
                             attribute: "str | int" = "none") -> bool:
    """Label material ``prim`` for lidar and radar (base, coating, attribute; names or indices); False (with an
    error logged, as Isaac does) for a prim that is no material or an unknown name."""
    if not prim or not prim.IsValid():
        log.error("Provided prim is not a valid USD prim")
        return False
    if not prim.IsA(UsdShade.Material):
        log.error("Provided prim is not a material prim")
        return False
    names = [_label_name(base, surface_materials.BASES, "Base material"),
             _label_name(coating, surface_materials.COATINGS, "Coating"),
             _label_name(attribute, surface_materials.ATTRIBUTES, "Attribute")]
    if None in names:
        return False
    for attr_name, value in zip(surface_materials.label_attribute_names(), names):
        prim.CreateAttribute(attr_name, Sdf.ValueTypeNames.String, custom=True).Set(value)
    return True


def get_material_id(prim: Usd.Prim) -> int:
    """The 16-bit non-visual material id of material ``prim`` (0 when it has no labels or is no material)."""
    if not prim or not prim.IsValid() or not prim.IsA(UsdShade.Material):
        log.error("Provided prim is not a valid material prim")
        return 0
    labels = surface_materials.material_labels(prim)
    return surface_materials.encode_material_id(*labels) if labels else 0


def _label_constants() -> dict[str, str]:
    """``ATTR_PREFIX``, ``ATTR_BASE``, ``ATTR_COATING``, ``ATTR_ATTRIBUTE``: the label attribute names (read from
    the prefix setting when compat mode is installed, as Isaac reads it when its extension loads)."""
    base, coating, attribute = surface_materials.label_attribute_names()
    return {"ATTR_PREFIX": base.rsplit(":", 1)[0], "ATTR_BASE": base, "ATTR_COATING": coating,
            "ATTR_ATTRIBUTE": attribute}


def get_gmo_data(dataPtr: Any) -> Any:
    """The :class:`GenericModelOutput` of a GMO buffer (an array, or the address of one); an empty one for
    None or 0."""
    if dataPtr is None or (isinstance(dataPtr, int) and dataPtr == 0):
        log.warning("isaacsim.sensors.rtx.get_gmo_data: received null pointer (%s), returning empty "
                    "GenericModelOutput buffer.", dataPtr)
    return parse_generic_model_output_data(dataPtr)


class LidarRtx(BaseSensor):
    """``isaacsim.sensors.rtx.LidarRtx`` (module docstring): a ``BaseSensor``, so ``World.scene.add`` takes it."""

    _VISUALIZATION_WRITER = "RtxLidarDebugDrawPointCloud"

    def __init__(self, prim_path: str, name: str = "lidar_rtx", position: Any = None, translation: Any = None,
                 orientation: Any = None, config_file_name: str | None = None, **kwargs: Any) -> None:
        self._annotators: dict[str, Any] = {}
        self._writers: dict[str, Any] = {}
        self._initialized = False
        stage = get_stage()
        prim = stage.GetPrimAtPath(prim_path)
        if prim and prim.IsValid():
            if prim.GetTypeName() == "Camera":
                # Isaac still accepts the Isaac Sim 4 camera-based lidar with a deprecation warning; graphsdg
                # places it and gives it a render product, and refuses to scan with it (_refuse_camera_lidar)
                log.warning("LidarRtx(%s): a Camera prim as a lidar is deprecated; graphsdg poses it but scans only "
                            "OmniLidar prims", prim_path)
            elif prim.GetTypeName() != "OmniLidar":
                raise ValueError(f"Prim at {prim_path} is not an OmniLidar.")
            elif not prim.HasAPI("OmniSensorGenericLidarCoreAPI"):
                raise ValueError(f"Prim at {prim_path} does not have the OmniSensorGenericLidarCoreAPI schema.")
            if prim.GetTypeName() == "OmniLidar":
                prim.GetAttribute("omni:sensor:Core:accumulateOutputs").Set(True)
            for key, value in kwargs.items():
                if prim.HasAttribute(key):
                    prim.GetAttribute(key).Set(value)
                else:
                    log.warning("Sensor at %s does not have attribute %s", prim_path, key)
        else:
            prim = IsaacSensorCreateRtxLidarCommand(path=prim_path, parent=None, config=config_file_name,
                                                    **kwargs).do()
        self._prim = prim
        self._name = name
        BaseSensor.__init__(self, str(prim.GetPath()), name=name)
        if position is not None or translation is not None or orientation is not None:
            self.set_world_pose(position, orientation) if translation is None else \
                self.set_local_pose(translation, orientation)
        self._render_product = graphsdg.create.render_product(str(prim.GetPath()), (128, 128), force_new=True)
        self._current_frame: dict[str, Any] = {"rendering_time": 0, "rendering_frame": 0}

    # ---- identity and pose --------------------------------------------------------------------------------
    @property
    def name(self) -> str:
        """The sensor's name."""
        return self._name

    @property
    def prim_path(self) -> str:
        """The lidar prim's path."""
        return str(self._prim.GetPath())

    @property
    def prim(self) -> Usd.Prim:
        """The lidar prim."""
        return self._prim

    def is_valid(self) -> bool:
        """Whether the lidar prim still exists."""
        return bool(self._prim and self._prim.IsValid())

    def get_world_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(position, orientation w x y z) in the world."""
        m = np.array(UsdGeom.Xformable(self._prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
        q = Gf.Matrix4d(m.tolist()).ExtractRotationQuat()
        return m[3, :3].copy(), np.array([q.GetReal(), *q.GetImaginary()])

    def set_world_pose(self, position: Any = None, orientation: Any = None) -> None:
        """Place the lidar in the world (position; orientation w x y z)."""
        parent = np.array(UsdGeom.Xformable(self._prim.GetParent()).ComputeLocalToWorldTransform(
            Usd.TimeCode.Default())) if self._prim.GetParent().IsA(UsdGeom.Xformable) else np.eye(4)
        world = np.eye(4)
        pos, quat = self.get_world_pose()
        pos = pos if position is None else np.asarray(position, dtype=np.float64)
        quat = quat if orientation is None else np.asarray(orientation, dtype=np.float64)
        world[:3, :3] = np.array(Gf.Matrix3d(Gf.Quatd(*quat.tolist())))
        world[3, :3] = pos
        local = world @ np.linalg.inv(parent)
        q = Gf.Matrix4d(local.tolist()).ExtractRotationQuat()
        self.set_local_pose(local[3, :3], [q.GetReal(), *q.GetImaginary()])

    def get_local_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(translation, orientation w x y z) relative to the parent."""
        m = np.array(UsdGeom.Xformable(self._prim).GetLocalTransformation(Usd.TimeCode.Default()))
        q = Gf.Matrix4d(m.tolist()).ExtractRotationQuat()
        return m[3, :3].copy(), np.array([q.GetReal(), *q.GetImaginary()])

    def set_local_pose(self, translation: Any = None, orientation: Any = None) -> None:
        """Place the lidar relative to its parent (translation; orientation w x y z)."""
        set_local_pose(self._prim, position=translation, rotation=orientation)

    # ---- annotators and writers ---------------------------------------------------------------------------
    def get_render_product_path(self) -> str:
        """The lidar's render product path (its ``RenderProduct`` prim is authored in the session layer)."""
        sync_product_prims()
        return self._render_product.path

    def _refuse_camera_lidar(self, what: str) -> None:
        if self._prim.GetTypeName() == "Camera":
            raise CompatError(f"LidarRtx({self.prim_path!r}): {what} needs an OmniLidar prim; a Camera prim as a "
                              f"lidar is Isaac Sim 4's deprecated form, which graphsdg does not scan with "
                              f"(docs/sensors.md)")

    def get_annotators(self) -> dict:
        """The attached annotators by name."""
        return self._annotators

    def attach_annotator(self, annotator_name: str, **kwargs: Any) -> None:
        """Attach annotator ``annotator_name`` (initialized with ``kwargs``) to the lidar's render product."""
        self._refuse_camera_lidar(f"annotator {annotator_name!r}")
        if annotator_name in self._annotators:
            log.warning("Annotator %s already attached to %s", annotator_name, self._render_product.path)
            return
        annotator = graphsdg.AnnotatorRegistry.get_annotator(annotator_name)
        annotator.initialize(**kwargs)
        self._annotators[annotator_name] = annotator.attach([self._render_product.path])

    def detach_annotator(self, annotator_name: str) -> None:
        """Detach annotator ``annotator_name``."""
        annotator = self._annotators.pop(annotator_name, None)
        if annotator is None:
            log.warning("Annotator %s not attached to %s", annotator_name, self._render_product.path)
        else:
            annotator.detach()

    def detach_all_annotators(self) -> None:
        """Detach every annotator."""
        for name in list(self._annotators):
            self.detach_annotator(name)

    def get_writers(self) -> dict:
        """The attached writers by name."""
        return self._writers

    def attach_writer(self, writer_name: str, **kwargs: Any) -> None:
        """Attach writer ``writer_name`` (initialized with ``kwargs``) to the lidar's render product."""
        self._refuse_camera_lidar(f"writer {writer_name!r}")
        if writer_name in self._writers:
            log.warning("Writer %s already attached to %s", writer_name, self._render_product.path)
            return
        writer = graphsdg.writers.get(writer_name)
        writer.initialize(**kwargs)
        writer.attach([self._render_product.path])
        self._writers[writer_name] = writer

    def detach_writer(self, writer_name: str) -> None:
        """Detach writer ``writer_name``."""
        writer = self._writers.pop(writer_name, None)
        if writer is None:
            log.warning("Writer %s not attached to %s", writer_name, self._render_product.path)
        else:
            writer.detach()

    def detach_all_writers(self) -> None:
        """Detach every writer."""
        for name in list(self._writers):
            self.detach_writer(name)

    def enable_visualization(self) -> None:
        """Attach the debug-draw writer (headless: it writes the points, docs/sensors.md)."""
        self.attach_writer(self._VISUALIZATION_WRITER)

    def disable_visualization(self) -> None:
        """Detach the debug-draw writer."""
        self.detach_writer(self._VISUALIZATION_WRITER)

    # ---- data ---------------------------------------------------------------------------------------------
    def initialize(self, physics_sim_view: Any = None) -> None:
        """Start reporting the annotators' data in :meth:`get_current_frame`; the timeline pausing or stopping
        pauses the lidar, playing resumes it."""
        self._initialized = True
        timeline = runtime().timeline
        self._timeline_subscriptions = [
            timeline.subscribe(lambda event: self.pause(), TimelineEventType.PAUSE),
            timeline.subscribe(lambda event: self.pause(), TimelineEventType.STOP),
            timeline.subscribe(lambda event: self.resume(), TimelineEventType.PLAY)]

    def post_reset(self) -> None:
        """Nothing to reset."""

    def pause(self) -> None:
        """Stop refreshing :meth:`get_current_frame`."""
        self._initialized = False

    def resume(self) -> None:
        """Refresh :meth:`get_current_frame` again."""
        self._initialized = True

    def is_paused(self) -> bool:
        """Whether :meth:`get_current_frame` is not being refreshed."""
        return not self._initialized

    def get_current_frame(self) -> dict:
        """The latest capture's data: ``rendering_time``, each annotator's data by name, and the flat scan's
        ``linear_depth_data`` / ``intensities_data`` / ``azimuth_range`` / ``horizontal_resolution``."""
        if self._initialized and (self._annotators or self._writers):
            self._current_frame["rendering_time"] = float(runtime().sim.data.time)
            for name, annotator in self._annotators.items():
                self._current_frame[name] = annotator.get_data()
            flat = self._current_frame.get("IsaacComputeRTXLidarFlatScan")
            if isinstance(flat, dict):
                for key, source in (("linear_depth_data", "linearDepthData"), ("intensities_data", "intensitiesData"),
                                    ("azimuth_range", "azimuthRange"), ("horizontal_resolution",
                                                                        "horizontalResolution")):
                    self._current_frame[key] = flat.get(source)
        return self._current_frame

    def _flat(self, key: str) -> Any:
        if "IsaacComputeRTXLidarFlatScan" not in self._annotators:
            return None
        flat = self.get_current_frame().get("IsaacComputeRTXLidarFlatScan")
        return flat.get(key) if isinstance(flat, dict) else None

    def get_horizontal_resolution(self) -> float | None:
        """The flat scan's horizontal resolution (degrees), when its annotator is attached."""
        return self._flat("horizontalResolution")

    def get_horizontal_fov(self) -> float | None:
        """The flat scan's horizontal field of view (degrees)."""
        return self._flat("horizontalFov")

    def get_num_rows(self) -> int | None:
        """The flat scan's rows."""
        return self._flat("numRows")

    def get_num_cols(self) -> int | None:
        """The flat scan's columns."""
        return self._flat("numCols")

    def get_rotation_frequency(self) -> float | None:
        """The flat scan's rotation rate (Hz)."""
        return self._flat("rotationRate")

    def get_depth_range(self) -> Any:
        """The flat scan's depth range [near, far] (m)."""
        return self._flat("depthRange")

    def get_azimuth_range(self) -> Any:
        """The flat scan's azimuth range [min, max] (degrees)."""
        return self._flat("azimuthRange")

    @staticmethod
    def decode_stable_id_mapping(stable_id_mapping_raw: bytes) -> dict:
        """``{stable id: prim path}`` of a ``StableIdMap`` buffer."""
        return parse_stable_id_map_data(np.frombuffer(bytes(stable_id_mapping_raw), np.uint8))

    @staticmethod
    def get_object_ids(obj_ids: np.ndarray) -> list[int]:
        """Each 16-byte object id of a GMO ``objId`` buffer as a Python int."""
        return parse_object_ids(obj_ids)


def _deprecated_frame_method(name: str) -> Any:
    def method(self: LidarRtx) -> None:
        log.warning("%s is deprecated as of Isaac Sim 5.0; the data is in the current frame when its annotator is "
                    "attached (attach_annotator('IsaacComputeRTXLidarFlatScan')).", name)
    method.__name__ = name
    method.__doc__ = "Deprecated in Isaac Sim 5.0: annotators' data is in the current frame when they are attached."
    return method


for _what in ("point_cloud_data", "linear_depth_data", "intensities_data", "azimuth_range", "horizontal_resolution",
              "range_data", "azimuth_data", "elevation_data"):
    for _verb in ("add", "remove"):
        setattr(LidarRtx, f"{_verb}_{_what}_to_frame", _deprecated_frame_method(f"{_verb}_{_what}_to_frame"))


def modules() -> list[types.ModuleType]:
    """The compat modules of this area (module docstring)."""
    commands = {cls.__name__.removesuffix("Command"): cls for cls in COMMANDS}
    commands.update({cls.__name__: cls for cls in COMMANDS})
    return [CompatModule(NAME, LidarRtx=LidarRtx, get_gmo_data=get_gmo_data,
                         apply_nonvisual_material=apply_nonvisual_material, get_material_id=get_material_id,
                         decode_material_id=surface_materials.decode_material_id,
                         BASE_MATERIALS=dict(surface_materials.BASES), COATINGS=dict(surface_materials.COATINGS),
                         ATTRIBUTES=dict(surface_materials.ATTRIBUTES), **_label_constants(),
                         SUPPORTED_LIDAR_CONFIGS=SUPPORTED_LIDAR_CONFIGS,
                         SUPPORTED_LIDAR_VARIANT_SET_NAME=SUPPORTED_LIDAR_VARIANT_SET_NAME,
                         IsaacSensorCreateRtxSensor=IsaacSensorCreateRtxSensorCommand, **commands),
            generic_model_output_module(f"{NAME}.generic_model_output"),
            CompatModule(f"{NAME}.sensor_checker", **CHECKER_NAMES)]


def install() -> None:
    """Register the RTX sensor commands (Kit registers them when the extension starts)."""
    for command in COMMANDS:
        kit_command_registry.register(command)


def uninstall() -> None:
    """Unregister the RTX sensor commands."""
    for command in COMMANDS:
        kit_command_registry.unregister(command)
