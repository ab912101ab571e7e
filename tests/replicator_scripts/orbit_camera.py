# Turntable capture: the camera orbits a labelled mug at a fixed radius (pose_orbit), always aimed at it.
import asyncio

import omni.replicator.core as rep
from isaacsim.storage.native import get_assets_root_path

MUG = get_assets_root_path() + "/Isaac/Props/YCB/Axis_Aligned/025_mug.usd"

with rep.new_layer():
    mug = rep.create.from_usd(MUG, semantics=[("class", "mug")])
    rep.create.light(light_type="dome", intensity=1200)
    cam = rep.create.camera()
    rp = rep.create.render_product(cam, (320, 320))
    with rep.trigger.on_frame(max_execs=4):
        with cam:
            rep.modify.pose_orbit(barycentre=(0, 0, 0.05), distance=0.6,
                                  azimuth=rep.distribution.sequence([0, 90, 180, 270]), elevation=30)
    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_orbit", bounding_box_2d_tight=True)
    writer.attach([rp])


async def main():
    await rep.orchestrator.run_async()


asyncio.ensure_future(main())
