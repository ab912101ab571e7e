"""Mass and inertia of compiled bodies, by body path. Read from and written into MuJoCo's model.

A body's inertia is MuJoCo's principal moments ``body_inertia`` in the principal
frame ``body_iquat``; PhysX's views give it as a 3x3 matrix in the body's frame
(about its centre of mass). :func:`inertia_matrix` composes the one from the
other; :func:`set_inertia` diagonalises a symmetric matrix back into moments and
axes, so any valid inertia round-trips. Writing a mass keeps the inertia (as
PhysX's ``set_masses`` does). Writes last across recompiles
(:mod:`graphsdg.physics.model_overrides`) and refresh MuJoCo's derived constants.
"""
from __future__ import annotations

import mujoco
import numpy as np

from graphsdg.maths.rotations import matrix_to_quat_wxyz, quat_wxyz_to_matrix
from graphsdg.physics.model_overrides import overrides_for
from graphsdg.sim.compiled_scene import CompiledScene
from graphsdg.sim.scene import SimScene


def body_id(compiled: CompiledScene, path: str) -> int:
    """The MuJoCo body of rigid body or link ``path`` (KeyError when the model has none)."""
    bid = mujoco.mj_name2id(compiled.model, mujoco.mjtObj.mjOBJ_BODY, path)
    if bid < 0:
        raise KeyError(path)
    return bid


def mass(compiled: CompiledScene, path: str) -> float:
    """The body's mass (kg)."""
    return float(compiled.model.body_mass[body_id(compiled, path)])


def inertia_matrix(compiled: CompiledScene, path: str) -> np.ndarray:
    """The body's 3x3 inertia (kg m²) about its centre of mass, in the body's frame."""
    m = compiled.model
    bid = body_id(compiled, path)
    rot = quat_wxyz_to_matrix(m.body_iquat[bid])
    return rot @ np.diag(m.body_inertia[bid]) @ rot.T


def set_mass(sim: SimScene, path: str, value: float) -> None:
    """Write body ``path``'s mass (kg, > 0), keeping its inertia."""
    value = float(value)
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"mass of {path} must be a finite number > 0 (kg), got {value!r}")

    def apply(c: CompiledScene) -> None:
        c.model.body_mass[body_id(c, path)] = value
    overrides_for(sim).write(("mass", path), apply, constants=True)


def principal_inertia(matrix: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray]:
    """(principal moments, principal frame as a w, x, y, z quaternion) of a symmetric 3x3 inertia."""
    mat = np.asarray(matrix, dtype=np.float64).reshape(3, 3)
    if not np.all(np.isfinite(mat)) or not np.allclose(mat, mat.T, rtol=1e-6, atol=1e-12):
        raise ValueError(f"{what}: an inertia must be a finite symmetric 3x3 matrix, got {mat.tolist()}")
    moments, axes = np.linalg.eigh(mat)
    if np.any(moments <= 0):
        raise ValueError(f"{what}: an inertia's principal moments must be > 0, got {moments.tolist()}")
    a, b, c = moments
    if a + b < c * (1 - 1e-9):
        raise ValueError(f"{what}: principal moments {moments.tolist()} break the triangle inequality "
                         f"(no body has them)")
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    return moments, matrix_to_quat_wxyz(axes)


def set_inertia(sim: SimScene, path: str, matrix: np.ndarray) -> None:
    """Write body ``path``'s 3x3 inertia (about its centre of mass, in its frame)."""
    moments, quat = principal_inertia(matrix, f"inertia of {path}")

    def apply(c: CompiledScene) -> None:
        m = c.model
        bid = body_id(c, path)
        m.body_inertia[bid] = moments
        m.body_iquat[bid] = quat
        # the compiler's shortcuts for a body whose inertial frame is its own frame no longer hold
        m.body_sameframe[bid] = 0
        m.body_simple[bid] = 0
        adr, num = int(m.body_dofadr[bid]), int(m.body_dofnum[bid])
        if adr >= 0:
            m.dof_simplenum[adr:adr + num] = 0
    overrides_for(sim).write(("inertia", path), apply, constants=True)
