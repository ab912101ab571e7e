# Read semantic segmentation straight from an annotator and colourize it with rep.tools (blog-post style).
import json

from isaacsim import SimulationApp

simulation_app = SimulationApp({"headless": True})

import numpy as np
import omni.replicator.core as rep

rep.create.cube(position=(0, 0, 0), scale=1.0, semantics=[("class", "cube")])
rep.create.light(light_type="dome", intensity=1000)
camera = rep.create.camera(position=(0, 0, 5), look_at=(0, 0, 0))
rp = rep.create.render_product(camera, (256, 256))

seg = rep.AnnotatorRegistry.get_annotator("semantic_segmentation", init_params={"colorize": False})
seg.attach(rp)
rep.orchestrator.step()

out = seg.get_data()
image, palette, ids = rep.tools.colorize_segmentation(out["data"], out["info"]["idToLabels"])
colours = {tuple(int(c) for c in px) for px in image.reshape(-1, 4)}
cube_colours = [c for c, labels in palette.items() if isinstance(labels, dict) and labels.get("class") == "cube"]
print("SEGMENTATION", json.dumps({"colours": len(colours), "cube_pixels": int(np.all(image == np.array(cube_colours[0]),
                                                                                      axis=-1).sum()),
                                  "shape": list(image.shape)}))
simulation_app.close()
