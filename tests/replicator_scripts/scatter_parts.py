# Parts scattered on a tray seen from above (project code, Isaac Sim 4.x standalone).
from isaacsim import SimulationApp

simulation_app = SimulationApp({"headless": True})

import omni.replicator.core as rep

rep.set_global_seed(11)
with rep.new_layer():
    tray = rep.create.plane(scale=(2, 2, 1), position=(0, 0, 0), visible=True)
    parts = rep.create.cube(count=5, scale=0.15, semantics=[("class", "part")])
    rep.create.light(light_type="dome", intensity=900)
    top = rep.create.camera(position=(0, 0, 8), look_at=(0, 0, 0))
    rp = rep.create.render_product(top, (640, 640))

    with rep.trigger.on_frame(max_execs=3):
        with parts:
            rep.randomizer.scatter_2d(surface_prims=tray, check_for_collisions=True)
            rep.modify.pose(rotation=rep.distribution.uniform((0, 0, -180), (0, 0, 180)))

    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_scatter", bounding_box_2d_tight=True)
    writer.attach(rp)

for _ in range(3):
    rep.orchestrator.step()
rep.orchestrator.wait_until_complete()
simulation_app.close()
