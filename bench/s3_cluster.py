"""What object storage costs: a 2-node local Ray cluster writing to a local S3 server vs one process on disk.

One run, four rows, the same job (a graph of on_frame randomizers over five labelled shapes, BasicWriter
with rgb, tight 2D boxes, semantic segmentation and depth) with the same seed and frame count:

* one process writing to disk (the baseline),
* one process writing to the S3 server (the per-frame cost of the object store alone),
* ``--workers 2`` on a 2-node Ray cluster (``ray.cluster_utils.Cluster``, one CPU per node, so one
  shard per node) writing to disk, and the same cluster writing to the S3 server: no shared disk,
  merge and ``graphsdg_index.json`` in the bucket.

The S3 server is moto's (:class:`graphsdg.io.local_s3.LocalS3Server`) on 127.0.0.1, with credentials
checked; its CPU time per frame is reported, as it shares this machine's cores with the job. ``wall`` is
the whole job (for the cluster: shard actors' start, capture, merge, index);
``shards`` is frames over the slowest shard's own time (capture and writes, no start-up). The S3 rows
are checked byte for byte against the disk rows before the table is printed.

    MUJOCO_GL=egl python bench/s3_cluster.py --frames 200 --resolution 256
"""
from __future__ import annotations

import argparse
import os
import platform
import shutil
import sys
import tempfile
import time

# BasicWriter on a graph of on_frame triggers; the resolution comes from the command line
JOB = '''
import sys
import graphsdg as rep
size = int(sys.argv[1])
rep.stage.new_stage()
rep.functional.create.xform(name="World")
rep.functional.create.dome_light(intensity=500, parent="/World")
rep.functional.create.plane(parent="/World", scale=(6, 6, 1), semantics={"class": "floor"})
for kind in ("cube", "sphere", "cone", "cylinder", "torus"):
    getattr(rep.functional.create, kind)(parent="/World", semantics={"class": kind})
cam = rep.functional.create.camera(position=(4, 4, 3.5), look_at=(0, 0, 0), parent="/World")
rp = rep.create.render_product(cam, (size, size))
with rep.trigger.on_frame():
    for kind in ("cube", "sphere", "cone", "cylinder", "torus"):
        with rep.get.prims(semantics=[("class", kind)]):
            rep.modify.pose(position=rep.distribution.uniform((-2, -2, 0.5), (2, 2, 0.5)),
                            rotation=rep.distribution.uniform((0, 0, 0), (0, 0, 360)))
writer = rep.writers.get("BasicWriter")
writer.initialize(output_dir="basic", rgb=True, bounding_box_2d_tight=True, semantic_segmentation=True,
                  distance_to_image_plane=True)
writer.attach(rp)
rep.orchestrator.run()
'''


def _disk_files(root: str) -> dict[str, bytes]:
    out = {}
    for folder, _, names in os.walk(os.path.join(root, "basic")):
        for name in names:
            path = os.path.join(folder, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, os.path.join(root, "basic"))] = f.read()
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--resolution", type=int, default=256)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()

    import ray
    from ray.cluster_utils import Cluster

    import graphsdg as rep
    from graphsdg.io import object_store
    from graphsdg.io.local_s3 import LocalS3Server
    from graphsdg.jobs.job import JobSpec, run_job
    from graphsdg.jobs.scaleout import run_sharded

    work = tempfile.mkdtemp(prefix="graphsdg-s3-bench-")
    script = os.path.join(work, "job.py")
    with open(script, "w", encoding="utf-8") as f:
        f.write(JOB)
    job_args = (str(args.resolution),)
    rows = []
    with LocalS3Server() as server:
        server.create_bucket("bench")
        os.environ.update(server.environment())     # the standard AWS chain, here and in the nodes
        os.environ.setdefault("MUJOCO_GL", "egl")
        object_store.forget_stores()

        def single(out: str, name: str) -> dict:
            cpu = server.cpu_seconds()
            summary = run_job(JobSpec(script, job_args, seed=args.seed, out=out, frames=args.frames))
            rep.orchestrator.wait_until_complete()
            return {"run": name, "frames": summary["frames"], "wall s": summary["seconds"],
                    "shards s": summary["seconds"], "bytes": summary["bytes"], "files": summary["files"],
                    "server cpu s": server.cpu_seconds() - cpu}

        rows.append(single(os.path.join(work, "disk1"), "1 process -> disk"))
        rows.append(single("s3://bench/single", "1 process -> S3"))
        cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False})
        cluster.add_node(num_cpus=1)
        cluster.wait_for_nodes()
        try:
            for out, name in ((os.path.join(work, "disk2"), "2-node Ray -> disk"),
                              ("s3://bench/cluster", "2-node Ray -> S3")):
                cpu = server.cpu_seconds()
                summary = run_sharded(JobSpec(script, job_args, seed=args.seed, out=out, frames=args.frames), 2,
                                      address=cluster.address)
                if len({s["node"] for s in summary["shards"]}) != 2:
                    raise RuntimeError("the shards did not run on two nodes")
                rows.append({"run": name, "frames": summary["frames"], "wall s": summary["seconds"],
                             "shards s": max(s["seconds"] for s in summary["shards"]), "bytes": summary["bytes"],
                             "files": summary["files"], "server cpu s": server.cpu_seconds() - cpu})
        finally:
            if ray.is_initialized():
                ray.shutdown()
            cluster.shutdown()
        disk = _disk_files(os.path.join(work, "disk1"))
        for name, other in (("s3://bench/single/basic", server.objects("bench", "single/basic/")),
                            ("s3://bench/cluster/basic", server.objects("bench", "cluster/basic/")),
                            ("the 2-node disk run", _disk_files(os.path.join(work, "disk2")))):
            differ = sorted(k for k in set(disk) | set(other) if disk.get(k) != other.get(k))
            if differ:
                raise RuntimeError(f"{name} differs from the 1-process disk dataset in {len(differ)} files: "
                                   f"{differ[:6]}")
    shutil.rmtree(work, ignore_errors=True)

    base = {r["run"]: r for r in rows}
    print(f"### {args.frames} frames, {args.resolution}x{args.resolution}, BasicWriter rgb + tight boxes + "
          f"semantic segmentation + depth\n")
    print(f"Machine: {platform.node()} ({os.cpu_count()} cores), Python {sys.version.split()[0]}, "
          f"MUJOCO_GL={os.environ.get('MUJOCO_GL')}; S3: moto server on 127.0.0.1\n")
    print("| run | frames/s (wall) | frames/s (shards) | ms/frame (wall) | S3 cost ms/frame | S3 server CPU "
          "ms/frame | objects/frame | KB/frame |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        ms = 1000 * r["wall s"] / r["frames"]
        twin = base.get(r["run"].replace("S3", "disk")) if r["run"].endswith("S3") else None
        cost = f"{ms - 1000 * twin['wall s'] / twin['frames']:+.1f}" if twin else "-"
        server_ms = f"{1000 * r['server cpu s'] / r['frames']:.1f}" if twin else "-"
        print(f"| {r['run']} | {r['frames'] / r['wall s']:.1f} | {r['frames'] / r['shards s']:.1f} | {ms:.1f} | "
              f"{cost} | {server_ms} | {r['files'] / r['frames']:.1f} | {r['bytes'] / r['frames'] / 1024:.1f} |")
    print("\nThe S3 datasets were checked byte for byte against the disk dataset.")


if __name__ == "__main__":
    main()
