"""Run Isaac Sim 6's Replicator-using scripts and tests unchanged under graphsdg's compat mode, one line each.

The targets are every file under ``source/standalone_examples/`` of an Isaac Sim
source tree that imports ``omni.replicator.core``, and every test file under
``source/extensions/*/`` and ``source/deprecated/*/`` that does. Scripts run
with ``graphsdg run --compat isaac`` in their own process and working folder,
with the small arguments of :data:`SCRIPT_ARGS` (``--test`` where the script
has one, a few frames for benchmarks); test files run under pytest with
``graphsdg.compat.pytest_plugin``, one process each, and count test by test.
Files out of scope (:data:`OUT_OF_SCOPE`) still run, to show that they fail with
graphsdg's error saying why, and are counted apart.

Usage (Isaac's tree from ``fetch github:isaac-sim/IsaacSim``, extracted)::

    python bench/isaac_tree.py /path/to/IsaacSim --out /tmp/isaac_runs [--markdown table.md] [--only scripts|tests]

prints one line per file and ``N passed, M failed`` for the in-scope scripts and tests.
"""
from __future__ import annotations

import argparse
import ast
import re
import subprocess
import sys
import time
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from graphsdg.jobs.script_suite import run_script_in_process   # noqa: E402

# path prefix (relative to source/) -> why it is out of scope (docs/porting.md, "Out of scope")
OUT_OF_SCOPE = {
    "standalone_examples/api/isaacsim.ros2.bridge/": "ROS 2",
    "standalone_examples/testing/isaacsim.ros2.bridge/": "ROS 2",
    "standalone_examples/benchmarks/validation/benchmark_robots_nova_carter_ros2_validation.py": "ROS 2",
    "extensions/isaacsim.ros2.": "ROS 2",
    "extensions/isaacsim.streaming.": "streaming / livestream",
    "standalone_examples/replicator/mobility_gen/experimental_nurec_camera.py": "NuRec",
    "standalone_examples/replicator/mobility_gen/replay_directory_for_nurec.py": "NuRec",
    "standalone_examples/api/isaacsim.replicator.teleop/": "teleop devices (a recorded XR teleop episode)",
    "extensions/isaacsim.replicator.teleop/": "teleop devices (a recorded XR teleop episode)",
    "standalone_examples/replicator/infinigen/": "Infinigen-generated scenes that are not in the repository",
    "extensions/isaacsim.sensors.experimental.rtx/python/tests/test_acoustic.py":
        "acoustic sensors (CompatError: not modelled yet, docs/sensors.md)",
    "extensions/isaacsim.sensors.experimental.rtx/python/tests/test_acoustic_sensor.py":
        "acoustic sensors (CompatError: not modelled yet, docs/sensors.md)",
    "extensions/isaacsim.sensors.experimental.rtx/python/tests/test_rtx_acoustic_configs.py":
        "acoustic sensors (CompatError: not modelled yet, docs/sensors.md)",
    "extensions/isaacsim.sensors.experimental.rtx/python/tests/test_structured_light_camera.py":
        "structured-light camera (CompatError: not modelled yet, docs/sensors.md)",
    "standalone_examples/api/isaacsim.sensors.experimental.rtx/create_acoustic_basic.py":
        "acoustic sensors (CompatError: not modelled yet, docs/sensors.md)",
    "standalone_examples/api/isaacsim.sensors.experimental.rtx/inspect_acoustic_gmo.py":
        "acoustic sensors (CompatError: not modelled yet, docs/sensors.md)",
    "standalone_examples/api/isaacsim.sensors.experimental.rtx/camera_structured_light.py":
        "structured-light camera (CompatError: not modelled yet, docs/sensors.md)",
    "extensions/isaacsim.replicator.synthetic_recorder/isaacsim/replicator/synthetic_recorder/tests/test_recorder_ui.py":
        "Kit UI windows",
    "standalone_examples/testing/doc_snippets/test_snippets_async.py":
        "its snippets (docs/isaacsim/snippets) are not in the repository",
    "standalone_examples/benchmarks/workflows/benchmark_workflow_manipulation_vision_cumotion.py":
        "cuMotion motion generation (NVIDIA's closed CUDA library)",
}

# script (relative to source/standalone_examples/) -> its arguments for a short run
SCRIPT_ARGS = {
    "api/isaacsim.replicator.experimental.domain_randomization/randomization_demo.py": ["--max-frames", "30"],
    "benchmarks/benchmark_camera.py": ["--num-frames", "5", "--num-cameras", "2"],
    "benchmarks/benchmark_rtx_lidar.py": ["--num-frames", "5"],
    "benchmarks/benchmark_rtx_radar.py": ["--num-frames", "5"],
    "benchmarks/benchmark_sdg.py": ["--num-frames", "5", "--num-cameras", "2", "--delete-data-when-done"],
    "benchmarks/validation/benchmark_sdg_validation.py": ["--num-frames", "5", "--num-cameras", "2"],
    "benchmarks/workflows/benchmark_workflow_manipulation_vision_cumotion.py": ["--num-frames", "5"],
    "benchmarks/workflows/benchmark_workflow_sdg_cosmos_writer.py": ["--num-frames", "5", "--delete-data-when-done"],
    "benchmarks/workflows/benchmark_workflow_sdg_physics_randomization.py": ["--num-frames", "5",
                                                                              "--delete-data-when-done"],
    "replicator/amr_navigation.py": ["--num_frames", "3"],
    "replicator/augmentation/annotator_augmentation.py": ["--num_frames", "3"],
    "replicator/augmentation/writer_augmentation.py": ["--num_frames", "3"],
    "testing/isaacsim.ros2.bridge/test_publish_camera_data.py": ["--test-steps", "3"],
}


@dataclass
class Outcome:
    """One file's verdict: tests counted (1 for a script), passed among them, seconds, and why it failed."""

    path: str
    kind: str
    scope: str
    total: int
    passed: int
    seconds: float
    reason: str = ""
    failures: list[str] = field(default_factory=list)

    def line(self) -> str:
        verdict = "PASS" if self.total and self.passed == self.total else "FAIL"
        counts = f"{self.passed}/{self.total}" if self.kind == "tests" else ""
        tail = "" if verdict == "PASS" else f"  {self.reason}"
        scope = "" if self.scope == "in" else f"  [out of scope: {self.scope}]"
        return f"{verdict}  {self.path:<100} {counts:>6} {self.seconds:7.1f} s{scope}{tail}"


def imports_replicator(path: Path) -> bool:
    """Whether ``path`` imports ``omni.replicator.core`` (any form), read from its syntax tree."""
    try:
        tree = ast.parse(path.read_text(errors="replace"))
    except SyntaxError:
        return False
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name.startswith("omni.replicator.core") for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and node.module:
            if node.module.startswith("omni.replicator.core"):
                return True
            if node.module == "omni.replicator" and any(a.name == "core" for a in node.names):
                return True
    return False


def is_helper_module(path: Path) -> bool:
    """A script folder's helper (imported by its script, nothing of its own to run): no ``SimulationApp``."""
    return path.name.endswith("_utils.py") and "SimulationApp(" not in path.read_text(errors="replace")


def scope_of(relative: str) -> str:
    """``"in"``, or the reason ``relative`` (a path under ``source/``) is out of scope."""
    for prefix, reason in OUT_OF_SCOPE.items():
        if relative.startswith(prefix):
            return reason
    return "in"


def find_targets(source: Path) -> tuple[list[Path], list[Path]]:
    """The standalone scripts and the test files under ``source`` that import Replicator."""
    scripts = sorted(p for p in (source / "standalone_examples").rglob("*.py")
                     if imports_replicator(p) and not is_helper_module(p))
    tests = sorted(p for base in ("extensions", "deprecated") for p in (source / base).rglob("test_*.py")
                   if "/tests/" in str(p) and imports_replicator(p))
    return scripts, tests


def run_script(source: Path, script: Path, out: Path, timeout: float, scale: float) -> Outcome:
    relative = str(script.relative_to(source))
    args = SCRIPT_ARGS.get(str(script.relative_to(source / "standalone_examples")))
    if args is None:
        args = ["--test"] if re.search(r"add_argument\(\s*[\"']--test[\"']", script.read_text()) else []
    workdir = out / "scripts" / relative.replace("/", "__")
    result = run_script_in_process(script, workdir, "isaac", args, timeout,
                                   extra=["--resolution-scale", str(scale)])
    return Outcome(relative, "script", scope_of(relative), 1, int(result.passed), result.seconds, result.reason)


def run_test_file(source: Path, test: Path, out: Path, timeout: float, scale: float) -> Outcome:
    relative = str(test.relative_to(source))
    workdir = out / "tests" / relative.replace("/", "__")
    workdir.mkdir(parents=True, exist_ok=True)
    report = workdir / "junit.xml"
    command = [sys.executable, "-m", "pytest", "-q", "-p", "graphsdg.compat.pytest_plugin", "-p", "no:cacheprovider",
               "--import-mode=importlib", f"--junitxml={report}", "-o", "junit_family=xunit2",
               f"--resolution-scale={scale}", str(test)]
    start = time.perf_counter()
    try:
        proc = subprocess.run(command, cwd=workdir, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              timeout=timeout)
        output = proc.stdout
    except subprocess.TimeoutExpired as exc:
        output = exc.stdout if isinstance(exc.stdout, str) else (exc.stdout or b"").decode(errors="replace")
        output += f"\ntimed out after {timeout:g} s"
    seconds = time.perf_counter() - start
    (workdir / "pytest.log").write_text(output)
    total, passed, failures = _junit_counts(report)
    reason = failures[0] if failures else ("" if total else _last_error(output))
    return Outcome(relative, "tests", scope_of(relative), max(total, 1), passed, seconds, reason, failures)


def _junit_counts(report: Path) -> tuple[int, int, list[str]]:
    if not report.exists():
        return 0, 0, []
    root = ElementTree.parse(report).getroot()
    total = passed = 0
    failures = []
    for case in root.iter("testcase"):
        total += 1
        problem = next((child for child in case if child.tag in ("failure", "error", "skipped")), None)
        if problem is None:
            passed += 1
        else:
            message = (problem.get("message") or problem.text or problem.tag).strip().splitlines()
            failures.append(f"{case.get('name')}: {message[0][:300] if message else problem.tag}")
    return total, passed, failures


def _last_error(output: str) -> str:
    lines = [ln.strip() for ln in output.splitlines() if "Error" in ln or "error" in ln]
    return (lines or ["no test ran"])[-1][:300]


def markdown(outcomes: list[Outcome]) -> str:
    """The table kept in docs/porting.md: file, verdict, tests, seconds, why it failed or is out of scope."""
    rows = ["| file | result | tests | seconds | note |", "| --- | --- | ---: | ---: | --- |"]
    for o in outcomes:
        verdict = "pass" if o.passed == o.total else "fail"
        tests = f"{o.passed}/{o.total}" if o.kind == "tests" else ""
        note = o.reason.replace("|", "\\|") if verdict == "fail" else ""
        if o.scope != "in":
            note = f"out of scope ({o.scope}){': ' + note if note else ''}"
        rows.append(f"| `{o.path}` | {verdict} | {tests} | {o.seconds:.1f} | {note} |")
    return "\n".join(rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("isaac", type=Path, help="Isaac Sim's source tree (the folder holding source/)")
    parser.add_argument("--out", type=Path, default=Path("/tmp/isaac_tree_runs"))
    parser.add_argument("--only", choices=("scripts", "tests", "all"), default="all")
    parser.add_argument("--match", default="", help="run only files whose path contains this text")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per file")
    parser.add_argument("--resolution-scale", type=float, default=0.125,
                        help="scripts' render products at this fraction of their resolution (default 0.125)")
    parser.add_argument("--test-resolution-scale", type=float, default=1.0,
                        help="tests' render products at this fraction (default 1: tests read resolutions back)")
    parser.add_argument("--markdown", type=Path, help="write the table to this file")
    args = parser.parse_args(argv)
    source = args.isaac / "source"
    scripts, tests = find_targets(source)
    outcomes = []
    if args.only in ("scripts", "all"):
        for script in scripts:
            if args.match in str(script):
                outcomes.append(run_script(source, script, args.out, args.timeout, args.resolution_scale))
                print(outcomes[-1].line(), flush=True)
    if args.only in ("tests", "all"):
        for test in tests:
            if args.match in str(test):
                outcomes.append(run_test_file(source, test, args.out, args.timeout, args.test_resolution_scale))
                print(outcomes[-1].line(), flush=True)
    for kind, label in (("script", "scripts"), ("tests", "tests")):
        chosen = [o for o in outcomes if o.kind == kind and o.scope == "in"]
        if chosen:
            passed = sum(o.passed for o in chosen)
            total = sum(o.total for o in chosen)
            print(f"in-scope {label}: {passed} passed, {total - passed} failed")
    out_scope = [o for o in outcomes if o.scope != "in"]
    if out_scope:
        print(f"out of scope: {len(out_scope)} files (each fails with graphsdg's error saying why)")
    if args.markdown:
        args.markdown.write_text(markdown(outcomes))
    in_scope = [o for o in outcomes if o.scope == "in"]
    passed = sum(o.passed for o in in_scope)
    total = sum(o.total for o in in_scope)
    print(f"{passed} passed, {total - passed} failed")
    return 0 if passed == total else 1


if __name__ == "__main__":
    raise SystemExit(main())
