"""Several views per launch or one at a time: does batching worlds pay for mujoco-warp-pbr? (issue 19, item 6)

Run on a machine with an NVIDIA GPU and ``graphsdg[gpu]`` (Python >= 3.12):
``MUJOCO_GL=egl python3 bench/pbr_batching.py [--size 512] [--views 1 4 16] [--repeats 20]``.

Renders the ``graphsdg bench`` scene (5 shapes x ``--assets`` assets, its lights) with the real-time tier.
Every view has its own camera pose and its own random asset poses, as N frames of one model or N render
products of one stage would. Each measurement renders N views two ways and reads back what annotators read
(colour, depth and segmentation, to host arrays):

* ``one at a time``: a render context of one world; per view, its poses are uploaded, the scene BVH
  refit, one launch, one readback (what ``graphsdg.render.pbr`` does for each render product today);
* ``batched``: a context of N worlds; the N views' poses uploaded at once, one refit, one launch, one
  readback.

Prints a Markdown table of ms per view for each N, the speedup, and the CPU ms the main thread spent per
view in each way (the host is CPU-bound, docs/rendering.md, so that column decides as much as wall time).
"""
from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

import graphsdg as rep
from graphsdg.benchmark import throughput
from graphsdg.maths.rotations import look_at_matrix
from graphsdg.render.pbr import ENABLED_GROUPS
from graphsdg.engine.runtime import runtime
from graphsdg.sim.visual import PBR_CAMERA


def random_states(model: mujoco.MjModel, data: mujoco.MjData, count: int, rng: np.random.Generator):
    """``count`` scene states: geom poses after random mocap poses (as the bench randomizes), camera poses
    on the bench's [5, 10]^3 box looking at the origin."""
    xpos, xmat, cam_pos, cam_mat = [], [], [], []
    saved_pos, saved_quat = data.mocap_pos.copy(), data.mocap_quat.copy()
    for _ in range(count):
        data.mocap_pos[:] = rng.uniform(-3, 3, data.mocap_pos.shape)
        quat = rng.normal(size=data.mocap_quat.shape)
        data.mocap_quat[:] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
        mujoco.mj_kinematics(model, data)
        xpos.append(data.geom_xpos.astype(np.float32))
        xmat.append(data.geom_xmat.reshape(-1, 3, 3).astype(np.float32))
        eye = rng.uniform(5, 10, 3)
        cam_pos.append(eye.astype(np.float32))
        cam_mat.append(look_at_matrix(eye, (0.0, 0.0, 0.0)).astype(np.float32))
    data.mocap_pos[:], data.mocap_quat[:] = saved_pos, saved_quat
    mujoco.mj_kinematics(model, data)
    return np.stack(xpos), np.stack(xmat), np.stack(cam_pos), np.stack(cam_mat)


class Views:
    """One render context of ``nworld`` worlds over the compiled bench model."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, nworld: int, size: int, device: str) -> None:
        import mujoco_warp as mjw
        import mujoco_warp_pbr as mjpbr
        import warp as wp
        self.wp, self.mjw, self.mjpbr = wp, mjw, mjpbr
        self.camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, PBR_CAMERA)
        self.nworld = nworld
        with wp.ScopedDevice(device):
            self.m = mjw.put_model(model)
            self.d = mjw.put_data(model, data, nworld=nworld)
            self.rc = mjpbr.create_render_context(
                model, nworld=nworld, cam_res=[(size, size)], render_rgb=True, render_depth=True, render_seg=True,
                enabled_geom_groups=ENABLED_GROUPS, cam_active=[i == self.camera for i in range(model.ncam)],
                light_model=mjpbr.LightModel.PHYSICAL, tone_mapper=mjpbr.ToneMapper.CLAMP,
                tier=mjpbr.Tier.REALTIME)
        self.device = device
        self.ncam = model.ncam

    def render(self, states, first: int, seed: int) -> list[np.ndarray]:
        """Upload views ``first .. first + nworld - 1`` of ``states``, refit, launch once, read back."""
        xpos, xmat, cam_pos, cam_mat = (s[first:first + self.nworld] for s in states)
        wp, d = self.wp, self.d
        with wp.ScopedDevice(self.device):
            d.geom_xpos.assign(xpos)
            d.geom_xmat.assign(xmat)
            cams_pos = np.zeros((self.nworld, self.ncam, 3), dtype=np.float32)
            cams_mat = np.tile(np.eye(3, dtype=np.float32), (self.nworld, self.ncam, 1, 1))
            cams_pos[:, self.camera], cams_mat[:, self.camera] = cam_pos, cam_mat
            d.cam_xpos.assign(cams_pos)
            d.cam_xmat.assign(cams_mat)
            self.mjw.refit_bvh(self.m, d, self.rc.base)
            self.mjpbr.render(self.m, d, self.rc, seed=seed)
            base = self.rc.base
            return [base.rgb_data.numpy(), base.depth_data.numpy(), base.seg_data.numpy()]


def measure(views: Views, states, count: int, repeats: int) -> tuple[float, float]:
    """(wall ms, main-thread CPU ms) per view of rendering ``count`` views ``repeats`` times."""
    views.render(states, 0, 0)                      # warm-up: kernels loaded, buffers touched
    wall, cpu = time.perf_counter(), time.thread_time()
    for r in range(repeats):
        for first in range(0, count, views.nworld):
            views.render(states, first, r)
    n = repeats * count
    return 1e3 * (time.perf_counter() - wall) / n, 1e3 * (time.thread_time() - cpu) / n


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512, help="square render size in pixels (default 512)")
    parser.add_argument("--views", type=int, nargs="+", default=[1, 4, 16], help="views per measurement")
    parser.add_argument("--assets", type=int, default=10, help="assets of each of the 5 shapes (default 10)")
    parser.add_argument("--repeats", type=int, default=20, help="measurements averaged (default 20)")
    parser.add_argument("--device", default="cuda:0", help="Warp device (cpu for a smoke test)")
    args = parser.parse_args()
    rep.settings.set("/graphsdg/render/backend", "pbr")
    rep.settings.set("/graphsdg/render/pbrDevice", args.device)
    throughput.build_scene(throughput.BenchConfig(asset_count=args.assets, resolution=(args.size, args.size)))
    sim = runtime().sim
    model, data = sim.model, sim.data
    states = random_states(model, data, max(args.views), np.random.default_rng(7))
    single = Views(model, data, 1, args.size, args.device)
    print(f"### pbr real-time tier, {args.size}x{args.size}, {model.ngeom} geoms, colour + depth + segmentation "
          f"read back, {args.repeats} repeats\n")
    print("| views | one at a time, ms/view | batched, ms/view | speedup | CPU ms/view, one at a time | "
          "CPU ms/view, batched |")
    print("|---|---|---|---|---|---|")
    for count in args.views:
        one_wall, one_cpu = measure(single, states, count, args.repeats)
        batch = single if count == 1 else Views(model, data, count, args.size, args.device)
        many_wall, many_cpu = measure(batch, states, count, args.repeats)
        print(f"| {count} | {one_wall:.3f} | {many_wall:.3f} | {one_wall / many_wall:.2f} | {one_cpu:.3f} | "
              f"{many_cpu:.3f} |")


if __name__ == "__main__":
    main()
