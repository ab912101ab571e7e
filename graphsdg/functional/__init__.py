"""The immediate-mode API (``rep.functional``): every call edits the stage at once.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> cube = rep.functional.create.cube(position=(0, 0, 1), semantics={"class": "cube"})
    >>> str(cube.GetPath())
    '/Cube'
"""
from graphsdg.functional import create, create_batch, get, modify, physics, randomizer
from graphsdg.io.io_functions import write_blob, write_image, write_json, write_np

__all__ = ["create", "create_batch", "get", "modify", "randomizer", "physics", "write_image", "write_np", "write_json",
           "write_blob"]
