"""The GenericModelOutput (GMO) byte layout: encoding a sensor's returns, and reading a buffer back.

RTX sensors hand their returns to Isaac Sim as one contiguous, packed, little-endian buffer that Isaac's parser
(``getModelOutputFromBuffer``) reads. graphsdg writes the same layout, so Isaac's scripts read graphsdg's
buffers unchanged:

* a 264-byte header: magic ``NGMO`` (0x4E474D4F), version 1.0.0, the buffer's size in bytes (bytes 16-23),
  the element count (24-27), frame of reference and motion-compensation state (u16 each), frame id, timestamp
  (ns), coordinate type, output type, a model-to-app matrix (16 float32), the sensor's pose at the frame's start
  and end (each: timestamp ns, orientation x y z w and position in metres as float32, 4 padding bytes), the
  auxiliary type and the modality, then seven pointer slots (zero in a buffer: a reader points them into it);
* the elements, one array after the other: ``timeOffsetNs`` (int32), ``x``, ``y``, ``z``, ``scalar`` (float32)
  and ``flags`` (uint8), padded to 8 bytes; spherical coordinates hold azimuth and elevation in degrees and
  the range in metres in ``x``, ``y``, ``z``;
* the auxiliary data of the modality when the auxiliary type is not ``NONE``: for a lidar an 88-byte block
  (scan complete, azimuth offset, which members follow, padding, nine pointer slots) and the members it lists,
  in this order: emitter id, channel id, material id, tick id (uint32), hit normals, velocities (3 float32),
  object ids (16 bytes: a 128-bit stable id), echo id, tick state (uint8); for a radar a 56-byte block
  (sensor id, scan index, cycle count, unambiguous range / velocity / angle limits, a pointer slot) and the
  radial velocities (float32).

Example:
    >>> import numpy as np
    >>> buffer = encode(GmoContent(modality=Modality.LIDAR, timestamp_ns=5, x=np.array([10.0]), y=np.zeros(1),
    ...                            z=np.array([3.0]), scalar=np.array([0.5])))
    >>> gmo = decode(buffer)
    >>> gmo.magicNumber == MAGIC_NUMBER, gmo.numElements, gmo.sizeInBytes == len(buffer), gmo.z.tolist()
    (True, 1, True, [3.0])
"""
from __future__ import annotations

import enum
import struct
from dataclasses import dataclass, field

import numpy as np

MAGIC_NUMBER = 0x4E474D4F
HEADER_SIZE = 264
LIDAR_AUX_SIZE = 88
RADAR_AUX_SIZE = 56
_FRAME = struct.Struct("<Q4f3f4x")
_HEAD = struct.Struct("<4IQIHHQQII16f")   # up to and including the model-to-app matrix (120 bytes)
_TAIL = struct.Struct("<II7Q")            # aux type, modality, 6 element pointers, aux pointer


class AuxType(enum.IntEnum):
    """How much auxiliary data follows the elements."""

    NONE = 0
    BASIC = 1
    EXTRA = 2
    FULL = 3


class Modality(enum.IntEnum):
    """Which kind of sensor made the output."""

    UNDEFINED = 0
    LIDAR = 1
    RADAR = 2
    ACOUSTIC = 3
    IDS = 4


class CoordsType(enum.IntEnum):
    """What the elements' x, y, z hold."""

    CARTESIAN = 0
    SPHERICAL = 1
    NOT_APPLICABLE = 2


class FrameOfReference(enum.IntEnum):
    """The frame the elements are expressed in."""

    SENSOR = 0
    WORLD = 1
    CUSTOM = 2
    PARENT = 3


class MotionCompensationState(enum.IntEnum):
    """Whether the sensor's own motion was removed from the elements."""

    NONCOMPENSATED = 0
    COMPENSATED = 1
    NOT_APPLICABLE = 2


class OutputType(enum.IntEnum):
    """The kind of output (a point cloud)."""

    POINTCLOUD = 0


class ElementFlags(enum.IntEnum):
    """Per-element flags (``VALID``: a real return)."""

    FLAG_1 = 0
    FLAG_2 = 1 << 0
    FLAG_3 = 1 << 1
    FLAG_4 = 1 << 2
    FLAG_5 = 1 << 3
    FLAG_6 = 1 << 4
    FLAG_7 = 1 << 5
    VALID = 1 << 6


class LidarAuxHas(enum.IntFlag):
    """Which lidar auxiliary members a buffer holds."""

    NONE = 0
    EMITTER_ID = 1 << 0
    CHANNEL_ID = 1 << 1
    ECHO_ID = 1 << 2
    MAT_ID = 1 << 3
    OBJ_ID = 1 << 4
    TICK_ID = 1 << 5
    TICK_STATES = 1 << 6
    HIT_NORMALS = 1 << 7
    VELOCITIES = 1 << 8


class IDSAuxHas(enum.IntFlag):
    """Which IDS auxiliary members a buffer holds."""

    NONE = 0
    VELOCITIES = 1 << 0


# lidar aux members: (flag, name, dtype, values per element), in buffer order
LIDAR_MEMBERS = ((LidarAuxHas.EMITTER_ID, "emitterId", np.uint32, 1),
                 (LidarAuxHas.CHANNEL_ID, "channelId", np.uint32, 1),
                 (LidarAuxHas.MAT_ID, "matId", np.uint32, 1), (LidarAuxHas.TICK_ID, "tickId", np.uint32, 1),
                 (LidarAuxHas.HIT_NORMALS, "hitNormals", np.float32, 3),
                 (LidarAuxHas.VELOCITIES, "velocities", np.float32, 3), (LidarAuxHas.OBJ_ID, "objId", np.uint8, 16),
                 (LidarAuxHas.ECHO_ID, "echoId", np.uint8, 1), (LidarAuxHas.TICK_STATES, "tickStates", np.uint8, 1))

#: the lidar members each auxiliary level fills
LIDAR_LEVEL_MEMBERS = {
    AuxType.NONE: LidarAuxHas.NONE,
    AuxType.BASIC: LidarAuxHas.EMITTER_ID | LidarAuxHas.CHANNEL_ID | LidarAuxHas.TICK_ID | LidarAuxHas.ECHO_ID
    | LidarAuxHas.TICK_STATES,
}
LIDAR_LEVEL_MEMBERS[AuxType.EXTRA] = LIDAR_LEVEL_MEMBERS[AuxType.BASIC] | LidarAuxHas.OBJ_ID | LidarAuxHas.MAT_ID
LIDAR_LEVEL_MEMBERS[AuxType.FULL] = LIDAR_LEVEL_MEMBERS[AuxType.EXTRA] | LidarAuxHas.HIT_NORMALS | \
    LidarAuxHas.VELOCITIES


@dataclass
class FramePose:
    """A sensor pose at a time: ``timestampNs``, ``orientation`` (x, y, z, w), ``posM`` (metres)."""

    timestamp_ns: int = 0
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
    position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass
class GmoContent:
    """Everything one buffer holds (arrays of one entry per element; ``aux`` by member name)."""

    modality: Modality
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    scalar: np.ndarray
    time_offset_ns: np.ndarray | None = None
    flags: np.ndarray | None = None
    timestamp_ns: int = 0
    frame_id: int = 0
    coords: CoordsType = CoordsType.SPHERICAL
    frame_of_reference: FrameOfReference = FrameOfReference.SENSOR
    motion_compensation: MotionCompensationState = MotionCompensationState.NONCOMPENSATED
    frame_start: FramePose = field(default_factory=FramePose)
    frame_end: FramePose = field(default_factory=FramePose)
    aux_type: AuxType = AuxType.NONE
    lidar_members: LidarAuxHas = LidarAuxHas.NONE
    scan_complete: bool = True
    azimuth_offset: float = 0.0
    aux: dict[str, np.ndarray] = field(default_factory=dict)
    radar_limits: dict[str, float] = field(default_factory=dict)


def _pad8(size: int) -> int:
    return (8 - size % 8) % 8


def _frame_bytes(pose: FramePose) -> bytes:
    return _FRAME.pack(int(pose.timestamp_ns), *[float(v) for v in pose.orientation],
                       *[float(v) for v in pose.position_m])


def encode(content: GmoContent) -> np.ndarray:
    """The GMO buffer (uint8) of ``content``."""
    n = len(content.x)
    offsets = content.time_offset_ns if content.time_offset_ns is not None else np.zeros(n, np.int32)
    flags = content.flags if content.flags is not None else np.full(n, ElementFlags.VALID, np.uint8)
    body = b"".join([np.asarray(offsets, "<i4").tobytes(), np.asarray(content.x, "<f4").tobytes(),
                     np.asarray(content.y, "<f4").tobytes(), np.asarray(content.z, "<f4").tobytes(),
                     np.asarray(content.scalar, "<f4").tobytes(), np.asarray(flags, np.uint8).tobytes()])
    body += b"\0" * _pad8(HEADER_SIZE + len(body))
    aux = b""
    if content.aux_type != AuxType.NONE and content.modality == Modality.LIDAR:
        members = LidarAuxHas(content.lidar_members)
        aux = struct.pack("<IfI4x9Q", int(bool(content.scan_complete)), float(content.azimuth_offset), int(members),
                          *([0] * 9))
        for flag, name, dtype, width in LIDAR_MEMBERS:
            if members & flag:
                values = np.asarray(content.aux[name], dtype=dtype).reshape(-1)
                if values.size != n * width:
                    raise ValueError(f"GMO lidar member {name} has {values.size} values; expected {n * width}")
                aux += values.astype(np.dtype(dtype).newbyteorder("<")).tobytes()
    elif content.aux_type != AuxType.NONE and content.modality == Modality.RADAR:
        limits = content.radar_limits
        aux = struct.pack("<BB6xQ7f4xQ", int(limits.get("sensorID", 0)), int(limits.get("scanIdx", 0)),
                          int(limits.get("cycleCnt", 0)),
                          *[float(limits.get(k, 0.0)) for k in ("maxRangeM", "minVelMps", "maxVelMps", "minAzRad",
                                                                  "maxAzRad", "minElRad", "maxElRad")], 0)
        aux += np.asarray(content.aux["rv_ms"], "<f4").tobytes()
    size = HEADER_SIZE + len(body) + len(aux)
    head = _HEAD.pack(MAGIC_NUMBER, 1, 0, 0, size, n, int(content.frame_of_reference),
                      int(content.motion_compensation), int(content.frame_id), int(content.timestamp_ns),
                      int(content.coords), int(OutputType.POINTCLOUD), *np.eye(4, dtype=np.float32).reshape(-1))
    head += _frame_bytes(content.frame_start) + _frame_bytes(content.frame_end)
    head += _TAIL.pack(int(content.aux_type), int(content.modality), *([0] * 7))
    assert len(head) == HEADER_SIZE
    return np.frombuffer(head + body + aux, dtype=np.uint8).copy()


class FrameAtTime:
    """A decoded frame pose: ``timestampNs``, ``orientation`` [x, y, z, w], ``posM`` [x, y, z]."""

    def __init__(self, timestamp_ns: int = 0, orientation=(0.0, 0.0, 0.0, 1.0), pos_m=(0.0, 0.0, 0.0)) -> None:
        self.timestampNs = int(timestamp_ns)
        self.orientation = [float(v) for v in orientation]
        self.posM = [float(v) for v in pos_m]

    def __repr__(self) -> str:
        return f"FrameAtTime(timestampNs={self.timestampNs}, orientation={self.orientation}, posM={self.posM})"


class GenericModelOutput:
    """A decoded GMO buffer, with the field names of Isaac's ``generic_model_output.GenericModelOutput``.

    Made empty (no elements, the right magic number) or by :func:`decode`; the arrays are copies.
    """

    def __init__(self) -> None:
        self.magicNumber = MAGIC_NUMBER
        self.majorVersion, self.minorVersion, self.patchVersion = 1, 0, 0
        self.sizeInBytes = HEADER_SIZE
        self.numElements = 0
        self.frameOfReference = FrameOfReference.SENSOR
        self.motionCompensationState = MotionCompensationState.NOT_APPLICABLE
        self.frameId = 0
        self.timestampNs = 0
        self.elementsCoordsType = CoordsType.SPHERICAL
        self.outputType = OutputType.POINTCLOUD
        self.modelToAppTransform = np.eye(4, dtype=np.float32).reshape(-1)
        self.frameStart, self.frameEnd = FrameAtTime(), FrameAtTime()
        self.auxType = AuxType.NONE
        self.modality = Modality.UNDEFINED
        empty_f, empty_u = np.zeros(0, np.float32), np.zeros(0, np.uint32)
        self.timeOffsetNs = np.zeros(0, np.int32)
        self.x = self.y = self.z = self.scalar = empty_f
        self.flags = np.zeros(0, np.uint8)
        self.scanComplete, self.azimuthOffset = 0, 0.0
        self.filledAuxMembers = LidarAuxHas.NONE
        self.emitterId = self.channelId = self.matId = self.tickId = empty_u
        self.hitNormals = self.velocities = empty_f
        self.objId = self.echoId = self.tickStates = np.zeros(0, np.uint8)
        self.sensorID = self.scanIdx = self.cycleCnt = 0
        self.maxRangeM = self.minVelMps = self.maxVelMps = 0.0
        self.minAzRad = self.maxAzRad = self.minElRad = self.maxElRad = 0.0
        self.rv_ms = empty_f

    @property
    def timeOffSetNs(self) -> np.ndarray:
        """The older spelling of :attr:`timeOffsetNs`."""
        return self.timeOffsetNs

    def __repr__(self) -> str:
        return (f"GenericModelOutput(modality={self.modality.name}, numElements={self.numElements}, "
                f"timestampNs={self.timestampNs})")


def _frame_at(raw: bytes, offset: int) -> FrameAtTime:
    values = _FRAME.unpack_from(raw, offset)
    return FrameAtTime(values[0], values[1:5], values[5:8])


def decode(buffer: "np.ndarray | bytes | bytearray | memoryview") -> GenericModelOutput:
    """The :class:`GenericModelOutput` a buffer holds; one with ``magicNumber`` 0 when it is not a GMO."""
    raw = bytes(np.asarray(buffer, dtype=np.uint8).reshape(-1).tobytes()) if isinstance(buffer, np.ndarray) \
        else bytes(buffer)
    out = GenericModelOutput()
    if len(raw) < HEADER_SIZE or struct.unpack_from("<I", raw, 0)[0] != MAGIC_NUMBER:
        out.magicNumber = 0
        return out
    head = _HEAD.unpack_from(raw, 0)
    (out.magicNumber, out.majorVersion, out.minorVersion, out.patchVersion, out.sizeInBytes, n,
     frame_of_reference, motion, out.frameId, out.timestampNs, coords, output_type) = head[:12]
    out.modelToAppTransform = np.array(head[12:], dtype=np.float32)
    out.numElements = n
    out.frameOfReference = FrameOfReference(frame_of_reference)
    out.motionCompensationState = MotionCompensationState(motion)
    out.elementsCoordsType, out.outputType = CoordsType(coords), OutputType(output_type)
    out.frameStart, out.frameEnd = _frame_at(raw, 120), _frame_at(raw, 160)
    aux_type, modality = struct.unpack_from("<II", raw, 200)
    out.auxType, out.modality = AuxType(aux_type), Modality(modality)
    offset = HEADER_SIZE

    def take(dtype, count: int) -> np.ndarray:
        nonlocal offset
        array = np.frombuffer(raw, dtype=dtype, count=count, offset=offset).copy()
        offset += array.nbytes
        return array

    out.timeOffsetNs = take("<i4", n)
    out.x, out.y, out.z, out.scalar = (take("<f4", n) for _ in range(4))
    out.flags = take(np.uint8, n)
    offset += _pad8(offset)
    if out.auxType != AuxType.NONE and out.modality == Modality.LIDAR:
        out.scanComplete, out.azimuthOffset, members = struct.unpack_from("<IfI", raw, offset)
        out.filledAuxMembers = LidarAuxHas(members)
        offset += LIDAR_AUX_SIZE
        for flag, name, dtype, width in LIDAR_MEMBERS:
            if members & flag:
                setattr(out, name, take(np.dtype(dtype).newbyteorder("<"), n * width))
    elif out.auxType != AuxType.NONE and out.modality == Modality.RADAR:
        values = struct.unpack_from("<BB6xQ7f", raw, offset)
        out.sensorID, out.scanIdx, out.cycleCnt = values[:3]
        (out.maxRangeM, out.minVelMps, out.maxVelMps, out.minAzRad, out.maxAzRad, out.minElRad,
         out.maxElRad) = values[3:]
        offset += RADAR_AUX_SIZE
        out.rv_ms = take("<f4", n)
    return out
