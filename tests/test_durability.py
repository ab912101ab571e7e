"""Nothing lost: atomic files, complete flushes, exit hook, worker errors, full disks, backpressure, interrupts.

Process-level behaviour (interpreter exit, SIGINT, SIGTERM) runs in subprocesses.
"""
from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from PIL import Image

import graphsdg as rep
from graphsdg.errors import WriterError
from graphsdg.io import run_state
from graphsdg.io.write_queue import WriteQueue, get_write_queue, reset_write_queue

from conftest import unit_cube_scene

STEMS = ("rgb_{n}.png", "bounding_box_2d_tight_{n}.npy", "bounding_box_2d_tight_labels_{n}.json",
         "bounding_box_2d_tight_prim_paths_{n}.json", "semantic_segmentation_{n}.png",
         "semantic_segmentation_labels_{n}.json")

# A job for subprocesses: a few cubes, a BasicWriter, optionally slowed or failing writes.
JOB = '''
import os, sys, time
import graphsdg as rep
from graphsdg.io import backends

out, mode, frames = sys.argv[1], sys.argv[2], int(sys.argv[3])
slow = float(os.environ.get("SLOW_WRITE_S", "0"))
fail_at = os.environ.get("FAIL_FILE")
real = backends.write_file_atomic

def write(path, data):
    if fail_at and path.endswith(fail_at):
        raise OSError(5, "Input/output error (injected)")
    time.sleep(slow)
    real(path, data)

backends.write_file_atomic = write
rep.settings.set("/omni/replicator/backend/writeThreads", 1)
# the injected failures and delays act in this process: writer processes only where a test asks for them
rep.settings.set("/graphsdg/io/writeProcesses", int(os.environ.get("WRITE_PROCESSES", "0")))
rep.set_global_seed(1)
rep.functional.create.xform(name="World")
rep.functional.create.dome_light(intensity=600, parent="/World")
cubes = rep.functional.create_batch.cube(count=3, parent="/World", semantics={"class": "cube"}, scale=0.5)
cam = rep.functional.create.camera(position=(4, 4, 4), look_at=(0, 0, 0), parent="/World")
rp = rep.create.render_product(cam, (48, 32))
writer = rep.writers.get(os.environ.get("WRITER", "BasicWriter"))
if type(writer).__name__ == "BasicWriter":
    writer.initialize(output_dir=out, rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True)
else:
    writer.initialize(output_dir=out)
writer.attach(rp)
if mode == "graph":
    with rep.trigger.on_frame():
        with rep.get.prims(semantics=[("class", "cube")]):
            rep.modify.pose(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 0)))
    print("started", flush=True)
    rep.orchestrator.run(num_frames=frames)
    print("run returned", flush=True)
else:
    rng = rep.rng.ReplicatorRNG(seed=1)
    print("started", flush=True)
    for i in range(frames):
        rep.functional.modify.pose(cubes, position_value=rng.generator.uniform(-1, 1, (3, 3)))
        rep.orchestrator.step()
    if mode == "wait":
        rep.orchestrator.wait_until_complete()
if os.environ.get("WRITE_PROCESSES"):
    from graphsdg.io.write_queue import get_write_queue
    print("writer processes", *get_write_queue().process_ids(), flush=True)
print("script end", flush=True)
'''


def run_job(tmp_path, mode, frames, env=None, timeout=120):
    script = tmp_path / "job.py"
    script.write_text(JOB)
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, str(script), str(out), mode, str(frames)], capture_output=True,
                          text=True, timeout=timeout, env=dict(os.environ, **(env or {})), cwd=str(tmp_path))
    return proc, out


def frame_files(out, n):
    return [os.path.join(out, s.format(n=f"{n:04d}")) for s in STEMS]


def assert_frame_whole(out, n):
    """Every file of BasicWriter frame ``n`` is there and decodes completely."""
    for path in frame_files(out, n):
        assert os.path.exists(path), path
        if path.endswith(".png"):
            Image.open(path).load()
        elif path.endswith(".npy"):
            np.load(path)
        else:
            json.load(open(path))


def frames_on_disk(out):
    return sorted({int(name.split("_")[-1].split(".")[0]) for name in os.listdir(out) if name.startswith("rgb_")})


def no_temp_files(out):
    return not [n for _, _, names in os.walk(out) for n in names if n.endswith(".tmp") or n.startswith(".")]


# ---- in-process ----------------------------------------------------------------------------------------


def test_wait_until_complete_returns_only_when_every_file_is_on_disk(out_dir, monkeypatch):
    """Writes are slowed down so that without waiting most files would still be queued."""
    from graphsdg.io import backends
    real = backends.write_file_atomic
    monkeypatch.setattr(backends, "write_file_atomic", lambda p, d: (time.sleep(0.01), real(p, d)))
    cube, cam, rp = unit_cube_scene(resolution=(48, 32))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True)
    writer.attach(rp)
    for i in range(6):
        rep.functional.modify.pose(cube, position_value=(0.1 * i, 0, 0))
        rep.orchestrator.step()
    assert get_write_queue().pending() > 0          # the test is only meaningful if writes were still queued
    state = run_state.read(out_dir)["writers"]["BasicWriter"]
    assert state["status"] == "writing" and state["next_frame"] >= 1
    rep.orchestrator.wait_until_complete()
    assert get_write_queue().pending() == 0
    for n in range(6):
        assert_frame_whole(out_dir, n)
    assert run_state.read(out_dir) is None          # complete: the run-state file is gone
    assert no_temp_files(out_dir)
    writer.detach()


def test_worker_failure_is_raised_at_the_next_step(out_dir, monkeypatch):
    from graphsdg.io import backends
    real = backends.write_file_atomic

    def failing(path, data):
        if "rgb_0001" in path:
            raise OSError(5, "Input/output error (injected)")
        real(path, data)

    monkeypatch.setattr(backends, "write_file_atomic", failing)
    cube, cam, rp = unit_cube_scene(resolution=(32, 32))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.step()
    deadline = time.monotonic() + 10
    while get_write_queue().pending() and time.monotonic() < deadline:   # the failure happens on a worker
        time.sleep(0.01)
    with pytest.raises(WriterError, match=r"OSError: \[Errno 5\] Input/output error \(injected\)"):
        rep.orchestrator.step()
    state = run_state.read(out_dir)["writers"]["BasicWriter"]
    assert state["status"] == "failed" and state["failed"] == [1] and state["complete"] == [[0, 0]]
    rep.orchestrator.wait_until_complete()           # the error was raised once; the file keeps the record
    state = run_state.read(out_dir)["writers"]["BasicWriter"]
    assert state["failed"] == [1] and state["complete"] == [[0, 0]]
    writer.detach()


def test_disk_full_leaves_only_whole_files(out_dir, monkeypatch):
    """A disk that fills up mid-dataset: every file under a final name is whole, no temp file, a clear error."""
    import errno
    import graphsdg.io.atomic_files as atomic_files
    real_write_all = atomic_files._write_all
    budget = {"bytes": None}

    def quota_write_all(fd, data):
        if budget["bytes"] is None:
            return real_write_all(fd, data)
        room = max(0, budget["bytes"])
        real_write_all(fd, data[:room])                   # what fits really reaches the disk
        budget["bytes"] -= len(data)
        if len(data) > room:
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(atomic_files, "_write_all", quota_write_all)
    cube, cam, rp = unit_cube_scene(resolution=(64, 48))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True)
    writer.attach(rp)
    rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    per_frame = sum(os.path.getsize(p) for p in frame_files(out_dir, 0))
    budget["bytes"] = int(per_frame * 2.5)                # room for about two and a half more frames
    with pytest.raises(WriterError, match=r"disk full while writing '.*'; the partial file was removed"):
        for i in range(1, 8):
            rep.functional.modify.pose(cube, position_value=(0.05 * i, 0, 0))
            rep.orchestrator.step()
        rep.orchestrator.wait_until_complete()
    with contextlib.suppress(WriterError):           # failures after the first one are raised by the next call
        rep.orchestrator.wait_until_complete()
    monkeypatch.undo()
    assert no_temp_files(out_dir)
    for name in os.listdir(out_dir):                      # whatever is there is whole
        path = os.path.join(out_dir, name)
        if name.endswith(".png"):
            Image.open(path).load()
        elif name.endswith(".npy"):
            np.load(path)
        elif name.endswith(".json"):
            json.load(open(path))
    for n in frames_on_disk(out_dir)[:2]:
        assert_frame_whole(out_dir, n)
    assert len(frames_on_disk(out_dir)) < 8
    writer.detach()


def test_queue_size_and_byte_limit_are_live_settings():
    q = get_write_queue()
    rep.settings.set("/omni/replicator/backend/queueSize", 3)
    rep.settings.set("/graphsdg/io/queueMaxBytes", 4096)
    rep.settings.set("/omni/replicator/backend/writeThreads", 2)
    try:
        assert get_write_queue() is q and (q.max_size, q.max_bytes, q.num_threads) == (3, 4096, 2)
    finally:
        rep.settings.reset()
        reset_write_queue()
    with pytest.raises(ValueError, match=r"setting /omni/replicator/backend/queueSize must be an integer >= 1, "
                                         r"got 0"):
        rep.settings.set("/omni/replicator/backend/queueSize", 0)
    with pytest.raises(ValueError, match=r"setting /omni/replicator/backend/writeThreads must be a positive integer, "
                                         r"got 0"):
        WriteQueue(num_threads=0)


def test_byte_limit_throttles_the_producer_and_bounds_memory():
    q = WriteQueue(num_threads=1, max_size=1000, max_bytes=10_000)
    gate = threading.Event()
    seen = []
    q.schedule(gate.wait)
    arrays = [np.zeros(4000, np.uint8) for _ in range(6)]
    producer = threading.Thread(target=lambda: [q.schedule(lambda arr: seen.append(arr.size), a) for a in arrays])
    producer.start()
    time.sleep(0.2)
    assert producer.is_alive()                  # 2 arrays (8 kB) queued; the third would pass 10 kB
    assert q.queued_bytes() == 8000 and q.pending() == 3
    gate.set()
    producer.join(5)
    q.wait_until_done()
    assert seen == [4000] * 6 and q.peak_bytes <= 10_000 and q.throttled_seconds > 0.1
    q.shutdown()


def test_a_task_may_schedule_follow_ups_on_a_full_queue():
    """Backpressure must not deadlock a worker that schedules more work (it never waits for its own room)."""
    q = WriteQueue(num_threads=1, max_size=1)
    done = []

    def parent(k):
        for i in range(3):
            q.schedule(done.append, (k, i))

    for k in range(3):
        q.schedule(parent, k)
    q.wait_until_done()
    assert sorted(done) == [(k, i) for k in range(3) for i in range(3)]
    q.shutdown()


def test_tasks_run_in_order_and_groups_report_completion():
    q = WriteQueue(num_threads=4, max_size=4)
    order, groups = [], []
    for g in range(5):
        with q.group(lambda ok, g=g: groups.append((g, ok))):
            for i in range(3):
                q.schedule(lambda g=g, i=i: (time.sleep(0.001 * (3 - i)), order.append((g, i))))
    with q.group(lambda ok: groups.append(("failing", ok))):
        q.schedule(lambda: 1 / 0)
    with q.group(lambda ok: groups.append(("empty", ok))):
        pass
    with pytest.raises(WriterError, match="ZeroDivisionError"):
        q.wait_until_done()
    assert sorted(order) == [(g, i) for g in range(5) for i in range(3)]
    assert sorted(groups, key=str) == sorted([(g, True) for g in range(5)] + [("failing", False), ("empty", True)],
                                             key=str)
    q.shutdown()


def test_attach_detach_cycles_leave_no_tracked_state(out_dir):
    cube, cam, rp = unit_cube_scene(resolution=(16, 16))
    for i in range(5):
        writer = rep.writers.get("BasicWriter")
        writer.initialize(output_dir=out_dir, rgb=True)
        writer.attach(rp)
        rep.orchestrator.step()
        writer.detach()
        rep.orchestrator.wait_until_complete()
    assert run_state.open_ledgers() == 0 and run_state.read(out_dir) is None


# ---- interpreter exit ------------------------------------------------------------------------------------


def test_exit_without_wait_until_complete_still_writes_every_frame(tmp_path):
    proc, out = run_job(tmp_path, "steps", 8, env={"SLOW_WRITE_S": "0.02"})
    assert proc.returncode == 0, proc.stderr
    assert "file writes were still queued at exit (wait_until_complete() was not called); finishing them now" \
        in proc.stderr
    for n in range(8):
        assert_frame_whole(out, n)
    state = run_state.read(out)["writers"]["BasicWriter"]         # the script did not finish its writes itself
    assert state["status"] == "exited" and state["complete"] == [[0, 7]] and state["next_frame"] == 8


def test_exit_without_wait_until_complete_finishes_the_writer_processes_writes(tmp_path):
    proc, out = run_job(tmp_path, "steps", 8, env={"WRITE_PROCESSES": "2"})
    assert proc.returncode == 0, proc.stderr
    for n in range(8):
        assert_frame_whole(out, n)
    state = run_state.read(out)["writers"]["BasicWriter"]
    assert state["status"] == "exited" and state["complete"] == [[0, 7]]
    pids = [int(p) for p in next(line for line in proc.stdout.splitlines()
                                 if line.startswith("writer processes")).split()[2:]]
    assert pids
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(os.path.exists(f"/proc/{pid}") for pid in pids):
        time.sleep(0.05)
    assert not any(os.path.exists(f"/proc/{pid}") for pid in pids)   # no writer process outlives the script


def test_exit_flushes_aggregate_files(tmp_path):
    proc, out = run_job(tmp_path, "steps", 3, env={"WRITER": "CocoWriter", "SOURCE_DATE_EPOCH": "1700000000"})
    assert proc.returncode == 0, proc.stderr
    coco = json.load(open(next(os.path.join(out, n) for n in os.listdir(out) if n.startswith("coco_annotations"))))
    assert len(coco["images"]) == 3 and len(coco["annotations"]) >= 3


def test_failed_writes_at_exit_are_reported_loudly(tmp_path):
    proc, out = run_job(tmp_path, "steps", 4, env={"FAIL_FILE": "rgb_0003.png", "SLOW_WRITE_S": "0.01"})
    assert "ERROR at exit: writes failed and the dataset is incomplete" in proc.stderr
    assert "a background write of 'rgb_0003.png' failed: OSError: [Errno 5] Input/output error (injected)" in proc.stderr
    state = run_state.read(out)["writers"]["BasicWriter"]
    assert state["status"] == "failed" and state["complete"] == [[0, 2]] and state["failed"] == [3]


# ---- interrupts -------------------------------------------------------------------------------------------


def _interrupt_when_frames_exist(proc, out, count, sig=signal.SIGINT, timeout=60):
    assert proc.stdout.readline().strip() == "started"
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if os.path.isdir(out) and len([n for n in os.listdir(out) if n.startswith("rgb_")]) >= count:
            break
        time.sleep(0.02)
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=timeout)
    return stdout, stderr


def _start(tmp_path, mode, frames, env=None):
    script = tmp_path / "job.py"
    script.write_text(JOB)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, str(script), str(out), mode, str(frames)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=str(tmp_path), env=dict(os.environ, **(env or {})))
    return proc, out


def _assert_resumable(out, status):
    """The interrupted dataset: only whole frames, all of them listed as complete in graphsdg_run.json."""
    state = run_state.read(out)["writers"]["BasicWriter"]
    on_disk = frames_on_disk(out)
    assert state["status"] == status
    assert on_disk == list(range(len(on_disk))) and len(on_disk) >= 3
    assert state["complete"] == [[0, len(on_disk) - 1]] and state["next_frame"] == len(on_disk)
    for n in on_disk:
        assert_frame_whole(out, n)
    assert no_temp_files(out)
    return len(on_disk)


@pytest.mark.parametrize("processes", ["0", "2"])
@pytest.mark.parametrize("sig,code", [(signal.SIGINT, (-signal.SIGINT, 130, 1)), (signal.SIGTERM, (143,))])
def test_signal_during_run_stops_after_the_frame_and_flushes(tmp_path, sig, code, processes):
    """Writer threads or writer processes (which ignore the signal: the script decides when writing stops)."""
    proc, out = _start(tmp_path, "graph", 100000, env={"WRITE_PROCESSES": processes})
    stdout, stderr = _interrupt_when_frames_exist(proc, out, 3, sig)
    assert proc.returncode in code, (proc.returncode, stderr)
    assert "run returned" not in stdout                   # run() re-raises the interrupt after flushing
    assert "graphsdg: interrupted after" in stderr and "every captured frame is on disk" in stderr
    _assert_resumable(out, "interrupted")


def test_ctrl_c_in_a_step_loop_stops_between_frames(tmp_path):
    proc, out = _start(tmp_path, "steps", 100000)
    stdout, stderr = _interrupt_when_frames_exist(proc, out, 3)
    assert proc.returncode in (-signal.SIGINT, 130, 1), stderr
    assert "KeyboardInterrupt" in stderr and "script end" not in stdout
    _assert_resumable(out, "interrupted")


def test_signal_handlers_of_the_script_are_left_alone():
    seen = []
    previous = signal.signal(signal.SIGINT, lambda *a: seen.append("mine"))
    try:
        cube, cam, rp = unit_cube_scene(resolution=(16, 16))
        rep.annotators.get("rgb").attach(rp)
        os.kill(os.getpid(), signal.SIGINT)
        rep.orchestrator.step()
        assert seen == ["mine"]
    finally:
        signal.signal(signal.SIGINT, previous)


# ---- the run-state file ------------------------------------------------------------------------------------


def test_aggregate_writers_frames_complete_only_after_their_shared_files_are_flushed(out_dir, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    cube, cam, rp = unit_cube_scene(resolution=(32, 32))
    writer = rep.writers.get("CocoWriter")
    writer.initialize(output_dir=out_dir, dataset_id="agg")
    writer.attach(rp)
    for _ in range(3):
        rep.orchestrator.step()
    get_write_queue().wait_until_done()              # the images are on disk, the json is not rewritten yet
    run_state.save(force=True)
    state = run_state.read(writer.output_dir)["writers"]["CocoWriter"]
    assert state["aggregate_files"] and state["complete"] == [] and state["next_frame"] == 3
    rep.orchestrator.wait_until_complete()
    assert run_state.read(writer.output_dir) is None
    writer.detach()


def test_ledger_restore_numbering_and_shard_file_names(out_dir):
    cube, cam, rp = unit_cube_scene(resolution=(16, 16))
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out_dir, rgb=True)
    writer.attach(rp)
    ledger = run_state.ledger_for(writer)
    ledger.restore({"complete": [[0, 4], [7, 7]], "steps": [[0, 0, 8]], "next_frame": 8})
    assert ledger.next_frame == 5                     # frames 5 and 6 were left incomplete: redo from 5
    rep.orchestrator.step()
    get_write_queue().wait_until_done()
    run_state.save(force=True)
    state = run_state.read(out_dir)["writers"]["BasicWriter"]
    assert state["complete"] == [[0, 5], [7, 7]] and state["next_frame"] == 6
    assert state["steps"] == [[0, 0, 5], [5, 0, 1]]   # frame 5 was captured by this stage's first step
    rep.settings.set("/graphsdg/run/shardIndex", 1)
    rep.settings.set("/graphsdg/run/shardCount", 3)
    assert run_state.file_name() == "graphsdg_run.shard-1-of-3.json"
    rep.settings.reset()
    rep.orchestrator.wait_until_complete()
    writer.detach()


def test_run_state_read_rejects_foreign_files(tmp_path):
    (tmp_path / run_state.FILE_NAME).write_text('{"format": "something-else", "version": 1}')
    with pytest.raises(ValueError, match=r"is not a graphsdg.run_state file of version 1 \(found \('something-else', 1\)\)"):
        run_state.read(tmp_path)
    assert run_state.read(tmp_path / "nowhere") is None


def test_validate_reports_an_unfinished_run(tmp_path):
    from graphsdg.dataset.validate import validate
    script = tmp_path / "job.py"
    script.write_text(JOB)
    subprocess.run([sys.executable, str(script), str(tmp_path / "out"), "steps", "3"], check=True, timeout=120,
                   capture_output=True, cwd=str(tmp_path))      # exits without wait_until_complete: status exited
    found = [str(v) for v in validate(str(tmp_path / "out")) if "did not finish" in str(v)]
    assert found == ["-: [complete] the run that wrote this folder did not finish (graphsdg_run.json: BasicWriter "
                     "exited, complete frames 0-2); resume or rerun it"]


def test_temporaries_of_interrupted_writes_are_recognised_and_removed(tmp_path, monkeypatch):
    from graphsdg.io import backends

    def die_before_rename(src, dst):
        raise KeyboardInterrupt   # the process stops between writing the temporary and renaming it
    monkeypatch.setattr(backends.os, "replace", die_before_rename)
    monkeypatch.setattr(backends.os, "unlink", lambda path: None)   # and never gets to clean up
    with contextlib.suppress(KeyboardInterrupt):
        backends.write_file_atomic(str(tmp_path / "rgb_0007.png"), b"pixels")
    monkeypatch.undo()
    left = os.listdir(tmp_path)
    assert len(left) == 1 and left[0].startswith(".rgb_0007.png.") and left[0].endswith(".tmp")
    (tmp_path / "notes.tmp").write_text("a user's file")               # not ours: kept
    (tmp_path / ".rgb_0001.png.0123456789ab.tmp").write_bytes(b"x")    # an earlier build's temporary
    assert backends.remove_temporaries(str(tmp_path)) == 2
    assert os.listdir(tmp_path) == ["notes.tmp"]
