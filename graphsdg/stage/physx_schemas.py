"""Omniverse's PhysX USD API schemas (``PhysxSchema``), as data: names, attribute types and fallbacks.

usd-core has no ``PhysxSchema`` and cannot learn new schemas once its schema
registry is loaded, so graphsdg keeps their definitions here: each single-apply
API schema's token (``PhysxRigidBodyAPI``), its attribute namespace
(``physxRigidBody``) and every attribute's USD type and fallback value, copied
from Omniverse's schema declarations. An applied schema is its token in the
prim's ``apiSchemas``, exactly as Omniverse writes it, so stages round-trip with
Isaac Sim; :func:`resolved_value` gives an attribute's value the way USD would
with the schema registered (authored value, else the fallback where the schema
is applied).

The compat classes (``pxr.PhysxSchema``, :mod:`graphsdg.compat.physx_schema`)
and the MuJoCo mapping (:mod:`graphsdg.sim.physx_attributes`) both read these
definitions.

Example:
    >>> from pxr import Usd
    >>> stage = Usd.Stage.CreateInMemory()
    >>> prim = stage.DefinePrim("/Body", "Xform")
    >>> resolved_value(prim, "PhysxRigidBodyAPI", "angularDamping") is None   # not applied, not authored
    True
    >>> apply_api(prim, "PhysxRigidBodyAPI")
    >>> resolved_value(prim, "PhysxRigidBodyAPI", "angularDamping")
    0.05
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from pxr import Sdf, Usd

INF = math.inf


@dataclass(frozen=True)
class AttributeDef:
    """One attribute of an API schema: base name (``linearDamping``), USD type name, fallback, uniform or not."""

    name: str
    type_name: str
    fallback: Any
    uniform: bool = False

    @property
    def value_type(self) -> Sdf.ValueTypeName:
        """The ``Sdf.ValueTypeName`` of the attribute."""
        return Sdf.ValueTypeNames.Find(self.type_name)


@dataclass(frozen=True)
class SchemaDef:
    """A single-apply API schema: its token, attribute namespace and attributes."""

    token: str
    namespace: str
    attributes: tuple[AttributeDef, ...]
    doc: str = ""

    def attribute(self, name: str) -> AttributeDef:
        """The attribute definition ``name`` (base name), or ``KeyError`` listing the schema's attributes."""
        for a in self.attributes:
            if a.name == name:
                return a
        raise KeyError(f"{self.token} has no attribute {name!r}; it has: "
                       f"{', '.join(a.name for a in self.attributes)}")

    def full_name(self, name: str) -> str:
        """``namespace:name``, the attribute's name on the prim."""
        return f"{self.namespace}:{name}"


def _a(name: str, type_name: str, fallback: Any, uniform: bool = False) -> AttributeDef:
    return AttributeDef(name, type_name, fallback, uniform)


# Declarations (type, fallback) as in Omniverse's physxSchema (omni.usd.schema.physx).
SCHEMAS: dict[str, SchemaDef] = {s.token: s for s in (
    SchemaDef("PhysxRigidBodyAPI", "physxRigidBody", (
        _a("linearDamping", "float", 0.0), _a("angularDamping", "float", 0.05),
        _a("maxLinearVelocity", "float", INF), _a("maxAngularVelocity", "float", 5729.58),
        _a("sleepThreshold", "float", 0.00005), _a("stabilizationThreshold", "float", 0.00001),
        _a("maxDepenetrationVelocity", "float", INF), _a("maxContactImpulse", "float", INF),
        _a("solverPositionIterationCount", "int", 16), _a("solverVelocityIterationCount", "int", 1),
        _a("enableCCD", "bool", False), _a("enableSpeculativeCCD", "bool", False),
        _a("retainAccelerations", "bool", False), _a("enableGyroscopicForces", "bool", True),
        _a("disableGravity", "bool", False), _a("lockedPosAxis", "int", 0), _a("lockedRotAxis", "int", 0),
        _a("contactSlopCoefficient", "float", 0.0), _a("cfmScale", "float", 0.025),
        _a("solveContact", "bool", True), _a("localSpaceVelocities", "bool", False),
    ), "PhysX rigid body extended parameters"),
    SchemaDef("PhysxCollisionAPI", "physxCollision", (
        _a("contactOffset", "float", -INF), _a("restOffset", "float", -INF),
        _a("torsionalPatchRadius", "float", 0.0), _a("minTorsionalPatchRadius", "float", 0.0),
    ), "PhysX collision shape extended parameters"),
    SchemaDef("PhysxMaterialAPI", "physxMaterial", (
        _a("frictionCombineMode", "token", "average", uniform=True),
        _a("restitutionCombineMode", "token", "average", uniform=True),
        _a("dampingCombineMode", "token", "average", uniform=True),
        _a("improvePatchFriction", "bool", True, uniform=True),
        _a("compliantContactStiffness", "float", 0.0), _a("compliantContactDamping", "float", 0.0),
        _a("compliantContactAccelerationSpring", "bool", False, uniform=True),
    ), "PhysX material extended parameters"),
    SchemaDef("PhysxSceneAPI", "physxScene", (
        _a("bounceThreshold", "float", 0.2), _a("frictionOffsetThreshold", "float", 0.04),
        _a("frictionCorrelationDistance", "float", 0.025), _a("maxBiasCoefficient", "float", INF),
        _a("collisionSystem", "token", "PCM", uniform=True), _a("solverType", "token", "TGS", uniform=True),
        _a("broadphaseType", "token", "GPU", uniform=True), _a("frictionType", "token", "patch", uniform=True),
        _a("enableCCD", "bool", False), _a("enableStabilization", "bool", False),
        _a("enableGPUDynamics", "bool", True), _a("enableEnhancedDeterminism", "bool", False),
        _a("enableExternalForcesEveryIteration", "bool", False), _a("enableSceneQuerySupport", "bool", True),
        _a("enableResidualReporting", "bool", False),
        _a("timeStepsPerSecond", "uint", 60),
        _a("gpuTempBufferCapacity", "uint64", 16777216), _a("gpuMaxRigidContactCount", "uint", 524288),
        _a("gpuMaxRigidPatchCount", "uint", 81920), _a("gpuHeapCapacity", "uint", 67108864),
        _a("gpuFoundLostPairsCapacity", "uint", 262144), _a("gpuFoundLostAggregatePairsCapacity", "uint", 1024),
        _a("gpuTotalAggregatePairsCapacity", "uint", 1024), _a("gpuMaxSoftBodyContacts", "uint", 1048576),
        _a("gpuMaxDeformableSurfaceContacts", "uint", 1048576), _a("gpuMaxParticleContacts", "uint", 1048576),
        _a("gpuCollisionStackSize", "uint", 67108864), _a("gpuMaxNumPartitions", "uint", 8),
        _a("invertCollisionGroupFilter", "bool", False, uniform=True),
        _a("reportKinematicKinematicPairs", "bool", False, uniform=True),
        _a("reportKinematicStaticPairs", "bool", False, uniform=True),
        _a("minPositionIterationCount", "uint", 1), _a("maxPositionIterationCount", "uint", 255),
        _a("minVelocityIterationCount", "uint", 0), _a("maxVelocityIterationCount", "uint", 255),
        _a("updateType", "token", "Synchronous", uniform=True),
    ), "PhysX scene extended parameters"),
    SchemaDef("PhysxContactReportAPI", "physxContactReport", (
        _a("threshold", "float", 1.0),
    ), "PhysX contact reports of a rigid body"),
    SchemaDef("PhysxArticulationAPI", "physxArticulation", (
        _a("articulationEnabled", "bool", True), _a("enabledSelfCollisions", "bool", True),
        _a("solverPositionIterationCount", "int", 32), _a("solverVelocityIterationCount", "int", 1),
        _a("sleepThreshold", "float", 0.005), _a("stabilizationThreshold", "float", 0.001),
    ), "PhysX articulation extended parameters"),
    SchemaDef("PhysxJointAPI", "physxJoint", (
        _a("jointFriction", "float", 0.0), _a("maxJointVelocity", "float", 1000000.0),
        _a("armature", "float", 0.0), _a("enableProjection", "bool", False),
    ), "PhysX joint extended parameters"),
)}


def schema(token: str) -> SchemaDef:
    """The definition of API schema ``token``; ``KeyError`` listing the known ones."""
    try:
        return SCHEMAS[token]
    except KeyError:
        raise KeyError(f"unknown PhysX API schema {token!r}; known: {', '.join(sorted(SCHEMAS))}") from None


def has_api(prim: Usd.Prim, token: str) -> bool:
    """Whether ``prim``'s composed ``apiSchemas`` list ``token`` (USD itself has no definition for it)."""
    # GetAppliedSchemas() drops schemas USD has no definition for; the type info keeps every token
    return bool(prim) and token in prim.GetPrimTypeInfo().GetAppliedAPISchemas()


def apply_api(prim: Usd.Prim, token: str) -> None:
    """Add ``token`` to ``prim``'s ``apiSchemas`` (as ``UsdPrim::ApplyAPI`` does), once."""
    schema(token)
    if not prim or not prim.IsValid():
        raise ValueError(f"cannot apply {token} to an invalid prim {prim}")
    if not has_api(prim, token):
        prim.AddAppliedSchema(token)


def resolved_value(prim: Usd.Prim, token: str, name: str) -> Any:
    """The value of ``token``'s attribute ``name`` on ``prim`` as USD resolves it with the schema known:
    the authored value, else the fallback when the schema is applied, else None."""
    definition = schema(token)
    attribute = definition.attribute(name)
    attr = prim.GetAttribute(definition.full_name(name))
    if attr and attr.HasAuthoredValue():
        return attr.Get()
    return attribute.fallback if has_api(prim, token) else None


def authored_value(prim: Usd.Prim, token: str, name: str) -> Any:
    """The authored value of ``token``'s attribute ``name`` on ``prim``, or None."""
    attr = prim.GetAttribute(schema(token).full_name(name))
    return attr.Get() if attr and attr.HasAuthoredValue() else None
