"""A plain (non-editable) wheel carries the runtime and the node library."""
from __future__ import annotations

import os
import subprocess
import sys
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_wheel_contains_nodes_and_imports(tmp_path):
    wheel_dir = tmp_path / "dist"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                    "-w", str(wheel_dir), ROOT], check=True)
    wheels = list(wheel_dir.glob("graphsdg-*.whl"))
    assert len(wheels) == 1
    names = set(zipfile.ZipFile(wheels[0]).namelist())
    assert "graphsdg/nodes/annotators.py" in names and "graphsdg/orchestrator.py" in names
    # every module of the source tree ships (a package missing from pyproject's list would not)
    for folder, sub in (("graphsdg", "graphsdg"), ("nodes", "graphsdg/nodes")):
        for dirpath, _, files in os.walk(os.path.join(ROOT, folder)):
            rel = os.path.relpath(dirpath, os.path.join(ROOT, folder))
            for f in files:
                if f.endswith(".py"):
                    name = "/".join(p for p in (sub, rel if rel != "." else "", f) if p)
                    assert name in names, f"{name} is missing from the wheel (pyproject packages list?)"
    # every file of the asset pack ships (a file type missing from pyproject's package-data would not)
    pack_root = os.path.join(ROOT, "graphsdg", "assets", "pack")
    for dirpath, _, files in os.walk(pack_root):
        for f in files:
            name = "graphsdg/assets/pack/" + os.path.relpath(os.path.join(dirpath, f), pack_root).replace(os.sep, "/")
            assert name in names, f"{name} is missing from the wheel (pyproject package-data?)"
    target = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(target),
                    str(wheels[0])], check=True)
    code = ("import graphsdg, graphsdg.nodes, sys; "
            "assert graphsdg.__file__.startswith(sys.argv[1]), graphsdg.__file__; "
            "assert 'rgb' in graphsdg.annotators.get_registered_annotators(); "
            "from graphsdg.assets import get_assets_root_path as r; import os; "
            "assert r().startswith(sys.argv[1]) and os.path.isfile(r() + '/Isaac/Environments/Grid/"
            "default_environment.usd'), r(); print('ok')")
    env = {**os.environ, "PYTHONPATH": str(target)}
    out = subprocess.run([sys.executable, "-c", code, str(target)], cwd=str(tmp_path), env=env,
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


def test_plain_import_leaves_isaac_names_alone(tmp_path):
    code = "import graphsdg, sys; bad = [m for m in sys.modules if m.split('.')[0] in ('omni', 'carb', 'isaacsim')]; " \
           "assert not bad, bad"
    subprocess.run([sys.executable, "-c", code], check=True, cwd=str(tmp_path))


def test_source_checkout_imports_the_node_library():
    code = "import graphsdg, sys; assert graphsdg.__file__.startswith(sys.argv[1]); " \
           "assert 'rgb' in graphsdg.annotators.get_registered_annotators()"
    subprocess.run([sys.executable, "-c", code, ROOT], check=True, cwd=ROOT)


def test_rendering_works_when_mujoco_was_imported_first(tmp_path):
    code = ("import mujoco\nimport graphsdg as rep\n"
            "cam = rep.functional.create.camera(position=(3, 3, 3), look_at=(0, 0, 0))\n"
            "rp = rep.create.render_product(cam, (16, 16)); a = rep.annotators.get('rgb'); a.attach(rp)\n"
            "rep.orchestrator.step(); assert a.get_data().shape == (16, 16, 4)\n")
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    subprocess.run([sys.executable, "-c", code], check=True, cwd=str(tmp_path), env=env)
