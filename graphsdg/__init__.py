"""graphsdg: Replicator-style synthetic data generation on MuJoCo and OpenUSD.

Use it as Isaac Sim's ``omni.replicator.core``::

    import graphsdg as rep

    rep.stage.new_stage()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=500, parent="/World")
    cube = rep.functional.create.cube(parent="/World", semantics={"class": "cube"})
    cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0), parent="/World")
    rp = rep.create.render_product(cam, (512, 512))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir="_out", rgb=True, bounding_box_2d_tight=True)
    writer.attach(rp)
    for _ in range(3):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
"""
from graphsdg.render.gl_platform import select_gl_platform

select_gl_platform()   # before anything imports mujoco

from graphsdg.stage.sensor_schemas import register_sensor_schemas  # noqa: E402

register_sensor_schemas()   # before anything makes a stage: USD builds its schema registry once

from graphsdg.engine import session as _session  # noqa: E402,F401  (owns the process state before a stage is made)

from graphsdg import (annotators, backends, functional, orchestrator, rng, settings,  # noqa: E402
                      stage, writers)
from graphsdg import runtime, settings_store  # noqa: E402,F401  (their old paths: engine.runtime, base.settings_store)
from graphsdg import augmentations_default  # noqa: E402  (rep.augmentations_default; registers RgbToHsv, ...)
from graphsdg.annotate.annotator import Annotator, AnnotatorRegistry  # noqa: E402
from graphsdg.io import writers as _builtin_writers  # noqa: E402,F401  (registers BasicWriter)
from graphsdg.io.backends import BackendDispatch  # noqa: E402
from graphsdg.io.writer import Writer, WriterRegistry  # noqa: E402
from graphsdg.rng import get_global_seed, set_global_seed  # noqa: E402
from graphsdg.physics import timeline  # noqa: E402


def _import_node_library():
    """Import ``graphsdg.nodes`` (registering every node type).

    Installed, the build maps the repository's top-level ``nodes/`` to
    ``graphsdg.nodes``. Run straight from a source checkout (the repo root on
    ``sys.path``) that mapping does not exist, so the folder beside the package is
    loaded under the same name.
    """
    import importlib
    import importlib.util
    import os
    import sys

    try:
        return importlib.import_module("graphsdg.nodes")
    except ModuleNotFoundError as exc:
        if exc.name != "graphsdg.nodes":
            raise
    folder = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "nodes")
    spec = importlib.util.spec_from_file_location("graphsdg.nodes", os.path.join(folder, "__init__.py"),
                                                  submodule_search_locations=[folder])
    if spec is None or spec.loader is None:
        raise ModuleNotFoundError("graphsdg.nodes: the node library is missing from this installation")
    module = importlib.util.module_from_spec(spec)
    sys.modules["graphsdg.nodes"] = module
    spec.loader.exec_module(module)
    return module


nodes = _import_node_library()

# the graph-API calls are made from the node types registered above
from graphsdg import create, distribution, events, get, graph, modify, randomizer, trigger  # noqa: E402
from graphsdg import example, tools, utils  # noqa: E402  (rep.example, rep.tools, rep.utils)
from graphsdg.graph import ReplicatorItem, new_layer  # noqa: E402

__version__ = "0.1.0"

__all__ = ["annotators", "augmentations_default", "backends", "create", "functional", "orchestrator", "rng",
           "settings", "stage", "writers", "distribution", "get", "graph", "modify", "randomizer", "trigger", "utils", "events",
           "example", "tools",
           "new_layer", "ReplicatorItem",
           "Annotator", "AnnotatorRegistry", "BackendDispatch", "Writer", "WriterRegistry",
           "get_global_seed", "set_global_seed", "timeline"]
