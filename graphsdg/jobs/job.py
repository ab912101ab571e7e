"""A dataset job: one script run, with its seed, output root, frame count and plan.

``graphsdg run`` builds a :class:`JobSpec`; :func:`run_job` runs it in this
process (the whole job, or one shard of a sharded job) and returns a summary.
A job with an output root (a folder or an ``s3://bucket/prefix``) leaves
``.graphsdg-job.json`` there, so ``--resume`` can refuse to continue a dataset
that another job (other script, seed or frame count) wrote.
"""
from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import asdict, dataclass, field

from graphsdg import orchestrator
from graphsdg.io import frame_plan
from graphsdg.io.frame_plan import FramePlan
from graphsdg.io import backends
from graphsdg.io.location import open_location
from graphsdg.jobs.script_runner import run_script

JOB_FILE = ".graphsdg-job.json"


class JobMismatchError(RuntimeError):
    """``--resume`` on an output folder written by a different job."""


@dataclass(frozen=True)
class JobSpec:
    """What ``graphsdg run`` was asked to run."""

    script: str
    args: tuple[str, ...] = ()
    compat: str | None = None
    seed: int | None = None
    out: str | None = None
    frames: int | None = None
    resume: bool = False
    resolution_scale: float | None = None
    env: dict = field(default_factory=dict)
    #: the script's bytes, sent along to shards on nodes that may not see ``script`` (no shared filesystem)
    script_source: bytes | None = None

    def describe(self) -> dict:
        """The job for summaries and ``graphsdg_index.json`` (no environment, no script bytes)."""
        return {k: v for k, v in asdict(self).items() if k not in ("env", "script_source")}

    def fingerprint(self) -> dict:
        """What must match for a resume: the script's bytes, its arguments, seed and frame count."""
        with open(self.script, "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
        return {"script": os.path.abspath(self.script), "script_sha256": digest, "args": list(self.args),
                "compat": self.compat, "seed": self.seed, "frames": self.frames,
                "resolution_scale": self.resolution_scale}


def check_job_file(job: JobSpec) -> None:
    """Write ``.graphsdg-job.json`` under ``job.out``; on resume first check it describes the same job."""
    if job.out is None:
        return
    root = open_location(job.out)       # an s3:// root: the bucket and credentials are checked here
    mine = job.fingerprint()
    if job.resume and root.exists(JOB_FILE):
        theirs = json.loads(root.read(JOB_FILE))
        diff = {k: (theirs.get(k), v) for k, v in mine.items() if k != "script" and theirs.get(k) != v}
        if diff:
            detail = ", ".join(f"{k}: {a!r} on disk, {b!r} now" for k, (a, b) in diff.items())
            raise JobMismatchError(f"--resume: {job.out} was written by a different job ({detail}); "
                                   f"rerun with the same script, arguments, --seed and --frames, or drop --resume")
    root.write(JOB_FILE, json.dumps(mine, indent=2).encode(), count=False)


def run_job(job: JobSpec, plan: FramePlan | None = None) -> dict:
    """Run ``job`` in this process (shard ``plan`` of it, if given); return its summary."""

    plan = plan or FramePlan(resume=job.resume)
    for key, value in job.env.items():
        os.environ.setdefault(key, value)
    start, frames0 = time.perf_counter(), orchestrator.frames_captured()
    files0, bytes0 = backends.files_written(), backends.bytes_written()
    frame_plan.set_plan(plan)
    frame_plan.clear_records()
    try:
        run_script(job.script, job.args, compat=job.compat, seed=job.seed, out_dir=job.out, frames=job.frames,
                   resolution_scale=job.resolution_scale)
    finally:
        frame_plan.set_plan(None)
    seconds = time.perf_counter() - start
    frames = orchestrator.frames_captured() - frames0
    return {"shard": plan.shard_index, "frames": frames, "files": backends.files_written() - files0,
            "bytes": backends.bytes_written() - bytes0, "seconds": round(seconds, 3),
            "frames/s": round(frames / seconds, 2) if seconds > 0 else 0.0,
            "writers": frame_plan.records(), "job": job.describe()}


def format_summary(summary: dict) -> str:
    """One line: frames, files, bytes, wall time, frames per second."""
    size = float(summary["bytes"])
    unit = "B"
    for unit in ("B", "KB", "MB", "GB", "TB"):
        if size < 1024 or unit == "TB":
            break
        size /= 1024
    text = (f"{summary['frames']} frames, {summary['files']} files, {size:.1f} {unit} in "
            f"{summary['seconds']:.1f} s ({summary['frames/s']:.2f} frames/s)")
    if summary.get("workers"):
        text += f" on {summary['workers']} workers"
    return text
