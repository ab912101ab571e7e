"""MuJoCo's scene geoms (``MjvScene.geoms``) as one numpy structured array over their memory.

Two passes of every render read or write a few fields of every geom in the
scene: the id colours' code -> geom table (``segid``, ``objtype``, ``objid``) and
the rescaled meshes' matrices (``type``, ``objid``, ``mat``). Through the Python
bindings each geom is an object and each field an attribute, the largest
per-object cost of a crowded frame (docs/performance.md, "Scene geoms as one
array"). Over the same memory as a structured array each pass is a few array
operations.

The view is laid over the bindings' own memory: its address comes from a field
the bindings already expose as an array (``size``), its stride from two
consecutive geoms. The integer fields sit before ``size`` and their number
differs across MuJoCo releases (ten in MuJoCo 4, eight before 3.3), so each
candidate layout is checked against the attributes of a scene's geoms once; when
none matches (a future release), :func:`geom_array` returns None and callers use
the attributes.

Example:
    >>> import mujoco
    >>> m = mujoco.MjModel.from_xml_string(
    ...     "<mujoco><worldbody>" + "<geom size='.1'/>" * 6 + "</worldbody></mujoco>")
    >>> d = mujoco.MjData(m); mujoco.mj_forward(m, d)
    >>> scene = mujoco.MjvScene(m, maxgeom=100)
    >>> mujoco.mjv_updateScene(m, d, mujoco.MjvOption(), None, mujoco.MjvCamera(),
    ...                        mujoco.mjtCatBit.mjCAT_ALL, scene)
    >>> geom_array(scene)["objid"].tolist()
    [0, 1, 2, 3, 4, 5]
"""
from __future__ import annotations

import ctypes

import mujoco
import numpy as np

# bytes of int fields before ``size`` (type, dataid, objtype, objid, category, ..., segid): MuJoCo >= 3.3 has
# ten (matid, texid, texuniform, texcoord between category and segid), earlier releases eight
_SIZE_OFFSETS = (40, 32)
_CHECKED_FIELDS = ("type", "dataid", "objtype", "objid", "category", "segid")
_MIN_GEOMS_TO_CHECK = 4    # fewer geoms could match a wrong layout by chance; their attribute loop is cheap anyway

_layout: dict[str, int | None] = {}          # "size_offset" once a layout matched (None: none did)
_views: dict[tuple[int, int], np.ndarray] = {}   # (address, maxgeom) -> view of the whole geom buffer
_last: dict[str, object] = {}   # the last scene asked about and its view: every render asks about the same one


def _address(array: np.ndarray) -> int:
    return int(array.__array_interface__["data"][0])


def _dtype(size_offset: int, stride: int) -> np.dtype:
    names = ["type", "dataid", "objtype", "objid", "category", "segid", "size", "pos", "mat"]
    formats = ["<i4"] * 6 + [("<f4", 3), ("<f4", 3), ("<f4", 9)]
    offsets = [0, 4, 8, 12, 16, size_offset - 4, size_offset, size_offset + 12, size_offset + 24]
    return np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": stride})


def _view(base: int, maxgeom: int, size_offset: int, stride: int) -> np.ndarray:
    buffer = (ctypes.c_char * (maxgeom * stride)).from_address(base)
    return np.frombuffer(buffer, dtype=_dtype(size_offset, stride), count=maxgeom)


def _matches(view: np.ndarray, geoms, n: int) -> bool:
    """Whether the first ``n`` rows of ``view`` read what the bindings' attributes read."""
    for i in range(n):
        row, g = view[i], geoms[i]
        if any(int(row[f]) != int(getattr(g, f)) for f in _CHECKED_FIELDS):
            return False
        if not np.array_equal(row["mat"].reshape(3, 3), g.mat):
            return False
    return True


def geom_array(scene: mujoco.MjvScene) -> np.ndarray | None:
    """The scene's first ``ngeom`` geoms as a structured array sharing their memory (writes reach MuJoCo):
    int32 ``type``, ``dataid``, ``objtype``, ``objid``, ``category``, ``segid``; float32 ``size`` (3),
    ``pos`` (3), ``mat`` (9, row-major). None when this MuJoCo's layout is not one checked here.

    Valid while ``scene`` is alive and not reallocated; take it again for each pass.
    """
    last = _last.get("scene")
    if last is scene:          # the renderer's scene again (held here, so its memory is the view's)
        return _last["view"][:scene.ngeom]
    ngeom, maxgeom = int(scene.ngeom), int(scene.maxgeom)
    if maxgeom < 2:
        return None
    geoms = scene.geoms
    first = _address(geoms[0].size)
    stride = _address(geoms[1].size) - first
    key = (first, maxgeom)
    view = _views.get(key)
    if view is not None and view.dtype.itemsize == stride:
        _last.update(scene=scene, view=view)
        return view[:ngeom]
    size_offset = _layout.get("size_offset", 0)
    if size_offset is None:
        return None
    if not size_offset:   # not known yet: find which candidate reads what the attributes read
        if ngeom < _MIN_GEOMS_TO_CHECK:
            return None
        n = min(ngeom, 256)
        found = [c for c in _SIZE_OFFSETS if stride >= c + 60 and
                 _matches(_view(first - c, maxgeom, c, stride), geoms, n)]
        _layout["size_offset"] = size_offset = found[0] if found else None
        if size_offset is None:
            return None
    if len(_views) > 16:   # scenes come and go with recompiles: keep the few alive now
        _views.clear()
    view = _views[key] = _view(first - size_offset, maxgeom, size_offset, stride)
    _last.update(scene=scene, view=view)
    return view[:ngeom]
