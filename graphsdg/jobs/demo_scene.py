"""The built-in demo scene of ``graphsdg demo`` and ``graphsdg warmup``. A floor, ten shapes, a camera.

Example:
    >>> import tempfile
    >>> summary = run_demo(tempfile.mkdtemp(), 1, (32, 32), 0)
    >>> summary["frames"]
    1
"""
from __future__ import annotations

import time

#: what ``graphsdg demo`` writes: BasicWriter's flags
DEMO_ANNOTATORS = {"rgb": True, "semantic_segmentation": True, "bounding_box_2d_tight": True,
                   "distance_to_image_plane": True}


def run_demo(out: str, frames: int, resolution: tuple[int, int], seed: int,
             annotators: dict[str, bool] | None = None) -> dict:
    """Build the demo scene, capture ``frames`` randomized frames into ``out``; return a summary.

    ``annotators``: BasicWriter's flags (default :data:`DEMO_ANNOTATORS`).
    """
    import graphsdg as rep

    start = time.perf_counter()
    rep.stage.new_stage()
    rep.set_global_seed(seed)
    rng = rep.rng.ReplicatorRNG(seed=seed)
    rep.orchestrator.set_capture_on_play(False)
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=450, parent="/World", name="Sky")
    rep.functional.create.distant_light(intensity=900, parent="/World", name="Sun", rotation=(35, 20, 0))
    floor = rep.functional.create.plane(parent="/World", name="Floor", scale=(8, 8, 1),
                                        semantics={"class": "floor"})
    rep.functional.modify.display_color(floor, (0.45, 0.42, 0.38))
    shapes = []
    for kind in ("cube", "sphere", "cylinder", "cone", "torus"):
        shapes += getattr(rep.functional.create_batch, kind)(count=2, parent="/World", name=kind.capitalize(),
                                                             semantics={"class": kind})
    cam = rep.functional.create.camera(position=(4.5, -4.5, 3.5), look_at=(0, 0, 0.3), parent="/World",
                                       name="Camera")
    rp = rep.create.render_product(cam, resolution, name="demo")
    writer = rep.writers.get("BasicWriter")
    writer.initialize(output_dir=out, **(DEMO_ANNOTATORS if annotators is None else annotators))
    writer.attach(rp)
    n = len(shapes)
    for _ in range(frames):
        xy = rng.generator.uniform(-1.8, 1.8, size=(n, 2))
        scale = rng.generator.uniform(0.4, 0.9, size=(n, 1)).repeat(3, 1)
        position = [(x, y, s[2] / 2) for (x, y), s in zip(xy, scale)]
        rotation = [(0.0, 0.0, a) for a in rng.generator.uniform(0, 360, size=n)]
        rep.functional.modify.pose(shapes, position_value=position, rotation_value=rotation, scale_value=scale)
        rep.functional.randomizer.display_color(shapes, rng=rng)
        rep.orchestrator.step()
    rep.orchestrator.wait_until_complete()
    writer.detach()
    rp.destroy()
    return {"frames": frames, "output_dir": writer.output_dir, "seconds": time.perf_counter() - start}
