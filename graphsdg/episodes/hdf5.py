"""The optional HDF5 dependency of episode sessions (``h5py``, the ``episodes`` extra)."""
from __future__ import annotations

import types
import warnings

INSTALL_HINT = "pip install 'graphsdg[episodes]'"


class MissingHdf5Error(ImportError):
    """h5py, which episode sessions are written and read with, is not installed."""


def require_h5py() -> types.ModuleType:
    """The ``h5py`` module, or :class:`MissingHdf5Error` naming the extra that installs it."""
    try:
        with warnings.catch_warnings():
            # a wheel built against another HDF5 patch release warns on import; the file format is the same
            warnings.filterwarnings("ignore", message=r"h5py is running against HDF5", category=UserWarning)
            import h5py
    except ImportError as exc:
        raise MissingHdf5Error(f"episode recording and replay store sessions as HDF5 files and need h5py, which is "
                               f"not installed ({exc}); install it with: {INSTALL_HINT}") from exc
    return h5py
