"""Isaac compat area: ``isaacsim.core.experimental`` objects, prims and materials.

The classes live in :mod:`graphsdg.compat.experimental_objects` (lights in
:mod:`graphsdg.compat.experimental_lights`, the camera in :mod:`graphsdg.compat.experimental_camera`),
:mod:`graphsdg.compat.experimental_prims` and
:mod:`graphsdg.compat.experimental_materials`; this module maps them to Isaac's
module names (deformable prims and materials come from
:mod:`graphsdg.compat.deformables`, merged into the same modules).
"""
from __future__ import annotations

import types

from graphsdg.compat import experimental_articulation as articulation
from graphsdg.compat import experimental_camera as camera
from graphsdg.compat import experimental_lights as lights
from graphsdg.compat import experimental_materials as materials
from graphsdg.compat import experimental_nonvisual_material as nonvisual
from graphsdg.compat import experimental_objects as objects
from graphsdg.compat import experimental_prims as prims
from graphsdg.compat.modules import CompatModule


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    return [
        CompatModule("isaacsim.core.experimental.objects", GroundPlane=objects.GroundPlane, Shape=objects.Shape,
                     Cube=objects.Cube, Sphere=objects.Sphere, Cylinder=objects.Cylinder, Capsule=objects.Capsule,
                     Cone=objects.Cone, Plane=objects.Plane, Mesh=objects.Mesh, Camera=camera.Camera,
                     Light=lights.Light, DistantLight=lights.DistantLight, SphereLight=lights.SphereLight,
                     RectLight=lights.RectLight, DiskLight=lights.DiskLight, CylinderLight=lights.CylinderLight,
                     DomeLight=lights.DomeLight),
        CompatModule("isaacsim.core.experimental.prims", Prim=prims.Prim, XformPrim=prims.XformPrim,
                     GeomPrim=prims.GeomPrim, RigidPrim=prims.RigidPrim,
                     Articulation=articulation.Articulation),
        CompatModule("isaacsim.core.experimental.materials", VisualMaterial=materials.VisualMaterial,
                     PreviewSurfaceMaterial=materials.PreviewSurfaceMaterial,
                     OmniPbrMaterial=materials.OmniPbrMaterial, PhysicsMaterial=materials.PhysicsMaterial,
                     RigidBodyMaterial=materials.RigidBodyMaterial,
                     NonVisualMaterial=nonvisual.NonVisualMaterial),
    ]
