# "Light randomization" from a course notebook: a registered randomizer that returns its lights' node.
import omni.replicator.core as rep

with rep.new_layer():
    plane = rep.create.plane(scale=10, visible=True, semantics=[("class", "floor")])
    sphere = rep.create.sphere(semantics=[("class", "sphere")], position=(0, 0, 100), scale=2)
    camera = rep.create.camera(position=(0, -900, 600), look_at=(0, 0, 0))
    rp = rep.create.render_product(camera, (640, 480))

    def sphere_lights(num):
        lights = rep.create.light(
            light_type="Sphere",
            temperature=rep.distribution.normal(6500, 500),
            intensity=rep.distribution.normal(35000, 5000),
            position=rep.distribution.uniform((-300, -300, 200), (300, 300, 400)),
            scale=rep.distribution.uniform(50, 100),
            count=num,
        )
        return lights.node

    rep.randomizer.register(sphere_lights)

    with rep.trigger.on_frame(num_frames=3):
        rep.randomizer.sphere_lights(4)

    writer = rep.WriterRegistry.get("BasicWriter")
    writer.initialize(output_dir="_out_lights", rgb=True)
    writer.attach([rp])

rep.orchestrator.run()

import omni.usd

stage = omni.usd.get_context().get_stage()
lights = [p for p in stage.Traverse() if p.GetTypeName() == "SphereLight"]
print("SPHERE_LIGHTS", len(lights), sorted(round(p.GetAttribute("inputs:intensity").Get()) for p in lights))
