"""omni.kit.viewport.utility's window and file capture draw the viewport's camera into an image file."""
import asyncio

import numpy as np
import pytest
from PIL import Image

from graphsdg.compat import isaac


@pytest.fixture
def compat():
    isaac.install()
    yield
    isaac.uninstall()


def test_capture_viewport_to_file_writes_the_viewport_camera_image(compat, tmp_path):
    import omni.replicator.core as rep
    import omni.usd
    from omni.kit.viewport.utility import capture_viewport_to_file, get_active_viewport_window
    omni.usd.get_context().new_stage()
    rep.functional.create.dome_light(intensity=1000)
    cube = rep.functional.create.cube(name="Cube", scale=2.0)
    rep.functional.modify.attribute(cube, "primvars:displayColor", [(1.0, 0.0, 0.0)])
    window = get_active_viewport_window()
    viewport = window.viewport_api
    viewport.resolution = (64, 48)
    target = tmp_path / "shot.png"
    capture = capture_viewport_to_file(viewport, str(target))
    assert asyncio.run(capture.wait_for_result())
    image = np.asarray(Image.open(target))
    assert image.shape == (48, 64, 3)
    centre = image[24, 32].astype(int)
    assert centre[0] > 2 * max(centre[1], centre[2], 1)   # the red cube the perspective camera looks at


def test_capture_refuses_hdr_and_a_missing_path(compat):
    from omni.kit.viewport.utility import capture_viewport_to_file
    with pytest.raises(ValueError, match="file_path"):
        capture_viewport_to_file(None, None)
    with pytest.raises(ValueError, match="LDR"):
        capture_viewport_to_file(None, "/tmp/x.exr", is_hdr=True)


def test_physx_interface_steps_a_falling_body_and_reads_its_pose(compat):
    import omni.physx
    import omni.replicator.core as rep
    import omni.usd
    omni.usd.get_context().new_stage()
    rep.functional.physics.create_physics_scene("/PhysicsScene")
    ball = rep.functional.create.sphere(name="Ball", position=(0, 0, 10))
    rep.functional.physics.apply_rigid_body(ball)
    physx = omni.physx.get_physx_interface()
    physx.start_simulation()
    physx.update_simulation(0.5, 0.0)
    pose = physx.get_rigidbody_transformation(str(ball.GetPath()))
    assert pose["ret_val"]
    assert pose["position"][2] == pytest.approx(10 - 0.5 * 9.81 * 0.25, abs=0.1)   # free fall for 0.5 s
    assert pose["rotation"][3] == pytest.approx(1.0, abs=1e-3)                      # x, y, z, w: no spin
    assert not physx.get_rigidbody_transformation("/Nothing")["ret_val"]
    with pytest.warns(UserWarning, match="no effect"):
        physx.overwrite_gpu_setting(1)


def test_old_create_hydra_texture_makes_a_render_product_of_the_camera(compat):
    import omni.replicator.core as rep
    import omni.usd
    from omni.isaac.core.utils.render_product import create_hydra_texture, get_camera_prim_path, get_resolution
    omni.usd.get_context().new_stage()
    cam = rep.functional.create.camera(position=(3, 0, 0), look_at=(0, 0, 0), name="Cam")
    texture, path = create_hydra_texture((64, 32), str(cam.GetPath()))
    assert get_camera_prim_path(path) == str(cam.GetPath())
    assert tuple(get_resolution(path)) == (64, 32)
    assert texture.get_updates_enabled()
