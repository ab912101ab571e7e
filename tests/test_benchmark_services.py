"""Benchmark sessions and isaacsim.benchmark.services: metrics files parsed back against a known workload."""
from __future__ import annotations

import doctest
import importlib
import json
import os
import statistics
import time
import unittest

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.base import settings_store
from graphsdg.benchmark import process_stats
from graphsdg.benchmark.benchmark_session import OUTPUT_FOLDER_SETTING, BenchmarkSession
from graphsdg.benchmark.measurements import BooleanMeasurement, ListMeasurement, SingleMeasurement, TestPhase
from graphsdg.benchmark.sample_stats import SampleStats
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError, CompatImportError

from conftest import unit_cube_scene


@pytest.fixture
def metrics_dir(tmp_path):
    folder = tmp_path / "metrics"
    settings_store.set(OUTPUT_FOLDER_SETTING, str(folder))
    return folder


@pytest.fixture
def compat():
    isaac.install()
    rep.stage.new_stage()
    from isaacsim.core.utils.extensions import enable_extension
    enable_extension("isaacsim.benchmark.services")
    yield
    rep.timeline.get_timeline_interface().stop()
    isaac.uninstall()


def _by_name(phase: TestPhase, prefix: str = "") -> dict:
    return {m.name[len(prefix):]: m for m in phase.measurements}


def _rgb_scene(size=(32, 24)):
    _, _, rp = unit_cube_scene(resolution=size)
    annotator = rep.AnnotatorRegistry.get_annotator("rgb")
    annotator.attach(rp)
    return rp, annotator


# ---- a known workload, measured and read back ---------------------------------------------------
def test_n_steps_give_n_minus_one_frame_times_within_the_phase_wall_time(metrics_dir):
    _rgb_scene()
    frames = 6
    session = BenchmarkSession("steps", backend_type="JSONFileMetrics", report_generation=False,
                               workflow_metadata={"metadata": [{"name": "frames", "data": frames},
                                                               {"name": "label", "data": "tiny"},
                                                               {"name": "skip_write", "data": True}]},
                               recorders=["app_frametime", "gpu_frametime", "runtime", "memory", "hardware"])
    session.set_phase("benchmark")
    wall = time.perf_counter()
    for _ in range(frames):
        rep.orchestrator.step()
    session.store_measurements()
    wall_ms = (time.perf_counter() - wall) * 1000
    written = session.stop()
    assert [p.name for p in written] == ["metrics_steps.json"]

    phases = [TestPhase.from_json(p) for p in json.loads(written[0].read_text())]
    assert [p.phase_name for p in phases] == ["benchmark"]
    m = _by_name(phases[0], "steps benchmark ")
    samples = m["App_Update Frametime Samples"].value
    # the phase's start to the first step is dropped: N frames, N - 1 whole intervals between their starts
    assert len(samples) == frames - 1 == m["Num App Updates"].value
    assert all(s > 0 for s in samples)
    runtime = m["Runtime"].value
    assert sum(samples) <= runtime <= wall_ms + 1e-3
    assert m["Mean App_Update Frametime"].value == round(statistics.mean(samples), 2)
    assert m["Min App_Update Frametime"].value == round(min(samples), 2)
    assert m["Max App_Update Frametime"].value == round(max(samples), 2)
    assert m["Mean FPS"].value == pytest.approx(1000 / m["Mean App_Update Frametime"].value, abs=1e-3)
    # one render time per frame, every frame rendered something, all inside the phase
    gpu = m["GPU Frametime Samples"].value
    assert len(gpu) == frames and all(g > 0 for g in gpu) and sum(gpu) <= runtime
    assert m["num_cpus"].value == os.cpu_count()
    assert m["gpu_device_name"].value == (process_stats.gpu_devices()[0].name if process_stats.gpu_devices()
                                          else "Unknown")
    rss = m["System Memory RSS"].value
    assert 0 < rss <= m["System Memory VMS"].value and 0 < m["System Memory USS"].value <= rss
    metadata = {d.name: d.data for d in phases[0].metadata}
    assert metadata == {"steps benchmark workflow_name": "steps", "steps benchmark frames": frames,
                        "steps benchmark label": "tiny", "steps benchmark phase": "benchmark"}   # bools left out


def test_app_updates_count_once_with_the_steps_they_run(compat, metrics_dir):
    import omni.kit.app
    from isaacsim.benchmark.services import BaseIsaacBenchmark
    _rgb_scene()
    rep.timeline.get_timeline_interface().play()   # capture on play: every update steps
    benchmark = BaseIsaacBenchmark("updates", backend_type="OsmoKPIFile", report_generation=False,
                                   recorders=["app_frametime", "runtime"])
    benchmark.set_phase("benchmark", warmup_frames=2)
    for _ in range(5):
        omni.kit.app.get_app().update()
    rep.orchestrator.step()   # a step outside any update is a frame of its own
    benchmark.store_measurements()
    benchmark.stop()
    kpis = json.loads((metrics_dir / "kpis_updates_benchmark.json").read_text())
    assert kpis["Num App Updates"] == 5 and kpis["phase"] == "benchmark" and kpis["workflow_name"] == "updates"
    # the timeline played 6 frames of 1/60 s over the phase: the real-time factor is that over the wall time
    assert kpis["Real Time Factor"] == pytest.approx(6 / 60 / (kpis["Runtime"] / 1000), rel=0.05)


def test_physics_samples_one_per_tick_and_intervals_one_per_step(metrics_dir):
    cube = rep.functional.create.cube(position=(0, 0, 5))
    rep.functional.physics.apply_rigid_body(cube)
    rep.functional.physics.apply_collider(cube)
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()
    session = BenchmarkSession("physics", backend_type="JSONFileMetrics", report_generation=False,
                               recorders=["physics_frametime", "physics_step_interval", "runtime"])
    session.set_phase("benchmark")
    for _ in range(8):
        rep.orchestrator.update()
    session.store_measurements()
    timeline.stop()
    phase = TestPhase.from_json(json.loads(session.stop()[0].read_text())[0])
    m = _by_name(phase, "physics benchmark ")
    physics = m["Physics Frametime Samples"].value
    assert len(physics) == 8 - 1 and all(p > 0 for p in physics)   # 8 ticks, the first dropped
    steps = m["Physics Step Count"].value
    assert steps == 8 * 2 - 1   # 120 Hz physics: two steps a 60 Hz tick, the first interval dropped
    assert sum(physics) < m["Runtime"].value
    assert m["Min Physics_Step Frametime"].value <= m["P99 Physics_Step Frametime"].value \
        <= m["Max Physics_Step Frametime"].value


def test_rtf_windows_and_cpu_samples(metrics_dir):
    settings_store.set("/exts/isaacsim.benchmark.services/rtf_stability/window_wall_ms", 0.5)
    settings_store.set("/exts/isaacsim.benchmark.services/rtf_stability/export_window_samples", True)
    _rgb_scene((16, 16))
    timeline = rep.timeline.get_timeline_interface()
    session = BenchmarkSession("rtf", backend_type="JSONFileMetrics", report_generation=False,
                               recorders=["rtf_stability", "cpu_continuous"])
    session.recorders[1].sample_interval_frames = 2
    session.set_phase("benchmark")
    for _ in range(6):
        rep.orchestrator.step()   # each advances the timeline 1/60 s
    session.store_measurements()
    timeline.stop()
    m = _by_name(TestPhase.from_json(json.loads(session.stop()[0].read_text())[0]), "rtf benchmark ")
    windows = m["Windowed RTF Samples"].value
    assert m["Windowed RTF Sample Count"].value == len(windows) >= 6
    assert all(w >= 0 for w in windows) and max(windows) > 0
    assert m["Mean Windowed RTF"].value == round(statistics.mean(windows), 2)
    assert 0 <= m["Pct Windowed RTF Within 0.01 of Mean RTF"].value <= m["Pct Windowed RTF Within 0.10 of Mean RTF"].value
    assert m["Min CPU Usage"].value <= m["Mean CPU Usage"].value <= m["Max CPU Usage"].value
    assert 0 <= m["Min CPU Usage"].value


def test_phases_custom_measurements_and_the_three_file_formats(metrics_dir):
    for backend in ("OmniPerfKPIFile", "OsmoKPIFile", "JSONFileMetrics"):
        session = BenchmarkSession("files", backend_type=backend, report_generation=False,
                                   workflow_metadata={"metadata": [{"name": "width", "data": 64}]},
                                   recorders=["runtime", "app_frametime"])
        session.set_phase("loading", start_recording_frametime=False)
        assert {type(r).__name__ for r in session._active_recorders} == {"RuntimeRecorder"}
        session.store_measurements()
        session.store_custom_measurement("loading", SingleMeasurement("Load Count", 3, ""))
        session.store_custom_measurement("extra", BooleanMeasurement("ok", True))
        session.store_custom_measurement("extra", ListMeasurement("seq", [1, 2]))
        session.stop()
    omni = json.loads((metrics_dir / "kpis_files.json").read_text())
    assert omni["App Info"][2] == "graphsdg" and omni["Kit"].endswith("_graphsdg") and "timestamp" in omni
    assert omni["loading"]["Load Count"] == 3 and omni["loading"]["width"] == 64 and omni["loading"]["Runtime"] > 0
    assert omni["extra"] == {"workflow_name": "files", "width": 64, "phase": "extra"}   # only single values
    assert json.loads((metrics_dir / "kpis_files_extra.json").read_text())["phase"] == "extra"
    entries = json.loads((metrics_dir / "metrics_files.json").read_text())
    extra = TestPhase.from_json(entries[1])
    assert {m.name: m.type for m in extra.measurements} == {"files extra ok": "boolean", "files extra seq": "list"}


def test_randomized_file_names_do_not_overwrite(metrics_dir):
    settings_store.set("/exts/isaacsim.benchmark.services/metrics/randomize_filename_prefix", True)
    for _ in range(2):
        session = BenchmarkSession("rand", backend_type="OmniPerfKPIFile", report_generation=False,
                                   recorders=["runtime"])
        session.set_phase("p")
        session.store_measurements()
        session.stop()
    names = sorted(p.name for p in metrics_dir.iterdir())
    assert len(names) == 2 and all(n.startswith("kpis_rand") and n.endswith(".json") for n in names)


def test_bad_use_names_itself(metrics_dir):
    with pytest.raises(ValueError, match="KitGenericTelemetry.*telemetry"):
        BenchmarkSession("x", backend_type="KitGenericTelemetry")
    session = BenchmarkSession("x", backend_type="LocalLogMetrics", recorders=["runtime", "no_such_recorder"])
    assert [type(r).__name__ for r in session.recorders] == ["RuntimeRecorder"]
    with pytest.raises(TypeError, match="Measurement"):
        session.store_custom_measurement("p", 3.0)
    with pytest.raises(ValueError, match="warm-up"):
        session.set_phase("p", warmup_frames=-1)
    session.stop()
    with pytest.raises(RuntimeError, match="stopped"):
        session.set_phase("again")


def test_summary_report_prints_the_phase_tables(metrics_dir, capsys):
    _rgb_scene((16, 16))
    session = BenchmarkSession("report", backend_type="LocalLogMetrics", report_generation=True,
                               recorders=["app_frametime", "runtime", "memory", "hardware"])
    session.set_phase("benchmark")
    for _ in range(3):
        rep.orchestrator.step()
    session.store_measurements()
    session.stop()
    out = capsys.readouterr().out
    assert "Summary Report" in out and "| workflow_name: report" in out and "Runtime:" in out
    assert "App_Update" in out and "System Memory RSS" in out
    assert all(len(line) == 54 for line in out.splitlines() if line.startswith("|"))   # no line leaves the box


def test_sample_stats_match_numpy():
    rng = np.random.default_rng(3)
    samples = list(rng.uniform(1, 20, 57))
    stats = SampleStats.from_samples(samples, trim_outliers=False)
    assert stats.mean == round(float(np.mean(samples)), 2) and stats.median == round(float(np.median(samples)), 2)
    assert stats.stdev == round(float(np.std(samples, ddof=1)), 2)
    assert stats.p99 == round(float(np.percentile(samples, 99)), 2)
    many = list(rng.uniform(0, 1, 120)) + [1000.0]
    trimmed = sorted(many)[12:-12]
    assert SampleStats.from_samples(many).max == round(max(trimmed), 2) < 1000
    assert SampleStats.from_samples([]).to_dict()["one_percent"] == 0.0


# ---- compat mode --------------------------------------------------------------------------------
def test_the_extension_is_off_until_enabled():
    isaac.install()
    try:
        with pytest.raises(CompatImportError, match="enable_extension.*isaacsim.benchmark.services"):
            importlib.import_module("isaacsim.benchmark.services")
    finally:
        isaac.uninstall()


def test_script_recorders_register_and_report_as_in_benchmark_sdg(compat, metrics_dir):
    from isaacsim.benchmark.services import DEFAULT_RECORDERS, BaseIsaacBenchmark
    from isaacsim.benchmark.services.datarecorders import (MeasurementData, MeasurementDataRecorder,
                                                            MeasurementDataRecorderRegistry)
    from isaacsim.benchmark.services.metrics import measurements

    @MeasurementDataRecorderRegistry.register("frames_seen")
    class FramesSeen(MeasurementDataRecorder):
        def __init__(self, context=None):
            self.context = context
            self.count = 0

        def start_collecting(self):
            self.count = 0

        def stop_collecting(self):
            pass

        def get_data(self):
            return MeasurementData(measurements=[measurements.SingleMeasurement("Frames Seen", self.count, "")])

    benchmark = BaseIsaacBenchmark("script", backend_type="OmniPerfKPIFile", report_generation=False,
                                   recorders=DEFAULT_RECORDERS + ["frames_seen"])
    assert benchmark.assets_root_path
    seen = next(r for r in benchmark.recorders if isinstance(r, FramesSeen))
    benchmark.set_phase("benchmark")
    seen.count = 4
    benchmark.store_measurements()
    benchmark.stop()
    kpis = json.loads((metrics_dir / "kpis_script.json").read_text())["benchmark"]
    assert kpis["Frames Seen"] == 4 and "System Memory RSS" in kpis and "num_cpus" in kpis


def test_async_benchmark_test_case_writes_its_metrics_in_teardown(compat, metrics_dir):
    import omni.kit.app
    from isaacsim.benchmark.services import BaseIsaacBenchmarkAsync

    class Bench(BaseIsaacBenchmarkAsync):
        async def setUp(self):
            await super().setUp(backend_type="JSONFileMetrics", recorders=["runtime", "app_frametime"])

        async def test_updates(self):
            await self.set_phase("benchmark")
            for _ in range(4):
                await omni.kit.app.get_app().next_update_async()
            await self.store_measurements()

    result = unittest.TextTestRunner(stream=open(os.devnull, "w")).run(Bench("test_updates"))
    assert result.wasSuccessful(), result.errors + result.failures
    phase = TestPhase.from_json(json.loads((metrics_dir / "metrics_test_updates.json").read_text())[0])
    assert _by_name(phase, "test_updates benchmark ")["Num App Updates"].value == 3


def test_unsupported_names_raise(compat):
    import isaacsim.benchmark.services.metrics.backend as backend
    with pytest.raises(CompatError, match="KitGenericTelemetry"):
        backend.KitGenericTelemetry
    assert type(backend.MetricsBackend.get_instance()).__name__ == "JSONFileMetrics"
    from isaacsim.benchmark.services.validation import Validator
    with pytest.raises(CompatError, match="validate_frames_by_timestamp"):
        Validator().validate_frames_by_timestamp


def test_validator_compares_with_golden_images(compat, tmp_path):
    import omni.usd
    from isaacsim.benchmark.services.validation import Validator
    from PIL import Image
    unit_cube_scene(resolution=(32, 24))
    stage = omni.usd.get_context().get_stage()
    golden = Validator(regenerate_golden=True, golden_root=str(tmp_path / "golden"), blur_kernel=0)
    assert golden.run(stage, benchmark_name="b")
    names = sorted(golden.render_product_map.values())
    assert names == ["OmniverseKit_Persp", "World/Camera"]
    gold_png = tmp_path / "golden" / "b" / "World" / "Camera" / "rgb" / "rgb_0000.png"
    assert gold_png.is_file()
    # the same scene again: identical images, mean difference 0
    same = Validator(golden_root=str(tmp_path / "golden"), output_root=str(tmp_path / "cap"), blur_kernel=0)
    assert same.run(stage, benchmark_name="b")
    # a golden image brighter by 20 everywhere it can be: the mean difference is exactly that
    pixels = np.array(Image.open(gold_png))
    Image.fromarray(np.minimum(pixels.astype(int) + 20, 255).astype(np.uint8)).save(gold_png)
    expected = float(np.abs(np.minimum(pixels.astype(int) + 20, 255) - pixels).mean())
    strict = Validator(golden_root=str(tmp_path / "golden"), output_root=str(tmp_path / "cap"), blur_kernel=0,
                       tolerance=expected - 0.01, auto_cleanup=False)
    assert not strict.run(stage, benchmark_name="b")
    result = strict.validate_frames(strict._last_capture_path, str(tmp_path / "golden" / "b"))
    frame = result["render_products"]["World/Camera"]["frame_results"][0]
    assert frame["mean_diff"] == pytest.approx(expected) and not frame["passed"]
    gold_png.write_text("version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 1\n")
    with pytest.raises(OSError, match="Git LFS pointer"):
        strict.validate_images()


@pytest.mark.parametrize("name", ["graphsdg.benchmark.measurements", "graphsdg.benchmark.sample_stats",
                                  "graphsdg.benchmark.process_stats", "graphsdg.benchmark.frame_ticks",
                                  "graphsdg.benchmark.recorder_interface", "graphsdg.benchmark.frametime_recorders",
                                  "graphsdg.benchmark.system_recorders", "graphsdg.benchmark.metrics_files",
                                  "graphsdg.benchmark.summary_report", "graphsdg.benchmark.benchmark_session",
                                  "graphsdg.compat.benchmark_services", "graphsdg.compat.benchmark_validation"])
def test_module_examples(name, tmp_path):
    settings_store.set(OUTPUT_FOLDER_SETTING, str(tmp_path))
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0 and result.attempted > 0
