"""Randomization in Simulation - UR10 Palletizing (Isaac Sim tutorial), on a small built scene.

The tutorial's Replicator graphs, unchanged but for the import line:

* bin flip scenario: three sphere lights (temperature, intensity, position,
  scale and a colour palette, all randomized) from a registered randomizer, and a
  camera walking a sequence of positions, all ``on_frame()``; data read from
  annotators directly;
* pallet scenario: ten OmniPBR materials randomized and assigned to the bins
  every frame, and the pallet's texture and the camera pose every 4th frame
  (``on_frame(interval=4)``); data written by BasicWriter.

The UR10 simulation (which decides *when* to capture) is replaced by a built
pallet-and-bins scene; Omniverse asset textures by generated wood textures; and
``DeletePrimsCommand(paths=["/Replicator"])`` by ``rep.graph.clear()``, which
also releases the graph. The pallet scenario's BasicWriter also writes
``provenance_{n}.json`` (what the graph sampled for each frame).
"""
import json
import os
import sys

import numpy as np
from PIL import Image
from pxr import UsdShade

import graphsdg as rep
from graphsdg import settings, stage
from graphsdg.stage.xform import world_matrix


def build_scene(texture_dir):
    """A table with a pallet, a flip helper and bins; returns the wood texture paths."""
    stage.new_stage()
    rep.functional.create.xform(name="World")
    rep.functional.create.dome_light(intensity=400, parent="/World", name="Sky")
    rep.functional.create.xform(name="Ur10Table", parent="/World")
    rep.functional.create.xform(name="pallet", parent="/World/Ur10Table")
    rep.functional.create.xform(name="Xform", parent="/World/Ur10Table/pallet")
    pallet = rep.functional.create.cube(name="Mesh_015", parent="/World/Ur10Table/pallet/Xform",
                                        position=(0.78, 0.72, -0.2), scale=(1.2, 1.0, 0.12),
                                        semantics={"class": "pallet"})
    rep.functional.create.material(name="PalletWood", parent="/World", diffuse_color_constant=(0.55, 0.4, 0.25),
                                   bind_prims=[pallet])
    rep.functional.create.cube(name="pallet_holder", parent="/World/Ur10Table", position=(0.0, 0.0, -0.2),
                               scale=(0.4, 0.4, 0.1))
    rep.functional.create.xform(name="bins", parent="/World/Ur10Table")
    magenta = rep.functional.create.material(name="Magenta", parent="/World", diffuse_color_constant=(0.8, 0.1, 0.7))
    for i in range(4):
        rep.functional.create.xform(name=f"bin_{i}", parent="/World/Ur10Table/bins")
        rep.functional.create.xform(name="Visuals", parent=f"/World/Ur10Table/bins/bin_{i}")
        box = rep.functional.create.cube(name="FOF_Mesh_Magenta_Box", parent=f"/World/Ur10Table/bins/bin_{i}/Visuals",
                                         position=(0.53 + 0.5 * (i % 2), 0.5 + 0.45 * (i // 2), -0.06),
                                         scale=(0.4, 0.3, 0.16), semantics={"class": "bin"})
        rep.functional.modify.material(box, magenta)
    os.makedirs(texture_dir, exist_ok=True)
    paths = []
    rng = np.random.default_rng(0)
    for name, base in (("Oak", (150, 110, 70)), ("Ash", (200, 180, 150)), ("Plywood", (210, 170, 110)),
                       ("Timber", (120, 80, 50))):
        y = np.arange(64)[:, None] + 3 * np.sin(np.arange(64)[None, :] / 5.0) + rng.normal(0, 0.5, (64, 64))
        grain = 0.8 + 0.2 * np.sin(y / 2.5)
        img = np.clip(np.asarray(base)[None, None, :] * grain[..., None], 0, 255).astype(np.uint8)
        path = os.path.join(texture_dir, f"{name}_BaseColor.png")
        Image.fromarray(img).save(path)
        paths.append(path)
    return paths


class PalletizingSDGDemo:
    BINS_FOLDER_PATH = "/World/Ur10Table/bins"
    FLIP_HELPER_PATH = "/World/Ur10Table/pallet_holder"
    PALLET_PRIM_MESH_PATH = "/World/Ur10Table/pallet/Xform/Mesh_015"
    BIN_FLIP_SCENARIO_FRAMES = 4
    PALLET_SCENARIO_FRAMES = 16

    def __init__(self, output_dir, texture_paths, resolution=(512, 512)):
        self._bin_counter = 0
        self._stage = stage.get_stage()
        self._rep_camera = None
        self._output_dir = output_dir
        self._texture_paths = texture_paths
        self._resolution = resolution

    def _clear_graph(self):
        # Isaac: omni.kit.commands.execute("DeletePrimsCommand", paths=["/Replicator"])
        if self._stage.GetPrimAtPath("/Replicator"):
            rep.graph.clear()

    def run(self, num_bins=2):
        rep.orchestrator.set_capture_on_play(False)
        self._clear_graph()
        for self._bin_counter in range(num_bins):
            self._run_bin_flip_scenario()
            self._run_pallet_scenario()

    def _run_bin_flip_scenario(self):
        print(f"[PalletizingSDGDemo] Running bin flip scenario for bin {self._bin_counter}..")

        def save_img(rgb_data, filename):
            Image.fromarray(rgb_data).convert("RGBA").save(filename + ".png")

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
            save_img(rgb_annot.get_data(), f"{out_dir}rgb_{i}")
            is_data = is_annot.get_data()
            is_img_data = is_data["data"]
            height, width = is_img_data.shape[:2]
            save_img(is_img_data.view(np.uint8).reshape(height, width, -1), f"{out_dir}is_{i}")
            with open(f"{out_dir}is_info_{i}.json", "w") as f:
                json.dump(is_data["info"], f, indent=4)
        rgb_annot.detach()
        is_annot.detach()
        rp.destroy()
        rep.orchestrator.wait_until_complete()
        self._clear_graph()

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
        writer.initialize(output_dir=out_dir, rgb=True, instance_segmentation=True,
                          colorize_instance_segmentation=True, provenance=True)
        rp = rep.create.render_product(self._rep_camera, self._resolution)
        writer.attach(rp)
        for i in range(self.PALLET_SCENARIO_FRAMES):
            rep.orchestrator.step(rt_subframes=24, delta_time=0.0)
        writer.detach()
        rp.destroy()
        for mesh, mat in mesh_to_orig_mats.items():
            print(f"[PalletizingSDGDemo] Restoring original material({mat.GetPath()}) for {mesh.GetPath()}")
            UsdShade.MaterialBindingAPI(mesh).Bind(mat, UsdShade.Tokens.strongerThanDescendants)
        rep.orchestrator.wait_until_complete()
        self._clear_graph()

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
        texture_paths = self._texture_paths
        pallet_node = rep.get.prim_at_path(self.PALLET_PRIM_MESH_PATH)
        pallet_prim = pallet_node.get_output_prims()["prims"][0]
        pallet_loc = world_matrix(pallet_prim)[3, :3]   # omni.usd.get_world_transform_matrix(...).ExtractTranslation()
        self._rep_camera = rep.create.camera()
        with rep.trigger.on_frame(interval=4):
            with pallet_node:
                rep.randomizer.texture(texture_paths, texture_rotate=rep.distribution.uniform(80, 95))
            with self._rep_camera:
                rep.modify.pose(
                    position=rep.distribution.uniform((0, -2, 1), (2, 1, 2)),
                    look_at=(pallet_loc[0], pallet_loc[1], pallet_loc[2]),
                )


def main(output_dir=None, resolution=(512, 512), num_bins=2):
    output_dir = output_dir or os.path.join(os.getcwd(), "_out_palletizing_sdg_demo")
    settings.set("/rtx/rendermode", "RayTracedLighting")
    rep.set_global_seed(7)
    textures = build_scene(os.path.join(output_dir, "textures"))
    print(f"[PalletizingSDGDemo] Output directory: {output_dir}")
    PalletizingSDGDemo(output_dir, textures, resolution).run(num_bins=num_bins)
    return output_dir


if __name__ == "__main__":
    main(output_dir=sys.argv[1] if len(sys.argv) > 1 else None)
