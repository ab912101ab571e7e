"""graphsdg run-folder: one verdict per script, each in its own process and working folder."""
from __future__ import annotations

import subprocess
import sys
import textwrap

from graphsdg.jobs.script_suite import run_folder, summary_line

PASSING = '''
import os, sys
from isaacsim.core.utils.extensions import enable_extension
enable_extension("isaacsim.test.utils")
from isaacsim.test.utils.file_validation import validate_folder_contents
os.makedirs("_out", exist_ok=True)
open("_out/a.txt", "w").write(" ".join(sys.argv[1:]))
if validate_folder_contents("_out", {"txt": 1}, fail_on_empty_files=True):
    print("[SDG][Test][PASS] ok")
'''
SILENT = '''
# prints [SDG][Test][PASS] only when its check holds; here it does not
if False:
    print("[SDG][Test][PASS]")
'''
FAILING = '''
print("[SDG][Test][FAIL] counted 2 files")
'''
CRASHING = '''
import omni.not_a_module
'''


def _folder(tmp_path):
    folder = tmp_path / "scripts"
    folder.mkdir()
    for name, code in {"a_pass": PASSING, "b_silent": SILENT, "c_fail": FAILING, "d_crash": CRASHING}.items():
        (folder / f"{name}.py").write_text(textwrap.dedent(code))
    return folder


def test_verdicts_per_script_and_separate_working_folders(tmp_path):
    out = tmp_path / "runs"
    results = run_folder(_folder(tmp_path), compat="isaac", script_args=["--test"], out=out, timeout=120)
    verdicts = {r.name: (r.passed, r.reason) for r in results}
    assert verdicts["a_pass"] == (True, "")
    assert (out / "a_pass" / "_out" / "a.txt").read_text() == "--test"   # the script's args and its own folder
    assert "without printing [SDG][Test][PASS]" in verdicts["b_silent"][1]
    assert verdicts["c_fail"] == (False, "[SDG][Test][FAIL] counted 2 files")
    assert "omni.not_a_module" in verdicts["d_crash"][1] and not verdicts["d_crash"][0]
    assert summary_line(results) == "1 passed, 3 failed"


def test_command_line_prints_a_line_per_script_and_exits_1_on_a_failure(tmp_path):
    folder = _folder(tmp_path)
    proc = subprocess.run([sys.executable, "-m", "graphsdg.jobs.cli", "run-folder", str(folder), "--compat", "isaac",
                           "--pattern", "[ac]_*.py", "--out", str(tmp_path / "o"), "--", "--test"],
                          capture_output=True, text=True, timeout=120)
    lines = proc.stdout.strip().splitlines()
    assert proc.returncode == 1
    assert lines[0].startswith("PASS  a_pass") and lines[1].startswith("FAIL  c_fail")
    assert lines[-1] == "1 passed, 1 failed"
    missing = subprocess.run([sys.executable, "-m", "graphsdg.jobs.cli", "run-folder", str(tmp_path / "none")],
                             capture_output=True, text=True, timeout=60)
    assert missing.returncode != 0 and "does not exist" in missing.stderr
