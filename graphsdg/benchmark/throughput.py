"""The SDG throughput benchmark: Isaac Sim's ``benchmark_sdg.py`` scene, and the floor to beat.

Scene (Isaac Sim 6.0's benchmark, rebuilt): ``asset_count`` each of cube, cone,
cylinder, sphere and torus (1 m primitives, ``class=<shape>``), a distant light
(2000) and a dome light (400), no floor; per frame every asset gets a uniform
position in [-3, 3]^3, Euler rotation in [0, 360)^3, one uniform scale in
[0.1, 1] and a random display colour, and every camera a position in [5, 10]^3
looking at the origin. ``frames`` timed captures follow ``warmup`` untimed ones.

The *hand-written loop* is what a user would write with MuJoCo alone over the
same compiled model: set the arrays, ``mujoco.Renderer`` colour / depth /
segmentation renders per camera, tight boxes from the ids, and PNG/NPY writes
with OpenCV on a thread pool of the same size. Both run in one process, one
after the other, and the report gives their ratio.

Example:
    >>> from graphsdg.benchmark.throughput import BenchConfig, run_graphsdg
    >>> result = run_graphsdg(BenchConfig(frames=2, warmup=1, asset_count=1, resolution=(64, 48),
    ...                                   skip_write=True))
    >>> result.frames
    2
"""
from __future__ import annotations

import collections
import concurrent.futures
import dataclasses
import math
import os
import resource
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np

from graphsdg.base import cpu_share

SHAPES = ("cube", "cone", "cylinder", "sphere", "torus")
# benchmark_sdg.py annotator names -> BasicWriter flags
ANNOTATOR_FLAGS = {
    "rgb": "rgb", "bounding_box_2d_tight_fast": "bounding_box_2d_tight",
    "bounding_box_2d_tight": "bounding_box_2d_tight", "bounding_box_2d_loose_fast": "bounding_box_2d_loose",
    "bounding_box_2d_loose": "bounding_box_2d_loose", "semantic_segmentation": "semantic_segmentation",
    "instance_id_segmentation_fast": "instance_id_segmentation",
    "instance_id_segmentation": "instance_id_segmentation",
    "instance_segmentation_fast": "instance_segmentation", "instance_segmentation": "instance_segmentation",
    "distance_to_camera": "distance_to_camera", "distance_to_image_plane": "distance_to_image_plane",
    "bounding_box_3d_fast": "bounding_box_3d", "bounding_box_3d": "bounding_box_3d", "occlusion": "occlusion",
    "normals": "normals", "motion_vectors": "motion_vectors", "camera_params": "camera_params",
    "pointcloud": "pointcloud",
}


@dataclass
class BenchConfig:
    """The benchmark's knobs, mirroring ``benchmark_sdg.py`` flags."""

    frames: int = 600
    warmup: int = 10
    num_cameras: int = 1
    resolution: tuple[int, int] = (1280, 720)
    asset_count: int = 10
    annotators: tuple[str, ...] = ("rgb",)
    skip_write: bool = False
    rt_subframes: int = -1
    wait_for_render: bool = False       # benchmark_sdg.py's default: pipelined steps
    write_to_fabric: bool = True
    seed: int = 11
    out_dir: str | None = None           # keep the frames here (graphsdg's; the loop's in its "hand-written" folder)
    write_threads: int | None = None     # None: write_queue.default_threads(), or with --processes their share
    msaa_samples: int | None = None      # None: graphsdg's default (/graphsdg/render/msaaSamples)
    shadow_size: int | None = None       # None: graphsdg's default (/graphsdg/render/shadowSize)
    image_threads: int | None = None     # OpenCV's pool; None: its default, or with --processes each one's share
    render_backend: str | None = None    # /graphsdg/render/backend (classic, pbr, auto); None: the setting as it is
    render_mode: str | None = None       # /rtx/rendermode (RaytracedLighting, PathTracing); None: the setting as it is
    path_spp: int | None = None          # /rtx/pathtracing/spp of the path tier; None: the setting as it is
    pbr_batch_pixels: int | None = None  # /graphsdg/render/pbrBatchPixels (0: a launch per product); None: as set
    pbr_kernel: str | None = None        # /graphsdg/render/pbrKernel (compact, inlined); None: as set
    png_on_device: bool | None = None    # /graphsdg/render/pbrPngOnDevice; None: as set
    seconds: float | None = None         # time about this long: fewer than ``frames`` when the warm-up is slow (with
    #                                      a before_timing barrier, processes started together: until this deadline)
    write_processes: int | str | None = None   # /graphsdg/io/writeProcesses (a count, 0, auto); None: as set
    temp_dir: str | None = None          # where each run makes (and then removes) its output folder; None: the
    #                                      system's temporary folder. It picks the file system the frames go to.


MIN_TIMED_FRAMES = 20


def timed_frames(config: BenchConfig, warmup_times: list[float]) -> int:
    """Frames to time: ``config.frames``, or with ``config.seconds`` what the warm-up's rate (its second half:
    the first frames compile and upload) fits in those seconds, at least ``MIN_TIMED_FRAMES`` and at most
    ``config.frames``."""
    if config.seconds is None or not warmup_times:
        return config.frames
    recent = warmup_times[len(warmup_times) // 2:]
    per_frame = max(sum(recent) / len(recent), 1e-6)
    return max(min(config.frames, MIN_TIMED_FRAMES), min(config.frames, int(config.seconds / per_frame)))


@dataclass
class BenchResult:
    """Timing of one run."""

    label: str
    frames: int
    cameras: int
    frame_times: list[float] = field(default_factory=list)
    wall_seconds: float = 0.0
    drain_seconds: float = 0.0
    started_at: float = 0.0               # wall clock (time.time()) when the timed frames began
    cpu_seconds: float = 0.0              # process CPU time (all threads) over the timed frames and the drain
    system_seconds: float = 0.0           # the part of cpu_seconds spent in the kernel (system calls, faults)
    main_thread_seconds: float = 0.0      # the part of cpu_seconds the thread that steps the frames spent
    page_faults: int = 0                  # minor page faults over the same span (fresh pages the kernel mapped)
    peak_rss_mb: float = 0.0
    profile: dict[str, float] = field(default_factory=dict)

    @property
    def fps(self) -> float:
        return self.frames / self.wall_seconds if self.wall_seconds else 0.0

    @property
    def fps_with_drain(self) -> float:
        total = self.wall_seconds + self.drain_seconds
        return self.frames / total if total else 0.0

    @property
    def images_per_second(self) -> float:
        return self.fps * self.cameras

    def summary(self) -> dict[str, float | str]:
        ft = np.array(self.frame_times) * 1000 if self.frame_times else np.zeros(1)
        return {"run": self.label, "frames": self.frames, "frames/s": round(self.fps, 2), "images/s": round(self.images_per_second, 2),
                "frames/s incl. drain": round(self.fps_with_drain, 2), "min ms": round(float(ft.min()), 2),
                "mean ms": round(float(ft.mean()), 2), "max ms": round(float(ft.max()), 2),
                "CPU ms/frame": round(1000 * self.cpu_seconds / self.frames, 1) if self.frames else 0.0,
                "of which system ms": round(1000 * self.system_seconds / self.frames, 1) if self.frames else 0.0,
                "of which main thread ms": round(1000 * self.main_thread_seconds / self.frames, 1) if self.frames
                else 0.0,
                "page faults/frame": round(self.page_faults / self.frames) if self.frames else 0,
                "peak RSS MB": round(self.peak_rss_mb, 1)}


def _cpu_counters() -> np.ndarray:
    """(all CPU seconds, system CPU seconds, minor page faults) of this process (every thread) and of its
    running writer processes."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    own = np.array([usage.ru_utime + usage.ru_stime, usage.ru_stime, usage.ru_minflt])
    return own + _writer_processes_cpu_counters()


def _writer_processes_cpu_counters() -> np.ndarray:
    """(all CPU seconds, system CPU seconds, minor page faults) of this process's running writer processes."""
    from graphsdg.io.write_queue import current_write_queue
    queue = current_write_queue()
    total = np.zeros(3)
    for pid in queue.process_ids() if queue is not None else ():
        try:
            with open(f"/proc/{pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:            # it ended: its time is gone with it
            continue
        user, system = (int(v) / os.sysconf("SC_CLK_TCK") for v in fields[11:13])   # utime, stime
        total += (user + system, system, int(fields[7]))                             # minflt
    return total


def file_system_of(path: str, mounts: str = "/proc/mounts") -> str:
    """The type of the file system holding ``path`` (``ext4``, ``tmpfs``, ...), from ``mounts``; "unknown"
    where that cannot be read.

    Example:
        >>> file_system_of("/proc")
        'proc'
    """
    return _mount_of(path, mounts)[0]


def huge_pages_of(path: str, mounts: str = "/proc/mounts") -> str | None:
    """The ``huge=`` option of the tmpfs holding ``path`` (``always``, ``within_size``, ``advise``), or None where
    it is not a tmpfs or gives its files small pages only. A tmpfs with large pages allocates a written file's
    memory in far fewer pieces, which decides how fast many processes writing at once can go
    (docs/performance.md, "Four GPUs and the output file system")."""
    kind, options = _mount_of(path, mounts)
    huge = dict(o.partition("=")[::2] for o in options.split(",")).get("huge", "never")
    return huge if kind == "tmpfs" and huge not in ("never", "deny") else None


def _mount_of(path: str, mounts: str) -> tuple[str, str]:
    """(type, options) of the deepest mount in ``mounts`` holding ``path``; ("unknown", "") where unreadable."""
    try:
        with open(mounts) as f:
            rows = [line.split()[1:4] for line in f]
    except OSError:
        return "unknown", ""
    real = os.path.realpath(path)
    best, found = "", ("unknown", "")
    for point, fs, options in rows:
        point = point.replace("\\040", " ")
        inside = real == point or real.startswith(point.rstrip("/") + "/")
        if inside and len(point) >= len(best):
            best, found = point, (fs, options)
    return found


def _peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


class Randomization:
    """The per-frame draws, shared by both loops so they render the same frames."""

    def __init__(self, config: BenchConfig) -> None:
        self.n = config.asset_count * len(SHAPES)
        self.cameras = config.num_cameras
        self.rng = np.random.default_rng(config.seed)

    def draw(self) -> dict[str, np.ndarray]:
        g, n = self.rng, self.n
        return {"position": g.uniform(-3, 3, (n, 3)), "rotation": g.uniform(0, 360, (n, 3)),
                "scale": g.uniform(0.1, 1.0, (n, 1)).repeat(3, 1), "color": g.uniform(0, 1, (n, 3)),
                "camera": g.uniform(5, 10, (self.cameras, 3))}


def _write_threads(config: BenchConfig) -> int:
    """Writer threads of both loops: ``config.write_threads``, or one process's default for this machine's cores."""
    from graphsdg.io.write_queue import default_threads
    return default_threads() if config.write_threads is None else config.write_threads


def build_scene(config: BenchConfig):
    """The benchmark stage; returns (asset prims, camera prims, render products)."""
    import graphsdg as rep

    if config.msaa_samples is not None:
        rep.settings.set("/graphsdg/render/msaaSamples", int(config.msaa_samples))
    if config.shadow_size is not None:
        rep.settings.set("/graphsdg/render/shadowSize", int(config.shadow_size))
    if config.render_backend is not None:
        rep.settings.set("/graphsdg/render/backend", config.render_backend)
    if config.render_mode is not None:
        rep.settings.set("/rtx/rendermode", config.render_mode)
    if config.path_spp is not None:
        rep.settings.set("/rtx/pathtracing/spp", int(config.path_spp))
    if config.pbr_batch_pixels is not None:
        rep.settings.set("/graphsdg/render/pbrBatchPixels", int(config.pbr_batch_pixels))
    if config.pbr_kernel is not None:
        rep.settings.set("/graphsdg/render/pbrKernel", config.pbr_kernel)
    if config.png_on_device is not None:
        rep.settings.set("/graphsdg/render/pbrPngOnDevice", config.png_on_device)
    rep.stage.new_stage()
    rep.set_global_seed(config.seed)
    rep.orchestrator.set_capture_on_play(False)
    rep.settings.set("/exts/omni.replicator.core/enableWriteToFabric", config.write_to_fabric)
    rep.functional.create.xform(name="World")
    rep.functional.create.distant_light(intensity=2000, parent="/World", name="DistantLight", rotation=(315, 0, 0))
    rep.functional.create.dome_light(intensity=400, parent="/World", name="DomeLight")
    assets = []
    for shape in SHAPES:
        assets += getattr(rep.functional.create_batch, shape)(count=config.asset_count, parent="/World",
                                                               name=shape.capitalize(),
                                                               semantics={"class": shape})
    cams = [rep.functional.create.camera(position=(7.5, 7.5, 7.5), look_at=(0, 0, 0), parent="/World",
                                         name=f"Camera_{i}") for i in range(config.num_cameras)]
    rps = [rep.create.render_product(c, config.resolution, name=f"rp_{i}") for i, c in enumerate(cams)]
    return assets, cams, rps


def _apply(draw: dict[str, np.ndarray], assets, cams) -> None:
    import graphsdg as rep

    rep.functional.modify.pose(assets, position_value=draw["position"], rotation_value=draw["rotation"],
                               scale_value=draw["scale"])
    rep.functional.modify.display_color(assets, draw["color"])
    for cam, pos in zip(cams, draw["camera"]):
        rep.functional.modify.pose(cam, position_value=pos, look_at_value=(0.0, 0.0, 0.0),
                                   look_at_up_axis=(0.0, 0.0, 1.0))


def run_graphsdg(config: BenchConfig, before_timing=None) -> BenchResult:
    """Time graphsdg on the benchmark scene; ``before_timing()`` runs after the warm-up (a barrier, say)."""
    import graphsdg as rep
    from graphsdg.base import profiling
    from graphsdg.io.write_queue import reset_write_queue

    rep.settings.set("/omni/replicator/backend/writeThreads", _write_threads(config))
    if config.write_processes is not None:
        rep.settings.set("/graphsdg/io/writeProcesses", config.write_processes)
    reset_write_queue()
    if config.image_threads is not None:
        from graphsdg.base.cpu_share import limit_image_threads
        limit_image_threads(config.image_threads)
    assets, cams, rps = build_scene(config)
    flags = {ANNOTATOR_FLAGS[a]: True for a in config.annotators}
    tmp = None
    if config.skip_write:
        annotators = [rep.annotators.get(a) for a in config.annotators]
        for a in annotators:
            a.attach(rps)
        writer = None
    else:
        out = config.out_dir or (tmp := tempfile.mkdtemp(prefix="graphsdg_bench_", dir=config.temp_dir))
        writer = rep.writers.get("BasicWriter")
        writer.initialize(output_dir=out, **flags)
        writer.attach(rps)
    draws = Randomization(config)
    warmup_times = []
    for _ in range(config.warmup):
        t = time.perf_counter()
        _apply(draws.draw(), assets, cams)
        rep.orchestrator.step(rt_subframes=config.rt_subframes, wait_for_render=config.wait_for_render)
        warmup_times.append(time.perf_counter() - t)
    rep.orchestrator.wait_until_complete()
    # processes started together stop together: at the deadline (a frame count from each one's warm-up rate left
    # the processes whose warm-up ran while others still compiled straggling at the end of the window)
    together = before_timing is not None and config.seconds is not None
    frames = config.frames if together else timed_frames(config, warmup_times)
    if before_timing is not None:
        before_timing()
    rep.orchestrator.reset_profile()
    result = BenchResult(label="graphsdg", frames=0, cameras=config.num_cameras)
    result.started_at = time.time()
    cpu_start, main_start = _cpu_counters(), time.thread_time()
    start = last = time.perf_counter()
    deadline = start + config.seconds if together else math.inf
    while result.frames < frames and last < deadline:
        t = time.perf_counter()
        _apply(draws.draw(), assets, cams)
        profiling.add("randomize", time.perf_counter() - t)
        rep.orchestrator.step(rt_subframes=config.rt_subframes, wait_for_render=config.wait_for_render)
        now = time.perf_counter()
        result.frame_times.append(now - last)
        result.frames += 1
        last = now
    result.wall_seconds = time.perf_counter() - start
    t = time.perf_counter()
    rep.orchestrator.wait_until_complete()
    result.drain_seconds = time.perf_counter() - t
    result.cpu_seconds, result.system_seconds, result.page_faults = _cpu_counters() - cpu_start   # before the
    # queue's processes stop
    result.main_thread_seconds = time.thread_time() - main_start
    result.profile = rep.orchestrator.get_profile()
    result.peak_rss_mb = _peak_rss_mb()
    if writer is not None:
        writer.detach()
    for rp in rps:
        rp.destroy()
    if tmp:
        import shutil
        shutil.rmtree(tmp, ignore_errors=True)
    return result


def run_handwritten(config: BenchConfig) -> BenchResult:
    """Time the plain MuJoCo loop a user would write, over graphsdg's compiled model of the same scene."""
    import cv2
    import mujoco

    import graphsdg as rep  # noqa: F401  (EGL selection)
    from graphsdg.base import profiling
    from graphsdg.engine.runtime import runtime

    assets, cams, rps = build_scene(config)
    sim = runtime().sim
    model = sim.ensure_compiled().model
    data = sim.data
    geoms = [sim.compiled.geoms[str(p.GetPath())] for p in assets]
    mocap = np.array([g.mocap_id for g in geoms])
    geom_ids = np.array([g.geom_id for g in geoms])
    unit_size = model.geom_size[geom_ids].copy()
    is_mesh = np.array([g.type_name in ("Mesh", "Cone") for g in geoms])
    # MuJoCo draws a mesh at its compiled vertices: a scaled mesh (cone, torus) is drawn through its scene
    # geom's matrix scaled by s, with its offset from the body (geom_pos) scaled in the model
    mesh_geoms, mesh_rows = geom_ids[is_mesh], np.flatnonzero(is_mesh)
    unit_mesh_pos = model.geom_pos[mesh_geoms].copy()
    mesh_row_of = {int(g): int(k) for g, k in zip(mesh_geoms, mesh_rows)}
    geom_obj = int(mujoco.mjtObj.mjOBJ_GEOM)
    w, h = config.resolution
    model.vis.global_.offwidth, model.vis.global_.offheight = max(w, 64), max(h, 64)
    vfov = np.degrees(2 * np.arctan(20.955 / 24.0 / 2 * h / w))
    model.vis.global_.fovy = vfov
    # MuJoCo's own scene is sized 10,000 geoms by default: crowded benches (--asset-count 5000) need more
    max_geom = model.ngeom + 100
    renderer = mujoco.Renderer(model, h, w, max_geom=max_geom)
    # Depth and ids from a single-sample context of their own. mujoco.Renderer reads them out of its
    # multisampled buffer; MuJoCo turns multisampling off for id colours, which Mesa honours but
    # NVIDIA's driver does not: resolving blends neighbouring ids byte by byte into codes of a third
    # geom, or (256 geoms and more, two bytes a code) into codes beyond the scene, where the
    # renderer's own segid -> object table raised "index 502 is out of bounds for axis 0 with size
    # 501" at 500 assets (tests/test_id_range.py replays such a resolve).
    samples = int(model.vis.quality.offsamples)
    model.vis.quality.offsamples = 0
    try:
        id_renderer = mujoco.Renderer(model, h, w, max_geom=max_geom)
    finally:
        model.vis.quality.offsamples = samples
    want = set(config.annotators)
    need_depth = bool(want & {"distance_to_image_plane", "distance_to_camera"})
    need_seg = bool(want - {"rgb", "distance_to_image_plane", "distance_to_camera"})
    pool = concurrent.futures.ThreadPoolExecutor(_write_threads(config))
    if config.out_dir:
        tmp = os.path.join(config.out_dir, "hand-written")
        os.makedirs(tmp, exist_ok=True)
    else:
        tmp = tempfile.mkdtemp(prefix="mujoco_bench_", dir=config.temp_dir)
    pending: list[concurrent.futures.Future] = []
    draws = Randomization(config)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    labels = np.append(np.repeat(np.arange(len(SHAPES)), config.asset_count), -1)
    geom_to_asset = np.full(model.ngeom + 1, -1)
    geom_to_asset[geom_ids] = np.arange(len(assets))

    def write(path, payload):
        if path.endswith(".png"):
            ok, buf = cv2.imencode(".png", payload)
            open(path, "wb").write(buf.tobytes())
        else:
            np.save(path, payload)

    def scale_meshes(scene, scale):
        for g in scene.geoms[:scene.ngeom]:
            if g.objtype == geom_obj and g.objid in mesh_row_of:
                g.mat = g.mat * scale[mesh_row_of[g.objid]]

    def frame(draw, index):
        t0 = time.perf_counter()
        data.mocap_pos[mocap] = draw["position"]
        for mid, rot in zip(mocap, draw["rotation"]):
            quat = np.empty(4)
            mujoco.mju_euler2Quat(quat, np.radians(rot), "XYZ")
            data.mocap_quat[mid] = quat
        model.geom_size[geom_ids[~is_mesh]] = unit_size[~is_mesh] * draw["scale"][~is_mesh, :1]
        model.geom_pos[mesh_geoms] = unit_mesh_pos * draw["scale"][mesh_rows, :1]
        model.geom_rgba[geom_ids, :3] = draw["color"]
        mujoco.mj_kinematics(model, data)
        profiling.add("baseline:randomize", time.perf_counter() - t0)
        for c, pos in enumerate(draw["camera"]):
            d = np.linalg.norm(pos)
            cam.lookat[:] = 0
            cam.distance = d
            cam.azimuth = np.degrees(np.arctan2(pos[1], pos[0])) + 180
            cam.elevation = -np.degrees(np.arcsin(pos[2] / d))
            renderer.update_scene(data, cam)
            scale_meshes(renderer.scene, draw["scale"][:, 0])
            with profiling.timed("baseline:render:rgb"):
                rgb = renderer.render()
            if not config.skip_write:
                pending.append(pool.submit(write, f"{tmp}/rgb_{c}_{index}.png", rgb[..., ::-1].copy()))
            if need_depth or need_seg:
                id_renderer.update_scene(data, cam)
                scale_meshes(id_renderer.scene, draw["scale"][:, 0])
            if need_depth:
                id_renderer.enable_depth_rendering()
                with profiling.timed("baseline:render:depth"):
                    depth = id_renderer.render()
                id_renderer.disable_depth_rendering()
                if not config.skip_write:
                    pending.append(pool.submit(write, f"{tmp}/depth_{c}_{index}.npy", depth))
            if need_seg:
                id_renderer.enable_segmentation_rendering()
                with profiling.timed("baseline:render:segmentation"):
                    seg = id_renderer.render()
                t1 = time.perf_counter()
                id_renderer.disable_segmentation_rendering()
                ids = np.where(seg[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM), seg[..., 0], -1)
                inst = geom_to_asset[ids]
                flat = inst.ravel()
                sel = np.nonzero(flat >= 0)[0]
                ys, xs = np.divmod(sel, w)
                k = flat[sel]
                n = len(assets)
                boxes = np.stack([np.full(n, w), np.full(n, h), np.full(n, -1), np.full(n, -1)], 1)
                np.minimum.at(boxes[:, 0], k, xs)
                np.minimum.at(boxes[:, 1], k, ys)
                np.maximum.at(boxes[:, 2], k, xs)
                np.maximum.at(boxes[:, 3], k, ys)
                profiling.add("baseline:boxes", time.perf_counter() - t1)
                if not config.skip_write:
                    sem = (labels[inst] + 2).astype(np.uint16)
                    pending.append(pool.submit(write, f"{tmp}/seg_{c}_{index}.png", sem))
                    pending.append(pool.submit(write, f"{tmp}/boxes_{c}_{index}.npy", boxes))

    warmup_times = []
    for i in range(config.warmup):
        t = time.perf_counter()
        frame(draws.draw(), -1 - i)
        warmup_times.append(time.perf_counter() - t)
    concurrent.futures.wait(pending)
    frames = timed_frames(config, warmup_times)
    result = BenchResult(label="hand-written MuJoCo loop", frames=frames, cameras=config.num_cameras)
    pending.clear()
    profiling.reset()
    cpu_start, main_start = _cpu_counters(), time.thread_time()
    start = last = time.perf_counter()
    for i in range(frames):
        frame(draws.draw(), i)
        while len(pending) > 1000:          # the same bounded queue as graphsdg's writer pool
            pending.pop(0).result()
        now = time.perf_counter()
        result.frame_times.append(now - last)
        last = now
    result.wall_seconds = time.perf_counter() - start
    t = time.perf_counter()
    for f in pending:
        f.result()
    result.drain_seconds = time.perf_counter() - t
    result.cpu_seconds, result.system_seconds, result.page_faults = _cpu_counters() - cpu_start
    result.main_thread_seconds = time.thread_time() - main_start
    result.peak_rss_mb = _peak_rss_mb()
    result.profile = profiling.snapshot()
    pool.shutdown()
    renderer.close()
    id_renderer.close()
    if not config.out_dir:
        import shutil
        shutil.rmtree(tmp, ignore_errors=True)
    for rp in rps:
        rp.destroy()
    return result


def run_pair(config: BenchConfig) -> tuple[BenchResult, BenchResult]:
    """graphsdg, then the hand-written loop, in this process."""
    return run_graphsdg(config), run_handwritten(config)


def round_summaries(rounds: list[tuple[BenchResult, BenchResult | None]]) -> list[dict]:
    """The bench table's rows for ``rounds`` of (graphsdg, hand-written loop or None): each run's
    :meth:`BenchResult.summary` with its ratio to the loop of its own round, then, with several rounds, the
    median of every column per side (the ratio: the median of the rounds' ratios).

    Example:
        >>> g, h = BenchResult("graphsdg", 10, 1, wall_seconds=1.0), BenchResult("loop", 10, 1, wall_seconds=2.0)
        >>> [row["ratio to hand-written"] for row in round_summaries([(g, h)])]
        [2.0, 1.0]
    """
    several = len(rounds) > 1
    rows: list[dict] = []
    sides: dict[str, list[dict]] = {}
    for k, (ours, loop) in enumerate(rounds, 1):
        for result in (ours, loop):
            if result is None:
                continue
            row = result.summary()
            if loop is not None:
                ratio = ours.fps / loop.fps if loop.fps else float("nan")
                row["ratio to hand-written"] = round(ratio, 2) if result is ours else 1.0
            sides.setdefault(row["run"], []).append(row)
            if several:
                row["run"] = f"{row['run']} (round {k})"
            rows.append(row)
    if several:
        for label, runs in sides.items():
            median = {"run": f"{label} (median of {len(runs)})"}
            for key in runs[0]:
                if key != "run":
                    values = [r[key] for r in runs]
                    middle = round(float(np.median(values)), 2)
                    median[key] = int(middle) if all(isinstance(v, int) for v in values) and middle.is_integer() \
                        else middle
            rows.append(median)
    return rows


def _worker(config_dict: dict, before_timing=None) -> dict:
    """One benchmark process of :func:`run_processes`: its timing, the GPU it was given (None: any) and the cores
    it ran on."""
    config = BenchConfig(**config_dict)
    r = run_graphsdg(config, before_timing=before_timing)
    return {"frames": r.frames, "wall": r.wall_seconds, "start": r.started_at, "cpu": r.cpu_seconds,
            "system": r.system_seconds, "main_thread": r.main_thread_seconds, "page_faults": r.page_faults,
            "frame_ends": (r.started_at + np.cumsum(r.frame_times)).tolist(),
            "gpu": int(os.environ["GRAPHSDG_GPU"]) if os.environ.get("GRAPHSDG_GPU", "").isdigit() else None,
            "cuda_visible_devices": os.environ.get("CUDA_VISIBLE_DEVICES"),
            "egl_device": os.environ.get("MUJOCO_EGL_DEVICE_ID"),
            "cores": sorted(cpu_share.usable_core_set())}


def _steady_rate(results: list[dict]) -> float:
    """Frames/s of all processes together while every one of them was running (after the last
    start, before the first finish): the rate of a long job, without the start and end staggering."""
    lo = max(r["start"] for r in results)
    hi = min(r["start"] + r["wall"] for r in results)
    if hi <= lo:
        return float("nan")
    ends = [np.asarray(r["frame_ends"]) for r in results]
    done = sum(int(np.count_nonzero((e > lo) & (e <= hi))) for e in ends)
    return done / (hi - lo)


def run_processes(config: BenchConfig, processes: int) -> dict[str, float]:
    """``processes`` independent graphsdg benchmark processes at once (seeds differ); aggregate frames/s.

    Every process builds its scene and warms up, then all start their timed
    frames together (a barrier) and, with ``config.seconds``, stop together at
    that deadline. The aggregate is all frames over the window
    from the first start to the last finish, so a straggler counts against it;
    the steady rate counts only the frames finished while every process ran.
    """
    results, elapsed, config = launch_processes(config, processes)
    return summarize_processes(results, config, elapsed)


def launch_processes(config: BenchConfig, processes: int, environments: list[dict[str, str]] | None = None,
                     cores: list[list[int]] | None = None) -> tuple[list[dict], float, BenchConfig]:
    """Run ``processes`` benchmark processes (process i with seed + i, ``environments[i]`` added to its
    environment: its GPU, say, and bound to ``cores[i]`` where given); return their :func:`_worker` results,
    the seconds it all took, and the config they ran (the writer and OpenCV threads set to each one's share of
    the cores: of its bound cores among the processes bound to the same ones, else of this process's)."""
    from graphsdg.benchmark.process_launch import run_in_processes
    from graphsdg.io.write_queue import threads_per_process
    sharing, share_of = processes, None
    if cores is not None:      # the tightest share: the fewest cores a process of a bound set gets
        bound = collections.Counter(frozenset(c) for c in cores)    # core set -> processes bound to it
        share_of, sharing = min(((len(c), n) for c, n in bound.items()), key=lambda s: s[0] // s[1])
    if config.write_threads is None:   # as the CLI's scale-out does: the processes share the cores
        config = dataclasses.replace(config, write_threads=threads_per_process(sharing, share_of))
    if config.image_threads is None:
        config = dataclasses.replace(config, image_threads=cpu_share.cores_per_process(sharing, share_of))
    configs = [(dataclasses.asdict(dataclasses.replace(config, seed=config.seed + i)),) for i in range(processes)]
    start = time.perf_counter()
    results = run_in_processes(_worker, configs, environments or [{}] * processes, cores=cores)
    return results, time.perf_counter() - start, config


def summarize_processes(results: list[dict], config: BenchConfig, elapsed: float) -> dict[str, float]:
    """The table row of a ``--processes`` run from each process's ``_worker`` result.

    Besides frames/s: images/s (frames times cameras: a step of K cameras writes K annotated images) and
    the cores the processes kept busy over the common window (their CPU seconds over its length), which
    tells a CPU-bound host (close to the core count) from one held back elsewhere (the GPU, say).
    """
    from graphsdg.io.write_queue import processes_wanted
    per_process = [r["frames"] / r["wall"] for r in results]
    window = max(r["start"] + r["wall"] for r in results) - min(r["start"] for r in results)
    aggregate = sum(r["frames"] for r in results) / window
    cpu = sum(r["cpu"] for r in results)
    system = sum(r.get("system", 0.0) for r in results)
    main_thread = sum(r.get("main_thread", 0.0) for r in results)
    faults = sum(r.get("page_faults", 0) for r in results)
    frames = sum(r["frames"] for r in results)
    return {"processes": len(results),
            "aggregate frames/s (all frames / common window)": round(aggregate, 1),
            "steady frames/s (all processes running)": round(_steady_rate(results), 1),
            "images/s (aggregate x cameras)": round(aggregate * config.num_cameras, 1),
            "sum of per-process frames/s": round(sum(per_process), 1),
            "slowest process frames/s": round(min(per_process), 1),
            "CPU ms per frame (all threads)": round(1000 * cpu / frames, 1),
            "of which system (kernel) ms": round(1000 * system / frames, 1),
            "of which main threads ms": round(1000 * main_thread / frames, 1),
            "minor page faults per frame": round(faults / frames),
            "cores busy (CPU s / window s)": round(cpu / window, 1),
            "wall s (incl. start-up)": round(elapsed, 1),
            "cpu count": cpu_share.usable_cores(), "writer threads per process": config.write_threads,
            "writer processes per process": processes_wanted(
                "auto" if config.write_processes is None else config.write_processes, config.write_threads),
            "OpenCV threads per process": config.image_threads}


def format_table(rows: list[dict]) -> str:
    """A Markdown table of dict rows (same keys)."""
    cols = list(rows[0])
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(str(r[c]) for c in cols) + " |" for r in rows]
    return "\n".join(lines)
