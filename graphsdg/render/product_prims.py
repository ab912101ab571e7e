"""The live render products as ``UsdRender.Product`` prims in the stage's session layer, authored on demand.

Kit keeps a ``RenderProduct`` prim (camera relationship, resolution) in the session layer for every render
product; code that lists them (``rep.functional.get.renderproduct()``) reads those prims. graphsdg's render
products are Python objects (:mod:`graphsdg.render.render_product`), so this module writes the prims when
they are asked for: one per live product at its ``path``, and it removes the prims of products destroyed
since. Products are not mirrored otherwise, so scenes that never ask carry no extra prims.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.render.product_prims import sync_product_prims
    >>> _ = rep.stage.new_stage()
    >>> cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0))
    >>> rp = rep.create.render_product(cam, (64, 48))
    >>> [tuple(p.GetAttribute("resolution").Get()) for p in sync_product_prims()]
    [(64, 48)]
"""
from __future__ import annotations

from pxr import Gf, Sdf, Usd, UsdRender

from graphsdg.render.render_product import registry
from graphsdg.stage.context import get_stage

#: marks the prims this module wrote (and may remove), as opposed to RenderProduct prims a script authored
AUTHORED_KEY = "graphsdg:renderProductMirror"


def sync_product_prims(stage: Usd.Stage | None = None) -> list[Usd.Prim]:
    """Author (or refresh) a ``UsdRender.Product`` prim per live render product in ``stage``'s session layer;
    return them in creation order."""
    stage = stage or get_stage()
    live = {rp.path: rp for rp in registry}
    prims = []
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        for path in [p.GetPath() for p in stage.Traverse() if p.GetCustomDataByKey(AUTHORED_KEY)]:
            if str(path) not in live:
                stage.RemovePrim(path)
        for path, rp in live.items():
            product = UsdRender.Product.Define(stage, Sdf.Path(path))
            product.CreateCameraRel().SetTargets([Sdf.Path(rp.camera)])
            product.CreateResolutionAttr().Set(Gf.Vec2i(rp.width, rp.height))
            product.GetPrim().SetCustomDataByKey(AUTHORED_KEY, True)
            prims.append(product.GetPrim())
    return prims
