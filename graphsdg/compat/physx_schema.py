"""Isaac compat area: ``pxr.PhysxSchema`` and ``pxr.PhysicsSchemaTools`` (Omniverse's PhysX USD schemas).

usd-core lacks both. In compat mode they are set on the real ``pxr`` package:

* ``PhysxSchema.<Schema>`` (``PhysxRigidBodyAPI``, ``PhysxCollisionAPI``,
  ``PhysxMaterialAPI``, ``PhysxSceneAPI``, ``PhysxContactReportAPI``,
  ``PhysxArticulationAPI``, ``PhysxJointAPI``): USD single-apply API schema
  classes built from :mod:`graphsdg.stage.physx_schemas`: ``Apply``, ``CanApply``,
  ``Get``, ``GetSchemaAttributeNames``, ``GetPrim``, ``GetPath`` and a
  ``Get<Attr>Attr`` / ``Create<Attr>Attr`` pair per attribute. ``Apply`` adds the
  schema's token to the prim's ``apiSchemas``; attributes carry Omniverse's names
  and types. Which ones move the MuJoCo simulation is :mod:`graphsdg.sim.physx_attributes`.
* ``PhysicsSchemaTools``: ``addGroundPlane``, ``addPhysicsScene``, ``addRigidBox``,
  ``addRigidSphere``, ``sdfPathToInt``, ``intToSdfPath``, ``encodeSdfPath``,
  ``decodeSdfPath``.

usd-core cannot learn a schema's fallbacks, so for an attribute with no authored
value ``Get<Attr>Attr()`` returns a :class:`SchemaAttribute` that answers the
fallback (where the schema is applied) and authors the real attribute on ``Set``;
once authored it returns the plain ``Usd.Attribute``.
"""
from __future__ import annotations

import itertools
import math
import threading
import types
from typing import Any, Callable

from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.stage import physx_schemas as defs


class SchemaAttribute(CompatObject):
    """A PhysX schema attribute not authored on its prim yet: ``Get`` gives the schema's fallback (None when
    the schema is not applied, as USD's invalid attribute does); ``Set`` authors it with its declared type."""

    _compat_name = "Usd.Attribute (PhysX schema attribute, not authored)"

    def __init__(self, prim: Usd.Prim, schema: defs.SchemaDef, attribute: defs.AttributeDef) -> None:
        self._prim, self._schema, self._def = prim, schema, attribute

    def _real(self) -> Usd.Attribute:
        return self._prim.GetAttribute(self.GetName())

    def _create(self) -> Usd.Attribute:
        variability = Sdf.VariabilityUniform if self._def.uniform else Sdf.VariabilityVarying
        return self._prim.CreateAttribute(self.GetName(), self._def.value_type, False, variability)

    def Get(self, time: Usd.TimeCode | float = Usd.TimeCode.Default()) -> Any:  # noqa: N802 - pxr's name
        """The authored value, else the fallback where the schema is applied, else None."""
        attr = self._real()
        if attr and attr.HasAuthoredValue():
            return attr.Get(time)
        return self._def.fallback if defs.has_api(self._prim, self._schema.token) else None

    def Set(self, value: Any, time: Usd.TimeCode | float = Usd.TimeCode.Default()) -> bool:  # noqa: N802
        """Author ``value`` (the attribute is created with its schema type first)."""
        if not self._prim or not self._prim.IsValid():
            raise ValueError(f"cannot set {self.GetName()}: its prim is invalid")
        return self._create().Set(value, time)

    def GetName(self) -> str:  # noqa: N802
        return self._schema.full_name(self._def.name)

    def GetBaseName(self) -> str:  # noqa: N802
        return self._def.name

    def GetNamespace(self) -> str:  # noqa: N802
        return self._schema.namespace

    def GetTypeName(self) -> Sdf.ValueTypeName:  # noqa: N802
        return self._def.value_type

    def GetPrim(self) -> Usd.Prim:  # noqa: N802
        return self._prim

    def GetPath(self) -> Sdf.Path:  # noqa: N802
        return self._prim.GetPath().AppendProperty(self.GetName())

    def IsValid(self) -> bool:  # noqa: N802
        """True where the schema is applied (the attribute is then defined by it) or the attribute exists."""
        return bool(self._prim) and (defs.has_api(self._prim, self._schema.token) or bool(self._real()))

    __bool__ = IsValid
    IsDefined = IsValid

    def HasAuthoredValue(self) -> bool:  # noqa: N802
        attr = self._real()
        return bool(attr) and attr.HasAuthoredValue()

    def HasValue(self) -> bool:  # noqa: N802
        return self.Get() is not None

    def HasFallbackValue(self) -> bool:  # noqa: N802
        return True

    def IsAuthored(self) -> bool:  # noqa: N802
        return bool(self._real())

    def Clear(self) -> bool:  # noqa: N802
        attr = self._real()
        return attr.Clear() if attr else True

    def GetTimeSamples(self) -> list[float]:  # noqa: N802
        attr = self._real()
        return list(attr.GetTimeSamples()) if attr else []

    def __repr__(self) -> str:
        return f"SchemaAttribute({self.GetPath()})"


class PhysxAPISchema(CompatObject):
    """Base of the ``PhysxSchema`` API classes: a prim (or another schema's prim) and its schema definition."""

    _schema: defs.SchemaDef

    def __init__(self, prim: Usd.Prim | Any = None) -> None:
        if prim is None:
            prim = Usd.Prim()
        elif not isinstance(prim, Usd.Prim):
            get_prim = getattr(prim, "GetPrim", None)
            if get_prim is None:
                raise TypeError(f"{type(self).__name__}() takes a Usd.Prim or a schema object, got {prim!r}")
            prim = get_prim()
        self._prim = prim

    def GetPrim(self) -> Usd.Prim:  # noqa: N802
        return self._prim

    def GetPath(self) -> Sdf.Path:  # noqa: N802
        return self._prim.GetPath() if self._prim else Sdf.Path()

    def __bool__(self) -> bool:
        return bool(self._prim) and self._prim.IsValid() and defs.has_api(self._prim, self._schema.token)

    def __repr__(self) -> str:
        return f"PhysxSchema.{self._schema.token}({self.GetPath()})"

    @classmethod
    def Apply(cls, prim: Usd.Prim) -> "PhysxAPISchema":  # noqa: N802
        """Add the schema's token to ``prim``'s ``apiSchemas`` and return the schema on it."""
        if not isinstance(prim, Usd.Prim) or not prim.IsValid():
            raise ValueError(f"PhysxSchema.{cls._schema.token}.Apply needs a valid Usd.Prim, got {prim!r}")
        defs.apply_api(prim, cls._schema.token)
        return cls(prim)

    @classmethod
    def CanApply(cls, prim: Usd.Prim, whyNot: Any = None) -> bool:  # noqa: N802,N803 - pxr's names
        """Whether ``prim`` can take the schema: any valid prim can (none of these schemas restricts it)."""
        return isinstance(prim, Usd.Prim) and prim.IsValid()

    @classmethod
    def Get(cls, stage: Usd.Stage, path: str | Sdf.Path) -> "PhysxAPISchema":  # noqa: N802
        """The schema on the prim at ``path`` (an invalid schema when there is none)."""
        return cls(stage.GetPrimAtPath(Sdf.Path(str(path))))

    @classmethod
    def GetSchemaAttributeNames(cls, includeInherited: bool = True) -> list[str]:  # noqa: N802,N803
        return [cls._schema.full_name(a.name) for a in cls._schema.attributes]

    def _get_attr(self, attribute: defs.AttributeDef) -> Usd.Attribute | SchemaAttribute:
        attr = self._prim.GetAttribute(self._schema.full_name(attribute.name)) if self._prim else None
        if attr and attr.HasAuthoredValue():
            return attr
        return SchemaAttribute(self._prim, self._schema, attribute)

    def _create_attr(self, attribute: defs.AttributeDef, defaultValue: Any = None,  # noqa: N803
                     writeSparsely: bool = False) -> Usd.Attribute:
        if not self._prim or not self._prim.IsValid():
            raise ValueError(f"cannot create {self._schema.full_name(attribute.name)} on an invalid prim")
        name = self._schema.full_name(attribute.name)
        existing = self._prim.GetAttribute(name)
        if writeSparsely and not (existing and existing.HasAuthoredValue()) and defaultValue is not None \
                and _same(defaultValue, attribute.fallback):
            return existing if existing else SchemaAttribute(self._prim, self._schema, attribute)._create()
        variability = Sdf.VariabilityUniform if attribute.uniform else Sdf.VariabilityVarying
        attr = self._prim.CreateAttribute(name, attribute.value_type, False, variability)
        if defaultValue is not None:
            attr.Set(defaultValue)
        return attr


def _same(a: Any, b: Any) -> bool:
    try:
        return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))
    except Exception:   # Gf / Vt values that do not compare with Python ones
        return False


def _schema_class(schema: defs.SchemaDef) -> type:
    """A PhysxAPISchema subclass for ``schema`` with a Get/Create method pair per attribute."""
    namespace: dict[str, Any] = {"_schema": schema, "_compat_name": f"pxr.PhysxSchema.{schema.token}",
                                 "__doc__": f"PhysxSchema.{schema.token}: {schema.doc} (attributes "
                                            f"{schema.namespace}:*)."}
    for attribute in schema.attributes:
        stem = attribute.name[0].upper() + attribute.name[1:]

        def getter(self, _a=attribute):
            return self._get_attr(_a)

        def creator(self, defaultValue=None, writeSparsely=False, _a=attribute):  # noqa: N803
            return self._create_attr(_a, defaultValue, writeSparsely)

        getter.__name__, creator.__name__ = f"Get{stem}Attr", f"Create{stem}Attr"
        getter.__doc__ = (f"{schema.full_name(attribute.name)} ({attribute.type_name}, fallback "
                          f"{attribute.fallback!r}).")
        creator.__doc__ = f"Create (and with ``defaultValue`` author) {schema.full_name(attribute.name)}."
        namespace[getter.__name__], namespace[creator.__name__] = getter, creator
    cls = type(schema.token, (PhysxAPISchema,), namespace)
    cls.__module__ = __name__
    return cls


SCHEMA_CLASSES: dict[str, type] = {token: _schema_class(s) for token, s in defs.SCHEMAS.items()}


# ---- PhysicsSchemaTools ---------------------------------------------------------------------------
_AXES = ("X", "Y", "Z")
_path_ids: dict[str, int] = {}
_id_paths: dict[int, str] = {}
_next_id = itertools.count(1)
_ids_lock = threading.Lock()


def sdfPathToInt(path: str | Sdf.Path) -> int:  # noqa: N802 - Omniverse's name
    """A 64-bit integer standing for ``path`` in this process; :func:`intToSdfPath` turns it back.

    Omniverse encodes the path's pool handle; graphsdg numbers paths in the order
    they are first asked for (the same script gets the same numbers).
    """
    text = str(Sdf.Path(str(path)))
    with _ids_lock:
        value = _path_ids.get(text)
        if value is None:
            value = next(_next_id)
            _path_ids[text], _id_paths[value] = value, text
    return value


def intToSdfPath(value: int) -> Sdf.Path:  # noqa: N802
    """The ``Sdf.Path`` that :func:`sdfPathToInt` encoded as ``value``."""
    try:
        return Sdf.Path(_id_paths[int(value)])
    except KeyError:
        raise ValueError(f"{value!r} is not an integer sdfPathToInt / encodeSdfPath gave in this process") from None


def encodeSdfPath(path: str | Sdf.Path) -> tuple[int, int]:  # noqa: N802
    """:func:`sdfPathToInt` split into two 32-bit integers (low, high), as contact reports carry paths."""
    value = sdfPathToInt(path)
    return value & 0xFFFFFFFF, value >> 32


def decodeSdfPath(low: int, high: int) -> Sdf.Path:  # noqa: N802
    """The ``Sdf.Path`` of an :func:`encodeSdfPath` pair."""
    return intToSdfPath((int(high) << 32) | (int(low) & 0xFFFFFFFF))


def _axis(axis: str) -> str:
    text = str(axis).upper()
    if text not in _AXES:
        raise ValueError(f"axis must be one of {_AXES}, got {axis!r}")
    return text


def addPhysicsScene(stage: Usd.Stage, path: str | Sdf.Path) -> UsdPhysics.Scene:  # noqa: N802
    """Define a ``UsdPhysics.Scene`` at ``path`` with gravity down the stage's up axis at 9.81 m/s² (in
    stage units)."""
    scene = UsdPhysics.Scene.Define(stage, Sdf.Path(str(path)))
    up = UsdGeom.GetStageUpAxis(stage)
    direction = {"X": (-1.0, 0.0, 0.0), "Y": (0.0, -1.0, 0.0), "Z": (0.0, 0.0, -1.0)}[up]
    scene.CreateGravityDirectionAttr().Set(Gf.Vec3f(*direction))
    scene.CreateGravityMagnitudeAttr().Set(9.81 / (UsdGeom.GetStageMetersPerUnit(stage) or 1.0))
    return scene


def addGroundPlane(stage: Usd.Stage, planePath: str | Sdf.Path, axis: str, size: float,  # noqa: N802,N803
                   position: Any, color: Any) -> str:
    """A ground plane as Omniverse builds it: an Xform at ``planePath`` translated to ``position``, holding
    ``CollisionMesh`` (a ``2 size`` square normal to ``axis``, coloured ``color``, drawn) and
    ``CollisionPlane`` (an infinite ``UsdGeom.Plane`` collider, purpose ``guide``). Returns the path."""
    axis = _axis(axis)
    if isinstance(size, bool) or not isinstance(size, (int, float)) or not size > 0:
        raise ValueError(f"addGroundPlane size must be a number > 0, got {size!r}")
    root = Sdf.Path(str(planePath))
    xform = UsdGeom.Xform.Define(stage, root)
    xform.AddTranslateOp().Set(Gf.Vec3d(*[float(v) for v in position]))
    s = float(size)
    corners = {"X": [(0, -s, -s), (0, s, -s), (0, s, s), (0, -s, s)],
               "Y": [(-s, 0, -s), (-s, 0, s), (s, 0, s), (s, 0, -s)],
               "Z": [(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)]}[axis]
    normal = {"X": (1, 0, 0), "Y": (0, 1, 0), "Z": (0, 0, 1)}[axis]
    mesh = UsdGeom.Mesh.Define(stage, root.AppendChild("CollisionMesh"))
    mesh.CreatePointsAttr([Gf.Vec3f(*p) for p in corners])
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    mesh.CreateNormalsAttr([Gf.Vec3f(*normal)] * 4)
    mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    mesh.CreateDisplayColorAttr([Gf.Vec3f(*[float(c) for c in color])])
    mesh.CreateExtentAttr([Gf.Vec3f(*[min(p[i] for p in corners) for i in range(3)]),
                           Gf.Vec3f(*[max(p[i] for p in corners) for i in range(3)])])
    plane = UsdGeom.Plane.Define(stage, root.AppendChild("CollisionPlane"))
    plane.CreatePurposeAttr(UsdGeom.Tokens.guide)
    plane.CreateAxisAttr(axis)
    UsdPhysics.CollisionAPI.Apply(plane.GetPrim())
    return str(root)


def _rigid(stage: Usd.Stage, gprim: UsdGeom.Gprim, position: Any, orientation: Any, color: Any, density: float,
           lin_velocity: Any, ang_velocity: Any) -> None:
    prim = gprim.GetPrim()
    gprim.AddTranslateOp().Set(Gf.Vec3d(*[float(v) for v in position]))
    q = orientation if isinstance(orientation, (Gf.Quatf, Gf.Quatd)) else None
    if q is None:   # a 4-sequence (x, y, z, w) as Gf.Quatf's imaginary-then-real carb order is ambiguous: ask
        raise ValueError(f"orientation must be a Gf.Quatf or Gf.Quatd, got {orientation!r}")
    gprim.AddOrientOp().Set(Gf.Quatf(q))
    gprim.CreateDisplayColorAttr([Gf.Vec3f(*[float(c) for c in color])])
    UsdPhysics.CollisionAPI.Apply(prim)
    body = UsdPhysics.RigidBodyAPI.Apply(prim)
    if density:
        UsdPhysics.MassAPI.Apply(prim).CreateDensityAttr(float(density))
    body.CreateVelocityAttr(Gf.Vec3f(*[float(v) for v in lin_velocity]))
    body.CreateAngularVelocityAttr(Gf.Vec3f(*[float(v) for v in ang_velocity]))


def addRigidBox(stage: Usd.Stage, path: str | Sdf.Path, size: Any, position: Any, orientation: Any,  # noqa: N802
                color: Any, density: float, lin_velocity: Any, ang_velocity: Any) -> None:
    """A dynamic box: a ``UsdGeom.Cube`` of edge 1 scaled to ``size`` (3 edges), at ``position`` /
    ``orientation`` (a Gf quaternion), coloured, with collision, rigid body, ``density`` (kg per cubic stage
    unit; 0 leaves the default) and initial velocities (linear; angular in degrees per second)."""
    cube = UsdGeom.Cube.Define(stage, Sdf.Path(str(path)))
    cube.CreateSizeAttr(1.0)
    cube.CreateExtentAttr([Gf.Vec3f(-0.5), Gf.Vec3f(0.5)])
    _rigid(stage, cube, position, orientation, color, density, lin_velocity, ang_velocity)
    cube.AddScaleOp().Set(Gf.Vec3f(*[float(v) for v in size]))


def addRigidSphere(stage: Usd.Stage, path: str | Sdf.Path, radius: float, position: Any, orientation: Any,  # noqa: N802
                   color: Any, density: float, lin_velocity: Any, ang_velocity: Any) -> None:
    """A dynamic ``UsdGeom.Sphere`` of ``radius``, as :func:`addRigidBox` otherwise."""
    sphere = UsdGeom.Sphere.Define(stage, Sdf.Path(str(path)))
    sphere.CreateRadiusAttr(float(radius))
    sphere.CreateExtentAttr([Gf.Vec3f(-float(radius)), Gf.Vec3f(float(radius))])
    _rigid(stage, sphere, position, orientation, color, density, lin_velocity, ang_velocity)


_usd_has_api: Callable[..., bool] | None = None   # pxr's own Usd.Prim.HasAPI while compat mode is installed


def _has_api(prim: Usd.Prim, schema: Any, *args: Any, **kwargs: Any) -> bool:
    """``prim.HasAPI(PhysxSchema.X)`` answers from the prim's ``apiSchemas``; other schemas go to pxr."""
    if isinstance(schema, type) and issubclass(schema, PhysxAPISchema):
        return defs.has_api(prim, schema._schema.token)
    return _usd_has_api(prim, schema, *args, **kwargs)


def install() -> None:
    """Called by :func:`graphsdg.compat.isaac.install`: ``Usd.Prim.HasAPI`` learns the PhysX schema classes
    (usd-core cannot register them as schema types, and Isaac scripts ask ``prim.HasAPI(PhysxSchema...)``)."""
    global _usd_has_api
    if _usd_has_api is None:
        _usd_has_api = Usd.Prim.HasAPI
        Usd.Prim.HasAPI = _has_api


def uninstall() -> None:
    """Called by :func:`graphsdg.compat.isaac.uninstall`: pxr's ``HasAPI`` back."""
    global _usd_has_api
    if _usd_has_api is not None:
        Usd.Prim.HasAPI = _usd_has_api
        _usd_has_api = None


def modules() -> list[types.ModuleType]:
    """The compat modules of this area: ``pxr.PhysxSchema`` and ``pxr.PhysicsSchemaTools``."""
    physx = CompatModule("pxr.PhysxSchema", doc="Omniverse's PhysX USD API schemas (graphsdg compat).",
                         hint="graphsdg maps the PhysX API schemas listed in docs/porting.md.", **SCHEMA_CLASSES)
    tools = CompatModule("pxr.PhysicsSchemaTools", doc="Omniverse's physics USD helpers (graphsdg compat).",
                         addGroundPlane=addGroundPlane, addPhysicsScene=addPhysicsScene, addRigidBox=addRigidBox,
                         addRigidSphere=addRigidSphere, sdfPathToInt=sdfPathToInt, intToSdfPath=intToSdfPath,
                         encodeSdfPath=encodeSdfPath, decodeSdfPath=decodeSdfPath)
    return [physx, tools]
