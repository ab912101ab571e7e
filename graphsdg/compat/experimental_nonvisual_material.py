"""Isaac compat: ``isaacsim.core.experimental.materials.NonVisualMaterial``: what RTX sensors see of a material.

A non-visual material labels a ``UsdShade.Material`` with a base material, a
coating and an attribute (three custom string attributes
``<prefix>:base``, ``<prefix>:coating``, ``<prefix>:attributes``, ``"none"`` until
set), which lidar / radar sensors read. The prefix is the carb setting
``/rtx/materialDb/nonVisualMaterialSemantics/prefix`` (Isaac's RTX sensor extension
sets it to ``omni:simready:nonvisual``, the default here). A material id packs the
three into 16 bits: base in bits 0-7, coating in bits 8-10, attribute in 11-15,
with the index tables of Isaac's RTX material specification
(:data:`BASES`, :data:`COATINGS`, :data:`ATTRIBUTES`).

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.usd
    >>> from isaacsim.core.experimental.materials import NonVisualMaterial
    >>> _ = omni.usd.get_context().new_stage()
    >>> material = NonVisualMaterial("/World/Looks/Sign", bases="aluminum", coatings="paint", attributes="emissive")
    >>> int(NonVisualMaterial.encode_material_ids(material)[0, 0])
    2305
    >>> NonVisualMaterial.decode_material_ids(2305)
    [('aluminum', 'paint', 'emissive')]
    >>> isaac.uninstall()
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from pxr import Sdf, Usd, UsdShade

from graphsdg.sensors import surface_materials
from graphsdg.sensors.surface_materials import ATTRIBUTES, BASES, COATINGS
from graphsdg.compat.experimental_arguments import resolve_indices
from graphsdg.compat.experimental_prim_base import Prim
from graphsdg.compat.experimental_stage_scope import current_stage
from graphsdg.compat.warp_arrays import WarpLikeArray
from graphsdg.compat.warp_arrays import as_warp_like as _warp

def attribute_names() -> tuple[str, str, str]:
    """The (base, coating, attributes) attribute names under the current prefix setting."""
    return tuple(surface_materials.label_attribute_names())


def _encode(prim: Usd.Prim) -> int:
    def label(name: str) -> str:
        attr = prim.GetAttribute(name)
        value = attr.Get() if attr and attr.IsValid() else None
        return value if isinstance(value, str) else "none"

    return surface_materials.encode_material_id(*(label(name) for name in attribute_names()))


class NonVisualMaterial(Prim):
    """``isaacsim.core.experimental.materials.NonVisualMaterial`` (see the module docstring).

    Wraps existing ``UsdShade.Material`` prims (a visual material gains non-visual
    labels) or defines new materials at paths where there is no prim.
    """

    _compat_name = "isaacsim.core.experimental.materials.NonVisualMaterial"

    def __init__(self, paths: str | Sequence[str], *, bases: str | Sequence[str] | None = None,
                 coatings: str | Sequence[str] | None = None,
                 attributes: str | Sequence[str] | None = None) -> None:
        stage = current_stage()
        existent, nonexistent = Prim.resolve_paths(paths)
        if existent:
            for path in existent:
                if not stage.GetPrimAtPath(path).IsA(UsdShade.Material):
                    raise ValueError(f"the prim at {path} is a {stage.GetPrimAtPath(path).GetTypeName() or 'typeless'}"
                                     f" prim, not a USD Material")
        else:
            for path in nonexistent:
                UsdShade.Material.Define(stage, path)
        super().__init__(existent or nonexistent, resolve_paths=False)
        self._materials = [UsdShade.Material(p) for p in self._prims]
        for prim in self._prims:
            for name in attribute_names():
                if not prim.HasAttribute(name):
                    prim.CreateAttribute(name, Sdf.ValueTypeNames.String, custom=True).Set("none")
        if bases is not None:
            self.set_bases(bases)
        if coatings is not None:
            self.set_coatings(coatings)
        if attributes is not None:
            self.set_attributes(attributes)

    @property
    def materials(self) -> list[UsdShade.Material]:
        """The wrapped ``UsdShade.Material`` objects."""
        return list(self._materials)

    # ---- labels ------------------------------------------------------------------------------------------
    def _set_labels(self, which: int, values: str | Sequence[str], indices: Any, table: dict[str, int],
                    what: str) -> None:
        self._check_valid()
        idx = resolve_indices(indices, len(self))
        items = [values] if isinstance(values, str) else list(values)
        for item in items:
            if item not in table:
                raise ValueError(f"Invalid {what}: {item!r}. Supported {what}s: {list(table)}")
        if len(items) not in (1, len(idx)):
            raise ValueError(f"{what}s {values!r}: expected one value or {len(idx)} values")
        name = attribute_names()[which]
        for n, i in enumerate(idx):
            self._prims[i].GetAttribute(name).Set(items[0 if len(items) == 1 else n])

    def _get_labels(self, which: int, indices: Any) -> list[str]:
        self._check_valid()
        name = attribute_names()[which]
        return [self._prims[i].GetAttribute(name).Get() for i in resolve_indices(indices, len(self))]

    def set_bases(self, bases: str | Sequence[str], *, indices: Any = None) -> None:
        """Set the base material of each material (one of :data:`BASES`)."""
        self._set_labels(0, bases, indices, BASES, "base")

    def get_bases(self, *, indices: Any = None) -> list[str]:
        """Each material's base material."""
        return self._get_labels(0, indices)

    def set_coatings(self, coatings: str | Sequence[str], *, indices: Any = None) -> None:
        """Set the coating of each material (one of :data:`COATINGS`)."""
        self._set_labels(1, coatings, indices, COATINGS, "coating")

    def get_coatings(self, *, indices: Any = None) -> list[str]:
        """Each material's coating."""
        return self._get_labels(1, indices)

    def set_attributes(self, attributes: str | Sequence[str], *, indices: Any = None) -> None:
        """Set the attribute of each material (one of :data:`ATTRIBUTES`)."""
        self._set_labels(2, attributes, indices, ATTRIBUTES, "attribute")

    def get_attributes(self, *, indices: Any = None) -> list[str]:
        """Each material's attribute."""
        return self._get_labels(2, indices)

    # ---- material ids ------------------------------------------------------------------------------------
    @staticmethod
    def encode_material_ids(prims: Any) -> WarpLikeArray:
        """The 16-bit material id of each prim (path, prim, material or a NonVisualMaterial), shape (N, 1)."""
        stage = current_stage()
        if isinstance(prims, NonVisualMaterial):
            items = prims.prims
        elif isinstance(prims, (str, Sdf.Path, Usd.Prim, UsdShade.Material)):
            items = [prims]
        elif isinstance(prims, (list, tuple)):
            items = list(prims)
        else:
            raise ValueError(f"Invalid type: {type(prims).__name__}; expected a path, prim, material, a list of them "
                             f"or a NonVisualMaterial")
        resolved = []
        for item in items:
            prim = item.GetPrim() if isinstance(item, UsdShade.Material) else \
                item if isinstance(item, Usd.Prim) else stage.GetPrimAtPath(str(item))
            if not prim or not prim.IsValid():
                raise ValueError(f"encode_material_ids: no prim at {item!r}")
            resolved.append(prim)
        return _warp(np.array([_encode(p) for p in resolved], dtype=np.uint16).reshape(-1, 1))

    @staticmethod
    def decode_material_ids(ids: Any) -> list[tuple[str, str, str]]:
        """(base, coating, attribute) names of each 16-bit material id (``"none"`` for unknown indices)."""
        raw = np.asarray(ids.numpy() if hasattr(ids, "numpy") else ids).reshape(-1)
        out = []
        for value in raw.tolist():
            if not float(value).is_integer() or not 0 <= value <= 0xFFFF:
                raise ValueError(f"The given material ID ({value}) is outside valid unsigned integer 16-bit range")
            out.append(surface_materials.decode_material_id(int(value)))
        return out
