"""Event-triggered data capture: timeline and simulation.

Port of Isaac Sim's ``sdg_getting_started_04.py`` (the standalone form). A cube
and a sphere fall under physics; each time the cube has dropped another 0.5 m
the script captures a frame, then captures again with the cube hidden, with
``delta_time=0.0`` so the simulation does not advance between the two. Isaac-only
lines map to graphsdg as follows:

===============================================  ==============================================
Isaac Sim                                        graphsdg
===============================================  ==============================================
``import omni.replicator.core as rep``           ``import graphsdg as rep``
``simulation_app.update()``                      ``rep.orchestrator.update()``
``omni.timeline.get_timeline_interface()``       ``rep.timeline.get_timeline_interface()``
``omni.usd.get_context().new_stage()``           ``rep.stage.new_stage()``
``isaacsim.core.experimental.prims.RigidPrim``   ``graphsdg.physics.bodies.RigidBodyView``
``get_world_poses(...)[0].numpy()``              ``get_world_poses(...)[0]`` (already numpy)
===============================================  ==============================================

Run: ``python examples/getting_started_04.py [--resolution 256 256]``.
"""
import argparse
import os

from pxr import UsdGeom

import graphsdg as rep
from graphsdg.physics.bodies import RigidBodyView


def run_example(out_dir=None, resolution=(512, 512)):
    """Run the example; returns one record per capture: (step, simulated time, cube height, cube visible)."""
    # Create a new stage and disable capture on play
    rep.stage.new_stage()
    rep.orchestrator.set_capture_on_play(False)

    # Add a light
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=500, parent="/World", name="DomeLight")

    # Create a cube with colliders and rigid body dynamics at a specific location
    cube = rep.functional.create.cube(name="Cube", parent="/World")
    rep.functional.modify.position(cube, (0, 0, 2))
    rep.functional.modify.semantics(cube, {"class": "my_cube"}, mode="add")
    rep.functional.physics.apply_rigid_body(cube, with_collider=True)

    # Create a sphere with colliders and rigid body dynamics next to the cube
    sphere = rep.functional.create.sphere(name="Sphere", parent="/World")
    rep.functional.modify.position(sphere, (-1, -1, 2))
    rep.functional.modify.semantics(sphere, {"class": "my_sphere"}, mode="add")
    rep.functional.physics.apply_rigid_body(sphere, with_collider=True)

    # Create a render product using the viewport perspective camera
    cam = rep.functional.create.camera(position=(5, 5, 5), look_at=(0, 0, 0), parent="/World", name="Camera")
    rp = rep.create.render_product(cam, resolution)

    # Write data using the basic writer with the rgb and semantic segmentation annotators
    backend = rep.backends.get("DiskBackend")
    out_dir = out_dir or os.path.join(os.getcwd(), "_out_basic_writer_sim")
    backend.initialize(output_dir=out_dir)
    print(f"Output directory: {out_dir}")
    writer = rep.writers.get("BasicWriter")
    writer.initialize(backend=backend, rgb=True, semantic_segmentation=True, colorize_semantic_segmentation=True)
    writer.attach(rp)

    # Start the timeline (will only advance with app update)
    timeline = rep.timeline.get_timeline_interface()
    timeline.play()

    # Wrap the cube as a rigid-body view for easy access to its world poses and velocities
    cube_rigid = RigidBodyView(str(cube.GetPrimPath()))

    # Wrap the cube as an Imageable object to toggle visibility during capture
    cube_imageable = UsdGeom.Imageable(cube)

    # Define the capture interval in meters
    capture_interval_meters = 0.5
    cube_pos = cube_rigid.get_world_poses(indices=[0])[0]
    previous_capture_height = cube_pos[0, 2]
    captures = []

    # Update the app which will advance the timeline (and implicitly the simulation)
    for i in range(100):
        rep.orchestrator.update()
        cube_pos = cube_rigid.get_world_poses(indices=[0])[0]
        current_height = cube_pos[0, 2]
        distance_dropped = previous_capture_height - current_height
        print(f"Step {i}; cube height: {current_height:.3f}; drop since last capture: {distance_dropped:.3f}")

        # Stop the simulation if the cube falls below the ground
        if current_height < 0:
            print(f"\t Cube fell below the ground at height {current_height:.3f}, stopping simulation..")
            break

        # Capture every time the cube drops by the threshold distance
        if distance_dropped >= capture_interval_meters:
            print(f"\t Capturing at height {current_height:.3f}")
            previous_capture_height = current_height

            # Setting delta_time to 0.0 will make sure the timeline is not advanced during capture
            rep.orchestrator.step(delta_time=0.0)
            captures.append((i, timeline.get_current_time(), float(cube_rigid.get_world_poses()[0][0, 2]), True))

            # Capture again with the cube hidden
            print("\t Capturing with cube hidden")
            cube_imageable.MakeInvisible()
            rep.orchestrator.step(delta_time=0.0)
            captures.append((i, timeline.get_current_time(), float(cube_rigid.get_world_poses()[0][0, 2]), False))
            cube_imageable.MakeVisible()

            # Resume the timeline to continue the simulation
            timeline.play()

    # Pause the simulation
    timeline.pause()

    # Wait for the data to be written to disk and clean up resources
    rep.orchestrator.wait_until_complete()
    writer.detach()
    rp.destroy()
    return captures


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolution", type=int, nargs=2, default=(512, 512), metavar=("W", "H"))
    parser.add_argument("--out-dir", default=None)
    args = parser.parse_args()
    run_example(args.out_dir, tuple(args.resolution))
