"""Data Capture: BasicWriter (Isaac Sim's sdg_getting_started_01.py, standalone form).

Two edits from the original: ``import graphsdg as rep`` for the Replicator
import, and graphsdg's stage/settings modules for ``omni.usd`` and
``carb.settings``. Writes rgb_000N.png and bounding_box_2d_tight_000N.npy with
their _labels_ and _prim_paths_ JSON files to ./_out_basic_writer.
"""
import os

import graphsdg as rep
from graphsdg import settings, stage


def run_example():
    # Create a new stage and disable capture on play
    stage.new_stage()
    rep.orchestrator.set_capture_on_play(False)

    # Set DLSS to Quality mode (2) for best SDG results (no effect on graphsdg's rasteriser)
    settings.set("rtx/post/dlss/execMode", 2)

    # Setup the stage with a dome light and a cube
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=500, parent="/World", name="DomeLight")
    cube = rep.functional.create.cube(parent="/World", name="Cube")
    rep.functional.modify.semantics(cube, {"class": "my_cube"}, mode="add")

    # Create a render product using the viewport perspective camera
    cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0), parent="/World", name="Camera")
    rp = rep.create.render_product(cam, (512, 512), name="MyRenderProduct")

    # Write data using the basic writer with the rgb and bounding box annotators
    backend = rep.backends.get("DiskBackend")
    out_dir = os.path.join(os.getcwd(), "_out_basic_writer")
    backend.initialize(output_dir=out_dir)
    print(f"Output directory: {out_dir}")
    writer = rep.writers.get("BasicWriter")
    writer.initialize(backend=backend, rgb=True, bounding_box_2d_tight=True)
    writer.attach(rp)

    # Trigger a data capture request (data will be written to disk by the writer)
    for i in range(3):
        print(f"Step {i}")
        rep.orchestrator.step()

    # Wait for the data to be written to disk and clean up resources
    rep.orchestrator.wait_until_complete()
    writer.detach()
    rp.destroy()


if __name__ == "__main__":
    run_example()
