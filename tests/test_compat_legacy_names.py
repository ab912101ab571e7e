"""Isaac Sim's pre-4.5 names (omni.isaac.*, omni.replicator.isaac, ...): the same objects as the new names, one
DeprecationWarning per old module naming the new one, clear errors where the new name is missing."""
from __future__ import annotations

import importlib
import sys
import warnings

import pytest

from graphsdg.compat import isaac
from graphsdg.compat.legacy_names import LegacyModule, lookup
from graphsdg.compat.legacy_table import EXTENSIONS, MOVED, NAMES, REMOVED
from graphsdg.compat.modules import CompatError, CompatImportError


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def deprecations(caught: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]


def test_simulation_app_old_name_is_the_new_object_and_warns_once(compat):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        from omni.isaac.kit import SimulationApp
        from omni.isaac.kit import SimulationApp as again   # already imported: no second warning
    import isaacsim
    from isaacsim.simulation_app import SimulationApp as new_home
    assert SimulationApp is again is isaacsim.SimulationApp is new_home
    messages = deprecations(caught)
    assert len(messages) == 1
    assert "omni.isaac.kit" in messages[0] and "isaacsim.simulation_app" in messages[0]
    assert caught[0].filename == __file__   # attributed to the import statement, as Python's own deprecations


def test_moved_module_gives_the_new_modules_objects(compat):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        from omni.isaac.core.utils.prims import get_prim_at_path, is_prim_path_valid
        import omni.isaac.core.utils.stage as old_stage
    import isaacsim.core.utils.prims as new_prims
    import isaacsim.core.utils.stage as new_stage
    assert get_prim_at_path is new_prims.get_prim_at_path and is_prim_path_valid is new_prims.is_prim_path_valid
    assert old_stage.add_reference_to_stage is new_stage.add_reference_to_stage
    messages = deprecations(caught)
    for old, new in (("omni.isaac.core.utils.prims", "isaacsim.core.utils.prims"),
                     ("omni.isaac.core.utils.stage", "isaacsim.core.utils.stage")):
        assert len([m for m in messages if m.startswith(old + " ")]) == 1
        assert any(m.startswith(old + " ") and new in m for m in messages)
    # the old names work on the real stage
    new_stage.create_new_stage()
    prim = old_stage.get_current_stage().DefinePrim("/World/Thing", "Xform")
    assert get_prim_at_path("/World/Thing") == prim and is_prim_path_valid("/World/Thing")


def test_star_import_and_submodule_attributes(compat):
    namespace: dict = {}
    exec("from omni.isaac.core.utils.stage import *", namespace)
    import isaacsim.core.utils.stage as new_stage
    exported = getattr(new_stage, "__all__", None) or [n for n in vars(new_stage) if not n.startswith("_")]
    assert {n: namespace[n] for n in exported} == {n: getattr(new_stage, n) for n in exported}
    import omni.isaac.core.utils as old_utils
    assert old_utils.stage is sys.modules["omni.isaac.core.utils.stage"]   # a submodule keeps its old name
    from omni.isaac.nucleus import get_assets_root_path
    from isaacsim.storage.native import get_assets_root_path as new_root
    assert get_assets_root_path is new_root


def test_renamed_names_resolve_lazily_to_the_new_object(compat, monkeypatch):
    import isaacsim.core.prims as new_prims
    import omni.isaac.core.prims.rigid_prim as old_module
    from omni.isaac.core.prims import XFormPrimView
    assert XFormPrimView is new_prims.XFormPrim             # the old *View class is the new plain one

    class LaterSingleRigidPrim:                            # what another area adds after the old module imported
        pass

    monkeypatch.setattr(new_prims, "SingleRigidPrim", LaterSingleRigidPrim, raising=False)
    assert old_module.RigidPrim is LaterSingleRigidPrim
    from omni.isaac.core.prims import RigidPrim
    assert RigidPrim is LaterSingleRigidPrim
    monkeypatch.delattr(new_prims, "SingleRigidPrim")
    with pytest.raises(CompatImportError) as caught:
        old_module.RigidPrim
    text = str(caught.value)
    assert "omni.isaac.core.prims.rigid_prim.RigidPrim" in text and "isaacsim.core.prims.SingleRigidPrim" in text


def test_missing_new_module_fails_naming_both(compat):
    with pytest.raises(CompatImportError) as caught:
        import omni.isaac.core.utils.no_such_module  # noqa: F401
    assert "omni.isaac.core.utils.no_such_module" in str(caught.value)
    assert "isaacsim.core.utils.no_such_module" in str(caught.value)
    with pytest.raises(CompatImportError, match="omni.isaac.franka.*isaacsim.robot.manipulators.examples.franka"):
        importlib.import_module("omni.isaac.franka.tasks")
    import omni.isaac.core.utils.stage as old_stage
    with pytest.raises(CompatError, match="omni.isaac.core.utils.stage.no_such_function is not available"):
        old_stage.no_such_function


def test_removed_and_unknown_old_names(compat):
    with pytest.raises(CompatImportError, match="omni.isaac.dynamic_control .*no replacement"):
        import omni.isaac.dynamic_control  # noqa: F401
    with pytest.raises(CompatImportError) as caught:
        import omni.isaac.no_such_extension  # noqa: F401
    assert "omni.isaac.no_such_extension is not one of Isaac's pre-4.5 module names" in str(caught.value)
    assert "omni.isaac provides: " in str(caught.value) and "core" in str(caught.value)
    with pytest.raises(CompatImportError, match="out of scope"):
        import omni.isaac.ros2_bridge  # noqa: F401


def test_old_extension_names(compat):
    from isaacsim.core.utils.extensions import enable_extension, get_extension_id
    import omni.kit.app
    assert enable_extension("omni.isaac.core") is True
    assert omni.kit.app.get_app().get_extension_manager().is_extension_enabled("omni.isaac.core")
    assert get_extension_id("omni.isaac.nucleus") == "omni.isaac.nucleus"
    with pytest.raises(CompatImportError, match="'omni.isaac.lula_test_widget' is Isaac's pre-4.5 name of "
                                                "isaacsim.robot_motion.lula_test_widget"):
        enable_extension("omni.isaac.lula_test_widget")


def test_old_modules_leave_with_uninstall_and_warn_again_after():
    isaac.install()
    try:
        importlib.import_module("omni.isaac.core.utils.prims")
        assert isinstance(sys.modules["omni.isaac.core.utils.prims"], LegacyModule)
    finally:
        isaac.uninstall()
    assert not [n for n in sys.modules if n.startswith(("omni.", "isaacsim."))]
    isaac.install()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            importlib.import_module("omni.isaac.core.utils.prims")
        assert any(m.startswith("omni.isaac.core.utils.prims ") for m in deprecations(caught))
    finally:
        isaac.uninstall()


def test_table_lookups():
    assert lookup("omni.isaac.core.utils.numpy.rotations") == ("moved", "isaacsim.core.utils.numpy.rotations")
    assert lookup("omni.isaac.core.world.world") == ("moved", "isaacsim.core.api.world.world")
    assert lookup("omni.isaac.core.prims.soft") == ("namespace", None)
    assert lookup("omni.isaac.core.prims.rigid_prim")[1] == {"RigidPrim": "isaacsim.core.prims:SingleRigidPrim"}
    assert lookup("omni.isaac.core.prims.base_sensor") == ("moved", "isaacsim.core.api.sensors.base_sensor")
    assert lookup("omni.isaac.core.prims.not_a_module") is None   # below a module of chosen names
    assert lookup("omni.replicator.isaac.scripts.writers.pose_writer")[1] == {
        "PoseWriter": "isaacsim.replicator.writers:PoseWriter"}
    assert lookup("omni.isaac.sensor")[1]["Camera"] == "isaacsim.sensors.camera:Camera"
    assert lookup("omni.replicator.core") is None and lookup("isaacsim.core.api") is None
    assert set(REMOVED) <= set(EXTENSIONS) | set(REMOVED)


def test_every_table_entry_imports_or_names_its_replacement(compat):
    """Each old module imports, or fails with CompatImportError naming it and its replacement (or why not);
    each renamed name is the new object or fails naming both names."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for old in sorted(set(MOVED) | set(NAMES) | set(REMOVED)):
            try:
                module = importlib.import_module(old)
            except CompatImportError as exc:
                text = str(exc)
                assert old in text or old.startswith(text.split(" ")[0]), (old, text)
                assert (MOVED.get(old, "") in text or "no replacement" in text or "out of scope" in text
                        or "pre-4.5 name of" in text), (old, text)
                continue
            for name, target in NAMES.get(old, {}).items():
                new_module, new_name = target.split(":")
                try:
                    value = getattr(module, name)
                except CompatImportError as exc:
                    assert f"{old}.{name}" in str(exc) and f"{new_module}.{new_name}" in str(exc)
                else:
                    assert value is getattr(importlib.import_module(new_module), new_name)


def test_warning_shows_for_imports_outside_main(tmp_path):
    """Python hides DeprecationWarnings raised outside __main__; the old names' warning shows (as Isaac's log line
    does), once for the module however many modules import it."""
    import subprocess
    for name in ("helper_one", "helper_two"):
        (tmp_path / f"{name}.py").write_text("from omni.isaac.core.utils.prims import get_prim_at_path\n")
    code = (f"import sys; sys.path.insert(0, {str(tmp_path)!r}); from graphsdg.compat import isaac; isaac.install(); "
            "import helper_one, helper_two; isaac.uninstall()")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    notice = "IsaacDeprecationWarning: omni.isaac.core.utils.prims "
    lines = [line for line in done.stderr.splitlines() if notice in line]
    assert len(lines) == 1 and "helper_one.py:1" in lines[0] and "isaacsim.core.utils.prims" in lines[0]
