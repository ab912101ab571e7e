"""Randomization in Simulation - UR10 Palletizing (Isaac Sim tutorial), ported to graphsdg's own API.

A UR10-style arm palletizes bins in a running MuJoCo simulation
(:mod:`graphsdg.scenarios.palletizing`); this script watches the bin the robot is
working on and, at two events, pauses the simulation, captures data and resumes:

* bin flip scenario (the bin touches the flip helper): the high-quality render
  mode, three randomized sphere lights and a camera walking four poses; rgb and
  colorized instance segmentation read from annotators and saved with Pillow;
* pallet scenario (the bin touches the pallet or a bin on it): the materials of
  the bins placed so far randomized every frame, the pallet's wood texture and
  the camera every 4th frame; 16 frames written by BasicWriter with 24 subframes.

Each capture builds its graph and render product, then removes them and puts the
original materials back, so the robot's work is exactly what it is without any
capture (``tests/test_palletizing.py`` checks this bit for bit).

The code follows the tutorial line by line. What changes with the imports:

==============================================================  ===========================================
Isaac Sim                                                        graphsdg
==============================================================  ===========================================
``omni.timeline.get_timeline_interface()`` + event stream        ``rep.timeline.get_timeline_interface()``,
                                                                 ``subscribe(callback, event_type)``
``get_physx_scene_query_interface().overlap_box(...)``           ``graphsdg.physics.queries.overlap_box(...)``
``isaacsim.core.utils.bounds.create_bbox_cache``                 ``graphsdg.sim.bounds.create_bbox_cache``
``omni.usd.get_world_transform_matrix``                          ``graphsdg.sim.transforms.get_world_transform_matrix``
``DeletePrimsCommand(paths=["/Replicator"])``                    ``rep.graph.clear()`` (also releases the graph)
``carb.settings.get_settings().set(...)``                        ``rep.settings.set(...)``
``get_assets_root_path()`` (Nucleus)                             ``graphsdg.assets.get_assets_root_path()``
``asyncio.ensure_future(self._run_..._scenario())``              the scenario runs from the app loop
                                                                 (:meth:`PalletizingSDGDemo.update`)
``BinStacking`` (isaacsim.examples.interactive)                  ``graphsdg.scenarios.palletizing.BinStacking``
==============================================================  ===========================================

The unchanged Isaac script runs too: ``graphsdg run --compat isaac <script>``.
Run this one with ``python examples/palletizing_sdg.py [output_dir]``.
"""
import json
import os
import random
import sys

import numpy as np
from PIL import Image
from pxr import UsdShade

import graphsdg as rep
from graphsdg.assets import get_assets_root_path
from graphsdg.scenarios.palletizing import BinStacking
from graphsdg.sim.bounds import create_bbox_cache
from graphsdg.physics.queries import overlap_box
from graphsdg.sim.timeline import TimelineEventType
from graphsdg.sim.transforms import get_world_transform_matrix


class PalletizingSDGDemo:
    BINS_FOLDER_PATH = "/World/Ur10Table/bins"
    FLIP_HELPER_PATH = "/World/Ur10Table/pallet_holder"
    PALLET_PRIM_MESH_PATH = "/World/Ur10Table/pallet/Xform/Mesh_015"
    BIN_FLIP_SCENARIO_FRAMES = 4
    PALLET_SCENARIO_FRAMES = 16

    def __init__(self, output_dir=None, resolution=(512, 512)):
        # There are 36 bins in total
        self._bin_counter = 0
        self._num_captures = 36
        self._stage = None
        self._active_bin = None
        # Simulation state flags
        self._in_running_state = False
        self._bin_flip_scenario_done = False
        # Used to pause/resume the simulation
        self._timeline = None
        # Used to actively track the active bins surroundings (e.g., in contact with pallet)
        self._timeline_sub = None
        self._overlap_extent = None
        # The capture the last tick asked for (Isaac schedules it with asyncio.ensure_future)
        self._due = None
        # SDG
        self._rep_camera = None
        self._resolution = resolution
        self._output_dir = output_dir or os.path.join(os.getcwd(), "_out_palletizing_sdg_demo", "")
        print(f"[PalletizingSDGDemo] Output directory: {self._output_dir}")

    def start(self, num_captures):
        self._num_captures = num_captures if 1 <= num_captures <= 36 else 36
        if self._init():
            self._start()

    def is_running(self):
        return self._in_running_state

    def update(self):
        """One app update: the capture a tick asked for, else one simulation frame."""
        if self._due is not None:
            scenario, self._due = self._due, None
            scenario()
        else:
            rep.orchestrator.update()

    def _init(self):
        self._stage = rep.stage.get_stage()
        self._active_bin = self._stage.GetPrimAtPath(f"{self.BINS_FOLDER_PATH}/bin_{self._bin_counter}")
        if not self._active_bin:
            print("[PalletizingSDGDemo] Could not find bin, make sure the palletizing demo is loaded..")
            return False
        bb_cache = create_bbox_cache()
        half_ext = bb_cache.ComputeLocalBound(self._active_bin).GetRange().GetSize() * 0.5
        self._overlap_extent = (half_ext[0], half_ext[1], half_ext[2] * 1.1)
        self._timeline = rep.timeline.get_timeline_interface()
        if not self._timeline.is_playing():
            print("[PalletizingSDGDemo] Please start the palletizing demo first..")
            return False
        # Disable capture on play for replicator, data capture will be triggered manually
        rep.orchestrator.set_capture_on_play(False)
        # Clear any previously generated SDG graphs
        if self._stage.GetPrimAtPath("/Replicator"):
            rep.graph.clear()
        return True

    def _start(self):
        self._timeline_sub = self._timeline.subscribe(self._on_timeline_event, TimelineEventType.CURRENT_TIME_TICKED)
        self._in_running_state = True
        print("[PalletizingSDGDemo] Starting the palletizing SDG demo..")

    def clear(self):
        if self._timeline_sub:
            self._timeline_sub.unsubscribe()
            self._timeline_sub = None
        self._in_running_state = False
        self._bin_counter = 0
        self._active_bin = None
        if self._stage.GetPrimAtPath("/Replicator"):
            rep.graph.clear()

    def _on_timeline_event(self, e):
        self._check_bin_overlaps()

    def _check_bin_overlaps(self):
        bin_pose = get_world_transform_matrix(self._active_bin)
        origin = bin_pose.ExtractTranslation()
        quat_gf = bin_pose.ExtractRotation().GetQuaternion()
        overlap_box(
            self._overlap_extent,
            (origin[0], origin[1], origin[2]),
            (quat_gf.GetImaginary()[0], quat_gf.GetImaginary()[1], quat_gf.GetImaginary()[2], quat_gf.GetReal()),
            self._on_overlap_hit,
            False,
        )

    def _on_overlap_hit(self, hit):
        if hit.rigid_body == self._active_bin.GetPrimPath():
            return True  # Self hit, return True to continue the query

        # First contact with the flip helper
        if hit.rigid_body.startswith(self.FLIP_HELPER_PATH) and not self._bin_flip_scenario_done:
            self._timeline.pause()
            self._timeline_sub.unsubscribe()
            self._timeline_sub = None
            self._due = self._run_bin_flip_scenario
            return False  # Relevant hit, return False to finish the hit query

        # Contact with the pallet or other bin on the pallet
        pallet_hit = hit.rigid_body.startswith(self.PALLET_PRIM_MESH_PATH)
        other_bin_hit = hit.rigid_body.startswith(f"{self.BINS_FOLDER_PATH}/bin_")
        if pallet_hit or other_bin_hit:
            self._timeline.pause()
            self._timeline_sub.unsubscribe()
            self._timeline_sub = None
            self._due = self._run_pallet_scenario
            return False  # Relevant hit, return False to finish the hit query

        return True  # No relevant hit, return True to continue the query

    def _switch_to_pathtracing(self):
        # graphsdg's best rasteriser settings: 8x MSAA, large shadow maps, totalSpp jittered subframes
        rep.settings.set("/rtx/rendermode", "PathTracing")
        rep.settings.set("/rtx/pathtracing/spp", 32)
        rep.settings.set("/rtx/pathtracing/totalSpp", 32)

    def _switch_to_raytracing(self):
        rep.settings.set("/rtx/rendermode", "RayTracedLighting")

    def _run_bin_flip_scenario(self):
        print(f"[PalletizingSDGDemo] Running bin flip scenario for bin {self._bin_counter}..")

        # Util function to save rgb images to file
        def save_img(rgb_data, filename):
            rgb_img = Image.fromarray(rgb_data).convert("RGBA")
            rgb_img.save(filename + ".png")

        self._switch_to_pathtracing()
        self._create_bin_flip_graph()

        rgb_annot = rep.AnnotatorRegistry.get_annotator("rgb")
        is_annot = rep.AnnotatorRegistry.get_annotator("instance_segmentation", init_params={"colorize": True})
        rp = rep.create.render_product(self._rep_camera, self._resolution)
        rgb_annot.attach(rp)
        is_annot.attach(rp)
        out_dir = os.path.join(self._output_dir, f"annot_bin_{self._bin_counter}", "")
        os.makedirs(out_dir, exist_ok=True)

        for i in range(self.BIN_FLIP_SCENARIO_FRAMES):
            rep.orchestrator.step(delta_time=0.0)

            rgb_data = rgb_annot.get_data()
            rgb_filename = f"{out_dir}rgb_{i}"
            save_img(rgb_data, rgb_filename)

            is_data = is_annot.get_data()
            is_filename = f"{out_dir}is_{i}"
            is_img_data = is_data["data"]
            height, width = is_img_data.shape[:2]
            is_img_data = is_img_data.view(np.uint8).reshape(height, width, -1)
            save_img(is_img_data, is_filename)
            is_info = is_data["info"]
            with open(f"{out_dir}is_info_{i}.json", "w") as f:
                json.dump(is_info, f, indent=4)

        # Free up resources
        rgb_annot.detach()
        is_annot.detach()
        rp.destroy()

        # Make sure the backend finishes writing the data before clearing the generated SDG graph
        rep.orchestrator.wait_until_complete()

        # Cleanup the generated SDG graph
        if self._stage.GetPrimAtPath("/Replicator"):
            rep.graph.clear()

        self._switch_to_raytracing()

        self._bin_flip_scenario_done = True
        self._timeline_sub = self._timeline.subscribe(self._on_timeline_event, TimelineEventType.CURRENT_TIME_TICKED)
        self._timeline.play()

    def _create_bin_flip_graph(self):
        # Create new random lights using the color palette for the color attribute
        color_palette = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]

        def randomize_bin_flip_lights():
            lights = rep.create.light(
                light_type="Sphere",
                temperature=rep.distribution.normal(6500, 2000),
                intensity=rep.distribution.normal(45000, 15000),
                position=rep.distribution.uniform((0.25, 0.25, 0.5), (1, 1, 0.75)),
                scale=rep.distribution.uniform(0.5, 0.8),
                color=rep.distribution.choice(color_palette),
                count=3,
            )
            return lights.node

        rep.randomizer.register(randomize_bin_flip_lights)

        # Move the camera to the given location sequences and look at the predefined location
        camera_positions = [(1.96, 0.72, -0.34), (1.48, 0.70, 0.90), (0.79, -0.86, 0.12), (-0.49, 1.47, 0.58)]

        self._rep_camera = rep.create.camera()
        with rep.trigger.on_frame():
            rep.randomizer.randomize_bin_flip_lights()
            with self._rep_camera:
                rep.modify.pose(position=rep.distribution.sequence(camera_positions), look_at=(0.78, 0.72, -0.1))

    def _run_pallet_scenario(self):
        print(f"[PalletizingSDGDemo] Running pallet scenario for bin {self._bin_counter}..")
        mesh_to_orig_mats = {}
        pallet_mesh = self._stage.GetPrimAtPath(self.PALLET_PRIM_MESH_PATH)
        pallet_orig_mat, _ = UsdShade.MaterialBindingAPI(pallet_mesh).ComputeBoundMaterial()
        mesh_to_orig_mats[pallet_mesh] = pallet_orig_mat
        for i in range(self._bin_counter + 1):
            bin_mesh = self._stage.GetPrimAtPath(f"{self.BINS_FOLDER_PATH}/bin_{i}/Visuals/FOF_Mesh_Magenta_Box")
            bin_orig_mat, _ = UsdShade.MaterialBindingAPI(bin_mesh).ComputeBoundMaterial()
            mesh_to_orig_mats[bin_mesh] = bin_orig_mat

        self._create_bin_and_pallet_graph()

        out_dir = os.path.join(self._output_dir, f"writer_bin_{self._bin_counter}", "")
        writer = rep.WriterRegistry.get("BasicWriter")
        # provenance (graphsdg's): what the graph sampled for each frame, next to the frame
        writer.initialize(output_dir=out_dir, rgb=True, instance_segmentation=True,
                          colorize_instance_segmentation=True, provenance=True)
        rp = rep.create.render_product(self._rep_camera, self._resolution)
        writer.attach(rp)
        for i in range(self.PALLET_SCENARIO_FRAMES):
            rep.orchestrator.step(rt_subframes=24, delta_time=0.0)

        # Free up resources after the capture
        writer.detach()
        rp.destroy()

        # Restore the original materials of the randomized meshes
        for mesh, mat in mesh_to_orig_mats.items():
            print(f"[PalletizingSDGDemo] Restoring original material({mat.GetPath()}) for {mesh.GetPath()}")
            UsdShade.MaterialBindingAPI(mesh).Bind(mat, UsdShade.Tokens.strongerThanDescendants)

        # Make sure the backend finishes writing the data before clearing the generated SDG graph
        rep.orchestrator.wait_until_complete()

        # Cleanup the generated SDG graph
        if self._stage.GetPrimAtPath("/Replicator"):
            rep.graph.clear()

        self._timeline.play()
        if self._next_bin():
            self._timeline_sub = self._timeline.subscribe(self._on_timeline_event,
                                                          TimelineEventType.CURRENT_TIME_TICKED)

    def _create_bin_and_pallet_graph(self):
        # Bin material randomization
        bin_paths = [
            f"{self.BINS_FOLDER_PATH}/bin_{i}/Visuals/FOF_Mesh_Magenta_Box" for i in range(self._bin_counter + 1)
        ]
        bins_node = rep.get.prim_at_path(bin_paths)

        with rep.trigger.on_frame():
            mats = rep.create.material_omnipbr(
                diffuse=rep.distribution.uniform((0.2, 0.1, 0.3), (0.6, 0.6, 0.7)),
                roughness=rep.distribution.choice([0.1, 0.9]),
                count=10,
            )
            with bins_node:
                rep.randomizer.materials(mats)

        # Camera and pallet texture randomization at a slower rate
        assets_root_path = get_assets_root_path()
        texture_paths = [
            assets_root_path + "/NVIDIA/Materials/Base/Wood/Oak/Oak_BaseColor.png",
            assets_root_path + "/NVIDIA/Materials/Base/Wood/Ash/Ash_BaseColor.png",
            assets_root_path + "/NVIDIA/Materials/Base/Wood/Plywood/Plywood_BaseColor.png",
            assets_root_path + "/NVIDIA/Materials/Base/Wood/Timber/Timber_BaseColor.png",
        ]
        pallet_node = rep.get.prim_at_path(self.PALLET_PRIM_MESH_PATH)
        pallet_prim = pallet_node.get_output_prims()["prims"][0]
        pallet_loc = get_world_transform_matrix(pallet_prim).ExtractTranslation()
        self._rep_camera = rep.create.camera()
        with rep.trigger.on_frame(interval=4):
            with pallet_node:
                rep.randomizer.texture(texture_paths, texture_rotate=rep.distribution.uniform(80, 95))
            with self._rep_camera:
                rep.modify.pose(
                    position=rep.distribution.uniform((0, -2, 1), (2, 1, 2)),
                    look_at=(pallet_loc[0], pallet_loc[1], pallet_loc[2]),
                )

    def _next_bin(self):
        self._bin_counter += 1
        if self._bin_counter >= self._num_captures:
            self.clear()
            print("[PalletizingSDGDemo] Palletizing SDG demo finished..")
            return False
        self._active_bin = self._stage.GetPrimAtPath(f"{self.BINS_FOLDER_PATH}/bin_{self._bin_counter}")
        print(f"[PalletizingSDGDemo] Moving to bin {self._bin_counter}..")
        self._bin_flip_scenario_done = False
        return True


NUM_CAPTURES = 12


def run_example(output_dir=None, num_captures=NUM_CAPTURES, resolution=(512, 512), seed=42, num_bins=None):
    """Load and start the palletizing cell, then run the SDG on top of it until ``num_captures`` bins are done.

    Returns ``(demo, sample)``: the SDG demo and the running ``BinStacking``.
    """
    # Load the bin stacking stage and start the demo
    random.seed(seed)
    rep.set_global_seed(seed)
    bin_stacking_sample = BinStacking(num_bins=num_bins)
    bin_stacking_sample.load_world()
    bin_stacking_sample.start()

    # Wait a few frames for the stacking demo to start
    for _ in range(3):
        rep.orchestrator.update()

    # Start the SDG pipeline on top of the palletizing demo
    sdg_demo = PalletizingSDGDemo(output_dir, resolution)
    sdg_demo.start(num_captures=num_captures)

    # Wait until the demo is finished
    while sdg_demo.is_running():
        sdg_demo.update()
    print("[PalletizingSDGDemo] Done..")
    return sdg_demo, bin_stacking_sample


if __name__ == "__main__":
    run_example(output_dir=sys.argv[1] if len(sys.argv) > 1 else None)
