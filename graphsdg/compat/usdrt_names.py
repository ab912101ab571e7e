"""Isaac compat area: ``usdrt.Sdf.Path``, the Fabric-side path type scripts pass as OmniGraph target values.

Isaac's scripts and tests give OmniGraph ``target`` inputs lists of
``usdrt.Sdf.Path`` (``og.Controller.edit(..., {SET_VALUES: [("odom.inputs:chassisPrim",
[usdrt.Sdf.Path("/robot/chassis")])]})``). graphsdg has no Fabric stage: its
OmniGraph layer reads USD, so ``usdrt.Sdf.Path`` is USD's ``Sdf.Path``. The rest
of ``usdrt`` (its stage, prims and attributes over Fabric) raises
:class:`~graphsdg.compat.modules.CompatError` naming the name asked for.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import usdrt.Sdf
    >>> str(usdrt.Sdf.Path("/World/robot"))
    '/World/robot'
    >>> isaac.uninstall()
"""
from __future__ import annotations

import types

from pxr import Sdf

from graphsdg.compat.modules import CompatModule

HINT = ("graphsdg has no Fabric stage: usdrt.Sdf.Path is pxr's Sdf.Path (OmniGraph target values); read and write "
        "the stage with pxr's Usd instead of usdrt.Usd")


def modules() -> list[types.ModuleType]:
    """``usdrt`` and ``usdrt.Sdf`` (``Path``)."""
    sdf = CompatModule("usdrt.Sdf", Path=Sdf.Path, hint=HINT)
    return [CompatModule("usdrt", Sdf=sdf, hint=HINT), sdf]
