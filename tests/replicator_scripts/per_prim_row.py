# Three boxes in a row, each given its own position at creation, with per-frame lift from a sequence of
# per-prim heights (one height per box) and a seeded log-uniform size.
import omni.replicator.core as rep

HEIGHTS = [(0.0, 0.5, 1.0), (1.0, 0.5, 0.0)]

rep.set_global_seed(5)
with rep.new_layer():
    boxes = rep.create.cube(count=3, position=[(-2, 0, 0), (0, 0, 0), (2, 0, 0)], scale=0.5,
                            semantics=[("class", "box")])
    rep.create.light(light_type="distant", rotation=(-60, 0, 30), intensity=2500)
    cam = rep.create.camera(position=(0, -10, 0.5), look_at=(0, 0, 0.5))
    rp = rep.create.render_product(cam, (960, 540))
    with rep.trigger.on_frame(max_execs=len(HEIGHTS)):
        with boxes:
            rep.modify.pose(position_z=rep.distribution.sequence(HEIGHTS),
                            scale=rep.distribution.log_uniform(0.3, 0.6))
    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_row", bounding_box_2d_tight=True)
    writer.attach([rp])

rep.orchestrator.run()
