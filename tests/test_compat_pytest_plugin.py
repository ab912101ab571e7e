"""The opt-in pytest plugin gives an Isaac extension's test files what Kit's test runner gives them."""
import subprocess
import sys
import textwrap
from pathlib import Path

from graphsdg.compat import pytest_plugin

MANIFEST = textwrap.dedent('''
    [package]
    version = "1.0.0"

    [dependencies]
    "omni.replicator.core" = {}

    [[python.module]]
    name = "my.ext"

    [[test]]
    name = "plain"
    pythonTests.exclude = ["my.ext.tests.test_special*test_*"]
    dependencies = ["isaacsim.test.utils", "some.unknown.extension"]
    args = ["--/omni/replicator/RTSubframes=3", "--/rtx/descriptorSets=360000"]

    [[test]]
    name = "special"
    pythonTests.include = ["my.ext.tests.test_special*test_*"]
    dependencies = ["omni.simready.explorer"]
''')

TEST_FILE = textwrap.dedent('''
    import carb.settings
    import omni.kit.test
    from isaacsim.test.utils.file_validation import validate_folder_contents   # off until enabled

    class TestPlain(omni.kit.test.AsyncTestCase):
        async def test_setting_applied(self):
            self.assertEqual(carb.settings.get_settings().get("/omni/replicator/RTSubframes"), 3)
            self.assertTrue(callable(validate_folder_contents))
''')


def _extension(tmp_path: Path) -> Path:
    root = tmp_path / "my.ext"
    (root / "config").mkdir(parents=True)
    (root / "config" / "extension.toml").write_text(MANIFEST)
    tests = root / "python" / "tests"
    tests.mkdir(parents=True)
    (tests / "__init__.py").write_text("")
    (tests / "test_plain.py").write_text(TEST_FILE)
    (tests / "test_special.py").write_text("def test_nothing():\n    pass\n")
    return root


def test_entries_select_by_kit_patterns(tmp_path):
    root = _extension(tmp_path)
    manifest = pytest_plugin._load(root / "config" / "extension.toml")
    plain = pytest_plugin.selected_test_entries(manifest, "my.ext.tests.test_plain")
    special = pytest_plugin.selected_test_entries(manifest, "my.ext.tests.test_special")
    assert [e["name"] for e in plain] == ["plain"]
    assert [e["name"] for e in special] == ["special"]
    assert pytest_plugin.test_module_name(manifest, root / "config" / "extension.toml",
                                          root / "python" / "tests" / "test_plain.py") == "my.ext.tests.test_plain"


def test_setting_arguments_parse_like_kit():
    assert pytest_plugin.setting_arguments(["--enable", "x", "--/a/b=1", "--/c=true", '--/d="Z"', "--/e=0.5"]) == {
        "/a/b": 1, "/c": True, "/d": "Z", "/e": 0.5}


def test_extension_tests_run_with_their_dependencies_enabled(tmp_path):
    root = _extension(tmp_path)
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "graphsdg.compat.pytest_plugin",
                          "--import-mode=importlib", "-p", "no:cacheprovider", str(root / "python" / "tests")],
                         capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "2 passed" in run.stdout


def test_an_extension_under_test_has_its_folder_as_extension_path(tmp_path):
    root = _extension(tmp_path)
    (root / "python" / "tests" / "test_path.py").write_text(textwrap.dedent(f'''
        import omni.kit.app

        def test_folder():
            manager = omni.kit.app.get_app().get_extension_manager()
            assert manager.get_extension_path("my.ext") == {str(root)!r}
            assert manager.get_extension_path_by_module("my.ext.tests") == {str(root)!r}
    '''))
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "graphsdg.compat.pytest_plugin",
                          "--import-mode=importlib", "-p", "no:cacheprovider",
                          str(root / "python" / "tests" / "test_path.py")],
                         capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr


def test_a_test_imports_another_extensions_test_helpers_from_its_source_folder(tmp_path):
    """Kit loads an extension's ``tests`` package with it; one extension's tests import another's helpers."""
    tree = tmp_path / "source"
    helper = tree / "deprecated" / "isaacsim.sensors.rtx"          # graphsdg maps the module, not its tests
    (helper / "config").mkdir(parents=True)
    (helper / "config" / "extension.toml").write_text(
        '[[python.module]]\nname = "isaacsim.sensors.rtx"\n\n[[python.module]]\nname = "isaacsim.sensors.rtx.tests"\n')
    (helper / "python" / "tests").mkdir(parents=True)
    (helper / "python" / "tests" / "__init__.py").write_text("")
    (helper / "python" / "tests" / "common.py").write_text("def answer():\n    return 6 * 7\n")
    user = tree / "extensions" / "my.ext"
    (user / "config").mkdir(parents=True)
    (user / "config" / "extension.toml").write_text(
        '[dependencies]\n"isaacsim.sensors.rtx" = {}\n\n[[python.module]]\nname = "my.ext"\n')
    (user / "python" / "tests").mkdir(parents=True)
    (user / "python" / "tests" / "__init__.py").write_text("")
    (user / "python" / "tests" / "test_uses_helper.py").write_text(textwrap.dedent('''
        import isaacsim.sensors.rtx
        from isaacsim.sensors.rtx.tests.common import answer

        def test_helper():
            assert answer() == 42
            assert hasattr(isaacsim.sensors.rtx, "LidarRtx")        # still graphsdg's module
    '''))
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "graphsdg.compat.pytest_plugin",
                          "--import-mode=importlib", "-p", "no:cacheprovider", str(user / "python" / "tests")],
                         capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "1 passed" in run.stdout
    # a module under a mapped name that no stood-in folder holds still fails naming what is mapped
    (user / "python" / "tests" / "test_missing.py").write_text(
        "def test_missing():\n    import isaacsim.sensors.rtx.nowhere\n")
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "graphsdg.compat.pytest_plugin",
                          "--import-mode=importlib", "-p", "no:cacheprovider",
                          str(user / "python" / "tests" / "test_missing.py")],
                         capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert run.returncode == 1 and "isaacsim.sensors.rtx.nowhere is not available" in run.stdout
