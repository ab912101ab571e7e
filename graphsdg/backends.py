"""``rep.backends``: backend classes and their registry."""
from graphsdg.io.backends import (BackendDispatch, BackendGroup, BaseBackend, DiskBackend, get,
                                  get_registered_backends, register)

__all__ = ["BaseBackend", "DiskBackend", "BackendGroup", "BackendDispatch", "get", "register",
           "get_registered_backends"]
