"""Reading point-cloud files (PLY, PCD, NumPy) into a :class:`~graphsdg.dataset.view_frame.PointCloud`.

Lidar and radar writers save one cloud per frame. The readers take the
positions (``x y z``) and, where present, colour (``red green blue`` or PCD's
packed ``rgb``), a class id per point (``semantic``, ``label``, ``class`` or
``object_class``) and an object id (``instance``, ``object_id``, ``obj_id``);
other properties (intensity, ring, time) are ignored. Formats: PLY (ascii,
binary little- and big-endian; the ``vertex`` element), PCD (ascii and binary;
``binary_compressed`` is refused by name), ``.npy`` (a structured array with
those field names, or an (N, >= 3) array whose first three columns are x y z).

Example:
    >>> ply = b"ply\\nformat ascii 1.0\\nelement vertex 1\\nproperty float x\\nproperty float y\\n" \\
    ...       b"property float z\\nproperty uchar label\\nend_header\\n1 2 3 7\\n"
    >>> cloud = read_point_cloud(ply, "ply", "lidar")
    >>> cloud.positions.tolist(), cloud.semantic_ids.tolist()
    ([[1.0, 2.0, 3.0]], [7])
"""
from __future__ import annotations

import io

import numpy as np

from graphsdg.dataset.view_frame import PointCloud

POINT_CLOUD_EXTENSIONS = ("ply", "pcd")
SEMANTIC_FIELDS = ("semantic", "label", "class", "object_class", "semantic_id")
INSTANCE_FIELDS = ("instance", "object_id", "obj_id", "instance_id")
_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def read_point_table(data: bytes, ext: str) -> dict[str, np.ndarray]:
    """Every per-point field (name -> (N,) array) of file bytes ``data`` of type ``ext`` (``ply``, ``pcd`` or
    ``npy``)."""
    ext = ext.lower().lstrip(".")
    if ext == "ply":
        return _read_ply(data)
    if ext == "pcd":
        return _read_pcd(data)
    if ext == "npy":
        return _from_array(np.load(io.BytesIO(data)))
    raise ValueError(f"unknown point-cloud file type {ext!r}; known: ply, pcd, npy")


def read_point_cloud(data: bytes, ext: str, name: str) -> PointCloud:
    """The cloud in file bytes ``data`` of type ``ext`` (``ply``, ``pcd`` or ``npy``), named ``name``."""
    return point_cloud(read_point_table(data, ext), name)


def _from_array(arr: np.ndarray) -> dict[str, np.ndarray]:
    if arr.dtype.names:
        return {n: arr[n] for n in arr.dtype.names}
    arr = np.asarray(arr)
    if arr.ndim != 2 or arr.shape[1] < 3:
        raise ValueError(f"a point-cloud array needs shape (N, 3) or more columns, or named fields; got {arr.shape}")
    return {"x": arr[:, 0], "y": arr[:, 1], "z": arr[:, 2]}


def point_cloud(table: dict[str, np.ndarray], name: str) -> PointCloud:
    """A :class:`PointCloud` (frame ``"sensor"``) of a table of per-point fields."""
    lower = {k.lower(): v for k, v in table.items()}
    missing = [k for k in ("x", "y", "z") if k not in lower]
    if missing:
        raise ValueError(f"point cloud {name!r} has no {', '.join(missing)} field; fields: {sorted(table)}")
    positions = np.stack([lower["x"], lower["y"], lower["z"]], axis=1).astype(np.float32)
    colors = None
    if all(k in lower for k in ("red", "green", "blue")):
        colors = np.stack([lower["red"], lower["green"], lower["blue"]], axis=1).astype(np.uint8)
    elif "rgb" in lower:   # PCD's packed colour: a float32 (or uint32) holding 0x00RRGGBB
        packed = np.ascontiguousarray(lower["rgb"]).view(np.uint32)
        colors = np.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], axis=1).astype(np.uint8)
    semantic = next((lower[k] for k in SEMANTIC_FIELDS if k in lower), None)
    instance = next((lower[k] for k in INSTANCE_FIELDS if k in lower), None)
    return PointCloud(name, positions, "sensor", colors=colors,
                      semantic_ids=None if semantic is None else semantic.astype(np.int64),
                      instance_ids=None if instance is None else instance.astype(np.int64))


def _header_lines(data: bytes, end: bytes) -> tuple[list[str], int]:
    at = data.find(end)
    if at < 0:
        raise ValueError(f"point-cloud header has no {end.decode().strip()!r} line")
    stop = at + len(end)
    return data[:stop].decode("ascii", errors="replace").splitlines(), stop


def _read_ply(data: bytes) -> dict[str, np.ndarray]:
    if not data.startswith(b"ply"):
        raise ValueError("not a PLY file: it does not start with 'ply'")
    lines, body = _header_lines(data, b"end_header\n")
    fmt, elements, current = "", [], None
    for line in lines:
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "format":
            fmt = parts[1]
        elif parts[0] == "element":
            current = (parts[1], int(parts[2]), [])
            elements.append(current)
        elif parts[0] == "property" and current is not None:
            if parts[1] == "list":
                raise ValueError(f"PLY element {current[0]!r} has a list property; a point cloud has none in "
                                 f"its vertex element")
            current[2].append((parts[2], _PLY_TYPES[parts[1]]))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise ValueError(f"unknown PLY format {fmt!r}")
    order = "<" if fmt != "binary_big_endian" else ">"
    offset, text_rows = body, data[body:].decode("ascii", errors="replace").split("\n") if fmt == "ascii" else []
    row = 0
    for name, count, props in elements:
        dtype = np.dtype([(p, order + t) for p, t in props])
        if fmt == "ascii":
            values = np.array([[float(v) for v in text_rows[row + i].split()] for i in range(count)]).reshape(
                count, len(props))
            row += count
            table = {p: values[:, i].astype(t) for i, (p, t) in enumerate(props)}
        else:
            arr = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
            offset += count * dtype.itemsize
            table = {p: arr[p] for p, _ in props}
        if name == "vertex":
            return table
    raise ValueError("PLY file has no vertex element")


def _read_pcd(data: bytes) -> dict[str, np.ndarray]:
    head = data[:4096].decode("ascii", errors="replace")
    marker = next((m for m in ("DATA ascii", "DATA binary_compressed", "DATA binary") if m in head), None)
    if marker is None:
        raise ValueError("not a PCD file: no DATA line in its header")
    lines, body = _header_lines(data, (marker + "\n").encode())
    fields: dict[str, list[str]] = {}
    for line in lines:
        parts = line.split()
        if parts and parts[0] in ("FIELDS", "SIZE", "TYPE", "COUNT", "POINTS"):
            fields[parts[0]] = parts[1:]
    if marker == "DATA binary_compressed":
        raise ValueError("PCD 'binary_compressed' data is not supported; save the cloud as ascii or binary")
    names, sizes, types = fields["FIELDS"], fields["SIZE"], fields["TYPE"]
    counts = fields.get("COUNT", ["1"] * len(names))
    n = int(fields["POINTS"][0])
    kinds = {"F": "f", "U": "u", "I": "i"}
    dtype = np.dtype([(nm, f"<{kinds[t]}{s}", (int(c),)) if int(c) > 1 else (nm, f"<{kinds[t]}{s}")
                      for nm, s, t, c in zip(names, sizes, types, counts)])
    if marker == "DATA ascii":
        rows = [r.split() for r in data[body:].decode("ascii").splitlines() if r.strip()][:n]
        values = np.array(rows, dtype=np.float64).reshape(n, -1)
        out, col = {}, 0
        for nm, c in zip(names, counts):
            width = int(c)
            column = values[:, col] if width == 1 else values[:, col:col + width]
            if nm == "rgb":   # packed colour written as the float's value
                column = column.astype(np.float32)
            out[nm] = column.astype(dtype[nm].base) if nm != "rgb" else column
            col += width
        return out
    arr = np.frombuffer(data, dtype=dtype, count=n, offset=body)
    return {nm: arr[nm] for nm in names}
