# Standalone generation driven the way forum answers show it: start the orchestrator, then keep updating the
# app while it starts and while it runs (Isaac Sim 2022.2 module names).
from omni.isaac.kit import SimulationApp

kit = SimulationApp({"headless": True, "renderer": "RayTracedLighting"})

import omni.replicator.core as rep


def generate():
    rep.orchestrator.run()
    while not rep.orchestrator.get_is_started():
        kit.update()
    while rep.orchestrator.get_is_started():
        kit.update()
    rep.BackendDispatch.wait_until_done()
    rep.orchestrator.stop()


with rep.new_layer():
    cam = rep.create.camera(position=(0, 0, 1000))
    rp = rep.create.render_product(cam, (1024, 1024))
    crate = rep.create.cube(semantics=[("class", "crate")], position=(0, 0, 100), scale=150)
    rep.create.light(light_type="distant", intensity=3000)
    with rep.trigger.on_frame(num_frames=3):
        with crate:
            rep.modify.pose(rotation=rep.distribution.uniform((0, 0, 0), (360, 360, 360)))
    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_polling", rgb=True, bounding_box_2d_tight=True)
    writer.attach([rp])

generate()
print("STATUS", rep.orchestrator.get_status(), rep.orchestrator.get_is_started(), rep.orchestrator.get_is_stopped())
kit.close()
