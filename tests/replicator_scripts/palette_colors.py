# Each sphere takes one colour of a fixed palette every frame (randomizer.color with a list of colours).
import omni.replicator.core as rep

with rep.new_layer():
    balls = rep.create.sphere(count=3, position=[(-1.2, 0, 0), (0, 0, 0), (1.2, 0, 0)], scale=0.5,
                              semantics=[("class", "ball")])
    rep.create.light(light_type="dome", intensity=1500)
    cam = rep.create.camera(position=(0, 0, 6), look_at=(0, 0, 0))
    rp = rep.create.render_product(cam, (640, 640))
    with rep.trigger.on_frame(max_execs=2):
        with balls:
            rep.randomizer.color(colors=[(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)])
    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_palette", rgb=True)
    writer.attach([rp])

rep.orchestrator.run()
