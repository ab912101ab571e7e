"""Point clouds as files people open: NumPy structured arrays, PLY and PCD.

A point cloud is a NumPy structured array: ``x``, ``y``, ``z`` (float32, metres) and any further per-point
fields (``intensity``, ``object_id``, ...). It is written as

* ``.npy``: the structured array itself (``np.load`` gives it back, field names included);
* ``.ply``: binary little-endian PLY, one ``vertex`` element with a property per field (MeshLab, CloudCompare,
  Open3D, Blender read it);
* ``.pcd``: binary PCD v0.7 (PCL, Open3D, CloudCompare), ``FIELDS`` in the same order.

:func:`read_ply` and :func:`read_pcd` read those files back (the tests and ``graphsdg view`` use them).

Example:
    >>> import numpy as np
    >>> cloud = np.zeros(2, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("object_id", "<u4")])
    >>> cloud["x"] = [1, 2]; cloud["object_id"] = [7, 9]
    >>> back = read_ply(encode_ply(cloud))
    >>> back["x"].tolist(), back["object_id"].tolist()
    ([1.0, 2.0], [7, 9])
    >>> read_pcd(encode_pcd(cloud))["object_id"].tolist()
    [7, 9]
"""
from __future__ import annotations

import numpy as np

# numpy dtype -> (PLY type name, PCD (type, size))
_PLY = {"f4": "float", "f8": "double", "u1": "uchar", "i1": "char", "u2": "ushort", "i2": "short", "u4": "uint",
        "i4": "int"}
_PLY_BACK = {v: k for k, v in _PLY.items()}
_PCD = {"f4": ("F", 4), "f8": ("F", 8), "u1": ("U", 1), "i1": ("I", 1), "u2": ("U", 2), "i2": ("I", 2),
        "u4": ("U", 4), "i4": ("I", 4), "u8": ("U", 8), "i8": ("I", 8)}


def _little_endian(cloud: np.ndarray) -> np.ndarray:
    names = cloud.dtype.names
    if not names or not {"x", "y", "z"} <= set(names):
        raise ValueError(f"a point cloud is a structured array with x, y and z fields, got dtype {cloud.dtype}")
    dtype = np.dtype([(n, cloud.dtype[n].newbyteorder("<")) for n in names])
    return np.ascontiguousarray(cloud.astype(dtype))


def _code(dtype: np.dtype) -> str:
    return f"{dtype.kind}{dtype.itemsize}"


def encode_ply(cloud: np.ndarray) -> bytes:
    """Binary little-endian PLY bytes of a structured point cloud (64-bit integers are stored as 32-bit)."""
    cloud = _little_endian(cloud)
    fields = []
    for name in cloud.dtype.names:
        dtype = cloud.dtype[name]
        if _code(dtype) in ("u8", "i8"):   # PLY has no 64-bit integers
            dtype = np.dtype("<u4" if dtype.kind == "u" else "<i4")
        if _code(dtype) not in _PLY:
            raise ValueError(f"PLY cannot store field {name!r} of type {cloud.dtype[name]}")
        fields.append((name, dtype))
    cloud = cloud.astype(np.dtype(fields))
    header = ["ply", "format binary_little_endian 1.0", "comment written by graphsdg",
              f"element vertex {len(cloud)}"]
    header += [f"property {_PLY[_code(cloud.dtype[n])]} {n}" for n in cloud.dtype.names]
    header.append("end_header")
    return ("\n".join(header) + "\n").encode("ascii") + cloud.tobytes()


def read_ply(data: bytes) -> np.ndarray:
    """The structured array of a binary little-endian PLY written by :func:`encode_ply`."""
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").splitlines()
    if lines[0] != "ply" or "binary_little_endian" not in lines[1]:
        raise ValueError("not a binary little-endian PLY file")
    count = next(int(line.split()[2]) for line in lines if line.startswith("element vertex"))
    fields = [(line.split()[2], "<" + _PLY_BACK[line.split()[1]]) for line in lines if line.startswith("property")]
    return np.frombuffer(data, dtype=np.dtype(fields), count=count, offset=end).copy()


def encode_pcd(cloud: np.ndarray) -> bytes:
    """Binary PCD v0.7 bytes of a structured point cloud."""
    cloud = _little_endian(cloud)
    names = cloud.dtype.names
    types = [_PCD[_code(cloud.dtype[n])] for n in names]
    header = ["# .PCD v0.7 - written by graphsdg", "VERSION 0.7", f"FIELDS {' '.join(names)}",
              f"SIZE {' '.join(str(s) for _, s in types)}", f"TYPE {' '.join(t for t, _ in types)}",
              f"COUNT {' '.join('1' for _ in names)}", f"WIDTH {len(cloud)}", "HEIGHT 1", "VIEWPOINT 0 0 0 1 0 0 0",
              f"POINTS {len(cloud)}", "DATA binary"]
    return ("\n".join(header) + "\n").encode("ascii") + cloud.tobytes()


def read_pcd(data: bytes) -> np.ndarray:
    """The structured array of a binary PCD written by :func:`encode_pcd`."""
    marker = data.index(b"DATA binary\n") + len(b"DATA binary\n")
    header = dict(line.split(" ", 1) for line in data[:marker].decode("ascii").splitlines() if not line.startswith("#"))
    names, sizes, types = header["FIELDS"].split(), header["SIZE"].split(), header["TYPE"].split()
    kinds = {"F": "f", "U": "u", "I": "i"}
    dtype = np.dtype([(n, f"<{kinds[t]}{s}") for n, s, t in zip(names, sizes, types)])
    return np.frombuffer(data, dtype=dtype, count=int(header["POINTS"]), offset=marker).copy()
