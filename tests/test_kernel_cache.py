"""The node's Warp kernel cache (issue 37): each module compiled once a node, and compiled ahead without a GPU.

Warp compiles for its CPU device here (LLVM) and, ahead of time, for a GPU architecture (NVRTC runs on the
CPU), so these run on a machine without a GPU. Each case runs in fresh processes with a fresh cache folder.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

from graphsdg.render.kernel_cache import cache_root, file_lock

pytest.importorskip("warp")

KERNEL_MODULE = '''
import warp as wp

@wp.kernel(enable_backward=False)
def scale(a: wp.array(dtype=float), b: wp.array(dtype=float), k: float):
    i = wp.tid()
    b[i] = a[i] * k + 1.0
'''


def _python(code: str, cwd, cache, timeout: float = 240.0) -> subprocess.Popen:
    env = {**os.environ, "GRAPHSDG_KERNEL_CACHE": str(cache), "PYTHONPATH": str(cwd)}
    env.pop("WARP_CACHE_PATH", None)
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], cwd=cwd, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def _stats(process: subprocess.Popen, timeout: float = 240.0) -> dict:
    """The JSON a snippet printed last, with ``"warp"``: what Warp printed of loading ``kmod`` (compiled or
    cached, its own words)."""
    out, err = process.communicate(timeout=timeout)
    assert process.returncode == 0, err[-3000:]
    said = [line for line in out.splitlines() if line.startswith("Module kmod ")]
    return {**json.loads(out.strip().splitlines()[-1]), "warp": said}


def test_the_docstring_examples_run():
    import doctest
    from graphsdg.render import kernel_cache
    assert doctest.testmod(kernel_cache).failed == 0


def test_the_cache_folder_is_graphsdgs_then_warps_own(tmp_path):
    assert cache_root({"GRAPHSDG_KERNEL_CACHE": "/a", "WARP_CACHE_PATH": "/b"}) == "/a"
    assert cache_root({"WARP_CACHE_PATH": "/b"}) == "/b" and cache_root({}) is None
    with file_lock(str(tmp_path / "x" / "m.lock")) as waited:
        assert waited >= 0 and (tmp_path / "x" / "m.lock").exists()


def test_processes_that_start_together_compile_a_module_once(tmp_path):
    (tmp_path / "kmod.py").write_text(KERNEL_MODULE)
    code = '''
    import json, os, sys, time
    from graphsdg.render import kernel_cache
    kernel_cache.configure_warp()
    import warp as wp
    import kmod
    open(f"ready_{sys.argv[1]}", "w").close()        # both processes load the module at the same moment
    while not all(os.path.exists(f"ready_{i}") for i in (0, 1)):
        time.sleep(0.01)
    a = wp.array([1.0, 2.0], dtype=float, device="cpu")
    b = wp.zeros(2, dtype=float, device="cpu")
    wp.launch(kmod.scale, dim=2, inputs=[a, b, 3.0], device="cpu")
    assert b.numpy().tolist() == [4.0, 7.0]
    print(json.dumps(kernel_cache.stats))
    '''
    runs = []
    for i in (0, 1):
        env = {**os.environ, "GRAPHSDG_KERNEL_CACHE": str(tmp_path / "cache"), "PYTHONPATH": str(tmp_path)}
        env.pop("WARP_CACHE_PATH", None)
        runs.append(subprocess.Popen([sys.executable, "-c", textwrap.dedent(code), str(i)], cwd=tmp_path, env=env,
                                     text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE))
    stats = [_stats(r) for r in runs]
    assert sorted((s["compiled"], s["cached"]) for s in stats) == [(0, 1), (1, 0)], stats
    # Warp's own account: one process compiled the module, the other loaded it from the cache
    assert sorted(line.rsplit("(", 1)[1] for s in stats for line in s["warp"]) == ["cached)", "compiled)"], stats
    assert max(s["lock_wait_s"] for s in stats) > 0.05            # one waited for the other's compile
    folders = [p for p in (tmp_path / "cache").rglob("wp_kmod_*") if p.is_dir()]
    assert len(folders) == 1


def test_the_pbr_outputs_module_compiles_once_for_all_its_kernels(tmp_path):
    code = '''
    import json
    import numpy as np
    from graphsdg.render import kernel_cache
    kernel_cache.configure_warp()
    import warp as wp
    from graphsdg.render import pbr_outputs as po
    h, w = 2, 3
    packed = wp.array(np.full((1, h * w), 0xFF102030, dtype=np.uint32), device="cpu")
    distance = wp.array(np.ones((1, h * w), dtype=np.float32), device="cpu")
    seg = wp.array(np.array([[[1, 5]] * (h * w)], dtype=np.int32), dtype=wp.vec2i, device="cpu")
    cosines = wp.array(np.ones(h * w, dtype=np.float32), device="cpu")
    rgba, depth = wp.zeros(h * w, dtype=wp.uint32, device="cpu"), wp.zeros(h * w, dtype=wp.float32, device="cpu")
    codes = wp.zeros(h * w, dtype=wp.uint8, device="cpu")
    boxes = wp.zeros((4, 4), dtype=wp.int32, device="cpu")
    wp.launch(po._classic_layout, dim=h * w, inputs=[packed, distance, seg, 0, 0, 0, cosines, 0.1, 10.0, rgba, depth,
              codes], device="cpu")
    wp.launch(po._clear_boxes, dim=4, inputs=[boxes], device="cpu")
    wp.launch(po._code_boxes, dim=(h, 1), inputs=[codes, w, boxes], device="cpu")
    assert codes.numpy().tolist() == [2] * (h * w) and boxes.numpy()[2].tolist() == [0, 0, w - 1, h - 1]
    assert rgba.numpy()[0] == 0xFF302010 and abs(float(depth.numpy()[0]) - 1.1) < 1e-6
    print(json.dumps(kernel_cache.stats))
    '''
    stats = _stats(_python(code, tmp_path, tmp_path / "cache"))
    # one module, its three kernels and every code type's instance: compiled once (not again at the boxes)
    assert (stats["compiled"], stats["cached"]) == (1, 0), stats


def test_a_gpu_binary_is_compiled_ahead_without_a_gpu(tmp_path):
    (tmp_path / "kmod.py").write_text(KERNEL_MODULE)
    code = '''
    import json, os
    from graphsdg.render import kernel_cache
    kernel_cache.configure_warp()
    import warp as wp
    import kmod
    assert wp.get_cuda_device_count() == 0
    a = wp.array([1.0, 2.0], dtype=float, device="cpu")
    b = wp.zeros(2, dtype=float, device="cpu")
    with kernel_cache.LaunchRecorder() as recorder:
        wp.launch(kmod.scale, dim=2, inputs=[a, b, 3.0], device="cpu", block_dim=64)
    paths = kernel_cache.compile_ahead(recorder, [90])
    print(json.dumps({"paths": [str(p) for p in paths], **kernel_cache.stats}))
    '''
    out = _stats(_python(code, tmp_path, tmp_path / "cache"))
    assert len(out["paths"]) == 1 and out["paths"][0].endswith(".sm90.cubin")
    with open(out["paths"][0], "rb") as f:
        assert f.read(4) == b"\x7fELF"                 # a CUBIN is an ELF file of the GPU's code
    assert os.path.basename(os.path.dirname(out["paths"][0])).startswith("wp_kmod_")
    assert (out["compiled"], out["cached"]) == (2, 0)      # the CPU's object, then the GPU's CUBIN


def test_modules_compiled_in_the_background_are_loaded_from_the_cache_at_their_first_launch(tmp_path):
    (tmp_path / "kmod.py").write_text(KERNEL_MODULE)
    (tmp_path / "kmod2.py").write_text(KERNEL_MODULE.replace("* k + 1.0", "* k + 2.0"))
    code = '''
    import json
    from graphsdg.render import kernel_cache
    kernel_cache.configure_warp()
    import warp as wp
    import kmod, kmod2
    threads = kernel_cache.compile_in_background(("kmod", "kmod2"), "cpu")
    for thread in threads:
        thread.join()
    ahead = dict(kernel_cache.stats)
    a = wp.array([1.0, 2.0], dtype=float, device="cpu")
    b = wp.zeros(2, dtype=float, device="cpu")
    wp.launch(kmod.scale, dim=2, inputs=[a, b, 3.0], device="cpu")
    c = wp.zeros(2, dtype=float, device="cpu")
    wp.launch(kmod2.scale, dim=2, inputs=[a, c, 3.0], device="cpu")
    print(json.dumps({"ahead": ahead, "b": b.numpy().tolist(), "c": c.numpy().tolist(), **kernel_cache.stats}))
    '''
    out = _stats(_python(code, tmp_path, tmp_path / "cache"))
    assert (out["ahead"]["compiled"], out["ahead"]["cached"]) == (2, 0)     # both, by the threads
    assert (out["compiled"], out["cached"]) == (2, 2)                       # the launches found them
    assert out["b"] == [4.0, 7.0] and out["c"] == [5.0, 8.0]
    assert out["warp"] and all(line.endswith("(cached)") for line in out["warp"]), out["warp"]
