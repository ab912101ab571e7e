"""The benchmark's own arithmetic (its runs are measured in bench/, not timed here)."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest

from graphsdg.benchmark.throughput import BenchConfig, _steady_rate, summarize_processes
from graphsdg.base.cpu_share import cores_per_process, limit_image_threads
from graphsdg.io.write_queue import threads_per_process


def _process(start: float, period: float, frames: int) -> dict:
    ends = [start + period * (i + 1) for i in range(frames)]
    return {"start": start, "wall": ends[-1] - start, "frames": frames, "frame_ends": ends}


def test_steady_rate_counts_only_frames_while_every_process_runs():
    # A: 10 frames/s from t=0 for 10 s; B: 20 frames/s from t=2 for 5 s. Both run from 2 to 7.
    a, b = _process(0.0, 0.1, 100), _process(2.0, 0.05, 100)
    assert math.isclose(_steady_rate([a, b]), 30.0, rel_tol=0.02)
    assert math.isclose(_steady_rate([a]), 10.0, rel_tol=1e-9)


def test_a_processes_row_counts_images_of_every_camera_and_the_cores_kept_busy():
    # two processes, 2 cameras each: A 100 frames over 0-10 s with 40 CPU s, B 100 frames over 2-7 s with 30
    a, b = _process(0.0, 0.1, 100), _process(2.0, 0.05, 100)
    a["cpu"], b["cpu"] = 40.0, 30.0
    a["system"], b["system"] = 4.0, 6.0
    a["main_thread"], b["main_thread"] = 20.0, 16.0
    a["page_faults"], b["page_faults"] = 1000, 3000
    row = summarize_processes([a, b], BenchConfig(num_cameras=2, write_threads=1, write_processes=0), 12.0)
    assert row["processes"] == 2
    assert math.isclose(row["aggregate frames/s (all frames / common window)"], 20.0)      # 200 frames in 10 s
    assert math.isclose(row["images/s (aggregate x cameras)"], 40.0)
    assert math.isclose(row["cores busy (CPU s / window s)"], 7.0)                        # 70 CPU s in 10 s
    assert math.isclose(row["CPU ms per frame (all threads)"], 350.0)
    assert math.isclose(row["of which system (kernel) ms"], 50.0)                         # 10 system s, 200 frames
    assert math.isclose(row["of which main threads ms"], 180.0)                           # 36 s of main threads
    assert row["minor page faults per frame"] == 20
    assert math.isclose(row["sum of per-process frames/s"], 30.0) and row["slowest process frames/s"] == 10.0
    assert row["writer processes per process"] == 0 and row["wall s (incl. start-up)"] == 12.0


def test_steady_rate_is_undefined_when_the_processes_never_overlap():
    assert math.isnan(_steady_rate([_process(0.0, 0.1, 10), _process(5.0, 0.1, 10)]))


@pytest.mark.parametrize("processes, cores, threads", [(1, 16, 4), (2, 16, 4), (5, 16, 3), (16, 16, 1), (32, 16, 1),
                                                       (1, 2, 2), (1, 1, 1)])
def test_processes_sharing_the_cores_get_their_share_of_writer_threads(processes, cores, threads):
    assert threads_per_process(processes, cores) == threads


@pytest.mark.parametrize("bad", [0, -2, 1.5, True, "4"])
def test_writer_threads_need_a_positive_process_count(bad):
    with pytest.raises(ValueError, match=repr(bad).replace("(", r"\(")):
        threads_per_process(bad, 16)


@pytest.mark.parametrize("processes, cores, share", [(1, 16, 16), (3, 16, 5), (16, 16, 1), (32, 16, 1), (1, 1, 1)])
def test_processes_sharing_the_cores_get_their_share_of_image_threads(processes, cores, share):
    assert cores_per_process(processes, cores) == share


def _sized_pools() -> dict[str, int]:
    """What a process sizes from its cores, in a spawned process given one core (the test's own stays as it is)."""
    from graphsdg.base.cpu_share import usable_cores
    from graphsdg.io.write_queue import default_threads, processes_wanted
    from graphsdg.render.gpu_assignment import default_processes_per_gpu
    threads = default_threads()
    return {"usable": usable_cores(), "machine": os.cpu_count(), "writer threads": threads,
            "writer processes": processes_wanted("auto", threads), "share of 2": cores_per_process(2),
            "processes a GPU": default_processes_per_gpu(1)}


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="no CPU affinity on this OS")
def test_a_process_sizes_its_pools_by_the_cores_its_affinity_allows_not_the_machines():
    import concurrent.futures
    import multiprocessing
    ours = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(ours)})       # a spawned child inherits it (taskset, a container's cpuset)
    try:
        with concurrent.futures.ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
            child = pool.submit(_sized_pools).result(timeout=120)
    finally:
        os.sched_setaffinity(0, ours)
    assert child == {"usable": 1, "machine": os.cpu_count(), "writer threads": 1, "writer processes": 0,
                     "share of 2": 1, "processes a GPU": 1}
    assert _sized_pools()["usable"] == len(ours)


@pytest.mark.parametrize("bad", [0, -1, 2.0, False])
def test_image_threads_need_positive_counts(bad):
    with pytest.raises(ValueError, match="positive integer"):
        cores_per_process(bad, 16)
    with pytest.raises(ValueError, match="positive integer"):
        limit_image_threads(bad)


def test_image_threads_set_opencvs_pool():
    import cv2
    before = cv2.getNumThreads()
    try:
        limit_image_threads(1)
        assert cv2.getNumThreads() == 1
    finally:
        cv2.setNumThreads(before)


def test_every_bench_option_is_described_in_its_help():
    from graphsdg.jobs.cli import build_parser
    commands = next(a for a in build_parser()._actions if isinstance(a, __import__("argparse")._SubParsersAction))
    bench = commands.choices["bench"]
    options = [a for a in bench._actions if a.option_strings and a.dest != "help"]
    assert len(options) >= 18
    for action in options:
        assert action.help and len(action.help.split()) >= 4, f"{action.option_strings} has no description"
    assert bench.description and "hand-written MuJoCo loop" in bench.description


@pytest.mark.parametrize("bad", [["--asset-count", "0"], ["--num-frames", "-1"], ["--msaa", "-2"],
                                 ["--rt-subframes", "0"], ["--seconds", "0"], ["--backend", "rtx"],
                                 ["--temp-dir", "/no/such/folder"]])
def test_bench_refuses_bad_values_naming_them(bad, capsys):
    from graphsdg.jobs.cli import build_parser
    with pytest.raises(SystemExit):
        build_parser().parse_args(["bench", *bad])
    assert bad[1] in capsys.readouterr().err


@pytest.mark.parametrize("frames, seconds, warmup_times, expected", [
    (600, None, [0.1] * 10, 600),            # no time budget: every frame asked for
    (600, 8.0, [1.0] * 5 + [0.1] * 5, 80),   # the warm-up's second half: 10 frames/s for 8 s
    (600, 8.0, [0.001] * 10, 600),           # never more than asked for
    (600, 1.0, [1.0] * 10, 20),              # at least 20
    (5, 1.0, [1.0] * 10, 5),                 # ... unless fewer were asked for
])
def test_timed_frames_fit_the_time_budget(frames, seconds, warmup_times, expected):
    from graphsdg.benchmark.throughput import BenchConfig, timed_frames
    assert timed_frames(BenchConfig(frames=frames, seconds=seconds), warmup_times) == expected


@pytest.mark.parametrize("cores, threads", [(1, 1), (2, 1), (7, 1), (8, 2), (12, 3), (16, 4), (64, 4)])
def test_one_process_gets_writer_threads_for_its_cores(cores, threads):
    from graphsdg.io.write_queue import default_threads
    assert default_threads(cores) == threads


def test_file_system_of_names_the_deepest_mount_holding_the_path(tmp_path):
    from graphsdg.benchmark.throughput import file_system_of
    assert file_system_of("/proc/self/status") == "proc"          # /proc, not the root file system around it
    assert file_system_of("/") not in ("proc", "unknown")
    with open("/proc/mounts") as f:
        mounts = {line.split()[1]: line.split()[2] for line in f}
    if "/dev/shm" in mounts:
        assert file_system_of("/dev/shm/any/file") == mounts["/dev/shm"]


def test_huge_pages_of_reads_a_tmpfs_mounts_huge_option(tmp_path):
    from graphsdg.benchmark.throughput import file_system_of, huge_pages_of
    mounts = tmp_path / "mounts"
    mounts.write_text("/dev/vda / ext4 rw,relatime 0 0\n"
                      "tmpfs /dev/shm tmpfs rw,relatime,size=536870912k,huge=within_size 0 0\n"
                      "tmpfs /tmp/small tmpfs rw,relatime,huge=never 0 0\n"
                      "tmpfs /run tmpfs rw,nosuid,size=100k 0 0\n"
                      "/dev/vdb /data\\040set xfs rw,huge=always 0 0\n")
    assert huge_pages_of("/dev/shm/out/frame.npy", str(mounts)) == "within_size"
    assert huge_pages_of("/tmp/small/x", str(mounts)) is None           # small pages said outright
    assert huge_pages_of("/run/x", str(mounts)) is None                 # the default: small pages
    assert huge_pages_of("/data set/x", str(mounts)) is None            # not a tmpfs
    assert file_system_of("/data set/x", str(mounts)) == "xfs"
    assert huge_pages_of("/x", str(tmp_path / "absent")) is None


def test_a_bench_run_writes_its_frames_inside_temp_dir_and_removes_them(tmp_path):
    import os

    from graphsdg.benchmark.throughput import run_graphsdg
    seen = []

    def look():   # after the warm-up: its frames are in a folder of the run's own under temp_dir
        from graphsdg.orchestrator import wait_until_complete
        wait_until_complete()
        for folder, _, names in os.walk(tmp_path):
            seen.extend(os.path.join(folder, n) for n in names)

    config = BenchConfig(frames=2, warmup=2, asset_count=1, resolution=(64, 48), annotators=("rgb",),
                         temp_dir=str(tmp_path), write_processes=0)
    result = run_graphsdg(config, before_timing=look)
    assert result.frames == 2
    pngs = [p for p in seen if p.endswith(".png")]
    assert len(pngs) == 2 and all(os.path.relpath(p, tmp_path).startswith("graphsdg_bench_") for p in pngs)
    assert os.listdir(tmp_path) == []                              # the run's folder is gone with its frames


def _result(label: str, frames: int, wall: float, cpu: float = 0.0):
    from graphsdg.benchmark.throughput import BenchResult
    return BenchResult(label, frames, 1, frame_times=[wall / frames] * frames, wall_seconds=wall, cpu_seconds=cpu)


def test_rounds_give_each_run_with_its_own_rounds_ratio_and_the_medians():
    from graphsdg.benchmark.throughput import round_summaries
    # graphsdg 100, 120, 90 frames/s against the loop's 100, 100, 150: ratios 1.0, 1.2, 0.6
    rounds = [(_result("graphsdg", 100, 1.0, cpu=1.0), _result("loop", 100, 1.0)),
              (_result("graphsdg", 120, 1.0, cpu=3.0), _result("loop", 100, 1.0)),
              (_result("graphsdg", 90, 1.0, cpu=2.0), _result("loop", 150, 1.0))]
    rows = round_summaries(rounds)
    assert [r["run"] for r in rows] == ["graphsdg (round 1)", "loop (round 1)", "graphsdg (round 2)", "loop (round 2)",
                                        "graphsdg (round 3)", "loop (round 3)", "graphsdg (median of 3)",
                                        "loop (median of 3)"]
    assert [r["ratio to hand-written"] for r in rows[:6:2]] == [1.0, 1.2, 0.6]
    ours, loop = rows[6], rows[7]
    assert ours["frames/s"] == 100.0 and loop["frames/s"] == 100.0
    assert ours["ratio to hand-written"] == 1.0                  # the median of the rounds' ratios
    assert ours["CPU ms/frame"] == 22.2                          # medians column by column: of 10, 25, 22.2 ms
    single = round_summaries([(_result("graphsdg", 50, 1.0), None)])
    assert [r["run"] for r in single] == ["graphsdg"] and "ratio to hand-written" not in single[0]


def test_bench_rounds_alternate_both_loops_in_one_run(capsys):
    from graphsdg.jobs.cli import main
    assert main(["bench", "--num-frames", "3", "--warmup", "1", "--resolution", "32", "24", "--asset-count", "1",
                 "--rounds", "2", "--skip-write"]) == 0
    out = capsys.readouterr().out
    assert "2 rounds alternately" in out
    loop = "hand-written MuJoCo loop"
    for row in ("graphsdg (round 1)", f"{loop} (round 1)", "graphsdg (round 2)", f"{loop} (round 2)",
                "graphsdg (median of 2)", f"{loop} (median of 2)"):
        assert f"| {row} |" in out


def test_bench_rounds_refuse_processes_naming_both(capsys):
    from graphsdg.jobs.cli import main
    assert main(["bench", "--rounds", "3", "--processes", "2", "--num-frames", "2"]) != 0
    err = capsys.readouterr().err
    assert "--rounds 3" in err and "--processes 2" in err


def test_the_hand_written_loop_draws_the_frames_graphsdg_draws(tmp_path):
    # The ratio compares two ways of making one dataset: the loop's depth images must match graphsdg's frame for
    # frame, scaled cones and tori included (before the loop scaled its meshes, ~5 % of the pixels differed).
    import numpy as np

    from graphsdg.benchmark.throughput import run_graphsdg, run_handwritten
    config = BenchConfig(frames=2, warmup=1, asset_count=10, resolution=(64, 64),
                         annotators=("rgb", "distance_to_image_plane"), out_dir=str(tmp_path), write_threads=1,
                         write_processes=0)
    run_graphsdg(config)
    run_handwritten(config)
    for i in range(config.frames):
        ours = np.load(tmp_path / f"distance_to_image_plane_{config.warmup + i:04d}.npy")
        loop = np.load(tmp_path / "hand-written" / f"depth_0_{i}.npy")
        hit, loop_hit = np.isfinite(ours), loop < loop.max() - 1e-3   # the loop's misses read its far plane
        assert hit.mean() > 0.05                                        # the frame shows the assets
        assert (hit == loop_hit).mean() > 0.99                          # up to an edge pixel here and there
        both = hit & loop_hit
        # within 0.25 % of the distance: the loop's depth buffer resolves ~1 cm at the scene's ~12 m, and on a GPU
        # host `auto` renders graphsdg's frames with the pbr backend, whose depths are exact (measured on an H200:
        # up to 1.5 cm apart); a shape drawn at another size differs by far more, and in what is hit
        assert np.mean(np.abs(ours[both] - loop[both]) < 0.0025 * loop[both]) > 0.99


def test_processes_started_together_stop_together_at_the_deadline():
    from graphsdg.benchmark.throughput import BenchConfig, run_graphsdg
    waited = []
    config = BenchConfig(frames=100000, seconds=0.6, warmup=1, asset_count=1, resolution=(64, 48), skip_write=True)
    r = run_graphsdg(config, before_timing=lambda: waited.append(True))
    assert waited == [True] and 0 < r.frames < 100000 and len(r.frame_times) == r.frames
    assert 0.6 <= r.wall_seconds <= 0.6 + max(r.frame_times) + 0.05   # the frame under way at the deadline ends it


def _bench_path(name: str) -> str:
    return os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "bench", f"{name}.py")


def _bench_script(name: str):
    import importlib.util
    import sys
    spec = importlib.util.spec_from_file_location(f"graphsdg_bench_{name}", _bench_path(name))
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_cpu_speed_under_load_gives_a_row_a_process_count():
    """bench/cpu_speed.py --load: each count's processes time the unit and copy memory together; the table has
    a row a count with the unit's time, positive copy rates (all processes' the sum of theirs) and steal."""
    cpu_speed = _bench_script("cpu_speed")
    one, two = cpu_speed.under_load(1, 0.05), cpu_speed.under_load(2, 0.05)
    for row in (one, two):
        assert row["unit ms"] > 0 and row["copy GB/s"] > 0
        assert math.isnan(row["steal % (unit)"]) or 0 <= row["steal % (unit)"] <= 100
    assert one["copy GB/s, all"] == pytest.approx(one["copy GB/s"])
    assert two["copy GB/s, all"] >= two["copy GB/s"]                  # the sum of two, the median of two
    table = cpu_speed.load_table([1, 2], 0.05).splitlines()
    assert table[0].startswith("| processes |") and [r.split("|")[1].strip() for r in table[2:]] == ["1", "2"]
    assert table[2].split("|")[2].strip().endswith("(1.00)")          # the first count against itself


def test_cpu_speed_refuses_a_load_of_no_processes():
    import subprocess
    import sys
    done = subprocess.run([sys.executable, _bench_path("cpu_speed"), "--load", "2", "0"], capture_output=True,
                          text=True)
    assert done.returncode == 2 and "--load takes process counts of 1 or more, got [2, 0]" in done.stderr


@pytest.mark.parametrize("shape", [(70, 53, 4), (37, 29, 3), (5, 1, 1), (300, 2, 1)])
def test_gpu_png_prototype_encodes_exact_pngs_on_warps_cpu(shape):
    """bench/gpu_png.py (run on Warp's CPU device): for fixed codes, codes built for the image and codes built
    from another image, and segments of a few bytes up to many lines, its zlib stream is byte for byte the one
    bench/png_codes.py writes for the same parse, zlib checks its Adler-32, and Pillow and OpenCV decode the
    pixels encoded."""
    pytest.importorskip("warp")
    import io
    import zlib
    import cv2
    from PIL import Image
    from graphsdg.io.png import filtered_lines
    gpu_png, png_codes = _bench_script("gpu_png"), _bench_script("png_codes")
    rng = np.random.default_rng(sum(shape))
    image = rng.integers(0, 256, shape, dtype=np.uint8)
    image[shape[0] // 2:] = 7                                   # flat rows below: matches
    stream = filtered_lines(image).reshape(-1)
    other = png_codes.histograms(png_codes.greedy_parse(stream[::-1].copy(), *png_codes.best_matches(
        stream[::-1].copy(), [1, 2], 64)))
    given = png_codes.block_code_lengths(other[0] + 1, other[1] + 1)
    for segment in (5, 256, 4096):
        encoder = gpu_png.SegmentDeflate(*shape, device="cpu", segment=segment)
        distances = png_codes.distance_set("9", shape[2], stream.size // shape[0])
        symbols = png_codes.greedy_parse(stream, *png_codes.best_matches(stream, distances, segment))
        lit_len, distance, _ = png_codes.histograms(symbols)
        for codes, lengths in (("fixed", ()), ("own", png_codes.block_code_lengths(lit_len, distance)),
                               (given, given)):
            data = encoder.png(image, codes)
            start = data.index(b"IDAT")
            idat = data[start + 4:start + 4 + int.from_bytes(data[start - 4:start], "big")]
            assert idat == png_codes.zlib_stream(symbols, stream.tobytes(), *lengths)
            assert zlib.decompress(idat) == stream.tobytes()
            assert np.array_equal(np.asarray(Image.open(io.BytesIO(data))).reshape(shape), image)
    decoded = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED).reshape(shape)
    if shape[2] >= 3:
        decoded = decoded[..., [2, 1, 0, 3][:shape[2]]]
    assert np.array_equal(decoded, image)
    with pytest.raises(ValueError, match="segment must be 1 byte or more, got 0"):
        gpu_png.SegmentDeflate(*shape, device="cpu", segment=0)


def test_png_on_device_reports_the_streams_size_against_isal(tmp_path):
    """bench/png_on_device.py on Warp's CPU device: the stream it times is checked by zlib, and it prints its
    size against ISA-L's and the host CPU of an encode."""
    pytest.importorskip("warp")
    import subprocess
    import sys
    import cv2
    image = np.zeros((24, 40, 4), np.uint8)
    image[:, :, 3] = 255
    image[8:16, 10:30, :3] = (200, 40, 10)
    cv2.imwrite(str(tmp_path / "rgb.png"), image)
    done = subprocess.run([sys.executable, _bench_path("png_on_device"), str(tmp_path / "rgb.png"), "--device", "cpu",
                           "--frames", "2"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    lines = [line for line in done.stdout.splitlines() if not line.startswith(("Warp", "Module", "   "))]
    assert lines[0].startswith("40x24 on cpu: ") and "bytes of stream against ISA-L level 1's" in lines[0]
    assert lines[1].startswith("host CPU a frame, plain launches: ") and lines[-1].startswith("ISA-L (encode_png)")


def test_png_codes_parse_rebuilds_the_filtered_lines_and_counts_its_bits():
    """bench/png_codes.py: the segment-by-segment parse a GPU would make replays to the exact filtered lines (no
    match past its segment's end), a flat image is nearly all matches, and the bits counted with the fixed codes
    are the lengths of the codes RFC 1951 gives each symbol."""
    from graphsdg.io.png import filtered_lines
    png_codes = _bench_script("png_codes")
    rng = np.random.default_rng(3)
    image = rng.integers(0, 256, (24, 20, 4), dtype=np.uint8)
    image[12:] = (9, 90, 200, 255)                                   # flat rows below: long matches
    stream = filtered_lines(image).reshape(-1)
    for segment in (7, 64, stream.size):
        best, distance = png_codes.best_matches(stream, png_codes.distance_set("9", 4, 81), segment)
        ends = np.arange(stream.size) + best
        assert (best <= 258).all() and ((ends - 1) // segment <= np.arange(stream.size) // segment).all()
        symbols = png_codes.greedy_parse(stream, best, distance)
        assert png_codes.replayed(symbols) == stream.tobytes()
    flat = filtered_lines(np.full((16, 16, 4), 77, np.uint8)).reshape(-1)
    symbols = png_codes.greedy_parse(flat, *png_codes.best_matches(flat, [1, 4, 65], flat.size))
    assert png_codes.replayed(symbols) == flat.tobytes() and len(symbols) < 20
    lit_len, dist, extra = png_codes.histograms([(0, 0), (200, 0), (3, 1), (258, 65)])
    assert lit_len[[0, 200, 256, 257, 285]].tolist() == [1, 1, 1, 1, 1] and dist[[0, 12]].tolist() == [1, 1]
    assert extra == 5                                                 # distance 65: 5 extra bits; lengths 3, 258: 0
    assert png_codes.fixed_bits(lit_len, dist, extra) == 3 + 8 + 9 + 7 + 7 + 8 + 5 + 5 + 5
    import zlib
    symbols = png_codes.greedy_parse(stream, *png_codes.best_matches(stream, [1, 4, 81], 64))
    counts = png_codes.histograms(symbols)
    for lengths, bits in (((), png_codes.fixed_bits(*counts)),
                          (png_codes.block_code_lengths(*counts[:2]), png_codes.dynamic_bits(*counts))):
        written = png_codes.zlib_stream(symbols, stream.tobytes(), *lengths)   # the sizes are the streams' own
        assert zlib.decompress(written) == stream.tobytes() and len(written) == (bits + 7) // 8 + 6


@pytest.mark.parametrize("counts", [[5, 1], [1, 1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192,
                                              16384, 32768, 65536], [3, 0, 0, 7, 7, 1]])
def test_png_codes_lengths_are_complete_prefix_codes_within_the_limit(counts):
    """Package-merge: lengths at most the limit (the skewed counts would want 17 bits unlimited), a complete
    prefix code (Kraft sum 1), unused symbols left out, and no worse than a plain Huffman code would be where
    the limit does not bind."""
    png_codes = _bench_script("png_codes")
    counts = np.array(counts)
    lengths = png_codes.limited_code_lengths(counts, limit=15)
    used = counts > 0
    assert (lengths[~used] == 0).all() and lengths[used].min() >= 1 and lengths.max() <= 15
    assert sum(2.0 ** -int(n) for n in lengths[used]) == 1.0
    if counts.size < 10:
        import heapq
        heap = [int(c) for c in counts if c]
        heapq.heapify(heap)
        huffman_cost = 0
        while len(heap) > 1:
            merged = heapq.heappop(heap) + heapq.heappop(heap)
            huffman_cost += merged
            heapq.heappush(heap, merged)
        assert int(counts @ lengths) == huffman_cost


def test_png_codes_table_sizes_an_image_against_isal(tmp_path):
    """The script's table: a row a (distance set, segment) with ISA-L's size and both estimates."""
    import subprocess
    import sys
    import cv2
    image = np.zeros((40, 30, 4), np.uint8)
    image[:, :, 3] = 255
    image[10:30, 5:20, :3] = (200, 40, 10)
    path = str(tmp_path / "mask.png")
    cv2.imwrite(path, image)
    done = subprocess.run([sys.executable, _bench_path("png_codes"), path, "--distances", "5", "--segments", "64",
                           "256"], capture_output=True, text=True, check=True)
    rows = [line.split("|") for line in done.stdout.splitlines()[2:]]
    assert [(r[2].strip(), r[3].strip()) for r in rows] == [("5", "64"), ("5", "256")]
    assert all(int(r[4].replace(",", "")) > 0 for r in rows)
    bad = subprocess.run([sys.executable, _bench_path("png_codes"), path, "--segments", "0"], capture_output=True,
                         text=True)
    assert bad.returncode == 2 and "--segments takes lengths of 1 byte or more, got [0]" in bad.stderr
