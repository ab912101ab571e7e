"""Isaac compat area: SimReady assets, Kit actions and the upgrade of legacy semantics.

* ``omni.simready.explorer`` (an extension Isaac leaves off; enable it first):
  ``find_assets(search_words)`` searches the asset pack's SimReady catalogue
  (:mod:`graphsdg.assets.simready`) as the SimReady Explorer does: every search
  word must match, case-insensitively and as a substring, the asset's name or
  one of its tags or labels; no words (or ``None``) finds every asset. Results are
  :class:`SimreadyAsset` objects (``name``, ``main_url``, ``tags``, ``labels``,
  ``hierarchy``, ``behaviors``, ``extent_in_meters``, ...). ``add_asset_to_stage``
  references one into the current stage with variant selections.
* ``omni.kit.actions.core``: a registry of named actions per extension;
  ``execute_action("omni.simready.explorer", "toggle_window")`` is registered.
  There is no UI here: toggling the window only marks it open (the explorer's
  ``browser_model`` is then the catalogue) and warns once.
* ``isaacsim.core.experimental.utils.semantics.upgrade_prim_semantics_to_labels``
  rewrites Isaac's older ``Semantics.SemanticsAPI`` labels as
  ``UsdSemantics.LabelsAPI`` labels.

Example:
    >>> from graphsdg.compat import isaac
    >>> isaac.install()
    >>> import omni.kit.app, asyncio
    >>> omni.kit.app.get_app().get_extension_manager().set_extension_enabled_immediate("omni.simready.explorer", True)
    True
    >>> import omni.simready.explorer as sre
    >>> sorted(a.name for a in asyncio.run(sre.find_assets(["bowl"])))
    ['bowl_cereal_a01', 'bowl_serving_a02']
    >>> isaac.uninstall()
"""
from __future__ import annotations

import enum
import json
import os
import types
import warnings
from typing import Any, Callable, Iterable, Sequence

from pxr import Gf, Sdf, Usd, UsdGeom

from graphsdg.assets import get_assets_root_path
from graphsdg.compat.extensions import get_extension_manager
from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.functional import create
from graphsdg.stage import get_stage, semantics
from graphsdg.stage.xform import set_local_pose

EXPLORER = "omni.simready.explorer"
TOGGLE_WINDOW = "toggle_window"
_warned: set[str] = set()


def _warn_once(key: str, message: str) -> None:
    """Warn once per process for something that has no effect here (``key`` names it)."""
    if key not in _warned:
        _warned.add(key)
        warnings.warn(message, stacklevel=3)


# ---- the SimReady catalogue -------------------------------------------------------------------------------
class AssetType(enum.IntEnum):
    """omni.simready.explorer.AssetType: the kinds of SimReady assets (the pack's stand-ins are all PROP)."""

    PROP = 0
    VEHICLE = 1
    CHARACTER = 2
    GENERIC = 3


class SimreadyAsset(CompatObject):
    """omni.simready.explorer.SimreadyAsset: one asset of the catalogue."""

    _compat_name = "omni.simready.explorer.SimreadyAsset"

    def __init__(self, record: dict, root: str) -> None:
        self._record = dict(record)
        self._root = root

    @property
    def name(self) -> str:
        """The asset's name."""
        return self._record["name"]

    @property
    def main_url(self) -> str:
        """Absolute path of the asset's USD file."""
        return os.path.join(self._root, self._record["url"].lstrip("/"))

    @property
    def tags(self) -> list[str]:
        """Search tags (the labels are tags too)."""
        return list(dict.fromkeys(self._record["tags"] + self._record["labels"]))

    @property
    def labels(self) -> list[str]:
        """Semantic class labels."""
        return list(self._record["labels"])

    @property
    def hierarchy(self) -> list[str]:
        """Category path, most general first."""
        return list(self._record["hierarchy"])

    @property
    def behaviors(self) -> dict[str, list[str]]:
        """Variant sets the asset offers and their variants (``{"PhysicsVariant": ["None", "RigidBody"]}``)."""
        return {k: list(v) for k, v in self._record["behaviors"].items()}

    @property
    def asset_type(self) -> AssetType:
        """The asset's :class:`AssetType`."""
        return AssetType[self._record["asset_type"]]

    @property
    def extent_in_meters(self) -> tuple[float, float, float]:
        """Bounding-box size (x, y, z) in metres."""
        return tuple(float(v) for v in self._record["extent_m"])

    @property
    def extent_as_str(self) -> str:
        """The size as the explorer shows it: ``"1.60 x 0.90 x 0.75 m"``."""
        return " x ".join(f"{v:.2f}" for v in self.extent_in_meters) + " m"

    def __repr__(self) -> str:
        return f"SimreadyAsset({self.name!r}, {self.main_url!r})"


class PropAsset(SimreadyAsset):
    """omni.simready.explorer.PropAsset: a SimReady prop."""

    _compat_name = "omni.simready.explorer.PropAsset"


class Catalog(CompatObject):
    """The SimReady catalogue of an asset root: the records of its ``simready_catalog.json``."""

    _compat_name = "omni.simready.explorer.BrowserModel"

    def __init__(self, root: str) -> None:
        from graphsdg.assets.simready import SIMREADY_CATALOG
        path = os.path.join(root, SIMREADY_CATALOG.lstrip("/"))
        if not os.path.isfile(path):
            raise FileNotFoundError(f"the SimReady catalogue {path!r} does not exist under the asset root {root!r}")
        with open(path, encoding="utf-8") as f:
            self.records: list[dict] = json.load(f)["assets"]
        self.root = root

    def search(self, search_words: Iterable[str] | None) -> list[PropAsset]:
        """Assets whose name, tags or labels contain every one of ``search_words`` (case-insensitive)."""
        words = _check_words(search_words)
        found = []
        for record in self.records:
            fields = [record["name"].lower()] + [t.lower() for t in record["tags"] + record["labels"]]
            if all(any(w in f for f in fields) for w in words):
                found.append(PropAsset(record, self.root))
        return found


def _check_words(search_words: Iterable[str] | None) -> list[str]:
    if search_words is None:
        return []
    if isinstance(search_words, str):
        raise TypeError(f"find_assets search_words must be a list of strings, got the string {search_words!r} "
                        f"(write [{search_words!r}])")
    words = list(search_words)
    bad = [w for w in words if not isinstance(w, str)]
    if bad:
        raise TypeError(f"find_assets search_words must be strings, got {bad[0]!r}")
    return [w.strip().lower() for w in words if w.strip()]


def _catalog() -> Catalog:
    root = get_assets_root_path()
    if root is None:
        raise FileNotFoundError("no asset root (get_assets_root_path() is None): the SimReady catalogue cannot "
                                "be read")
    cached = _explorer._catalogs.get(root)
    if cached is None:
        cached = _explorer._catalogs[root] = Catalog(root)
    return cached


async def find_assets(search_words: Sequence[str] | None = None) -> list[SimreadyAsset]:
    """omni.simready.explorer.find_assets: assets matching every search word (all assets for none)."""
    return _catalog().search(search_words)


def add_asset_to_stage(url: str, parent_path: Sdf.Path | str = Sdf.Path.emptyPath,
                       position: Gf.Vec3d | Sequence[float] = (0.0, 0.0, 0.0),
                       variants: dict[str, str] | None = None, payload: bool = False,
                       instanceable: bool = False) -> tuple[bool, Sdf.Path]:
    """omni.simready.explorer.add_asset_to_stage: reference (or payload) ``url`` as a new Xform under
    ``parent_path`` at ``position``, with ``variants`` selected; returns (True, the new prim's path).

    Raises ``ValueError`` naming a variant set or variant the asset does not offer.
    """
    parent = str(parent_path) if str(parent_path) else None
    name = os.path.splitext(os.path.basename(os.fspath(url)))[0]
    if payload:
        prim = create.xform(name=name, parent=parent)
        prim.GetPayloads().AddPayload(os.fspath(url))
    else:
        prim = create.reference(usd_path=url, parent=parent, name=name)
    set_local_pose(prim, position=[float(v) for v in position])   # keeps the asset's own pose ops
    select_variants(prim, variants or {})
    if instanceable:
        prim.SetInstanceable(True)
    return True, prim.GetPath()


def select_variants(prim: Usd.Prim, variants: dict[str, str]) -> None:
    """Select ``variants`` (variant set -> variant) on ``prim``; unknown sets or variants raise ``ValueError``."""
    sets = prim.GetVariantSets()
    for set_name, choice in variants.items():
        if not sets.HasVariantSet(set_name):
            raise ValueError(f"{prim.GetPath()} has no variant set {set_name!r}; it has {sets.GetNames()}")
        vset = sets.GetVariantSet(set_name)
        if choice not in vset.GetVariantNames():
            raise ValueError(f"variant set {set_name!r} of {prim.GetPath()} has no variant {choice!r}; it has "
                             f"{vset.GetVariantNames()}")
        vset.SetVariantSelection(choice)


def get_average_position_of_prims(prims: Sequence[Usd.Prim]) -> Gf.Vec3d:
    """omni.simready.explorer.get_average_position_of_prims: mean world position of ``prims``."""
    prims = list(prims)
    if not prims:
        raise ValueError("get_average_position_of_prims needs at least one prim, got none")
    total = Gf.Vec3d(0.0, 0.0, 0.0)
    for prim in prims:
        total += UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()).ExtractTranslation()
    return total / len(prims)


class Explorer(CompatObject):
    """The SimReady Explorer extension instance (``omni.simready.explorer.get_instance()``).

    ``browser_model`` is None until the explorer window is toggled open (the
    ``toggle_window`` action); then it is the :class:`Catalog` of the asset root.
    """

    _compat_name = "omni.simready.explorer.SimReadyExplorerExtension"

    def __init__(self) -> None:
        self.browser_model: Catalog | None = None
        self._catalogs: dict[str, Catalog] = {}

    def toggle_window(self) -> None:
        """Open or close the explorer window (no UI here: only ``browser_model`` follows; warns once)."""
        _warn_once("toggle_window", "omni.simready.explorer's window (action 'toggle_window') has no UI in "
                   "graphsdg: toggling it only sets get_instance().browser_model; find_assets searches the asset "
                   "pack's SimReady catalogue either way")
        self.browser_model = None if self.browser_model is not None else _catalog()


_explorer = Explorer()


def get_instance() -> Explorer:
    """omni.simready.explorer.get_instance(): the explorer extension instance."""
    return _explorer


# ---- omni.kit.actions.core ----------------------------------------------------------------------------------
class Action(CompatObject):
    """omni.kit.actions.core.Action: a named callable of an extension."""

    _compat_name = "omni.kit.actions.core.Action"

    def __init__(self, extension_id: str, action_id: str, fn: Callable[..., Any], display_name: str = "",
                 description: str = "", tag: str = "") -> None:
        self.extension_id, self.id, self._fn = extension_id, action_id, fn
        self.display_name, self.description, self.tag = display_name or action_id, description, tag

    def execute(self, *args: Any, **kwargs: Any) -> Any:
        """Run the action."""
        return self._fn(*args, **kwargs)


class ActionRegistry(CompatObject):
    """omni.kit.actions.core.ActionRegistry: actions by (extension id, action id)."""

    _compat_name = "omni.kit.actions.core.ActionRegistry"

    def __init__(self) -> None:
        self._actions: dict[tuple[str, str], Action] = {}

    def register_action(self, extension_id: str, action_id: str, fn: Callable[..., Any], display_name: str = "",
                        description: str = "", tag: str = "") -> Action:
        """Register (or replace) ``fn`` as ``extension_id``/``action_id``."""
        if not callable(fn):
            raise TypeError(f"action {extension_id}/{action_id} must be callable, got {fn!r}")
        action = Action(extension_id, action_id, fn, display_name, description, tag)
        self._actions[(extension_id, action_id)] = action
        return action

    def deregister_action(self, extension_id: str, action_id: str) -> Action | None:
        """Remove an action; returns it (None if it was not registered)."""
        return self._actions.pop((extension_id, action_id), None)

    def get_action(self, extension_id: str, action_id: str) -> Action | None:
        """The action, or None."""
        return self._actions.get((extension_id, action_id))

    def get_all_actions(self) -> list[Action]:
        """Every registered action."""
        return list(self._actions.values())

    def get_all_actions_for_extension(self, extension_id: str) -> list[Action]:
        """The actions of one extension."""
        return [a for (ext, _), a in self._actions.items() if ext == extension_id]

    def execute_action(self, extension_id: str, action_id: str, *args: Any, **kwargs: Any) -> Any:
        """Run an action. Raises ``KeyError`` naming an action that is not registered, or whose extension is off."""
        action = self._actions.get((extension_id, action_id))
        if action is None:
            known = ", ".join(f"{e}/{a}" for e, a in sorted(self._actions)) or "none"
            raise KeyError(f"no action {action_id!r} of extension {extension_id!r} is registered; registered: "
                           f"{known}")
        manager = get_extension_manager()
        if extension_id in _EXTENSION_ACTIONS and not manager.is_extension_enabled(extension_id):
            raise KeyError(f"action {extension_id}/{action_id} belongs to the extension {extension_id!r}, which is "
                           f"not enabled; enable it first, as in Isaac Sim")
        return action.execute(*args, **kwargs)


# actions that extensions register when Kit loads them (they run only while the extension is enabled)
_EXTENSION_ACTIONS = {EXPLORER}
_registry = ActionRegistry()
_registry.register_action(EXPLORER, TOGGLE_WINDOW, lambda *a, **k: _explorer.toggle_window(),
                          display_name="SimReady Explorer", description="Show or hide the SimReady Explorer window")


def get_action_registry() -> ActionRegistry:
    """omni.kit.actions.core.get_action_registry()."""
    return _registry


def execute_action(extension_id: str, action_id: str, *args: Any, **kwargs: Any) -> Any:
    """omni.kit.actions.core.execute_action: run a registered action."""
    return _registry.execute_action(extension_id, action_id, *args, **kwargs)


# ---- legacy semantics -----------------------------------------------------------------------------------------
def _schema_tokens(prim: Usd.Prim) -> list[str]:
    """The prim's composed ``apiSchemas`` tokens, those of schemas usd-core does not know included
    (``GetAppliedSchemas`` drops unregistered ones such as Isaac's ``SemanticsAPI``)."""
    items: list[str] = []
    for spec in reversed(prim.GetPrimStack()):           # weakest opinion first
        if spec.HasInfo("apiSchemas"):
            items = list(spec.GetInfo("apiSchemas").ApplyOperations(items))
    return items


def _legacy_instances(prim: Usd.Prim) -> list[str]:
    """Instance names of the older ``SemanticsAPI`` still on ``prim``: applied, or with a type value."""
    names = [t.split(":", 1)[1] for t in _schema_tokens(prim) if t.startswith("SemanticsAPI:")]
    for attr in prim.GetAttributes():
        parts = attr.GetName().split(":")
        if len(parts) == 4 and parts[0] == "semantic" and parts[2:] == ["params", "semanticType"] and attr.Get():
            names.append(parts[1])
    return list(dict.fromkeys(names))


def upgrade_prim_semantics_to_labels(prim: Usd.Prim | str, include_descendants: bool = False) -> int:
    """Rewrite the older ``Semantics.SemanticsAPI`` labels of ``prim`` (and its descendants if
    ``include_descendants``) as ``UsdSemantics.LabelsAPI`` labels: ``semanticType`` becomes the taxonomy,
    ``semanticData`` a label in it. The old API and its attributes are removed (blocked where a referenced
    layer authors them). Returns how many ``SemanticsAPI`` instances were upgraded.
    """
    if isinstance(prim, (str, Sdf.Path)):
        path = str(prim)
        prim = get_stage().GetPrimAtPath(path)
        if not prim:
            raise ValueError(f"upgrade_prim_semantics_to_labels: no prim at {path!r}")
    if not isinstance(prim, Usd.Prim) or not prim.IsValid():
        raise ValueError(f"upgrade_prim_semantics_to_labels needs a valid Usd.Prim or prim path, got {prim!r}")
    count = 0
    for p in (Usd.PrimRange(prim) if include_descendants else [prim]):
        for instance in _legacy_instances(p):
            type_attr = p.GetAttribute(f"semantic:{instance}:params:semanticType")
            data_attr = p.GetAttribute(f"semantic:{instance}:params:semanticData")
            sem_type = type_attr.Get() if type_attr else None
            data = data_attr.Get() if data_attr else None
            if sem_type and data:
                semantics.apply(p, {str(sem_type): str(data)}, mode="add")
            for attr in (type_attr, data_attr):
                if attr:
                    p.RemoveProperty(attr.GetName())
                    left = p.GetAttribute(attr.GetName())
                    if left and left.HasAuthoredValue():   # authored in a referenced layer: block it
                        left.Block()
            token = f"SemanticsAPI:{instance}"
            if token in _schema_tokens(p):
                p.RemoveAppliedSchema(token)
            count += 1
    return count


def modules() -> list[types.ModuleType]:
    """``omni.simready.explorer``, ``omni.kit.actions.core`` and the semantics upgrade."""
    explorer = CompatModule(EXPLORER, find_assets=find_assets, add_asset_to_stage=add_asset_to_stage,
                            get_average_position_of_prims=get_average_position_of_prims, get_instance=get_instance,
                            SimreadyAsset=SimreadyAsset, PropAsset=PropAsset, AssetType=AssetType)
    actions = CompatModule("omni.kit.actions.core", get_action_registry=get_action_registry,
                           execute_action=execute_action, ActionRegistry=ActionRegistry, Action=Action)
    exp_semantics = CompatModule("isaacsim.core.experimental.utils.semantics",
                                 upgrade_prim_semantics_to_labels=upgrade_prim_semantics_to_labels)
    return [explorer, actions, exp_semantics]
