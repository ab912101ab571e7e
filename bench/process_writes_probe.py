"""A measurement probe, not product code: the bench's disk writes in a separate process, to measure what the
interpreter lock shared with a writer thread costs a small frame (docs/performance.md, "Small images on the GPU
host").

It replaces the write queue's ``schedule`` for BasicWriter's image / array / JSON writes to a disk backend:
each task's data and full path go over a pipe to one spawned process, which encodes and writes atomically
with graphsdg's own functions; ``wait_until_done`` waits for that process too. Everything else runs as in
``bench/thread_cpu.py``, whose arguments it takes.

Usage (GPU host):
    MUJOCO_GL=egl python bench/process_writes_probe.py --resolution 128
"""
from __future__ import annotations

import fcntl
import multiprocessing as mp
import os
import sys
from typing import Callable

F_SETPIPE_SZ = 1031   # Linux: a pipe's buffer size


def _child(conn) -> None:
    from graphsdg.io import encode
    from graphsdg.io.backends import write_file_atomic
    encoders = {"write_image": lambda d, p: encode.encode_image(d, os.path.splitext(p)[1]),
                "write_np": lambda d, p: encode.encode_npy(d), "write_json": lambda d, p: encode.encode_json(d)}
    while True:
        message = conn.recv()
        if message == "stop":
            return
        if message is None:            # a wait: everything before it is written
            conn.send("done")
            continue
        kind, data, path = message
        write_file_atomic(path, encoders[kind](data, path))


def install() -> tuple[mp.Process, Callable[[], None]]:
    """Start the writer process and route the bench's disk writes to it; returns the process and a function
    that waits for its writes and routes them back to the write queue."""
    from graphsdg.io import backends, io_functions, write_queue
    ctx = mp.get_context("spawn")
    parent, child = ctx.Pipe()
    for end in (parent, child):
        try:
            fcntl.fcntl(end.fileno(), F_SETPIPE_SZ, 1 << 20)
        except OSError:                # a socket pair has no pipe size
            pass
    process = ctx.Process(target=_child, args=(child,), daemon=True)
    process.start()
    names = {io_functions.write_image: "write_image", io_functions.write_np: "write_np",
             io_functions.write_json: "write_json"}
    schedule, wait = write_queue.WriteQueue.schedule, write_queue.WriteQueue.wait_until_done

    def routed(self, fn, *args, **kwargs):
        backend = kwargs.get("backend_instance")
        if isinstance(backend, backends.BackendGroup) and len(backend.backends) == 1:
            backend = backend.backends[0]
        if fn in names and type(backend) is backends.DiskBackend and not args:
            parent.send((names[fn], kwargs["data"], backend.resolve(kwargs["path"])))
            return None
        return schedule(self, fn, *args, **kwargs)

    def waited(self):
        parent.send(None)
        parent.recv()
        return wait(self)

    def restore() -> None:
        parent.send(None)
        parent.recv()
        write_queue.WriteQueue.schedule, write_queue.WriteQueue.wait_until_done = schedule, wait
        parent.send("stop")
        process.join(10)

    write_queue.WriteQueue.schedule = routed
    write_queue.WriteQueue.wait_until_done = waited
    return process, restore


def main(argv: list[str] | None = None) -> int:
    process, restore = install()
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import thread_cpu

    def cpu() -> float:
        with open(f"/proc/{process.pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    start = cpu()
    thread_cpu.main(argv)
    used = cpu() - start
    restore()
    print(f"  writer process CPU over the whole run: {used:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
