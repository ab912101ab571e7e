"""``rep.create``: render products (the graph-API creators join this namespace)."""
from graphsdg.render.render_product import create_render_product as render_product

__all__ = ["render_product"]
