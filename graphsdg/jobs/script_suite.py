"""Run every script of a folder as ``graphsdg run`` would, with a verdict each. Each script runs in a fresh process
of its own.

A script passes when its process exits 0, prints no line matching the failure
pattern, and, if its source contains the pass marker (Isaac's examples print
``[SDG][Test][PASS]`` from their ``--test`` block), prints that marker. Each
script runs in its own working folder (``OUT/<script name>/``), so the relative
output folders of different scripts never mix.

Example (the command line form)::

    graphsdg run-folder isaac_examples/ --compat isaac --out /tmp/runs -- --test

prints one line per script and ``N passed, M failed``.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

PASS_MARKER = "[SDG][Test][PASS]"
FAIL_PATTERN = r"\[Test\]\[FAIL\]"


@dataclass(frozen=True)
class ScriptResult:
    """The verdict on one script: ``passed``, its exit code, wall seconds and, if it failed, why."""

    name: str
    passed: bool
    returncode: int
    seconds: float
    reason: str
    log: str

    def line(self) -> str:
        verdict = "PASS" if self.passed else "FAIL"
        return f"{verdict}  {self.name:<40} {self.seconds:7.1f} s" + ("" if self.passed else f"  {self.reason}")


def _verdict(source: str, output: str, returncode: int, timed_out: bool, timeout: float) -> tuple[bool, str]:
    if timed_out:
        return False, f"timed out after {timeout:g} s"
    lines = [ln for ln in output.splitlines() if ln.strip()]
    if returncode != 0:
        errors = [ln for ln in lines if "error" in ln.lower()]   # the error line, not the hint after it
        return False, f"exit code {returncode}: {(errors or lines or ['no output'])[-1].strip()}"
    failed = [ln for ln in lines if re.search(FAIL_PATTERN, ln)]
    if failed:
        return False, failed[0]
    if PASS_MARKER in source and PASS_MARKER not in output:
        return False, f"exited 0 without printing {PASS_MARKER}"
    return True, ""


def run_script_in_process(script: Path, workdir: Path, compat: str | None, script_args: Sequence[str],
                          timeout: float, extra: Sequence[str] = ()) -> ScriptResult:
    """Run ``script`` with ``graphsdg run`` in a new process whose working folder is ``workdir``."""
    workdir.mkdir(parents=True, exist_ok=True)
    command = [sys.executable, "-m", "graphsdg.jobs.cli", "run", str(script.resolve()), *extra]
    if compat:
        command += ["--compat", compat]
    command += ["--", *script_args]
    start = time.perf_counter()
    try:
        proc = subprocess.run(command, cwd=workdir, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              timeout=timeout)
        output, returncode, timed_out = proc.stdout, proc.returncode, False
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout or ""
        output, returncode, timed_out = out if isinstance(out, str) else out.decode(errors="replace"), -9, True
    seconds = time.perf_counter() - start
    (workdir / "run.log").write_text(output)
    passed, reason = _verdict(script.read_text(errors="replace"), output, returncode, timed_out, timeout)
    return ScriptResult(script.stem, passed, returncode, seconds, reason, output)


def run_folder(folder: str | os.PathLike, compat: str | None = None, script_args: Sequence[str] = (),
               out: str | os.PathLike | None = None, timeout: float = 600.0, pattern: str = "*.py",
               extra: Sequence[str] = (), report: Callable[[ScriptResult], None] | None = None
               ) -> list[ScriptResult]:
    """Run every script of ``folder`` matching ``pattern`` (sorted by name); ``report`` sees each result.

    Raises:
        FileNotFoundError: ``folder`` is not a folder, or holds no script matching ``pattern``.
    """
    root = Path(folder)
    if not root.is_dir():
        raise FileNotFoundError(f"script folder {str(folder)!r} does not exist or is not a folder")
    scripts = sorted(p for p in root.glob(pattern) if p.is_file())
    if not scripts:
        raise FileNotFoundError(f"script folder {str(folder)!r} has no file matching {pattern!r}")
    base = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="graphsdg_scripts_"))
    results = []
    for script in scripts:
        workdir = base / script.stem
        if workdir.exists():
            shutil.rmtree(workdir)   # a verdict on this run's output only
        result = run_script_in_process(script, workdir, compat, script_args, timeout, extra)
        results.append(result)
        if report is not None:
            report(result)
    return results


def summary_line(results: Sequence[ScriptResult]) -> str:
    passed = sum(r.passed for r in results)
    return f"{passed} passed, {len(results) - passed} failed"
