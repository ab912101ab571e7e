# Toggle which of three objects is shown, one pattern per frame (each tuple: one flag per prim).
import omni.replicator.core as rep

PATTERNS = [(True, False, True), (False, True, False), (True, True, False)]

with rep.new_layer():
    a = rep.create.cube(semantics=[("class", "a")], position=(-1.5, 0, 0.5), scale=0.6)
    b = rep.create.sphere(semantics=[("class", "b")], position=(0, 0, 0.5), scale=0.6)
    c = rep.create.cone(semantics=[("class", "c")], position=(1.5, 0, 0.5), scale=0.6)
    rep.create.light(light_type="distant", rotation=(-45, 0, 0), intensity=2000)
    camera = rep.create.camera(position=(0, -7, 2), look_at=(0, 0, 0.5))
    rp = rep.create.render_product(camera, (800, 600))

    with rep.trigger.on_frame(max_execs=len(PATTERNS)):
        with rep.create.group([a, b, c]):
            rep.modify.visibility(rep.distribution.sequence(PATTERNS))

    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_visibility", bounding_box_2d_tight=True)
    writer.attach([rp])

rep.orchestrator.run()
