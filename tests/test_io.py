"""Writers and backends: atomic files, errors that reach the script, custom writers."""
from __future__ import annotations

import os

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.errors import WriterError
from graphsdg.io.backends import write_file_atomic

from conftest import unit_cube_scene


def test_write_is_atomic_and_cleans_up(tmp_path, monkeypatch):
    target = tmp_path / "a.bin"

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full.*a.bin"):
        write_file_atomic(str(target), b"x" * 1000)
    monkeypatch.undo()
    assert os.listdir(tmp_path) == []          # neither the final name nor a temp file remains
    write_file_atomic(str(target), b"data")
    assert target.read_bytes() == b"data"


def test_worker_failure_reaches_the_script(out_dir):
    class BadWriter(rep.Writer):
        def __init__(self, output_dir):
            self.annotators = ["rgb"]
            self.backend = rep.backends.get("DiskBackend")
            self.backend.initialize(output_dir=output_dir)

        def write(self, data):
            # a float image cannot be a PNG: the encoder raises on a worker thread
            self.backend.schedule(rep.functional.write_image, data=np.zeros((4, 4), np.float64),
                                  path="bad.png")

    rep.WriterRegistry.register(BadWriter)
    cube, cam, rp = unit_cube_scene()
    writer = rep.writers.get("BadWriter")
    writer.initialize(output_dir=out_dir)
    writer.attach(rp)
    rep.orchestrator.step()
    with pytest.raises(WriterError, match="dtype float64"):
        rep.orchestrator.wait_until_complete()
    assert not os.path.exists(os.path.join(out_dir, "bad.png"))
    writer.detach()


def test_custom_writer_data_structures(out_dir):
    seen = {}

    class Probe(rep.Writer):
        def __init__(self, structure):
            self.data_structure = structure
            self.annotators = [rep.annotators.get("rgb"), "bounding_box_2d_tight"]

        def write(self, data):
            seen[self.data_structure] = data

    rep.writers.register_writer(Probe)
    cube, cam, rp = unit_cube_scene(resolution=(64, 48))
    cam2 = rep.functional.create.camera(position=(0, 0, 5), look_at=(0, 0, 0), parent="/World", name="Top")
    rp2 = rep.create.render_product(cam2, (32, 32), name="top")
    writers = []
    for structure in ("legacy", "annotator", "renderProduct"):
        w = rep.writers.get("Probe")
        w.initialize(structure=structure)
        w.attach([rp, rp2])
        writers.append(w)
    rep.orchestrator.step()
    legacy = seen["legacy"]
    assert legacy[f"rgb-{rp.name}"].shape == (48, 64, 4) and legacy["rgb-top"].shape == (32, 32, 4)
    assert set(legacy[f"bounding_box_2d_tight-{rp.name}"]) == {"data", "info"}
    anno = seen["annotator"]["annotators"]
    assert anno["rgb"]["top"]["data"].shape == (32, 32, 4)
    assert anno["bounding_box_2d_tight"][rp.name]["primPaths"] == ["/World/Cube"]
    per_rp = seen["renderProduct"]["renderProducts"]["top"]
    assert per_rp["camera"] == "/World/Top" and per_rp["resolution"] == [32, 32]
    assert "trigger_outputs" in legacy and "reference_time" in legacy
    for w in writers:
        w.detach()


def test_output_dir_that_is_a_file_is_refused(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    with pytest.raises(NotADirectoryError, match="file"):
        rep.writers.get("BasicWriter").initialize(output_dir=str(f), rgb=True)


def test_backend_registry():
    with pytest.raises(KeyError, match="DiskBackend"):
        rep.backends.get("DiskBackendd")

    class MemoryBackend(rep.backends.BaseBackend):
        def __init__(self):
            self.blobs = {}

        def write_blob(self, path, data):
            self.blobs[path] = data

    rep.backends.register(MemoryBackend)
    b = rep.backends.get("MemoryBackend", init_params={})
    b.schedule(rep.functional.write_json, data={"a": np.int64(1)}, path="x.json")
    rep.orchestrator.wait_until_complete()
    assert b.blobs == {"x.json": b'{"a": 1}'}


def test_full_queue_throttles_the_producer():
    import threading
    import time

    from graphsdg.io.write_queue import WriteQueue

    q = WriteQueue(num_threads=1, max_size=2)
    gate = threading.Event()
    q.schedule(gate.wait)                     # occupies the only worker
    q.schedule(lambda: None)
    q.schedule(lambda: None)                  # queue now full (2 waiting)
    blocked = threading.Thread(target=q.schedule, args=(lambda: None,))
    blocked.start()
    time.sleep(0.2)
    assert blocked.is_alive()                 # backpressure: the producer waits instead of growing memory
    assert q.pending() <= 4
    gate.set()
    blocked.join(5)
    q.wait_until_done()
    assert q.completed == 4 and q.throttled_seconds > 0.1
    q.shutdown()


def test_a_batch_wakes_the_workers_once_when_it_ends():
    import threading
    import time

    from graphsdg.io.write_queue import WriteQueue

    q = WriteQueue(num_threads=2, max_size=100)
    ran: list[int] = []
    q.schedule(ran.append, -1)
    q.wait_until_done()
    deadline = time.monotonic() + 10          # a worker that just finished a task may not be waiting yet
    while len(q._has_work._waiters) < len(q._threads) and time.monotonic() < deadline:   # CPython's Condition
        time.sleep(0.01)                                                                 # keeps its waiters
    assert len(q._has_work._waiters) == len(q._threads) >= 1     # every worker now waits for work
    with q.batch():
        for i in range(5):
            q.schedule(ran.append, i)
        with q.batch():                       # nested: still held until the outer block ends
            q.schedule(ran.append, 5)
        time.sleep(0.1)
        assert ran == [-1]                    # no idle worker was woken inside the block
        assert q.pending() == 6
    q.wait_until_done()
    assert sorted(ran) == [-1, 0, 1, 2, 3, 4, 5]
    # inside a block, a full queue, wait_until_done and shutdown wake the workers first (no deadlock)
    small = WriteQueue(num_threads=1, max_size=2)
    done = threading.Event()

    def produce():
        with small.batch():
            for i in range(6):
                small.schedule(ran.append, 10 + i)
            small.wait_until_done()
            small.schedule(ran.append, 16)
            small.shutdown()
        done.set()

    threading.Thread(target=produce, daemon=True).start()
    assert done.wait(10), "a batch on a full queue deadlocked"
    assert sorted(ran)[-7:] == list(range(10, 17))
    q.shutdown()


@pytest.mark.parametrize("threads", [1, 3])
def test_bytes_do_not_depend_on_writer_threads(tmp_path, threads):
    from test_foundation import _capture
    from graphsdg.io.write_queue import reset_write_queue

    reference = _capture(str(tmp_path / "ref"))
    rep.settings.set("/omni/replicator/backend/writeThreads", threads)
    reset_write_queue()
    try:
        other = _capture(str(tmp_path / f"t{threads}"))
    finally:
        rep.settings.reset()
        reset_write_queue()
    assert reference == other


def test_seed_custom_writer_example(capsys):
    """The MyWriter of Isaac Sim's getting-started example 02, registered and attached to two cameras."""

    class MyWriter(rep.Writer):
        def __init__(self, camera_params: bool = True, bounding_box_3d: bool = True):
            self.data_structure = "renderProduct"
            self.annotators = []
            if camera_params:
                self.annotators.append(rep.annotators.get("camera_params"))
            if bounding_box_3d:
                self.annotators.append(rep.annotators.get("bounding_box_3d"))
            self._frame_id = 0
            self.frames = []

        def write(self, data: dict):
            print(f"[MyWriter][{self._frame_id}] data:")
            for key, value in data.items():
                print(f"  {key}: {value}")
            self.frames.append(data)
            self._frame_id += 1

    rep.writers.register_writer(MyWriter)
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=500, parent="/World", name="DomeLight")
    cube = rep.functional.create.cube(parent="/World", name="Cube")
    rep.functional.modify.semantics(cube, {"class": "my_cube"}, mode="add")
    top = rep.functional.create.camera(position=(0, 0, 5), look_at=(0, 0, 0), parent="/World", name="TopCamera")
    persp = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0), parent="/World", name="PerspCamera")
    rp_top = rep.create.render_product(top.GetPath(), (40, 40), name="top_view")
    rp_persp = rep.create.render_product(persp.GetPath(), (51, 51), name="persp_view")
    writer = rep.writers.get("MyWriter")
    writer.initialize(camera_params=True, bounding_box_3d=True)
    writer.attach([rp_top, rp_persp])
    for _ in range(3):
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    assert writer._frame_id == 3
    products = writer.frames[-1]["renderProducts"]
    assert set(products) == {"top_view", "persp_view"}
    top_data = products["top_view"]
    assert top_data["camera"] == "/World/TopCamera" and top_data["resolution"] == [40, 40]
    assert list(top_data["camera_params"]["renderProductResolution"]) == [40, 40]
    box = top_data["bounding_box_3d"]
    assert box["primPaths"] == ["/World/Cube"] and np.allclose(box["data"][0]["x_max"], 0.5)
    assert "[MyWriter][2] data:" in capsys.readouterr().out
    writer.detach()
    rp_top.destroy()
    rp_persp.destroy()


def test_a_forked_child_names_its_temporary_files_apart():
    """Atomic writes' temporary names carry a per-process token: a forked child (a worker pool's) makes its
    own, so parent and child writing the same file never share a temporary name."""
    from graphsdg.io import atomic_files

    parent = atomic_files._temp_token()
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:                                   # the child: report its token and leave at once
        os.close(read)
        os.write(write, atomic_files._temp_token().encode())
        os._exit(0)
    os.close(write)
    child = os.read(read, 100).decode()
    os.close(read)
    os.waitpid(pid, 0)
    assert child[:10] != parent[:10] and atomic_files._temp_token()[:10] == parent[:10]


def test_writer_threads_start_as_the_backlog_needs_them():
    """One worker while it keeps up; more, up to the setting, once tasks wait; fewer configured retire."""
    import threading
    import time

    from graphsdg.io.write_queue import BACKLOG_PER_WORKER, WriteQueue

    q = WriteQueue(num_threads=4, max_size=1000)
    for _ in range(50):                        # one task at a time: one worker keeps up
        q.schedule(lambda: None)
        q.wait_until_done()
    assert len(q._threads) == 1
    gate = threading.Event()
    for _ in range(5 * BACKLOG_PER_WORKER):    # every task holds its worker: the backlog grows
        q.schedule(gate.wait)
    assert len(q._threads) == 4                # the backlog started the others, never more than the setting
    gate.set()
    q.wait_until_done()
    assert q.completed == 50 + 5 * BACKLOG_PER_WORKER
    q.configure(num_threads=2, max_size=1000, max_bytes=1 << 30)
    deadline = time.monotonic() + 10
    while len(q._threads) > 2 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert len(q._threads) == 2
    q.schedule(lambda: None)
    q.wait_until_done()
    assert len(q._threads) == 2
    q.shutdown()


def test_waiting_for_progress_returns_once_a_write_let_go_of_its_data():
    """``wait_for_progress``: False at once with nothing queued; else back after a task finished, by when the
    task's arguments are released (what lent frame buffers wait on)."""
    import threading
    import weakref

    from graphsdg.io.write_queue import WriteQueue

    class Frame:
        pass

    q = WriteQueue(num_threads=1, max_size=10)
    assert q.wait_for_progress() is False
    gate = threading.Event()
    frame = Frame()
    alive = weakref.ref(frame)
    q.schedule(lambda held: gate.wait(), frame)
    del frame
    threading.Timer(0.05, gate.set).start()
    assert q.wait_for_progress() is True
    assert alive() is None                      # the worker let go of the frame before the write counted as done
    assert q.wait_for_progress() is False and q.completed == 1
    with q.batch():                             # a task deferred by this thread's batch is woken, not waited on forever
        q.schedule(lambda: None)
        assert q.wait_for_progress() is True
    q.shutdown()
