# Random shapes dataset, pasted into the Script Editor (Replicator 1.x tutorial style).
# Three labelled shapes jump around in front of a fixed camera; BasicWriter saves RGB and tight 2D boxes.
import omni.replicator.core as rep

with rep.new_layer():
    camera = rep.create.camera(position=(0, 0, 1000))
    render_product = rep.create.render_product(camera, (1024, 1024))

    torus = rep.create.torus(semantics=[("class", "torus")], position=(0, -200, 100))
    sphere = rep.create.sphere(semantics=[("class", "sphere")], position=(0, 100, 100))
    cube = rep.create.cube(semantics=[("class", "cube")], position=(100, -200, 100))
    light = rep.create.light(light_type="distant", rotation=(315, 0, 0), intensity=3000)

    with rep.trigger.on_frame(num_frames=4):
        with rep.create.group([torus, sphere, cube]):
            rep.modify.pose(
                position=rep.distribution.uniform((-150, -150, 0), (150, 150, 100)),
                scale=rep.distribution.uniform(50, 80),
            )

    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_shapes", rgb=True, bounding_box_2d_tight=True)
    writer.attach([render_product])

rep.orchestrator.run()
