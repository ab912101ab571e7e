"""Collision-shape properties of rigid bodies and links in the MuJoCo model: friction, restitution, offsets.

PhysX's tensor views read and write, per collision shape, a material (static
friction, dynamic friction, restitution) and two offsets (contact, rest). Here
a collision shape is one colliding MuJoCo geom, named by its geom name (stable
across recompiles), and each value maps onto the geom as follows:

===================  ==========================================================================
dynamic friction     ``geom_friction[0]``, MuJoCo's one sliding friction coefficient (the compiler
                     maps a bound physics material's dynamic friction there too)
static friction      kept beside the model and read back: MuJoCo's friction cone has one
                     coefficient for sticking and sliding, the dynamic one
restitution e        the contact's damping ratio ``geom_solref[1] = -ln e / sqrt(pi^2 + ln^2 e)``
                     (e = 0: 1, critically damped, MuJoCo's default; e = 1: 0, undamped), the
                     ratio of a spring-damper whose bounce keeps a fraction e of the speed
contact offset c     ``geom_margin = c``: MuJoCo detects contacts from ``margin`` apart
rest offset r        ``geom_gap = c - r``: contacts act from ``margin - gap = r`` apart, where shapes
                     rest (PhysX's rule r <= c is checked)
===================  ==========================================================================

MuJoCo mixes two touching geoms' ``solref`` by their ``solmix`` weights (equal by
default: the mean damping ratio), as PhysX averages two materials' restitution.
Every write goes through :mod:`graphsdg.physics.model_overrides`, so it lasts
across recompiles.
"""
from __future__ import annotations

import math
from typing import Sequence

import mujoco
import numpy as np

from graphsdg.physics.model_overrides import overrides_for
from graphsdg.sim.compiled_scene import CompiledScene
from graphsdg.sim.scene import SimScene

MATERIAL_COLUMNS = ("static_friction", "dynamic_friction", "restitution")


def restitution_to_damping_ratio(e: float) -> float:
    """The spring-damper damping ratio whose bounce keeps the fraction ``e`` (0..1) of the impact speed."""
    if not 0.0 <= e <= 1.0:
        raise ValueError(f"restitution must be in [0, 1], got {e!r}")
    if e == 0.0:
        return 1.0
    log_e = math.log(e)
    return -log_e / math.sqrt(math.pi ** 2 + log_e ** 2)


def damping_ratio_to_restitution(ratio: float) -> float:
    """The restitution of a contact with damping ratio ``ratio`` (0 at or above critical damping)."""
    if ratio >= 1.0:
        return 0.0
    if ratio <= 0.0:
        return 1.0
    return math.exp(-ratio * math.pi / math.sqrt(1.0 - ratio * ratio))


def collider_geom_names(compiled: CompiledScene, owners: Sequence[str]) -> list[str]:
    """Names of the colliding geoms owned by the bodies ``owners``, in geom order (the PhysX shape order)."""
    wanted = set(owners)
    ids = sorted(g for g, owner in compiled.collider_owner.items() if owner in wanted)
    return [mujoco.mj_id2name(compiled.model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in ids]


def geom_id(compiled: CompiledScene, name: str) -> int:
    """The id of geom ``name`` in ``compiled`` (KeyError when the model has none by that name)."""
    gid = mujoco.mj_name2id(compiled.model, mujoco.mjtObj.mjOBJ_GEOM, name)
    if gid < 0:
        raise KeyError(name)
    return gid


class ShapeTable:
    """The collision shapes of ``rows`` bodies (or groups of bodies), padded to the largest row.

    ``owner_rows[i]`` lists the body paths of row ``i`` (one rigid body, or the links
    of one articulation). Values of padded columns read 0 and are never written.
    """

    def __init__(self, sim: SimScene, owner_rows: Sequence[Sequence[str]]) -> None:
        self.sim = sim
        compiled = sim.ensure_compiled()
        self.rows: list[list[str]] = [collider_geom_names(compiled, owners) for owners in owner_rows]
        self.max_shapes = max((len(r) for r in self.rows), default=0)

    # ---- reading -----------------------------------------------------------------------------------------
    def _table(self, read) -> np.ndarray:
        compiled = self.sim.ensure_compiled()
        out = np.zeros((len(self.rows), self.max_shapes) + read(compiled, None).shape, dtype=np.float64)
        for i, row in enumerate(self.rows):
            for k, name in enumerate(row):
                out[i, k] = read(compiled, name)
        return out

    def get_material_properties(self) -> np.ndarray:
        """(rows, max_shapes, 3): static friction, dynamic friction, restitution of each shape."""
        kept = overrides_for(self.sim).kept

        def read(c: CompiledScene, name: str | None) -> np.ndarray:
            if name is None:
                return np.zeros(3)
            g = geom_id(c, name)
            dynamic = float(c.model.geom_friction[g, 0])
            static = kept.get(("static_friction", name), dynamic)
            return np.array([static, dynamic, damping_ratio_to_restitution(float(c.model.geom_solref[g, 1]))])
        return self._table(read)

    def get_contact_offsets(self) -> np.ndarray:
        """(rows, max_shapes): each shape's contact offset (its ``geom_margin``)."""
        return self._table(lambda c, n: np.float64(0.0) if n is None else np.float64(c.model.geom_margin[
            geom_id(c, n)]))

    def get_rest_offsets(self) -> np.ndarray:
        """(rows, max_shapes): each shape's rest offset (``geom_margin - geom_gap``)."""
        def read(c: CompiledScene, n: str | None) -> np.float64:
            if n is None:
                return np.float64(0.0)
            g = geom_id(c, n)
            return np.float64(c.model.geom_margin[g] - c.model.geom_gap[g])
        return self._table(read)

    # ---- writing -----------------------------------------------------------------------------------------
    def _rows_of(self, data: np.ndarray, indices: np.ndarray, per_shape: tuple[int, ...], what: str) -> np.ndarray:
        """``data`` for the selected rows, shaped (len(indices), max_shapes, *per_shape)."""
        arr = np.asarray(data, dtype=np.float64)
        width = self.max_shapes * int(np.prod(per_shape, dtype=np.int64))
        flat = arr.reshape(arr.shape[0], -1) if arr.ndim else arr.reshape(1, -1)
        if flat.shape[1] != width:
            raise ValueError(f"{what}: expected {self.max_shapes} shape(s) x {per_shape or 1} values a row, got "
                             f"shape {arr.shape}")
        if flat.shape[0] == len(self.rows):
            flat = flat[indices]
        elif flat.shape[0] != len(indices):
            raise ValueError(f"{what}: expected {len(self.rows)} rows (every row) or {len(indices)} (the selected "
                             f"ones), got {flat.shape[0]}")
        if not np.all(np.isfinite(flat)):
            raise ValueError(f"{what}: values must be finite, got {data!r}")
        return flat.reshape((len(indices), self.max_shapes) + per_shape)

    def set_material_properties(self, data: np.ndarray, indices: np.ndarray) -> None:
        """Write static friction, dynamic friction and restitution of the shapes of rows ``indices``."""
        values = self._rows_of(data, indices, (3,), "material properties")
        if np.any(values[..., :2] < 0) or np.any((values[..., 2] < 0) | (values[..., 2] > 1)):
            raise ValueError(f"material properties: frictions must be >= 0 and restitution in [0, 1], got "
                             f"{values.tolist()}")
        overrides = overrides_for(self.sim)
        for row, vals in zip(indices, values):
            for name, (static, dynamic, restitution) in zip(self.rows[int(row)], vals):
                ratio = restitution_to_damping_ratio(float(restitution))

                def apply(c: CompiledScene, name: str = name, dynamic: float = float(dynamic),
                          ratio: float = ratio) -> None:
                    g = geom_id(c, name)
                    c.model.geom_friction[g, 0] = dynamic
                    c.model.geom_solref[g, 1] = ratio
                overrides.write(("material", name), apply)
                overrides.kept[("static_friction", name)] = float(static)

    def set_contact_offsets(self, data: np.ndarray, indices: np.ndarray) -> None:
        """Write the contact offsets (>= each shape's rest offset) of the shapes of rows ``indices``."""
        self._set_offsets(data, indices, contact=True)

    def set_rest_offsets(self, data: np.ndarray, indices: np.ndarray) -> None:
        """Write the rest offsets (0 <= rest <= contact offset) of the shapes of rows ``indices``."""
        self._set_offsets(data, indices, contact=False)

    def _set_offsets(self, data: np.ndarray, indices: np.ndarray, contact: bool) -> None:
        what = "contact offsets" if contact else "rest offsets"
        values = self._rows_of(data, indices, (), what)
        compiled = self.sim.ensure_compiled()
        overrides = overrides_for(self.sim)
        for row, vals in zip(indices, values):
            for name, value in zip(self.rows[int(row)], vals):
                g = geom_id(compiled, name)
                margin, gap = float(compiled.model.geom_margin[g]), float(compiled.model.geom_gap[g])
                contact_offset, rest = (float(value), margin - gap) if contact else (margin, float(value))
                if rest < 0 or rest > contact_offset:
                    raise ValueError(f"{what} of shape {name}: rest offset {rest:.6g} must be >= 0 and <= the "
                                     f"contact offset {contact_offset:.6g} (PhysX's rule; MuJoCo cannot rest "
                                     f"shapes inside each other)")

                def apply(c: CompiledScene, name: str = name, margin: float = contact_offset,
                          gap: float = contact_offset - rest) -> None:
                    g = geom_id(c, name)
                    c.model.geom_margin[g] = margin
                    c.model.geom_gap[g] = gap
                overrides.write(("offsets", name), apply)
