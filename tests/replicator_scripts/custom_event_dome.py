# A dome light recoloured only when the script sends an event (Replicator's on_custom_event + send_og_event).
from isaacsim import SimulationApp

simulation_app = SimulationApp({"headless": True})

import omni.replicator.core as rep
import omni.usd

rep.create.cube(semantics=[("class", "cube")])
with rep.trigger.on_custom_event(event_name="recolour_dome"):
    dome = rep.create.light(light_type="Dome", color=rep.distribution.uniform((0, 0, 0), (1, 1, 1)))

stage = omni.usd.get_context().get_stage()
dome_prim = dome.get_output_prims()["prims"][0]
seen = []
for frame in range(4):
    if frame in (1, 3):
        rep.utils.send_og_event(event_name="recolour_dome")
    rep.orchestrator.step()
    seen.append(tuple(round(v, 5) for v in dome_prim.GetAttribute("inputs:color").Get()))
changes = [i for i in range(1, len(seen)) if seen[i] != seen[i - 1]]
print("DOME_CHANGES", changes)
simulation_app.close()
