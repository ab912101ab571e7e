# Cycle through sample assets with instantiate + a sequence distribution (Replicator docs test pattern).
import omni.replicator.core as rep

assets = rep.utils.get_usd_files(rep.example.ASSETS_DIR, path_filter="(cracker_box|mug)")

with rep.new_layer():
    rep.create.light(light_type="dome", intensity=1000)
    camera = rep.create.camera(position=(0, -0.8, 0.4), look_at=(0, 0, 0.05))
    rp = rep.create.render_product(camera, (400, 400))
    with rep.trigger.on_frame(max_execs=2):
        with rep.randomizer.instantiate(rep.distribution.sequence(assets), size=1, mode="reference"):
            rep.modify.semantics([("class", "object")])
    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_instances", bounding_box_2d_tight=True)
    writer.attach([rp])

rep.orchestrator.run()
print("ASSETS", [a.rsplit("/", 1)[-1] for a in assets])
