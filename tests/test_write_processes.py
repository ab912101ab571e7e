"""Writer processes (/graphsdg/io/writeProcesses): the same files as writer threads, errors that reach the
script, a killed process, the arena's ring and its limits, the order of writes to one file, forks."""
from __future__ import annotations

import json
import os
import signal
import zlib

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg.errors import WriterError
from graphsdg.io import io_functions as iof
from graphsdg.io import run_state
from graphsdg.io.write_processes import FileWrite, WriteProcesses
from graphsdg.io.write_queue import get_write_queue, processes_wanted, reset_write_queue

from conftest import unit_cube_scene


@pytest.fixture(autouse=True)
def fresh_queue():
    reset_write_queue()
    yield
    reset_write_queue()


def _dataset(out_dir: str, processes: int, frames: int = 3) -> dict[str, bytes]:
    """A BasicWriter dataset of a moving cube (images large enough to go through the arena); name -> bytes."""
    rep.settings.set("/graphsdg/io/writeProcesses", processes)
    cube, cam, rp = unit_cube_scene(resolution=(96, 64))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True,
                      distance_to_image_plane=True, camera_params=True)
    writer.attach(rp)
    for i in range(frames):
        rep.functional.modify.pose(cube, position_value=(0.2 * i, 0.0, 0.1 * i))
        rep.orchestrator.step()
    pids = get_write_queue().process_ids()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    rp.destroy()
    files = {name: open(os.path.join(out_dir, name), "rb").read() for name in sorted(os.listdir(out_dir))}
    files["pids"] = repr(pids).encode()
    return files


def test_processes_write_the_same_bytes_as_threads(tmp_path):
    threads = _dataset(str(tmp_path / "threads"), processes=0)
    rep.stage.new_stage()
    reset_write_queue()
    processes = _dataset(str(tmp_path / "processes"), processes=2)
    assert threads.pop("pids") == b"[]"
    pids = eval(processes.pop("pids"))
    assert pids and os.getpid() not in pids                   # the writes really went to other processes
    assert sorted(threads) == sorted(processes) and len(threads) >= 3 * 8
    for name in threads:
        assert processes[name] == threads[name], name
    depth = np.load(tmp_path / "processes" / "distance_to_image_plane_0002.npy")
    assert depth.shape == (64, 96) and depth.dtype == np.float32 and np.isfinite(depth).any()
    rgb = np.asarray(Image.open(tmp_path / "processes" / "rgb_0001.png"))
    assert rgb.shape == (64, 96, 4) and rgb[..., :3].std() > 0   # a real render, decoded by another reader
    # the class mask's rows went unfiltered on both paths (a label image), the colour's Sub-filtered
    for name, filter_type in (("semantic_segmentation_0001.png", 0), ("rgb_0001.png", 1)):
        png = processes[name]
        start = png.index(b"IDAT") + 4
        lines = zlib.decompress(png[start:start + int.from_bytes(png[start - 8:start - 4], "big")])
        assert set(lines[::96 * 4 + 1]) == {filter_type}, name
    state = json.load(open(tmp_path / "processes" / run_state.FILE_NAME)) \
        if os.path.exists(tmp_path / "processes" / run_state.FILE_NAME) else None
    assert state is None or state["writers"]["BasicWriter"]["complete"] == [[0, 2]]


def test_a_failed_write_reaches_the_script_naming_the_file(out_dir):
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    backend = rep.backends.get("DiskBackend", init_params={"output_dir": out_dir})
    open(os.path.join(out_dir, "blocker"), "w").close()          # a file where a folder must go
    queue = get_write_queue()
    backend.schedule(iof.write_image, data=np.zeros((64, 64, 3), np.uint8), path="blocker/rgb_0000.png")
    backend.schedule(iof.write_np, data=np.arange(5), path="fine.npy")
    with pytest.raises(WriterError, match=r"background write of '.*blocker/rgb_0000\.png' failed: "
                                          r"(NotADirectoryError|FileExistsError): \[Errno \d+\] [A-Z][^\[]*: '"):
        queue.wait_until_done()
    assert queue.process_ids()
    assert np.load(os.path.join(out_dir, "fine.npy")).tolist() == [0, 1, 2, 3, 4]
    queue.schedule(iof.write_image, data=np.zeros((4, 4), np.float64), path=os.path.join(out_dir, "bad.png"))
    with pytest.raises(WriterError, match=r"bad\.png' failed: ValueError: cannot encode an image of dtype "
                                          r"float64"):
        queue.wait_until_done()
    assert not [f for f in os.listdir(out_dir) if f.endswith(".tmp")]


def test_a_killed_writer_process_fails_its_writes_and_the_next_one_takes_over(out_dir):
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    queue = get_write_queue()
    queue.schedule(iof.write_json, data={"a": 1}, path=os.path.join(out_dir, "first.json"))
    queue.wait_until_done()
    (pid,) = queue.process_ids()
    os.kill(pid, signal.SIGSTOP)                                 # the next write is surely still held when it dies
    queue.schedule(iof.write_np, data=np.ones((128, 128)), path=os.path.join(out_dir, "lost.npy"))
    os.kill(pid, signal.SIGKILL)
    with pytest.raises(WriterError, match=r"writer process \(pid \d+\) exited (with code -9 )?before"):
        queue.wait_until_done()
    queue.schedule(iof.write_np, data=np.ones((128, 128)), path=os.path.join(out_dir, "after.npy"))
    queue.wait_until_done()
    assert np.load(os.path.join(out_dir, "after.npy")).sum() == 128 * 128
    assert not os.path.exists(os.path.join(out_dir, "lost.npy"))
    assert queue.process_ids() and pid not in queue.process_ids()


def test_writes_to_one_file_land_in_the_order_scheduled(out_dir):
    rep.settings.set("/graphsdg/io/writeProcesses", 3)
    queue = get_write_queue()
    for i in range(12):                                         # a backlog: more processes start
        queue.schedule(iof.write_np, data=np.full((64, 64), i, np.float64), path=os.path.join(out_dir, f"{i}.npy"))
    queue.wait_until_done()
    assert len(queue.process_ids()) >= 2
    path = os.path.join(out_dir, "frame.json")
    slow = {"values": np.random.default_rng(0).random(400_000)}         # ~0.1 s to turn into JSON
    queue.schedule(iof.write_json, data=slow, path=path)
    queue.schedule(iof.write_blob, data=b"the last write", path=path)   # an idle process would finish it first
    queue.wait_until_done()
    assert open(path, "rb").read() == b"the last write"


def test_the_arena_is_a_ring_with_backpressure_and_oversized_arrays_travel_in_the_message(tmp_path):
    done = []
    pool = WriteProcesses(1, on_done=lambda finished, seconds: done.extend((t, e) for t, e, _ in finished),
                          arena_bytes=1 << 20)
    arrays = [np.full((400, 256), i, np.float32) for i in range(12)]      # 400 KB each: ~2 fit at a time
    for i, a in enumerate(arrays):
        pool.send([(FileWrite("npy", str(tmp_path / f"{i}.npy"), a, None), i)], durable=False)
    big = np.arange(600 * 600, dtype=np.float32).reshape(600, 600)       # 1.4 MB: more than the whole arena
    pool.send([(FileWrite("npy", str(tmp_path / "big.npy"), big, None), "big")], durable=False)
    pool.shutdown()
    assert sorted(map(str, (t for t, _ in done))) == sorted(map(str, [*range(12), "big"]))
    assert all(error is None for _, error in done)
    for i, a in enumerate(arrays):
        np.testing.assert_array_equal(np.load(tmp_path / f"{i}.npy"), a)
    np.testing.assert_array_equal(np.load(tmp_path / "big.npy"), big)


def test_ring_reservations_never_overlap_held_batches():
    import collections

    from graphsdg.io.write_processes import _Process
    ring = _Process.__new__(_Process)                  # the ring's arithmetic alone, no process
    ring.size, ring.head = 100, 0
    ring.regions = collections.deque()
    assert ring.reserve(101) is None and ring.reserve(100) == 0
    ring.regions.extend([(0, 40), (40, 80)])
    ring.head = 80
    assert ring.reserve(20) == 80 and ring.reserve(21) is None      # [80, 100) free, [0, 0) before the tail
    ring.regions.popleft()                                          # the oldest is written: [0, 40) free
    assert ring.reserve(30) == 0                                    # past the end: from the start
    ring.regions.append((0, 30))
    ring.head = 30
    assert ring.reserve(10) == 30 and ring.reserve(11) is None      # wrapped: only [30, 40)


def test_the_queue_limits_count_process_writes(out_dir):
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    rep.settings.set("/omni/replicator/backend/queueSize", 2)
    queue = get_write_queue()
    for i in range(20):
        queue.schedule(iof.write_np, data=np.zeros((64, 64)), path=os.path.join(out_dir, f"{i}.npy"))
        assert queue.pending() <= 2
    queue.wait_until_done()
    assert len([f for f in os.listdir(out_dir) if f.endswith(".npy")]) == 20 and queue.throttled_seconds >= 0


def test_a_forked_child_starts_its_own_writer_process(out_dir):
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    queue = get_write_queue()
    queue.schedule(iof.write_json, data=[1], path=os.path.join(out_dir, "parent.json"))
    queue.wait_until_done()
    parent_pids = queue.process_ids()
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            os.close(read)
            assert get_write_queue().process_ids() == []
            get_write_queue().schedule(iof.write_json, data=[2], path=os.path.join(out_dir, "child.json"))
            child_pids = get_write_queue().process_ids()
            get_write_queue().wait_until_done()
            os.write(write, json.dumps(child_pids).encode())
            get_write_queue().shutdown()
            code = 0
        finally:
            os._exit(code)
    os.close(write)
    child_pids = json.loads(os.read(read, 1000).decode() or "null")
    os.close(read)
    assert os.waitpid(pid, 0)[1] == 0
    assert child_pids and not set(child_pids) & set(parent_pids)
    assert json.load(open(os.path.join(out_dir, "child.json"))) == [2]
    queue.schedule(iof.write_json, data=[3], path=os.path.join(out_dir, "parent.json"))
    queue.wait_until_done()                                     # the parent's process still serves it
    assert queue.process_ids() == parent_pids and json.load(open(os.path.join(out_dir, "parent.json"))) == [3]


def test_writes_that_are_not_plain_local_files_stay_on_the_threads(out_dir):
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    queue = get_write_queue()
    seen = []
    queue.schedule(seen.append, "custom")                        # a writer's own function
    big = np.zeros((1024, 1024, 3), np.uint8)                    # 3 MiB: copying it costs more than it saves
    queue.schedule(iof.write_image, data=big, path=os.path.join(out_dir, "big.png"))
    queue.wait_until_done()
    assert queue.process_ids() == [] and np.asarray(Image.open(os.path.join(out_dir, "big.png"))).shape == big.shape

    class CountingDisk(rep.backends.DiskBackend):                # a backend with a write_blob of its own
        def write_blob(self, path, data):
            seen.append(path)
            super().write_blob(path, data)

    backend = CountingDisk(output_dir=out_dir)
    backend.schedule(iof.write_np, data=np.zeros((64, 64)), path="counted.npy")
    queue.wait_until_done()
    assert seen == ["custom", "counted.npy"] and np.load(os.path.join(out_dir, "counted.npy")).shape == (64, 64)
    rep.settings.set("/graphsdg/io/discardWrites", True)
    queue.schedule(iof.write_json, data=[1], path=os.path.join(out_dir, "discarded.json"))
    queue.wait_until_done()
    assert queue.process_ids() == [] and not os.path.exists(os.path.join(out_dir, "discarded.json"))


def test_the_setting_is_checked_and_auto_follows_the_cores():
    with pytest.raises(ValueError, match=r"/graphsdg/io/writeProcesses must be 'auto' or an integer >= 0, got -1"):
        rep.settings.set("/graphsdg/io/writeProcesses", -1)
    with pytest.raises(ValueError, match=r"writeProcesses must be 'auto' or an integer >= 0, got 'many'"):
        rep.settings.set("/graphsdg/io/writeProcesses", "many")
    assert processes_wanted("auto", 4, cores=16) == 4
    assert processes_wanted("auto", 1, cores=16) == 0        # one writer thread: one of many processes on a host
    assert processes_wanted("auto", 4, cores=2) == 0
    assert processes_wanted(3, 1, cores=2) == 3


def test_no_thread_reads_the_replies_the_threads_using_the_pool_take_them(out_dir):
    # a reader thread woken by every reply took the interpreter lock from the thread that renders; now the
    # pool's users collect replies (at each send, and while they wait or ask for progress)
    import threading
    import time
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    before = set(threading.enumerate())
    queue = get_write_queue()
    path = os.path.join(out_dir, "a.npy")
    queue.schedule(iof.write_np, data=np.ones((128, 128)), path=path)
    assert queue.process_ids() and set(threading.enumerate()) == before
    deadline = time.monotonic() + 60
    while not queue.is_done():                                  # asking takes the reply that came
        assert time.monotonic() < deadline
        time.sleep(0.005)
    assert np.load(path).sum() == 128 * 128 and queue.pending() == 0
    for i in range(30):                                         # many more replies than sends wait unread
        queue.schedule(iof.write_np, data=np.full((64, 64), i, np.float64), path=os.path.join(out_dir, f"{i}.npy"))
    queue.wait_until_done()
    assert [float(np.load(os.path.join(out_dir, f"{i}.npy"))[0, 0]) for i in range(30)] == list(range(30))
    assert set(threading.enumerate()) == before


def test_a_group_closed_inside_a_batch_reports_when_its_writes_are_written(out_dir):
    """A frame's group closes before the batch holding its writes is sent: it must not report them done then."""
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    queue = get_write_queue()
    done = []
    os.makedirs(out_dir, exist_ok=True)
    open(os.path.join(out_dir, "blocker"), "w").close()                 # a file where a folder must go
    with queue.batch():
        with queue.group(done.append):
            queue.schedule(iof.write_np, data=np.arange(3), path=os.path.join(out_dir, "a.npy"))
            queue.schedule(iof.write_json, data={"a": 1}, path=os.path.join(out_dir, "a.json"))
        with queue.group(done.append):
            queue.schedule(iof.write_np, data=np.arange(3), path=os.path.join(out_dir, "blocker", "b.npy"))
        with queue.group(done.append):
            pass                                             # nothing scheduled: done when the block ends
        assert done == [True] and queue.pending() == 0      # the batch's writes are not sent yet
    with pytest.raises(WriterError, match="blocker/b.npy"):
        queue.wait_until_done()
    assert sorted(done) == [False, True, True]
    assert np.load(os.path.join(out_dir, "a.npy")).tolist() == [0, 1, 2]


def test_a_batch_larger_than_the_queue_goes_whole_once_the_queue_is_empty(out_dir):
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    rep.settings.set("/omni/replicator/backend/queueSize", 2)
    queue = get_write_queue()
    for frame in range(4):
        with queue.batch():
            for i in range(5):
                queue.schedule(iof.write_np, data=np.full(4, frame), path=os.path.join(out_dir, f"{frame}_{i}.npy"))
        assert queue.pending() <= 5
    queue.wait_until_done()
    assert [np.load(os.path.join(out_dir, f"{f}_4.npy"))[0] for f in range(4)] == [0, 1, 2, 3]


def test_schedule_many_sends_the_files_as_one_batch_and_honours_a_backends_own_schedule(out_dir, monkeypatch):
    rep.settings.set("/graphsdg/io/writeProcesses", 1)
    batches = []
    real_send = WriteProcesses.send
    monkeypatch.setattr(WriteProcesses, "send", lambda self, writes, durable: (batches.append(len(writes)),
                                                                              real_send(self, writes, durable)))
    backend = rep.backends.get("DiskBackend", init_params={"output_dir": out_dir})
    calls = [(iof.write_np, {"data": np.arange(i + 1), "path": f"a_{i}.npy"}) for i in range(3)]
    calls.append((iof.write_json, {"data": {"n": 3}, "path": "a.json"}))
    calls.append((lambda backend_instance, text: backend_instance.write_blob("b.txt", text.encode()),
                  {"text": "on a thread"}))                       # not a file write a process can do
    backend.schedule_many(calls)
    get_write_queue().wait_until_done()
    assert batches == [4]
    assert [np.load(os.path.join(out_dir, f"a_{i}.npy")).tolist() for i in range(3)] == [[0], [0, 1], [0, 1, 2]]
    assert json.load(open(os.path.join(out_dir, "a.json"))) == {"n": 3}
    assert open(os.path.join(out_dir, "b.txt")).read() == "on a thread"

    class Counting(type(backend)):
        def schedule(self, fn, *args, **kwargs):
            seen.append(kwargs["path"])
            super().schedule(fn, *args, **kwargs)
    seen = []
    counting = Counting(out_dir)
    counting.schedule_many(calls[:2])
    get_write_queue().wait_until_done()
    assert seen == ["a_0.npy", "a_1.npy"]
