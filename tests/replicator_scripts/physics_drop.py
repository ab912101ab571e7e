# Drop test: a rigid box falls onto a static floor; the script steps the app and reports where it rests.
from isaacsim import SimulationApp

simulation_app = SimulationApp({"headless": True})

import omni.replicator.core as rep
import omni.timeline
import omni.usd

with rep.new_layer():
    floor = rep.create.cube(position=(0, 0, -0.05), scale=(4, 4, 0.1), semantics=[("class", "floor")])
    box = rep.create.cube(position=(0, 0, 1.0), scale=0.4, semantics=[("class", "box")])
    with floor:
        rep.physics.collider()
    with box:
        rep.physics.collider()
        rep.physics.rigid_body(velocity=(0, 0, 0))
        rep.physics.mass(mass=2.0)

timeline = omni.timeline.get_timeline_interface()
timeline.play()
for _ in range(120):
    simulation_app.update()
timeline.pause()

stage = omni.usd.get_context().get_stage()
prim = box.get_output_prims()["prims"][0]
from pxr import UsdGeom

z = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(0).ExtractTranslation()[2]
print(f"BOX_REST_Z {z:.4f}")
simulation_app.close()
