"""Replicator's public API in compat mode: the documented names graphsdg answers beyond ``graphsdg`` itself.

``omni.replicator.core`` forwards to ``graphsdg`` (``graphsdg.compat.isaac``); this area adds, to the
forwarding modules of its submodules, what Replicator documents and graphsdg has no module name for:

* the names that cannot work here, each a function raising :class:`CompatError` that names it and says why
  (RTX projection materials and decals, MDL shader graphs, keyboard triggers, skeletal animation,
  RTX-sensor tiling); a name stays importable, so only a script that calls it stops;
* ``rep.orchestrator.set_next_rt_subframes`` / ``set_minimum_next_rt_subframes`` (the next capture's
  subframes: :func:`graphsdg.engine.capture.request_next_subframes`) and ``get_sim_times_to_write`` (always
  empty: graphsdg writes each capture in its own step, nothing waits);
* ``rep.orchestrator.run`` / ``run_async`` and ``get_is_started`` as Kit scripts poll them: in Kit ``run()``
  returns at once and the script updates the app ``while not get_is_started()`` and then ``while
  get_is_started()``; graphsdg's ``run()`` has made every frame when it returns, so the first
  ``get_is_started()`` after it answers True once (the run did start), and False from then on;
* ``omni.replicator.core.scripts.writers_default`` (and ``omni.replicator.core.writers_default``): the writer
  classes (``BasicWriter``, ``KittiWriter``, ...) and ``tools``, the module path of ``rep.tools``, with
  ``basicwriter`` / ``kitti`` / ``cocowriter`` submodules as custom-writer tutorials import them.

A refusal is added only where graphsdg has no such name, so an area or a room that implements one later
(``render_product_tiled``, ``omni_lidar``) is not hidden. ``docs/porting.md`` ("Replicator's public API")
lists every documented name and what it maps to.
"""
from __future__ import annotations

import types
from typing import Any, Callable

import graphsdg
from graphsdg import tools
from graphsdg.compat.modules import CompatError, CompatModule, ForwardingModule
from graphsdg.engine.capture import request_next_subframes, withdraw_subframe_request

# documented names graphsdg cannot honour: module -> name -> why (the error says it)
REFUSED: dict[str, dict[str, str]] = {
    "create": {
        "mdl_from_json": "it builds an MDL shader graph, and graphsdg renders UsdPreviewSurface-style materials "
                         "(use rep.create.material_omnipbr)",
        "projection_material": "RTX projection materials (a copy of the mesh pushed out along its normals, "
                               "textured by projection) are not rendered by MuJoCo's rasteriser",
        "mesh_decal": "RTX mesh decals are not rendered by MuJoCo's rasteriser",
        "tiled_sensor": "it is Replicator's deprecated RTX-sensor tiling (RTX sensors do not exist here); use "
                        "one render product per camera",
        "render_product_tiled": "tiled render products are not available in this build",
    },
    "get": {
        "normalized_decal_position": "it places RTX mesh decals, which graphsdg does not render",
    },
    "modify": {
        "projection_material": "RTX projection materials are not rendered by MuJoCo's rasteriser",
        "animation": "skeletal animation clips are not played (graphsdg has no skeleton animation runtime)",
    },
    "trigger": {
        "on_key_press": "graphsdg runs headless: there is no keyboard to press (use "
                        "rep.trigger.on_custom_event with rep.utils.send_og_event)",
    },
}


def refusal(qualified: str, why: str) -> Callable[..., Any]:
    """A stand-in for ``qualified`` that raises :class:`CompatError` naming it and saying ``why`` when called."""
    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise CompatError(f"{qualified} is not available in graphsdg's compat mode: {why}. See docs/porting.md "
                          f"(Replicator's public API).")

    refuse.__name__ = refuse.__qualname__ = qualified.rsplit(".", 1)[-1]
    refuse.__doc__ = f"Not available in graphsdg: {why}."
    return refuse


def set_next_rt_subframes(value: int) -> None:
    """Render the next capture with ``value`` subframes (at least ``/omni/replicator/RTSubframes``)."""
    request_next_subframes(value, minimum=False)


def set_minimum_next_rt_subframes(value: int) -> None:
    """Render the next capture with at least ``value`` subframes."""
    request_next_subframes(value, minimum=True)


def get_sim_times_to_write() -> list:
    """The simulation times still waiting to be written: none (each ``step()`` writes its own capture)."""
    return []


class _RunStarts:
    """Whether a finished ``run()``'s start has not been seen by ``get_is_started()`` yet."""

    unseen = False


def run(*args: Any, **kwargs: Any) -> None:
    """``rep.orchestrator.run``: make the frames, then let one ``get_is_started()`` see that the run started."""
    _RunStarts.unseen = False
    graphsdg.orchestrator.run(*args, **kwargs)
    _RunStarts.unseen = True


async def run_async(*args: Any, **kwargs: Any) -> None:
    """``rep.orchestrator.run_async``: :func:`run` for ``await``."""
    run(*args, **kwargs)


def get_is_started() -> bool:
    """True while generating, and once more after a ``run()`` finished (Kit's polling loops see it start)."""
    if graphsdg.orchestrator.get_is_started():
        return True
    seen, _RunStarts.unseen = _RunStarts.unseen, False
    return seen


def _family_module(family: str, target: types.ModuleType) -> ForwardingModule:
    """``omni.replicator.core.<family>`` forwarding to graphsdg's module, with the refusals graphsdg lacks."""
    extra = {name: refusal(f"omni.replicator.core.{family}.{name}", why)
             for name, why in REFUSED.get(family, {}).items() if not hasattr(target, name)}
    return ForwardingModule(f"omni.replicator.core.{family}", target, **extra)


def modules() -> list[types.ModuleType]:
    """The compat modules of this area (see the module docstring)."""
    out: list[types.ModuleType] = [_family_module(f, getattr(graphsdg, f)) for f in REFUSED]
    orchestrator_extra = {name: fn for name, fn in (
        ("set_next_rt_subframes", set_next_rt_subframes),
        ("set_minimum_next_rt_subframes", set_minimum_next_rt_subframes),
        ("get_sim_times_to_write", get_sim_times_to_write)) if not hasattr(graphsdg.orchestrator, name)}
    orchestrator_extra.update(run=run, run_async=run_async, get_is_started=get_is_started)
    out.append(ForwardingModule("omni.replicator.core.orchestrator", graphsdg.orchestrator, **orchestrator_extra))
    writers_tools = ForwardingModule("omni.replicator.core.scripts.writers_default.tools", tools)
    writer_classes = dict(graphsdg.WriterRegistry.get_writers())   # BasicWriter, KittiWriter, ... as classes
    out.append(writers_tools)
    out.append(CompatModule("omni.replicator.core.scripts.writers_default", tools=writers_tools, **writer_classes))
    out.append(CompatModule("omni.replicator.core.writers_default", tools=writers_tools, **writer_classes))
    for module, cls in (("basicwriter", "BasicWriter"), ("kitti", "KittiWriter"), ("cocowriter", "CocoWriter")):
        if cls in writer_classes:
            out.append(CompatModule(f"omni.replicator.core.scripts.writers_default.{module}",
                                    **{cls: writer_classes[cls]}))
    return out


def uninstall() -> None:
    """Forget a pending subframe request and an unseen run start (compat mode removed)."""
    withdraw_subframe_request()
    _RunStarts.unseen = False
