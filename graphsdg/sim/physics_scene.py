"""The model's physics options: MuJoCo's solver settings and what ``UsdPhysics.Scene`` sets.

Reads the first ``UsdPhysics.Scene`` prim: its gravity direction and magnitude
and ``physxScene:timeStepsPerSecond`` (the physics step); without one, earth
gravity points down the stage's up axis and the step is
:data:`PHYSICS_STEPS_PER_SECOND`.
"""
from __future__ import annotations

import mujoco
import numpy as np
from pxr import Usd, UsdGeom, UsdPhysics

from graphsdg.sim.compile_error import CompileError

# MuJoCo's soft contacts need a shorter step than PhysX's 60 Hz (whose solver iterates
# positions within a step) to keep dropped boxes within millimetres of each other and
# to calm a pile within the 75 frames the SDG workflows settle for: two physics steps
# per 60 Hz timeline frame, with elliptic friction cones (no creeping on slopes).
PHYSICS_STEPS_PER_SECOND = 120.0


def configure_physics(spec: mujoco.MjSpec, stage: Usd.Stage) -> None:
    """Set ``spec``'s compiler and solver options, gravity and physics step for ``stage``."""
    spec.compiler.degree = False          # joint ranges are given in radians
    spec.compiler.boundmass = 1e-6
    spec.compiler.boundinertia = 1e-9
    spec.option.timestep = 1.0 / PHYSICS_STEPS_PER_SECOND
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10.0
    up = UsdGeom.GetStageUpAxis(stage)
    spec.option.gravity = [0, -9.81, 0] if up == UsdGeom.Tokens.y else [0, 0, -9.81]
    configure_physics_scene(spec, stage, up)


def configure_physics_scene(spec: mujoco.MjSpec, stage: Usd.Stage, up: str) -> None:
    """Gravity and physics step from the first ``UsdPhysics.Scene`` prim, if any."""
    mpu = UsdGeom.GetStageMetersPerUnit(stage) or 1.0
    for prim in stage.Traverse():
        if not prim.IsA(UsdPhysics.Scene):
            continue
        scene = UsdPhysics.Scene(prim)
        direction = scene.GetGravityDirectionAttr().Get()
        magnitude = scene.GetGravityMagnitudeAttr().Get()
        # USD's fallback magnitude (-inf) means "earth gravity in stage units".
        g = 9.81 / mpu if magnitude is None or not np.isfinite(magnitude) or magnitude < 0 else float(magnitude)
        if direction is not None and np.linalg.norm(np.array(direction)) > 0:
            d = np.array(direction, dtype=np.float64)
            spec.option.gravity = (d / np.linalg.norm(d) * g).tolist()
        else:
            spec.option.gravity = [0, -g, 0] if up == UsdGeom.Tokens.y else [0, 0, -g]
        attr = prim.GetAttribute("physxScene:timeStepsPerSecond")
        tps = attr.Get() if attr and attr.IsValid() else None
        if tps is not None:
            if not np.isfinite(tps) or tps <= 0:
                raise CompileError(f"physxScene:timeStepsPerSecond of {prim.GetPath()} is {tps!r}; "
                                   f"it must be a positive number of physics steps per second")
            spec.option.timestep = 1.0 / float(tps)
        return
