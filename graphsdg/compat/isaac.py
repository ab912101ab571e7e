"""Install Isaac Sim / Omniverse module names that map onto graphsdg.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.replicator.core as rep      # this is graphsdg
    >>> isaac.uninstall()

``graphsdg run --compat isaac script.py`` does this before running the script.
Only names listed in docs/porting.md exist; any other attribute of these
modules raises :class:`~graphsdg.compat.modules.CompatError` naming what is there.
"""
from __future__ import annotations

import importlib
import sys
import types

import graphsdg
from graphsdg import assets, functional
from graphsdg.compat import extensions, isaac_core, kit
from graphsdg.compat.modules import ROOTS, CompatFinder, CompatModule, ForwardingModule
from graphsdg.sim import transforms
from graphsdg.sim.timeline import TimelineEventType

# Compat modules of one Isaac area each: every module of graphsdg.compat with a ``modules() -> list[ModuleType]``
# function returning CompatModules named by their full Isaac name (:func:`_mount` links them under their parents).
# An area may have ``install()`` / ``uninstall()``, called by :func:`install` / :func:`uninstall` to hook into pxr or
# graphsdg's runtime and to let go again, and ``EXTENSIONS`` (extension name -> module prefixes it provides) and
# ``OFF_AT_START`` (those of its extensions Isaac leaves off), which join :mod:`graphsdg.compat.extensions`' tables.
def _discover_areas() -> tuple[str, ...]:
    import pkgutil

    import graphsdg.compat as package
    names = []
    for info in sorted(pkgutil.iter_modules(package.__path__), key=lambda i: i.name):
        if info.name in ("isaac", "modules", "pytest_plugin") or info.ispkg:
            continue
        name = f"{package.__name__}.{info.name}"
        if callable(getattr(importlib.import_module(name), "modules", None)):
            names.append(name)
    return tuple(names)


AREAS = _discover_areas()
for _area in AREAS:
    _module = importlib.import_module(_area)
    extensions.declare(getattr(_module, "EXTENSIONS", {}), getattr(_module, "OFF_AT_START", ()))

_installed: dict[str, types.ModuleType] = {}
_finder: CompatFinder | None = None


def _assets():
    return assets


def _modules() -> dict[str, types.ModuleType]:
    rep = ForwardingModule("omni.replicator.core", graphsdg, BackendDispatch=graphsdg.BackendDispatch)
    rep_functional = ForwardingModule("omni.replicator.core.functional", functional)
    utils = CompatModule("omni.replicator.core.scripts.functional.utils",
                         get_world_position=transforms.get_world_position,
                         get_world_transform_matrix=transforms.get_world_transform_matrix)
    scripts_functional = CompatModule("omni.replicator.core.scripts.functional", utils=utils)
    scripts = CompatModule("omni.replicator.core.scripts", functional=scripts_functional)
    rep.scripts = scripts  # type: ignore[attr-defined]
    rep.functional = rep_functional  # type: ignore[attr-defined]

    timeline = CompatModule("omni.timeline", get_timeline_interface=kit.get_timeline_interface,
                            TimelineEventType=TimelineEventType)
    app = CompatModule("omni.kit.app", get_app=kit.get_app)
    commands = CompatModule("omni.kit.commands", execute=kit.execute)
    kit_test = CompatModule("omni.kit.test", AsyncTestCase=kit.AsyncTestCase)
    omni_kit = CompatModule("omni.kit", app=app, commands=commands, test=kit_test)
    usd = CompatModule("omni.usd", get_context=kit.get_context, StageEventType=kit.StageEventType, StageState=kit.StageState,
                       get_world_transform_matrix=kit.get_world_transform_matrix,
                       get_local_transform_matrix=kit.get_local_transform_matrix)
    physx = CompatModule("omni.physx", get_physx_scene_query_interface=isaac_core.get_physx_scene_query_interface)
    replicator = CompatModule("omni.replicator", core=rep)
    omni = CompatModule("omni", replicator=replicator, usd=usd, timeline=timeline, kit=omni_kit, physx=physx)

    carb_settings = CompatModule("carb.settings", get_settings=kit.get_settings)
    carb_events = CompatModule("carb.events", IEvent=kit.Event, IEventStream=kit.EventStream)
    carb = CompatModule("carb", settings=carb_settings, events=carb_events, Float3=kit.Float3, Float4=kit.Float4,
                        log_info=kit.log_info, log_warn=kit.log_warn, log_error=kit.log_error)

    storage_native = CompatModule("isaacsim.storage.native",
                                  get_assets_root_path=lambda *a, **k: _assets().get_assets_root_path(*a, **k),
                                  get_assets_root_path_async=lambda *a, **k: _assets().get_assets_root_path_async(
                                      *a, **k))
    storage = CompatModule("isaacsim.storage", native=storage_native)
    replicator_writers = CompatModule("isaacsim.replicator.writers",
                                      PoseWriter=graphsdg.WriterRegistry.get_writers()["PoseWriter"])
    bounds = CompatModule("isaacsim.core.utils.bounds", create_bbox_cache=isaac_core.create_bbox_cache,
                          compute_aabb=isaac_core.compute_aabb,
                          compute_combined_aabb=isaac_core.compute_combined_aabb,
                          compute_obb=isaac_core.compute_obb)
    core_utils = CompatModule("isaacsim.core.utils", bounds=bounds)
    exp_bounds = CompatModule("isaacsim.core.experimental.utils.bounds",
                              create_bbox_cache=isaac_core.create_bbox_cache, compute_aabb=isaac_core.compute_aabb,
                              compute_combined_aabb=isaac_core.compute_combined_aabb,
                              compute_obb=isaac_core.compute_obb)
    exp_stage = CompatModule("isaacsim.core.experimental.utils.stage", get_current_stage=isaac_core.get_current_stage)
    # its names (Isaac Sim 6's keyword-only label helpers) come from graphsdg.compat.experimental_semantics
    exp_semantics = CompatModule("isaacsim.core.experimental.utils.semantics")
    exp_utils = CompatModule("isaacsim.core.experimental.utils", bounds=exp_bounds, stage=exp_stage,
                             semantics=exp_semantics)
    exp_prims = CompatModule("isaacsim.core.experimental.prims", RigidPrim=isaac_core.RigidPrim,
                             XformPrim=isaac_core.XformPrim)
    experimental = CompatModule("isaacsim.core.experimental", prims=exp_prims, utils=exp_utils)
    core = CompatModule("isaacsim.core", utils=core_utils, experimental=experimental)
    isaacsim = CompatModule("isaacsim", SimulationApp=kit.SimulationApp, storage=storage, core=core)

    modules = [omni, replicator, rep, rep_functional, scripts, scripts_functional, utils, usd, timeline,
               omni_kit, app, commands, kit_test, physx, carb, carb_settings, carb_events, isaacsim, storage,
               storage_native, replicator_writers, core, core_utils, bounds, experimental, exp_utils, exp_bounds,
               exp_stage,
               exp_semantics, exp_prims]
    scenario = _palletizing_module()
    if scenario is None:
        scenario = [CompatModule("isaacsim.examples", hint=(
            "Isaac's UR10 palletizing example maps to graphsdg.scenarios.palletizing, which this installation "
            "does not have."))]
    isaacsim.examples = scenario[-1]  # type: ignore[attr-defined]
    modules += scenario
    for area in AREAS:
        modules += importlib.import_module(area).modules()
    return _mount(modules)


def _mount(modules: list[types.ModuleType]) -> dict[str, types.ModuleType]:
    """Index ``modules`` by name, adding any missing ancestor package and setting each module as an
    attribute of its parent (``isaacsim.test.utils`` becomes ``isaacsim.test``'s ``utils``)."""
    by_name: dict[str, types.ModuleType] = {}
    for m in modules:
        if m.__name__ in by_name and by_name[m.__name__] is not m:
            # two areas add names to one module: merge the later one's names into the first
            by_name[m.__name__].__dict__.update({k: v for k, v in m.__dict__.items() if not k.startswith("__")
                                                 and k != "_hint"})
        else:
            by_name[m.__name__] = m
    for name in sorted(by_name, key=lambda n: n.count(".")):
        parent, _, leaf = name.rpartition(".")
        if not parent:
            continue
        if parent not in by_name and parent.split(".")[0] not in ROOTS:
            continue   # a name added to a real package (pxr.PhysxSchema): install() sets it there
        if parent not in by_name:
            _add_ancestors(by_name, parent)
        setattr(by_name[parent], leaf, by_name[name])
    return by_name


def _add_ancestors(by_name: dict[str, types.ModuleType], name: str) -> None:
    parts = name.split(".")
    for i in range(1, len(parts) + 1):
        path = ".".join(parts[:i])
        if path not in by_name:
            by_name[path] = CompatModule(path)
            if i > 1:
                setattr(by_name[".".join(parts[:i - 1])], parts[i - 1], by_name[path])


def _palletizing_module() -> list[types.ModuleType] | None:
    """The UR10 palletizing example's modules when the scenario exists: Isaac Sim 6.0.1's
    ``isaacsim.cortex.examples.ur10_palletizing.ur10_palletizing`` and the older
    ``isaacsim.examples.interactive.ur10_palletizing.ur10_palletizing``."""
    try:
        from graphsdg.scenarios import palletizing
    except ModuleNotFoundError as exc:   # absent; a scenario that is there but broken raises
        if exc.name in ("graphsdg.scenarios", "graphsdg.scenarios.palletizing"):
            return None
        raise
    leaf = CompatModule("isaacsim.examples.interactive.ur10_palletizing.ur10_palletizing",
                        BinStacking=palletizing.BinStacking)
    pkg = CompatModule("isaacsim.examples.interactive.ur10_palletizing", ur10_palletizing=leaf)
    interactive = CompatModule("isaacsim.examples.interactive", ur10_palletizing=pkg)
    examples = CompatModule("isaacsim.examples", interactive=interactive)
    cortex_leaf = CompatModule("isaacsim.cortex.examples.ur10_palletizing.ur10_palletizing",
                               BinStacking=palletizing.BinStacking)
    return [cortex_leaf, leaf, pkg, interactive, examples]


def install() -> None:
    """Put the Isaac / Omniverse names into ``sys.modules`` (no-op if already installed)."""
    if _installed:
        return
    modules = _modules()
    clash = [n for n in modules if n in sys.modules and n not in _installed]
    if clash:
        raise RuntimeError(f"cannot install graphsdg's Isaac compat modules: {clash[0]!r} is already imported "
                           f"(a real Omniverse install?)")
    manager = extensions.get_extension_manager()
    manager._reset()
    # modules of extensions Isaac leaves off import only once enabled (the finder loads them then)
    sys.modules.update({n: m for n, m in modules.items() if manager.providing(n) is None})
    _installed.update(modules)
    for name, module in modules.items():
        parent, _, leaf = name.rpartition(".")
        if parent and parent.split(".")[0] not in ROOTS:   # e.g. pxr.PhysxSchema on the real pxr package
            setattr(importlib.import_module(parent), leaf, module)
    global _finder
    _finder = CompatFinder(_installed, manager.providing)
    sys.meta_path.insert(0, _finder)
    kit.get_context()._listen()   # stage events from here on
    for area in AREAS:   # areas that extend pxr or graphsdg's runtime while installed
        extend = getattr(importlib.import_module(area), "install", None)
        if extend is not None:
            extend()


def uninstall() -> None:
    """Remove the names :func:`install` added."""
    global _finder
    for name in list(_installed):
        if sys.modules.get(name) is _installed[name]:
            del sys.modules[name]
        parent, _, leaf = name.rpartition(".")
        if parent and parent.split(".")[0] not in ROOTS and getattr(sys.modules.get(parent), leaf, None) is \
                _installed[name]:
            delattr(sys.modules[parent], leaf)
    _installed.clear()
    for name in [n for n in sys.modules if n.split(".")[0] in ROOTS]:
        # submodules imported by dotted path while installed (``omni.replicator.core.example`` is
        # graphsdg.example's stand-in, entered by the import system) and Isaac test packages
        del sys.modules[name]
    kit.get_context()._stop_listening()
    for area in AREAS:   # areas that hooked graphsdg's runtime let go of it
        release = getattr(importlib.import_module(area), "uninstall", None)
        if release is not None:
            release()
    if _finder is not None and _finder in sys.meta_path:
        sys.meta_path.remove(_finder)
    _finder = None


def installed_names() -> list[str]:
    """The Isaac / Omniverse module names currently installed."""
    return sorted(_installed)


def installed_module(name: str) -> types.ModuleType:
    """The installed compat module ``name`` (also those an extension that is off keeps out of ``sys.modules``)."""
    return _installed[name]


def is_installed() -> bool:
    return bool(_installed)
