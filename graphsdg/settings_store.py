"""The old import path of :mod:`graphsdg.base.settings_store` (``graphsdg.settings_store`` is that very module)."""
import sys

from graphsdg.base import settings_store as _moved

sys.modules[__name__] = _moved
