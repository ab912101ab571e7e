"""Display colours written into MuJoCo's ``geom_rgba``: write-to-fabric for ``modify.display_color``."""
from __future__ import annotations

from typing import Sequence

import numpy as np
from pxr import Usd

from graphsdg.sim.pose_writes.targets import targets_for
from graphsdg.sim.scene import SimScene


def write_colors(sim: SimScene, prims: Sequence[Usd.Prim], rgb: np.ndarray) -> bool:
    """Write per-prim display colours into ``geom_rgba``; ``False`` if not eligible."""
    t = targets_for(sim, prims)
    if not t.eligible or t.has_material:
        return False
    rgba = np.ones((len(prims), 4))
    rgba[:, :3] = np.asarray(rgb, dtype=np.float64).reshape(len(prims), 3)
    sim.model.geom_rgba[t.geom_ids] = rgba
    return True


__all__ = ["write_colors"]
