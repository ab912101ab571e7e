"""Isaac compat area: deformables (to be filled)."""
from __future__ import annotations

import types


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    return []
