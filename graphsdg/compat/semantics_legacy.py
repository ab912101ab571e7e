"""Isaac compat area: the semantics API of Isaac Sim 2022.x to 5.x. Published scripts still use it.

Before ``UsdSemantics.LabelsAPI``, Isaac labelled prims with Kit's multiple-apply schema
``Semantics.SemanticsAPI`` (``from pxr import Semantics``): an instance (``"Semantics"`` by
default) holds two attributes, ``semantic:<instance>:params:semanticType`` (the taxonomy, a token)
and ``semantic:<instance>:params:semanticData`` (the label, a string). Isaac's helpers
``add_update_semantics``, ``get_semantics`` and ``remove_all_semantics`` (``isaacsim.core.utils
.semantics`` in 4.5 to 5.x, ``omni.isaac.core.utils.semantics`` before) wrote and read it. Isaac
Sim 6 dropped the helpers but keeps reading the schema.

usd-core has no ``Semantics`` module, so this area supplies ``pxr.Semantics.SemanticsAPI`` as
the schema's authored form (the ``apiSchemas`` entry ``SemanticsAPI:<instance>`` and the two
attributes), and adds the three helpers to ``isaacsim.core.utils.semantics``. graphsdg's
annotators read these attributes as labels (:func:`graphsdg.stage.semantics.direct_labels`), so
a prim labelled the old way shows in segmentation and boxes. ``prim.HasAPI(Semantics.SemanticsAPI)``
and ``prim.RemoveAPI(Semantics.SemanticsAPI, name)`` answer from the ``apiSchemas`` list.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> from pxr import Semantics, Usd
    >>> stage = Usd.Stage.CreateInMemory()
    >>> prim = stage.DefinePrim("/Cube", "Cube")
    >>> sem = Semantics.SemanticsAPI.Apply(prim, "Semantics")
    >>> _ = sem.CreateSemanticTypeAttr().Set("class"); _ = sem.CreateSemanticDataAttr().Set("cube")
    >>> prim.GetAttribute("semantic:Semantics:params:semanticData").Get()
    'cube'
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types
from typing import Any, Callable

from pxr import Sdf, Usd

from graphsdg.compat.modules import CompatModule, CompatObject

SCHEMA = "SemanticsAPI"
NAMESPACE = "semantic"
TYPE_ATTR = "params:semanticType"
DATA_ATTR = "params:semanticData"


def _applied_instances(prim: Usd.Prim) -> list[str]:
    """The instance names of ``SemanticsAPI`` in ``prim``'s ``apiSchemas``, in order."""
    prefix = SCHEMA + ":"
    # GetAppliedSchemas() drops schemas USD has no definition for; the type info keeps every entry
    applied = prim.GetPrimTypeInfo().GetAppliedAPISchemas() if prim else []
    return [name[len(prefix):] for name in applied if name.startswith(prefix)]


def _attribute_name(instance: str, which: str) -> str:
    return f"{NAMESPACE}:{instance}:{which}"


class SemanticsAPI(CompatObject):
    """Kit's ``Semantics.SemanticsAPI``: one named semantic instance (a type and a label) on a prim."""

    _compat_name = "pxr.Semantics.SemanticsAPI"

    def __init__(self, prim: Usd.Prim | Any = None, name: str = "Semantics") -> None:
        if prim is None:
            prim = Usd.Prim()
        elif not isinstance(prim, Usd.Prim):
            get_prim = getattr(prim, "GetPrim", None)
            if get_prim is None:
                raise TypeError(f"SemanticsAPI() takes a Usd.Prim or a schema object, got {prim!r}")
            prim = get_prim()
        if not isinstance(name, str) or not name:
            raise ValueError(f"SemanticsAPI: the instance name must be a non-empty string, got {name!r}")
        self._prim, self._name = prim, name

    def GetPrim(self) -> Usd.Prim:  # noqa: N802 - pxr's name
        return self._prim

    def GetPath(self) -> Sdf.Path:  # noqa: N802
        return self._prim.GetPath() if self._prim else Sdf.Path()

    def GetName(self) -> str:  # noqa: N802
        return self._name

    def __bool__(self) -> bool:
        return bool(self._prim) and self._prim.IsValid() and self._name in _applied_instances(self._prim)

    def __repr__(self) -> str:
        return f"Semantics.SemanticsAPI({self.GetPath()}, {self._name!r})"

    @classmethod
    def Apply(cls, prim: Usd.Prim, name: str = "Semantics") -> "SemanticsAPI":  # noqa: N802
        """Add ``SemanticsAPI:<name>`` to ``prim``'s ``apiSchemas`` and return that instance."""
        if not isinstance(prim, Usd.Prim) or not prim.IsValid():
            raise ValueError(f"Semantics.SemanticsAPI.Apply needs a valid Usd.Prim, got {prim!r}")
        api = cls(prim, name)
        if name not in _applied_instances(prim):
            prim.AddAppliedSchema(f"{SCHEMA}:{name}")
        return api

    @classmethod
    def CanApply(cls, prim: Usd.Prim, name: str = "Semantics", whyNot: Any = None) -> bool:  # noqa: N802,N803
        """Whether ``prim`` can take the schema: any valid prim can."""
        return isinstance(prim, Usd.Prim) and prim.IsValid()

    @classmethod
    def Get(cls, prim_or_stage: Usd.Prim | Usd.Stage, name_or_path: str | Sdf.Path = "Semantics"  # noqa: N802
            ) -> "SemanticsAPI":
        """The instance ``name`` on a prim, or (stage, property path ``/P.semantic:<name>``) the one it names."""
        if isinstance(prim_or_stage, Usd.Stage):
            path = Sdf.Path(str(name_or_path))
            name = path.name.split(":")[1] if path.IsPropertyPath() and path.name.startswith(NAMESPACE + ":") else ""
            return cls(prim_or_stage.GetPrimAtPath(path.GetPrimPath()), name or "Semantics")
        return cls(prim_or_stage, str(name_or_path))

    @classmethod
    def GetAll(cls, prim: Usd.Prim) -> list["SemanticsAPI"]:  # noqa: N802
        """Every ``SemanticsAPI`` instance applied on ``prim``."""
        return [cls(prim, name) for name in _applied_instances(prim)]

    @staticmethod
    def IsSemanticsAPIPath(path: Sdf.Path | str) -> bool:  # noqa: N802
        """Whether ``path`` is the property path of a semantic instance's attribute (``semantic:<name>:...``)."""
        path = Sdf.Path(str(path))
        return path.IsPropertyPath() and path.name.startswith(NAMESPACE + ":") and len(path.name.split(":")) >= 2

    @classmethod
    def GetSchemaAttributeNames(cls, includeInherited: bool = True,  # noqa: N802,N803
                                instanceName: str | None = None) -> list[str]:  # noqa: N803
        """The attribute names of an instance (``__INSTANCE_NAME__`` stands for it when none is given)."""
        name = instanceName or "__INSTANCE_NAME__"
        return [_attribute_name(name, TYPE_ATTR), _attribute_name(name, DATA_ATTR)]

    def _create(self, which: str, value_type: Sdf.ValueTypeName, default: Any) -> Usd.Attribute:
        if not self._prim or not self._prim.IsValid():
            raise ValueError(f"cannot create {_attribute_name(self._name, which)} on an invalid prim")
        attr = self._prim.CreateAttribute(_attribute_name(self._name, which), value_type)
        if default is not None:
            attr.Set(default)
        return attr

    def GetSemanticTypeAttr(self) -> Usd.Attribute:  # noqa: N802
        """The taxonomy attribute (``"class"``, ...), invalid where it was never created."""
        return self._prim.GetAttribute(_attribute_name(self._name, TYPE_ATTR))

    def CreateSemanticTypeAttr(self, defaultValue: Any = None, writeSparsely: bool = False  # noqa: N802,N803
                               ) -> Usd.Attribute:
        """Create the taxonomy attribute (a token), set to ``defaultValue`` when one is given."""
        return self._create(TYPE_ATTR, Sdf.ValueTypeNames.Token, defaultValue)

    def GetSemanticDataAttr(self) -> Usd.Attribute:  # noqa: N802
        """The label attribute, invalid where it was never created."""
        return self._prim.GetAttribute(_attribute_name(self._name, DATA_ATTR))

    def CreateSemanticDataAttr(self, defaultValue: Any = None, writeSparsely: bool = False  # noqa: N802,N803
                               ) -> Usd.Attribute:
        """Create the label attribute (a string), set to ``defaultValue`` when one is given."""
        return self._create(DATA_ATTR, Sdf.ValueTypeNames.String, defaultValue)


def _remove_instance(prim: Usd.Prim, name: str) -> bool:
    """Drop ``SemanticsAPI:<name>`` from ``prim``'s ``apiSchemas`` and its two attributes."""
    removed = prim.RemoveAppliedSchema(f"{SCHEMA}:{name}")
    for which in (TYPE_ATTR, DATA_ATTR):
        if prim.GetAttribute(_attribute_name(name, which)):
            prim.RemoveProperty(_attribute_name(name, which))
    return removed


# ---- isaacsim.core.utils.semantics (Isaac Sim 4.5 to 5.x; omni.isaac.core.utils.semantics before) -------------
def add_update_semantics(prim: Usd.Prim, semantic_label: str, type_label: str = "class", suffix: str = "") -> None:
    """Give ``prim`` the semantic instance ``"Semantics" + suffix`` of type ``type_label`` and label
    ``semantic_label``, creating it or updating the one there."""
    if not isinstance(prim, Usd.Prim) or not prim.IsValid():
        raise ValueError(f"add_update_semantics needs a valid Usd.Prim, got {prim!r}")
    if semantic_label is None:
        return
    api = SemanticsAPI(prim, "Semantics" + str(suffix))
    if not api:
        api = SemanticsAPI.Apply(prim, "Semantics" + str(suffix))
    type_attr = api.GetSemanticTypeAttr() or api.CreateSemanticTypeAttr()
    data_attr = api.GetSemanticDataAttr() or api.CreateSemanticDataAttr()
    if type_attr.Get() != type_label:
        type_attr.Set(type_label)
    if data_attr.Get() != semantic_label:
        data_attr.Set(semantic_label)


def get_semantics(prim: Usd.Prim) -> dict[str, tuple[str, str]]:
    """``{instance name: (type, label)}`` for every semantic instance authored on ``prim``."""
    result: dict[str, tuple[str, str]] = {}
    for attr in prim.GetAttributes():
        parts = attr.GetName().split(":")
        if len(parts) == 4 and parts[0] == NAMESPACE and ":".join(parts[2:]) == TYPE_ATTR:
            data = prim.GetAttribute(_attribute_name(parts[1], DATA_ATTR))
            result[parts[1]] = (attr.Get(), data.Get() if data else None)
    return result


def remove_all_semantics(prim: Usd.Prim, recursive: bool = False) -> None:
    """Remove every semantic instance from ``prim`` (and its descendants when ``recursive``)."""
    for p in (Usd.PrimRange(prim) if recursive else [prim]):
        names = set(_applied_instances(p)) | set(get_semantics(p))
        for name in sorted(names):
            _remove_instance(p, name)


# ---- Usd.Prim.HasAPI / RemoveAPI learn SemanticsAPI (usd-core cannot register it as a schema type) ------------
# pxr's methods (or the hooks of areas installed before this one), kept for good: an area that wraps ours and
# puts ours back when it is uninstalled after us leaves ours reaching them.
_originals: dict[str, Callable[..., Any]] = {}


def _has_api(prim: Usd.Prim, schema: Any, *args: Any, **kwargs: Any) -> bool:
    if schema is SemanticsAPI:
        name = args[0] if args else kwargs.get("instanceName")
        applied = _applied_instances(prim)
        return bool(applied) if not name else str(name) in applied
    return _originals["HasAPI"](prim, schema, *args, **kwargs)


def _remove_api(prim: Usd.Prim, schema: Any, *args: Any, **kwargs: Any) -> bool:
    if schema is SemanticsAPI:
        name = args[0] if args else kwargs.get("instanceName", "Semantics")
        return _remove_instance(prim, str(name))
    return _originals["RemoveAPI"](prim, schema, *args, **kwargs)


_WRAPPERS = {"HasAPI": _has_api, "RemoveAPI": _remove_api}


def install() -> None:
    """Called by :func:`graphsdg.compat.isaac.install`: ``HasAPI``/``RemoveAPI`` answer for ``SemanticsAPI``
    (wrapping whatever they are then, so other areas' hooks keep working)."""
    for name, wrapper in _WRAPPERS.items():
        current = getattr(Usd.Prim, name)
        if current is not wrapper:
            _originals.setdefault(name, current)
            setattr(Usd.Prim, name, wrapper)


def uninstall() -> None:
    """Called by :func:`graphsdg.compat.isaac.uninstall`: pxr's methods back where ours are still in place (where
    another area wrapped ours, it puts ours back, and ours pass every other schema on to pxr's)."""
    for name, wrapper in _WRAPPERS.items():
        if getattr(Usd.Prim, name) is wrapper and name in _originals:
            setattr(Usd.Prim, name, _originals[name])


def modules() -> list[types.ModuleType]:
    """``pxr.Semantics`` and the pre-6.0 helpers of ``isaacsim.core.utils.semantics``."""
    return [CompatModule("pxr.Semantics", doc="Kit's legacy semantics schema (graphsdg compat).",
                         SemanticsAPI=SemanticsAPI),
            CompatModule("isaacsim.core.utils.semantics", add_update_semantics=add_update_semantics,
                         get_semantics=get_semantics, remove_all_semantics=remove_all_semantics)]
