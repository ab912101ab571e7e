"""The render backend seam: settings choose classic or pbr, pbr says what it lacks, tiers map from Isaac's modes."""
from __future__ import annotations

import logging
import warnings

import numpy as np
import pytest

import graphsdg as rep
from graphsdg import settings
from graphsdg.render import backend
from graphsdg.render.backend import BackendRequest, PbrUnavailableError, pbr_missing, requested_backend, \
    resolve_backend
from graphsdg.engine.runtime import runtime

HAVE_ALL = dict(has_module=lambda name: True, cuda_devices=lambda: 1, python=(3, 12))


def test_pbr_missing_names_each_gap_and_how_to_close_it():
    assert pbr_missing(**HAVE_ALL) == []
    old_python = pbr_missing(**{**HAVE_ALL, "python": (3, 11)})
    assert len(old_python) == 1 and "Python >= 3.12" in old_python[0] and "3.11" in old_python[0]
    assert "pip install 'graphsdg[gpu]'" in old_python[0]
    no_pbr = pbr_missing(**{**HAVE_ALL, "has_module": lambda name: name != "mujoco_warp_pbr"})
    assert no_pbr == ["the gpu extra (mujoco-warp-pbr==0.2.0 not installed): pip install 'graphsdg[gpu]'"]
    no_gpu = pbr_missing(**{**HAVE_ALL, "cuda_devices": lambda: 0})
    assert len(no_gpu) == 1 and "CUDA GPU" in no_gpu[0]


def test_cuda_is_not_probed_without_the_extra():
    def probe():
        raise AssertionError("Warp was imported on a machine without the extra")
    assert pbr_missing(has_module=lambda name: False, cuda_devices=probe, python=(3, 12))


def test_classic_is_the_rasterizer_itself():
    settings.set("/graphsdg/render/backend", "classic")
    assert runtime().renderer is runtime().rasterizer
    assert isinstance(runtime().renderer, backend.RenderBackend)


@pytest.mark.skipif(not pbr_missing(), reason="this machine can run the pbr backend")
def test_auto_falls_back_to_classic_and_explicit_pbr_raises_naming_what_is_missing():
    assert settings.get("/graphsdg/render/backend") == "auto"      # the default
    assert runtime().renderer is runtime().rasterizer
    settings.set("/graphsdg/render/backend", "pbr")
    with pytest.raises(PbrUnavailableError, match=r"graphsdg\[gpu\]|CUDA GPU") as err:
        runtime().renderer
    assert "/graphsdg/render/backend" in str(err.value) and "classic" in str(err.value)


def test_explicit_pbr_error_lists_the_missing_parts():
    request = BackendRequest("pbr", "realtime", 1, False)
    with pytest.raises(PbrUnavailableError, match=r"needs a CUDA GPU"):
        resolve_backend(request, missing=lambda: ["a CUDA GPU (none)"])
    assert resolve_backend(request, missing=lambda: []) == "pbr"
    assert resolve_backend(BackendRequest("classic", "realtime", 1, False),
                           missing=lambda: pytest.fail("classic needs no probe")) == "classic"


def test_auto_logs_its_choice_once(monkeypatch, caplog):
    monkeypatch.setattr(backend, "_auto_logged", False)
    auto = BackendRequest("auto", "realtime", 1, False)
    with caplog.at_level(logging.INFO, logger="graphsdg.render"):
        assert resolve_backend(auto, missing=lambda: ["a CUDA GPU"]) == "classic"
        assert resolve_backend(auto, missing=lambda: ["a CUDA GPU"]) == "classic"
    said = [r.getMessage() for r in caplog.records if "render backend auto" in r.getMessage()]
    assert said == ["render backend auto -> classic (pbr needs a CUDA GPU)"]
    monkeypatch.setattr(backend, "_auto_logged", False)
    assert resolve_backend(auto, missing=lambda: []) == "pbr"


def test_isaac_render_modes_map_to_tiers():
    assert requested_backend() == BackendRequest("auto", "realtime", 1, True)
    rep.settings.set_render_pathtraced(samples_per_pixel=64)
    settings.set("/rtx/pathtracing/spp", 16)
    assert requested_backend() == BackendRequest("auto", "path", 64, True)
    settings.set("/rtx/pathtracing/spp", 128)                 # per-frame samples above the total: the larger
    settings.set("/rtx/pathtracing/optixDenoiser/enabled", False)
    assert requested_backend() == BackendRequest("auto", "path", 128, False)
    settings.set("/graphsdg/render/maxSubframes", 8)          # CI-sized runs bound path samples too
    assert requested_backend().path_samples == 8
    rep.settings.set_render_rtx_realtime()
    assert requested_backend().tier == "realtime"


def test_backend_settings_have_effect_and_refuse_nonsense():
    with warnings.catch_warnings():
        warnings.simplefilter("error")        # honoured keys do not warn "no effect"
        settings.set("/graphsdg/render/backend", "PBR")
        settings.set("/rtx/pathtracing/optixDenoiser/enabled", True)
    assert requested_backend().backend == "pbr"
    with pytest.raises(ValueError, match="/graphsdg/render/backend"):
        settings.set("/graphsdg/render/backend", "vulkan")
    with pytest.raises(ValueError, match="/rtx/pathtracing/spp"):
        settings.set("/rtx/pathtracing/spp", 0)


def test_captures_render_through_the_chosen_backend(monkeypatch):
    """The orchestrator asks the runtime's backend, not the rasteriser, for pixels: a step's render products in
    one batch (the pbr backend draws them in one launch), each with its own size and passes."""
    rep.functional.create.dome_light(intensity=600)
    rep.functional.create.cube()
    cam = rep.functional.create.camera(position=(0, -4, 0), look_at=(0, 0, 0))
    rgb = rep.annotators.get("rgb")
    rgb.attach(rep.create.render_product(cam, (32, 24)))
    depth = rep.annotators.get("distance_to_image_plane")
    depth.attach(rep.create.render_product(cam, (16, 12)))
    calls = []

    class Recording:
        def render(self, scene, view, passes, subframes=1, defer=False, motion=None):
            raise AssertionError("a step renders its products through render_batch")

        def render_batch(self, scene, requests):
            calls.append([(r.view.width, r.view.height, set(r.passes), r.subframes) for r in requests])
            return runtime().rasterizer.render_batch(scene, requests)

        def close(self):
            pass

    monkeypatch.setattr(type(runtime()), "renderer", property(lambda self: Recording()))
    rep.orchestrator.step(delta_time=0)
    assert calls == [[(32, 24, {"color"}, 1), (16, 12, {"depth"}, 1)]]
    assert rgb.get_data().shape == (24, 32, 4) and np.asarray(rgb.get_data())[..., 3].min() == 255
    assert np.asarray(depth.get_data()).shape == (12, 16) and np.isfinite(depth.get_data()).any()


def test_launch_groups_pack_products_up_to_the_pixel_limit():
    quarter = 512 * 512
    assert backend.launch_groups([quarter] * 4, limit=1 << 20) == [[0, 1, 2, 3]]
    assert backend.launch_groups([quarter] * 5, limit=1 << 20) == [[0, 1, 2, 3], [4]]
    assert backend.launch_groups([1920 * 1080, 64 * 64, 64 * 64], limit=1 << 20) == [[0], [1, 2]]
    assert backend.launch_groups([10, 10, 10], limit=0) == [[0], [1], [2]]
    settings.set(backend.BATCH_PIXELS_KEY, 25)
    assert backend.launch_groups([10, 10, 10]) == [[0, 1], [2]]
    with pytest.raises(ValueError, match="pbrBatchPixels"):
        settings.set(backend.BATCH_PIXELS_KEY, -1)


def test_gpu_extra_pins_the_measured_versions_for_python_312_only():
    import os
    import tomllib
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with open(os.path.join(root, "pyproject.toml"), "rb") as f:
        project = tomllib.load(f)["project"]
    gpu = project["optional-dependencies"]["gpu"]
    pins = {req.split(";")[0].strip() for req in gpu}
    assert pins == set(backend.PBR_MODULES.values())
    assert all('python_version >= "3.12"' in req for req in gpu)
    assert not any("warp" in dep for dep in project["dependencies"])          # the core install is unchanged
    # CI's has Warp for the augmentations' CPU kernels (the warp extra), never the pbr renderer's modules
    dev = project["optional-dependencies"]["dev"]
    assert not any(dep.startswith(("mujoco-warp", "mujoco_warp")) for dep in dev)


def test_models_compiled_for_pbr_carry_a_camera_per_render_product(monkeypatch):
    """Where pbr draws, each compile gives every render product a PBR camera (a step's products then go in one
    launch without recompiling mid-step); more products than cameras later recompile once, keeping the state."""
    import mujoco

    from graphsdg.sim.visual import pbr_camera_name
    monkeypatch.setattr(backend, "pbr_in_use", True)
    rep.functional.create.cube()
    cam = rep.functional.create.camera(position=(0, -4, 0), look_at=(0, 0, 0))
    for size in ((32, 24), (16, 12), (8, 8)):
        rep.create.render_product(cam, size)
    sim = runtime().sim
    model = sim.model

    def names(m):
        return {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(m.ncam)}

    assert {pbr_camera_name(i) for i in range(3)} <= names(model) and pbr_camera_name(3) not in names(model)
    compiles = sim.stats["compiles"]
    runtime().render_scene.require_pbr_cameras(2)
    assert sim.stats["compiles"] == compiles and sim.model is model
    sim.data.time = 1.25
    runtime().render_scene.require_pbr_cameras(5)
    assert sim.stats["compiles"] == compiles + 1 and pbr_camera_name(4) in names(sim.model)
    assert sim.data.time == 1.25


def test_finish_finishes_copied_passes_and_leaves_derived_ones_until_asked():
    calls = []
    out = backend.RenderOutputs()
    out.put("id_codes", lambda: calls.append("codes") or np.array([[2, 0]], dtype=np.uint8))
    out.id_lut = np.array([-1, 0, 1], dtype=np.int32)
    out.derive("geom_ids", lambda done: calls.append("ids") or done.id_lut[done.id_codes])
    out.finish()
    assert calls == ["codes"]                    # the copy is taken, the lookup nobody asked for is not made
    assert out.geom_ids.tolist() == [[1, -1]]
    assert calls == ["codes", "ids"]
