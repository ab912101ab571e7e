"""The old import path of :mod:`graphsdg.engine.runtime` (``graphsdg.runtime`` is that very module)."""
import sys

from graphsdg.engine import runtime as _moved

sys.modules[__name__] = _moved
