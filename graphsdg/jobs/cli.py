"""The ``graphsdg`` command line: ``demo``, ``run``, ``graph``, ``view``, ``validate``, ``bench``, ``warmup``.

``graphsdg COMMAND --help`` describes each; docs/cli.md has examples and the
semantics of ``run --workers`` (sharding on Ray) and ``run --resume``.
"""
from __future__ import annotations

import argparse
import math
import os
import sys

from graphsdg.jobs.demo_scene import run_demo  # noqa: F401  (graphsdg demo; importable from here as before)
from graphsdg.render.cuda_mps import MODES as MPS_MODES


def run_bench(args: argparse.Namespace) -> None:
    """``graphsdg bench``: print (and optionally record) the benchmark table."""
    import platform

    from graphsdg.benchmark import throughput

    annotators = tuple(throughput.ANNOTATOR_FLAGS) if args.annotators == ["all"] else tuple(args.annotators)
    if args.rounds > 1 and args.processes and not args.gpus:
        raise ValueError(f"--rounds {args.rounds} alternates the one-process comparison with the hand-written loop; "
                         f"with --processes {args.processes} there is none (with --gpus the GPU counts take turns): "
                         f"run the command again instead")
    if args.processes_per_gpu and not args.gpus:
        raise ValueError(f"--processes-per-gpu {args.processes_per_gpu} needs --gpus: it is each GPU's share of the "
                         f"processes")
    if args.bind_cores == "on" and not args.gpus:
        raise ValueError("--bind-cores needs --gpus: it binds each GPU's processes to that GPU's share of the cores")
    unknown = [a for a in annotators if a not in throughput.ANNOTATOR_FLAGS]
    if unknown:
        raise ValueError(f"unknown benchmark annotator(s) {unknown}; known: {sorted(throughput.ANNOTATOR_FLAGS)}")
    config = throughput.BenchConfig(
        frames=args.num_frames, warmup=args.warmup, num_cameras=args.num_cameras, resolution=tuple(args.resolution),
        asset_count=args.asset_count, annotators=annotators, skip_write=args.skip_write,
        rt_subframes=args.rt_subframes, wait_for_render=args.wait_for_render,
        write_to_fabric=not args.no_replicator_write_to_fabric, write_threads=args.write_threads,
        msaa_samples=args.msaa, shadow_size=args.shadow_size, render_backend=args.backend, seconds=args.seconds,
        render_mode=args.rendermode, path_spp=args.spp, pbr_batch_pixels=args.pbr_batch_pixels,
        pbr_kernel=args.pbr_kernel, png_on_device=True if args.png_on_device else None,
        write_processes=args.write_processes, temp_dir=args.temp_dir)
    quality = "".join([f", MSAA {args.msaa}" if args.msaa is not None else "",
                       f", shadow map {args.shadow_size}" if args.shadow_size is not None else "",
                       f", {args.write_threads} write threads" if args.write_threads is not None else
                       "" if args.processes or args.gpus else f", {_default_write_threads()} write threads",
                       f", write processes {args.write_processes}" if args.write_processes is not None else "",
                       ", wait_for_render" if args.wait_for_render else "",
                       f", {args.rendermode}" if args.rendermode else "",
                       f", {args.spp} path samples" if args.spp else "",
                       f", pbr batch pixels {args.pbr_batch_pixels}" if args.pbr_batch_pixels is not None else "",
                       f", pbr kernel {args.pbr_kernel}" if args.pbr_kernel is not None else "",
                       ", PNGs compressed on the GPU" if args.png_on_device else "",
                       f", {args.rounds} rounds alternately" if args.rounds > 1 else ""])
    length = f"{args.num_frames} frames" if args.seconds is None else \
        f"~{args.seconds:g} s a run (at most {args.num_frames} frames)"
    settings_line = (f"{length}, {args.num_cameras} camera(s), {args.resolution[0]}x{args.resolution[1]}{quality}, "
                     f"{args.asset_count * 5} assets, annotators {', '.join(annotators)}, "
                     f"{'skip-write' if args.skip_write else 'written to ' + _written_where(args.temp_dir)}")
    machine = f"{platform.node()} ({_cores_line()}), GL: {_gl_renderer()}, render backend: " \
              f"{_render_backend(args.backend)}"
    if args.gpus:
        table = _bench_on_gpus(args, config)
    elif args.processes:
        from graphsdg.render.cuda_mps import shared_gpus
        with shared_gpus(args.mps, args.processes) as mps:     # every process on the one GPU CUDA shows
            row = throughput.run_processes(config, args.processes)
        table = f"{throughput.format_table([row])}\n\n{mps.describe()}"
    else:
        rounds = [throughput.run_pair(config) if not args.no_baseline else (throughput.run_graphsdg(config), None)
                  for _ in range(args.rounds)]
        table = throughput.format_table(throughput.round_summaries(rounds))
        if args.profile:   # the first round's phases
            ours, loop = rounds[0]
            prof = ours.profile
            frame_ms = 1000.0 / ours.fps if ours.fps else 0.0
            table += "\n\n" + throughput.format_table(
                [{"phase": k, "ms/frame": round(v / ours.frames * 1000, 2),
                  "share of frame": "(worker threads)" if k == "encode+write" else
                  f"{v / ours.frames * 1000 / frame_ms:.0%}" if frame_ms else "-"}
                 for k, v in sorted(prof.items(), key=lambda kv: -kv[1])])
            table += f"\n\ngraphsdg frame time {frame_ms:.2f} ms"
            if loop is not None and loop.profile:
                base_ms = 1000.0 / loop.fps if loop.fps else 0.0
                table += "\n\n" + throughput.format_table(
                    [{"hand-written phase": k, "ms/frame": round(v / loop.frames * 1000, 2)}
                     for k, v in sorted(loop.profile.items(), key=lambda kv: -kv[1])])
                table += f"\n\nhand-written frame time {base_ms:.2f} ms"
    text = f"### {settings_line}\n\nMachine: {machine}\n\n{table}\n"
    print(text)
    if args.report:
        with open(args.report, "a", encoding="utf-8") as f:
            f.write("\n" + text)


def run_view(args: argparse.Namespace) -> int:
    """``graphsdg view``: the contact sheet (and gallery page), or the Rerun recording; print the summary and any
    warning (one ``warning:`` line each, on stderr)."""
    import warnings

    from graphsdg.dataset.view import summary_lines, write_view
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if args.rerun is not None:
            from graphsdg.base.heap import keep_freed_buffers
            from graphsdg.dataset.rerun_recording import record
            keep_freed_buffers()   # a frame's decoded masks and depth are megabyte buffers made and dropped
            target = args.rerun
            result = record(args.dir, None if target in ("", "spawn") or target.startswith("rerun") else target,
                            spawn=target == "spawn", connect=target if target.startswith("rerun") else None,
                            max_frames=args.max)
        else:
            result = write_view(args.dir, args.out, args.max, args.html, args.page_size)
    for line in summary_lines(result):
        print(line)
    for w in caught:
        print(f"warning: {w.message}", file=sys.stderr)
    return 0


def _bench_on_gpus(args: argparse.Namespace, config) -> str:
    """``graphsdg bench --gpus K [K ...]``: per count, the total and per-GPU tables; with several counts, the
    scaling table. Every count is checked against the machine before anything runs."""
    from graphsdg.benchmark import multi_gpu
    from graphsdg.benchmark.throughput import format_table
    from graphsdg.render.cuda_mps import shared_gpus, would_share
    from graphsdg.render.gpu_assignment import check_egl_sees, choose_gpus, default_processes_per_gpu
    if args.processes and args.processes_per_gpu:
        raise ValueError(f"--processes {args.processes} and --processes-per-gpu {args.processes_per_gpu} both say "
                         f"how many processes run: give one of them")
    chosen = {count: choose_gpus(count) for count in args.gpus}     # GpuCountError before any run
    if os.environ.get("MUJOCO_GL", "egl").lower() == "egl":
        from graphsdg.render.egl_device import egl_cuda_devices
        check_egl_sees(chosen[max(chosen)], egl_cuda_devices())
    shares = _gpu_core_shares() if args.bind_cores != "off" else None
    rounds, parts = [], []
    for number in range(1, args.rounds + 1):     # with --rounds K the counts take turns: 1, 2, 4, 1, 2, 4, ...
        runs = []
        for count, gpus in chosen.items():
            cores = bound_cores(args.bind_cores, count, shares)
            per_gpu = args.processes_per_gpu or default_processes_per_gpu(
                count, cores=len(cores[gpus[0].index]) * count if cores else None, mps=would_share(args.mps))
            processes = args.processes or count * per_gpu
            with shared_gpus(args.mps, math.ceil(processes / count)) as mps:
                run = multi_gpu.run_on_gpus(config, processes, gpus, cores)
            runs.append(run)
            bound = f", each GPU's processes on its {len(cores[gpus[0].index])} cores" if cores else ""
            which = f", round {number}" if args.rounds > 1 else ""
            parts.append(f"#### {count} GPU(s), {processes} processes{bound}{which}\n\n{format_table([run.total])}"
                         f"\n\n{format_table(run.per_gpu) if run.per_gpu else '(no per-GPU rows)'}\n\n"
                         f"{mps.describe()}")
        rounds.append(runs)
    if args.rounds > 1:
        parts.append("#### Rounds\n\n" + format_table(multi_gpu.round_rows(rounds)))
    if len(chosen) > 1:
        title = "#### Scaling (each count's median round)" if args.rounds > 1 else "#### Scaling"
        parts.append(f"{title}\n\n" + format_table(multi_gpu.scaling_rows(multi_gpu.median_runs(rounds))))
    return "\n\n".join(parts)


def bound_cores(mode: str, count: int, shares: dict[int, list[int]] | None) -> dict[int, list[int]] | None:
    """``bench --bind-cores MODE``'s binding for a run on ``count`` GPUs: ``shares`` (each GPU's cores) or None
    (every process may run on every core). ``on`` binds at every count, ``auto`` with more than one GPU (where
    it measured faster; one GPU's processes then have every core), ``off`` never.

    Example:
        >>> shares = {0: [0, 1], 1: [2, 3]}
        >>> bound_cores("auto", 1, shares), bound_cores("auto", 2, shares) is shares, bound_cores("on", 1, shares)
        (None, True, {0: [0, 1], 1: [2, 3]})
    """
    return shares if mode == "on" or (mode == "auto" and count > 1) else None


def _gpu_core_shares() -> dict[int, list[int]]:
    """``--bind-cores``: each GPU this process sees, with its share of the cores this process may run on."""
    from graphsdg.render.gpu_assignment import host_gpus, visible_gpus
    from graphsdg.render.gpu_cores import gpu_cores
    from graphsdg.base.cpu_share import usable_core_set
    seen = visible_gpus(host_gpus(), os.environ.get("CUDA_VISIBLE_DEVICES"))
    return gpu_cores(seen, usable_core_set())


def run_graph(args: argparse.Namespace, script_args: list[str]) -> int:
    """``graphsdg graph``: build the script's graph (no render, no write); print it, write DOT and PNG."""
    from graphsdg import graph as graphs
    from graphsdg.jobs.script_runner import build_script

    stopped_at = build_script(args.script, script_args, compat=args.compat, seed=args.seed)
    g = graphs.current_graph(create=False)
    stem = os.path.splitext(os.path.basename(args.script))[0]
    out = args.out or "."
    os.makedirs(out, exist_ok=True)
    dot_path = args.dot or os.path.join(out, f"{stem}.graph.dot")
    png_path = args.png or os.path.join(out, f"{stem}.graph.png")
    json_path = args.json or os.path.join(out, f"{stem}.graph.json")
    dot = graphs.to_dot(g, dot_path)
    text = graphs.to_json(g, json_path)
    graphs.draw(g, png_path)
    printed = {"text": graphs.describe(g), "dot": dot, "json": text}[args.print]
    print(printed.rstrip("\n"))
    where = f"stopped at orchestrator.{stopped_at}()" if stopped_at else "the script ended without capturing"
    print(f"\n{where}; wrote {dot_path}, {json_path}, {png_path}", file=sys.stderr)
    return 0


def _cores_line() -> str:
    """``64 cores``, or ``64 cores, 16 of them usable`` where this process's affinity allows fewer."""
    from graphsdg.base.cpu_share import usable_cores
    machine, usable = os.cpu_count() or 1, usable_cores()
    return f"{machine} cores" + (f", {usable} of them usable" if usable < machine else "")


def _gl_renderer() -> str:
    try:
        from mujoco.rendering.classic import gl_context
        from OpenGL import GL

        ctx = gl_context.GLContext(16, 16)
        ctx.make_current()
        name = GL.glGetString(GL.GL_RENDERER).decode()
        ctx.free()
        return name
    except Exception as exc:  # noqa: BLE001 - informational only
        return f"unknown ({exc})"


def _count_or_auto(text: str) -> int | str:
    if text == "auto":
        return text
    return _non_negative(text)


def _default_write_threads() -> int:
    from graphsdg.io.write_queue import default_threads
    return default_threads()


def _render_backend(requested: str | None) -> str:
    """The renderer a bench run drew with: ``requested`` (or the setting) resolved on this machine."""
    import dataclasses

    from graphsdg.render.backend import requested_backend, resolve_backend
    request = requested_backend()
    if requested is not None:
        request = dataclasses.replace(request, backend=requested)
    try:
        return resolve_backend(request)
    except Exception as exc:  # noqa: BLE001 - informational only (the run itself reported any error)
        return f"unknown ({exc})"


def run_job_command(args: argparse.Namespace, script_args: list[str]) -> int:
    """``graphsdg run``: the script in this process, or sharded over Ray workers; then the summary."""
    from graphsdg.jobs.job import JobSpec, check_job_file, format_summary, run_job

    if not os.path.isfile(args.script):
        raise FileNotFoundError(f"script {args.script!r} does not exist")
    job = JobSpec(script=args.script, args=tuple(script_args), compat=args.compat, seed=args.seed, out=args.out,
                  frames=args.frames, resume=args.resume, resolution_scale=args.resolution_scale)
    if args.gpus is not None and args.workers is None:
        raise ValueError(f"--gpus {args.gpus} spreads --workers over GPUs; without --workers the script runs in "
                         f"this process (its GPU: CUDA_VISIBLE_DEVICES)")
    if args.workers is not None:
        from graphsdg.jobs.scaleout import import_ray, run_sharded
        import_ray()                      # says how to get Ray before anything runs
        check_job_file(job)
        summary = run_sharded(job, args.workers, address=args.address, gpus_per_worker=args.gpus_per_worker,
                              gpus=args.gpus, mps=args.mps, bind_cores=args.bind_cores == "auto")
    else:
        check_job_file(job)
        summary = run_job(job)
    print(f"graphsdg run: {format_summary(summary)}")
    if args.workers is not None:
        from graphsdg.jobs.scaleout import format_gpu_rows
        gpu_line = format_gpu_rows(summary)
        if gpu_line:
            print(f"graphsdg run: {gpu_line}")
        print(f"graphsdg run: {summary['mps']}")
    if summary.get("index"):
        print(f"graphsdg run: index {summary['index']}")
    return 0


def run_folder_command(args: argparse.Namespace, script_args: list[str]) -> int:
    """``graphsdg run-folder``: a verdict line per script, then the totals; 1 if any failed."""
    from graphsdg.jobs.script_suite import run_folder, summary_line
    extra = [] if args.resolution_scale is None else ["--resolution-scale", str(args.resolution_scale)]
    results = run_folder(args.folder, args.compat, script_args, args.out, args.timeout, args.pattern, extra,
                         report=lambda r: print(r.line(), flush=True))
    print(summary_line(results))
    return 0 if all(r.passed for r in results) else 1


def _hint(exc: BaseException) -> str:
    """The hint line printed under a one-line error."""
    from graphsdg.jobs.job import JobMismatchError
    from graphsdg.io.object_store import ObjectStoreError, S3MissingError
    from graphsdg.jobs.scaleout import RayMissingError, ShardFailedError
    from graphsdg.render.gpu_assignment import GpuCountError
    from graphsdg.render.egl_device import EglDeviceError
    if isinstance(exc, (GpuCountError, EglDeviceError)):
        return "nvidia-smi lists this machine's GPUs; CUDA_VISIBLE_DEVICES limits the ones graphsdg sees"
    if isinstance(exc, RayMissingError):
        return "install Ray with: pip install 'graphsdg[ray]'"
    if type(exc).__name__ == "RerunMissingError":
        return "install the Rerun SDK with: pip install 'graphsdg[viewer]'"
    if isinstance(exc, S3MissingError):
        return "install boto3 with: pip install 'graphsdg[s3]'"
    if isinstance(exc, ShardFailedError):
        return "rerun the same command with --resume to capture the missing frames"
    if isinstance(exc, ObjectStoreError):
        return "check the bucket, the endpoint (AWS_ENDPOINT_URL_S3) and the credentials; see docs/cli.md"
    if isinstance(exc, JobMismatchError):
        return "resume with the arguments of the first run, or write to a fresh --out"
    if isinstance(exc, (FileNotFoundError, NotADirectoryError)):
        return "check the path; rerun with --debug for the traceback"
    return "rerun with --debug for the traceback"


def _folder(value: str) -> str:
    if not os.path.isdir(value):
        raise argparse.ArgumentTypeError(f"{value!r} is not an existing folder")
    return value


def _written_where(temp_dir: str | None) -> str:
    """Where the bench's frames go, for its report: the folder, its file system's type and a tmpfs's large
    pages."""
    import tempfile

    from graphsdg.benchmark.throughput import file_system_of, huge_pages_of
    folder = temp_dir or tempfile.gettempdir()
    huge = huge_pages_of(folder)
    return f"{folder} ({file_system_of(folder)}{f', huge={huge}' if huge else ''})"


def _positive(value: str) -> int:
    n = int(value)
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {value}")
    return n


def _positive_or_auto(value: str) -> int | str:
    if value == "auto":
        return value
    return _positive(value)


def _non_negative(value: str) -> int:
    n = int(value)
    if n < 0:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0, got {value}")
    return n


def _positive_float(value: str) -> float:
    x = float(value)
    if not x > 0:
        raise argparse.ArgumentTypeError(f"must be a number > 0, got {value}")
    return x


def _subframes(value: str) -> int:
    n = int(value)
    if n < 1 and n != -1:
        raise argparse.ArgumentTypeError(f"must be -1 (the default) or a positive integer, got {value}")
    return n


def _fraction(value: str) -> float:
    x = float(value)
    if not x >= 0:
        raise argparse.ArgumentTypeError(f"must be a number >= 0, got {value}")
    return x


EPILOG = ("exit codes: 0 success, 1 error (one line and a hint; --debug shows the traceback), 2 bad command "
          "line, 130 interrupted (Ctrl-C). See docs/cli.md.")


def _add_pbr_kernel(command: argparse.ArgumentParser) -> None:
    """``--pbr-kernel``: the setting /graphsdg/render/pbrKernel for this command (graphsdg.render.pbr_kernel)."""
    command.add_argument("--pbr-kernel", choices=("compact", "inlined"),
                         help="how the pbr backend's render kernel is built: compact (compiles about four times "
                              "faster) or inlined (mujoco-warp-pbr's own build); a kernel cache warmed with one "
                              "holds nothing for the other (default: the setting /graphsdg/render/pbrKernel, "
                              "compact)")


def build_parser() -> argparse.ArgumentParser:
    """The ``graphsdg`` argument parser (every command has ``--help``)."""
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help="show the traceback of an error")
    parser = argparse.ArgumentParser(prog="graphsdg", description="Synthetic data generation on MuJoCo + OpenUSD",
                                     epilog=EPILOG)
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    demo = sub.add_parser("demo", parents=[common], help="write a small dataset of the built-in demo scene",
                          description="Writes rgb, semantic segmentation, tight 2D boxes and depth of the "
                                      "built-in demo scene with BasicWriter.", epilog=EPILOG)
    demo.add_argument("--out", default="_out_demo", help="output directory (default: _out_demo)")
    demo.add_argument("--frames", type=_positive, default=10, help="frames to capture (default: 10)")
    demo.add_argument("--resolution", type=_positive, nargs=2, default=(512, 512), metavar=("W", "H"))
    demo.add_argument("--seed", type=int, default=0)
    _add_pbr_kernel(demo)
    bench = sub.add_parser(
        "bench", parents=[common], help="Isaac Sim's SDG benchmark scene vs a hand-written MuJoCo loop",
        description="Times Isaac Sim's benchmark_sdg.py scene (cube, cone, cylinder, sphere and torus assets with "
                    "random poses, scales and colours every frame, a distant and a dome light) captured by "
                    "graphsdg, then a hand-written MuJoCo loop over the same compiled model in the same process, "
                    "and prints a Markdown table (docs/performance.md says what is measured; bench/scaling.py "
                    "sweeps asset counts and resolutions).", epilog=EPILOG)
    bench.add_argument("--num-frames", type=_positive, default=600,
                       help="timed frames of each run, after the warm-up (default: 600)")
    bench.add_argument("--seconds", type=_positive_float,
                       help="time each run for about this many seconds: fewer than --num-frames frames when the "
                            "warm-up's rate says so, at least 20; with --processes every process stops at the same "
                            "deadline, this many seconds after they start together (default: always --num-frames)")
    bench.add_argument("--warmup", type=_non_negative, default=10,
                       help="untimed frames captured first, so compiling and first uploads are not timed "
                            "(default: 10)")
    bench.add_argument("--num-cameras", type=_positive, default=1,
                       help="cameras, each with its own render product, all randomized every frame (default: 1)")
    bench.add_argument("--resolution", type=_positive, nargs=2, default=(1280, 720), metavar=("W", "H"),
                       help="width and height of every render product in pixels (default: 1280 720)")
    bench.add_argument("--asset-count", type=_positive, default=10,
                       help="assets of each of the 5 shapes, so the scene holds 5 times this many "
                            "(default: 10, i.e. 50 assets)")
    bench.add_argument("--annotators", nargs="+", default=["rgb"],
                       help="annotators to capture, by their benchmark_sdg.py names, or 'all' (default: rgb)")
    bench.add_argument("--skip-write", action="store_true",
                       help="compute the annotators' data but write no files")
    bench.add_argument("--rt-subframes", type=_subframes, default=-1,
                       help="jittered renders averaged per frame (anti-aliasing), -1 for the default of 1")
    bench.add_argument("--wait-for-render", action="store_true",
                       help="finish each frame inside its step (off by default, as in benchmark_sdg.py: steps "
                            "are pipelined)")
    bench.add_argument("--no-replicator-write-to-fabric", action="store_true",
                       help="write randomized poses and colours to USD and sync them, instead of straight into "
                            "MuJoCo (Isaac Sim 6's write-to-fabric, on by default)")
    bench.add_argument("--write-threads", type=_positive,
                       help="writer threads per process, shared by both loops; graphsdg starts them as its backlog needs "
                            "(default: 4 on 16 cores or more, "
                            "a quarter of the cores below, at least 1; with --processes each process's share)")
    bench.add_argument("--write-processes", type=_count_or_auto, metavar="N",
                       help="graphsdg's writer processes per process, which encode and write its image, array "
                            "and JSON files outside the interpreter lock: a count, 0 for writer threads only, or "
                            "auto: /graphsdg/io/writeProcesses (default: the setting, auto: as many as writer "
                            "threads, when 2 or more, on 4 cores or more)")
    bench.add_argument("--temp-dir", type=_folder,
                       help="folder in which each run makes its output folder and removes it afterwards: it "
                            "picks the file system the frames are written to, e.g. /dev/shm for memory "
                            "(default: the system's temporary folder)")
    bench.add_argument("--msaa", type=_non_negative,
                       help="multisample count of the colour pass, 0 for none (default: graphsdg's 4)")
    bench.add_argument("--shadow-size", type=_positive,
                       help="shadow map size in texels (default: graphsdg's 1024)")
    bench.add_argument("--backend", choices=("classic", "pbr", "auto"),
                       help="graphsdg's renderer: the OpenGL rasteriser (classic), the GPU ray tracer (pbr) or "
                            "pbr where it can run (auto); the hand-written loop always rasterises (default: the "
                            "setting /graphsdg/render/backend, auto)")
    bench.add_argument("--rendermode", choices=("RaytracedLighting", "PathTracing"),
                       help="Isaac's /rtx/rendermode: on pbr the real-time or the path-traced tier, on classic "
                            "PathTracing raises the quality (default: the setting, RaytracedLighting)")
    bench.add_argument("--spp", type=_positive,
                       help="path-traced samples per pixel of one launch, /rtx/pathtracing/spp (default: the larger of "
                            "the settings spp and totalSpp)")
    _add_pbr_kernel(bench)
    bench.add_argument("--png-on-device", action="store_true",
                       help="on pbr, compress each frame's colour PNG on the GPU and colour and compress its class "
                            "masks there, /graphsdg/render/pbrPngOnDevice (graphsdg.render.device_png: less CPU a "
                            "written frame, larger files)")
    bench.add_argument("--pbr-batch-pixels", type=_non_negative, metavar="N",
                       help="on pbr, draw a step's render products in one launch while their pixels add up to at "
                            "most N, 0 for a launch per product: /graphsdg/render/pbrBatchPixels (default: the "
                            "setting, 2097152: eight 512x512 products)")
    bench.add_argument("--processes", type=_non_negative, default=0,
                       help="run this many graphsdg processes at once and report their aggregate frames/s, "
                            "images/s (frames times cameras) and the cores they kept busy (no hand-written "
                            "loop); 0 runs one process with the loop (default: 0)")
    bench.add_argument("--gpus", type=_positive, nargs="+", metavar="K",
                       help="spread the processes over the first K GPUs this process sees (each process's CUDA and "
                            "EGL device the same GPU) and add a row per GPU; several counts (e.g. 1 2 4) run one "
                            "after the other and end with a scaling table (no hand-written loop)")
    bench.add_argument("--processes-per-gpu", type=_positive, metavar="N",
                       help="with --gpus: N processes on each GPU (default: --processes spread over the GPUs, or "
                            "the cores' share of each GPU, at most 16 under CUDA MPS and 8 without)")
    bench.add_argument("--bind-cores", nargs="?", const="on", default="auto", choices=("auto", "on", "off"),
                       help="with --gpus: bind each GPU's processes to that GPU's share of the cores (its NUMA-local "
                            "cores where the host lists them, split evenly among the GPUs near them); on (the flag "
                            "alone): at every GPU count, the same share whatever the count, so --gpus 1 2 4 scales "
                            "GPUs and cores together; auto: with more than one GPU (one GPU's processes may run on "
                            "every core); off: never (default: auto)")
    bench.add_argument("--mps", choices=MPS_MODES, default="auto",
                       help="with --processes or --gpus: CUDA MPS for the processes that share a GPU, so their "
                            "kernels run side by side (auto: when a GPU has several processes and the host has "
                            "nvidia-cuda-mps-control; on: required; off; default: auto)")
    bench.add_argument("--no-baseline", action="store_true", help="skip the hand-written MuJoCo loop")
    bench.add_argument("--rounds", type=_positive, default=1,
                       help="run graphsdg and the hand-written loop this many times each, alternately, in one "
                            "process; the table adds the medians, the ratio being the median of the rounds' "
                            "ratios, so a machine whose speed drifts between runs weighs on both; with --gpus, the "
                            "GPU counts take turns this many times and the scaling table takes each count's median "
                            "run (default: 1)")
    bench.add_argument("--profile", action="store_true",
                       help="also print milliseconds per frame of each phase (randomize, render passes, "
                            "annotators, writing) for both runs")
    bench.add_argument("--report", metavar="MD", help="append the printed tables to this Markdown file")
    warmup = sub.add_parser("warmup", parents=[common],
                            help="compile the pbr backend's kernels into this node's cache ahead of a job",
                            description="Renders one small frame of each scene with the pbr backend so that its "
                                        "Warp kernels are compiled into the node's kernel cache "
                                        "(GRAPHSDG_KERNEL_CACHE, else Warp's): a job's first frame then loads "
                                        "them. --arch also compiles them for a GPU architecture, without a GPU "
                                        "(with --device cpu), e.g. while building a container image. "
                                        "docs/performance.md has the cold-start numbers.", epilog=EPILOG)
    warmup.add_argument("--scenes", nargs="+", default=["demo", "bench"], choices=["demo", "bench"],
                        help="scenes to render one frame of (default: demo bench)")
    warmup.add_argument("--resolution", type=_positive, nargs=2, default=(64, 64), metavar=("W", "H"),
                        help="their size; the kernels do not depend on it (default: 64 64)")
    warmup.add_argument("--arch", type=_positive, nargs="+", default=[], metavar="SM",
                        help="also compile every kernel the frames launched for these CUDA architectures "
                             "(90: H100, H200), which needs no GPU")
    warmup.add_argument("--device", help="Warp device to render the frames on: cuda:N (default: the setting "
                                         "/graphsdg/render/pbrDevice, cuda:0) or cpu (no GPU; slow)")
    _add_pbr_kernel(warmup)
    run = sub.add_parser("run", parents=[common],
                         help="run a graphsdg (or, with --compat isaac, an Isaac Sim Replicator) script",
                         usage="graphsdg run SCRIPT [options] [-- SCRIPT_ARGS ...]",
                         description="Runs SCRIPT as __main__ and prints a summary (frames, files, bytes, "
                                     "wall time, frames/s). --workers shards orchestrator.run(num_frames) over "
                                     "Ray processes and merges their output; --resume continues an interrupted "
                                     "run. Everything after -- goes to the script's sys.argv.", epilog=EPILOG)
    run.add_argument("script")
    run.add_argument("--compat", choices=["isaac"], help="provide Isaac Sim's module names to the script")
    run.add_argument("--seed", type=int, help="global seed (unless the script sets its own)")
    run.add_argument("--out", help="root for the script's relative output directories")
    run.add_argument("--frames", type=_positive, help="frames for orchestrator.run() calls without num_frames")
    run.add_argument("--resolution-scale", type=float, metavar="F",
                     help="scale every render product's resolution by F (e.g. 0.125 for a quick, small run)")
    run.add_argument("--workers", type=_positive_or_auto, metavar="K",
                     help="shard the run over K Ray worker processes and merge their output (needs --out; "
                          "pip install 'graphsdg[ray]'); auto: the cores' share of workers on every GPU (at most 8 "
                          "a GPU), one a core without GPUs")
    run.add_argument("--gpus", type=_positive, metavar="K",
                     help="with --workers: use K GPUs (default: every GPU of this machine, or of the cluster with "
                          "--address); more than there are is an error")
    run.add_argument("--address", help="join this Ray cluster (e.g. ray://host:10001 or auto) instead of "
                                       "starting a local one")
    run.add_argument("--gpus-per-worker", type=_fraction, metavar="F",
                     help="GPUs per worker, may be a fraction (default: 1/ceil(workers/GPUs), so the workers fill "
                          "every GPU; 1 with fewer workers than GPUs; 0 without GPUs)")
    run.add_argument("--mps", choices=MPS_MODES, default="auto",
                     help="with --workers on this machine: CUDA MPS for the workers that share a GPU, so their "
                          "kernels run side by side (auto: when a GPU has several workers and the host has "
                          "nvidia-cuda-mps-control; on: required; off; default: auto)")
    run.add_argument("--bind-cores", choices=("auto", "off"), default="auto",
                     help="with --workers: auto binds each worker given one GPU of a machine with several to that "
                          "GPU's share of the machine's cores (its NUMA-local cores where the machine lists them, "
                          "split evenly among the GPUs near them), so a GPU's workers share its cores; off lets "
                          "every worker run on every core (default: auto)")
    run.add_argument("--resume", action="store_true",
                     help="continue an interrupted run: frames complete on disk are kept, the rest are captured")
    folder = sub.add_parser("run-folder", parents=[common],
                            help="run every script of a folder, one process each; one verdict line per script",
                            usage="graphsdg run-folder FOLDER [options] [-- SCRIPT_ARGS ...]",
                            description="Runs each FOLDER/*.py with 'graphsdg run' in its own process and "
                                        "working folder (OUT/<name>/). A script passes when it exits 0, prints "
                                        "no '[Test][FAIL]' line and, if its source prints [SDG][Test][PASS], "
                                        "prints it. Prints one line per script (verdict, seconds, reason) and "
                                        "'N passed, M failed'; exit 1 if any failed.", epilog=EPILOG)
    folder.add_argument("folder")
    folder.add_argument("--compat", choices=["isaac"], help="provide Isaac Sim's module names to the scripts")
    folder.add_argument("--out", help="folder for the scripts' working folders (default: a new temporary one)")
    folder.add_argument("--pattern", default="*.py", help="which files to run (default: *.py)")
    folder.add_argument("--timeout", type=float, default=600.0, help="seconds per script (default 600)")
    folder.add_argument("--resolution-scale", type=float, metavar="F",
                        help="scale every render product's resolution by F in every script")
    view = sub.add_parser("view", parents=[common],
                          help="contact sheet, gallery page or Rerun recording of a dataset, with statistics",
                          description="Draws boxes, class names and masks over the frames of a BasicWriter, "
                                      "COCO, KITTI or YOLO dataset (detected from its files) into a contact "
                                      "sheet PNG and prints per-class counts, empty frames and box sizes; "
                                      "--html adds a gallery page, --rerun logs every frame to Rerun instead.",
                          epilog=EPILOG)
    view.add_argument("dir")
    view.add_argument("--html", action="store_true",
                      help="also write a gallery page (index.html): statistics tables, every frame with toggles "
                           "for boxes, masks and labels, a class filter, depth beside the image")
    view.add_argument("--rerun", nargs="?", const="", metavar="OUT.rrd",
                      help="log every frame to a Rerun recording (default DIR.rrd); 'spawn' opens a Rerun "
                           "viewer, a rerun+http://... URL streams to a running one (pip install "
                           "'graphsdg[viewer]')")
    view.add_argument("--max", type=_positive,
                      help="frames to show (default: 16 in the contact sheet, every frame in the gallery and "
                           "the recording)")
    view.add_argument("--page-size", type=_positive, default=48, help="frames per gallery page (default 48)")
    view.add_argument("--out", help="output folder (default: DIR.view next to the dataset)")
    graph = sub.add_parser("graph", parents=[common],
                           help="build a script's node graph without running it; print and draw it",
                           usage="graphsdg graph SCRIPT [options] [-- SCRIPT_ARGS ...]",
                           description="Runs SCRIPT until its first orchestrator capture call (run, step, "
                                       "preview), which stops it: nothing is rendered or written. Prints the "
                                       "graph and writes it as DOT, JSON and a PNG drawing.", epilog=EPILOG)
    graph.add_argument("script")
    graph.add_argument("--compat", choices=["isaac"], help="provide Isaac Sim's module names to the script")
    graph.add_argument("--seed", type=int, help="global seed (values sampled while building)")
    graph.add_argument("--print", choices=["text", "dot", "json"], default="text",
                       help="what to print (default: text)")
    graph.add_argument("--out", help="folder for SCRIPT.graph.{dot,json,png} (default: current folder)")
    graph.add_argument("--dot", metavar="PATH", help="DOT file path")
    graph.add_argument("--json", metavar="PATH", help="JSON file path")
    graph.add_argument("--png", metavar="PATH", help="PNG drawing path")
    validate = sub.add_parser("validate", parents=[common],
                              help="check a dataset's consistency; exit 1 on any violation",
                              description="Checks a BasicWriter dataset: complete frames, boxes inside the image "
                                          "and around their masks, ids that agree, finite depth on objects, "
                                          "empty and duplicate frames. Exit code 1 if anything is violated.",
                              epilog=EPILOG)
    validate.add_argument("dir")
    return parser


FRAME_LOOPS = ("demo", "run", "run-folder", "bench")     # commands whose steady state makes and drops frames


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``graphsdg`` console script; returns the exit code."""
    parser = build_parser()
    from_console = argv is None      # a process of its own (a library caller keeps its allocator as it is)
    argv = list(sys.argv[1:] if argv is None else argv)
    script_args: list[str] = []
    if "--" in argv:   # everything after "--" belongs to the script (graphsdg run SCRIPT ... -- ARGS)
        cut = argv.index("--")
        argv, script_args = argv[:cut], argv[cut + 1:]
    args = parser.parse_args(argv)
    if from_console and args.command in FRAME_LOOPS:
        from graphsdg.base.heap import keep_freed_buffers_here_and_in_children
        keep_freed_buffers_here_and_in_children()   # each frame's megabyte buffers, made and dropped
    if getattr(args, "pbr_kernel", None) is not None and args.command != "bench":   # bench's processes set it
        from graphsdg.base import settings_store
        settings_store.set("/graphsdg/render/pbrKernel", args.pbr_kernel)
    try:
        if args.command == "demo":
            summary = run_demo(args.out, args.frames, tuple(args.resolution), args.seed)
            print(f"wrote {summary['frames']} frames to {summary['output_dir']} in {summary['seconds']:.1f} s")
        elif args.command == "run":
            return run_job_command(args, script_args)
        elif args.command == "graph":
            return run_graph(args, script_args)
        elif args.command == "run-folder":
            return run_folder_command(args, script_args)
        elif args.command == "bench":
            run_bench(args)
        elif args.command == "warmup":
            from graphsdg.jobs.warmup import warm_up
            done = warm_up(tuple(args.scenes), tuple(args.resolution), tuple(args.arch), args.device)
            print(f"warmed {', '.join(f'{k} ({v} s)' for k, v in done['scenes'].items())} in {done['seconds']} s: "
                  f"{done['compiled']} module(s) compiled, {done['cached']} found cached"
                  + (f", {done['compiled ahead']} CUBIN(s) for sm_{'/'.join(map(str, done['archs']))}"
                     if done["archs"] else "") + f"; cache {done['cache']}")
        elif args.command == "view":
            return run_view(args)
        elif args.command == "validate":
            from graphsdg.dataset.validate import validate
            violations = validate(args.dir)
            for v in violations:
                print(v)
            print(f"{len(violations)} violation(s) in {args.dir}")
            return 1 if violations else 0
        return 0
    except SystemExit:
        raise
    except KeyboardInterrupt:
        if args.debug:
            raise
        hint = " (rerun with --resume to continue)" if args.command == "run" else ""
        print(f"graphsdg: interrupted{hint}", file=sys.stderr)
        return 130
    except Exception as exc:  # one clear line unless --debug
        if args.debug:
            raise
        message = " ".join(str(exc).split()) or type(exc).__name__
        print(f"graphsdg: error: {message}", file=sys.stderr)
        print(f"hint: {_hint(exc)}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
