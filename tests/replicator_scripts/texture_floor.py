# Domain randomization of a floor texture with Replicator's sample textures, standalone (Isaac Sim 2023.1 style).
from omni.isaac.kit import SimulationApp

simulation_app = SimulationApp({"headless": True})

import omni.replicator.core as rep

with rep.new_layer():
    floor = rep.create.plane(scale=4, semantics=[("class", "floor")])
    rep.create.light(light_type="dome", intensity=1000)
    cam = rep.create.camera(position=(0, 0, 6), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (512, 512))

    def random_floor():
        with floor:
            rep.randomizer.texture(textures=rep.example.TEXTURES, texture_rotate=rep.distribution.uniform(0, 90))
        return floor.node

    rep.randomizer.register(random_floor)
    with rep.trigger.on_frame(num_frames=3):
        rep.randomizer.random_floor()

    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_texture_floor", rgb=True)
    writer.attach([rp])

rep.orchestrator.run_until_complete()
simulation_app.close()
