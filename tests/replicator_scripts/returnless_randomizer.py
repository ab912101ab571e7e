# A registered randomizer with no return statement (common in project code): it moves the
# prims found by semantics along a fixed path, one stop per frame.
import omni.replicator.core as rep

STOPS = [(-1.0, 0.0, 0.5), (0.0, 0.0, 0.5), (1.0, 0.0, 0.5)]

with rep.new_layer():
    rep.create.cube(semantics=[("class", "crate")], position=(0, 0, 0.5), scale=0.5)
    rep.create.plane(scale=5)
    rep.create.light(light_type="dome", intensity=800)
    cam = rep.create.camera(position=(0, -6, 3), look_at=(0, 0, 0.5))
    rp = rep.create.render_product(cam, (512, 512))

    def move_crates():
        crates = rep.get.prims(semantics=[("class", "crate")])
        with crates:
            rep.modify.pose(position=rep.distribution.sequence(STOPS))

    rep.randomizer.register(move_crates)
    with rep.trigger.on_frame(max_execs=len(STOPS)):
        rep.randomizer.move_crates()

    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_returnless", bounding_box_2d_tight=True)
    writer.attach([rp])

rep.orchestrator.run()
