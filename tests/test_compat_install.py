"""Installing compat mode: out-of-scope Isaac capabilities say why, modules at their Isaac 6 paths, a clean uninstall."""
import importlib

import pytest

from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatImportError


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


@pytest.mark.parametrize("module, words", [
    ("isaacsim.ros2.bridge", "ROS 2"),
    ("omni.kit.livestream.webrtc", "livestream"),
    ("isaacsim.replicator.nurec_utils", "NuRec"),
    ("isaacsim.replicator.teleop", "teleoperation"),
    ("omni.ui", "UI"),
])
def test_import_names_the_module_and_the_reason(compat, module, words):
    with pytest.raises(CompatImportError) as caught:
        importlib.import_module(module)
    message = str(caught.value)
    assert "out of scope" in message and words in message
    assert module.split(".")[0] in message


def test_enabling_an_out_of_scope_extension_says_why(compat):
    from isaacsim.core.utils.extensions import enable_extension
    with pytest.raises(CompatImportError, match=r"'isaacsim.ros2.bridge' is out of scope.*ROS 2"):
        enable_extension("isaacsim.ros2.bridge")


def test_an_unmapped_name_still_gets_the_generic_answer(compat):
    with pytest.raises(CompatImportError, match="not available in graphsdg's compat mode"):
        importlib.import_module("isaacsim.no_such_module")


def test_palletizing_example_imports_from_its_isaac_6_path(compat):
    from isaacsim.core.utils.extensions import enable_extension
    assert enable_extension("isaacsim.cortex.examples")
    from isaacsim.cortex.examples.ur10_palletizing.ur10_palletizing import BinStacking
    from isaacsim.examples.interactive.ur10_palletizing.ur10_palletizing import BinStacking as older
    from graphsdg.scenarios.palletizing import BinStacking as scenario
    assert BinStacking is older is scenario


def test_uninstall_leaves_no_isaac_module_behind():
    import sys
    isaac.install()
    import omni.replicator.core.functional.create   # noqa: F401 - a submodule entered by dotted import
    importlib.import_module("omni.replicator.core.scripts.functional.utils")
    isaac.uninstall()
    assert [n for n in sys.modules if n.split(".")[0] in ("omni", "carb", "isaacsim")] == []
